# SPDX-License-Identifier: MIT
"""The wheel: `pip wheel` of the checkout (offline, as CHANGELOG.md says), installed into a fresh virtual
environment of Debian's python3 and used there, away from the checkout.

It reuses the C++ build folder named by TRIVCON_CMAKE_BUILD_DIR (scripts/python.sh sets it), so that only the
module's packaging runs; without it the test is skipped, since a wheel from scratch compiles the whole library."""

import os
import subprocess
import sys
import zipfile

import pytest

from conftest import REPO

SYSTEM_PYTHON = "/usr/bin/python3"


def run(*cmd, **kw):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    assert p.returncode == 0, f"{' '.join(map(str, cmd))} exited {p.returncode}:\n{p.stdout}\n{p.stderr}"
    return p.stdout


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    build_dir = os.environ.get("TRIVCON_CMAKE_BUILD_DIR")
    if not build_dir:
        pytest.skip("set TRIVCON_CMAKE_BUILD_DIR to a configured build folder to reuse (scripts/python.sh does)")
    if not os.access(SYSTEM_PYTHON, os.X_OK):
        pytest.skip(f"no {SYSTEM_PYTHON} (Debian's python3, with python3-pip, -setuptools, -wheel, -venv)")
    out = tmp_path_factory.mktemp("wheel")
    env = dict(os.environ, TRIVCON_CMAKE_BUILD_DIR=os.path.abspath(os.path.join(REPO, build_dir)))
    # This interpreter (scripts/python.sh's venv, on Debian's python3) builds it, as it installed the module: the
    # build folder's CMake cache then keeps its Python_EXECUTABLE and nothing is compiled again.
    run(sys.executable, "-m", "pip", "wheel", REPO, "--no-build-isolation", "--no-deps", "--no-cache-dir", "-q",
        "-w", str(out), env=env, cwd=REPO)
    wheels = [f for f in os.listdir(out) if f.endswith(".whl")]
    assert len(wheels) == 1, wheels
    return out / wheels[0]


def program_version(cli):
    """The number of `trivcon --version` ('trivcon X.Y.Z')."""
    words = cli("--version").stdout.split()
    assert len(words) == 2 and words[0] == "trivcon", words
    return words[1]


def test_wheel_name_and_contents(wheel, cli):
    version = program_version(cli)
    tag = f"cp{sys.version_info.major}{sys.version_info.minor}"
    assert wheel.name.startswith(f"trivcon-{version}-{tag}-{tag}-linux_"), wheel.name
    names = zipfile.ZipFile(wheel).namelist()
    assert any(n.startswith("trivcon/_core.") and n.endswith(".so") for n in names), names
    for name in ("trivcon/__init__.py", "trivcon/batch.py", "trivcon/py.typed", "trivcon/__init__.pyi"):
        assert name in names
    dist_info = f"trivcon-{version}.dist-info"
    for name in ("METADATA", "LICENSE", "THIRD_PARTY.md"):
        assert f"{dist_info}/{name}" in names, names
    metadata = zipfile.ZipFile(wheel).read(f"{dist_info}/METADATA").decode()
    assert f"Version: {version}\n" in metadata
    assert "License: MIT" in metadata
    assert not [n for n in names if "/tests/" in n or n.startswith("tests/")], "tests in the wheel"


def test_installs_into_a_fresh_venv_and_solves(wheel, cli, tmp_path):
    venv = tmp_path / "venv"
    run(SYSTEM_PYTHON, "-m", "venv", "--system-site-packages", str(venv))
    run(str(venv / "bin" / "pip"), "install", "--no-index", "--no-deps", "-q", str(wheel))
    # Run from an empty folder, so that nothing of the checkout (python/) can be imported instead.
    script = (
        "import trivcon, numpy as np\n"
        "V, F = trivcon.make_cube_sphere(6)\n"
        "valence = np.bincount(F.ravel(), minlength=len(V))\n"
        "corners = [int(v) for v in np.flatnonzero(valence == 3)]\n"
        "r = trivcon.FieldDesigner(V, F).solve(N=4, singularities={v: '1/4' for v in corners})\n"
        "print(trivcon.__version__, trivcon.__file__, len(corners), r.verified, r.field_exact)\n"
    )
    workdir = tmp_path / "elsewhere"
    workdir.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    version, path, corners, verified, exact = run(str(venv / "bin" / "python"), "-c", script, cwd=workdir, env=env).split()
    assert version == program_version(cli)
    assert path.startswith(str(venv)), path
    assert (corners, verified, exact) == ("8", "True", "True")
