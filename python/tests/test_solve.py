"""solve(): equal to the C++ API (the ceres_sesync program) on the datasets,
options by keyword, progress and stop callbacks, the GIL released."""

import json
import signal
import threading
import time

import numpy as np
import pytest

import ceres_sesync as cs
from conftest import dataset, objective, run_tool

DATASETS = ["CSAIL", "intel", "kitti_00", "tinyGrid3D", "smallGrid3D", "sphere2500"]


@pytest.mark.parametrize("name", DATASETS)
def test_results_equal_the_cpp_api(tmp_path, name):
    path = dataset(name)
    out, summary = tmp_path / "poses.g2o", tmp_path / "summary.json"
    run = run_tool("solve", path, "--output", out, "--json", summary)
    assert run.returncode == 0, run.stdout + run.stderr
    cpp = json.loads(summary.read_text())

    g = cs.read_g2o(path)
    r = cs.solve(g)
    assert r.status == cpp["status"] == "CERTIFIED_OPTIMUM"
    assert r.certified
    # The same library on the same data: the same numbers, bit for bit.
    for key, value in [
        ("objective", r.objective),
        ("lower_bound", r.lower_bound),
        ("sdp_value", r.sdp_value),
        ("relative_suboptimality_bound", r.relative_suboptimality_bound),
        ("eta", r.eta),
        ("rank", r.final_rank),
        ("iterations", r.iterations),
        ("hessian_vector_products", r.hessian_vector_products),
    ]:
        assert value == cpp[key], key
    assert r.relaxation_exact == cpp["relaxation_exact"]
    assert r.proof_precision == cpp["proof"]["precision"]
    assert r.factorizations == cpp["proof"]["factorizations"]
    assert r.extended_factorizations == cpp["proof"]["extended_factorizations"]
    # The poses the program wrote (shortest round-trip decimals; rotations
    # through angles / quaternions).
    R, t = cs.read_g2o_poses(out, g)
    np.testing.assert_allclose(r.rotations, R, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(r.translations, t)
    # The arrays are laid out as documented: eq. (12) evaluated with numpy on
    # them gives the reported objective.
    ms = g.measurements
    f = objective(ms.i, ms.j, ms.R, ms.t, ms.kappa, ms.tau, r.rotations, r.translations)
    assert f == pytest.approx(r.objective, rel=1e-12)
    # Every summary field is there.
    assert len(r.levels) >= 1 and r.levels[-1].certified
    assert r.levels[-1].rank == r.final_rank
    assert r.total_time_s >= r.optimization_time_s > 0
    assert "Status                             CERTIFIED_OPTIMUM" in r.summary
    assert r.summary == r.full_report and r.brief_report.startswith("SE-Sync: CERTIFIED_OPTIMUM")


def test_options_by_keyword():
    g, _, _ = cs.generate_cube(side=4, seed=3)
    r = cs.solve(g, initial_rank=4, max_rank=4, num_threads=1, initialization="random", seed=5)
    assert r.levels[0].rank == 4 and r.final_rank == 4
    assert r.certified
    s = cs.solve(g, initialization=cs.Initialization.random, seed=5, initial_rank=4, max_rank=4)
    assert s.objective == r.objective  # the same seed: the same solve
    assert cs.solve(g, preconditioner="block_jacobi").certified
    # The default resolves by the exact factor's cost: exact on this cube,
    # block-Jacobi on a city (SolverSummary::preconditioner says which).
    assert cs.SolverOptions().preconditioner == cs.Preconditioner.automatic
    assert cs.solve(g).preconditioner == "exact (Q + eps I)^-1"
    city = cs.generate_city(num_poses=1000, seed=1)[0]
    auto = cs.solve(city, newton_at_rank_d=False)  # Else Newton at rank d.
    exact = cs.solve(city, preconditioner="regularized_q", newton_at_rank_d=False)
    assert auto.certified and auto.preconditioner == "block-Jacobi"
    assert exact.certified and exact.preconditioner == "exact (Q + eps I)^-1"
    assert abs(auto.objective - exact.objective) <= 1e-9 * exact.objective
    # By default a 2D city this size runs its first level on the Newton
    # system from the start (SolverOptions.newton_at_rank_d), nothing else.
    newton = cs.solve(city)
    assert newton.certified and newton.preconditioner.startswith("Newton at rank d (")
    assert newton.hessian_vector_products < auto.hessian_vector_products
    assert abs(newton.objective - auto.objective) <= 1e-9 * auto.objective
    double = cs.solve(g, proof_arithmetic="double")
    assert double.certified and double.proof_precision == "double"
    assert double.extended_factorizations == 0
    extended = cs.solve(g, proof_arithmetic=cs.ProofArithmetic.double_double)
    assert extended.certified and extended.proof_precision == "double-double"
    assert extended.extended_factorizations >= 1
    options = cs.SolverOptions(max_rank=7, local_solver="trust_region")
    assert options.max_rank == 7 and options.local_solver == cs.LocalSolver.trust_region
    assert options.as_dict()["max_rank"] == 7
    options.initialization = "vertices"
    assert options.initialization == cs.Initialization.vertices
    # The Newton switch at rank d (on by default); the cube's first solves
    # are short, so it does not switch and the results are the same.
    assert cs.SolverOptions().newton_at_rank_d
    assert not cs.SolverOptions(newton_at_rank_d=False).newton_at_rank_d
    off = cs.solve(g, newton_at_rank_d=False)
    assert off.certified and off.objective == cs.solve(g).objective
    assert "Newton" not in off.preconditioner


def test_option_errors():
    g, _, _ = cs.generate_cube(side=2, seed=0)
    with pytest.raises(TypeError, match=r"^solve\(\) got an unexpected keyword argument 'robustness'$"):
        cs.solve(g, robustness=True)
    with pytest.raises(TypeError, match="max_rank must be int, not str"):
        cs.solve(g, max_rank="10")
    choices = "initialization must be one of 'chordal', 'random', 'vertices', not 'chordial'"
    with pytest.raises(ValueError, match=choices):
        cs.solve(g, initialization="chordial")
    with pytest.raises(TypeError, match="progress must be a callable or None, not int"):
        cs.solve(g, progress=3)
    with pytest.raises(TypeError, match="unexpected keyword argument 'max_rnk'"):
        cs.SolverOptions(max_rnk=3)
    # Invalid combinations are the library's input errors.
    with pytest.raises(ValueError, match="initial_rank must be >= d \\+ 1"):
        cs.solve(g, initial_rank=2)
    with pytest.raises(ValueError, match="no initial poses"):
        cs.solve(g, initialization="vertices")


def test_initial_rotations():
    g, R, t = cs.generate_cube(side=3, seed=4)
    r = cs.solve(g, initial_rotations=R)
    assert r.certified
    assert r.objective == pytest.approx(cs.solve(g).objective, rel=1e-9)
    with pytest.raises(ValueError, match="rotations must have shape"):
        cs.solve(g, initial_rotations=R[1:])


def test_progress_and_callback():
    g, _, _ = cs.generate_cube(side=4, seed=6)
    reports = []
    r = cs.solve(g, progress=lambda p: reports.append((p.stage, p.rank, p.iteration, p.objective)))
    stages = [s for s, *_ in reports]
    assert stages[:2] == ["data", "initialize"]
    assert stages[-2:] == ["round", "done"]
    assert "optimize" in stages and "verify" in stages
    assert reports[-1][3] == r.objective
    verify = [x for x in reports if x[0] == "verify"]
    assert [x[3] for x in verify] == [level.sdp_value for level in r.levels]

    calls = []

    def stop_after_two(rank, iteration, f, gradient_norm, radius):
        calls.append(iteration)
        return iteration < 2

    r = cs.solve(g, callback=stop_after_two, max_rank=5)
    assert r.levels[0].termination == "stopped by callback"
    assert r.levels[0].iterations == 2

    def fails(p):
        raise RuntimeError("from the callback")

    with pytest.raises(RuntimeError, match="from the callback"):
        cs.solve(g, progress=fails)


def busy_graph(side, kappa):
    g, _, _ = cs.generate_cube(side=side, kappa=kappa, tau=20, seed=1, loop_closure_probability=0.3)
    return g


def test_solve_releases_the_gil():
    g = busy_graph(12, 6)  # ~0.2 s on one core
    stamps, done = [], threading.Event()
    window = {}

    def worker():
        window["start"] = time.monotonic()
        window["result"] = cs.solve(g, num_threads=1)
        window["end"] = time.monotonic()
        done.set()

    thread = threading.Thread(target=worker)
    thread.start()
    while not done.is_set():  # pure Python: runs only while the GIL is free
        stamps.append(time.monotonic())
    thread.join()
    start, end = window["start"], window["end"]
    assert end - start > 0.05, "the solve is too short to tell"
    middle = [s for s in stamps if start + 0.3 * (end - start) < s < end - 0.3 * (end - start)]
    assert middle, "no Python ran while the solver worked: the GIL was held"
    assert window["result"].objective > 0


def test_ctrl_c_stops_a_solve():
    g = busy_graph(13, 3)  # ~0.9 s on one core
    start = time.monotonic()
    cs.solve(g, num_threads=1)
    uninterrupted = time.monotonic() - start
    main = threading.main_thread().ident
    timer = threading.Timer(0.05, lambda: signal.pthread_kill(main, signal.SIGINT))
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        cs.solve(g, num_threads=1)
    elapsed = time.monotonic() - start
    timer.join()
    # Raised from inside the solve, at its next progress check (an interrupt
    # raised only once the solve returned would come after all of it).
    assert elapsed < 0.5 * uninterrupted, (elapsed, uninterrupted)
