# SPDX-License-Identifier: MIT
"""Solves judged by the independent reference (reference.py): holonomy, transport, indices read back."""

import math
from fractions import Fraction

import numpy as np
import pytest

import reference
import trivcon


def check_result(V, d, r, singularities):
    """Every property a solve must have, measured without trivcon."""
    ref = reference.Mesh(V, d.F)
    m = d.num_faces
    assert r.directions.shape == (m, 3) and r.directions.dtype == np.float64
    assert r.angles.shape == (m,) and r.angles.dtype == np.float64
    assert r.edges.dtype == np.int64 and r.edges.shape[1] == 2
    assert r.connection.shape == (r.edges.shape[0],)
    # Unit vectors in the face planes, at the stated angles of the face frames.
    assert np.allclose(np.linalg.norm(r.directions, axis=1), 1, atol=1e-12)
    assert np.abs(np.einsum("ij,ij->i", r.directions, ref.normal)).max() < 1e-12
    expected = np.cos(r.angles)[:, None] * ref.X + np.sin(r.angles)[:, None] * ref.Y
    assert np.abs(expected - r.directions).max() < 1e-12
    assert np.all((r.angles >= 0) & (r.angles < 2 * math.pi))
    # Edges: the interior ones, i < j, sorted, as --connection-out.
    assert np.array_equal(r.edges, ref.interior_edges)
    # The holonomy around every interior vertex is its prescribed index.
    want = {v: Fraction(i) for v, i in singularities.items()}
    assert ref.vertex_holonomy_residual(r.edges, r.connection, want) < 1e-9
    assert r.residual < 1e-9
    # The field is transported by the connection across every interior edge.
    assert ref.transport_mismatch(r.edges, r.connection, r.angles, r.N) < 1e-9
    # Indices read back from the directions (our own reading, and the library's) equal the prescription.
    # (A field sampled once per face cannot show an index where the connection turns by pi/N or more
    # across an edge: then only the holonomy above holds the prescription, and the mismatches are explained.)
    want_nonzero = {v: i for v, i in want.items() if i != 0}
    read_back = ref.field_indices(r.directions, r.N)
    assert trivcon.field_indices(V, d.F, r.directions, N=r.N) == read_back == r.field_singularities
    if r.large_turn_edges == 0:
        assert read_back == want_nonzero
        assert len(r.index_mismatches) == 0
    else:
        assert np.abs(r.connection).max() >= math.pi / r.N - 1e-9
        assert len(r.unexplained_mismatches) == 0
    assert r.singularities == want_nonzero
    assert r.verified
    # The energy is sum x^2 / w; with unit weights it is sum x^2.
    if d.weights == "unit":
        assert r.energy == pytest.approx(float(np.sum(r.connection**2)), rel=1e-9)


def test_cube_corners_cross_field(cube):
    V, F, corners, d = cube
    r = d.solve(N=4, singularities={v: "1/4" for v in corners})
    check_result(V, d, r, {v: Fraction(1, 4) for v in corners})
    assert r.N == 4
    assert len(r.generators) == 0 and len(r.boundary) == 0


def test_resolve_many_singularity_sets(cube):
    """One designer, several prescriptions (N = 1, 2, 4, 6): each judged on its own."""
    V, F, corners, d = cube
    a, b, c = corners[0], corners[7], int(np.argmax(V[:, 2]))
    sets = [
        (1, {a: 1, b: 1}),
        (1, {a: 2}),
        (2, {a: "1/2", b: "1/2", c: 1}),
        (4, {v: Fraction(1, 4) for v in corners}),
        (4, {a: 0.75, b: 1.25}),
        (6, {a: "1/3", b: "5/3"}),
        (4, {a: 3, c: -1}),
    ]
    energies = []
    for N, sings in sets:
        r = d.solve(N=N, singularities=sings)
        check_result(V, d, r, {v: Fraction(i) if not isinstance(i, str) else Fraction(i) for v, i in sings.items()})
        energies.append(r.energy)
    # The cube's corners are the smoothest cross field of all the N = 4 sets.
    assert energies[3] < energies[4] < energies[6]


