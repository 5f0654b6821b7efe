# SPDX-License-Identifier: MIT
"""FieldDesigner, Result and AutoResult pickle: through pickle, a multiprocessing worker and a Dask worker they
come back giving the same values (a Result is not solved again; a designer is prepared again and factors on
its first solve)."""

import multiprocessing
import pickle

import numpy as np
import pytest

import trivcon


def outputs(r, tmp_path, tag, timings=True):
    """Everything a Result gives: its values, and the bytes of the files it writes (and its timings, unless
    it is compared with another process's solve)."""
    values = {
        "directions": r.directions, "angles": r.angles, "all_directions": r.all_directions(), "edges": r.edges,
        "connection": r.connection, "matching": r.matching, "index_mismatches": r.index_mismatches,
        "unexplained_mismatches": r.unexplained_mismatches, "singularity_arrays": r.singularity_arrays,
        "field_singularity_arrays": r.field_singularity_arrays,
        "scalars": (r.N, r.energy, r.residual, r.rhs_scale, r.transport_mismatch, r.fixed_error, r.large_turn_edges, r.verified,
                    r.field_exact, repr(r)),
        "indices": (r.singularities, r.field_singularities, r.generators, r.generators_chosen, r.boundary, r.boundary_chosen, r.fixed,
                    r.conflicts),
        "picture": r.render(size=(160, 120), supersampling=1),
    }
    if timings:
        values["seconds"] = r.seconds
    for name, write in (("field.txt", r.write_field), ("field.rawfield", r.write_field), ("connection.txt", r.write_connection),
                        ("field.matching", r.write_matching), ("lines.obj", r.write_lines), ("field.sing", r.write_singularities),
                        ("mesh.obj", r.write_mesh)):
        path = tmp_path / f"{tag}.{name}"
        write(path)
        values[name] = path.read_bytes()
    return values


def assert_same(a, b):
    assert a.keys() == b.keys()
    for key in a:
        x, y = a[key], b[key]
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and np.array_equal(x, y), key
        elif isinstance(x, tuple) and x and isinstance(x[0], np.ndarray):
            assert all(np.array_equal(p, q) for p, q in zip(x, y)), key
        else:
            assert x == y, key


@pytest.fixture(scope="module")
def ball():
    V, F = trivcon.make_icosphere(2)
    return V, F, trivcon.FieldDesigner(V, F, weights="unit", weight_floor=0.0, threads=1)


def test_designer_round_trip(ball):
    V, F, d = ball
    e = pickle.loads(pickle.dumps(d))
    assert e is not d and e._d is not d._d
    for name in ("V", "F", "F_input", "edges", "edge_faces", "flipped_faces", "boundary_vertices"):
        assert np.array_equal(getattr(e, name), getattr(d, name)), name
    assert (e.weights, e.solver, e.factorization, e.weight_floor, e.threads) == ("unit", "cholesky", "own", 0.0, 1)
    assert all(np.array_equal(p, q) for p, q in zip(e.face_frames(), d.face_frames()))
    # It factors again on its first solve, and solves as the original does.
    sings = {0: 1, 5: 1}
    a, b = d.solve(N=1, singularities=sings), e.solve(N=1, singularities=sings)
    assert np.array_equal(a.angles, b.angles) and np.array_equal(a.connection, b.connection) and a.energy == b.energy


def test_result_round_trip(ball, tmp_path):
    V, F, d = ball
    r = d.solve(N=4, singularities={0: "3/2", 5: "1/2"}, fixed={7: 0.3})  # large turns: not exact, and a fixed face
    assert not r.field_exact and r.fixed
    q = pickle.loads(pickle.dumps(r))
    assert_same(outputs(r, tmp_path, "a"), outputs(q, tmp_path, "b"))
    assert q.designer is not d and np.array_equal(q.designer.V, V)
    # A result pickled with its designer shares the unpickled designer, as before.
    q, e = pickle.loads(pickle.dumps((r, d)))
    assert q.designer is e
    # The unpickled designer solves (it factors for the fixed face on its first solve).
    again = e.solve(N=4, singularities={0: "3/2", 5: "1/2"}, fixed={7: 0.3})
    assert np.allclose(again.angles, r.angles, atol=1e-12) and again.field_exact == r.field_exact


