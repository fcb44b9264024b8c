"""Shared fixtures of the Python tests (run by ctest with the environment set
in python/CMakeLists.txt; runnable by hand with PYTHONPATH=<build>/python)."""

import os
import subprocess

import numpy as np
import pytest

DATA_DIR = os.environ.get("CERES_SESYNC_DATA_DIR", "")
TOOL = os.environ.get("CERES_SESYNC_TOOL", "")
SOURCE_DIR = os.environ.get(
    "CERES_SESYNC_SOURCE_DIR",
    os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
)


def dataset(name):
    """Path of a benchmark dataset; skips the test when it is absent."""
    path = os.path.join(DATA_DIR, name + ".g2o")
    if not DATA_DIR or not os.path.exists(path):
        pytest.skip(f"{path} not found (CERES_SESYNC_DATA_DIR)")
    return path


def run_tool(*args):
    """Runs the ceres_sesync program; skips when it is not built."""
    if not TOOL or not os.path.exists(TOOL):
        pytest.skip("the ceres_sesync program is not built")
    return subprocess.run([TOOL, *map(str, args)], capture_output=True, text=True)


def random_rotations(rng, n, d):
    """n Haar-uniform rotations in SO(d) (QR of Gaussian matrices)."""
    q, r = np.linalg.qr(rng.standard_normal((n, d, d)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1
    return q


def relative_measurements(R, t, i, j):
    """Exact relative rotations R_i^T R_j and translations R_i^T (t_j - t_i)."""
    Rij = np.einsum("kba,kbc->kac", R[i], R[j])
    tij = np.einsum("kba,kb->ka", R[i], t[j] - t[i])
    return Rij, tij


def objective(i, j, Rm, tm, kappa, tau, R, t):
    """Eq. (12) evaluated with numpy, independently of the library."""
    rot = R[j] - R[i] @ Rm
    tra = t[j] - t[i] - np.einsum("kab,kb->ka", R[i], tm)
    return float(np.sum(kappa * np.sum(rot**2, axis=(1, 2))) + np.sum(tau * np.sum(tra**2, axis=1)))


def in_frame_of_first(R, t):
    """The poses expressed in the frame of pose 0 (removes the gauge)."""
    R0, t0 = R[0], t[0]
    return np.einsum("ba,kbc->kac", R0, R), np.einsum("ba,kb->ka", R0, t - t0)
