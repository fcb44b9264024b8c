"""Local optima from uniformly random rotations against SE-Sync's answer.

For each g2o file: SE-Sync's F(x) and bound, then 30 solves at the fixed
rank d + 1 (initial_rank = max_rank = d + 1: a local search, its rounding
and refinement) from random rotations; prints the best and median F and how
many end below SE-Sync's F(x). Run from the repository root after a build
with the Python module:
  /usr/bin/python3 bench/results/continue/random_starts.py FILE.g2o...
"""
import sys

import numpy as np

sys.path.insert(0, 'build/python')
import ceres_sesync as cs  # noqa: E402

rng = np.random.default_rng(0)
for path in sys.argv[1:]:
    g = cs.read_g2o(path)
    d, n = g.dimension, g.num_poses
    r = cs.solve(g, num_threads=1)
    values = []
    for _ in range(30):
        R0 = np.empty((n, d, d))
        for i in range(n):
            Q, _ = np.linalg.qr(rng.normal(size=(d, d)))
            if np.linalg.det(Q) < 0:
                Q[:, 0] *= -1
            R0[i] = Q
        values.append(cs.solve(g, R0, initial_rank=d + 1, max_rank=d + 1,
                               num_threads=1).objective)
    values = np.array(values)
    below = int((values < r.objective * (1 - 1e-9)).sum())
    print(f'{path}: SE-Sync F {r.objective:.6f} (bound '
          f'{r.relative_suboptimality_bound:.2e}); random starts best '
          f'{values.min():.6f}, median {np.median(values):.6f}, below: '
          f'{below} of 30', flush=True)
