# SPDX-License-Identifier: MIT
"""Meshes as users have them: FieldDesigner repairs what is not manifold (repair=True, the default), says so, and
writes the input's faces and vertices, as the CLI does; repair=False refuses with the topology's message."""
import pickle
import warnings

import numpy as np
import pytest

import trivcon


def box(offset=(0.0, 0.0, 0.0)):
    V = np.array([[(i >> 2) & 1, (i >> 1) & 1, i & 1] for i in range(8)], dtype=float) + np.array(offset)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    F = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    return V, F


def two_boxes():
    """Two closed boxes touching at one corner: vertex 7 of the first is vertex 0 of the second."""
    V1, F1 = box()
    V2, F2 = box((1.0, 1.0, 1.0))
    F2 = np.where(F2 == 0, 7 - 8, F2 - 1) + 8
    return np.vstack([V1, V2[1:]]), np.vstack([F1, F2])


def test_two_boxes_sharing_a_corner_are_solved_with_the_input_ids(tmp_path):
    V, F = two_boxes()
    with pytest.warns(UserWarning, match=r"repaired: 1 vertex split into separate fans \(first: vertex 7, 2 fans\)"):
        d = trivcon.FieldDesigner(V, F)
    r = d.repair
    assert r["split_vertices"] == [(7, 2)] and r["input_vertices"] == 15 and r["input_faces"] == 24
    assert d.num_vertices == 16 and list(r["vertex_origin"][15:]) == [7]
    assert d.euler_characteristic == 4
    res = d.solve(N=4, singularities="auto")
    assert res.verified and res.field_exact
    # The field per input face, each row in its input face's plane.
    D = res.input_directions
    assert D.shape == (24, 3)
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    assert np.allclose(np.linalg.norm(D, axis=1), 1) and np.allclose(np.einsum("ij,ij->i", D, n), 0, atol=1e-12)
    res.write_field(str(tmp_path / "f.txt"))
    assert np.allclose(trivcon.read_field(str(tmp_path / "f.txt"), 24)[0], D)
    res.write_singularities(str(tmp_path / "s.txt"))
    assert all(v < 15 for v in trivcon.read_singularities(str(tmp_path / "s.txt"), 4))
    # The repaired mesh written beside, manifold.
    res.write_mesh(str(tmp_path / "m.obj"))
    Vm, Fm = trivcon.read_mesh(str(tmp_path / "m.obj"))
    assert Fm.shape == (24, 3) and np.array_equal(Vm[Fm], V[F])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        trivcon.FieldDesigner(Vm, Fm)  # nothing to repair
    # Pickled: repaired again on loading.
    d2 = pickle.loads(pickle.dumps(d))
    assert d2.repair["split_vertices"] == [(7, 2)] and d2.num_vertices == 16


def test_duplicates_and_degenerate_faces_are_dropped():
    V, F = box()
    G = np.vstack([F, F[3][::-1], [[2, 2, 6]]])  # a reversed copy of face 3, a face with a repeated vertex
    with pytest.warns(UserWarning, match="1 face with a repeated vertex dropped .first: face 13.; 1 duplicate face dropped "
                                         r".first: face 12, a copy of face 3."):
        d = trivcon.FieldDesigner(V, G)
    assert d.num_faces == 12 and list(d.repair["face_of_input"][12:]) [0] == 3
    res = d.solve(N=4, singularities="auto")
    D = res.input_directions
    assert D.shape == (14, 3) and np.array_equal(D[12], D[3])
    assert np.linalg.norm(D[13]) == pytest.approx(1)  # a neighbour's direction


def test_repair_false_refuses():
    V, F = two_boxes()
    with pytest.raises(trivcon.Error, match=r"^non-manifold vertex 7: its faces form 2 separate fans"):
        trivcon.FieldDesigner(V, F, repair=False)


def test_three_fins_on_an_edge():
    V = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0.1], [0.5, 0, 1]], dtype=float)
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    with pytest.warns(UserWarning, match=r"1 edge with more than two faces cut \(first: \(0, 1\)\)"):
        d = trivcon.FieldDesigner(V, F)
    assert d.repair["unpaired_faces"] == [2] and d.num_vertices == 7
    assert d.solve(N=4, singularities="auto").verified


def test_the_batch_repairs_and_says_so(tmp_path):
    from trivcon import batch

    V, F = two_boxes()
    mesh = tmp_path / "boxes.obj"
    trivcon.write_mesh(str(mesh), V, F)
    job = {"mesh": str(mesh), "name": "boxes", "out": str(tmp_path), "N": 4, "sing_file": None, "auto_cancel": 0.0,
           "align_boundary": False, "weights": "cotan", "field_format": "txt", "connection": True, "png": False}
    row = batch.solve_mesh(job)
    assert row["status"] == "ok", row["message"]
    assert row["repair"].startswith("repaired: 1 vertex split")
    assert trivcon.read_field(str(tmp_path / "boxes.field.txt"), 24)[0].shape == (24, 3)
    assert (tmp_path / "boxes.mesh.obj").exists()  # beside the connection, whose edges are its vertex pairs
    row = batch.solve_mesh(dict(job, repair=False))
    assert row["status"] == "failed" and row["message"].startswith("non-manifold vertex 7")
