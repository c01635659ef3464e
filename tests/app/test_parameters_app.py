"""Live parameters in the window (issue 17): a slider per parameter, re-extraction as it moves."""

import pytest

from app_helpers import settle, wait_run


def _until_result(qtbot, window, check, timeout=60_000):
    """Wait until the result on screen passes ``check`` (parameter steps may end one after another)."""
    qtbot.waitUntil(lambda: window.result is not None and not window.is_running() and check(window.result),
                    timeout=timeout)


def test_a_parameter_in_the_text_gets_a_slider_and_rows_follow_the_formulas(qtbot, window):
    p = window.formula_panel
    p.set_state(dict(n=3, k=1, variables=["x", "y", "z"], formulas=["x^2 + y^2 - z^2 - a"], bounds=[[-2, 2]] * 3,
                     div=12))
    settle(qtbot, p)
    assert p.is_valid() and p.parameters.names() == ["a"]
    assert not p.parameters.isHidden()
    p.parameters.set_value("a", 0.25, commit=False)
    p.formula_edits[0].setText("x^2 + y^2 - z^2 - a*b")
    settle(qtbot, p)
    assert p.parameters.names() == ["a", "b"] and p.job().params["a"] == 0.25
    p.formula_edits[0].setText("x^2 + y^2 - z^2 - 1")   # no parameter: no rows
    settle(qtbot, p)
    assert p.parameters.names() == [] and p.parameters.isHidden() and p.job().params is None
    p.formula_edits[0].setText("x^2 + y^2 - z^2 - a")    # a comes back with its value
    settle(qtbot, p)
    assert p.params() == {"a": 0.25}


def test_moving_the_slider_changes_the_hyperboloid_across_the_critical_value(qtbot, window):
    window.load_example("hyperboloid", div=16)
    assert wait_run(qtbot, window) == "done", window.last_status
    p = window.formula_panel
    row = p.parameters.rows["a"]
    assert (row.state["min"], row.state["max"], row.state["value"]) == (-1.0, 1.0, 0.5)   # the file's range
    assert window.result.euler_characteristic() == 0                                   # one sheet
    # a drag: coarse steps while the slider is held, the full grid when it is let go
    row.slider.setSliderDown(True)
    for v in (0.3, 0.0, -0.3, -0.5):
        row.slider.setValue(int(round((v + 1) / 2 * 200)))
    _until_result(qtbot, window, lambda cx: cx.meta["params"]["a"] == -0.5)
    assert window.model.job.step == "coarse" and window.model.job.div != 16
    row.slider.setSliderDown(False)   # (Qt's release: the full grid)
    _until_result(qtbot, window, lambda cx: cx.meta["div"] == [16, 16, 16])
    assert window.result.meta["params"] == {"a": -0.5}
    assert window.result.euler_characteristic() == 2                                    # two sheets
    assert window.topology_panel.values["euler"].text().startswith("2")
    assert not p.parameters.notice.text()
    p.parameters.set_value("a", 0.0)   # the cone: a critical value, and the window says so
    _until_result(qtbot, window, lambda cx: cx.meta["params"] == {"a": 0.0})
    assert window.result.meta["singular_vertices"] > 0
    assert window.scene.style.subtitle.startswith("a = 0 \u00b7")   # the picture says at which value
    assert "a = 0 is a critical value:" in window.last_status
    assert "a = 0 is a critical value:" in p.parameters.notice.text()
    assert "critical value" in window.topology_panel.values["euler"].text()
    p.parameters.set_value("a", 0.5)
    _until_result(qtbot, window, lambda cx: cx.meta["params"] == {"a": 0.5})
    assert window.result.euler_characteristic() == 0 and not p.parameters.notice.text()


def test_the_view_is_kept_across_parameter_steps(qtbot, window):
    window.load_example("shrinking-tori", div=12)
    assert wait_run(qtbot, window) == "done", window.last_status
    pp = window.projection_panel
    pp.sliders[0].setValue(35)                     # a turn in R^4
    i = pp.color_combo.findData("x")
    pp.color_combo.setCurrentIndex(i)
    cam = window.plotter.camera
    cam.azimuth = 20.0
    cam.zoom(1.3)
    before = (pp.state(), list(cam.position), list(cam.focal_point), cam.parallel_scale, pp.model.mapping)
    window.formula_panel.parameters.set_value("r", 0.6)
    _until_result(qtbot, window, lambda cx: cx.meta["params"] == {"r": 0.6})
    after = (pp.state(), list(cam.position), list(cam.focal_point), cam.parallel_scale, pp.model.mapping)
    assert after[0] == before[0] and after[4] == before[4] == "stereographic"
    assert after[1] == pytest.approx(before[1]) and after[2] == pytest.approx(before[2])
    assert after[3] == pytest.approx(before[3])
    assert window.scene.style.color_by == "x"


def test_continuation_steps_from_the_previous_result(qtbot, window):
    window.load_example("hyperboloid", div=16, method="gcch")
    assert wait_run(qtbot, window) == "done", window.last_status
    first = window.result
    window.formula_panel.parameters.set_value("a", 0.4)
    _until_result(qtbot, window, lambda cx: cx.meta["params"] == {"a": 0.4})
    assert window.model.job.start is first                 # continued from the result that was on screen
    assert window.result.euler_characteristic() == 0
    window.formula_panel.parameters.set_value("a", -0.4)   # through the cone to two sheets
    _until_result(qtbot, window, lambda cx: cx.meta["params"] == {"a": -0.4})
    assert window.result.euler_characteristic() == 2


