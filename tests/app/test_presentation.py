"""Presentation mode (gcmh_studio.qt_presentation): full screen with the typeset formula, axes, walking the gallery."""

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from app_helpers import small_div


@pytest.fixture
def presenting(qtbot, window):
    """The window with its presentation controller, active (keys reach it), showing the hyperboloid."""
    from gcmh_studio.qt_presentation import QtPresentation

    window.activateWindow()
    qtbot.waitActive(window)
    p = QtPresentation(window)
    _open(qtbot, window, "hyperboloid")
    return window, p


def _open(qtbot, window, name):
    from gcmh_core.examples import load_example

    with qtbot.waitSignal(window.runFinished, timeout=180_000) as b:
        assert window.load_example(name, div=small_div(load_example(name)))
    assert b.args[0] == "done", window.last_status


def _layout(window):
    split = window.centralWidget()
    return dict(state=int(window.windowState()), size=(window.width(), window.height()), sizes=split.sizes(),
                side=split.widget(0).isVisible(), run=window.run_button.isVisible(),
                menu=window.menuBar().isVisible(), status=window.statusBar().isVisible(),
                actions=list(window.actions()))


def _key(qtbot, window, key):
    from qtpy.QtWidgets import QApplication

    target = QApplication.focusWidget() or window
    qtbot.keyClick(target, key)
    qtbot.wait(50)