def test_index_forms_agree(cube):
    V, F, corners, d = cube
    forms = [
        {v: "1/4" for v in corners},
        {v: Fraction(1, 4) for v in corners},
        {v: 0.25 for v in corners},
        {np.int64(v): np.float32(0.25) for v in corners},
        [(v, " 1/4 ") for v in corners],
        {v: "2/8" for v in corners},
    ]
    results = [d.solve(N=4, singularities=s) for s in forms]
    for r in results[1:]:
        assert np.array_equal(r.angles, results[0].angles)
    ints = d.solve(N=1, singularities={corners[0]: 1, corners[1]: np.int32(1)})
    same = d.solve(N=1, singularities={corners[0]: "1", corners[1]: 1.0})
    assert np.array_equal(ints.connection, same.connection)


def test_unit_weights(cube):
    V, F, corners, _ = cube
    d = trivcon.FieldDesigner(V, F, weights="unit")
    r = d.solve(N=4, singularities={v: "1/4" for v in corners})
    check_result(V, d, r, {v: Fraction(1, 4) for v in corners})


@pytest.mark.skipif(not trivcon.with_suitesparse, reason="the QR route needs a build with TRIVCON_WITH_SUITESPARSE")
def test_qr_route_agrees(cube):
    V, F, corners, d = cube
    q = trivcon.FieldDesigner(V, F, solver="qr")
    sings = {v: "1/4" for v in corners}
    a, b = d.solve(N=4, singularities=sings), q.solve(N=4, singularities=sings)
    assert np.abs(a.connection - b.connection).max() < 1e-9
    assert a.energy == pytest.approx(b.energy, rel=1e-9)


def test_torus_generators(torus):
    V, F, d = torus
    assert d.euler_characteristic == 0 and d.num_generators == 2
    free = d.solve(N=4)
    check_result(V, d, free, {})
    assert sorted(free.generators_chosen) == [0, 1]
    loops, gens = d.cycle_indices(free.directions, N=4)
    assert gens == free.generators and loops == {}
    # Prescribed turns around both generators: read back from the field, and costlier than the free choice.
    r = d.solve(N=4, generators={0: 1, 1: "1/4"})
    check_result(V, d, r, {})
    assert r.generators == {0: Fraction(1), 1: Fraction(1, 4)} and r.generators_chosen == []
    assert d.cycle_indices(r.directions, N=4)[1] == r.generators
    assert r.energy > free.energy
    # A saddle and a vortex on the torus (sum 0 = chi).
    outer, inner = int(np.argmax(V[:, 0])), int(np.argmin(np.linalg.norm(V[:, :2], axis=1)))
    r = d.solve(N=1, singularities={outer: 1, inner: -1})
    check_result(V, d, r, {outer: 1, inner: -1})


def test_disk_boundary_loop(disk):
    V, F, d = disk
    assert len(d.boundary_loops) == 1
    r = d.solve(N=4)
    check_result(V, d, r, {})
    assert r.boundary == {0: Fraction(1)}  # a constant field on a flat disk: loop index +1
    assert r.boundary_chosen == [0]
    # Four +1/4 inside leave 0 for the loop.
    centre = 0
    ring = [v for v in range(1, 9)]
    r = d.solve(N=4, singularities={ring[0]: "1/4", ring[2]: "1/4", ring[4]: "1/4", ring[6]: "1/4"}, boundary={0: 0})
    check_result(V, d, r, {ring[0]: Fraction(1, 4), ring[2]: Fraction(1, 4), ring[4]: Fraction(1, 4), ring[6]: Fraction(1, 4)})
    assert r.boundary == {0: Fraction(0)}
    assert d.cycle_indices(r.directions, N=4)[0] == {0: Fraction(0)}
    r = d.solve(N=1, singularities={centre: 1}, boundary={0: 0})
    check_result(V, d, r, {centre: 1})


def test_annulus_loops(annulus):
    V, F, d = annulus
    r = d.solve(N=4, boundary={0: 1, 1: -1})
    check_result(V, d, r, {})
    loops, _ = d.cycle_indices(r.directions, N=4)
    assert loops == {0: Fraction(1), 1: Fraction(-1)} == r.boundary


