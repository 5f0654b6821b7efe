# SPDX-License-Identifier: MIT
"""FieldDesigner.relax and solve(relax=True): singularities moved downhill in the field's energy, from Python,
checked against real solves and against `trivcon solve --relax`."""

import json
import pickle
from fractions import Fraction

import numpy as np
import pytest

import trivcon


def corners_and_start():
    """A box (cube sphere, flat sides), its 8 valence-3 corners, and a vertex one or two edges from each."""
    V, F = trivcon.make_cube_sphere(6, spherical=False)
    neighbours = [set() for _ in range(len(V))]
    for a, b, c in F:
        for x, y in ((a, b), (b, c), (c, a)):
            neighbours[x].add(int(y))
            neighbours[y].add(int(x))
    corners = [v for v in range(len(V)) if len(neighbours[v]) == 3]
    start = []
    for k, c in enumerate(corners):
        ring, seen = {c}, {c}
        for _ in range(1 + k % 2):
            ring = {u for x in ring for u in neighbours[x]} - seen
            seen |= ring
        start.append(min(ring))
    return V, F, corners, start


def test_quarter_singularities_reach_the_box_corners():
    V, F, corners, start = corners_and_start()
    d = trivcon.FieldDesigner(V, F)
    r = d.relax({v: "1/4" for v in start}, N=4)
    assert r.converged
    assert r.singularities == {c: Fraction(1, 4) for c in corners}
    vertices, numerators = r.singularity_arrays
    assert vertices.tolist() == sorted(corners) and numerators.tolist() == [1] * 8
    assert len(r.moves["from"]) == 12  # four one edge away, four two edges away
    assert r.energies[0] == r.energy_before and r.energies[-1] == r.energy_after
    assert np.all(np.diff(r.energies) < 0)
    assert np.array_equal(r.moves["energy"], r.energies[1:])
    assert not r.moves["cancelled"].any() and np.all(r.moves["index"] == 1)
    assert r.energy_after < 1e-9 * r.energy_before
    # The Result is the relaxed field, and solving the relaxed placement again gives the same energy.
    assert r.result.verified and r.result.singularities == r.singularities
    assert abs(d.solve(4, r.singularities).energy - r.energy_after) <= 1e-12 * max(1.0, r.energy_after)
    assert "12 moves" in repr(r)


def test_solve_with_relax_after_auto_and_pins():
    V, F, corners, start = corners_and_start()
    d = trivcon.FieldDesigner(V, F)
    res = d.solve(4, {v: "1/4" for v in start}, relax=True, relax_pins=[start[1], corners[0]])
    assert isinstance(res.relax, trivcon.RelaxResult)
    assert start[1] in res.singularities and corners[0] not in res.singularities
    assert all(c in res.singularities for c in corners[2:])
    assert res.energy == pytest.approx(res.relax.energy_after, rel=1e-12)
    one = d.solve(4, {v: "1/4" for v in start}, relax=True, relax_max_moves=1)
    assert len(one.relax.moves["from"]) == 1 and not one.relax.converged
    auto = d.solve(4, "auto", relax=True)
    assert auto.auto is not None and auto.relax.converged
    assert auto.relax.energy_after <= auto.relax.energy_before
    assert d.solve(4, {v: "1/4" for v in corners}).relax is None


def test_relax_pickles_with_its_result():
    V, F, corners, start = corners_and_start()
    d = trivcon.FieldDesigner(V, F)
    res = d.solve(4, {v: "1/4" for v in start}, relax=True)
    back = pickle.loads(pickle.dumps(res))
    assert back.relax.singularities == res.relax.singularities
    assert np.array_equal(back.relax.energies, res.relax.energies)
    assert back.relax.converged == res.relax.converged


def test_relax_errors_are_named():
    V, F, corners, start = corners_and_start()
    d = trivcon.FieldDesigner(V, F)
    sings = {v: "1/4" for v in start}
    with pytest.raises(trivcon.Error, match="relax: pinned vertex 100000 out of range"):
        d.relax(sings, N=4, pins=[100000])
    with pytest.raises(trivcon.Error, match="relax_max_moves must be a whole number >= 0, not -1"):
        d.relax(sings, N=4, max_moves=-1)
    with pytest.raises(trivcon.Error, match="relax_cancel must be a whole number >= 0, not 1.5"):
        d.relax(sings, N=4, cancel_distance=1.5)
    with pytest.raises(trivcon.Error, match="need relax=True"):
        d.solve(4, sings, relax_pins=[3])
    with pytest.raises(trivcon.Error, match="sum to"):
        d.relax({start[0]: "1/4"}, N=4)


