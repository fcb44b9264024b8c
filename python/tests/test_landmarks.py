"""Landmarks and priors from Python: generate_landmarks, solve returning the
landmark positions, certify / evaluate_objective / write and read with them,
an objective evaluated with numpy from the graph's arrays, and results equal
to the ceres_sesync program's."""

import json

import numpy as np
import pytest

import ceres_sesync as cs
from conftest import objective, run_tool


def full_objective(g, R, t, p):
    """F of pose_graph.h (edges, landmark measurements, priors) with numpy,
    from the graph's arrays, independently of the library."""
    ms = g.measurements
    f = objective(ms.i, ms.j, ms.R, ms.t, ms.kappa, ms.tau, R, t)
    lm = g.landmark_measurements
    i, l = lm["i"], lm["l"]
    r = p[l] - t[i] - np.einsum("kab,kb->ka", R[i], lm["z"])
    f += float(np.sum(lm["nu"] * np.sum(r**2, axis=1)))
    pr = g.priors
    for k in range(len(pr["i"])):
        i = pr["i"][k]
        if pr["kappa"][k] > 0:
            f += pr["kappa"][k] * float(np.sum((R[i] - pr["R"][k]) ** 2))
        if pr["tau"][k] > 0:
            f += pr["tau"][k] * float(np.sum((t[i] - pr["t"][k]) ** 2))
    return f


def small(d, **options):
    base = dict(dimension=d, num_poses=200, world_size=20, num_landmarks=150,
                sensor_range=4, gps_interval=25, start_prior=True, seed=3)
    base.update(options)
    return cs.generate_landmarks(**base)


@pytest.mark.parametrize("d", [2, 3])
def test_noiseless_map_recovered_in_the_world_frame(d):
    g, R, t, p = small(d, noiseless=True)
    assert g.num_landmarks == p.shape[0] > 0 and len(g.priors["i"]) > 0
    r = cs.solve(g)
    assert r.certified, r.summary
    assert r.num_landmarks == g.num_landmarks
    assert r.landmarks.shape == (g.num_landmarks, d)
    # Priors fix the gauge: the map itself, not just up to a rigid motion.
    np.testing.assert_allclose(r.rotations, R, atol=1e-7)
    np.testing.assert_allclose(r.translations, t, atol=1e-6)
    np.testing.assert_allclose(r.landmarks, p, atol=1e-6)


@pytest.mark.parametrize("d", [2, 3])
def test_noisy_map_certified_objective_reproduced_with_numpy(d):
    g, R, t, p = small(d)
    r = cs.solve(g)
    assert r.certified, r.summary
    f = full_objective(g, r.rotations, r.translations, r.landmarks)
    assert f == pytest.approx(r.objective, rel=1e-10)
    assert cs.evaluate_objective(g, r.rotations, r.translations, r.landmarks) == (
        pytest.approx(f, rel=1e-12))
    # Certified optimal: the ground truth is no better.
    assert r.objective <= full_objective(g, R, t, p)

    c = cs.certify(g, r.rotations, r.translations, r.landmarks)
    assert c.certified, c.summary
    assert c.objective == pytest.approx(r.objective, rel=1e-12)

    # One landmark moved by 1 m: not certified, the bound stays valid, and
    # the improvement run gets back to the optimum.
    moved = r.landmarks.copy()
    moved[5] += 1.0
    q = cs.certify(g, r.rotations, r.translations, moved,
                   improve_if_not_certified=True)
    assert not q.certified
    assert q.lower_bound <= r.objective * (1 + 1e-12)
    assert q.improvement_summary.certified
    np.testing.assert_allclose(q.improved_landmarks, r.landmarks, atol=1e-6)

    with pytest.raises(ValueError, match="landmarks"):
        cs.certify(g, r.rotations, r.translations)  # positions missing
    with pytest.raises(ValueError, match="landmarks"):
        cs.certify(g, r.rotations, r.translations, r.landmarks[:-1])
    with pytest.raises(ValueError, match="landmarks"):
        cs.evaluate_objective(g, r.rotations, r.translations)


