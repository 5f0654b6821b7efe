# SPDX-License-Identifier: MIT
"""Ctrl-C: a long call raises KeyboardInterrupt within a fraction of a second of SIGINT, the abandoned work
stops, and the module (and the designer) stay usable.

Each case runs a child Python that prepares, prints "ready", makes one long call and reports how it ended;
the parent sends SIGINT shortly after "ready" and times the child's report. The calls take several seconds on
these meshes (4-5 s to set up 1.08M faces, about 4 s for the automatic placement on 480k on the 2-core
machine of BENCHMARKS.md), so an uninterruptible call would miss the bounds below by far; the bounds are
generous next to what is measured (about 20 ms to the KeyboardInterrupt).
"""

import signal
import subprocess
import sys
import time

import pytest

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")

PREAMBLE = r"""
import sys, time
import trivcon
def report(*words):
    print(*words, flush=True)
"""


def interrupt(code, delay=0.5, timeout=120):
    """Runs `code` in a child; SIGINT `delay` s after it prints "ready". Returns (lines with the seconds
    after the signal at which each arrived, return code, stderr)."""
    child = subprocess.Popen([sys.executable, "-c", PREAMBLE + code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = child.stdout.readline()
        assert line.strip() == "ready", line + child.stderr.read()
        time.sleep(delay)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        lines = [(time.monotonic() - sent, line.strip()) for line in child.stdout]
        child.wait(timeout=timeout)
        return lines, child.returncode, child.stderr.read(), time.monotonic() - sent
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def test_designer_set_up_is_interrupted():
    code = r"""
V, F = trivcon.make_cube_sphere(300)           # 1.08M faces
report("ready")
try:
    trivcon.FieldDesigner(V, F)
    report("finished")
except KeyboardInterrupt:
    report("interrupted")
    t = time.monotonic()
    left = trivcon._core.wait_for_background(30)  # the abandoned set-up stops at its next safe point
    report("stopped", left, time.monotonic() - t, trivcon._core.background_running())
# The module still works.
d = trivcon.FieldDesigner(*trivcon.make_icosphere(2))
r = d.solve(N=1, singularities={0: 1, 5: 1})
report("works", r.verified, r.field_exact)
"""
    lines, status, err, _ = interrupt(code)
    words = {line.split()[0]: (t, line.split()[1:]) for t, line in lines}
    assert "finished" not in words, "the set-up ended before the signal: the mesh is too small for this machine"
    assert "interrupted" in words, err
    assert words["interrupted"][0] < 1.0  # KeyboardInterrupt within a second of SIGINT
    _, (left, seconds, running) = words["stopped"]
    assert left == "True" and running == "0" and float(seconds) < 3.0
    assert words["works"][1] == ["True", "True"] and status == 0, err


def test_automatic_placement_is_interrupted_and_the_designer_stays_usable():
    code = r"""
V, F = trivcon.make_cube_sphere(200)           # 480k faces
d = trivcon.FieldDesigner(V, F)
report("ready")
try:
    d.solve(N=4, singularities="auto")
    report("finished")
except KeyboardInterrupt:
    report("interrupted")
trivcon._core.wait_for_background(30)
# The designer is as it was: the cube's corners (its vertices of valence 3) solve and read back exactly.
import numpy as np
valence = np.bincount(F.ravel(), minlength=len(V))
sings = {int(v): "1/4" for v in np.flatnonzero(valence == 3)}
r = d.solve(N=4, singularities=sings)
report("works", r.verified, r.field_exact, len(sings))
"""
    lines, status, err, _ = interrupt(code)
    words = {line.split()[0]: (t, line.split()[1:]) for t, line in lines}
    assert "finished" not in words and "interrupted" in words, err
    assert words["interrupted"][0] < 1.0
    assert words["works"][1] == ["True", "True", "8"] and status == 0, err


def test_an_uncaught_interrupt_ends_the_program():
    code = r"""
V, F = trivcon.make_cube_sphere(300)
report("ready")
trivcon.FieldDesigner(V, F)
report("finished")
"""
    lines, status, err, seconds = interrupt(code)
    assert lines == [] and "KeyboardInterrupt" in err.splitlines()[-1]
    assert status in (-signal.SIGINT, 128 + signal.SIGINT)  # Python ends by SIGINT after an uncaught KeyboardInterrupt
    assert seconds < 3.0  # the abandoned set-up stopped at a safe point: the exit did not wait for it to finish


def test_a_call_that_polls_is_stopped_at_once():
    """The cancellation hook itself (_core.sleep_interruptibly polls it every millisecond): the abandoned
    work ends right after the KeyboardInterrupt, not after its 60 s."""
    code = r"""
report("ready")
try:
    trivcon._core.sleep_interruptibly(60.0)
    report("finished")
except KeyboardInterrupt:
    report("interrupted")
    t = time.monotonic()
    report("stopped", trivcon._core.wait_for_background(10), time.monotonic() - t)
"""
    lines, status, err, _ = interrupt(code, delay=0.2)
    words = {line.split()[0]: (t, line.split()[1:]) for t, line in lines}
    assert words["interrupted"][0] < 1.0 and words["stopped"][1][0] == "True" and float(words["stopped"][1][1]) < 0.5
    assert status == 0, err


def test_other_threads_are_not_interrupted():
    """A call waiting in another Python thread is not abandoned by the main thread's KeyboardInterrupt."""
    code = r"""
import threading
out = {}
def work():
    out["slept"] = trivcon._core.sleep_interruptibly(1.5)
t = threading.Thread(target=work)
t.start()
report("ready")
try:
    trivcon._core.sleep_interruptibly(60.0)
except KeyboardInterrupt:
    report("interrupted")
t.join()
report("thread", out.get("slept"))
"""
    lines, status, err, _ = interrupt(code, delay=0.2)
    assert [line for _, line in lines] == ["interrupted", "thread 1.5"] and status == 0, err


def test_exit_cancels_the_calls_of_daemon_threads():
    """At exit only daemon threads can still be inside a call: it is cancelled, and the program ends without
    waiting for it (nor unloading the libraries under it)."""
    code = r"""
import threading
V, F = trivcon.make_cube_sphere(300)
threading.Thread(target=trivcon.FieldDesigner, args=(V, F), daemon=True).start()
threading.Thread(target=trivcon._core.sleep_interruptibly, args=(60.0,), daemon=True).start()
time.sleep(0.3)
report("leaving", trivcon._core.background_running(), time.monotonic())
"""
    child = subprocess.run([sys.executable, "-c", PREAMBLE + code], capture_output=True, text=True, timeout=120)
    ended = time.monotonic()  # the same clock as the child's (CLOCK_MONOTONIC)
    words = child.stdout.split()
    assert words[:2] == ["leaving", "2"] and child.returncode == 0, child.stderr
    # From the last line of the program to the end of the process: the cancelled set-up stopped at a safe
    # point, and the 60 s sleep at once.
    assert ended - float(words[2]) < 3.0