def test_f11_presents_the_view_alone_with_the_typeset_formula(qtbot, presenting):
    from qtpy.QtCore import Qt

    from gcmh_studio.qt_presentation import FORMULA_ACTOR

    window, p = presenting
    before = _layout(window)
    assert before["side"] and before["menu"] and not before["state"] & Qt.WindowFullScreen
    title = window.plotter.actors["gcmh-title"].GetTextProperty()
    window.screenshot_array()
    size_before = title.GetFontSize()
    _key(qtbot, window, Qt.Key_F11)
    qtbot.waitUntil(lambda: p.presenting and window.isFullScreen(), timeout=5000)
    assert not window.tabs.isVisible() and not window.run_button.isVisible()
    assert not window.menuBar().isVisible() and not window.statusBar().isVisible()
    assert window.viewer.widget.isVisible()
    # the formula, typeset, is an actor of the view itself
    assert FORMULA_ACTOR in window.plotter.actors and p.formula_actor() is not None
    w, h = p.formula_actor().image_size
    assert w > 100 and h > 40
    with_card = window.screenshot_array()
    # larger type for the room, as large as fits in the view (a long title on a small screen fills its width)
    bb = [0.0] * 4
    window.plotter.actors["gcmh-title"].GetBoundingBox(window.plotter.renderer, bb)
    view_w, view_h = window.plotter.ren_win.GetSize()
    assert title.GetFontSize() > size_before or bb[1] - bb[0] > 0.8 * view_w
    assert bb[1] <= view_w and bb[3] <= view_h                     # and never off the view
    x, y = (int(v) for v in p.formula_actor().GetPosition())     # from the bottom left
    # the screenshot of the view carries the card: in its bottom right corner, and nowhere else
    p.set_formula_shown(False)
    assert FORMULA_ACTOR not in window.plotter.actors
    without = window.screenshot_array()
    H, W = without.shape[:2]
    x0, y0 = x, H - (y + h)
    assert x0 > W // 2 and y0 > H // 2
    corner = np.any(with_card[y0:, x0:] != without[y0:, x0:], axis=-1)
    rest = np.any(with_card[: H // 2, : W // 2] != without[: H // 2, : W // 2], axis=-1)
    assert corner.mean() > 0.3 and rest.mean() == 0.0
    p.set_formula_shown(True)
    assert FORMULA_ACTOR in window.plotter.actors
    # Esc: the layout as it was, the card and the larger type gone
    _key(qtbot, window, Qt.Key_Escape)
    qtbot.waitUntil(lambda: not p.presenting, timeout=5000)
    qtbot.waitUntil(lambda: not window.isFullScreen(), timeout=5000)
    qtbot.wait(100)
    assert _layout(window) == before
    assert FORMULA_ACTOR not in window.plotter.actors
    window.screenshot_array()
    assert title.GetFontSize() == size_before


def test_f11_toggles_back_and_the_menus_shortcuts_work_meanwhile(qtbot, presenting):
    from qtpy.QtCore import Qt

    window, p = presenting
    before = _layout(window)
    _key(qtbot, window, Qt.Key_F11)
    qtbot.waitUntil(lambda: p.presenting, timeout=5000)
    # the menu bar is hidden: its actions with shortcuts are on the window meanwhile (Space plays)
    assert window.menu_actions.play in window.actions()
    _key(qtbot, window, Qt.Key_Space)
    assert window.animation_panel.is_playing()
    _key(qtbot, window, Qt.Key_Space)
    assert not window.animation_panel.is_playing()
    _key(qtbot, window, Qt.Key_F11)
    qtbot.waitUntil(lambda: not p.presenting and not window.isFullScreen(), timeout=5000)
    qtbot.wait(100)
    assert _layout(window) == before
    assert window.menu_actions.play not in window.actions()


def test_the_card_follows_the_parameters_and_the_system(qtbot, presenting):
    window, p = presenting
    p.enter()
    key = p.formula_key()
    formulas, variables, params, cplx, _ = key
    assert formulas == ("x^2 + y^2 - z^2 - a",) and dict(params) == {"a": 0.5} and cplx is None
    first = p.formula_actor()
    _open(qtbot, window, "complex-cosine")
    assert p.formula_key()[3] == ("z = cos(w)",)          # the example over C shows its complex equation
    assert p.formula_actor() is not first
    p.leave()


def test_axes_with_ticks_are_titled_with_the_projection(qtbot, presenting):
    from qtpy.QtCore import Qt

    window, p = presenting
    _open(qtbot, window, "complex-cosine")
    p.enter()
    assert not p.axes_shown()
    _key(qtbot, window, Qt.Key_A)
    assert p.axes_shown() and p.axes_action.isChecked()
    window.screenshot_array()          # a render: the axes take the object's bounds and titles
    axes = window.plotter.renderer.cube_axes_actor
    assert [axes.GetXTitle(), axes.GetYTitle(), axes.GetZTitle()] == ["u = Re w", "v = Im w", "x = Re z"]
    lo, hi = np.array(axes.GetBounds()).reshape(3, 2).T
    mesh = np.array(window.scene.mesh.bounds).reshape(3, 2)
    # the box reaches round values around the object (bounds_axes.nice_range: an end a fiftieth of a step
    # past a round value stays at it)
    slack = 0.02 * (hi - lo)
    assert np.all(lo <= mesh[:, 0] + slack) and np.all(hi >= mesh[:, 1] - slack)
    # the ticks count in the variables (the drawing is centred on the object): x = cos(u) cosh(v) >= 0 here
    V = np.asarray(window.result.vertices)
    shown = np.array([axes.x_axis_range, axes.y_axis_range, axes.z_axis_range])
    data = np.stack([V[:, :3].min(0), V[:, :3].max(0)], 1)
    room = 0.02 * np.ptp(shown, axis=1)
    assert np.all(shown[:, 0] <= data[:, 0] + room) and np.all(shown[:, 1] >= data[:, 1] - room)
    assert shown[2, 0] == 0.0
    _key(qtbot, window, Qt.Key_A)
    assert not p.axes_shown()
    p.leave()
    # outside the presentation the key is the user's (typing in a field), the menu entry still works
    assert p.axes_action.shortcut().isEmpty()
    p.axes_action.trigger()
    assert p.axes_shown()
    p.set_axes(False)


def test_page_down_and_up_walk_the_gallery(qtbot, presenting):
    from qtpy.QtCore import Qt

    from gcmh_core.examples import load_example
    from gcmh_studio.qt_gallery_walk import example_names

    window, p = presenting
    names = example_names()
    opened = []
    real = window.load_example

    def opening(name, **kw):   # each example as the gallery opens it, at a test's small div
        opened.append(name)
        return real(name, div=small_div(load_example(name)))

    window.load_example = opening
    p.enter()
    start = names.index("hyperboloid")
    with qtbot.waitSignal(window.runFinished, timeout=180_000):
        _key(qtbot, window, Qt.Key_PageDown)
    assert opened == [names[start + 1]]
    assert window.model.title == load_example(names[start + 1]).title
    assert p.formula_key()[0] == tuple(window.model.job.formulas)
    with qtbot.waitSignal(window.runFinished, timeout=180_000):
        _key(qtbot, window, Qt.Key_PageUp)
    with qtbot.waitSignal(window.runFinished, timeout=180_000):
        _key(qtbot, window, Qt.Key_PageUp)
    assert opened == [names[start + 1], names[start], names[start - 1]]
    assert p.caption() == ""           # the "computing..." line is gone once the run is done
    p.leave()
    # outside the presentation Page Down scrolls the panels again
    assert p.next_action.shortcut().isEmpty()


def test_installing_twice_leaves_one_set_of_actions(qtbot, window):
    from qtpy.QtGui import QKeySequence

    from gcmh_studio.qt_presentation import QtPresentation

    QtPresentation(window)
    p = QtPresentation(window)
    f11 = [a for a in window.actions() if a.shortcut() == QKeySequence("F11")]
    assert f11 == [p.present_action]
    view = next(a.menu() for a in window.menuBar().actions() if a.text().replace("&", "") == "View")
    assert [a.text() for a in view.actions()].count("&Presentation mode") == 1
    p.enter()
    assert p.presenting
    p.leave()


def test_decorate_draws_the_card_and_axes_on_an_off_screen_copy(qtbot, presenting):
    import pyvista as pv

    from gcmh_studio.qt_presentation import FORMULA_ACTOR
    from gcmh_studio.scene import Scene

    window, p = presenting
    p.enter()
    p.set_axes(True)
    window.screenshot_array()
    pl = pv.Plotter(off_screen=True, window_size=[800, 600])
    try:
        Scene(pl).adopt(window.scene)
        pl.render()
        plain = pl.screenshot(return_img=True)
        p.decorate(pl)
        assert FORMULA_ACTOR in pl.actors
        w, h = pl.actors[FORMULA_ACTOR].image_size
        assert w <= 0.62 * 800 and h <= 0.3 * 600        # typeset for that picture's size
        axes = pl.renderer.cube_axes_actor
        assert axes is not None and axes.GetZTitle() == "z"
        pl.render()
        decorated = pl.screenshot(return_img=True)
        assert np.any(decorated[-h:, -w:] != plain[-h:, -w:])
    finally:
        pl.close()
    p.leave()


def test_screenshots_of_the_view_carry_the_card(qtbot, presenting, tmp_path):
    from PIL import Image

    window, p = presenting
    p.enter()
    window.screenshot_array()
    p.set_formula_shown(False)
    plain = window.viewer.save_screenshot(tmp_path / "plain.png", size=(800, 600))
    p.set_formula_shown(True)
    card = window.viewer.save_screenshot(tmp_path / "card.png", size=(800, 600))
    assert Image.open(tmp_path / "card.png").size == (800, 600)
    differs = np.any(card[..., :3] != plain[..., :3], axis=-1)
    h, w = differs.shape
    # the card sits in the bottom right corner of the picture, as in the view
    assert differs[h // 2:, w // 2:].mean() > 0.05 and differs[: h // 2, : w // 2].mean() == 0.0
    assert window.viewer.picture_decorators.count(p.decorate) == 1
    p.leave()
    p.uninstall()
    assert p.decorate not in window.viewer.picture_decorators


def test_a_card_that_cannot_be_drawn_is_plain_text(qtbot, presenting, monkeypatch):
    import gcmh_studio.formula_card as card

    window, p = presenting

    def broken(*a, **kw):
        raise ImportError("no matplotlib here")

    monkeypatch.setattr(card, "typeset_system", broken)
    p.enter()
    actor = p.formula_actor()
    assert actor is not None and actor.GetInput() == "x^2 + y^2 - z^2 - a = 0\na = 0.5"
    window.screenshot_array()
    p.leave()


def test_a_step_during_a_run_cancels_it_and_opens_the_example_when_it_has_stopped(qtbot, presenting, monkeypatch):
    from gcmh_studio.qt_gallery_walk import example_names

    window, p = presenting
    names = example_names()
    opened, cancels = [], []
    running = [True]
    monkeypatch.setattr(window, "is_running", lambda: running[0])
    monkeypatch.setattr(window, "cancel", lambda: cancels.append(1))
    monkeypatch.setattr(window, "load_example", lambda name, **kw: opened.append(name) or True)
    p.enter()
    start = names.index("hyperboloid")
    assert p.next_example() == names[start + 1]
    assert p.next_example() == names[start + 2]      # pressed again before the run stopped: the later one wins
    assert cancels and not opened
    assert p.caption().startswith(f"{start + 3}/{len(names)} ")
    running[0] = False
    window.runFinished.emit("cancelled")
    qtbot.waitUntil(lambda: opened == [names[start + 2]], timeout=2000)
    p.leave()


# ---------------------------------------------------------------- the control strip and live play


def _result_a(window):
    return window.result.meta.get("params", {}).get("a")


def test_the_strip_sets_a_parameter_and_the_result_follows(qtbot, presenting):
    """F11 keeps a strip beside the view: its parameter slider held gives coarse steps, let go the full
    grid, and the result follows (the hyperboloid: two sheets at a < 0, one at a > 0); H hides it."""
    from qtpy.QtCore import Qt

    from gcmh_studio.qt_parameters import STEPS

    window, p = presenting
    strip = p.strip
    assert not strip.isVisible()
    _key(qtbot, window, Qt.Key_F11)
    qtbot.waitUntil(lambda: p.presenting and strip.isVisible(), timeout=5000)
    assert list(strip.param_rows) == ["a"] and strip.width() <= window.width() // 4
    label, slider = strip.param_rows["a"]
    assert label.font().pixelSize() >= 18 or label.fontInfo().pixelSize() >= 18   # large type
    # held: a coarse step at each value, the picture following
    slider.setSliderDown(True)
    with qtbot.waitSignal(window.runFinished, timeout=120_000):
        slider.setValue(STEPS // 8)                        # a = -0.75
    assert window.model.job.step == "coarse" and _result_a(window) == pytest.approx(-0.75)
    # let go: the full grid at the value reached; two sheets
    with qtbot.waitSignal(window.runFinished, timeout=120_000) as b:
        slider.setSliderDown(False)
    qtbot.waitUntil(lambda: window.model.job.step == "full" and not window.controller.is_running(), timeout=120_000)
    assert b.args[0] in ("done", "cancelled")
    assert _result_a(window) == pytest.approx(-0.75) and window.result.euler_characteristic() == 2
    assert window.formula_panel.parameters.values()["a"] == pytest.approx(-0.75)
    assert label.text() == "a = -0.75"
    # a value set in the side panel shows on the strip
    with qtbot.waitSignal(window.runFinished, timeout=120_000):
        strip.set_param_position("a", STEPS * 7 // 8)       # a = 0.75: one sheet
    qtbot.waitUntil(lambda: not window.controller.is_running(), timeout=120_000)
    assert _result_a(window) == pytest.approx(0.75) and window.result.euler_characteristic() == 0
    # the slice and the turn
    strip.slice_check.setChecked(True)
    assert window.model.slice.on and strip.slice_slider.isEnabled()
    strip.slice_slider.setValue(250)
    assert window.model.slice.c == pytest.approx(0.25)
    row = window.model.projection.planes.index(tuple(window.model.animation.plane))
    strip.turn_slider.setValue(40)
    assert window.model.projection.angles[row] == pytest.approx(40.0)
    window.model.set_slice(c=0.6)                            # (the View tab, undo): the strip follows
    assert strip.slice_slider.value() == 600
    # H hides the strip and brings it back; leaving hides it
    _key(qtbot, window, Qt.Key_H)
    qtbot.waitUntil(lambda: not strip.isVisible(), timeout=5000)
    _key(qtbot, window, Qt.Key_H)
    qtbot.waitUntil(lambda: strip.isVisible(), timeout=5000)
    _key(qtbot, window, Qt.Key_Escape)
    qtbot.waitUntil(lambda: not p.presenting and not strip.isVisible(), timeout=5000)


def test_space_plays_a_rotation_and_a_parameter_sweep_live(qtbot, presenting):
    """Space in presentation mode plays the chosen animation in the window and stops it: a rotation turns
    the view; a parameter sweep re-extracts coarse while it plays and on the full grid where it stops."""
    from qtpy.QtCore import Qt

    window, p = presenting
    ap, strip = window.animation_panel, p.strip
    _key(qtbot, window, Qt.Key_F11)
    qtbot.waitUntil(lambda: p.presenting and strip.isVisible(), timeout=5000)
    ap.set_mode("rotate")
    angles = window.model.projection.angles.copy()
    _key(qtbot, window, Qt.Key_Space)
    assert ap.is_playing() and "Pause" in strip.play_button.text()
    qtbot.waitUntil(lambda: not np.allclose(window.model.projection.angles, angles), timeout=10_000)
    _key(qtbot, window, Qt.Key_Space)
    assert not ap.is_playing() and "Play" in strip.play_button.text()
    # the parameter sweep, chosen on the strip
    i = strip.mode_combo.findData("param")
    assert i >= 0
    strip.mode_combo.setCurrentIndex(i)
    strip.mode_combo.activated.emit(i)
    assert ap.mode() == "param"
    a0 = _result_a(window)
    steps = []
    window.runFinished.connect(lambda how: steps.append((window.model.job.step, _result_a(window))))
    _key(qtbot, window, Qt.Key_Space)
    assert ap.is_playing()
    qtbot.waitUntil(lambda: any(s == "coarse" and a != a0 for s, a in steps), timeout=120_000)
    _key(qtbot, window, Qt.Key_Space)
    assert not ap.is_playing()
    reached = window.formula_panel.parameters.values()["a"]
    qtbot.waitUntil(lambda: window.model.job.step == "full" and not window.controller.is_running(), timeout=120_000)
    assert _result_a(window) == pytest.approx(reached)
    p.leave()
