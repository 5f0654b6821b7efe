# SPDX-License-Identifier: MIT
"""Result.quad and Parametrization.quads: the quad mesh from Python, checked from (V, Q) alone and against
`trivcon quad`."""

import json
from fractions import Fraction
import pickle
from collections import Counter

import numpy as np
import pytest

import trivcon


def census(V, Q):
    """(chi, boundary edges, edges in more than two quads, {interior vertex: valence}) from the quads alone."""
    edges = Counter()
    for quad in Q:
        for k in range(4):
            a, b = int(quad[k]), int(quad[(k + 1) % 4])
            edges[(min(a, b), max(a, b))] += 1
    used = {v for e in edges for v in e}
    boundary = {v for e, n in edges.items() if n == 1 for v in e}
    valence = Counter(v for e in edges for v in e)
    chi = len(used) - len(edges) + len(Q)
    return chi, sum(n == 1 for n in edges.values()), sum(n > 2 for n in edges.values()), {v: n for v, n in valence.items() if v not in boundary}


def test_cube_quads_have_eight_valence_three_corners():
    V, F = trivcon.make_cube_sphere(8, spherical=False)
    r = trivcon.FieldDesigner(V, F).solve(4, "auto")
    q = r.quad(target_faces=400)
    QV, QQ = q  # unpacks as (V, Q)
    assert QQ.shape[1] == 4 and QQ.dtype == np.int64 and QV.shape[1] == 3
    chi, boundary, over, valence = census(QV, QQ)
    assert (chi, boundary, over) == (2, 0, 0)
    irregular = sorted(v for v, n in valence.items() if n != 4)
    assert len(irregular) == 8 and all(valence[v] == 3 for v in irregular)
    # The irregular quad vertices sit on the singular vertices of the field.
    assert sorted(int(q.vertex_cone[v]) for v in irregular) == sorted(r.singularities)
    assert q.ok and q.warning == "" and q.quality["singular_mismatches"] == 0
    assert q.quality["quads"] == len(QQ) and q.quality["irregular_vertices"] == 8
    assert q.quality["nonconvex_quads"] == 0 and q.quality["min_scaled_jacobian"] > 0
    assert 280 < len(QQ) < 520
    assert "8 irregular" in repr(q)


def test_same_as_the_program(cli, tmp_path):
    V, F = trivcon.make_torus(48, 16)
    mesh = tmp_path / "torus.obj"
    trivcon.write_mesh(str(mesh), V, F)
    report, out = tmp_path / "r.json", tmp_path / "q.obj"
    cli("quad", mesh, "--target-faces", 500, "-o", out, "--report", report)  # no singularities: a torus needs none
    j = json.loads(report.read_text())["quad"]
    q = trivcon.FieldDesigner(V, F).solve(4, {}).parametrize(target_faces=500)
    quads = q.quads()
    assert quads.quality["quads"] == j["quads"] and quads.quality["irregular_vertices"] == j["irregular_vertices"] == 0
    quads.write(tmp_path / "again.obj")
    # The same quads; positions equal to rounding (the two solves may sum in another order on other threads).
    V1, F1 = trivcon.read_mesh(str(out))
    V2, F2 = trivcon.read_mesh(str(tmp_path / "again.obj"))
    assert np.array_equal(F1, F2) and np.allclose(V1, V2, atol=1e-6)
    chi, boundary, over, valence = census(*quads)
    assert chi == 0 and boundary == 0 and over == 0 and set(valence.values()) == {4}


def test_parametrization_pickles_and_still_gives_quads():
    V, F = trivcon.make_cube_sphere(6, spherical=False)
    p = trivcon.FieldDesigner(V, F).solve(4, "auto").parametrize(target_faces=200)
    back = pickle.loads(pickle.dumps(p))
    assert back.quads().quality["quads"] == p.quads().quality["quads"]


