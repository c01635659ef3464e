"""The still picture's worker process (issue 26, item 8): it draws what the window would, the newest request
wins, and a worker that dies, hangs or cannot start never takes the app down: its requests fail (the window
then draws the picture itself) and the next request starts a new worker.

Under Xvfb (the worker opens its own X connection). Each test has a worker of its own (not the window's);
no timing: a stopped worker (SIGSTOP) is how a request is kept in flight, and every wait is for an event.
"""

import os
import signal
import sys

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from gcmh_core.examples import load_example

from app_helpers import small_div, torus_complex

WAIT_MS = 120_000


@pytest.fixture
def payload():
    """``payload(size)``: a small see-through torus in R^4, coloured, pickled as the window asks for its still
    picture."""
    import pyvista as pv

    from gcmh_studio.camera import camera_values, default_camera
    from gcmh_studio.offscreen import still_payload
    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Style
    from gcmh_studio.sections import SectionScene

    cx = torus_complex(12, 4)
    pl = pv.Plotter(off_screen=True, window_size=[200, 150])   # (never rendered: no GL context here)
    try:
        sc = SectionScene(pl, anti_aliasing=None)
        sc.set_complex(cx, ["x", "y", "z", "w"], ProjectionModel(n=4).view(),
                       Style(color_by="w", opacity=0.5, title="torus"))
        default_camera(pl)
        camera = camera_values(pl.camera)
        yield lambda size=(200, 150): still_payload(sc, size, camera, "fxaa")
    finally:
        pl.close()


@pytest.fixture
def worker():
    from gcmh_studio.still_process import StillProcess

    made = []

    def make(command=None):
        made.append(StillProcess(command))
        return made[-1]

    yield make
    for sp in made:   # (its pipes close when the test's objects go; a stopped worker would not read them)
        p = sp.process
        if p is not None and p.poll() is None:
            p.kill()
            p.wait()


def _ready(qtbot, sp):
    sp.start()
    qtbot.waitUntil(sp.ready, timeout=WAIT_MS)
    return sp.process


def test_the_worker_draws_the_picture_this_process_would_draw(qtbot, worker, payload):
    import pickle

    from gcmh_studio.still_process import draw_still

    sp = worker()
    request = sp.ask(payload())
    qtbot.waitUntil(request.done, timeout=WAIT_MS)
    assert request.error is None and not request.dropped
    img = request.image
    assert img.shape == (150, 200, 3) and img.dtype == np.uint8
    here = draw_still(**pickle.loads(payload()))
    assert np.array_equal(img, here)
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 50, "a picture of the torus, not a blank one"


def test_the_newest_request_wins(qtbot, worker, payload):
    sp = worker()
    proc = _ready(qtbot, sp)
    os.kill(proc.pid, signal.SIGSTOP)             # the worker reads nothing until all three are asked
    try:
        a, b, c = sp.ask(payload()), sp.ask(payload()), sp.ask(payload((120, 90)))
        qtbot.waitUntil(sp.idle, timeout=WAIT_MS)      # each written to the pipe, or dropped before
    finally:
        os.kill(proc.pid, signal.SIGCONT)
    qtbot.waitUntil(lambda: a.done() and b.done() and c.done(), timeout=WAIT_MS)
    assert a.dropped and b.dropped and a.image is None and b.image is None
    assert c.error is None and c.image.shape == (90, 120, 3)
    assert sp.starts == 1


def test_a_killed_worker_fails_its_request_and_the_next_one_is_drawn(qtbot, worker, payload):
    sp = worker()
    proc = _ready(qtbot, sp)
    os.kill(proc.pid, signal.SIGSTOP)             # (the request stays in flight)
    a = sp.ask(payload())
    qtbot.waitUntil(sp.idle, timeout=WAIT_MS)
    os.kill(proc.pid, signal.SIGKILL)
    qtbot.waitUntil(a.done, timeout=WAIT_MS)
    assert a.image is None and not a.dropped and "ended" in a.error
    b = sp.ask(payload())                         # a new worker
    qtbot.waitUntil(b.done, timeout=WAIT_MS)
    assert b.error is None and b.image is not None
    assert sp.starts == 2 and sp.process is not proc and sp.usable()


