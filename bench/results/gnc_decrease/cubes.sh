#!/bin/bash
# The 154 noisy cubes of bench/results/outliers_gnc_effort.md: 3x3x3 and
# 4x4x4 (`generate cube`, the paper's noise), seeds 1-40, 30% and 50% random
# wrong closures (`generate outliers --seed` = the cube's seed; graphs where
# none was added are skipped). Counts the robust solves whose rejected set is
# exactly the added one.
#
# usage: cubes.sh CERES_SESYNC_BINARY WORK_DIR [VAR=value ...]
# (the VAR=value pairs are put in each solve's environment)
set -eu
tool=$1
work=$2
shift 2
mkdir -p "$work"
cd "$work"
for side in 3 4; do
  for seed in $(seq 1 40); do
    "$tool" generate cube --side $side --seed $seed --output c${side}_$seed.g2o \
      > /dev/null
    for f in 0.3 0.5; do
      out=o${side}_${seed}_$f
      # (Refused when the cube has no loop closure to replace.)
      "$tool" generate outliers c${side}_$seed.g2o --fraction $f --seed $seed \
        --output $out.g2o --outlier_indices $out.idx > /dev/null 2>&1 || true
      [ -s $out.idx ] || rm -f $out.g2o $out.idx
    done
  done
done
exact=0
total=0
: > wrong.txt
for g in o*.g2o; do
  b=$(basename $g .g2o)
  env "$@" "$tool" solve $g --robust --num_threads 1 --json $b.json \
    > /dev/null 2>&1 || true
  got=$(/usr/bin/python3 -c 'import json, sys
print(" ".join(map(str, sorted(json.load(open(sys.argv[1]))["outlier_edges"]))))' \
    $b.json 2> /dev/null || true)
  want=$(sort -n $b.idx | tr '\n' ' ' | sed 's/ $//')
  total=$((total + 1))
  if [ "$got" == "$want" ]; then exact=$((exact + 1)); else echo $b >> wrong.txt; fi
done
echo "$exact / $total exact (the others: $work/wrong.txt)"