def test_quad_needs_a_cross_field_and_a_scale():
    V, F = trivcon.make_icosphere(2)
    d = trivcon.FieldDesigner(V, F)
    with pytest.raises(trivcon.Error, match="needs a cross field"):
        d.solve(6, "auto").quad(target_faces=100)
    with pytest.raises(trivcon.Error, match="give exactly one of target_faces and edge_length"):
        d.solve(4, "auto").quad()


def test_auto_for_a_map_is_the_programs(cli, tmp_path):
    # solve(..., "auto", map_target_faces=K) chooses the singularities as `trivcon quad --auto --target-faces K`
    # does (cancelled, gathered, kept and moved for the map): the same singularities and the same quads.
    V, F = trivcon.make_genus_surface(2, 3)
    mesh = tmp_path / "g2.obj"
    trivcon.write_mesh(str(mesh), V, F)
    report, out, sing = tmp_path / "r.json", tmp_path / "q.obj", tmp_path / "s.txt"
    cli("quad", mesh, "--auto", "--align-features", 30, "--target-faces", 300, "-o", out, "--report", report, "--sing-out", sing)
    j = json.loads(report.read_text())
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(4, "auto", align_features=30, map_target_faces=300)
    program = {int(v): k for v, k in (line.split() for line in sing.read_text().splitlines() if not line.startswith("#"))}
    assert {v: str(k) for v, k in r.singularities.items()} == program
    q = r.quad(target_faces=300)
    assert q.quality["quads"] == j["quad"]["quads"] and q.ok == (j["quad"]["singular_mismatches"] == 0)
    # Without it, the smoothest field's singularities as `solve --auto` finds them (no cancelling for a map).
    plain = d.solve(4, "auto", align_features=30)
    assert sum(plain.singularities.values()) == sum(r.singularities.values())
    with pytest.raises(trivcon.Error, match="give at most one of map_target_faces and map_edge_length"):
        d.solve(4, "auto", map_target_faces=300, map_edge_length=0.1)
    with pytest.raises(trivcon.Error, match="map_edge_length must be a positive number"):
        d.solve(4, "auto", map_edge_length=-1)


def test_small_pieces_of_creases_are_left_out_of_a_map(cli, tmp_path):
    # A flat-faced cube with a small spike on its top face: its rim is a closed piece of creases 0.25 across.
    # feature_min_length leaves it out (as --feature-min-length); a map's request leaves out what is shorter
    # than one unit by itself, as `trivcon quad` does, with the same singularities.
    n = 16
    V, F = trivcon.make_cube_sphere(n, spherical=False)
    V[(V[:, 0] == 0) & (V[:, 1] == 0) & (V[:, 2] == 1), 2] += 0.15
    d = trivcon.FieldDesigner(V, F)
    every = d.solve(4, "auto", align_features=30).sharp_edges
    assert len(every) > 12 * n
    assert len(d.solve(4, "auto", align_features=30, feature_min_length=0.3).sharp_edges) == 12 * n
    r = d.solve(4, "auto", align_features=30, map_target_faces=200)
    assert len(r.sharp_edges) == 12 * n
    on_cube = (np.abs(V[r.sharp_edges]) == 1).sum(axis=2) >= 2  # both ends on a cube edge
    assert on_cube.all()
    mesh, sing = tmp_path / "spiked.obj", tmp_path / "s.txt"
    trivcon.write_mesh(str(mesh), V, F)
    cli("quad", mesh, "--auto", "--align-features", 30, "--target-faces", 200, "-o", tmp_path / "q.obj", "--sing-out", sing)
    program = {int(v): k for v, k in (line.split() for line in sing.read_text().splitlines() if not line.startswith("#"))}
    assert {v: str(k) for v, k in r.singularities.items()} == program
    q = r.quad(target_faces=200)
    assert q.ok and q.quality["euler_characteristic"] == 2
    with pytest.raises(trivcon.Error, match="^feature_min_length needs align_features$"):
        d.solve(4, "auto", feature_min_length=1)
    with pytest.raises(trivcon.Error, match=r"^feature_min_length must be a number >= 0, not -1$"):
        d.solve(4, "auto", align_features=30, feature_min_length=-1)


