"""The View tab's angle switches ("angles as circles", "show the glued seam", issue 27 item 4) are kept in
sessions and undone like the other view settings; a session saved before them opens with them off; a bad
value is refused in one line naming the field.

Model, file and controller need no display; the View tab's box runs under Xvfb (``--xvfb-backend xvfb``).
"""

import copy
import json

import pytest
from test_controller import FakeRunner, FakeView, fake_form

from gcmh_studio import studio_io
from gcmh_studio.angles import angle_look
from gcmh_studio.controller import StudioController
from gcmh_studio.model import AngleView, StudioModel

CAMERA = {"position": [4.0, -6.0, 3.0], "focal_point": [0.0, 0.0, 0.5], "up": [0.0, 0.0, 1.0]}
TORUS = {"n": 3, "k": 1, "variables": ["s", "t", "x"], "formulas": ["x"], "bounds": [["0", "2*pi"]] * 2 + [["-1", "1"]],
         "div": "8", "method": "gcmh", "periodic": ["s", "t"]}


def _model() -> StudioModel:
    m = StudioModel()
    m.history.merge_seconds = 0.0   # (each switch its own step, however fast the test)
    m.set_system(copy.deepcopy(TORUS))
    m.set_view_variables(["s", "t", "x"])
    return m


@pytest.mark.parametrize("circles,seam", [(True, True), (True, False), (False, True)])
def test_the_switches_round_trip_through_a_session_file(tmp_path, circles, seam):
    m = _model()
    angle_look(m).set(circles=circles, seam=seam)      # (what the View tab's check boxes call)
    d = studio_io.session_dict(m, dict(CAMERA))
    assert (d["view"]["angles_as_circles"], d["view"]["show_seam"]) == (circles, seam)
    back = studio_io.read_session(studio_io.write_session(tmp_path / "s.json", d))
    other = _model()
    heard = []
    angle_look(other).changed.connect(lambda: heard.append(True))
    other.set_view_state(back["view"])
    assert other.angle_view == AngleView(circles=circles, seam=seam)
    assert (angle_look(other).circles, angle_look(other).seam) == (circles, seam) and heard == [True]


def test_a_session_saved_before_the_switches_opens_with_them_off(tmp_path):
    m = _model()
    d = studio_io.session_dict(m, dict(CAMERA))
    for key in ("angles_as_circles", "show_seam"):
        del d["view"][key]
    p = tmp_path / "old.json"
    p.write_text(json.dumps(d))
    back = studio_io.read_session(p)
    other = _model()
    other.set_angle_view(circles=True, seam=True)     # (on before the old session is opened)
    other.set_view_state(back["view"])
    assert other.angle_view == AngleView(circles=False, seam=False)


@pytest.mark.parametrize("key", ["angles_as_circles", "show_seam"])
@pytest.mark.parametrize("value", ["yes", 1, [True], {"on": True}])
def test_a_switch_that_is_not_true_or_false_is_refused_in_one_line(tmp_path, key, value):
    d = studio_io.session_dict(_model(), dict(CAMERA))
    d["view"][key] = value
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(d))
    with pytest.raises(ValueError) as err:
        studio_io.read_session(p)
    msg = str(err.value)
    assert f"view.{key}" in msg and "true or false" in msg and "\n" not in msg, msg


def test_a_switch_is_one_step_to_undo_and_redo():
    m = _model()
    look = angle_look(m)
    heard = []
    look.changed.connect(lambda: heard.append((look.circles, look.seam)))
    look.set(circles=True)
    look.set(seam=True)
    assert m.history.can_undo() and (look.circles, look.seam) == (True, True)
    assert m.undo()["view"]["show_seam"] is False and (look.circles, look.seam) == (True, False)
    assert m.undo()["view"]["angles_as_circles"] is False and (look.circles, look.seam) == (False, False)
    assert m.redo()["view"]["angles_as_circles"] is True and (look.circles, look.seam) == (True, False)
    assert heard == [(True, False), (True, True), (True, False), (False, False), (True, False)]
    look.set(circles=True)                             # (no change: no step, nothing heard)
    assert heard[-1] == (True, False) and m.history.can_redo()


def test_the_controller_saves_and_opens_the_switches_and_undoes_them(tmp_path):
    model = StudioModel()
    fake_form(model)
    runner = FakeRunner()
    studio = runner.controller = StudioController(model, runner, FakeView(model))
    assert studio.load_example("sphere", div=8)
    model.history.merge_seconds = 0.0
    model.set_angle_view(circles=True, seam=True)
    path = studio_io.write_session(tmp_path / "s.json", studio.session())
    assert studio.undo() and model.angle_view == AngleView()
    assert studio.redo() and model.angle_view == AngleView(circles=True, seam=True)
    model.set_angle_view(circles=False, seam=False)
    assert studio.open_session(path)
    assert model.angle_view == AngleView(circles=True, seam=True)


def test_the_view_tabs_switches_follow_undo(qtbot):
    from gcmh_studio.qt_style_box import QtStyleBox

    m = _model()
    box = QtStyleBox(m)
    qtbot.addWidget(box)
    box.circles_check.setChecked(True)
    assert m.angle_view.circles
    m.undo()
    assert not box.circles_check.isChecked() and not m.angle_view.circles
    m.redo()
    assert box.circles_check.isChecked() and box.seam_check.isChecked() is False


def test_the_window_reopens_a_session_drawn_as_circles_and_undoes_the_switch(qtbot, window, tmp_path):
    """A teacher's path: tick "angles as circles" on the torus of angles, save; a new window opens it drawn as
    circles with the box ticked; Edit > Undo unticks it and draws the angles as numbers again."""
    from app_helpers import open_window

    with qtbot.waitSignal(window.runFinished, timeout=120_000):
        window.load_example("torus-angles", div=10)
    box = window.projection_panel.style_box
    assert box.circles_check.isEnabled()
    box.circles_check.setChecked(True)
    box.seam_check.setChecked(True)
    assert window.viewer.scene.circles_on
    path = studio_io.write_session(tmp_path / "s.json", window.controller.session())

    w2 = open_window(qtbot)
    try:
        with qtbot.waitSignal(w2.runFinished, timeout=120_000):
            assert w2.controller.open_session(path)
        box2 = w2.projection_panel.style_box
        assert box2.circles_check.isChecked() and box2.seam_check.isChecked()
        assert w2.viewer.scene.circles_on and w2.model.angle_view == AngleView(circles=True, seam=True)
        w2.model.history.merge_seconds = 0.0
        box2.circles_check.setChecked(False)
        assert not w2.viewer.scene.circles_on
        w2.menu_actions.undo.trigger()
        assert box2.circles_check.isChecked() and w2.viewer.scene.circles_on
        w2.menu_actions.redo.trigger()
        assert not box2.circles_check.isChecked() and not w2.viewer.scene.circles_on
    finally:
        w2.close()
