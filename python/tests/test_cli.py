# SPDX-License-Identifier: MIT
"""The module agrees with the `trivcon` program (build/trivcon, or $TRIVCON_CLI) on the same input."""

import json
import os
from fractions import Fraction

import numpy as np
import pytest

import reference
import trivcon
from conftest import REPO

CUBE_OBJ = os.path.join(REPO, "data", "cube_sphere.obj")
CUBE_SING = os.path.join(REPO, "data", "cube_sphere.sing")


def read_connection(path):
    rows = [line.split() for line in open(path) if not line.startswith("#")]
    return np.array([[int(r[0]), int(r[1])] for r in rows], dtype=np.int64), np.array([float(r[2]) for r in rows])


def header(path):
    return [line for line in open(path) if line.startswith("#")]


def agree(cli, tmp_path, mesh_path, N, cli_args, result, tol=1e-9):
    """Runs `trivcon solve` with cli_args and compares its field and connection files with `result`."""
    f, c, s = tmp_path / "cli.field.txt", tmp_path / "cli.connection.txt", tmp_path / "cli.sing"
    cli("solve", mesh_path, "-N", N, *cli_args, "--field-out", f, "--connection-out", c, "--sing-out", s, "-q")
    directions, file_N = trivcon.read_field(str(f), result.designer.num_faces)
    assert file_N == N
    assert np.abs(directions - result.directions).max() < tol
    edges, x = read_connection(c)
    assert np.array_equal(edges, result.edges)
    assert np.abs(x - result.connection).max() < tol
    assert trivcon.read_singularities(str(s), N) == result.singularities
    # What the module writes for the same solve is what the program wrote (to round-off).
    result.write_field(str(tmp_path / "py.field.txt"))
    result.write_connection(str(tmp_path / "py.connection.txt"))
    result.write_singularities(str(tmp_path / "py.sing"))
    assert header(tmp_path / "py.field.txt") == header(f) and header(tmp_path / "py.connection.txt") == header(c)
    py_dirs, _ = trivcon.read_field(str(tmp_path / "py.field.txt"), result.designer.num_faces)
    assert np.abs(py_dirs - directions).max() < tol
    py_edges, py_x = read_connection(tmp_path / "py.connection.txt")
    assert np.array_equal(py_edges, edges) and np.abs(py_x - x).max() < tol
    assert open(tmp_path / "py.sing").read() == open(s).read()
    return directions


def test_cube_from_files(cli, tmp_path):
    V, F = trivcon.read_mesh(CUBE_OBJ)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=4, singularities=trivcon.read_singularities(CUBE_SING, N=4))
    assert len(r.singularities) == 8 and r.verified
    agree(cli, tmp_path, CUBE_OBJ, 4, ["-s", CUBE_SING], r)
    # `trivcon check` reads the module's field in every format and finds the prescription.
    for ext in ("txt", "rawfield", "ply"):
        path = tmp_path / f"py.{ext}"
        trivcon.write_field(str(path), V, F, r.directions, N=4)
        p = cli("check", CUBE_OBJ, path, "-N", 4, "-s", CUBE_SING, "--json")
        report = json.loads(p.stdout)
        assert report["differences"] == []
        assert {s["vertex"]: s["index"] for s in report["singularities"]} == {v: str(i) for v, i in r.singularities.items()}
        back, N = trivcon.read_field(str(path), len(F))
        assert N == (None if ext == "ply" else 4)  # the PLY field states no N
        assert trivcon.field_indices(V, F, back, N=4) == r.singularities


def test_edits_and_generated_mesh(cli, tmp_path):
    """A mesh made in code, written, and several singularity sets solved by both."""
    V, F = trivcon.make_uv_sphere(12, 16)
    path = str(tmp_path / "uv.obj")
    trivcon.write_mesh(path, V, F)
    V2, F2 = trivcon.read_mesh(path)
    assert np.array_equal(V2, V) and np.array_equal(F2, F)
    d = trivcon.FieldDesigner(V2, F2)
    south = len(V) - 1
    for N, sings in [(1, {0: 1, south: 1}), (2, {0: "1/2", south: "3/2"}), (4, {0: "1/4", 40: "3/4", 100: 1})]:
        r = d.solve(N=N, singularities=sings)
        args = [a for v, i in sings.items() for a in ("--sing", f"{v}:{i}")]
        (tmp_path / str(N)).mkdir()
        agree(cli, tmp_path / str(N), path, N, args, r)


