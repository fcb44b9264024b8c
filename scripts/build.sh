#!/usr/bin/env bash
# Installs dependencies (if missing), configures and builds into build/ (or
# $BUILD_DIR); $BUILD_TARGET limits the build to one target. Extra arguments
# go to cmake.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
build=${BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build" -j"$(nproc)" ${BUILD_TARGET:+--target "$BUILD_TARGET"} \
  -- --no-print-directory >/dev/null
