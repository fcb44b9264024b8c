#!/usr/bin/env bash
# Builds and runs the benchmark set (see bench/README.md) and regenerates
# bench/results/.
#
#   scripts/bench.sh           full run (~40-60 min on 2 cores, plus 1-3 h
#                              for the scaling bench up to 10^6 poses and
#                              several hours for the outlier bench):
#                              bench over every dataset (3 repeats), peak
#                              memory of SE-Sync on the largest datasets, the
#                              cube sweep (5 realizations) and scaling run,
#                              the scaling bench (city 2D/3D, cube), the
#                              outlier bench (bench/outliers.cc), plots.
#   scripts/bench.sh --quick   smoke run (seconds): bench --quick,
#                              cube_sweep --quick, scaling --quick and
#                              outliers --quick into $BUILD_DIR/bench-quick
#                              (bench/results is left alone).
#
# Environment: BUILD_DIR (default build/), BENCH_OUT (output directory;
# default bench/results, or $BUILD_DIR/bench-quick with --quick).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
quick=0
if [ "${1:-}" = "--quick" ]; then quick=1; shift; fi
if [ $# -ne 0 ]; then
  echo "usage: scripts/bench.sh [--quick]" >&2
  exit 2
fi

"$root/scripts/install-deps.sh"
build=${BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j"$(nproc)" --target bench cube_sweep scaling outliers landmarks -- \
  --no-print-directory >/dev/null
bin=$build/bench
py=/usr/bin/python3  # Debian's, with python3-matplotlib.
data=$(sed -n 's/^CERES_SESYNC_DATA_DIR:PATH=//p' "$build/CMakeCache.txt")

if [ $quick -eq 1 ]; then
  out=${BENCH_OUT:-$build/bench-quick}
  mkdir -p "$out"
  start=$(date +%s)
  if [ -d "$data" ]; then
    "$bin/bench" --quick --out_dir "$out" --poses_dir "$out/poses" \
      >"$out/bench.txt"
    "$py" "$root/bench/plot_trajectory.py" "$out/poses" "$out" \
      --datasets intel,CSAIL,smallGrid3D --compare intel >/dev/null
  else
    echo "bench.sh: no datasets at '$data'; skipping bench" >&2
  fi
  "$bin/cube_sweep" --quick --out_dir "$out" >"$out/cube_sweep.txt"
  "$py" "$root/bench/plot_cube_sweep.py" "$out"
  "$bin/scaling" --quick --out_dir "$out" >"$out/scaling.txt"
  "$bin/landmarks" --quick --out_dir "$out" >"$out/landmarks.txt"
  "$py" "$root/bench/plot_scaling.py" "$out"
  if [ -d "$data" ]; then
    "$bin/outliers" --quick --out_dir "$out" >"$out/outliers.txt"
    "$py" "$root/bench/plot_outliers.py" "$out" >/dev/null
  fi
  echo "bench.sh --quick: outputs in $out ($(($(date +%s) - start)) s)"
  exit 0
fi

out=${BENCH_OUT:-$root/bench/results}
poses=$build/bench-poses
mkdir -p "$out" "$poses"
[ -d "$data" ] || { echo "bench.sh: no datasets at '$data'" >&2; exit 2; }
start=$(date +%s)

# 1) Datasets: SE-Sync vs Ceres, 3 repeats, poses for the trajectory plots.
"$bin/bench" --repeats 3 --ceres_max_time 60 --out_dir "$out" \
  --poses_dir "$poses" | tee "$out/bench.txt"

# 2) Peak memory (VmHWM via /usr/bin/time -v) of SE-Sync plus Certify alone,
#    one process per dataset, for the largest datasets.
: >"$out/memory.txt"
for name in ais2klinik cubicle torus3D city10000; do
  [ -f "$data/$name.g2o" ] || continue
  /usr/bin/time -v "$bin/bench" --sesync_only --repeats 1 \
    --out_dir "$build/bench-memory" "$data/$name.g2o" \
    >/dev/null 2>"$build/bench-memory.log"
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' \
    "$build/bench-memory.log")
  echo "$name: peak RSS $((rss / 1024)) MiB (SE-Sync + Certify, incl. reading)" \
    | tee -a "$out/memory.txt"
done

# 3) Cube experiments (Figure 3) and scaling.
"$bin/cube_sweep" --realizations 5 --scaling_time_limit 120 \
  --out_dir "$out" | tee "$out/cube_sweep.txt"

# 4) Scaling (issue #16): city 2D/3D from 10^3 to 10^6 poses and the cube,
#    SE-Sync vs Ceres PDL-GN/LM from chordal, one process per run.
"$bin/scaling" --ceres_max_time 600 --out_dir "$out" | tee "$out/scaling.txt"

# 5) Outliers (issue #13): every dataset, random outliers at 10..90% and
#    clustered at 10..50% of the loop closures, 3 seeds, plain SE-Sync, the
#    robust solve and Ceres LM with Huber/Cauchy; then manhattan again with
#    the threshold its precisions need (bench/README.md).
"$bin/outliers" --out_dir "$out" | tee "$out/outliers.txt"
"$bin/outliers" --datasets manhattan --dataset_thresholds manhattan=100 \
  --out_name outliers_manhattan_c100 --out_dir "$out" \
  | tee "$out/outliers_manhattan_c100.txt"

# 6) Landmark SLAM and priors (issue #15): generated 2D/3D maps, SE-Sync vs
#    Ceres from odometry and chordal, every result certified (a few minutes).
"$bin/landmarks" --out_dir "$out" | tee "$out/landmarks.txt"

# 7) Plots.
"$py" "$root/bench/plot_cube_sweep.py" "$out"
"$py" "$root/bench/plot_scaling.py" "$out"
"$py" "$root/bench/plot_outliers.py" "$out"
"$py" "$root/bench/plot_outliers.py" "$out" --name outliers_manhattan_c100
"$py" "$root/bench/plot_trajectory.py" "$poses" "$out" --compare manhattan
"$py" "$root/bench/plot_trajectory.py" "$poses" "$out" --datasets "" \
  --compare torus3D >/dev/null
echo "bench.sh: done in $(($(date +%s) - start)) s; results in $out"
