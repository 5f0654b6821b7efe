# SPDX-License-Identifier: MIT
"""Result.field_exact: whether the per-face field, read on its own, shows exactly the prescription.

`verified` is about the connection (its holonomy, the field's transport by it); a field sampled once per face
and read with the closest (principal) matching, as every other tool reads it, misses an index wherever the
connection turns by pi/N or more across an edge. field_exact says whether it does, judged here by the
independent reader of reference.py.
"""

import os
from fractions import Fraction

import pytest

import reference
import trivcon


def read_by_reference(d, r):
    """The field's vertex indices as an independent reader sees them: {vertex: Fraction}, nonzero only."""
    return reference.Mesh(d.V, d.F).field_indices(r.directions, r.N)


def mismatched_vertices(read, prescribed):
    return {v for v in set(read) | set(prescribed) if read.get(v, 0) != prescribed.get(v, 0)}


def test_a_verified_field_that_is_not_exact_says_so():
    # A coarse sphere with all of its index at one vertex: the connection turns by pi/N or more around it.
    V, F = trivcon.make_icosphere(1)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=4, singularities={0: 2})
    assert r.verified and r.large_turn_edges > 0
    read = read_by_reference(d, r)
    assert read != {0: Fraction(2)}
    assert r.field_exact is False
    assert set(r.index_mismatches.tolist()) == mismatched_vertices(read, {0: Fraction(2)})
    k = len(r.index_mismatches)
    assert repr(r).endswith(f", verified, field NOT exact: {k} vertices read other indices (large turns); use split_large_turns=True>")
    # Refined where it turns that much: the field read on its own is the prescription, and says so.
    s = d.solve(N=4, singularities={0: 2}, split_large_turns=True)
    assert s.split_converged and s.large_turn_edges == 0
    assert read_by_reference(s.designer, s) == {0: Fraction(2)}
    assert s.field_exact is True and len(s.index_mismatches) == 0
    assert repr(s).endswith(", verified, field exact>")


def test_exact_fields(cube, torus):
    V, F, corners, d = cube
    r = d.solve(N=4, singularities={v: "1/4" for v in corners})
    assert r.field_exact and r.verified
    assert read_by_reference(d, r) == {v: Fraction(1, 4) for v in corners}
    Vt, Ft, dt = torus
    r = dt.solve(N=1)
    assert r.field_exact and read_by_reference(dt, r) == {}


@pytest.mark.parametrize("N, sings", [(1, {0: 2}), (2, {0: 1, 1: 1}), (4, {0: "3/2", 5: "1/2"}), (4, {v: "1/4" for v in range(8)}),
                                      (6, {0: 2}), (4, {0: 3, 1: -1})])
def test_field_exact_is_what_a_reader_sees(N, sings):
    """Over prescriptions with and without large turns: field_exact exactly when the independent reading
    of the field is the prescription, and index_mismatches are the vertices where it is not."""
    V, F = trivcon.make_icosphere(2)
    d = trivcon.FieldDesigner(V, F)
    r = d.solve(N=N, singularities=sings)
    prescribed = {v: Fraction(i) for v, i in sings.items()}
    read = read_by_reference(d, r)
    assert r.field_exact == (read == prescribed)
    assert set(r.index_mismatches.tolist()) == mismatched_vertices(read, prescribed)
    assert r.field_singularities == read


@pytest.mark.parametrize("name", ["kitten.off", "camelhead.off"])
def test_real_meshes_from_the_issue(shared_meshes, name):
    """Two of the issue's meshes whose automatic cross field verified but read other singularities."""
    d = trivcon.FieldDesigner(*trivcon.read_mesh(os.path.join(shared_meshes, name)))
    r = d.solve(N=4, singularities="auto")
    assert r.verified and not r.field_exact
    assert read_by_reference(d, r) != r.singularities
    assert "field NOT exact" in repr(r)
    s = d.solve(N=4, singularities="auto", split_large_turns=True)
    assert s.verified and s.field_exact
    assert read_by_reference(s.designer, s) == s.singularities == r.singularities