def test_fixed_directions(disk):
    V, F, d = disk
    f0, f1 = 3, d.num_faces - 5
    r = d.solve(N=4, fixed={f0: [1.0, 2.0, 0.0], f1: 0.3})
    check_result(V, d, r, {})
    ref = reference.Mesh(V, d.F)
    want0 = ref.angles_of(np.tile([1.0, 2.0, 0.0], (d.num_faces, 1)))[f0]
    assert abs(reference.reduce(r.angles[f0] - want0, 4)) < 1e-9
    assert abs(reference.reduce(r.angles[f1] - 0.3, 4)) < 1e-9
    assert r.fixed_error < 1e-9
    assert set(r.fixed) == {f0, f1}
    assert list(d._d.fixed_faces) == [f0, f1]
    # Same faces, other directions: no refactorization needed, and the field follows.
    r2 = d.solve(N=4, fixed={f0: 1.0, f1: 0.3})
    assert abs(reference.reduce(r2.angles[f0] - 1.0, 4)) < 1e-9
    # Back to no fixed faces.
    r3 = d.solve(N=4)
    check_result(V, d, r3, {})
    assert len(d._d.fixed_faces) == 0


def test_align_boundary(disk):
    V, F, d = disk
    # The aligned boundary turns once around the flat disk: the interior singularities must sum to 1.
    with pytest.raises(ValueError, match=r"need interior singularities summing to 1 .*, but the prescription's sum to 0; .*auto"):
        d.solve(N=4, align_boundary=True)
    r = d.solve(N=4, singularities={0: 1}, align_boundary=True)
    check_result(V, d, r, {0: 1})
    ref = reference.Mesh(V, d.F)
    boundary_faces = set(int(f) for f in ref.edge_faces[~ref.interior].max(axis=1))
    assert set(r.fixed) == boundary_faces
    # Each boundary face's direction runs along its boundary edge (modulo pi/2).
    for e in np.flatnonzero(~ref.interior):
        f = int(ref.edge_faces[e].max())
        i, j = ref.edges[e]
        t = V[j] - V[i]
        a = ref.angles_of(np.tile(t, (d.num_faces, 1)))[f]
        assert abs(reference.reduce(r.angles[f] - a, 4)) < 1e-9
    # A flat disk's aligned cross field has four +1/4 (found automatically).
    a = d.solve(N=4, singularities="auto", align_boundary=True)
    assert sum(a.singularities.values()) == 1 and all(i == Fraction(1, 4) for i in a.singularities.values())
    assert len(a.singularities) == 4
    assert a.verified


def test_roots_rotate_the_field(cube):
    V, F, corners, d = cube
    sings = {v: "1/4" for v in corners}
    r0 = d.solve(N=4, singularities=sings)
    r1 = d.solve(N=4, singularities=sings, roots={0: r0.angles[0] + 0.5})
    assert np.abs(reference.reduce(r1.angles - r0.angles - 0.5, 4)).max() < 1e-9
    assert np.array_equal(r0.connection, r1.connection)


def test_auto_cube():
    V, F = trivcon.make_cube_sphere(8, spherical=False)  # flat faces: the corners carry all the curvature
    corners = [int(v) for v in np.flatnonzero(reference.valence(F, len(V)) == 3)]
    d = trivcon.FieldDesigner(V, F)
    a = d.auto_singularities(N=4)
    assert a.singularities == {v: Fraction(1, 4) for v in corners} == a.found
    assert a.pairs == [] and a.directions.shape == (d.num_faces, 3)
    r = d.solve(N=4, singularities="auto")
    check_result(V, d, r, a.singularities)
    assert r.auto is not None and r.auto.singularities == a.singularities
    assert set(r.auto.seconds) == {"assemble", "factor", "iterate", "align", "indices", "cancel"}
    assert r.auto.coincident_removed == 0
    assert a.ordering == "AMD"  # 768 faces: below the size where a second order is tried


