# SPDX-License-Identifier: MIT
"""Files: meshes, fields, singularities and pictures, in the CLI's formats, with the file's own ids."""

import gzip
from fractions import Fraction

import numpy as np
import pytest

import trivcon


def test_read_mesh_keeps_ids_and_fans_polygons(tmp_path):
    path = tmp_path / "quads.obj"
    path.write_text("# a square pyramid without its base, plus an unused vertex\n"
                    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nv 9 9 9\n"
                    "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 4 3 2 1\n")
    V, F, info = trivcon.read_mesh(str(path), info=True)
    assert V.dtype == np.float64 and V.shape == (6, 3) and F.dtype == np.int64 and F.shape == (6, 3)
    assert F.tolist() == [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [3, 2, 1], [3, 1, 0]]
    assert info["format"] == "obj" and info["polygon_count"] == 5
    assert info["polygon_of_triangle"].tolist() == [0, 1, 2, 3, 4, 4]
    d = trivcon.FieldDesigner(V, F)
    assert d.unreferenced_vertices.tolist() == [5] and d.euler_characteristic == 2
    r = d.solve(N=1, singularities={4: 1, 0: 1})
    assert r.verified and r.singularities == {0: 1, 4: 1}


def test_formats_round_trip(tmp_path):
    V, F = trivcon.make_torus(8, 5)
    for name in ("m.obj", "m.ply", "M.OBJ"):
        trivcon.write_mesh(str(tmp_path / name), V, F)
        V2, F2 = trivcon.read_mesh(str(tmp_path / name))
        assert np.array_equal(V2, V) and np.array_equal(F2, F)
    with open(tmp_path / "m.obj", "rb") as f, gzip.open(tmp_path / "m.obj.gz", "wb") as g:
        g.write(f.read())
    V3, F3 = trivcon.read_mesh(str(tmp_path / "m.obj.gz"))
    assert np.array_equal(V3, V) and np.array_equal(F3, F)
    off = tmp_path / "m.off"
    off.write_text("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n")
    V4, F4, info = trivcon.read_mesh(off, info=True)  # a path-like works too
    assert info["format"] == "off" and F4.tolist()[0] == [0, 2, 1]
    with pytest.raises(trivcon.Error, match="unknown mesh format"):
        trivcon.write_mesh(str(tmp_path / "m.stl"), V, F)


def test_singularity_files(tmp_path):
    sings = {12: Fraction(1, 4), 3: -1, 40: "3/4", 7: 0.5}
    path = tmp_path / "s.sing"
    trivcon.write_singularities(str(path), sings, N=4)
    text = path.read_text()
    assert text == "# trivcon singularities\n# N 4\n# 4 singular vertices\n3 -1\n7 1/2\n12 1/4\n40 3/4\n"
    back = trivcon.read_singularities(str(path), N=4)
    assert back == {3: Fraction(-1), 7: Fraction(1, 2), 12: Fraction(1, 4), 40: Fraction(3, 4)}
    assert all(isinstance(i, Fraction) for i in back.values())
    directional = tmp_path / "d.sings"
    directional.write_text("4 2\n5 1\n9 -1\n")
    assert trivcon.read_singularities(str(directional), N=4) == {5: Fraction(1, 4), 9: Fraction(-1, 4)}
    with pytest.raises(trivcon.Error) as e:
        trivcon.read_singularities(str(path), N=2)
    assert str(e.value) == f"{path}:6: index 1/4 is not a multiple of 1/2 (use -N to change the symmetry)"


def test_field_files_and_lines(tmp_path):
    V, F = trivcon.make_icosphere(2)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=4, singularities={v: "1/4" for v in range(8)})
    for ext in ("txt", "rawfield", "ply"):
        r.write_field(str(tmp_path / f"f.{ext}"))
        back, N = trivcon.read_field(str(tmp_path / f"f.{ext}"), d.num_faces)
        assert np.abs(back - r.directions).max() < 1e-15
    raw = (tmp_path / "f.rawfield").read_text().splitlines()
    assert raw[0] == f"4 {d.num_faces}" and len(raw[1].split()) == 12
    assert (tmp_path / "f.txt").read_text().splitlines()[1] == "# N 4"
    r.write_lines(str(tmp_path / "lines.obj"))
    lines = (tmp_path / "lines.obj").read_text().splitlines()
    assert sum(l.startswith("v ") for l in lines) == 5 * d.num_faces and sum(l.startswith("l ") for l in lines) == 4 * d.num_faces
    r.write_connection(str(tmp_path / "c.txt"))
    rows = [l for l in (tmp_path / "c.txt").read_text().splitlines() if not l.startswith("#")]
    assert len(rows) == len(r.edges)
    with pytest.raises(trivcon.Error, match="faces"):
        trivcon.read_field(str(tmp_path / "f.txt"), d.num_faces + 1)


def test_render_and_png(tmp_path):
    V, F = trivcon.make_cube_sphere(6)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=1, singularities={0: 1, len(V) - 1: 1})
    a = r.render(size=(200, 150))
    b = trivcon.render(V, F, r.directions, N=1, size=(200, 150), singularities=r.singularities)
    assert a.shape == (150, 200, 3) and a.dtype == np.uint8
    assert np.array_equal(a, r.render(size=(200, 150)))  # deterministic
    assert (a != 255).any() and (a == 255).any()  # a surface on a white background
    # The same picture from the directions alone (angles recomputed from them: round-off at most).
    assert (a != b).any(axis=2).mean() < 0.01
    s = r.render(size=(200, 150), style="streamlines", flat=True, legend=False, view=(0, 90), up="z")
    assert s.shape == (150, 200, 3) and not np.array_equal(s, a)
    trivcon.write_png(str(tmp_path / "a.png"), a)
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(trivcon.Error, match="render: style must be 'hedgehog' or 'streamlines', not 'dots'"):
        r.render(style="dots")
    with pytest.raises(trivcon.Error, match=r"render: image size 0x10 out of range \(1..20000\)"):
        r.render(size=(0, 10))
    with pytest.raises(trivcon.Error, match="render: up axis must be x, y or z, not 'w'"):
        r.render(up="w")


def test_stl_and_gltf_read(tmp_path):
    """STL (welded) and glTF read as the C++ reader does: the cube's 8 corners from 12 binary STL triangles."""
    import struct
    V, F = trivcon.make_cube_sphere(1, False)
    data = b"binary".ljust(80, b"\0") + struct.pack("<I", len(F))
    for f in F:
        data += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *V[v]) for v in f) + b"\0\0"
    (tmp_path / "cube.stl").write_bytes(data)
    V2, F2, info = trivcon.read_mesh(tmp_path / "cube.stl", info=True)
    assert info["format"] == "stl-binary" and V2.shape == (8, 3) and F2.shape == (12, 3)
    assert np.array_equal(V2[F2], V[F].astype(np.float32).astype(np.float64))
    with pytest.raises(trivcon.Error, match="not a readable glTF 2.0 file"):
        (tmp_path / "bad.gltf").write_text("{}")
        trivcon.read_mesh(tmp_path / "bad.gltf")
