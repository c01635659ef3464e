"""Stress of the still picture (issue 26, item 8: one ``free(): corrupted unsorted chunks`` in eight runs of the
classroom benchmark, as its slider-step section opened new windows, when the picture was drawn in a thread of
the app; it is drawn by a worker process now, gcmh_studio.still_process).

Slider steps, releases, new results of a see-through system (each one's picture drawn by the worker), example
switches and a second window opened and closed while that picture may be drawing.
The suite runs a few rounds; thousands:

    MALLOC_CHECK_=3 GCMH_STRESS=2000 .venv/bin/python -X faulthandler -m pytest -q -x \\
        tests/app/test_stress_still.py --xvfb-backend xvfb -p no:randomly

(faulthandler prints every thread's stack on a native crash; MALLOC_CHECK_=3 makes glibc check each free and
abort at the first corrupted chunk, near its cause.) No timing: every wait is for an event.
"""

import os

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from gcmh_core.examples import load_example

from app_helpers import small_div

ROUNDS = int(os.environ.get("GCMH_STRESS", "3"))
SEE_THROUGH = ("three-sphere", "three-torus")


def _load(qtbot, window, name):
    with qtbot.waitSignal(window.runFinished, timeout=180_000) as b:
        assert window.load_example(name, div=small_div(load_example(name)))
    assert b.args[0] == "done", window.last_status


def test_still_pictures_survive_steps_releases_switches_and_windows(qtbot, small_window, monkeypatch):
    from gcmh_studio.qt_main_window import QtMainWindow
    from gcmh_studio.still_process import StillProcess, still_process

    asked = []   # the pictures asked of the worker
    real = StillProcess.ask

    def counted(self, payload):
        asked.append(real(self, payload))
        return asked[-1]

    monkeypatch.setattr(StillProcess, "ask", counted)
    w = small_window
    v = w.viewer
    qtbot.waitUntil(still_process().ready, timeout=120_000)   # (until then the window draws it itself)
    _load(qtbot, w, SEE_THROUGH[0])
    assert v.scene.see_through()
    starts = still_process().starts
    rng = np.random.default_rng(26)
    for i in range(ROUNDS):
        base = w.model.projection.angles.copy()
        for _ in range(8):    # slider steps: the moving look
            w.model.set_angles(base + rng.uniform(-15, 15, size=base.shape))
        v.render()            # let go: the still look, on the GUI thread
        with qtbot.waitSignal(w.runFinished, timeout=180_000):   # a new result: its picture, in the worker
            assert w.run()
        other = QtMainWindow(example=None)   # a window opened and closed while it may be drawing
        qtbot.addWidget(other)
        other.resize(320, 240)
        other.show()
        qtbot.waitExposed(other)
        other.close()
        qtbot.waitUntil(lambda: not v.still_pending(), timeout=60_000)
        if i % 4 == 3:        # an example switch (the next see-through one)
            _load(qtbot, w, SEE_THROUGH[(i // 4 + 1) % len(SEE_THROUGH)])
    assert w.isVisible() and v.scene.see_through()
    drawn = [r for r in asked if r.image is not None]
    failed = [r.error for r in asked if r.error is not None]
    assert not failed, failed[:3]      # (a worker that died or hung: the window drew those itself)
    assert still_process().starts == starts, "the worker was started again"
    if ROUNDS >= 3:
        assert len(drawn) >= 1, "no still picture was drawn by the worker: the stress tested nothing"
