# SPDX-License-Identifier: MIT
"""Wrong shapes, dtypes and indices raise the documented errors; library errors carry the CLI's message."""

import math
from fractions import Fraction

import numpy as np
import pytest

import trivcon


def raises(message, call, *args, **kwargs):
    """call(*args, **kwargs) raises trivcon.Error (a ValueError) with exactly `message`."""
    with pytest.raises(trivcon.Error) as e:
        call(*args, **kwargs)
    assert isinstance(e.value, ValueError)
    assert str(e.value) == message


@pytest.fixture(scope="module")
def sphere():
    V, F = trivcon.make_icosphere(1)
    return V, F, trivcon.FieldDesigner(V, F)


def test_error_is_a_value_error():
    assert issubclass(trivcon.Error, ValueError)
    assert trivcon.Error.__module__ == "trivcon"


def test_shapes(sphere):
    V, F, d = sphere
    raises("V must have shape (n, 3), got shape (42, 2)", trivcon.FieldDesigner, V[:, :2], F)
    raises("V must have shape (n, 3), got shape (126,)", trivcon.FieldDesigner, V.ravel(), F)
    raises("F must have shape (m, 3), got shape (80, 4)", trivcon.FieldDesigner, V, np.hstack([F, F[:, :1]]))
    raises("F must have shape (m, 3), got shape (240,)", trivcon.FieldDesigner, V, F.ravel())
    raises("V must have shape (n, 3), got shape (2, 42, 3)", trivcon.FieldDesigner, np.stack([V, V]), F)
    r = d.solve(N=1, singularities={0: 1, 1: 1})
    raises("directions must have shape (80, 3), got shape (79, 3)", trivcon.field_indices, V, F, r.directions[:-1], N=1)
    raises("directions must have shape (80, 3), got shape (80, 2)", trivcon.write_field, "x.txt", V, F, r.directions[:, :2])
    raises("directions must have shape (80, 3), got shape (80,)", trivcon.render, V, F, r.angles)
    raises("directions must have shape (80, 3), got shape (80, 3, 1)", d.field_indices, r.directions[:, :, None])
    raises("image must have shape (h, w, 3), got shape (4, 4)", trivcon.write_png, "x.png", np.zeros((4, 4), np.uint8))


def test_dtypes(sphere):
    V, F, d = sphere
    raises("F must hold integers, got dtype float64", trivcon.FieldDesigner, V, F.astype(float))
    raises("V must hold real numbers, got dtype complex128", trivcon.FieldDesigner, V.astype(complex), F)
    raises("V must hold real numbers, got dtype bool", trivcon.FieldDesigner, V > 0, F)
    raises("V must hold real numbers, got dtype <U1", trivcon.FieldDesigner, np.full((3, 3), "a"), F)
    raises("F must hold integers, got dtype bool", trivcon.FieldDesigner, V, F > 0)
    raises("image must hold uint8 values, got dtype float64", trivcon.write_png, "x.png", np.zeros((4, 4, 3)))
    with pytest.raises(trivcon.Error, match="^V must be an array: "):
        trivcon.FieldDesigner([[0, 0, 0], [1, 0]], F)


def test_other_dtypes_and_layouts_are_accepted(sphere):
    V, F, d = sphere
    sings = {0: 1, 1: 1}
    want = d.solve(N=1, singularities=sings)
    variants = [
        (np.asfortranarray(V), np.asfortranarray(F)),
        (V, F.astype(np.int64)),
        (V, F.astype(np.uint32)),
        (V, F.astype(np.int16)),
        (V.tolist(), F.tolist()),
        (np.repeat(V, 2, axis=0)[::2], np.repeat(F, 2, axis=0)[::2]),  # strided views
    ]
    for Vx, Fx in variants:
        assert np.array_equal(trivcon.FieldDesigner(Vx, Fx).solve(N=1, singularities=sings).angles, want.angles)
    # float32 V: converted to float64, solves and verifies.
    r = trivcon.FieldDesigner(V.astype(np.float32), F).solve(N=1, singularities=sings)
    assert r.verified
    # Non-contiguous views of a bigger array.
    big = np.zeros((len(V), 6))
    big[:, ::2] = V
    assert np.array_equal(trivcon.FieldDesigner(big[:, ::2], F[::-1][::-1]).solve(N=1, singularities=sings).angles, want.angles)


