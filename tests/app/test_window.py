"""The main window under Xvfb: examples, runs, worker thread, projection, input checks, files."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from gcmh_core.examples import list_examples

from app_helpers import app_in_process, picture_stats, run_and_wait, settle, small_div, wait_run

EXAMPLES = [ex.name for ex in list_examples()]
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def changed_fraction(a, b):
    return float(np.mean(np.any(a[..., :3] != b[..., :3], axis=-1)))


def set_system(qtbot, w, n, k, formulas, bounds=("-1.5", "1.5"), div="8", variables=None):
    """Fill the Manifold panel through its widgets, as a user would."""
    p = w.formula_panel
    p.complex_check.setChecked(False)   # (a complex example opens in complex mode: a real system is typed without)
    p.n_spin.setValue(n)
    p.k_spin.setValue(k)
    if variables is not None:
        p.vars_edit.clear()
        qtbot.keyClicks(p.vars_edit, ", ".join(variables))
    for e, f in zip(p.formula_edits, formulas):
        e.clear()
        qtbot.keyClicks(e, f)
    for r in range(n):
        p.table.item(r, 0).setText(bounds[0])
        p.table.item(r, 1).setText(bounds[1])
    p.per_axis.setChecked(False)
    p.div_edit.clear()
    qtbot.keyClicks(p.div_edit, str(div))
    settle(qtbot, p)


# --------------------------------------------------------------------------- examples
@pytest.mark.parametrize("name", EXAMPLES)
def test_each_example_gives_a_picture(qtbot, small_window, name):
    from gcmh_core.examples import load_example

    window = small_window
    blank = window.screenshot_array()
    ex = load_example(name)
    with qtbot.waitSignal(window.runFinished, timeout=180_000) as b:
        assert window.load_example(name, div=small_div(ex))
    assert b.args[0] == "done", window.last_status
    assert window.result is not None and window.result.count(0) > 0
    img = window.screenshot_array()
    assert picture_stats(img) > 300, "too few colours: is anything drawn?"
    assert changed_fraction(img, blank) > 0.03
    # the example's suggested view is applied
    pp = window.projection_panel
    assert pp.color_by() == ex.view["color"]
    assert [pp.names[a] for a in pp.model.axes] == list(ex.view["project"])
    assert "\u03c7 =" in window.result_label.text()


def test_examples_menu_lists_every_example(window):
    assert set(window.menu_actions.examples) == set(EXAMPLES)
    for a in window.menu_actions.examples.values():
        assert a.text() and a.statusTip()


# --------------------------------------------------------------------------- typing and running
def test_sphere_typed_in_gives_euler_characteristic_2(qtbot, window):
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="8")
    assert window.formula_panel.is_valid(), window.formula_panel.errors
    assert window.run_button.isEnabled()
    with qtbot.waitSignal(window.runFinished, timeout=60_000) as b:
        qtbot.mouseClick(window.run_button, 1)  # Qt.LeftButton
    assert b.args[0] == "done", window.last_status
    cx = window.result
    assert cx.dim == 2
    assert cx.euler_characteristic() == 2
    assert len(cx.boundary_facets()) == 0
    assert "\u03c7 = 2" in window.result_label.text()


def test_circle_in_the_plane_draws_lines(qtbot, window):
    set_system(qtbot, window, 2, 1, ["x1^2 + x2^2 - 1"], div="12")
    assert run_and_wait(qtbot, window) == "done"
    assert window.result.dim == 1
    assert window.result.euler_characteristic() == 0
    assert window.scene.mesh.n_lines == window.result.count(1)


def test_worker_error_goes_to_status_not_a_crash(qtbot, window):
    # log of a negative number everywhere: the engine may refuse or return nothing; never a crash
    set_system(qtbot, window, 3, 1, ["x1 + x2 + x3 - 1"], div="4")
    assert run_and_wait(qtbot, window) == "done"
    job = window.formula_panel.job()
    job.bounds = [(1.0, 0.0)] * 3    # invalid: bypasses the panel's checks, reaches the engine
    from gcmh_studio.worker import ExtractWorker

    w = ExtractWorker(job)
    with qtbot.waitSignal(w.failed, timeout=30_000) as b:
        w.start()
    w.wait(5000)
    assert b.args[0]


# --------------------------------------------------------------------------- the worker thread
def _long_run(qtbot, window):
    """A run that takes several seconds (5 s measured; cancelled after one): the 3-sphere in R^4 at div 60.
    (The Klein bottle at div 56 once took several seconds; the pruned sweep does it in one.)"""
    set_system(qtbot, window, 4, 1, ["x1^2 + x2^2 + x3^2 + x4^2 - 1"], div="60", variables=["x1", "x2", "x3", "x4"])
    assert window.run()


def test_gui_stays_responsive_and_cancel_is_prompt(qtbot, window):
    from qtpy.QtCore import QTimer

    # a first result, to be kept on screen
    assert window.load_example("complex-cosine", div=[8, 8, 8, 8])
    assert wait_run(qtbot, window) == "done"
    old = window.result
    old_cells = window.scene.mesh.n_cells
    old_points = np.array(window.scene.mesh.points)

    ticks = []
    timer = QTimer()
    timer.setInterval(20)
    timer.timeout.connect(lambda: ticks.append(1))
    _long_run(qtbot, window)
    timer.start()
    # meanwhile the GUI thread serves events and the old result can be turned
    window.projection_panel.sliders[0].setValue(30)
    qtbot.wait(1000)
    assert window.is_running(), "the long run ended too early for this test"
    assert ticks, "the GUI thread served no timer event while the run went on"
    assert not np.allclose(window.scene.mesh.points, old_points), "the old result did not turn during the run"
    assert window.progress.format() != "idle" and not window.run_button.isEnabled()

    with qtbot.waitSignal(window.runFinished, timeout=5000) as b:
        window.menu_actions.cancel.trigger()
    timer.stop()
    assert b.args[0] == "cancelled"
    assert not window.is_running() and window.progress.format() == "cancelled"
    assert window.result is old
    assert window.scene.mesh is not None and window.scene.mesh.n_cells == old_cells
    assert "Cancelled" in window.last_status
    assert window.run_button.isEnabled()


def test_escape_key_cancels(qtbot, window):
    from qtpy.QtCore import Qt

    window.activateWindow()
    qtbot.waitActive(window)
    _long_run(qtbot, window)
    qtbot.wait(300)
    target = window.focusWidget() or window
    with qtbot.waitSignal(window.runFinished, timeout=5000) as b:
        qtbot.keyClick(target, Qt.Key_Escape)
    assert b.args[0] == "cancelled"


# --------------------------------------------------------------------------- projection
def test_rotation_slider_changes_picture_not_topology(qtbot, window):
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("klein-bottle", div=[12, 12, 6, 12, 12])
    mesh = window.scene.mesh
    n_cells, n_points = mesh.n_cells, mesh.n_points
    before = window.screenshot_array()
    pts_before = np.array(mesh.points)
    pp = window.projection_panel
    row = pp.model.planes.index((0, 3))   # x-s
    assert pp.slider_labels[row].text() == "x\u2013s"
    pp.sliders[row].setValue(60)
    after = window.screenshot_array()
    assert window.scene.mesh is mesh, "the mesh must be updated in place"
    assert mesh.n_cells == n_cells and mesh.n_points == n_points
    assert not np.allclose(pts_before, mesh.points)
    assert changed_fraction(before, after) > 0.02
    assert window.scene.axes_labels()[0] != "x"
    # reset brings back the coordinate view
    pp.reset()
    np.testing.assert_allclose(mesh.points, pts_before, atol=1e-5)
    assert window.scene.axes_labels() == ["x", "y", "z"]


def _view_complex(qtbot, window, n):
    """A real n-dimensional complex for the view tests: from the engine for n <= 5,
    else a flat torus built as a CellComplex (the engine at k = n - 2 > 3 is slow)."""
    if n <= 5:
        k = n - 2 if n > 3 else 1
        if n == 3:
            forms = ["x1^2 + x2^2 + x3^2 - 1"]
        elif n == 4:
            forms = ["x1^2 + x2^2 - 1", "x3^2 + x4^2 - 1"]
        else:
            forms = ["x1^2 + x2^2 - 1", "x3^2 + x4^2 - 1", "x5 - x1*x3"]
        set_system(qtbot, window, n, k, forms, div="6")
        assert run_and_wait(qtbot, window) == "done", window.last_status
        return window.result
    from app_helpers import torus_complex

    cx = torus_complex(24, n)
    window.show_result(cx, cx.point_names(), title=f"flat torus in R^{n}")
    return cx


@pytest.mark.parametrize("n", [3, 4, 5, 10])   # (n = 6 would be a flat torus like 10)
def test_projection_chooser(qtbot, small_window, n):
    window = small_window
    cx = _view_complex(qtbot, window, n)
    pp = window.projection_panel
    assert len(pp.sliders) == n * (n - 1) // 2
    mesh = window.scene.mesh
    n_cells = mesh.n_cells
    seen = []
    # (n >= 4: each point is held SHEET_GAP of the radius off the sheets a linear view lays onto it)
    from gcmh_studio.scene import SHEET_GAP

    gap = 1e-4 + (1.01 * SHEET_GAP * window.scene.projector.radii()[0] if n >= 4 else 0.0)
    for kind in ("coordinates", "generic", "principal"):
        pp.set_kind(kind)
        P = pp.matrix()
        np.testing.assert_allclose(P @ P.T, np.eye(3), atol=1e-9)
        expected = (cx.vertices - window.scene.projector.center) @ P.T
        np.testing.assert_allclose(mesh.points, expected, rtol=1e-4, atol=gap)
        assert mesh.n_cells == n_cells
        seen.append(np.array(mesh.points))
        img = window.screenshot_array()
        assert picture_stats(img) > 100
    assert not np.allclose(seen[0], seen[1])
    # coordinate triple chosen by the user
    pp.set_kind("coordinates")
    if n == 3:  # a duplicate screen axis is refused with a message
        pp.axis_combos[0].setCurrentIndex(pp.axis_combos[0].findData(2))
        assert not pp.axes_error.isHidden() and pp.axes_error.text() and pp.model.axes == (0, 1, 2)
    for c in pp.axis_combos:
        c.setCurrentIndex(c.findData(-1))
    for c, a in zip(pp.axis_combos, (n - 1, 0, 1)):
        c.setCurrentIndex(c.findData(a))
    assert pp.model.axes == (n - 1, 0, 1)
    assert pp.axes_error.isHidden()
    np.testing.assert_allclose(mesh.points[:, 0], cx.vertices[:, n - 1] - window.scene.projector.center[n - 1],
                               rtol=1e-4, atol=gap)
    # the last slider exists and moves the picture
    pp.sliders[-1].setValue(45)
    assert mesh.n_cells == n_cells


def test_colour_opacity_edges(qtbot, window):
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("klein-bottle", div=[12, 12, 6, 12, 12])
    pp = window.projection_panel
    assert pp.color_by() == "s"
    assert "s" in window.plotter.scalar_bars.keys()
    pp.set_color_by("t")
    assert "t" in window.plotter.scalar_bars.keys() and "s" not in window.plotter.scalar_bars.keys()
    pp.set_color_by(None)
    assert len(window.plotter.scalar_bars.keys()) == 0
    pp.opacity_slider.setValue(40)
    assert window.scene.actor.prop.opacity == pytest.approx(0.4)
    pp.edges_check.setChecked(True)
    assert window.scene.actor.prop.show_edges


# --------------------------------------------------------------------------- input checks
def _msg_visible(label):
    return label.isVisible() and bool(label.text())


def test_bad_input_is_refused_next_to_the_field(qtbot, window):
    p = window.formula_panel
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"])
    assert p.is_valid() and window.run_button.isEnabled()

    def refused(label, key=None):
        settle(qtbot, p)
        assert not p.is_valid()
        assert not window.run_button.isEnabled()
        assert not window.menu_actions.run.isEnabled()
        assert _msg_visible(label), "no message next to the field"
        assert not window.run()  # even a forced run is refused, with a message
        assert window.last_status.startswith("Cannot run")

    def fixed():
        settle(qtbot, p)
        assert p.is_valid(), p.errors
        assert window.run_button.isEnabled()

    f = p.formula_edits[0]
    for bad, words in [("x1^2 + (x2", None), ("sinn(x1) - 1", "sinn"), ("", "empty"), ("x1 +* 2", None)]:
        f.clear()
        if bad:
            qtbot.keyClicks(f, bad)
        refused(p.formula_errors[0])
        if words:
            assert words in p.formula_errors[0].text()
        assert "border" in f.styleSheet()   # the red mark
    f.clear()
    qtbot.keyClicks(f, "x1 + y")   # a name that is no variable is a parameter: it gets a slider, in sight
    fixed()
    assert p.parameters.names() == ["y"] and p.parameters.isVisibleTo(p)
    f.clear()
    qtbot.keyClicks(f, "x1^2 + x2^2 + x3^2 - 1")
    fixed()
    assert p.parameters.names() == []

    # k >= n
    p.k_spin.setValue(3)
    refused(p.nk_error)
    p.k_spin.setValue(1)
    fixed()

    # variables
    p.vars_edit.setText("a, b")
    refused(p.vars_error)
    p.vars_edit.setText("x1, x2, x2")
    refused(p.vars_error)
    p.vars_edit.setText("x1, x2, x3")
    fixed()

    # domain: lower above upper, empty interval, not a number
    for lo, hi in [("2", "1"), ("1", "1"), ("abc", "1"), ("", "1"), ("-pi/2", "1/0")]:
        p.table.item(1, 0).setText(lo)
        p.table.item(1, 1).setText(hi)
        refused(p.domain_error)
    p.table.item(1, 0).setText("-pi/2")
    p.table.item(1, 1).setText("pi/2")
    fixed()

    # div 0, negative, fractional, text
    for bad in ["0", "-3", "2.5", "ten"]:
        p.div_edit.setText(bad)
        refused(p.div_error)
    p.div_edit.setText("6")
    fixed()
    # per-axis div
    p.per_axis.setChecked(True)
    p.table.item(2, 2).setText("0")
    refused(p.domain_error)
    p.table.item(2, 2).setText("5")
    fixed()
    assert p.div() == [6, 6, 5]
    assert run_and_wait(qtbot, window) == "done"


def test_big_run_asks_first(qtbot, window, monkeypatch):
    import dataclasses

    import gcmh_studio.worker
    from gcmh_studio.qt_actions import big_run_text

    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="8")
    real = gcmh_studio.worker.estimate_job
    # the real estimate of this run, said to need a petabyte (gcmh) so that it won't fit
    monkeypatch.setattr(gcmh_studio.worker, "estimate_job", lambda job: dataclasses.replace(
        real(job), peak_bytes=10**15 if job.method == "gcmh" else real(job).peak_bytes))
    asked, forced = [], []
    monkeypatch.setattr(window, "confirm_big_run", lambda est: asked.append(est) or None)
    with qtbot.waitSignal(window.runFinished, timeout=30_000) as b:
        assert window.run()
    assert b.args[0] == "declined" and window.result is None
    assert asked and not asked[0].fits and "smaller div" in window.last_status
    text = big_run_text(asked[0], gcch=True)
    assert "TB of memory" in text and "available" in text and "GCCH" in text
    assert not window.is_running()

    real_run = gcmh_studio.worker.run_job
    monkeypatch.setattr(gcmh_studio.worker, "run_job",
                        lambda job, **kw: forced.append(job.force) or real_run(job, **kw))
    monkeypatch.setattr(window, "confirm_big_run", lambda est: "run")   # the user agrees: force=True
    assert run_and_wait(qtbot, window) == "done"
    assert forced == [True]
    import gcmh_core

    if "gcch" in gcmh_core.METHODS:   # the dialog's other answer: switch to continuation and run
        monkeypatch.setattr(window, "confirm_big_run", lambda est: "gcch")
        window.formula_panel.set_method("gcmh")
        assert run_and_wait(qtbot, window) == "done"
        assert window.formula_panel.method() == "gcch" and forced[-1] is False   # gcch fits: no force
        assert window.result.euler_characteristic() == 2


# --------------------------------------------------------------------------- files
def test_session_save_and_open_restores_state(qtbot, window, tmp_path):
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("complex-cosine", div=[7, 7, 7, 7])
    pp = window.projection_panel
    pp.set_kind("generic")
    pp.seed_spin.setValue(4)
    pp.sliders[2].setValue(33)
    pp.set_color_by("u")
    pp.opacity_slider.setValue(70)
    window.formula_panel.seed_spin.setValue(3)
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.run()
    pp.sliders[2].setValue(33)
    pp.set_mapping("perspective")       # issue 5: mapping, slice and two-sided colours are part of the view
    pp.set_slice("u", 0.4, 0.05)
    pp.two_sided_check.setChecked(True)
    state = window.controller.session()
    assert state["view"]["mapping"] == "perspective" and state["view"]["slice"]["along"] == "u"
    path = tmp_path / "s.json"
    window.save_session(path)
    d = json.loads(path.read_text())
    assert d["format"] == "gcmh-session/1"
    points = np.array(window.scene.mesh.points)

    from gcmh_studio.qt_main_window import QtMainWindow

    w2 = QtMainWindow(example=None)
    qtbot.addWidget(w2)
    w2.show()
    try:
        with qtbot.waitSignal(w2.runFinished, timeout=60_000):
            assert w2.controller.open_session(path)
        s2 = w2.controller.session()
        assert s2["system"] == state["system"]
        assert s2["view"] == state["view"]
        assert w2.scene.slice is not None and w2.scene.view.mapping == "perspective" and w2.scene.style.two_sided
        np.testing.assert_allclose(s2["camera"]["position"], state["camera"]["position"], rtol=1e-6)
        np.testing.assert_allclose(w2.scene.mesh.points, points, atol=1e-5)
        assert w2.projection_panel.color_by() == "u"
    finally:
        w2.close()


def test_open_bad_session_reports(window, tmp_path):
    p = tmp_path / "bad.json"
    p.write_text("{not json")
    assert not window.controller.open_session(p)
    assert "Cannot open" in window.last_status


def test_screenshot_export_size_and_transparency(qtbot, window, tmp_path):
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("torus")
    import pyvista as pv

    path = tmp_path / "shot.png"
    window.save_screenshot(path, size=(640, 360))
    img = pv.read(str(path))
    assert tuple(img.dimensions[:2]) == (640, 360)
    arr = window.save_screenshot(tmp_path / "t.png", size=(320, 200), transparent=True)
    assert arr.shape == (200, 320, 4)
    alpha = arr[..., 3]
    assert (alpha == 0).mean() > 0.2 and (alpha == 255).mean() > 0.02


def test_exports(qtbot, window, tmp_path):
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("torus")
    from gcmh_core.complex import CellComplex

    window.export_complex(tmp_path / "c.npz")
    back = CellComplex.load(tmp_path / "c.npz")
    assert back.counts() == window.result.counts()
    window.export_complex(tmp_path / "c.vtu")
    assert (tmp_path / "c.vtu").stat().st_size > 0
    import pyvista as pv

    for ext in ("ply", "obj", "vtp"):
        window.export_mesh(tmp_path / f"m.{ext}")
        m = pv.read(str(tmp_path / f"m.{ext}"))
        assert m.n_points > 0 and m.n_cells > 0
    with pytest.raises(ValueError):
        window.export_mesh(tmp_path / "m.xyz")


def test_shortcuts(window):

    def keys(a):
        return {s.toString() for s in a.shortcuts()}

    assert "Ctrl+R" in keys(window.menu_actions.run)
    assert "Esc" in keys(window.menu_actions.cancel)
    assert {"Ctrl+Shift+S", "F12"} <= keys(window.menu_actions.screenshot)
    assert "Ctrl+O" in keys(window.menu_actions.open)
    assert "Ctrl+S" in keys(window.menu_actions.save)


# --------------------------------------------------------------------------- headless command
def test_headless_screenshot_command(tmp_path):
    out = tmp_path / "klein.png"
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    r = subprocess.run([sys.executable, "-m", "gcmh_studio", "--example", "klein-bottle", "--screenshot", str(out),
                        "--size", "400x300", "--div", "10"], cwd=REPO, env=env,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    import pyvista as pv

    img = pv.read(str(out))
    assert tuple(img.dimensions[:2]) == (400, 300)
    arr = np.asarray(img.point_data.active_scalars)
    assert len(np.unique(arr.reshape(len(arr), -1), axis=0)) > 300


def test_headless_bad_example_is_a_clean_error(tmp_path, capsys, monkeypatch):
    code, _, err = app_in_process(capsys, monkeypatch, "--example", "no-such-thing", "--screenshot",
                                  str(tmp_path / "x.png"))
    assert code == 2
    assert "no-such-thing" in err and "Traceback" not in err


def test_empty_result_is_explained(qtbot, window):
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 + 1"], div="4")
    assert run_and_wait(qtbot, window) == "done"
    assert window.result.count(0) == 0
    assert window.scene.mesh is None
    assert "empty" in window.last_status
    window.projection_panel.sliders[0].setValue(20)   # no mesh: nothing to move, no error


def test_engine_error_in_the_window_goes_to_the_status(qtbot, window, monkeypatch):
    import gcmh_studio.worker

    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="6")
    assert run_and_wait(qtbot, window) == "done"
    old = window.result

    def broken(job, progress=None, cancel=None):
        raise RuntimeError("simulated failure inside the engine")

    monkeypatch.setattr(gcmh_studio.worker, "run_job", broken)
    assert run_and_wait(qtbot, window) == "failed"
    assert "simulated failure" in window.last_status
    assert window.result is old and window.scene.mesh is not None
    assert window.run_button.isEnabled()


def test_methods_offered_are_the_engines(window):
    import gcmh_core

    p = window.formula_panel
    offered = [p.method_combo.itemData(i) for i in range(p.method_combo.count())]
    assert offered == [m.lower() for m in getattr(gcmh_core, "METHODS", ("gcmh",))]


def test_opens_on_the_klein_bottle(qtbot):
    from gcmh_studio.qt_main_window import QtMainWindow

    w = QtMainWindow()          # the default: the Klein bottle, run at start
    qtbot.addWidget(w)
    w.show()
    try:
        assert wait_run(qtbot, w, timeout=180_000) == "done"
        pp = w.projection_panel
        assert pp.names == ["x", "y", "z", "s", "t"]
        assert [pp.names[a] for a in pp.model.axes] == ["x", "y", "z"]
        assert pp.color_by() == "s"
        assert "s" in w.plotter.scalar_bars.keys()
        assert w.result.dim == 2
    finally:
        w.close()


def test_continuation_from_the_panel(qtbot, window):
    import gcmh_core

    if "gcch" not in gcmh_core.METHODS:
        pytest.skip("the engine has no continuation method")
    p = window.formula_panel
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="10")
    assert run_and_wait(qtbot, window) == "done"
    full = window.result.counts()
    assert p.set_method("gcch")
    assert p.start_edit.isVisibleTo(p)
    p.start_edit.setText("1, 2")             # wrong number of coordinates
    assert not p.is_valid() and p.start_error.text()
    p.start_edit.setText("0, 0, 1")
    assert p.is_valid()
    assert run_and_wait(qtbot, window) == "done"
    assert window.result.counts() == full
    p.start_edit.setText("")                 # auto
    assert p.is_valid()
    assert run_and_wait(qtbot, window) == "done"
    assert window.result.counts() == full


def test_ccs_takes_a_start_point_and_a_bad_cluster_address_is_marked(qtbot, window):
    p = window.formula_panel
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="8")
    assert p.set_method("ccs")
    assert p.start_edit.isVisibleTo(p)      # CCS is a continuation method too
    p.start_edit.setText("0, 0, 1")
    assert p.is_valid()
    p.scheduler_edit.setText("somewhere")   # neither 'local' nor tcp://host:port
    assert not p.is_valid() and "scheduler" in p.scheduler_error.text()
    assert not window.run_button.isEnabled()
    p.scheduler_edit.setText("tcp://localhost:8786")
    assert p.is_valid() and p.job().scheduler == "tcp://localhost:8786"
    p.scheduler_edit.setText("")
    assert p.is_valid() and p.job().scheduler is None
    assert p.state()["scheduler"] == ""
    assert run_and_wait(qtbot, window) == "done"
    assert window.result.euler_characteristic() == 2 and window.result.meta["method"] == "ccs"


def test_run_on_a_local_cluster_shows_blocks(qtbot, window):
    pytest.importorskip("dask.distributed")
    p = window.formula_panel
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="12")
    assert run_and_wait(qtbot, window) == "done"
    here = window.result
    p.scheduler_edit.setText("local")
    phases = []
    window.runs.progress.connect(lambda phase, fraction, seconds: phases.append(phase))  # as the window receives it
    assert run_and_wait(qtbot, window, timeout=180_000) == "done"
    assert any("blocks" in ph for ph in phases), phases
    there = window.result
    assert np.array_equal(here.vertices, there.vertices) and np.array_equal(here.edges, there.edges)
    assert there.meta.get("blocks", 0) >= 1


def test_an_example_opens_in_its_own_mapping(qtbot, window):
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("hopf-tori")
    pp = window.projection_panel
    assert pp.model.mapping == "stereographic" and window.scene.view.mapping == "stereographic"
    assert pp.mapping_combo.currentData() == "stereographic"
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("sphere")     # the next example brings its own (orthographic) view
    assert pp.model.mapping == "orthographic" and window.scene.view.mapping == "orthographic"


def test_own_system_after_an_example_drops_the_example_title(qtbot, window):
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("torus")
    assert window.scene.style.title
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="6", variables=["x1", "x2", "x3"])
    assert run_and_wait(qtbot, window) == "done"
    assert window.scene.style.title == ""
    assert window.projection_panel.color_by() == "x3"   # a new system is coloured by its last coordinate


def test_headless_view_options(tmp_path, capsys, monkeypatch):
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    out = tmp_path / "c.png"
    r = subprocess.run([sys.executable, "-m", "gcmh_studio", "--example", "complex-cosine", "--screenshot", str(out),
                        "--size", "320x240", "--div", "8", "--project", "u,v,y", "--color", "x",
                        "--rotate", "v-x=30", "--transparent"], cwd=REPO, env=env,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 0
    code, _, err = app_in_process(capsys, monkeypatch, "--example", "complex-cosine", "--screenshot", str(out),
                                  "--project", "u,v,q")
    assert code == 2 and "variables are" in err


# --------------------------------------------------------------------------- issue 5: seeing higher dimensions
def _klein(qtbot, window, div=(12, 12, 8, 16, 16)):
    with qtbot.waitSignal(window.runFinished, timeout=120_000) as b:
        window.load_example("klein-bottle", div=list(div))
    assert b.args[0] == "done", window.last_status
    return window.result


def test_slice_window_clips_the_klein_bottle(qtbot, window):
    cx = _klein(qtbot, window)
    pp = window.projection_panel
    full = window.scene.mesh.n_cells
    assert pp.set_slice("s", 0.5, 0.03)
    mesh = window.scene.mesh
    s = np.asarray(mesh.point_data["s"])
    lo, hi = cx.vertices[:, 3].min(), cx.vertices[:, 3].max()
    c, w = lo + 0.5 * (hi - lo), 0.03 * (hi - lo)
    assert 0 < mesh.n_cells < full / 4
    assert np.all(s >= c - w - 1e-9) and np.all(s <= c + w + 1e-9)
    assert np.isclose(s.min(), c - w) and np.isclose(s.max(), c + w)     # clipped, not dropped
    assert "cells" in pp.slice_info.text()
    assert window.scene._ghost is not None          # the whole bottle, faint, for context
    # moving the centre slider moves the window
    pp.slice_c.setValue(100)
    s2 = np.asarray(window.scene.mesh.point_data["s"])
    assert s2.max() < s.min()
    # a hidden direction of the view: for (x, y, z) of R^5 hidden direction 1 is s itself
    pp.set_slice("hidden direction 1", 0.5, 0.03)
    assert np.allclose(window.scene.slice[0], np.eye(5)[3])
    # ...and it turns with the view
    pp.set_angle((2, 3), 30)
    assert not np.allclose(window.scene.slice[0], np.eye(5)[3])
    img = window.screenshot_array()
    assert picture_stats(img) > 50
    pp.set_slice(None)
    assert window.scene.mesh.n_cells == full and window.scene.slice is None and window.scene._ghost is None


def test_slice_outside_is_empty_and_the_view_survives(qtbot, window):
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], bounds=("-1.5", "1.5"), div="8")
    assert run_and_wait(qtbot, window) == "done"
    pp = window.projection_panel
    pp.set_slice("x3", 0.5, 0.02)       # the equator: a band
    band = np.asarray(window.scene.mesh.points)
    assert len(band) and np.all(np.abs(band[:, 2]) < 0.1)
    pp.set_slice("x3", 0.0, 0.02)       # the window reaches just over the bottom: a small cap
    cap = window.scene.mesh.n_cells
    assert 0 < cap < 20
    assert window.scene.set_slice([0, 0, 1], 1.5, 0.1) == 0     # beyond the sphere: nothing
    assert window.scene.mesh is None
    pp.set_angle((0, 1), 20)            # turning the view with the slider re-slices; nothing breaks
    window.screenshot_array()
    pp.set_slice(None)
    assert window.scene.mesh is not None


def test_mapping_kinds_keep_the_rotation(qtbot, window):
    from gcmh_studio.projection import stereographic

    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        window.load_example("clifford-torus", div=10)
    pp = window.projection_panel
    pp.set_angle((0, 3), 25)
    angles = pp.model.angles.copy()
    pp.set_mapping("stereographic")
    assert np.allclose(pp.model.angles, angles)
    sc = window.scene
    X = (window.result.vertices - sc.geometry.projector.center)
    Y = pp.model.frame() @ X.T
    r = sc.geometry.projector.radii()[1]
    np.testing.assert_allclose(sc.mesh.points, stereographic(Y, r).T, rtol=1e-4, atol=1e-4)
    # normals come from the projected mesh: unit-ish, finite
    N = np.asarray(sc.mesh.point_data["Normals"])
    assert np.all(np.isfinite(N)) and np.linalg.norm(N, axis=1).min() > 0
    before = np.array(sc.mesh.points)
    pp.set_angle((2, 3), 40)            # the sliders still update in place
    assert not np.allclose(before, sc.mesh.points)
    pp.set_mapping("perspective")
    pp.distance_slider.setValue(20)
    assert pp.model.distance == 2.0 and "perspective" in sc.style.subtitle
    pp.set_mapping("orthographic")
    from gcmh_studio.scene import SHEET_GAP  # (a linear view holds each point this much off coincident sheets)

    np.testing.assert_allclose(sc.mesh.points, X @ pp.matrix().T, rtol=1e-4,
                               atol=1e-4 + 1.01 * SHEET_GAP * sc.projector.radii()[0])
    # R^3: nothing is hidden, the choice is refused next to the field
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="6")
    assert run_and_wait(qtbot, window) == "done"
    pp.set_mapping("perspective")
    assert pp.model.mapping == "orthographic" and not pp.mapping_error.isHidden()


def test_animation_play_tour_rotate_and_sweep(qtbot, window):
    _klein(qtbot, window)
    ap, pp = window.animation_panel, window.projection_panel
    assert ap.plane() == (2, 3)         # by default a plane that turns a hidden axis (s) into view (z)
    ap.set_mode("rotate")
    ap.set_plane((3, 4))
    row = pp.model.planes.index((3, 4))
    window._on_anim_playing(True)
    assert "hidden" in ap.message.text()   # s-t: both hidden, said so (the angle still turns)
    window.controller.tick(1.5)           # 1.5 s at speed 1: 45 degrees
    assert pp.model.angles[row] == pytest.approx(45.0)
    assert pp.sliders[row].value() == 45
    ap.set_mode("tour")
    a0 = pp.model.angles.copy()
    pts0 = np.array(window.scene.mesh.points)
    with qtbot.waitSignal(pp.projectionChanged, timeout=3000):
        ap.set_playing(True)
    qtbot.wait(300)
    ap.set_playing(False)
    assert not np.allclose(pp.model.angles, a0)
    assert not np.allclose(pts0, window.scene.mesh.points)
    ap.set_mode("slice")
    ap.set_playing(True)                # no slice: refused with a message
    assert not ap.is_playing() and "slice" in ap.message.text()
    pp.set_slice("s", 0.2, 0.03)
    ap.set_playing(True)
    assert ap.is_playing()
    c0 = pp.slice_c.value()
    window.controller.tick(1.0)
    assert pp.slice_c.value() != c0
    ap.set_playing(False)


def test_export_animation_from_the_window(qtbot, window, tmp_path):
    import imageio.v3 as iio

    _klein(qtbot, window)
    ap = window.animation_panel
    ap.set_mode("rotate")
    ap.set_plane((2, 3))                # z-s: turns s into view (s-t alone would move nothing on screen)
    angles = window.projection_panel.model.angles.copy()
    p = tmp_path / "rot.gif"
    assert window.export_animation(p, frames=5, size=(200, 150)) == 5
    g = iio.imread(p, index=None, mode="RGB")
    assert g.shape[:3] == (5, 150, 200)
    assert np.allclose(window.projection_panel.model.angles, angles)      # the window's view is untouched
    window.projection_panel.set_slice("s", 0.5, 0.05)
    ap.set_mode("slice")
    m = tmp_path / "sweep.mp4"
    assert window.export_animation(m, frames=4, size=(160, 120)) == 4
    import imageio.v2 as imageio

    r = imageio.get_reader(str(m), format="ffmpeg")
    assert len([f for f in r]) == 4
    r.close()


def test_two_sided_colours_boundary_and_grid(qtbot, window):
    cx = _klein(qtbot, window)
    pp = window.projection_panel
    pp.two_sided_check.setChecked(True)
    assert window.scene.actor.backface_prop is not None
    img = window.screenshot_array()[..., :3].astype(int)
    gold = np.sum((np.abs(img - [217, 164, 65]).sum(-1) < 120) & (img[..., 0] > img[..., 2] + 60))
    blue = np.sum(img[..., 2] > img[..., 0] + 60)
    assert gold > 500 and blue > 500, (gold, blue)
    pp.boundary_check.setChecked(True)
    geo, mesh = window.scene.overlays["boundary"][:2]
    assert mesh.n_cells == len(cx.boundary_facets()) > 0
    pp.grid_check.setChecked(True)
    gmesh = window.scene.overlays["grid"][1]
    assert gmesh.n_cells > 0
    # the overlays turn with the view, in place
    before = np.array(gmesh.points)
    pp.set_angle((0, 3), 30)
    assert not np.allclose(before, gmesh.points)
    pp.set_slice("s", 0.5, 0.05)        # and are clipped by the slice
    assert window.scene.overlays["grid"][1].n_cells < gmesh.n_cells


def test_pick_a_cell_shows_its_coordinates_and_cube(qtbot, window):
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], bounds=("-1.5", "1.5"), div="8")
    assert run_and_wait(qtbot, window) == "done"
    cx = window.result
    info = window.viewer.pick_cell(5)
    off, vids = cx.polygons()
    assert list(info["vertices"]) == list(vids[off[5]:off[5 + 1]])
    assert np.allclose(info["coords"], cx.vertices[info["vertices"]])
    lo, h = -1.5, 3.0 / 8
    cube = np.floor((info["coords"].mean(0) - lo) / h).astype(int)
    assert tuple(info["cube"]) == tuple(cube)
    assert "grid cube" in window.pick_label.text() and not window.pick_label.isHidden()
    # picking on screen: the cell nearest the camera at its own centre is found again
    cam = np.array(window.plotter.camera.position)
    X = np.asarray(window.scene.mesh.points)
    cent = np.array([X[vids[off[i]:off[i + 1]]].mean(0) for i in range(len(off) - 1)])
    near = int(np.argmin(np.linalg.norm(cent - cam, axis=1)))
    xy = window.scene.display_position(near)
    assert window.viewer.pick_at(xy)["cell"] == near
    assert window.viewer.pick_at((2, 2)) is None and window.pick_label.isHidden()


def test_topology_tab_refine_and_shared_switches(qtbot, window):
    pytest.importorskip("gcmh_core.analysis")
    if window.topology_panel is None:
        pytest.skip("no topology panel in this tree")
    set_system(qtbot, window, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"], div="8")
    assert run_and_wait(qtbot, window) == "done"
    tp, pp = window.topology_panel, window.projection_panel
    rep = tp.report()
    assert rep is not None and rep["euler_characteristic"] == 2
    assert any(window.tabs.tabText(i) == "Topology" for i in range(window.tabs.count()))
    # the panel's switches and the View tab's are one and the same
    tp.two_sided_check.setChecked(True)
    assert pp.two_sided_check.isChecked() and window.scene.style.two_sided
    pp.boundary_check.setChecked(True)
    assert tp.boundary_check.isChecked()
    tp.path_check.setChecked(True)
    assert "grid" in window.scene.overlays
    # refinement moves the vertices onto M
    r0 = np.abs(np.linalg.norm(window.result.vertices, axis=1) - 1).max()
    with qtbot.waitSignal(window.refineFinished, timeout=60_000) as sig:
        assert window.controller.refine()  # in a worker thread: the button waits meanwhile
        assert not tp.refine_button.isEnabled() and not window.controller.refine()
    assert sig.args == ["done"] and tp.refine_button.isEnabled()
    out = window.model.last_refinement
    assert out is not None and out["after"] < out["before"]
    r1 = np.abs(np.linalg.norm(window.result.vertices, axis=1) - 1).max()
    assert r1 < 0.1 * r0
    assert "\u2192" in window.last_status
    # a refinement that ends after the result changed is dropped, not shown over the new one
    base = window.result
    with qtbot.waitSignal(window.refineFinished, timeout=60_000) as sig:
        assert window.controller.refine()
        window.show_result(base, window.result_names)  # (the same complex, shown anew: a new result)
        shown = window.result
    assert sig.args == ["dropped"] and window.result is shown


def test_geometry_uses_the_library_orientation(qtbot, window):
    analysis = pytest.importorskip("gcmh_core.analysis")
    cx = _klein(qtbot, window)
    geo = window.scene.geometry
    o = analysis.orient_2cells(cx)
    oo, ov = np.asarray(o.offsets), np.asarray(o.vertices)
    keep = np.diff(oo) >= 3
    expect = np.concatenate([ov[oo[i]:oo[i + 1]] for i in np.flatnonzero(keep)])
    assert np.array_equal(geo.vids, expect)


def test_gallery_opens_from_the_examples_menu(qtbot, window):
    if window.menu_actions.gallery is None:
        pytest.skip("no gallery in this tree")
    window.menu_actions.gallery.trigger()
    g = window.gallery
    qtbot.waitExposed(g)
    with qtbot.waitSignal(window.runFinished, timeout=120_000) as b:
        g.exampleChosen.emit("sphere")
    assert b.args[0] == "done" and window.result.dim == 2
    g.close()
