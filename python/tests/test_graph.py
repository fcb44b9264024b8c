"""PoseGraph from numpy arrays: round trips, validation, exact recovery."""

import numpy as np
import pytest

import ceres_sesync as cs
from conftest import in_frame_of_first, objective, random_rotations, relative_measurements


def random_graph(rng, d, n, extra, kappa=10.0, tau=5.0):
    """A chain plus `extra` random loop closures, with exact measurements of
    random ground-truth poses. Returns (arrays, R, t)."""
    R = random_rotations(rng, n, d)
    t = rng.uniform(-3, 3, (n, d))
    i = np.concatenate([np.arange(n - 1), rng.integers(0, n, extra)])
    j = np.concatenate([np.arange(1, n), rng.integers(0, n, extra)])
    keep = i != j
    i, j = i[keep], j[keep]
    Rm, tm = relative_measurements(R, t, i, j)
    m = len(i)
    k = np.full(m, kappa) * rng.uniform(0.5, 2, m)
    w = np.full(m, tau) * rng.uniform(0.5, 2, m)
    return (d, i, j, Rm, tm, k, w), R, t


@pytest.mark.parametrize("d", [2, 3])
def test_measurement_arrays_round_trip_exactly(d):
    rng = np.random.default_rng(1)
    arrays, R, t = random_graph(rng, d, 12, 8)
    g = cs.PoseGraph.from_measurements(*arrays)
    assert (g.dimension, g.num_poses, g.num_measurements) == (d, 12, len(arrays[1]))
    ms = g.measurements
    assert len(ms) == g.num_measurements
    for name, value in zip(["i", "j", "R", "t", "kappa", "tau"], arrays[1:]):
        got = getattr(ms, name)
        assert got.shape == np.shape(value), name
        np.testing.assert_array_equal(got, value, err_msg=name)
    assert ms.i.dtype == np.int64 and ms.R.dtype == np.float64
    np.testing.assert_array_equal(g.vertex_ids, np.arange(12))
    assert g.fixed_pose is None and g.initial_poses is None
    assert g.index_of_vertex_id == {v: v for v in range(12)}
    # The library's objective is eq. (12): zero at the truth, and equal to a
    # numpy evaluation elsewhere.
    assert cs.evaluate_objective(g, R, t) < 1e-20 * np.sum(arrays[5] + arrays[6]) + 1e-24
    R2 = random_rotations(rng, 12, d)
    t2 = rng.standard_normal((12, d))
    expected = objective(*arrays[1:], R2, t2)
    assert cs.evaluate_objective(g, R2, t2) == pytest.approx(expected, rel=1e-13)


def test_optional_arrays_and_lists():
    rng = np.random.default_rng(2)
    (d, i, j, Rm, tm, k, w), R, t = random_graph(rng, 2, 5, 2)
    ids = np.array([10, 3, 77, 5, 1000000000000])
    g = cs.PoseGraph.from_measurements(
        d, list(i), list(j), Rm.tolist(), tm, k, w, num_poses=6,
        vertex_ids=np.append(ids, 4), initial_rotations=np.concatenate([R, R[:1]]),
        initial_translations=np.concatenate([t, t[:1]]), fixed_pose=2,
        allow_disconnected=True)
    assert g.num_poses == 6  # pose 5 has no measurement
    np.testing.assert_array_equal(g.vertex_ids, np.append(ids, 4))
    assert g.index_of_vertex_id[1000000000000] == 4
    assert g.fixed_pose == 2
    R0, t0 = g.initial_poses
    np.testing.assert_array_equal(R0[:5], R)
    np.testing.assert_array_equal(t0[:5], t)
    np.testing.assert_array_equal(g.connected_components(), [0, 0, 0, 0, 0, 1])


