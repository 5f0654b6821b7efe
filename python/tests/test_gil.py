# SPDX-License-Identifier: MIT
"""Long calls release the GIL: another Python thread runs while they work.

No clocks: the switch interval is made huge, so that a thread holding the GIL is never made to hand it over;
a counting thread can then only run while the main thread is inside a call that released it. Each call is
made with a flag up; the counter thread counts only while the flag is up.
"""

import sys
import threading
import time

import numpy as np
import pytest

import trivcon


class Counter:
    def __init__(self):
        self.inside = False
        self.count = 0
        self.stop = False
        self.thread = threading.Thread(target=self.run, daemon=True)

    def run(self):
        while not self.stop:
            if self.inside:
                self.count += 1
            time.sleep(0)  # releases the GIL, so the main thread gets it back as soon as it wants it


@pytest.fixture
def counting():
    old = sys.getswitchinterval()
    c = Counter()
    c.thread.start()
    sys.setswitchinterval(1000.0)
    try:
        yield c
    finally:
        sys.setswitchinterval(old)
        c.stop = True
        c.thread.join()


def counted(c, call, *args, **kwargs):
    """How often the counter thread ran during call(...), and its result. On a loaded machine the counter
    thread may not get a core during one short call even when the GIL is free, so the call is repeated (up to
    20 times) until the counter moves; a call that holds the GIL never lets it move, however often."""
    for _ in range(20):
        c.count = 0
        c.inside = True
        result = call(*args, **kwargs)
        c.inside = False
        if c.count > 0:
            break
    return c.count, result


@pytest.fixture(scope="module")
def big():
    V, F = trivcon.make_icosphere(5)  # 20k faces: each call below takes far longer than a thread switch
    return V, F


def test_long_calls_release_the_gil(counting, big, tmp_path):
    V, F = big
    n, d = counted(counting, trivcon.FieldDesigner, V, F)
    assert n > 0, "FieldDesigner (set-up and factorization) held the GIL"
    sings = {0: 1, 11: 1}
    n, r = counted(counting, d.solve, N=1, singularities=sings)
    assert n > 0, "solve held the GIL"
    n, a = counted(counting, d.auto_singularities, N=4)
    assert n > 0, "auto_singularities held the GIL"
    n, image = counted(counting, trivcon.render, V, F, r.directions, N=1, size=(300, 200))
    assert n > 0, "render held the GIL"
    n, _ = counted(counting, r.render, size=(300, 200))
    assert n > 0, "Result.render held the GIL"
    n, _ = counted(counting, trivcon.field_indices, V, F, r.directions, N=1)
    assert n > 0, "field_indices held the GIL"
    path = str(tmp_path / "big.obj")
    trivcon.write_mesh(path, V, F)
    n, _ = counted(counting, trivcon.read_mesh, path)
    assert n > 0, "read_mesh held the GIL"


def test_the_check_detects_a_call_that_holds_the_gil(counting):
    """The method above sees a call that keeps the GIL: the counter does not move during it."""
    def busy():
        total = 0
        for i in range(300000):  # pure Python: holds the GIL throughout (the switch interval is huge)
            total += i
        return total

    n, _ = counted(counting, busy)
    assert n == 0


def test_threads_share_a_designer(big):
    """Solves from several threads at once on one designer give the single-threaded results."""
    V, F = big
    d = trivcon.FieldDesigner(V, F)
    sets = [{0: 1, 11: 1}, {0: 2}, {5: 1, 7: 1}, {3: "1/2", 9: "3/2"}]
    want = [d.solve(N=2 if any(isinstance(i, str) for i in s.values()) else 1, singularities=s).angles for s in sets]
    results = [None] * len(sets)

    def work(k):
        s = sets[k]
        results[k] = d.solve(N=2 if any(isinstance(i, str) for i in s.values()) else 1, singularities=s).angles

    threads = [threading.Thread(target=work, args=(k,)) for k in range(len(sets))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for got, expected in zip(results, want):
        assert np.array_equal(got, expected)
