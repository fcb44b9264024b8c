"""g2o / TUM reading and writing: round trips through files, error paths with
file:line."""

import os

import numpy as np
import pytest

import ceres_sesync as cs
from conftest import dataset


def write(path, text):
    path.write_text(text)
    return str(path)


GOOD = (
    "VERTEX_SE2 3 0 0 0\n"
    "VERTEX_SE2 7 1 0 0\n"
    "VERTEX_SE2 9 1 1 1.5\n"
    "EDGE_SE2 3 7 1 0 0 5 0 0 5 0 10\n"
    "EDGE_SE2 7 9 0 1 1.5 5 0 0 5 0 30\n"
    "EDGE_SE2 9 3 -1 1 -1.5 5 0 0 5 0 20\n"
    "FIX 7\n"
)


def test_read_a_small_file(tmp_path):
    path = write(tmp_path / "good.g2o", GOOD)
    g, summary = cs.read_g2o(path, return_summary=True)
    assert (g.dimension, g.num_poses, g.num_measurements) == (2, 3, 3)
    np.testing.assert_array_equal(g.vertex_ids, [3, 7, 9])
    assert g.fixed_pose == 1
    ms = g.measurements
    np.testing.assert_array_equal(ms.i, [0, 1, 2])
    np.testing.assert_array_equal(ms.j, [1, 2, 0])
    np.testing.assert_array_equal(ms.kappa, [10, 30, 20])
    np.testing.assert_allclose(ms.tau, 5, rtol=1e-15)  # 2 / tr((5 I)^-1)
    c, s = np.cos(1.5), np.sin(1.5)
    np.testing.assert_allclose(ms.R[1], [[c, -s], [s, c]], atol=1e-15)
    np.testing.assert_array_equal(ms.t[2], [-1, 1])
    R0, t0 = g.initial_poses
    np.testing.assert_allclose(R0[2], [[c, -s], [s, c]], atol=1e-15)
    np.testing.assert_array_equal(t0[2], [1, 1])
    assert summary.num_edges == 3 and summary.has_fix
    # A pathlib.Path works too.
    assert cs.read_g2o(tmp_path / "good.g2o").num_poses == 3


def test_bad_input_names_file_and_line(tmp_path):
    text = "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n\nEDGE_SE2 1 2 1 0 0 1 0 0 1 0 oops\n"
    path = write(tmp_path / "bad.g2o", text)
    with pytest.raises(ValueError, match=f"^{path}:3: "):
        cs.read_g2o(path)
    path = write(tmp_path / "nan.g2o", "EDGE_SE2 0 1 nan 0 0 1 0 0 1 0 1\n")
    with pytest.raises(ValueError, match=f"^{path}:1: "):
        cs.read_g2o(path)
    path = write(tmp_path / "bearing.g2o", "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_BEARING_SE2_XY 0 5 0.5 1\n")
    with pytest.raises(ValueError, match=f"^{path}:2: unsupported tag 'EDGE_BEARING_SE2_XY'"):
        cs.read_g2o(path)
    g, summary = cs.read_g2o(path, skip_unsupported_tags=True, return_summary=True)
    assert g.num_poses == 2 and summary.num_skipped_lines == 1
    assert summary.skipped_tags == {"EDGE_BEARING_SE2_XY": 1}
    with pytest.raises(FileNotFoundError):
        cs.read_g2o(tmp_path / "missing.g2o")
    with pytest.raises(IsADirectoryError):
        cs.read_g2o(tmp_path)
    with pytest.raises(TypeError, match="unexpected keyword argument 'skip'"):
        cs.read_g2o(path, skip=True)


def test_disconnected_file_only_when_allowed(tmp_path):
    text = "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 5 6 1 0 0 1 0 0 1 0 1\n"
    path = write(tmp_path / "two.g2o", text)
    with pytest.raises(ValueError, match=f"^{path}:2: measurement graph is disconnected"):
        cs.read_g2o(path)
    g = cs.read_g2o(path, allow_disconnected=True)
    np.testing.assert_array_equal(g.connected_components(), [0, 0, 1, 1])