def test_a_new_value_supersedes_the_step_in_flight(qtbot, window):
    window.load_example("hyperboloid", div=16)
    assert wait_run(qtbot, window) == "done", window.last_status
    params = window.formula_panel.parameters
    ends = []
    window.runFinished.connect(ends.append)
    for v in (0.1, 0.2, 0.3, 0.4, -0.6):   # five full steps at once: the last one wins, no backlog
        params.set_value("a", v)
    _until_result(qtbot, window, lambda cx: cx.meta["params"] == {"a": -0.6})
    qtbot.wait(300)
    assert window.result.meta["params"] == {"a": -0.6} and not window.is_running()
    assert len(ends) <= 3   # the one in flight (cancelled) and the newest; the three between never ran


def test_parameters_and_ranges_are_saved_in_sessions_and_undone(qtbot, window, tmp_path):
    window.load_example("hyperboloid", div=16)
    assert wait_run(qtbot, window) == "done", window.last_status
    params = window.formula_panel.parameters
    window.model.history.merge_seconds = -1.0
    row = params.rows["a"]
    row.min_edit.setText("-2")
    row.min_edit.editingFinished.emit()
    params.set_value("a", -1.5)
    _until_result(qtbot, window, lambda cx: cx.meta["params"] == {"a": -1.5})
    path = tmp_path / "s.json"
    window.save_session(path)
    import json

    assert json.loads(path.read_text())["system"]["params"] == {"a": {"value": -1.5, "min": -2.0, "max": 1.0}}
    assert window.controller.undo()   # the value comes back, and the manifold at it
    assert params.state()["a"] == {"value": 0.5, "min": -2.0, "max": 1.0}
    _until_result(qtbot, window, lambda cx: cx.meta["params"] == {"a": 0.5})
    params.set_value("a", 0.7, commit=False)
    assert window.controller.open_session(path)
    assert wait_run(qtbot, window) == "done"
    assert params.state() == {"a": {"value": -1.5, "min": -2.0, "max": 1.0}}
    assert window.result.meta["params"] == {"a": -1.5}


def test_typed_values_and_ranges(qtbot, window):
    p = window.formula_panel
    p.set_state(dict(n=2, k=1, variables=["x", "y"], formulas=["x^2 + y^2 - r^2"], bounds=[[-3, 3]] * 2, div=8,
                     params="r = 0.5"))   # (a session of before the sliders)
    settle(qtbot, p)
    row = p.parameters.rows["r"]
    assert row.state == {"value": 0.5, "min": -1.0, "max": 1.0}
    row.value_edit.setText("pi/2")          # outside the range: the range widens
    row.value_edit.editingFinished.emit()
    assert row.state["value"] == pytest.approx(1.5707963) and row.state["max"] >= row.state["value"]
    assert wait_run(qtbot, window) == "done"   # (a committed value runs)
    row.value_edit.setText("1/0")
    row.value_edit.editingFinished.emit()
    assert p.parameters.error.isVisibleTo(p.parameters) and "1/0" in p.parameters.error.text()
    row.min_edit.setText("3")
    row.min_edit.editingFinished.emit()
    assert "min < max" in p.parameters.error.text() and row.state["min"] == -1.0


def test_a_name_one_edit_from_a_variable_asks_before_it_becomes_a_parameter(qtbot, window):
    p = window.formula_panel
    p.set_state(dict(n=3, k=1, variables=["x", "y", "z"], formulas=["x^2 + y^2 + z^2 - 1"], bounds=[[-2, 2]] * 3,
                     div=8))
    settle(qtbot, p)
    assert p.is_valid() and p.typo_prompt.isHidden()
    p.formula_edits[0].setText("x^2 + yy^2 + z^2 - 1")
    settle(qtbot, p)
    prompt = p.typo_prompt
    assert not prompt.isHidden() and "did you mean y?" in prompt.message()
    assert p.parameters.names() == []                   # no slider for the typo ...
    assert not p.is_valid() and not window.run_button.isEnabled()   # ... and no run until it is answered
    prompt.use_button.click()
    settle(qtbot, p)
    assert p.formula_edits[0].text() == "x^2 + y^2 + z^2 - 1"
    assert p.is_valid() and prompt.isHidden() and window.run_button.isEnabled()
    # a name the user says is a parameter gets its slider
    p.formula_edits[0].setText("x^2 + y^2 + z^2 - zz")
    settle(qtbot, p)
    assert "did you mean z?" in prompt.message() and not p.is_valid()
    prompt.keep_button.click()
    settle(qtbot, p)
    assert p.parameters.names() == ["zz"] and p.is_valid() and prompt.isHidden()


def test_which_names_look_like_typos():
    from gcmh_studio.formula_names import did_you_mean, one_edit_apart

    assert did_you_mean("yy", ["x", "y", "z"]) == "y"
    assert did_you_mean("x12", ["x1", "x2"]) == "x1"
    assert did_you_mean("sx", ["xs"]) == "xs"               # two neighbours swapped
    assert did_you_mean("a", ["x", "y", "z"]) is None       # a one-letter parameter beside one-letter variables
    assert did_you_mean("alpha", ["x", "y"]) is None
    assert not one_edit_apart("ab", "ba c") and one_edit_apart("abc", "abd") and not one_edit_apart("abc", "abc")