def test_torus_generators(cli, tmp_path):
    V, F = trivcon.make_torus(20, 10)
    path = str(tmp_path / "torus.obj")
    trivcon.write_mesh(path, V, F)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=4, generators={0: 1, 1: "-1/4"})
    agree(cli, tmp_path, path, 4, ["--generator", "0:1", "--generator", "1:-1/4"], r)


def test_disk_fixed_and_aligned(cli, tmp_path):
    V, F = trivcon.make_disk(6, 8)
    path = str(tmp_path / "disk.ply")
    trivcon.write_mesh(path, V, F)
    d = trivcon.FieldDesigner(*trivcon.read_mesh(path))
    # The aligned boundary needs +1 inside (trivcon/constraints.h): at the centre.
    r = d.solve(N=4, singularities={0: 1}, align_boundary=True, fixed={3: (1.0, 2.0, 0.0), 10: 0.4})
    agree(cli, tmp_path, path, 4, ["--sing", "0:1", "--align-boundary", "--fix", "3:1,2,0", "--fix", "10:angle=0.4"], r)
    r = d.solve(N=4, boundary={0: 0}, singularities={0: 1})
    (tmp_path / "b").mkdir()
    agree(cli, tmp_path / "b", path, 4, ["--boundary", "0:0", "--sing", "0:1"], r)


def test_auto(cli, tmp_path):
    V, F = trivcon.make_cube_sphere(6, spherical=False)
    path = str(tmp_path / "cube.obj")
    trivcon.write_mesh(path, V, F)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=4, singularities="auto", auto_cancel=2)
    agree(cli, tmp_path, path, 4, ["--auto", "--auto-cancel", "2"], r)


@pytest.mark.skipif(not trivcon.with_suitesparse, reason="the QR route needs a build with TRIVCON_WITH_SUITESPARSE")
def test_unit_weights_and_qr(cli, tmp_path):
    V, F = trivcon.make_icosphere(2)
    path = str(tmp_path / "ico.obj")
    trivcon.write_mesh(path, V, F)
    r = trivcon.FieldDesigner(V, F, weights="unit", solver="qr").solve(N=1, singularities={0: 1, 11: 1})
    agree(cli, tmp_path, path, 1, ["--weights", "unit", "--solver", "qr", "--sing", "0:1", "--sing", "11:1"], r)


def test_weight_floor_agrees_with_the_program(cli, tmp_path):
    # A jittered cube: many of its cotangents are small or clamped, so the floor raises them.
    V, F = trivcon.read_mesh(CUBE_OBJ)
    path = str(tmp_path / "cube.obj")
    trivcon.write_mesh(path, V, F)
    plain = trivcon.FieldDesigner(V, F).solve(N=4, singularities="auto")
    floored = trivcon.FieldDesigner(V, F, weight_floor=0.5)
    r = floored.solve(N=4, singularities=plain.singularities)
    assert r.verified
    assert r.energy != plain.energy
    args = ["--weight-floor", "0.5"]
    for v, n in sorted(plain.singularities.items()):
        args += ["--sing", f"{v}:{n}"]
    agree(cli, tmp_path, path, 4, args, r)


