"""certify(): the optimum is certified, a perturbed optimum is not (with a
valid lower bound), equal to the C++ API, error paths."""

import json

import numpy as np
import pytest

import ceres_sesync as cs
from conftest import dataset, run_tool


def rotate(R, angle, axis=2):
    """R times a rotation by `angle` about coordinate `axis` (3D) or in the
    plane (2D)."""
    d = R.shape[-1]
    c, s = np.cos(angle), np.sin(angle)
    if d == 2:
        E = np.array([[c, -s], [s, c]])
    else:
        a, b = [k for k in range(3) if k != axis]
        E = np.eye(3)
        E[a, a], E[a, b], E[b, a], E[b, b] = c, -s, s, c
    return R @ E


@pytest.mark.parametrize("d", [2, 3])
def test_optimum_certified_perturbed_optimum_not(d):
    g, _, _ = cs.generate_cube(dimension=d, side=8 if d == 2 else 4, seed=2)
    r = cs.solve(g)
    assert r.certified, r.summary
    c = cs.certify(g, r.rotations, r.translations)
    assert c.certified, c.summary
    assert c.objective == pytest.approx(r.objective, rel=1e-12)
    assert c.lower_bound <= c.objective
    assert c.relative_suboptimality_bound <= 1e-3
    assert c.negative_curvature_direction is None and c.improved_poses is None

    # Perturb: rotate a block of poses by 0.2 rad. The true gap is then
    # F(perturbed) - F*, with F* >= r.lower_bound; once it exceeds the 1e-3
    # tolerance no valid certificate may say "certified".
    R = r.rotations.copy()
    R[len(R) // 2 :] = rotate(R[len(R) // 2 :], 0.2)
    t = r.translations
    p = cs.certify(g, R, t)
    true_gap = (p.objective - r.objective) / r.objective
    assert true_gap > 1e-2
    assert not p.certified, p.summary
    assert p.lower_bound <= r.objective * (1 + 1e-9)  # a valid bound on F*
    assert p.relative_suboptimality_bound >= true_gap * (1 - 1e-9)
    assert p.objective == pytest.approx(cs.evaluate_objective(g, R, t), rel=1e-12)
    v = p.negative_curvature_direction
    if v is not None:
        assert v.shape == (d * g.num_poses,)
        assert np.linalg.norm(v) == pytest.approx(1, abs=1e-9)
        assert p.negative_curvature < 0

    # With improvement, SE-Sync from the perturbed poses gets back to the
    # certified optimum.
    q = cs.certify(g, R, t, improve_if_not_certified=True, solver_options={"max_rank": 8})
    assert not q.certified and q.has_improved_poses
    assert q.improvement_summary.status == "CERTIFIED_OPTIMUM"
    Ri, ti = q.improved_poses
    assert Ri.shape == R.shape and ti.shape == t.shape
    assert cs.evaluate_objective(g, Ri, ti) == pytest.approx(r.objective, rel=1e-8)


def test_errors():
    g, R, t = cs.generate_cube(dimension=3, side=2)
    with pytest.raises(ValueError, match=r"rotations must have shape \(8, 3, 3\), not \(7, 3, 3\)"):
        cs.certify(g, R[:7], t)
    with pytest.raises(ValueError, match=r"translations must have shape \(8, 3\)"):
        cs.certify(g, R, t[:, :2])
    bad = R.copy()
    bad[3, 0, 0] = np.nan
    with pytest.raises(ValueError, match="candidate pose 3 .* is not finite"):
        cs.certify(g, bad, t)
    with pytest.raises(TypeError, match="must be an array"):
        cs.certify(g, None, t)
    unexpected = r"^certify\(\) got an unexpected keyword argument 'solver_options.robust'$"
    with pytest.raises(TypeError, match=unexpected):
        cs.certify(g, R, t, solver_options={"robust": True})
    with pytest.raises(TypeError, match="unexpected keyword argument 'tolerance'"):
        cs.certify(g, R, t, tolerance=1)
    options = cs.CertifyOptions(solver_options=cs.SolverOptions(max_rank=6))
    assert options.solver_options.max_rank == 6
    options.solver_options.max_rank = 7  # a reference, not a copy
    assert options.solver_options.max_rank == 7


def test_equal_to_the_cpp_api(tmp_path):
    path = dataset("intel")
    g = cs.read_g2o(path)
    r = cs.solve(g)
    poses = tmp_path / "poses.g2o"
    cs.write_g2o_poses(poses, g, r.rotations, r.translations)
    R, t = cs.read_g2o_poses(poses, g)  # what the program reads
    run = run_tool("certify", path, poses, "--json", tmp_path / "c.json")
    assert run.returncode == 0, run.stdout + run.stderr
    cpp = json.loads((tmp_path / "c.json").read_text())
    c = cs.certify(g, R, t)
    keys = ["objective", "rotation_objective", "eta", "lower_bound", "relative_suboptimality_bound"]
    for key in keys:
        assert getattr(c, key) == cpp[key], key
    assert c.certified == cpp["certified"] is True
