# SPDX-License-Identifier: MIT
"""Builds the trivcon Python package: CMake compiles the extension trivcon._core (python/src/module.cpp)
against the repository's static library (CMakeLists.txt with -DTRIVCON_PYTHON=ON); setuptools packages it
with python/trivcon/. Metadata is in pyproject.toml. Install, offline on Debian 12 (docs/tutorials/python.md):

    /usr/bin/python3 -m venv --system-site-packages venv && venv/bin/pip install --no-build-isolation .

A wheel (python/tests/test_wheel.py builds, installs and uses one; CHANGELOG.md, "Packages"):

    /usr/bin/python3 -m pip wheel . --no-build-isolation --no-deps -w dist

The version is CMakeLists.txt's project() version (version() below), the one source of every version.

Environment:
  TRIVCON_CMAKE_BUILD_DIR  the CMake build folder (default: build/python in the checkout, kept between
                           installs so that a re-install compiles only what changed). An existing build folder
                           of the repository (e.g. build) is reused as it is configured, with TRIVCON_PYTHON
                           switched on: only the module is compiled.
  TRIVCON_BUILD_JOBS       parallel compile jobs (default: the number of cores)
  CMAKE_ARGS               extra arguments for CMake's configure step
"""

import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        match = re.search(r"project\(trivcon VERSION ([0-9]+\.[0-9]+\.[0-9]+)", f.read())
    if not match:
        sys.exit("setup.py: CMakeLists.txt has no 'project(trivcon VERSION MAJOR.MINOR.PATCH' line to take the version from")
    return match.group(1)


class CMakeBuild(build_ext):
    """build_ext that configures and builds the CMake target trivcon_python, then copies the module."""

    def build_extension(self, ext):
        given = os.environ.get("TRIVCON_CMAKE_BUILD_DIR")
        build_dir = os.path.abspath(given or os.path.join(ROOT, "build", "python"))
        args = ["-DTRIVCON_PYTHON=ON", f"-DPython_EXECUTABLE={sys.executable}"]
        try:
            import pybind11

            args.append(f"-Dpybind11_DIR={pybind11.get_cmake_dir()}")
        except ImportError:  # CMake then looks for pybind11-dev's config itself
            pass
        if not given:  # our own folder: the module only, Release, ccache when there is one
            # The module needs neither the editor's server nor its page (node, cpp-httplib).
            args += ["-DCMAKE_BUILD_TYPE=Release", "-DTRIVCON_BUILD_TESTS=OFF", "-DTRIVCON_BUILD_BENCH=OFF", "-DTRIVCON_EDITOR=OFF"]
            if shutil.which("ccache"):
                args.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        args += shlex.split(os.environ.get("CMAKE_ARGS", ""))
        subprocess.run(["cmake", "-S", ROOT, "-B", build_dir, *args], check=True)
        jobs = os.environ.get("TRIVCON_BUILD_JOBS") or str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", build_dir, "--target", "trivcon_python", "-j", jobs], check=True)
        built = os.path.join(build_dir, "python", "trivcon", "_core" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not os.path.exists(built):
            sys.exit(f"setup.py: the build did not produce {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)


setup(
    version=version(),
    ext_modules=[Extension("trivcon._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
)