def test_face_ids_beyond_int32(sphere):
    V, F, d = sphere
    G = F.astype(np.int64)
    G[5, 1] = 2**40
    raises(f"vertex index {2**40} out of range in face 5 (mesh has 42 vertices)", trivcon.FieldDesigner, V, G)
    G = F.astype(np.int64)
    G[7, 2] = -(2**35)
    raises(f"vertex index {-(2**35)} out of range in face 7 (mesh has 42 vertices)", trivcon.FieldDesigner, V, G)


def test_library_mesh_errors(sphere):
    V, F, d = sphere
    G = F.copy()
    G[7, 2] = 42
    raises("vertex index 42 out of range in face 7 (mesh has 42 vertices)", trivcon.FieldDesigner, V, G)
    G = F.copy()
    G[3, 1] = G[3, 0]
    raises(f"face 3 has a repeated vertex ({G[3, 0]}, {G[3, 0]}, {G[3, 2]})", trivcon.FieldDesigner, V, G, repair=False)
    W = V.copy()
    W[12, 1] = np.nan
    raises("non-finite coordinate in vertex 12", trivcon.FieldDesigner, W, F)
    with pytest.raises(trivcon.Error, match=r"^non-manifold edge \("):
        trivcon.FieldDesigner(V, np.vstack([F, F[:1]]), repair=False)


def test_index_errors(sphere):
    V, F, d = sphere
    raises("singularities[3]: index 1/3 is not a multiple of 1/4 (use -N to change the symmetry)", d.solve, N=4,
           singularities={3: "1/3"})
    raises("singularities[3]: index 1/3 is not a multiple of 1/4 (use -N to change the symmetry)", d.solve, N=4,
           singularities={3: Fraction(1, 3)})
    raises("singularities[3]: index 0.3 is not a multiple of 1/4", d.solve, N=4, singularities={3: 0.3})
    raises("singularities[3]: index nan is not finite", d.solve, N=4, singularities={3: math.nan})
    raises("singularities[3]: malformed index 'abc' (expected an integer or a fraction p/q, q > 0)", d.solve, N=4,
           singularities={3: "abc"})
    raises("singularities[3]: malformed index '1/0' (expected an integer or a fraction p/q, q > 0)", d.solve, N=4,
           singularities={3: "1/0"})
    raises("singularities[3]: an index must be an int, a float, a fractions.Fraction or a 'p/q' string, not list", d.solve, N=4,
           singularities={3: [1]})
    raises("singularities[3]: an index must be an int, a float, a fractions.Fraction or a 'p/q' string, not a bool", d.solve, N=4,
           singularities={3: True})
    raises("singularities: ids must be integers, got '3'", d.solve, N=4, singularities={"3": 1})
    raises("singularities: ids must be integers, got 3.0", d.solve, N=4, singularities={3.0: 1})
    raises("generators[0]: index 1/8 is not a multiple of 1/4 (use -N to change the symmetry)", d.solve, N=4, generators={0: "1/8"})
    raises("boundary[0]: index 0.1 is not a multiple of 1/4", d.solve, N=4, boundary={0: 0.1})
    raises("singularities[2]: given twice", d.solve, N=1, singularities=[(2, 1), (2, 1)])
    raises("N must be an integer, got 4.0", d.solve, N=4.0)
    raises("the symmetry N must be at least 1 (got 0)", d.solve, N=0)
    raises("singularities must be a dict {id: index}, a list of (id, index) pairs or a tuple (ids, numerators) of two integer arrays, "
           "not int", d.solve, N=1, singularities=5)


