#!/usr/bin/env bash
# Sanitizer run: configures build-asan (or $BUILD_DIR) with
# -DCERES_SESYNC_SANITIZE=ON (AddressSanitizer + UndefinedBehaviorSanitizer,
# see CMakeLists.txt), builds the library, tool, tests and examples in
# RelWithDebInfo, and runs ctest with leak detection on. Any sanitizer report
# aborts the reporting test, so the script fails on any report.
#
#   scripts/sanitize.sh [extra ctest arguments]
#
# Environment: BUILD_DIR (default build-asan), JOBS (build/ctest parallelism,
# default 2), CTEST_EXCLUDE (a ctest -E regex; default: see below).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build-asan}
jobs=${JOBS:-2}
supp="$root/scripts/sanitizers"

"$root/scripts/install-deps.sh"
start=$(date +%s)
# Benchmarks are not part of the test suite; everything ctest runs is built.
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCERES_SESYNC_SANITIZE=ON -DCERES_SESYNC_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j"$jobs" -- --no-print-directory >/dev/null
built=$(date +%s)
echo "sanitize: build took $((built - start)) s"

# detect_leaks: LeakSanitizer at exit. abort_on_error / halt_on_error: the first
# report kills the process, so the test fails. The suppression files (if any
# entries) only cover uninstrumented third-party libraries; see their comments.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
if [ -s "$supp/lsan.supp" ]; then
  export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"
fi
if [ -s "$supp/ubsan.supp" ]; then
  UBSAN_OPTIONS="$UBSAN_OPTIONS:suppressions=$supp/ubsan.supp"
fi
# The consumer_project test configures and builds a fresh project against the
# installed (instrumented) static library: it needs the sanitizer runtimes at
# link time, and its own code must be instrumented the same way (an
# uninstrumented consumer freeing Eigen memory allocated in the instrumented
# library is reported as a bad free; it also needs the library's Eigen allocator
# setting, see CMakeLists.txt). CMake initializes CMAKE_CXX_FLAGS and
# CMAKE_EXE_LINKER_FLAGS from CXXFLAGS and LDFLAGS.
export LDFLAGS="-fsanitize=address,undefined"
export CXXFLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -DEIGEN_MALLOC_ALREADY_ALIGNED=1"

exclude=${CTEST_EXCLUDE-}
cd "$build"
args=(--output-on-failure -j"$jobs")
[ -n "$exclude" ] && args+=(-E "$exclude")
ctest "${args[@]}" "$@"
echo "sanitize: ctest took $(($(date +%s) - built)) s"