@pytest.mark.parametrize("d", [2, 3])
def test_write_and_read_back(tmp_path, d):
    g, R, t = cs.generate_cube(dimension=d, side=3, seed=d)
    path = str(tmp_path / "graph.g2o")
    cs.write_g2o(path, g, R, t)
    h = cs.read_g2o(path)
    assert (h.dimension, h.num_poses, h.num_measurements) == (d, g.num_poses, g.num_measurements)
    np.testing.assert_array_equal(h.vertex_ids, g.vertex_ids)
    a, b = g.measurements, h.measurements
    np.testing.assert_array_equal(a.i, b.i)
    np.testing.assert_array_equal(a.j, b.j)
    np.testing.assert_array_equal(a.t, b.t)  # shortest round-trip decimals
    np.testing.assert_allclose(a.R, b.R, atol=1e-15)  # through angle / quaternion
    np.testing.assert_allclose(a.kappa, b.kappa, rtol=1e-15)
    np.testing.assert_allclose(a.tau, b.tau, rtol=1e-15)
    R2, t2 = h.initial_poses
    np.testing.assert_allclose(R2, R, atol=1e-15)
    np.testing.assert_array_equal(t2, t)
    # Only the poses, matched by id.
    poses = str(tmp_path / "poses.g2o")
    cs.write_g2o_poses(poses, g, R, t)
    R3, t3 = cs.read_g2o_poses(poses, g)
    np.testing.assert_allclose(R3, R, atol=1e-15)
    np.testing.assert_array_equal(t3, t)
    # The graph without poses has no VERTEX lines.
    cs.write_g2o(path, g)
    assert cs.read_g2o(path).initial_poses is None


def test_tum_file(tmp_path):
    g, R, t = cs.generate_cube(dimension=3, side=2, seed=1)
    path = str(tmp_path / "trajectory.tum")
    cs.write_tum(path, g, R, t)
    rows = np.loadtxt(path)
    assert rows.shape == (g.num_poses, 8)
    np.testing.assert_array_equal(rows[:, 0], g.vertex_ids)
    np.testing.assert_allclose(rows[:, 1:4], t, atol=1e-15)
    # Quaternion (x, y, z, w) of R: R = I + 2 w [v]x + 2 [v]x^2.
    x, y, z, w = rows[:, 4:].T
    K = np.zeros((len(x), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -z, y, -x
    K -= np.transpose(K, (0, 2, 1))
    np.testing.assert_allclose(np.eye(3) + 2 * w[:, None, None] * K + 2 * K @ K, R, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(rows[:, 4:], axis=1), 1, atol=1e-12)


def test_write_errors(tmp_path):
    g, R, t = cs.generate_cube(dimension=2, side=2)
    with pytest.raises(OSError):
        cs.write_g2o(tmp_path / "no_dir" / "x.g2o", g, R, t)
    assert not os.path.exists(tmp_path / "no_dir")
    with pytest.raises(ValueError, match=r"rotations must have shape \(4, 2, 2\)"):
        cs.write_g2o(tmp_path / "x.g2o", g, R[:3], t)
    bad = t.copy()
    bad[1, 0] = np.inf
    with pytest.raises(ValueError, match="translations: not finite"):
        cs.write_tum(tmp_path / "x.tum", g, R, bad)
    assert not os.path.exists(tmp_path / "x.tum")
    poses = write(tmp_path / "poses.g2o", "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 99 0 0 0\n")
    with pytest.raises(ValueError, match=f"^{poses}:2: "):
        cs.read_g2o_poses(poses, g)


def test_dataset_reads_like_the_command_line():
    path = dataset("CSAIL")
    g = cs.read_g2o(path)
    assert (g.dimension, g.num_poses, g.num_measurements) == (2, 1045, 1172)