def test_bad_arrays_raise_value_errors_that_name_the_problem():
    rng = np.random.default_rng(3)
    (d, i, j, Rm, tm, k, w), _, _ = random_graph(rng, 3, 6, 3)
    make = cs.PoseGraph.from_measurements

    def error(exception=ValueError, **changes):
        args = dict(d=d, i=i, j=j, R=Rm, t=tm, kappa=k, tau=w)
        options = {key: changes.pop(key) for key in list(changes) if key not in args}
        args.update(changes)
        with pytest.raises(exception) as info:
            make(*args.values(), **options)
        return str(info.value)

    m = len(i)
    assert f"R must have shape ({m}, 3, 3), not ({m}, 2, 2)" in error(R=Rm[:, :2, :2])
    assert "t must have shape" in error(t=tm[:-1])
    assert "kappa must have shape" in error(kappa=k[:, None])
    assert "j must have shape" in error(j=j[:-1])
    assert "must hold integers" in error(TypeError, i=i.astype(float))
    assert "dimension must be 2 or 3" in error(d=4)
    bad = k.copy()
    bad[2] = np.nan
    assert "measurement 2 " in error(kappa=bad) and "kappa and tau" in error(kappa=bad)
    bad = w.copy()
    bad[4] = -1
    assert "measurement 4 " in error(tau=bad)
    bad = Rm.copy()
    bad[1] *= 1.01
    assert "measurement 1 " in error(R=bad) and "SO(d)" in error(R=bad)
    loop = i.copy()
    loop[0] = j[0]
    assert "measurement 0 " in error(i=loop) and "self-loop" in error(i=loop)
    negative = i.copy()
    negative[3] = -1
    assert "out of range" in error(i=negative)
    assert "num_poses is 2" in error(num_poses=2)
    assert "duplicate id 7" in error(vertex_ids=[7, 1, 2, 7, 4, 5])
    assert "go together" in error(initial_rotations=np.zeros((6, 3, 3)))
    assert "fixed_pose" in error(fixed_pose=6)
    # Disconnected: pose 6 has no measurement.
    message = error(num_poses=7)
    assert "disconnected" in message and "allow_disconnected" in message


@pytest.mark.parametrize("d", [2, 3])
def test_noiseless_graph_is_recovered_exactly(d):
    rng = np.random.default_rng(4 + d)
    n = 30
    arrays, R, t = random_graph(rng, d, n, 25)
    g = cs.PoseGraph.from_measurements(*arrays)
    r = cs.solve(g)
    assert r.certified, r.summary
    assert r.status == "CERTIFIED_OPTIMUM"
    scale = np.sum(arrays[5] + arrays[6])
    assert r.objective <= 1e-12 * scale
    assert r.lower_bound <= r.objective
    # Gauge: pose 0 at the identity.
    np.testing.assert_allclose(r.rotations[0], np.eye(d), atol=1e-12)
    np.testing.assert_allclose(r.translations[0], 0, atol=1e-12)
    Rt, tt = in_frame_of_first(R, t)
    np.testing.assert_allclose(r.rotations, Rt, atol=1e-8)
    np.testing.assert_allclose(r.translations, tt, atol=1e-8)
    # Returned rotations are rotations.
    eye = np.broadcast_to(np.eye(d), r.rotations.shape)
    np.testing.assert_allclose(np.transpose(r.rotations, (0, 2, 1)) @ r.rotations, eye, atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(r.rotations), 1, atol=1e-12)


def test_graph_is_immutable():
    g, _, _ = cs.generate_cube(side=2, dimension=2)
    with pytest.raises(AttributeError):
        g.num_poses = 5
    ms = g.measurements
    ms.kappa[:] = -1  # a copy: the graph is unchanged
    assert np.all(g.measurements.kappa > 0)


def test_generated_graphs():
    g, R, t = cs.generate_cube(side=3, dimension=2, seed=7)
    assert (g.dimension, g.num_poses) == (2, 9)
    assert R.shape == (9, 2, 2) and t.shape == (9, 2)
    city, R, t = cs.generate_city(num_poses=300, seed=2)
    assert (city.dimension, city.num_poses) == (2, 300)
    assert city.num_measurements > 299  # odometry plus loop closures
    np.testing.assert_array_equal(t[0], [0, 0])
    assert cs.solve(city).certified
    with pytest.raises(ValueError):
        cs.generate_city(num_poses=1)
    with pytest.raises(TypeError, match="unexpected keyword argument 'side'"):
        cs.generate_city(side=3)