def fan_capped_prism(n=20, stacks=10):
    """A prism whose caps are fans from one rim vertex (as CAD exports triangulate flat faces)."""
    k = np.arange(n)
    V = np.array([[np.cos(2 * np.pi * i / n), 2.85 * s / stacks, np.sin(2 * np.pi * i / n)] for s in range(stacks + 1) for i in k])
    F = []
    for s in range(stacks):
        for i in k:
            a, b = s * n + i, s * n + (i + 1) % n
            F += [[a, a + n, b], [b, a + n, b + n]]
    for i in range(1, n - 1):
        F += [[0, i, i + 1], [stacks * n, stacks * n + i + 1, stacks * n + i]]
    return V, np.array(F)


def test_fan_caps_are_refined_as_the_program_refines_them(cli, tmp_path):
    # The map folds on the fans (their faces' corners all lie on the rims' iso-lines): solve for a map splits the
    # fans' inner edges as `trivcon quad` does, and the Result belongs to the refined mesh.
    V, F = fan_capped_prism()
    r = trivcon.FieldDesigner(V, F).solve(4, "auto", align_features=30, map_target_faces=300)
    assert r.designer.V.shape == (254, 3) and r.designer.F.shape == (504, 3)
    assert np.array_equal(r.designer.V[:220], V)
    assert np.array_equal(r.parent_face[:436], np.arange(436)) and ((r.parent_face[436:] >= 400) & (r.parent_face[436:] < 436)).all()
    q = r.quad(target_faces=300)
    assert q.ok and q.quality["euler_characteristic"] == 2 and q.quality["irregular_vertices"] == 8
    mesh, sing = tmp_path / "prism.obj", tmp_path / "s.txt"
    trivcon.write_mesh(str(mesh), V, F)
    cli("quad", mesh, "--auto", "--align-features", 30, "--target-faces", 300, "-o", tmp_path / "q.obj", "--sing-out", sing)
    program = {int(v): k for v, k in (line.split() for line in sing.read_text().splitlines() if not line.startswith("#"))}
    assert {v: str(k) for v, k in r.singularities.items()} == program


def test_uniform_size_turns_the_sizing_off():
    # An annulus with its circles aligned: by default the unit follows the map's own scale and stretches less;
    # uniform_size=True keeps one unit everywhere, as `--uniform-size`.
    V, F = trivcon.make_annulus(12, 96, 0.5, 1.0)
    r = trivcon.FieldDesigner(V, F).solve(4, "auto", align_boundary=True)
    sized = r.parametrize(target_faces=400)
    uniform = r.parametrize(target_faces=400, uniform_size=True)
    assert sized.quality["sizing"] == "map" and uniform.quality["sizing"] == "uniform"
    conformal = r.parametrize(target_faces=400, sizing="connection")
    assert conformal.quality["sizing"] == "connection" and conformal.quality["flipped_faces"] == 0
    assert conformal.quality["mean_distortion"] < uniform.quality["mean_distortion"] - 0.05
    with pytest.raises(trivcon.Error, match="sizing: expected 'map', 'connection' or 'uniform', not 'conformal'"):
        r.parametrize(target_faces=400, sizing="conformal")
    with pytest.raises(trivcon.Error, match="disagree"):
        r.parametrize(target_faces=400, uniform_size=True, sizing="map")
    assert sized.quality["flipped_faces"] == 0 and uniform.quality["flipped_faces"] == 0
    assert sized.quality["mean_distortion"] < uniform.quality["mean_distortion"] - 0.05
    q = r.quad(target_faces=400, uniform_size=True)
    chi, boundary, over, _ = census(*q)
    assert (chi, over) == (0, 0) and boundary > 0