def test_auto_align_curvature():
    # A fat torus: the smoothest cross field has singularities, the one that follows the principal
    # directions (meridians and parallels) has none, and is solved exactly with none.
    V, F = trivcon.make_torus(96, 24, R=1.0, r=0.4)
    d = trivcon.FieldDesigner(V, F)
    assert len(d.auto_singularities(N=4).singularities) > 0
    a = d.auto_singularities(N=4, align_curvature=-2)
    assert a.singularities == {} and a.seconds["align"] > 0
    r = d.solve(N=4, singularities="auto", align_curvature=0)
    assert r.singularities == {} and r.verified
    with pytest.raises(trivcon.Error, match="need t < 1"):
        d.auto_singularities(N=4, align_curvature=1)
    with pytest.raises(trivcon.Error, match="needs an even N"):
        d.auto_singularities(N=3, align_curvature=0)
    with pytest.raises(trivcon.Error, match="align_curvature must be None or a number"):
        d.auto_singularities(N=4, align_curvature="strong")
    with pytest.raises(trivcon.Error, match="align_curvature needs singularities='auto'"):
        d.solve(N=4, align_curvature=0)


def test_auto_cancel_planted_pair():
    V, F = trivcon.make_icosphere(3)
    d = trivcon.FieldDesigner(V, F)
    a = d.auto_singularities(N=1)
    assert sum(a.singularities.values()) == 2
    # cancel removes only opposite pairs: sums per component are kept.
    c = d.auto_singularities(N=4, cancel=3)
    assert sum(c.singularities.values()) == 2
    assert len(c.found) - 2 * len(c.pairs) == len(c.singularities)


def test_several_components():
    Va, Fa = trivcon.make_icosphere(2)
    Vb, Fb = trivcon.make_torus(16, 8)
    V = np.vstack([Va, Vb + [4, 0, 0]])
    F = np.vstack([Fa, Fb + len(Va)])
    d = trivcon.FieldDesigner(V, F)
    assert len(d.components) == 2 and [c["euler_characteristic"] for c in d.components] == [2, 0]
    r = d.solve(N=2, singularities={0: "1/2", 1: "1/2", 2: "1/2", 3: "1/2"})
    check_result(V, d, r, {0: Fraction(1, 2), 1: Fraction(1, 2), 2: Fraction(1, 2), 3: Fraction(1, 2)})


def test_reoriented_and_unreferenced_faces_keep_ids():
    V, F = trivcon.make_icosphere(2)
    F = F.copy()
    F[[3, 10]] = F[[3, 10]][:, ::-1]  # two faces flipped
    V = np.vstack([V, [[9.0, 9.0, 9.0]]])  # an unreferenced vertex
    d = trivcon.FieldDesigner(V, F)
    assert sorted(d.flipped_faces.tolist()) == [3, 10]
    assert d.unreferenced_vertices.tolist() == [len(V) - 1]
    for f in (3, 10):  # the oriented copy reverses them: (a, b, c) -> (a, c, b)
        assert d.F[f].tolist() == [F[f][0], F[f][2], F[f][1]]
    assert np.array_equal(np.delete(d.F, [3, 10], axis=0), np.delete(F, [3, 10], axis=0))
    r = d.solve(N=1, singularities={0: 1, 5: 1})
    check_result(V, d, r, {0: 1, 5: 1})


def test_designer_arrays(cube):
    V, F, corners, d = cube
    X, Y, Nrm = d.face_frames()
    ref = reference.Mesh(V, d.F)
    assert np.abs(X - ref.X).max() < 1e-12 and np.abs(Y - ref.Y).max() < 1e-12 and np.abs(Nrm - ref.normal).max() < 1e-12
    assert np.array_equal(d.edges, ref.edges) and np.array_equal(d.edge_faces, ref.edge_faces)
    assert d.num_vertices == len(V) and d.num_faces == len(F) and d.num_edges == len(ref.edges)
    assert np.array_equal(d.V, V)
    assert "FieldDesigner" in repr(d) and "verified" in repr(d.solve(N=4, singularities={v: "1/4" for v in corners}))
    assert set(d.timings) >= {"topology", "geometry", "setup", "prepare"}


