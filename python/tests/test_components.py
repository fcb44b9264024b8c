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


def _shift_ids(path, offset):
    """The g2o file's lines with every vertex id shifted by offset (SE2
    edges and vertices only)."""
    lines = []
    for line in open(path):
        f = line.split()
        if f[0] == "EDGE_SE2":
            f[1], f[2] = str(int(f[1]) + offset), str(int(f[2]) + offset)
        elif f[0] == "VERTEX_SE2":
            f[1] = str(int(f[1]) + offset)
        else:
            raise AssertionError(f"unexpected line {line!r}")
        lines.append(" ".join(f) + "\n")
    return lines


def test_landmarks_and_priors_stay_with_their_component(tmp_path):
    # A landmark map with GPS priors beside a pose graph: two components;
    # the map is solved with its landmarks and priors in the world frame.
    m = cs.generate_landmarks(num_poses=30, num_landmarks=40, world_size=10, gps_interval=5,
                              start_prior=True, seed=3)[0]
    cube = cs.generate_cube(dimension=2, side=3, seed=4)[0]
    cs.write_g2o(tmp_path / "map.g2o", m)
    cs.write_g2o(tmp_path / "cube.g2o", cube)
    both = tmp_path / "both.g2o"
    both.write_text(open(tmp_path / "map.g2o").read() + "".join(_shift_ids(tmp_path / "cube.g2o", 10**6)))
    with pytest.raises(ValueError, match="disconnected"):
        cs.read_g2o(both)
    g = cs.read_g2o(both, allow_disconnected=True)
    assert g.num_landmarks == m.num_landmarks
    r = cs.solve_components(g)
    assert r.certified, r.summary
    assert len(r.components) == 2
    num_priors = len(m.priors["i"])
    assert r.num_landmarks == m.num_landmarks and r.num_priors == num_priors
    world, own = r.components
    assert world.gauge_vertex_id == -1 and world.num_priors == num_priors
    assert own.gauge_vertex_id == 10**6 and len(own.landmarks) == 0
    np.testing.assert_array_equal(world.landmarks, np.arange(m.num_landmarks))
    alone = cs.solve(cs.read_g2o(tmp_path / "map.g2o"))  # the same text
    assert world.summary.objective == alone.objective  # bit for bit
    np.testing.assert_array_equal(r.landmarks, alone.landmarks)
    np.testing.assert_array_equal(r.translations[: m.num_poses], alone.translations)
    f = cs.evaluate_objective(g, r.rotations, r.translations, r.landmarks)
    assert r.objective == pytest.approx(f, rel=1e-12)
    split = g.split_into_components()
    np.testing.assert_array_equal(split[0].landmarks, world.landmarks)
    np.testing.assert_array_equal(split[0].priors, np.arange(num_priors))
    assert len(split[0].landmark_measurements) == m.landmark_measurements["i"].size
    assert len(split[1].landmark_measurements) == 0
