# SPDX-License-Identifier: MIT
"""threads=: per designer (OpenMP's count on the thread that runs each call, OpenBLAS single-threaded while a
one-thread call runs), the module's default (set_threads, TRIVCON_THREADS), and the same fields whatever
the count. _core.probe_threads(k) reports what a call with k threads sees from inside."""

import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import trivcon
from trivcon import _core


@pytest.fixture
def default_threads():
    """Restores the module's default (and OpenBLAS's count) after a test that changes them."""
    before = _core.default_threads()
    yield
    trivcon.set_threads(before or None)


def test_what_a_call_sees(default_threads):
    cores = _core.omp_default_threads()
    blas = _core.blas_threads()
    assert _core.probe_threads(1) == (1, 1)  # OpenMP on one thread, OpenBLAS on one thread during the call
    assert _core.blas_threads() == blas  # and OpenBLAS as before after it
    assert _core.probe_threads(3) == (3, blas)
    assert _core.probe_threads(0) == (cores, blas)  # the default: OpenMP's
    trivcon.set_threads(1)
    assert trivcon.get_threads() == 1 and _core.probe_threads(0) == (1, 1) and _core.blas_threads() == 1
    trivcon.set_threads(None)
    assert trivcon.get_threads() == cores and _core.probe_threads(0) == (cores, cores) and _core.blas_threads() == cores


def test_designer_threads(default_threads):
    V, F = trivcon.make_icosphere(4)
    one = trivcon.FieldDesigner(V, F, threads=1)
    assert one.threads == 1 and trivcon.FieldDesigner(*trivcon.make_icosphere(1)).threads is None
    two = trivcon.FieldDesigner(V, F, threads=2)
    sings = {0: 1, 100: 1}
    a, b = one.solve(N=1, singularities=sings), two.solve(N=1, singularities=sings)
    # The same field (to round-off: the factorization's sums split differently over threads) and indices.
    assert np.abs(a.connection - b.connection).max() < 1e-12 and a.singularities == b.singularities and a.field_exact == b.field_exact
    assert one.auto_singularities(N=4).singularities == two.auto_singularities(N=4).singularities
    one.threads = 2
    assert one.threads == 2
    one.threads = None
    assert one.threads is None
    for bad in (0, -1, 1.5, True, "2", 10**30):
        with pytest.raises(trivcon.Error, match="^threads must be None or a whole number from 1 to 4096, not "):
            trivcon.FieldDesigner(V, F, threads=bad)
        with pytest.raises(trivcon.Error, match="^threads must be None or a whole number from 1 to 4096"):
            trivcon.set_threads(bad)


def test_two_designers_in_two_threads(default_threads):
    """With one thread each, two designers in two Python threads give what they give one after the other."""
    meshes = [trivcon.make_icosphere(4), trivcon.make_torus(120, 60)]
    sings = [{0: 1, 100: 1}, {}]
    alone = [trivcon.FieldDesigner(V, F, threads=1).solve(N=1, singularities=s) for (V, F), s in zip(meshes, sings)]
    together = [None, None]

    def work(k):
        V, F = meshes[k]
        together[k] = trivcon.FieldDesigner(V, F, threads=1).solve(N=1, singularities=sings[k])

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(alone, together):
        assert np.array_equal(a.connection, b.connection) and np.array_equal(a.angles, b.angles)


def run(code, **env):
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env={**os.environ, **env}, timeout=60)
    assert p.returncode == 0, p.stderr
    return p


def test_environment_variable():
    code = ("import trivcon; print(trivcon.get_threads(), trivcon._core.blas_threads(), trivcon._core.probe_threads(0)[0], "
            "trivcon._core.omp_default_threads())")
    # (Dask's LocalCluster leaves OMP_NUM_THREADS=1 in this process's environment: the children get 2 explicitly.)
    env = {"OMP_NUM_THREADS": "2", "OPENBLAS_NUM_THREADS": "2"}
    assert run(code, TRIVCON_THREADS="1", **env).stdout.split() == ["1", "1", "1", "2"]
    p = run(code, TRIVCON_THREADS="lots", **env)
    assert "TRIVCON_THREADS='lots' is not a whole number from 1 to 4096: ignored" in p.stderr
    assert p.stdout.split() == ["2", "2", "2", "2"]