def test_a_hung_worker_is_ended_and_the_next_request_is_drawn(qtbot, worker, payload, monkeypatch):
    from gcmh_studio import still_process

    sp = worker()
    proc = _ready(qtbot, sp)
    monkeypatch.setattr(still_process, "HANG_S", 0.0)   # any request in flight counts as hung
    os.kill(proc.pid, signal.SIGSTOP)
    a = sp.ask(payload())
    qtbot.waitUntil(lambda: sp.check() or a.done(), timeout=WAIT_MS)   # (the GUI's poll)
    assert a.image is None and "hung" in a.error
    assert proc.wait(timeout=60) == -signal.SIGKILL
    monkeypatch.setattr(still_process, "HANG_S", 600.0)   # (a slow picture is not a hang)
    b = sp.ask(payload())
    qtbot.waitUntil(b.done, timeout=WAIT_MS)
    assert b.image is not None and sp.starts == 2


def test_a_worker_that_cannot_start_is_given_up_after_a_few_tries(qtbot, worker, payload):
    from gcmh_studio.still_process import MAX_FAILURES

    sp = worker([sys.executable, "-c", "import sys; sys.exit(3)"])
    for _ in range(MAX_FAILURES):
        assert sp.usable()
        request = sp.ask(payload())
        qtbot.waitUntil(request.done, timeout=WAIT_MS)
        assert request.image is None and request.error
    last = sp.ask(payload())
    assert not sp.usable() and last.done() and last.image is None and "too often" in last.error
    assert sp.starts == MAX_FAILURES


def test_a_worker_that_never_gets_ready_is_ended_and_started_again(worker, monkeypatch):
    from gcmh_studio import still_process

    sp = worker([sys.executable, "-c", "import os, sys; os.read(int(sys.argv[1]), 1)"])   # (never says ready)
    sp.start()
    first = sp.process
    monkeypatch.setattr(still_process, "START_S", 0.0)
    sp.start()                                    # (the window asks at each see-through result)
    assert first.wait(timeout=60) == -signal.SIGKILL
    assert sp.starts == 2 and sp.process is not first and sp.failures == 1


def _run_three_torus(qtbot, window):
    with qtbot.waitSignal(window.runFinished, timeout=180_000) as b:
        assert window.load_example("three-torus", div=small_div(load_example("three-torus")))
    assert b.args[0] == "done", window.last_status


def test_a_window_whose_worker_is_killed_keeps_running_and_its_pictures_come(qtbot, small_window):
    from gcmh_studio.still_process import still_process

    w, v = small_window, small_window.viewer
    sp = still_process()
    frames = []
    rw = w.plotter.ren_win
    rw.AddObserver("StartEvent", lambda *a: rw.GetSwapBuffers() and frames.append(1))

    # killed while the picture is asked of it: the window draws it itself
    proc = _ready(qtbot, sp)
    os.kill(proc.pid, signal.SIGSTOP)             # (it cannot answer before it is killed)
    try:
        _run_three_torus(qtbot, w)
        qtbot.waitUntil(lambda: v._still_job is not None, timeout=WAIT_MS)
    finally:
        proc.kill()
    qtbot.waitUntil(lambda: not v.still_pending() and len(frames) >= 1, timeout=WAIT_MS)
    assert not v.still_shown() and w.isVisible()

    # a result while the new worker starts: the window draws it itself; once it is ready, the next result's
    # picture comes from it
    n = len(frames)
    _run_three_torus(qtbot, w)
    qtbot.waitUntil(lambda: not v.still_pending() and len(frames) > n, timeout=WAIT_MS)
    qtbot.waitUntil(sp.ready, timeout=WAIT_MS)
    _run_three_torus(qtbot, w)
    qtbot.waitUntil(v.still_shown, timeout=WAIT_MS)
    assert sp.process is not proc and sp.process.poll() is None and sp.usable()