def perforated_plate(nx, ny, m, layers, r, height):
    """A plate of nx x ny unit cells, each with a round hole of radius r (m edges per cell side, `layers` rings of
    triangles from the hole to the cell's square), extruded `height` down into a closed solid (tests/support.cpp's
    perforated_plate and extruded, for the same mesh from Python)."""
    index, points, faces = {}, [], []

    def vertex(x, y):
        key = (round(x * 1e6), round(y * 1e6))
        if key not in index:
            index[key] = len(points)
            points.append((x, y, 0.0))
        return index[key]

    for cx in range(nx):
        for cy in range(ny):
            square = []
            for side in range(4):
                for k in range(m):
                    a = k / m
                    square.append((cx + (a, 1, 1 - a, 0)[side], cy + (0, a, 1, 1 - a)[side]))
            n = 4 * m
            ring = []
            for j in range(layers + 1):
                w, row = j / layers, []
                for k in range(n):
                    angle = np.arctan2(square[k][1] - cy - 0.5, square[k][0] - cx - 0.5)
                    hx, hy = cx + 0.5 + r * np.cos(angle), cy + 0.5 + r * np.sin(angle)
                    row.append(vertex((1 - w) * hx + w * square[k][0], (1 - w) * hy + w * square[k][1]))
                ring.append(row)
            for j in range(layers):
                for k in range(n):
                    a, b, c, d = ring[j][k], ring[j][(k + 1) % n], ring[j + 1][(k + 1) % n], ring[j + 1][k]
                    faces += [(a, b, c), (a, c, d)] if (j + k) % 2 else [(a, b, d), (b, c, d)]
    V, F = np.array(points), np.array(faces)
    directed = {(int(f[k]), int(f[(k + 1) % 3])) for f in F for k in range(3)}
    boundary = sorted((a, b) for a, b in directed if (b, a) not in directed)
    n = len(V)
    walls = [w for a, b in boundary for w in ((b, a, a + n), (b, a + n, b + n))]
    return np.vstack([V, V - [0, 0, height]]), np.vstack([F, F[:, ::-1] + n, np.array(walls)])


def test_a_map_folding_at_the_target_is_made_at_another_scale_as_the_program_makes_it(cli, tmp_path):
    # The closed 27-hole plate 0.3 thick at 700 quads: every placement's map keeps a fold at a hole's rim at the
    # edge length asked for, and the program makes it again at another (kMapScales). Result.parametrize (and
    # Result.quad) keep the field's map the same way (map_field), so Python gives the program's quads.
    V, F = perforated_plate(9, 3, 8, 4, 0.3, 0.3)
    mesh = tmp_path / "plate.obj"
    trivcon.write_mesh(str(mesh), V, F)
    report, out = tmp_path / "r.json", tmp_path / "q.obj"
    cli("quad", mesh, "--auto", "--align-features", 30, "--target-faces", 700, "-o", out, "--report", report)
    j = json.loads(report.read_text())
    assert j["map_scale"] in (0.95, 1.05, 0.9, 1.1)
    r = trivcon.FieldDesigner(V, F).solve(4, "auto", align_features=30, map_target_faces=700)
    p = r.parametrize(target_faces=700)
    assert p.scale == j["map_scale"] and p.quality["flipped_faces"] == 0 and p.warning == ""
    assert p.edge_length == pytest.approx(j["param"]["edge_length"], rel=1e-9)
    q = p.quads()
    assert q.ok and q.quality["quads"] == j["quad"]["quads"] and q.quality["irregular_vertices"] == j["quad"]["irregular_vertices"]
    assert q.quality["vertices"] == j["quad"]["vertices"] and q.quality["min_scaled_jacobian"] == pytest.approx(j["quad"]["min_scaled_jacobian"])
    # At the scale it was solved for, the map the search kept is given back, not made again: the program's.
    again = r.quad(target_faces=700)
    assert again.quality["quads"] == j["quad"]["quads"] and np.array_equal(again.V, q.V)
    chi, boundary, over, valence = census(*q)
    assert (chi, boundary, over) == (-52, 0, 0)
    # A map clean at the target keeps its scale.
    assert trivcon.FieldDesigner(*trivcon.make_torus(48, 16)).solve(4, {}).parametrize(target_faces=500).scale == 1


