"""`cmake --install` puts a self-contained package where python3 finds it."""

import os
import subprocess
import sys

import pytest

BINARY_DIR = os.environ.get("CERES_SESYNC_BINARY_DIR", "")
CMAKE = os.environ.get("CERES_SESYNC_CMAKE", "cmake")
INSTALL_DIR = os.environ.get("CERES_SESYNC_PYTHON_INSTALL_DIR", "")
PREFIX = os.environ.get("CERES_SESYNC_INSTALL_PREFIX", "")

pytestmark = pytest.mark.skipif(
    not BINARY_DIR or not INSTALL_DIR, reason="run by ctest (needs the build directory)"
)

SCRIPT = """
import ceres_sesync as cs
g, R, t = cs.generate_cube(side=3, seed=1)
r = cs.solve(g)
print(cs.__file__)
print(r.status)
"""


def test_installed_package_imports_and_solves(tmp_path):
    prefix = tmp_path / "prefix"
    run = subprocess.run(
        [CMAKE, "--install", BINARY_DIR, "--prefix", str(prefix), "--component", "python"],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    package = prefix / INSTALL_DIR / "ceres_sesync"
    files = sorted(os.listdir(package))
    assert "__init__.py" in files
    assert any(f.startswith("_ceres_sesync.") and f.endswith(".so") for f in files), files
    # Import from the install only (not from the build tree), from elsewhere.
    env = dict(os.environ, PYTHONPATH=str(prefix / INSTALL_DIR))
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, cwd=tmp_path
    )
    assert run.returncode == 0, run.stdout + run.stderr
    file, status = run.stdout.split()
    assert file == str(package / "__init__.py")
    assert status == "CERTIFIED_OPTIMUM"


def test_default_install_dir_is_on_the_interpreters_path():
    if PREFIX not in ("/usr/local", "/usr"):
        pytest.skip(f"install prefix {PREFIX} is not a system prefix")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    script = "import sys; print('\\n'.join(sys.path))"
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env)
    assert os.path.join(PREFIX, INSTALL_DIR) in run.stdout.split("\n"), run.stdout
