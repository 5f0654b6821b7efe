# SPDX-License-Identifier: MIT
"""Arrays in, arrays out: singularities as index arrays, all N directions per face, read-only arrays, and the
same short message for every too-large index."""

import math
import re
from fractions import Fraction

import numpy as np
import pytest

import reference
import trivcon


@pytest.fixture(scope="module")
def ball():
    V, F = trivcon.make_icosphere(2)
    return V, F, trivcon.FieldDesigner(V, F)


def test_arrays_handed_out_are_read_only_and_kept(ball, tmp_path):
    V, F, d = ball
    r = d.solve(N=4, singularities={0: "1/2", 7: "3/2"})
    a = d.auto_singularities(N=4)
    arrays = {
        "d.V": lambda: d.V, "d.F": lambda: d.F, "d.F_input": lambda: d.F_input, "d.edges": lambda: d.edges,
        "d.edge_faces": lambda: d.edge_faces, "d.flipped_faces": lambda: d.flipped_faces, "d.boundary_vertices": lambda: d.boundary_vertices,
        "d.unreferenced_vertices": lambda: d.unreferenced_vertices, "d.face_frames()[0]": lambda: d.face_frames()[0],
        "r.directions": lambda: r.directions, "r.angles": lambda: r.angles, "r.edges": lambda: r.edges, "r.connection": lambda: r.connection,
        "r.matching": lambda: r.matching, "r.index_mismatches": lambda: r.index_mismatches, "r.all_directions()": r.all_directions,
        "r.singularity_arrays[1]": lambda: r.singularity_arrays[1], "a.directions": lambda: a.directions, "a.angles": lambda: a.angles,
    }
    for name, get in arrays.items():
        x = get()
        assert get() is x, f"{name} is computed again on each access"
        assert not x.flags.writeable, name
        with pytest.raises(ValueError, match="read-only"):
            x[...] = 0
    # Writing a copy changes nothing the Result writes or reads.
    before = r.directions.copy()
    mine = np.array(r.directions)
    mine[:] = 1.0
    r.write_field(tmp_path / "f.txt")
    directions, _ = trivcon.read_field(tmp_path / "f.txt", len(F))
    assert np.array_equal(r.directions, before) and np.allclose(directions, before, atol=1e-15)
    # Arrays that functions return are new and the caller's.
    V2, F2 = trivcon.read_mesh(trivcon.write_mesh(tmp_path / "m.obj", V, F) or tmp_path / "m.obj")
    V2[0] = 0
    assert V2.flags.writeable and trivcon.render(V, F, r.directions, N=4, size=(40, 30)).flags.writeable


def test_singularities_as_arrays(ball, tmp_path):
    V, F, d = ball
    sings = {0: Fraction(1, 2), 7: Fraction(3, 2)}
    r = d.solve(N=4, singularities=sings)
    ids, numerators = r.singularity_arrays
    assert ids.dtype == numerators.dtype == np.int64
    assert ids.tolist() == [0, 7] and numerators.tolist() == [2, 6]  # index = numerator / N
    # In: the same arrays (any integer dtype) give the same solve as the dict.
    for form in (r.singularity_arrays, (ids.astype(np.int32), numerators.astype(np.int16)), (np.array([7, 0]), np.array([6, 2]))):
        s = d.solve(N=4, singularities=form)
        assert np.array_equal(s.angles, r.angles) and s.singularities == sings
    # Out: the field's own reading, field_indices and read_singularities as arrays, equal to the dicts.
    fv, fn = r.field_singularity_arrays
    assert {int(v): Fraction(int(n), 4) for v, n in zip(fv, fn)} == r.field_singularities
    v2, n2 = trivcon.field_indices(V, F, r.directions, N=4, arrays=True)
    assert np.array_equal(v2, fv) and np.array_equal(n2, fn)
    v3, n3 = d.field_indices(r.directions, N=4, arrays=True)
    assert np.array_equal(v3, fv) and np.array_equal(n3, fn)
    trivcon.write_singularities(tmp_path / "s.sing", r.singularity_arrays, N=4)
    v4, n4 = trivcon.read_singularities(tmp_path / "s.sing", N=4, arrays=True)
    assert np.array_equal(v4, ids) and np.array_equal(n4, numerators)
    assert trivcon.read_singularities(tmp_path / "s.sing", N=4) == sings
    a = d.auto_singularities(N=4)
    av, an = a.singularity_arrays
    assert {int(v): Fraction(int(n), 4) for v, n in zip(av, an)} == a.singularities
    # Generators and boundary loops take them too (the torus: one generator of index 1/4 each).
    Vt, Ft = trivcon.make_torus(24, 12)
    dt = trivcon.FieldDesigner(Vt, Ft)
    g = dt.solve(N=4, generators=(np.array([0, 1]), np.array([4, 1])))
    assert g.generators == {0: Fraction(1), 1: Fraction(1, 4)}