def test_prescription_errors_are_the_librarys(sphere, annulus):
    V, F, d = sphere
    raises("the indices on component 0 sum to 1, but Gauss-Bonnet needs its Euler characteristic 2", d.solve, N=1,
           singularities={0: 1})
    raises("the indices on component 0 sum to 3/4, but Gauss-Bonnet needs its Euler characteristic 2", d.solve, N=4,
           singularities={0: 0.75})
    raises("singular vertex 42 out of range (mesh has 42 vertices)", d.solve, N=1, singularities={42: 1, 0: 1})
    raises("singular vertex -1 out of range (mesh has 42 vertices)", d.solve, N=1, singularities={-1: 1, 0: 1})
    raises("generator 0 out of range (the mesh has 0 generators)", d.solve, N=1, singularities={0: 2}, generators={0: 1})
    raises("boundary loop 0 out of range (the mesh has 0 boundary loops)", d.solve, N=1, singularities={0: 2}, boundary={0: 1})
    raises("fixed face 80 out of range (mesh has 80 faces)", d.solve, N=1, singularities={0: 2}, fixed={80: 0.0})
    raises("fixed direction of face 2 is zero", d.solve, N=1, singularities={0: 2}, fixed={2: (0, 0, 0)})
    raises("fixed[2]: expected an angle (radians, in the face's frame) or a direction (x, y, z), got (1, 0)", d.solve, N=1,
           fixed={2: (1, 0)})
    raises("root face 99 out of range (mesh has 80 faces)", d.solve, N=1, singularities={0: 2}, roots={99: 0.0})
    Va, Fa, da = annulus
    v = int(da.boundary_loops[0][0])
    with pytest.raises(trivcon.Error, match=rf"^singular vertex {v} is on boundary loop 0: a boundary vertex has no dual cycle"):
        da.solve(N=1, singularities={v: 1})
    raises("auto_cancel needs singularities='auto'", d.solve, N=4, auto_cancel=2)
    raises("weights must be 'cotan' or 'unit', not 'area'", trivcon.FieldDesigner, V, F, weights="area")
    raises("weight_floor must be in [0, 1] (a fraction of the median weight), not 1.500000", trivcon.FieldDesigner, V, F,
           weight_floor=1.5)
    raises("weight_floor must be a number in [0, 1], not 'a'", trivcon.FieldDesigner, V, F, weight_floor="a")


def test_file_errors_match_the_cli(tmp_path, cli):
    """A broken file: the module's message is what the CLI prints after 'trivcon: error: '."""
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(trivcon.Error) as e:
        trivcon.read_mesh(str(bad))
    p = cli("info", bad, check=False)
    assert p.returncode == 1
    assert p.stderr.strip() == f"trivcon: error: {e.value}"
    assert str(bad) in str(e.value) and ":4:" in str(e.value)
    # A mesh error found by the topology (non-manifold edge): the same again, through FieldDesigner.
    V, F = trivcon.make_icosphere(1)
    nm = tmp_path / "nonmanifold.obj"
    trivcon.write_mesh(str(nm), V, F)
    with open(nm, "a") as f:
        f.write("v 5 5 5\nf %d %d 43\n" % (F[0][0] + 1, F[0][1] + 1))
    V2, F2 = trivcon.read_mesh(str(nm))
    with pytest.raises(trivcon.Error) as e:
        trivcon.FieldDesigner(V2, F2, repair=False)
    p = cli("solve", nm, "--no-repair", "--sing", "0:2", check=False)
    assert p.returncode == 1 and p.stderr.strip() == f"trivcon: error: {e.value}"
    # A prescription error: --sing 0:1/3 -N 4 against singularities={0: "1/3"}, past the "where" prefix.
    d = trivcon.FieldDesigner(V, F)
    with pytest.raises(trivcon.Error) as e:
        d.solve(N=1, singularities={0: 1})
    sphere = tmp_path / "sphere.obj"
    trivcon.write_mesh(str(sphere), V, F)
    p = cli("solve", sphere, "--sing", "0:1", check=False)
    assert p.returncode == 1 and p.stderr.strip() == f"trivcon: error: {e.value}"
    raises(f"cannot open '{tmp_path / 'missing.obj'}': No such file or directory", trivcon.read_mesh, str(tmp_path / "missing.obj"))