def test_files_and_results_equal_the_program(tmp_path):
    g, _, _, _ = small(2, seed=9)
    graph = tmp_path / "graph.g2o"
    cs.write_g2o(graph, g)
    out, summary = tmp_path / "solved.g2o", tmp_path / "summary.json"
    run = run_tool("solve", graph, "--output", out, "--json", summary)
    assert run.returncode == 0, run.stdout + run.stderr
    cpp = json.loads(summary.read_text())
    assert cpp["num_landmarks"] == g.num_landmarks
    assert cpp["num_priors"] == len(g.priors["i"])

    h = cs.read_g2o(graph)
    r = cs.solve(h)
    assert r.objective == cpp["objective"]
    assert r.lower_bound == cpp["lower_bound"]
    R, t, p = cs.read_g2o_solution(out, h)
    np.testing.assert_allclose(r.rotations, R, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(r.translations, t)
    np.testing.assert_array_equal(r.landmarks, p)

    # Written from Python, read back with their ids; certify with the program.
    mine = tmp_path / "mine.g2o"
    cs.write_g2o_poses(mine, h, r.rotations, r.translations, r.landmarks)
    R2, t2, p2 = cs.read_g2o_solution(mine, h)
    np.testing.assert_array_equal(p2, r.landmarks)
    assert run_tool("certify", graph, mine).returncode == 0
    # The whole graph with the solution as its VERTEX lines.
    full = tmp_path / "full.g2o"
    cs.write_g2o(full, h, r.rotations, r.translations, r.landmarks)
    np.testing.assert_array_equal(cs.read_g2o(full).initial_landmarks, r.landmarks)


def test_generate_landmarks_options():
    g, R, t, p = cs.generate_landmarks("victoria", num_poses=100, seed=1)
    assert g.dimension == 2 and g.num_poses == 100
    # The preset's dense observations: many landmarks per pose.
    assert len(g.landmark_measurements["i"]) > 10 * g.num_poses
    assert R.shape == (100, 2, 2) and t.shape == (100, 2) and p.shape == (g.num_landmarks, 2)
    o = cs.LandmarkGraphOptions(dimension=3, num_poses=50)
    assert o.as_dict()["num_poses"] == 50
    with pytest.raises(TypeError, match="bogus"):
        cs.generate_landmarks(bogus=1)
    with pytest.raises(ValueError, match="preset"):
        cs.generate_landmarks("city")
    with pytest.raises(ValueError):
        cs.generate_landmarks(num_poses=1)


def test_bad_landmark_lines_name_file_and_line(tmp_path):
    edge = "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
    cases = {
        "EDGE_SE2_XY 0 5 1 2 1 0\n": "EDGE_SE2_XY needs 7 fields, found 6",
        "EDGE_SE2_XY 0 5 nan 2 1 0 1\n": "field 3 'nan' is not finite",
        "EDGE_SE2_XY 0 5 1 2 0 0 0\n": "not positive definite",
        "VERTEX_XY 5 1 2\n": "landmark 5 is not observed",
        "EDGE_PRIOR_SE2_XY 0 1 2 1 0 -1\n": "not positive definite",
    }
    for k, (line, message) in enumerate(cases.items()):
        path = tmp_path / f"bad{k}.g2o"
        path.write_text(edge + line)
        with pytest.raises(ValueError, match=f"^{path}:2: .*{message}"):
            cs.read_g2o(path)
    # A landmark id reused as a pose names the edge's line.
    path = tmp_path / "mixed.g2o"
    path.write_text(edge + "EDGE_SE2_XY 0 5 1 2 1 0 1\nEDGE_SE2 1 5 1 0 0 1 0 0 1 0 1\n")
    with pytest.raises(ValueError, match=f"^{path}:2: vertex 5 is a pose"):
        cs.read_g2o(path)
    # A solution file missing a landmark's VERTEX line.
    g, _, _, _ = small(2, num_poses=30, seed=4)
    r = cs.solve(g)
    poses_only = tmp_path / "poses.g2o"
    cs.write_g2o_poses(poses_only, g, r.rotations, r.translations)
    with pytest.raises(ValueError, match=f"^{poses_only}:.*no VERTEX line for landmark"):
        cs.read_g2o_solution(poses_only, g)


def test_robust_solve_rejects_false_fixes_and_wrong_associations(tmp_path):
    """solve(robust=True) on a landmark graph with wrong associations and
    false GPS fixes made by the ceres_sesync program: the false fixes are
    exactly outlier_priors, the landmark rejections are as many as the wrong
    associations, and the inlier problem's objective is F of the accepted
    terms, evaluated here with numpy."""
    clean, bad = tmp_path / "clean.g2o", tmp_path / "bad.g2o"
    run = run_tool("generate", "landmarks", "--dimension", 3, "--num_poses", 200,
                   "--num_landmarks", 150, "--world_size", 16, "--gps_interval", 10,
                   "--start_prior", "--landmark_nu", 400, "--noiseless", "--seed", 2,
                   "--output", clean)
    assert run.returncode == 0, run.stderr
    run = run_tool("generate", "outliers", clean, "--landmark_fraction", 0.3,
                   "--prior_fraction", 0.3, "--seed", 5, "--output", bad)
    assert run.returncode == 0, run.stderr
    kinds = [line.split() for line in open(f"{bad}.outliers.txt")]
    wrong = [int(k) for kind, k in kinds if kind == "landmark"]
    fixes = [int(k) for kind, k in kinds if kind == "prior"]
    g = cs.read_g2o(str(bad))
    rr = cs.solve(g, robust=True)
    assert rr.certified, rr.summary
    assert list(rr.outlier_priors) == fixes
    assert len(rr.outlier_edges) == 0
    assert len(rr.outlier_landmark_measurements) == len(wrong)
    assert rr.num_landmark_measurements == len(g.landmark_measurements["i"])
    assert rr.landmarks.shape == (g.num_landmarks, 3)
    kind = np.array([e.kind for e in rr.edges])
    assert set(kind) == {"measurement", "landmark", "prior"}
    # F of the accepted terms at the result, with numpy.
    R, t, p = rr.rotations, rr.translations, rr.landmarks
    ms, lm, pr = g.measurements, g.landmark_measurements, g.priors
    inlier = rr.inliers
    m, M = len(ms.i), len(lm["i"])
    keep = inlier[:m]
    f = objective(ms.i[keep], ms.j[keep], ms.R[keep], ms.t[keep], ms.kappa[keep],
                  ms.tau[keep], R, t)
    keep = inlier[m:m + M]
    i, l = lm["i"][keep], lm["l"][keep]
    r = p[l] - t[i] - np.einsum("kab,kb->ka", R[i], lm["z"][keep])
    f += float(np.sum(lm["nu"][keep] * np.sum(r**2, axis=1)))
    for k in np.flatnonzero(inlier[m + M:]):
        i = pr["i"][k]
        if pr["kappa"][k] > 0:
            f += pr["kappa"][k] * float(np.sum((R[i] - pr["R"][k]) ** 2))
        if pr["tau"][k] > 0:
            f += pr["tau"][k] * float(np.sum((t[i] - pr["t"][k]) ** 2))
    assert f == pytest.approx(rr.objective, rel=1e-9, abs=1e-9)