def test_given_singularities_for_a_map_are_the_programs(cli, tmp_path):
    # solve(..., singularities, map_target_faces=K) makes the field as `trivcon quad -s S --target-faces K` does:
    # the singularities quad --auto moved onto the plate's rims get the sectors that make their index, so the
    # field is --auto's and the quads the program's. Without map_target_faces the faces follow the lines alone.
    V, F = perforated_plate(3, 1, 8, 4, 0.3, 0.3)
    mesh = tmp_path / "plate3.obj"
    trivcon.write_mesh(str(mesh), V, F)
    report, again, out, sing = tmp_path / "r.json", tmp_path / "r2.json", tmp_path / "q.obj", tmp_path / "s.txt"
    cli("quad", mesh, "--auto", "--align-features", 30, "--target-faces", 100, "-o", out, "--report", report, "--sing-out", sing)
    cli("quad", mesh, "-s", sing, "--align-features", 30, "--target-faces", 100, "-o", out, "--report", again)
    j, k = json.loads(report.read_text()), json.loads(again.read_text())
    assert j["features"]["singularities_moved_onto_them"] > 0
    assert k["features"]["sectors_turned_for_singularities"] == j["features"]["singularities_moved_onto_them"]
    assert k["field"]["energy"] == pytest.approx(j["field"]["energy"], rel=1e-9)
    given = {int(v): Fraction(n) for v, n in (line.split() for line in sing.read_text().splitlines() if not line.startswith("#"))}
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(4, given, align_features=30, map_target_faces=100)
    assert r.energy == pytest.approx(k["field"]["energy"], rel=1e-9) and r.field_exact
    q = r.quad(target_faces=100)
    assert q.ok and q.quality["quads"] == k["quad"]["quads"] and q.quality["vertices"] == k["quad"]["vertices"]
    plain = d.solve(4, given, align_features=30)
    assert plain.energy != pytest.approx(r.energy, rel=1e-6)


def lattice_plate(nx, ny, r, h):
    """A plate of nx x ny unit cells with a round hole of radius r in each, meshed on a triangle lattice of spacing h
    with the holes cut out and their rims put on the circles (tests/support.cpp, test::lattice_plate)."""
    rows, n = max(2, round(ny / (h * np.sqrt(3) / 2))), max(1, round(nx / h))
    P, row = [], []
    for j in range(rows + 1):
        xs = [nx * i / n for i in range(n + 1)] if j % 2 == 0 else [0] + [nx * (i + 0.5) / n for i in range(n)] + [nx]
        row.append(list(range(len(P), len(P) + len(xs))))
        P += [(x, ny * j / rows) for x in xs]
    P = np.array(P)
    faces = []
    for j in range(rows):
        a, b, i, k = row[j], row[j + 1], 0, 0
        while i + 1 < len(a) or k + 1 < len(b):
            if k + 1 == len(b) or (i + 1 < len(a) and P[a[i + 1], 0] <= P[b[k + 1], 0]):
                faces.append((a[i], a[i + 1], b[k]))
                i += 1
            else:
                faces.append((a[i], b[k + 1], b[k]))
                k += 1
    centres = np.array([(cx + 0.5, cy + 0.5) for cx in range(nx) for cy in range(ny)])
    dist = np.linalg.norm(P[:, None, :] - centres[None, :, :], axis=2)
    d, nearest = dist.min(axis=1), dist.argmin(axis=1)
    kept = [f for f in faces if all(d[v] >= r + 0.3 * h for v in f)]
    uses, neighbours = Counter(), [set() for _ in P]
    for f in kept:
        for k in range(3):
            a, b = f[k], f[(k + 1) % 3]
            uses[min(a, b), max(a, b)] += 1
            neighbours[a].add(b), neighbours[b].add(a)
    rim = np.zeros(len(P), bool)
    for (a, b), count in uses.items():
        if count == 1:
            rim[a] = rim[b] = True
    for v in np.nonzero(rim & (d < r + 2 * h))[0]:
        c = centres[nearest[v]]
        P[v] = c + r * (P[v] - c) / np.linalg.norm(P[v] - c)
    for _ in range(15):
        for v in range(len(P)):
            if not rim[v] and neighbours[v] and d[v] < r + 3 * h:
                P[v] = np.mean([P[w] for w in neighbours[v]], axis=0)
    used = sorted({v for f in kept for v in f})
    index = {v: i for i, v in enumerate(used)}
    V = np.column_stack([P[used], np.zeros(len(used))])
    return V, np.array([[index[v] for v in f] for f in kept], dtype=np.int64)


