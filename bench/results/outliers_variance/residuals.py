"""Per-measurement residuals at each dataset's certified optimum, split into
the rotation term kappa ||R_j - R_i R_ij||_F^2 and the translation term
tau ||t_j - t_i - R_i t_ij||^2, and the variance factors
s^2 = sum / (dof * (m - n + 1)) they give (README.md here).

Run from the repository root after a build with the Python module:
  /usr/bin/python3 bench/results/outliers_variance/residuals.py [names...]
"""
import sys

import numpy as np

sys.path.insert(0, 'build/python')
import ceres_sesync as cs  # noqa: E402

DATA = '../shared/datasets/'
NAMES = ['CSAIL', 'intel', 'manhattan', 'city10000', 'ais2klinik', 'kitti_00',
         'sphere2500', 'torus3D', 'parking-garage', 'cubicle', 'smallGrid3D',
         'tinyGrid3D']

for name in sys.argv[1:] or NAMES:
    g = cs.read_g2o(DATA + name + '.g2o')
    r = cs.solve(g, num_threads=2)
    m, R, t, d = g.measurements, r.rotations, r.translations, g.dimension
    Ri, Rj = R[m.i], R[m.j]
    rot = m.kappa * np.sum((Rj - np.einsum('kab,kbc->kac', Ri, m.R))**2,
                           axis=(1, 2))
    te = t[m.j] - t[m.i] - np.einsum('kab,kb->ka', Ri, m.t)
    tr = m.tau * np.sum(te**2, axis=1)
    f = rot + tr
    ids = np.array(g.vertex_ids)
    closure = np.abs(ids[m.j] - ids[m.i]) != 1  # as IsOdometry
    redundancy = len(f) - g.num_poses + 1
    dof_rot, dof_tr = d * (d - 1) // 2, d
    s2 = f.sum() / ((dof_rot + dof_tr) * redundancy)
    s2_rot = rot.sum() / (dof_rot * redundancy)
    s2_tr = tr.sum() / (dof_tr * redundancy)
    print(f'| {name} | {g.num_poses} | {len(f)} | {s2:.3g} | {s2_rot:.3g} | '
          f'{s2_tr:.3g} | {f[closure].max():.3g} | '
          f'{f[closure].max() / s2:.3g} | {rot[closure].max() / s2_rot:.3g} | '
          f'{tr[closure].max() / s2_tr:.3g} |', flush=True)
