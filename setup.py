"""`pip install .` for the Python package ceres_sesync (python/), offline with
Debian's pip and setuptools: the extension is built by this project's CMake
(library + python/ only, Release), nothing is downloaded.

    python3 -m venv --system-site-packages venv   # numpy from python3-numpy
    venv/bin/pip install .

Debian's python3 is "externally managed" (PEP 668): plain `pip install .`
into it is refused; use a venv as above (or `pip install --user
--break-system-packages .`). There is deliberately no pyproject.toml: with
one, pip would build in an isolated environment and try to download
setuptools. CMAKE_BUILD_PARALLEL_LEVEL sets the build's parallelism
(default 2), CMAKE_CXX_COMPILER_LAUNCHER=ccache is honoured.
"""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(ceres_sesync VERSION ([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = Path(self.build_temp).resolve() / "cmake"
        configure = [
            "cmake",
            "-S",
            str(ROOT),
            "-B",
            str(build),
            "-DCMAKE_BUILD_TYPE=Release",
            f"-DPython3_EXECUTABLE={sys.executable}",
        ]
        for part in ["TESTS", "TOOLS", "EXAMPLES", "BENCH"]:
            configure.append(f"-DCERES_SESYNC_BUILD_{part}=OFF")
        subprocess.run(configure, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        subprocess.run(
            ["cmake", "--build", str(build), "--target", "_ceres_sesync", "-j", jobs], check=True
        )
        built = list((build / "python" / "ceres_sesync").glob("_ceres_sesync*.so"))
        if len(built) != 1:
            raise RuntimeError(f"expected one extension module in {build}, found {built}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[0], target)


setup(
    name="ceres_sesync",
    version=version(),
    description="SE-Sync certifiable pose-graph optimization for Ceres users, on numpy arrays",
    packages=["ceres_sesync"],
    package_dir={"ceres_sesync": "python/ceres_sesync"},
    ext_modules=[Extension("ceres_sesync._ceres_sesync", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # Not build/: that is where scripts/build.sh keeps the CMake build.
    options={"build": {"build_base": "build-pip"}},
    install_requires=["numpy"],
    python_requires=">=3.9",
    zip_safe=False,
)