def test_render_matches_the_program(cli, tmp_path):
    V, F = trivcon.read_mesh(CUBE_OBJ)
    field = tmp_path / "f.txt"
    cli("solve", CUBE_OBJ, "-N", 4, "-s", CUBE_SING, "--field-out", field, "-q")
    directions, N = trivcon.read_field(str(field), len(F))
    for style, extra in (("hedgehog", []), ("streamlines", ["--view", "100,45", "--up", "z"])):
        cli("render", CUBE_OBJ, "--field", field, "-o", tmp_path / f"cli.{style}.png", "--size", "320x240", "--style", style, *extra)
        view, up = ((100, 45), "z") if extra else ((30, 20), "y")
        image = trivcon.render(V, F, directions, N=N, size=(320, 240), style=style, view=view, up=up)
        assert image.shape == (240, 320, 3) and image.dtype == np.uint8
        trivcon.write_png(str(tmp_path / f"py.{style}.png"), image)
        assert open(tmp_path / f"py.{style}.png", "rb").read() == open(tmp_path / f"cli.{style}.png", "rb").read()


def test_indices_of_the_programs_field(cli, tmp_path):
    """field_indices on the program's field equals `trivcon check` and the reference."""
    V, F = trivcon.make_genus_surface(2, 2)
    path = str(tmp_path / "eight.obj")
    trivcon.write_mesh(path, V, F)
    d = trivcon.FieldDesigner(V, F)
    a = d.auto_singularities(N=4)
    assert sum(a.singularities.values()) == -2
    field = tmp_path / "f.rawfield"
    cli("solve", path, "-N", 4, "--auto", "--field-out", field, "-q")
    directions, N = trivcon.read_field(str(field), len(F))
    found = trivcon.field_indices(V, F, directions, N=4)
    report = json.loads(cli("check", path, field, "--json").stdout)
    assert {s["vertex"]: s["index"] for s in report["singularities"]} == {v: str(i) for v, i in found.items()}
    assert reference.Mesh(V, d.F).field_indices(directions, 4) == found == a.singularities


def test_feature_alignment_agrees_with_the_program(cli, tmp_path):
    """align_features is the CLI's --align-features (one request layer): on the flat-faced cube, --auto with the
    sharp edges puts +1/4 at the 8 corners, every face beside a cube edge runs along it, and the module's field,
    connection and singularities are the program's; feature_edges (vertex pairs) is the --features file."""
    n = 5
    V, F = trivcon.make_cube_sphere(n, spherical=False)
    path = str(tmp_path / "cube.obj")
    trivcon.write_mesh(path, V, F)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=4, singularities="auto", align_features=30)
    assert r.verified and r.field_exact
    assert r.sharp_edges.shape == (12 * n, 2)
    corners = {v for v in range(len(V)) if (np.abs(V[v]) == 1).all()}
    assert r.singularities == {v: Fraction(1, 4) for v in corners}
    # Every face beside a sharp edge: its cross has an arm along the edge.
    for i, j in r.sharp_edges:
        e = V[j] - V[i]
        for f in np.nonzero(((F == i) | (F == j)).sum(axis=1) == 2)[0]:
            dirs = r.all_directions()[f]
            assert np.max(np.abs(dirs @ e)) / np.linalg.norm(e) > 1 - 1e-9
    agree(cli, tmp_path, path, 4, ["--auto", "--align-features", "30"], r)
    # The same edges given as a list: the same field (the prescription as found above).
    edges_file = tmp_path / "cube.features"
    edges_file.write_text("".join(f"{i} {j}\n" for i, j in r.sharp_edges))
    r.write_singularities(str(tmp_path / "auto.sing"))
    listed = d.solve(N=4, singularities=r.singularities, feature_edges=r.sharp_edges)
    assert np.abs(listed.directions - r.directions).max() < 1e-9  # fixed faces on the cube decide its rotation
    agree(cli, tmp_path, path, 4, ["-s", str(tmp_path / "auto.sing"), "--features", str(edges_file)], listed)
    with pytest.raises(trivcon.Error, match=r"^feature_edges\[0\]: \(0, 1000\) is not an edge of the mesh$"):
        d.solve(N=4, singularities=r.singularities, feature_edges=[[0, 1000]])
    with pytest.raises(trivcon.Error, match=r"^align_features: expected None or an angle in degrees in \[0, 180\], got 200$"):
        d.solve(N=4, singularities="auto", align_features=200)
