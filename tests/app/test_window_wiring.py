"""The window's wiring of features built in their own modules: the presentation mode is installed, sessions
keep the held camera, the Animate tab's parameter sweep exports from the window.  Runs under Xvfb."""

import numpy as np
import pytest

from app_helpers import wait_run


def test_the_window_has_the_presentation_mode(window):
    from gcmh_studio.qt_presentation import QtPresentation

    assert isinstance(window.presentation, QtPresentation)
    texts = [a.text() for a in window.actions()]
    assert texts.count("&Presentation mode") == 1 and "&Next example" in texts
    assert window.presentation.decorate in window.viewer.picture_decorators


def test_every_event_of_the_model_and_the_controller_has_a_listener(window):
    """napari's way: the model announces, the panels and the view listen; an event nobody hears is dead code."""
    for group in (window.model.events, window.controller.events):
        deaf = [name for name, signal in group.signals.items() if len(signal) == 0]
        assert deaf == [], f"no listener for {deaf}"


def test_the_view_and_topology_switches_are_one_model_field(window):
    pp, tp = window.projection_panel, window.topology_panel
    tp.two_sided_check.setEnabled(True)
    tp.two_sided_check.setChecked(True)
    assert window.model.style.two_sided and pp.two_sided_check.isChecked()
    pp.boundary_check.setChecked(True)
    assert window.model.style.boundary and tp.boundary_check.isChecked()
    window.model.set_style(grid=True)                      # (Undo, a session: the model changes)
    assert pp.grid_check.isChecked() and tp.path_check.isChecked()


def test_a_session_saved_by_the_window_brings_the_held_camera_back(qtbot, window, tmp_path):
    from gcmh_studio.qt_main_window import QtMainWindow

    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("sphere", div=10)
    window.projection_panel.keep_camera_check.setChecked(True)
    cam = window.plotter.camera
    cam.position = tuple(np.asarray(cam.position) * 1.7)
    saved = np.array(cam.position)
    path = tmp_path / "s.json"
    window.save_session(path)

    w2 = QtMainWindow(example=None)
    qtbot.addWidget(w2)
    w2.resize(1200, 800)
    w2.show()
    qtbot.waitExposed(w2)
    with qtbot.waitSignal(w2.runFinished, timeout=60_000):
        assert w2.controller.open_session(path)
    qtbot.wait(50)
    assert w2.viewer.keep_camera()
    assert np.allclose(w2.plotter.camera.position, saved, rtol=1e-6)
    w2.close()


def test_the_animate_tabs_parameter_sweep_exports_from_the_window(qtbot, window, tmp_path):
    from PIL import Image

    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("hyperboloid", div=16)
    ap = window.animation_panel
    assert "a" in ap.params                       # the sliders' parameters reach the Animate tab
    ap.set_mode("param")
    assert ap.spec_text().startswith("param:a=")
    path = tmp_path / "sweep.gif"
    written = window.export_animation(path, frames=4, size=(320, 240), show_progress=False)
    assert written == 4
    with Image.open(path) as im:
        assert im.n_frames == 4
        frames = []
        for i in range(4):
            im.seek(i)
            frames.append(np.asarray(im.convert("RGB")))
    assert any(np.any(frames[0] != f) for f in frames[1:])     # the surface changes with a
    assert "Parameter sweep saved" in window.last_status


def test_a_sweep_before_any_run_is_refused_with_a_message(window):
    ap = window.animation_panel
    ap.set_parameters({"a": {"value": 0.5, "min": -1.0, "max": 1.0}})
    ap.set_mode("param")
    with pytest.raises(ValueError, match="run first"):
        window.export_animation("never.gif", frames=3, show_progress=False)


def test_a_parameter_step_keeps_the_window_responsive(qtbot, window):
    """A slider step re-extracts and the window shows the new result (its subtitle names the value)."""
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("hyperboloid", div=16)
    fpp = window.formula_panel.parameters
    fpp.set_value("a", -0.5)
    wait_run(qtbot, window)
    assert window.result.meta["params"]["a"] == pytest.approx(-0.5)
    assert window.viewer.style().subtitle.startswith("a = -0.5")
