"""solve(robust=True): GNC-TLS around SE-Sync from Python, against ground
truth, plain solve() and the command line."""

import json
import signal
import threading
import time

import numpy as np
import pytest

import ceres_sesync as cs
from conftest import in_frame_of_first, random_rotations, relative_measurements, run_tool


def corrupted_graph(rng, d, n, closures, outliers):
    """A noiseless chain with `closures` exact loop closures, then `outliers`
    wrong ones (random pose pairs, random relative poses) appended. Returns
    (graph, R, t, indices of the wrong measurements)."""
    R = random_rotations(rng, n, d)
    t = rng.uniform(-10, 10, (n, d))
    i = [np.arange(n - 1)]
    j = [np.arange(1, n)]
    a = rng.integers(0, n, 4 * closures)
    b = rng.integers(0, n, 4 * closures)
    keep = np.abs(a - b) > 1
    i.append(a[keep][:closures])
    j.append(b[keep][:closures])
    i, j = np.concatenate(i), np.concatenate(j)
    Rm, tm = relative_measurements(R, t, i, j)
    a = rng.integers(0, n, 4 * outliers)
    b = rng.integers(0, n, 4 * outliers)
    keep = np.abs(a - b) > 1
    oi, oj = a[keep][:outliers], b[keep][:outliers]
    oR = random_rotations(rng, outliers, d)
    ot = rng.uniform(-10, 10, (outliers, d))
    m = len(i)
    graph = cs.PoseGraph.from_measurements(
        d,
        np.concatenate([i, oi]),
        np.concatenate([j, oj]),
        np.concatenate([Rm, oR]),
        np.concatenate([tm, ot]),
        np.full(m + outliers, 20.0),
        np.full(m + outliers, 10.0),
    )
    return graph, R, t, np.arange(m, m + outliers)


@pytest.mark.parametrize("d", [2, 3])
def test_noiseless_graph_with_outliers_is_recovered_exactly(d):
    rng = np.random.default_rng(3)
    g, R, t, wrong = corrupted_graph(rng, d, 40, 20, 12)
    r = cs.solve(g, robust=True)
    assert isinstance(r, cs.RobustResult)
    assert r.certified, r.summary
    np.testing.assert_array_equal(r.outlier_edges, wrong)
    assert r.num_outliers == len(wrong)
    assert r.inliers.shape == (g.num_measurements,)
    assert not r.inliers[wrong].any() and r.inliers.sum() == g.num_measurements - len(wrong)
    assert set(np.unique(r.weights)) <= {0.0, 1.0}
    assert r.objective < 1e-9  # The inlier problem's optimum is F = 0.
    Rr, tr = in_frame_of_first(r.rotations, r.translations)
    Rt, tt = in_frame_of_first(R, t)
    np.testing.assert_allclose(Rr, Rt, atol=1e-8)
    np.testing.assert_allclose(tr, tt, atol=1e-7)
    edge = r.edges[int(wrong[0])]
    assert not edge.inlier and edge.weight == 0 and edge.cost > r.inlier_threshold
    assert r.inlier_summary.num_measurements == g.num_measurements - len(wrong)


def test_without_outliers_equals_plain_solve():
    g, _, _ = cs.generate_cube(side=4, dimension=3, seed=2)
    plain = cs.solve(g)
    r = cs.solve(g, robust=True, num_threads=1)
    assert r.certified and plain.certified
    assert r.num_outliers == 0 and len(r.outlier_edges) == 0
    assert r.objective == pytest.approx(plain.objective, rel=1e-9)
    Rr, tr = in_frame_of_first(r.rotations, r.translations)
    Rp, tp = in_frame_of_first(plain.rotations, plain.translations)
    np.testing.assert_allclose(Rr, Rp, atol=1e-6)
    np.testing.assert_allclose(tr, tp, atol=1e-6)