def test_bad_index_arrays(ball):
    V, F, d = ball
    with pytest.raises(trivcon.Error, match=r"^singularities: \(ids, numerators\) must be two 1-D integer arrays of the same length, "
                                            r"got shapes \(2,\) and \(3,\)"):
        d.solve(N=4, singularities=(np.array([0, 1]), np.array([1, 2, 3])))
    with pytest.raises(trivcon.Error, match=r"dtypes int64 and float64$"):
        d.solve(N=4, singularities=(np.array([0, 1]), np.array([4.0, 4.0])))
    with pytest.raises(trivcon.Error, match=r"^singularities\[3\]: given twice$"):
        d.solve(N=4, singularities=(np.array([3, 3]), np.array([4, 4])))
    with pytest.raises(trivcon.Error, match=r"^singularities\[3\]: numerator 4294967296 is too large"):
        d.solve(N=4, singularities=(np.array([3]), np.array([2**32])))
    # Numerators, not indices: 4 is the index 1 (against Gauss-Bonnet's 2 alone), 8 the index 2 (which solves).
    with pytest.raises(trivcon.Error, match="^the indices on component 0 sum to 1, but Gauss-Bonnet"):
        d.solve(N=4, singularities=(np.array([3]), np.array([4])))
    assert d.solve(N=4, singularities=(np.array([3]), np.array([8]))).singularities == {3: Fraction(2)}


def test_all_directions(ball):
    V, F, d = ball
    for N in (1, 3, 4):
        r = d.solve(N=N, singularities={0: Fraction(2 * N - 1, N), 9: Fraction(1, N)})
        D = r.all_directions()
        m = d.num_faces
        assert D.shape == (m, N, 3) and D.dtype == np.float64
        assert np.array_equal(D[:, 0], r.directions)
        ref = reference.Mesh(V, d.F)
        assert np.abs(np.linalg.norm(D, axis=2) - 1).max() < 1e-14
        assert np.abs(np.einsum("mkj,mj->mk", D, ref.normal)).max() < 1e-14
        # Direction k + 1 is direction k turned by 2 pi / N counter-clockwise about the normal.
        if N > 1:
            nxt = np.roll(D, -1, axis=1)
            cos = np.einsum("mkj,mkj->mk", D, nxt)
            sin = np.einsum("mkj,mkj->mk", np.cross(D, nxt), ref.normal[:, None, :])
            assert np.abs(cos - math.cos(2 * math.pi / N)).max() < 1e-14 and np.abs(sin - math.sin(2 * math.pi / N)).max() < 1e-14
        # Any of the N is the same N-direction field: the same indices.
        for k in range(N):
            assert trivcon.field_indices(V, F, D[:, k], N=N) == r.field_singularities
    a = d.auto_singularities(N=4)
    assert np.array_equal(a.all_directions()[:, 0], a.directions) and a.all_directions().shape == (d.num_faces, 4, 3)


TOO_LARGE = re.compile(r"^singularities\[3\]: index \S{1,24} is too large \(\|index\| at most 536870911 with N = 4\)$")


@pytest.mark.parametrize("value", [10**30, -(10**30), 2**62, np.int64(2**62), 1e300, -1e300, 10**400, Fraction(10**30, 3), "1" * 40,
                                   "-" + "9" * 400, str(10**30) + "/7", "1000000000", 536870912, "536870912", 536870912.0])
def test_huge_indices_have_one_short_message(ball, value):
    """Whatever form a too-large index takes, the same message, short, naming the index; including those the
    library's int would have wrapped around (10**9 with N = 4 is 4e9 quarter turns)."""
    V, F, d = ball
    with pytest.raises(trivcon.Error) as e:
        d.solve(N=4, singularities={3: value})
    assert TOO_LARGE.match(str(e.value)), str(e.value)
    assert len(str(e.value)) < 110


def test_largest_index_and_other_huge_numbers(ball):
    V, F, d = ball
    # The largest index that fits (|index| N at most 1e9) passes the checks of size (and fails Gauss-Bonnet,
    # as it must); one quarter turn more is too large, whatever its form.
    for value in (250000000, "250000000", 250000000.0, Fraction(250000000)):
        with pytest.raises(trivcon.Error, match="Gauss-Bonnet"):
            d.solve(N=4, singularities={3: value})
    for value in (Fraction(1000000001, 4), "1000000001/4", 536870911):
        with pytest.raises(trivcon.Error, match="too large"):
            d.solve(N=4, singularities={3: value})
    with pytest.raises(trivcon.Error, match=r"^singularities: id 1e\+30 out of range$"):
        d.solve(N=4, singularities={10**30: 1})
    with pytest.raises(trivcon.Error, match=r"^the symmetry N = 1e\+30 is too large \(at most 2147483647\)$"):
        d.solve(N=10**30)
    with pytest.raises(trivcon.Error, match=r"^singularities\[3\]: malformed index '1e300' \(expected an integer or a fraction p/q"):
        d.solve(N=4, singularities={3: "1e300"})
    with pytest.raises(trivcon.Error, match=r"^singularities\[3\]: malformed index 'xxxxxxxxxxxxxxxxxxxx\.\.\.' \("):
        d.solve(N=4, singularities={3: "x" * 10000})
