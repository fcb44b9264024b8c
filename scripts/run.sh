#!/usr/bin/env bash
# The main job: install dependencies (if missing), build, generate the paper's
# 3D cube pose graph (side 10: 1000 poses, default noise), solve it with
# SE-Sync, certify the solution independently, and print both reports.
# Extra arguments go to `ceres_sesync solve` (e.g. --verbose).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
BUILD_TARGET=ceres_sesync_tool "$root/scripts/build.sh"
build=${BUILD_DIR:-$root/build}
tool="$build/ceres_sesync"
out="$build/demo"
mkdir -p "$out"
"$tool" generate cube --side 10 --seed 0 --output "$out/cube.g2o" \
  --ground_truth "$out/cube_ground_truth.g2o"
status=0
"$tool" solve "$out/cube.g2o" --output "$out/cube_sesync.g2o" \
  --tum "$out/cube_sesync.tum" --json "$out/solve.json" "$@" || status=$?
"$tool" certify "$out/cube.g2o" "$out/cube_sesync.g2o" \
  --json "$out/certify.json" || status=$?
echo
echo "Outputs in $out (poses: cube_sesync.g2o / .tum; summaries: *.json)"
exit $status
