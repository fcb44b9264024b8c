"""solve_components(): a disconnected graph solved per connected component."""

import numpy as np
import pytest

import ceres_sesync as cs


def merged(parts):
    """The graphs `parts` as one disconnected graph (poses of part p follow
    those of part p - 1; vertex ids 1000 p + k)."""
    arrays = {name: [] for name in ["i", "j", "R", "t", "kappa", "tau"]}
    ids, offset = [], 0
    for p, g in enumerate(parts):
        ms = g.measurements
        arrays["i"].append(ms.i + offset)
        arrays["j"].append(ms.j + offset)
        for name in ["R", "t", "kappa", "tau"]:
            arrays[name].append(getattr(ms, name))
        ids.extend(1000 * p + np.arange(g.num_poses))
        offset += g.num_poses
    d = parts[0].dimension
    joined = [np.concatenate(arrays[name]) for name in ["i", "j", "R", "t", "kappa", "tau"]]
    return cs.PoseGraph.from_measurements(d, *joined, vertex_ids=ids, allow_disconnected=True)


@pytest.mark.parametrize("d", [2, 3])
def test_each_component_is_solved_as_its_own_graph(d):
    parts = [cs.generate_cube(dimension=d, side=s, seed=s)[0] for s in (3, 2, 4)]
    g = merged(parts)
    np.testing.assert_array_equal(np.unique(g.connected_components()), [0, 1, 2])
    with pytest.raises(ValueError, match="disconnected"):
        cs.solve(g)
    r = cs.solve_components(g)
    assert r.certified and r.status == "CERTIFIED_OPTIMUM", r.summary
    assert len(r.components) == 3
    assert r.rotations.shape == (g.num_poses, d, d)
    offset = 0
    for p, (part, c) in enumerate(zip(parts, r.components)):
        alone = cs.solve(part)
        n = part.num_poses
        np.testing.assert_array_equal(c.poses, offset + np.arange(n))
        assert c.gauge_vertex_id == 1000 * p
        assert c.num_measurements == part.num_measurements
        assert c.summary.objective == alone.objective  # bit for bit
        np.testing.assert_array_equal(r.rotations[offset : offset + n], alone.rotations)
        np.testing.assert_array_equal(r.translations[offset : offset + n], alone.translations)
        np.testing.assert_allclose(r.rotations[offset], np.eye(d), atol=1e-12)  # own gauge
        offset += n
    total = sum(c.summary.objective for c in r.components)
    assert r.objective == pytest.approx(total, rel=1e-15)
    bound = sum(c.summary.lower_bound for c in r.components)
    assert r.lower_bound == pytest.approx(bound, rel=1e-15)
    f = cs.evaluate_objective(g, r.rotations, r.translations)
    assert r.objective == pytest.approx(f, rel=1e-12)
    assert "Connected components" in r.summary
    split = g.split_into_components()
    assert [len(c.poses) for c in split] == [p.num_poses for p in parts]
    for part, c in zip(parts, split):
        np.testing.assert_array_equal(c.graph.measurements.R, part.measurements.R)
        global_i = g.measurements.i[c.measurements]
        np.testing.assert_array_equal(global_i, c.poses[c.graph.measurements.i])
    assert r.as_dict()["components"][1]["summary"]["status"] == "CERTIFIED_OPTIMUM"


def test_progress_names_the_component():
    g = merged([cs.generate_cube(dimension=2, side=3, seed=s)[0] for s in (1, 2)])
    seen = set()
    cs.solve_components(g, progress=lambda p: seen.add((p.component, p.num_components)))
    assert seen == {(0, 2), (1, 2)}
