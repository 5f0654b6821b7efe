# SPDX-License-Identifier: MIT
"""Real meshes from ../shared/data/meshes (skipped with a message when the folder is absent)."""

import os

import numpy as np
import pytest

import reference
import trivcon
from test_cli import agree
from test_solve import check_result

MESHES = ["spot.obj", "torus.obj", "half-torus.obj", "circle.obj", "cheese.off"]


@pytest.mark.parametrize("name", MESHES)
def test_auto_then_edits(shared_meshes, name):
    V, F = trivcon.read_mesh(os.path.join(shared_meshes, name))
    d = trivcon.FieldDesigner(V, F)
    a = d.auto_singularities(N=4, cancel=2)
    if not len(d.boundary_loops):  # closed: Gauss-Bonnet
        assert sum(a.singularities.values()) == d.euler_characteristic
    r = d.solve(N=4, singularities=a.singularities)
    check_result(V, d, r, a.singularities)
    # Edit: move one singularity to a neighbouring free interior vertex, and re-solve.
    if a.singularities:
        v = min(a.singularities)
        free = set(np.flatnonzero(reference.Mesh(V, d.F).interior_vertex).tolist()) - set(a.singularities)
        ring = [int(w) for w in d.edges[(d.edges == v).any(axis=1)].ravel() if w != v and w in free]
        if ring:
            moved = dict(a.singularities)
            moved[ring[0]] = moved.pop(v)
            check_result(V, d, d.solve(N=4, singularities=moved), moved)


def test_errors_on_real_meshes(shared_meshes, cli):
    for name in ("mobius.obj", "hourglass_ico.obj"):
        path = os.path.join(shared_meshes, name)
        V, F = trivcon.read_mesh(path)
        with pytest.raises(trivcon.Error) as e:
            trivcon.FieldDesigner(V, F, repair=False)
        p = cli("info", "--no-repair", path, check=False)
        assert p.returncode == 1 and p.stderr.strip() == f"trivcon: error: {e.value}"


def test_spot_agrees_with_the_program(shared_meshes, cli, tmp_path):
    path = os.path.join(shared_meshes, "spot.obj")
    d = trivcon.FieldDesigner(*trivcon.read_mesh(path))
    r = d.solve(N=1, singularities={1453: 1, 849: 1})  # the picture in docs/getting-started.md
    agree(cli, tmp_path, path, 1, ["--sing", "1453:1", "--sing", "849:1"], r)
