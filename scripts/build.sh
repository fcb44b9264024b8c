#!/usr/bin/env bash
# Installs dependencies (if missing), configures and builds into build/ (or
# $BUILD_DIR); $BUILD_TARGET limits the build to one target. Extra arguments
# go to cmake. The build log is kept in $BUILD_DIR/build.log and its tail is
# printed if the build fails.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
build=${BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
if ! cmake --build "$build" -j"$(nproc)" ${BUILD_TARGET:+--target "$BUILD_TARGET"} \
  -- --no-print-directory >"$build/build.log" 2>&1; then
  tail -n 60 "$build/build.log" >&2
  echo "build failed; full log: $build/build.log" >&2
  exit 1
fi
