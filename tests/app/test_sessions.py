"""Sessions keep the camera and the "keep camera" toggle (issue 16); old files and hand-edited cameras still load.

The file level needs no display; the window test runs under Xvfb (pytest-xvfb ``--xvfb-backend xvfb``).
"""

import json

import numpy as np
import pytest

from gcmh_studio import studio_io
from gcmh_studio.model import StudioModel

CAMERA = {"position": [4.0, -6.0, 3.0], "focal_point": [0.0, 0.0, 0.5], "up": [0.0, 0.0, 1.0],
          "parallel_scale": 1.5, "view_angle": 24.0}


def _model(keep=False):
    m = StudioModel()
    m.set_system({"n": 3, "k": 1, "formulas": ["x1^2 + x2^2 + x3^2 - 1"]})
    m.projection.kind = "generic"
    m.projection_changed(base=True)
    m.set_style(color_by="x2", keep_camera=keep)
    return m


@pytest.mark.parametrize("keep", [True, False])
def test_the_toggle_and_the_camera_round_trip(tmp_path, keep):
    d = studio_io.session_dict(_model(keep), dict(CAMERA))
    assert d["view"]["kind"] == "generic" and d["view"]["color"] == "x2"
    back = studio_io.read_session(studio_io.write_session(tmp_path / "s.json", d))
    assert back["keep_camera"] is keep
    assert studio_io.session_camera(back) == (CAMERA, keep)


def test_a_session_saved_before_the_toggle_loads_as_not_held(tmp_path):
    old = {"format": "gcmh-session/1", "title": "Sphere", "system": {"n": 3, "k": 1, "formulas": ["x1"]},
           "view": {"kind": "generic"}, "camera": CAMERA}
    p = tmp_path / "old.json"
    p.write_text(json.dumps(old))
    back = studio_io.read_session(p)
    assert back["keep_camera"] is False and back["camera"] == CAMERA and back["view"] == {"kind": "generic"}
    del old["camera"]
    p.write_text(json.dumps(old))
    assert studio_io.session_camera(studio_io.read_session(p)) == (None, False)


@pytest.mark.parametrize("camera", [
    "front", {"position": [1, 2], "focal_point": [0, 0, 0], "up": [0, 0, 1]},
    {"position": [1, 2, "x"], "focal_point": [0, 0, 0], "up": [0, 0, 1]},
    {"position": [1, 2, float("nan")], "focal_point": [0, 0, 0], "up": [0, 0, 1]},
    {"position": [0, 0, 0], "focal_point": [0, 0, 0], "up": [0, 0, 1]},           # the eye on the focal point
    {"position": [1, 2, 3], "focal_point": [0, 0, 0], "up": [0, 0, 0]},
    dict(CAMERA, view_angle=0), dict(CAMERA, view_angle=400), dict(CAMERA, parallel_scale=-1),
])
def test_a_hand_edited_camera_that_cannot_be_used_is_dropped(tmp_path, camera):
    d = studio_io.session_dict(_model(), camera)
    d["keep_camera"] = "yes"
    p = tmp_path / "s.json"
    p.write_text(json.dumps(d))   # (json writes NaN as NaN and reads it back)
    back = studio_io.read_session(p)
    assert back["camera"] is None and back["keep_camera"] is False   # "yes" is not a toggle


def test_a_held_camera_comes_back_held_in_a_new_window(qtbot, window, tmp_path):
    """What the window saves and opens (its session() and open_session() pass the viewer's camera_session and
    restore_camera): the toggle comes back on, the camera as it was, and a new run leaves it alone."""
    from app_helpers import open_window

    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("sphere", div=10)
    window.projection_panel.keep_camera_check.setChecked(True)
    assert window.model.style.keep_camera
    cam = window.plotter.camera
    cam.position = tuple(np.asarray(cam.position) * 1.7)   # farther away than any fit would put it
    d = window.controller.session()
    assert d["keep_camera"] is True
    path = studio_io.write_session(tmp_path / "s.json", d)

    w2 = open_window(qtbot)
    try:
        with qtbot.waitSignal(w2.runFinished, timeout=60_000):
            assert w2.controller.open_session(path)
        back = studio_io.read_session(path)
        w2.viewer.restore_camera(*studio_io.session_camera(back))
        assert w2.viewer.keep_camera()
        saved = np.asarray(d["camera"]["position"])
        np.testing.assert_allclose(w2.plotter.camera.position, saved, rtol=1e-6)
        with qtbot.waitSignal(w2.runFinished, timeout=60_000):
            w2.run()
        np.testing.assert_allclose(w2.plotter.camera.position, saved, rtol=1e-6)   # held: no refit
        w2.viewer.restore_camera(None, False)                                      # nothing saved: toggle off
        assert not w2.viewer.keep_camera()
    finally:
        w2.close()