def test_matching_reads_exactly_the_prescription(tmp_path):
    # A coarse sphere with all of its index at one vertex: the connection turns by pi/N or more next to it,
    # so the closest (principal) matching misreads the field there; our matching reads the prescription.
    V, F = trivcon.make_icosphere(1)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=4, singularities={0: 2})
    assert r.large_turn_edges > 0
    ref = reference.Mesh(V, F)
    assert ref.field_indices(r.directions, 4) != {0: Fraction(2)}
    m = r.matching
    assert m.dtype == np.int64 and m.shape == (len(r.edges),) and ((m >= 0) & (m < 4)).all()
    assert reference.indices_with_matching(ref, r.directions, 4, r.edges, m) == {0: Fraction(2)}
    # The file: Directional's .matching ("N E" then "L R i j m" rows), the same numbers.
    path = tmp_path / "field.matching"
    r.write_matching(path)
    lines = path.read_text().split("\n")
    assert lines[0].split()[0] == "4"
    rows = {}
    for line in lines[1:]:
        parts = line.split()
        if len(parts) == 5:
            rows[(int(parts[2]), int(parts[3]))] = int(parts[4])
    assert rows == {(int(i), int(j)): int(k) for (i, j), k in zip(r.edges, m)}


def test_split_large_turns_lets_a_principal_matching_read_the_prescription():
    # The same coarse sphere: refined where the connection turns by pi/N or more, the field on the refined
    # mesh read by the independent principal matching has exactly the prescription at its vertex ids.
    V, F = trivcon.make_icosphere(1)
    d = trivcon.FieldDesigner(V, F)
    want = {0: Fraction(2)}
    r = d.solve(N=4, singularities={0: 2}, fixed={5: 0.25}, split_large_turns=True)
    assert r.split_converged and len(r.split_rounds) >= 1 and r.verified
    rd = r.designer
    assert rd is not d and rd.num_faces == r.split_rounds[-1]["faces"] > len(F)
    assert np.array_equal(rd.V[: len(V)], V)  # input vertices keep their ids
    assert r.parent_face.shape == (rd.num_faces,) and np.array_equal(r.parent_face[: len(F)], np.arange(len(F)))
    assert r.large_turn_edges == 0
    ref = reference.Mesh(rd.V, rd.F)
    assert ref.field_indices(r.directions, 4) == want
    # Face 5's children hold its direction (a world vector), modulo a quarter turn.
    held = d.face_frames()[0][5] * np.cos(0.25) + d.face_frames()[1][5] * np.sin(0.25)
    children = np.flatnonzero(r.parent_face == 5)
    assert len(children) >= 1 and set(r.fixed) == set(int(c) for c in children)
    for c in children:
        cos = abs(float(np.dot(r.directions[c], held)))
        assert min(abs(cos - 1), cos) < 1e-9
    # Nothing to refine: the same designer, no rounds.
    calm = d.solve(N=4, singularities={0: Fraction(1, 4), 1: Fraction(1, 4), 2: Fraction(1, 4), 3: Fraction(1, 4),
                                       4: Fraction(1, 4), 5: Fraction(1, 4), 6: Fraction(1, 4), 7: Fraction(1, 4)},
                   split_large_turns=True)
    if calm.large_turn_edges == 0:
        assert calm.split_rounds == [] and calm.designer is d
    with pytest.raises(trivcon.Error, match="^split_large_turns makes new generators and boundary loops"):
        d.solve(N=4, singularities={0: 2}, generators={0: 1}, split_large_turns=True)


def test_auto_keeps_the_smoothest_fields_rotation():
    # An ellipsoid: started at angle 0 the exact field is 0.44 rad off the smoothest field on average; with
    # "auto" it takes that field's rotation (as solve --auto does), within a few hundredths of a radian.
    V, F = trivcon.make_icosphere(4)
    V = V * np.array([2.0, 1.0, 0.6])
    d = trivcon.FieldDesigner(V, F)
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    for curvature in (None, 0.0):
        r = d.solve(N=4, singularities="auto", align_curvature=curvature)
        turned = np.sum(area * np.abs(reference.reduce(r.angles - r.auto.angles, 4))) / area.sum()
        plain = d.solve(N=4, singularities=r.singularities)
        started = np.sum(area * np.abs(reference.reduce(plain.angles - r.auto.angles, 4))) / area.sum()
        assert turned < 0.03 and started > 0.2, (curvature, turned, started)
        assert r.verified and r.singularities == plain.singularities
