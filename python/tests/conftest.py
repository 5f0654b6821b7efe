# SPDX-License-Identifier: MIT
"""Shared fixtures: meshes built in code, the CLI binary, the shared real meshes (skipped when absent)."""

import os
import subprocess

import numpy as np
import pytest

import reference
import trivcon

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SHARED_MESHES = os.path.join(REPO, "..", "shared", "data", "meshes")


def cli_path():
    return os.environ.get("TRIVCON_CLI") or os.path.join(REPO, "build", "trivcon")


@pytest.fixture(scope="session")
def cli():
    """A function running the trivcon program: cli(args...) -> CompletedProcess (text)."""
    path = cli_path()
    if not os.access(path, os.X_OK):
        pytest.skip(f"the trivcon program is not built at {path} (set TRIVCON_CLI)")

    def run(*args, check=True):
        p = subprocess.run([path, *map(str, args)], capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"trivcon {' '.join(map(str, args))} exited {p.returncode}: {p.stderr}")
        return p

    return run


@pytest.fixture(scope="session")
def shared_meshes():
    if not os.path.isdir(SHARED_MESHES):
        pytest.skip(f"the shared meshes are not at {SHARED_MESHES}")
    return SHARED_MESHES


@pytest.fixture(scope="session")
def cube():
    """A cube-like sphere, its 8 corners (the vertices of valence 3) and a FieldDesigner."""
    V, F = trivcon.make_cube_sphere(8)
    corners = [int(v) for v in np.flatnonzero(reference.valence(F, len(V)) == 3)]
    assert len(corners) == 8
    return V, F, corners, trivcon.FieldDesigner(V, F)


@pytest.fixture(scope="session")
def torus():
    V, F = trivcon.make_torus(24, 12)
    return V, F, trivcon.FieldDesigner(V, F)


@pytest.fixture(scope="session")
def disk():
    V, F = trivcon.make_disk(8, 8)
    return V, F, trivcon.FieldDesigner(V, F)


@pytest.fixture(scope="session")
def annulus():
    V, F = trivcon.make_annulus(6, 32)
    return V, F, trivcon.FieldDesigner(V, F)