def test_corners_of_the_boundary_are_listed_and_given_back(tmp_path):
    # A plate with 8 round holes at 80 quads: the map's placement moves the −1/4 beside the rims onto them as
    # corners of the boundary (tests/test_cli_quad.cpp has the quads). Result.corners lists them, write_singularities
    # writes them beside the singularities, and given back with the boundary aligned they turn the same fans: the
    # same field and, at the same edge length, the same quads. A boundary vertex's index without the boundary
    # aligned is refused.
    V, F = lattice_plate(4, 2, 0.2, 0.05)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(4, "auto", align_boundary=True, map_target_faces=80)
    assert len(r.corners) >= 24 and set(r.corners.values()) == {Fraction(-1, 4)}
    assert not set(r.corners) & set(r.singularities)
    path = tmp_path / "s.txt"
    r.write_singularities(str(path))
    written = {int(v): Fraction(n) for v, n in (line.split() for line in path.read_text().splitlines() if not line.startswith("#"))}
    assert written == {**r.singularities, **r.corners}
    assert pickle.loads(pickle.dumps(r)).corners == r.corners
    again = d.solve(4, written, align_boundary=True, map_target_faces=80)
    assert again.corners == r.corners and again.singularities == r.singularities
    assert again.energy == pytest.approx(r.energy, rel=1e-9) and again.field_exact
    p = r.parametrize(target_faces=80)
    q, q2 = p.quads(), again.quad(edge_length=p.edge_length)
    assert q.ok and q2.ok and np.array_equal(q.V, q2.V) and np.array_equal(q.Q, q2.Q)
    # The search: past the first placement's map (it has problems here) more were made; map_search_maps=1 stops
    # after the first placement's maps (with the other sizings').
    assert r.search["maps"] > 1 and not r.search["stopped"]
    # map_progress gets the search's lines as quad prints them, on this thread; what it raises stops the search.
    lines = []
    bounded = d.solve(4, "auto", align_boundary=True, map_target_faces=80, map_search_maps=1, map_progress=lines.append)
    assert len(lines) == 2 and lines[0].startswith("search: map") and " (placement the first): " in lines[0]
    assert lines[1] == f"search: stopped after {bounded.search['maps']} maps (the bound given); the best of them kept"

    class Enough(Exception):
        pass

    def stop(line):
        raise Enough(line)

    with pytest.raises(Enough, match="^search: map"):
        d.solve(4, "auto", align_boundary=True, map_target_faces=80, map_progress=stop)
    with pytest.raises(trivcon.Error, match=r"^map_progress must be callable or None, not 3$"):
        d.solve(4, "auto", align_boundary=True, map_target_faces=80, map_progress=3)
    assert bounded.search["stopped"] and 1 <= bounded.search["maps"] < r.search["maps"] and not bounded.corners
    with pytest.raises(trivcon.Error, match=r"^map_search_maps must be a whole number >= 0, not -1$"):
        d.solve(4, "auto", align_boundary=True, map_target_faces=80, map_search_maps=-1)
    with pytest.raises(trivcon.Error, match="is on boundary loop .*or align the boundary, --align-boundary, to make the vertex a corner of it"):
        d.solve(4, written)
