# SPDX-License-Identifier: MIT
"""Result.parametrize: the seamless integer-grid map from Python, checked from the (u, v) alone, and against the
`trivcon param` program."""

import os

import numpy as np
import pytest

import trivcon
from conftest import REPO

CUBE_OBJ = os.path.join(REPO, "data", "cube_sphere.obj")


def torus(nu=48, nv=16, R=1.0, r=0.4):
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a, b = 2 * np.pi * i / nu, 2 * np.pi * j / nv
    V = np.stack([(R + r * np.cos(b)) * np.cos(a), (R + r * np.cos(b)) * np.sin(a), r * np.sin(b)], -1).reshape(-1, 3)
    idx = lambda p, q: (p % nu) * nv + (q % nv)
    F = []
    for p in range(nu):
        for q in range(nv):
            F += [[idx(p, q), idx(p + 1, q), idx(p + 1, q + 1)], [idx(p, q), idx(p + 1, q + 1), idx(p, q + 1)]]
    return V, np.array(F, dtype=np.int64)


def max_transition_residual(F, uv):
    """Across every interior edge, the two faces' (u, v) at both ends differ by one quarter-turn rotation and
    one whole translation: the largest miss over edges, for the best rotation of each."""
    corners = {}
    for f, face in enumerate(F):
        for k in range(3):
            corners.setdefault((int(face[k]), int(face[(k + 1) % 3])), (f, k))
    rotations = [np.array(m) for m in ([[1, 0], [0, 1]], [[0, -1], [1, 0]], [[-1, 0], [0, -1]], [[0, 1], [-1, 0]])]
    worst = 0.0
    for (a, b), (f, k) in corners.items():
        if (b, a) not in corners or a > b:
            continue
        g, l = corners[(b, a)]
        la, lb = uv[f, k], uv[f, (k + 1) % 3]
        rb, ra = uv[g, l], uv[g, (l + 1) % 3]
        best = np.inf
        for J in rotations:
            ta, tb = ra - J @ la, rb - J @ lb
            best = min(best, max(np.abs(ta - tb).max(), np.abs(ta - np.round(ta)).max()))
        worst = max(worst, best)
    return worst


def test_torus_map_is_seamless():
    V, F = torus()
    r = trivcon.FieldDesigner(V, F).solve(N=4)
    p = r.parametrize(target_faces=300)
    assert p.uv.shape == (len(F), 3, 2) and p.uv.dtype == np.float64
    assert not p.uv.flags.writeable
    assert p.seamless and p.warning == ""
    assert p.quality["flipped_faces"] == 0
    assert len(p.cones) == 0 and p.cut_edges.shape[1] == 2 and len(p.cut_edges) > 0
    assert max_transition_residual(F, p.uv) < 1e-7
    assert abs(p.quality["unit_squares"] / 300 - 1) < 0.3
    assert "seamless=True" in repr(p)


def test_cube_map_agrees_with_the_program(cli, tmp_path):
    V, F = trivcon.read_mesh(CUBE_OBJ)
    r = trivcon.FieldDesigner(V, F).solve(N=4, singularities="auto")
    p = r.parametrize(target_faces=400)
    assert p.seamless
    assert sorted(p.cone_index.tolist()) == [1] * 8
    cone_uv = [p.uv[f, k] for f in range(len(F)) for k in range(3) if F[f, k] in set(p.cones.tolist())]
    assert np.abs(np.array(cone_uv) - np.round(cone_uv)).max() < 1e-9
    assert max_transition_residual(F, p.uv) < 1e-7
    p.write_obj(tmp_path / "py.obj")
    cli("param", CUBE_OBJ, "--auto", "--target-faces", 400, "-o", tmp_path / "cli.obj", "-q")
    vt = lambda path: np.array([[float(x) for x in line.split()[1:]] for line in open(path) if line.startswith("vt ")])
    assert np.abs(vt(tmp_path / "py.obj") - vt(tmp_path / "cli.obj")).max() < 1e-9
    assert np.abs(vt(tmp_path / "py.obj") - p.uv.reshape(-1, 2)).max() < 1e-12


def test_errors():
    V, F = torus(12, 6)
    d = trivcon.FieldDesigner(V, F)
    with pytest.raises(trivcon.Error, match=r"needs a cross field \(N = 4\), got N = 1"):
        d.solve(N=1).parametrize(target_faces=10)
    r = d.solve(N=4)
    with pytest.raises(trivcon.Error, match="exactly one of target_faces and edge_length"):
        r.parametrize()
    with pytest.raises(trivcon.Error, match="exactly one of target_faces and edge_length"):
        r.parametrize(target_faces=10, edge_length=0.1)
    with pytest.raises(trivcon.Error, match="edge_length must be a positive number"):
        r.parametrize(edge_length=-1)
    with pytest.raises(trivcon.Error, match="is not an edge of the mesh"):
        r.parametrize(edge_length=0.1, aligned_edges=[[0, 40]])