def test_options_and_errors():
    rng = np.random.default_rng(5)
    g, _, _, wrong = corrupted_graph(rng, 2, 30, 15, 5)
    r = cs.solve(g, robust=True, known_inliers="none", inlier_threshold=50.0, max_rank=6)
    assert r.inlier_threshold == 50.0
    np.testing.assert_array_equal(r.outlier_edges, wrong)
    with pytest.raises(TypeError, match="no_such_option"):
        cs.solve(g, robust=True, no_such_option=1)
    with pytest.raises(ValueError):
        cs.solve(g, robust=True, known_inliers="some")
    with pytest.raises(ValueError, match="mu_step"):
        cs.solve(g, robust=True, mu_step=1.0)
    with pytest.raises(TypeError):
        cs.solve(g, np.zeros((30, 2, 2)), robust=True)
    o = cs.RobustSolverOptions(inlier_probability=0.99)
    assert o.inlier_probability == 0.99 and o.as_dict()["known_inliers"] is not None


def test_time_limit_is_of_the_whole_solve_and_rank_cap():
    rng = np.random.default_rng(7)
    g, _, _, wrong = corrupted_graph(rng, 3, 40, 20, 12)
    # max_time_s is RobustSolverOptions' (the whole solve), not each solve's.
    r = cs.solve(g, robust=True, max_time_s=1e-4)
    assert r.status == "TIME_LIMIT" and not r.certified, r.summary
    assert r.inliers.shape == (g.num_measurements,)
    r = cs.solve(g, robust=True, max_time_s=1000.0, gnc_max_rank=5)
    assert r.status == "CONVERGED" and r.certified, r.summary
    np.testing.assert_array_equal(r.outlier_edges, wrong)
    assert cs.RobustSolverOptions(gnc_max_rank=5).gnc_max_rank == 5
    with pytest.raises(ValueError, match="max_time_s"):
        cs.solve(g, robust=True, max_time_s=-1.0)


def test_outlier_edges_equal_the_command_line(tmp_path):
    rng = np.random.default_rng(7)
    g, R, t, wrong = corrupted_graph(rng, 3, 30, 15, 6)
    path = tmp_path / "corrupted.g2o"
    cs.write_g2o(path, g, R, t)
    summary = tmp_path / "s.json"
    run = run_tool("solve", path, "--robust", "--json", summary)
    assert run.returncode == 0, run.stdout + run.stderr
    cli = json.loads(summary.read_text())
    r = cs.solve(cs.read_g2o(path), robust=True)
    assert cli["robust"] is True
    assert cli["outlier_edges"] == r.outlier_edges.tolist() == wrong.tolist()
    assert cli["certified"] == r.certified


def test_ctrl_c_stops_a_robust_solve_whose_runs_go_at_once(tmp_path):
    # A 10x10x10 cube with 30% wrong closures: ~2 s of GNC runs, two at once.
    cube, corrupted = tmp_path / "cube.g2o", tmp_path / "corrupted.g2o"
    g, _, _ = cs.generate_cube(side=10, seed=1)
    cs.write_g2o(cube, g)
    made = run_tool("generate", "outliers", cube, "--fraction", 0.3, "--seed", 1,
                    "--output", corrupted)
    assert made.returncode == 0, made.stderr
    g = cs.read_g2o(corrupted)
    start = time.monotonic()
    full = cs.solve(g, robust=True, num_threads=2)
    uninterrupted = time.monotonic() - start
    assert full.concurrent_runs == 2 and uninterrupted > 0.5, full.summary
    main = threading.main_thread().ident
    # At 0.3 s: in the GNC runs here (first solve 0.12 s, GNC runs 2.1 s).
    timer = threading.Timer(0.3, lambda: signal.pthread_kill(main, signal.SIGINT))
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        cs.solve(g, robust=True, num_threads=2)
    elapsed = time.monotonic() - start
    timer.join()
    # Both runs stopped at the interrupt: the calling thread's at its next
    # progress check, the other at its next report (else it would finish).
    assert elapsed < 0.5 * uninterrupted, (elapsed, uninterrupted)
