"""The still picture of a see-through result, drawn by a worker process (issue 16: never frozen after a result;
issue 26, item 8: not in a thread of the app).

Under Xvfb (pytest-xvfb ``--xvfb-backend xvfb``), the three-torus at a small div. No timing assertions: the
window shows the result without rendering it on the GUI thread, the picture it shows is the one the window
draws itself (up to the axes' corner), anything that renders the view takes the picture away, a picture
overtaken by a change never shows, and a screenshot while it is drawn neither waits for it nor stops it.
(The worker itself: test_still_process.py.)
"""

import os

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from gcmh_core.examples import load_example

from app_helpers import small_div

SHOTS = os.environ.get("GCMH_TEST_SHOTS")   # a folder: the tests leave their pictures there to look at


def _shot(img, name):
    if SHOTS:
        from PIL import Image

        os.makedirs(SHOTS, exist_ok=True)
        Image.fromarray(np.asarray(img)[..., :3]).save(os.path.join(SHOTS, name))


def _shown_frames(window):
    """A list that grows by one for every frame the window's view shows (an unshown render swaps nothing)."""
    frames = []
    rw = window.plotter.ren_win
    rw.AddObserver("StartEvent", lambda *a: rw.GetSwapBuffers() and frames.append(1))
    return frames


def _run_three_torus(qtbot, window):
    from gcmh_studio.still_process import still_process

    qtbot.waitUntil(still_process().ready, timeout=120_000)   # (until then the window draws it itself)
    ex = load_example("three-torus")
    with qtbot.waitSignal(window.runFinished, timeout=180_000) as b:
        assert window.load_example("three-torus", div=small_div(ex))
    assert b.args[0] == "done", window.last_status


def test_the_picture_is_drawn_by_the_worker_and_is_the_windows_own(qtbot, window):
    v = window.viewer
    frames = _shown_frames(window)
    _run_three_torus(qtbot, window)
    assert v.scene.see_through()
    n0 = len(frames)
    qtbot.waitUntil(v.still_shown, timeout=60_000)
    assert len(frames) == n0, "the window rendered the result on the GUI thread"
    assert v.renders >= 1 and not v.still_pending()
    picture = v.still_image.copy()
    _shot(picture, "still_in_worker.png")
    own = v.screenshot_array()          # the window draws its own still picture: the overlay goes
    _shot(own, "still_on_gui_thread.png")
    assert not v.still_shown()
    h, w = own.shape[:2]
    assert picture.shape == own.shape
    differ = np.any(picture != own, axis=-1)
    ys, xs = np.nonzero(differ)
    # the same picture but where the three arrows of the axes meet (which one VTK draws on top)
    assert differ.sum() <= 0.0005 * differ.size, differ.sum()
    assert np.all(xs < 0.2 * w) and np.all(ys > 0.72 * h), "the picture differs outside the axes' corner"
    # the window's first frame of the result has the colour bar's labels where later frames have them
    assert np.array_equal(v.screenshot_array(), own)


def test_a_change_takes_the_picture_away_and_a_late_picture_never_shows(qtbot, window):
    v = window.viewer
    _run_three_torus(qtbot, window)
    qtbot.waitUntil(v.still_shown, timeout=60_000)
    frames = _shown_frames(window)
    pp = window.projection_panel
    row = next(r for r, (i, j) in enumerate(pp.model.planes) if j >= 3)
    pp.sliders[row].setValue(pp.sliders[row].value() + 10)      # the moving look, drawn by the window
    assert not v.still_shown()
    qtbot.waitUntil(lambda: len(frames) >= 1, timeout=30_000)
    qtbot.waitUntil(lambda: not v.scene.moving_shown(), timeout=30_000)
    assert not v.still_shown()

    # a result whose picture is overtaken by a change before it arrives: the window draws the change
    _run_three_torus(qtbot, window)
    assert v.still_pending()
    v.render()
    assert not v.still_pending()
    qtbot.wait(300)
    qtbot.waitUntil(lambda: v._still_job is None and not v.still.poll.isActive(), timeout=30_000)
    assert not v.still_shown()


def test_a_screenshot_while_the_picture_is_drawn_is_made_and_the_picture_still_comes(qtbot, window, tmp_path):
    from PIL import Image

    v = window.viewer
    _run_three_torus(qtbot, window)
    assert v.still_pending()
    img = window.save_screenshot(tmp_path / "s.png", size=(320, 240))
    assert img.shape[:2] == (240, 320)
    with Image.open(tmp_path / "s.png") as im:
        assert im.size == (320, 240)
    qtbot.waitUntil(v.still_shown, timeout=60_000)


def test_without_the_worker_the_window_renders_the_result_itself(qtbot, window):
    v = window.viewer
    v.still_off_thread = False
    frames = _shown_frames(window)
    _run_three_torus(qtbot, window)
    qtbot.waitUntil(lambda: len(frames) >= 1, timeout=30_000)
    assert not v.still_pending() and v._still_job is None and not v.still_shown()
