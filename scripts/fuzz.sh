#!/usr/bin/env bash
# Builds the g2o reader fuzzer with clang into build-fuzz (or $BUILD_DIR) and
# runs it for SECONDS (default 600) on a copy of the seed corpus
# tests/fuzz/corpus, with inputs up to 4096 bytes. Prints libFuzzer's final
# statistics (execs, execs/s, coverage). Exits non-zero on any finding; the
# crashing input is saved in $BUILD_DIR/fuzz-artifacts/.
#
#   scripts/fuzz.sh [SECONDS]     e.g. scripts/fuzz.sh 30 (CI smoke run)
#
# Environment: BUILD_DIR, JOBS (build parallelism, default 2).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-600}
build=${BUILD_DIR:-$root/build-fuzz}
jobs=${JOBS:-2}

"$root/scripts/install-deps.sh"
CC=clang CXX=clang++ cmake -S "$root" -B "$build" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCERES_SESYNC_BUILD_FUZZERS=ON >/dev/null
cmake --build "$build" -j"$jobs" --target g2o_reader_fuzzer \
  -- --no-print-directory >/dev/null

# New inputs go to a scratch corpus so the checked-in seeds stay small; the
# seeds are read from the source tree.
work="$build/fuzz-corpus"
artifacts="$build/fuzz-artifacts"
mkdir -p "$work" "$artifacts"
log="$build/fuzz.log"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
"$build/g2o_reader_fuzzer" -max_total_time="$seconds" -max_len=4096 \
  -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$artifacts/" "$work" "$root/tests/fuzz/corpus" \
  >"$log" 2>&1 || status=$?

# The last status line (#N DONE/pulse cov: ft: corp: exec/s:) and the final
# stats block.
grep -E '^#[0-9]+' "$log" | tail -n 1 || true
grep -E '^(stat::|Done )' "$log" || true
if [ "$status" -ne 0 ]; then
  echo "fuzz: FAILED (exit $status); log: $log" >&2
  grep -E 'ERROR|invariant violated|Test unit written|SUMMARY' "$log" >&2 || true
  exit "$status"
fi
echo "fuzz: no findings in ${seconds} s"