def test_auto_and_split_results_round_trip(tmp_path):
    V, F = trivcon.make_icosphere(1)
    d = trivcon.FieldDesigner(V, F)
    a = d.solve(N=4, singularities="auto")
    q = pickle.loads(pickle.dumps(a))
    assert_same(outputs(a, tmp_path, "a"), outputs(q, tmp_path, "b"))
    assert q.auto.singularities == a.auto.singularities and q.auto.found == a.auto.found and q.auto.pairs == a.auto.pairs
    assert np.array_equal(q.auto.directions, a.auto.directions) and q.auto.energy == a.auto.energy and q.auto.seconds == a.auto.seconds
    assert q.auto.ordering == a.auto.ordering and np.array_equal(q.auto.all_directions(), a.auto.all_directions())
    # A refined mesh's result: its designer (the refined mesh, with the weights its refinement lowered), the
    # parent faces and the rounds.
    s = d.solve(N=4, singularities={0: 2}, split_large_turns=True)
    assert s.designer is not d and s.field_exact
    q = pickle.loads(pickle.dumps(s))
    assert_same(outputs(s, tmp_path, "c"), outputs(q, tmp_path, "d"))
    assert np.array_equal(q.parent_face, s.parent_face) and not q.parent_face.flags.writeable
    assert q.split_rounds == s.split_rounds and q.split_converged == s.split_converged
    assert q.designer.num_faces == s.designer.num_faces > d.num_faces
    assert q.designer._d.get_state()["edge_weight_scale"] == s.designer._d.get_state()["edge_weight_scale"]


def test_restoring_a_result_on_another_mesh_is_refused(ball):
    V, F, d = ball
    state = d.solve(N=1, singularities={0: 2}).__getstate__()
    state["designer"] = trivcon.FieldDesigner(*trivcon.make_icosphere(1))
    r = trivcon.Result.__new__(trivcon.Result)
    with pytest.raises(trivcon.Error, match="^cannot restore a Result: its arrays do not fit its designer's mesh"):
        r.__setstate__(state)


def solve_in_worker(level):
    """Runs in another process: a designer and an automatic cross field on an icosphere. One thread, here and
    there: the factorization's sums in the same order whatever the process's environment (Dask's LocalCluster
    leaves OMP_NUM_THREADS=1 in it, and a spawned child inherits that)."""
    d = trivcon.FieldDesigner(*trivcon.make_icosphere(level), threads=1)
    return d, d.solve(N=4, singularities="auto")


def test_through_a_multiprocessing_worker(tmp_path):
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        d, r = pool.apply(solve_in_worker, (2,))
    here = solve_in_worker(2)[1]
    assert r.designer is d and d.threads == 1
    assert_same(outputs(r, tmp_path, "worker", timings=False), outputs(here, tmp_path, "here", timings=False))


def test_through_a_dask_worker(tmp_path):
    distributed = pytest.importorskip("distributed", reason="python3-distributed (Dask) is not installed")

    def task(level):  # pickled by value (cloudpickle): the worker needs no test module
        import trivcon as t

        # One thread, as Dask's workers have (OMP_NUM_THREADS=1): the factorization's sums in the same order.
        d = t.FieldDesigner(*t.make_cube_sphere(level), threads=1)
        return d.solve(N=4, singularities="auto", split_large_turns=True)

    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            r = client.submit(task, 6, pure=False).result()
    here = task(6)
    assert_same(outputs(r, tmp_path, "dask", timings=False), outputs(here, tmp_path, "here", timings=False))
    assert np.array_equal(r.parent_face, here.parent_face)