def test_same_as_the_program(cli, tmp_path):
    V, F, corners, start = corners_and_start()
    mesh = tmp_path / "box.obj"
    trivcon.write_mesh(str(mesh), V, F)
    report = tmp_path / "r.json"
    args = ["solve", mesh, "-N", "4", "--relax", "--report", report]
    for v in start:
        args += ["--sing", f"{v}:1/4"]
    cli(*args)
    j = json.loads(report.read_text())["relax"]
    r = trivcon.FieldDesigner(V, F).relax({v: "1/4" for v in start}, N=4)
    assert [m["from"] for m in j["moves"]] == r.moves["from"].tolist()
    assert [m["to"] for m in j["moves"]] == r.moves["to"].tolist()
    assert j["energy_after"] == pytest.approx(r.energy_after, rel=1e-12, abs=1e-15)


def annulus_with_a_pair():
    """An annulus with both boundaries aligned (two loops, so two components of fixed faces) and a +1/4, -1/4
    pair off-centre: the periods of the conformal scale around the loops are not 0."""
    V, F = trivcon.make_annulus(10, 48)
    interior = np.ones(len(V), bool)
    edges = {}
    for a, b, c in F:
        for x, y in ((a, b), (b, c), (c, a)):
            key = (min(x, y), max(x, y))
            edges[key] = edges.get(key, 0) + 1
    for (x, y), n in edges.items():
        if n == 1:
            interior[x] = interior[y] = False
    ids = np.flatnonzero(interior)
    plus = int(ids[np.argmin(np.linalg.norm(V[ids] - [0.62, 0.25, 0], axis=1))])
    minus = int(ids[np.argmin(np.linalg.norm(V[ids] - [0.85, -0.2, 0], axis=1))])
    return V, F, {plus: "1/4", minus: "-1/4"}


def test_periods_and_reach(cli, tmp_path):
    V, F, sings = annulus_with_a_pair()
    d = trivcon.FieldDesigner(V, F)
    plain = d.relax(sings, N=4, align_boundary=True)
    assert plain.periods_before is None and plain.periods_after is None
    r = d.relax(sings, N=4, align_boundary=True, reach=3, period_weight=1.0)
    assert r.periods_before > 1e-6 and r.periods_after < r.periods_before
    assert r.energies[0] == pytest.approx(r.energy_before + r.periods_before, rel=1e-12)
    assert r.energies[-1] == pytest.approx(r.energy_after + r.periods_after, rel=1e-12)
    assert np.all(np.diff(r.energies) < 0)
    # The program relaxes the same way and reports the periods.
    mesh = tmp_path / "annulus.obj"
    trivcon.write_mesh(str(mesh), V, F)
    report = tmp_path / "r.json"
    args = ["solve", mesh, "-N", "4", "--align-boundary", "--relax", "--relax-reach", "3", "--relax-periods", "1", "--report", report]
    for v, k in sings.items():
        args += ["--sing", f"{v}:{k}"]
    out = cli(*args)
    j = json.loads(report.read_text())["relax"]
    assert [m["to"] for m in j["moves"]] == r.moves["to"].tolist()
    assert j["periods_after"] == pytest.approx(r.periods_after, rel=1e-9, abs=1e-12)
    assert "periods " in out.stdout


def test_reach_and_periods_errors_are_named():
    V, F, sings = annulus_with_a_pair()
    d = trivcon.FieldDesigner(V, F)
    with pytest.raises(trivcon.Error, match="relax_reach must be a whole number >= 1, not 0"):
        d.relax(sings, N=4, align_boundary=True, reach=0)
    with pytest.raises(trivcon.Error, match="relax_periods must be a number >= 0, not -1"):
        d.relax(sings, N=4, align_boundary=True, period_weight=-1)
    with pytest.raises(trivcon.Error, match="need relax=True"):
        d.solve(4, sings, align_boundary=True, relax_reach=2)
