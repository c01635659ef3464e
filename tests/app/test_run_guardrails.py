"""The run and input side of the window (issues 15 and 16): waits that explain themselves, nothing lost,
Undo / Redo, formula checks off the GUI thread, estimates before a run, and gcmh-app's refusals.

Window tests need a display (Xvfb); the gcmh-app subprocess tests need none.
"""

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("pytestqt")

from app_helpers import run_and_wait, settle

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SPHERE = "x1^2 + x2^2 + x3^2 + x4^2 - 1"


def fill(qtbot, p, n, k, formulas, bounds=("-1.5", "1.5"), div="6"):
    p.n_spin.setValue(n)
    p.k_spin.setValue(k)
    for e, f in zip(p.formula_edits, formulas):
        e.setText(f)
    for r in range(n):
        p.table.item(r, 0).setText(bounds[0])
        p.table.item(r, 1).setText(bounds[1])
    p.div_edit.setText(div)
    settle(qtbot, p)


# --------------------------------------------------------------------------- nothing lost
def test_k_round_trip_keeps_the_formulas(qtbot, window):
    p = window.formula_panel
    fill(qtbot, p, 4, 2, [SPHERE, "x1 - x2"])
    p.k_spin.setValue(1)
    assert len(p.formula_edits) == 1 and p.formulas() == [SPHERE]
    p.k_spin.setValue(2)
    assert p.formulas() == [SPHERE, "x1 - x2"]
    settle(qtbot, p)
    assert p.is_valid(), p.errors


def test_n_round_trip_keeps_bounds_and_names(qtbot, window):
    p = window.formula_panel
    fill(qtbot, p, 4, 1, [SPHERE])
    p.vars_edit.clear()
    qtbot.keyClicks(p.vars_edit, "a, b, c, d")   # typed: the names are the user's, no longer x1..x4
    p.table.item(3, 0).setText("-pi/2")
    p.table.item(3, 1).setText("2*pi")
    p.n_spin.setValue(3)
    assert p.table.rowCount() == 3 and p.variables() == ["a", "b", "c"]
    p.n_spin.setValue(4)
    assert p.state()["bounds"][3] == ["-pi/2", "2*pi"]
    assert p.variables() == ["a", "b", "c", "d"]


def test_a_new_example_does_not_bring_back_hidden_fields(qtbot, window):
    p = window.formula_panel
    fill(qtbot, p, 4, 2, [SPHERE, "x1 - x2"])
    window.load_example("klein-bottle", run=False)
    k = p.k
    p.k_spin.setValue(k + 1)
    assert p.formulas()[k] == ""   # F(k+1) of the system typed before is not the example's


# --------------------------------------------------------------------------- undo / redo
def test_undo_restores_the_previous_system_and_redo_reapplies_it(qtbot, window):
    p = window.formula_panel
    fill(qtbot, p, 4, 2, [SPHERE, "x1 - x2"], div="6")
    window.model.history.merge_seconds = -1.0   # a test types faster than a person: no change merges
    before = p.state()
    p.div_edit.setText("9")
    p.k_spin.setValue(1)
    p.set_method("gcch")
    after = p.state()
    assert after != before
    window.menu_actions.undo.trigger()   # Ctrl+Z
    window.menu_actions.undo.trigger()
    window.menu_actions.undo.trigger()
    assert p.state() == before
    assert window.menu_actions.redo.isEnabled()
    for _ in range(3):
        window.menu_actions.redo.trigger()   # Ctrl+Shift+Z
    assert p.state() == after
    assert not window.menu_actions.redo.isEnabled()


def test_undo_shortcuts(window):
    from qtpy.QtGui import QKeySequence

    assert window.menu_actions.undo.shortcut() == QKeySequence("Ctrl+Z")
    assert QKeySequence("Ctrl+Shift+Z") in window.menu_actions.redo.shortcuts()


def test_undo_restores_the_view(qtbot, window):
    fill(qtbot, window.formula_panel, 4, 2, [SPHERE, "x1 - x2"])
    assert run_and_wait(qtbot, window) == "done"
    pp = window.projection_panel
    first = pp.state()
    pp.sliders[0].setValue(40)
    turned = pp.state()
    assert turned["angles"] != first["angles"]
    assert window.controller.undo()
    assert pp.state()["angles"] == first["angles"]
    assert window.controller.redo()
    assert pp.state()["angles"] == turned["angles"]


# --------------------------------------------------------------------------- the example's description
def test_the_description_stays_after_the_result(qtbot, window):
    from gcmh_core.examples import load_example

    ex = load_example("sphere")
    window.load_example("sphere", div=8)
    assert window.about_box.isVisible() and window.about_box.title() == ex.title
    from app_helpers import wait_run

    assert wait_run(qtbot, window) == "done"
    assert window.about_box.isVisible()
    assert window.about_label.text() == " ".join(str(ex.description).split())
    fill(qtbot, window.formula_panel, 3, 1, ["x^2 + y^2 + z^2 - 2"])   # a system typed in: not the example
    assert run_and_wait(qtbot, window) == "done"
    assert not window.about_box.isVisible()


# --------------------------------------------------------------------------- estimate before a run
def test_the_estimate_is_shown_before_the_run(qtbot, window):
    fill(qtbot, window.formula_panel, 4, 2, [SPHERE, "x1 - x2"])
    seen = []
    window.runs.estimated.connect(lambda est: seen.append(window.last_status))
    assert run_and_wait(qtbot, window) == "done"
    assert window.controller.last_estimate is not None and window.controller.last_estimate.fits
    assert seen and "of memory" in seen[0] and "available" in seen[0]


# --------------------------------------------------------------------------- the kernels' first compile
@pytest.fixture
def slow_warm_up(monkeypatch):
    """A warm-up that lasts until released (a new install's compile: numba's "numba:compile" event for a kernel
    of gcmh_core, open until then), instead of the real one."""
    from types import SimpleNamespace

    from numba.core import event

    import gcmh_studio.jobs

    release = threading.Event()

    def kernel():
        pass

    kernel.__module__ = "gcmh_core.kernels.gcmh"

    def fake(methods, cancel=None, ready=None):
        with event.trigger_event("numba:compile", data={"dispatcher": SimpleNamespace(py_func=kernel)}):
            release.wait(60)

    monkeypatch.setattr(gcmh_studio.jobs, "_WARM_UP", None)
    monkeypatch.setattr(gcmh_studio.jobs, "warm_up_kernels", fake)
    yield release
    release.set()


def test_first_run_says_the_kernels_compile(qtbot, slow_warm_up):
    from gcmh_studio.qt_main_window import QtMainWindow
    from gcmh_studio.worker import COMPILING

    w = QtMainWindow(example=None)
    qtbot.addWidget(w)
    w.show()
    try:
        assert w.warm_up.running()
        qtbot.waitUntil(lambda: "once per install" in w.kernel_label.text(), timeout=5000)
        fill(qtbot, w.formula_panel, 4, 2, [SPHERE, "x1 - x2"])
        assert w.run()
        qtbot.waitUntil(lambda: w.progress.format().startswith(COMPILING), timeout=5000)
        assert "%" not in w.progress.format()
        qtbot.waitUntil(lambda: "once per install" in w.last_status, timeout=5000)   # (the measured notice)
        # Cancel is honoured while the run waits for the kernels
        with qtbot.waitSignal(w.runFinished, timeout=2000) as b:
            w.cancel()
        assert b.args[0] == "cancelled"
        # a second run starts as soon as the compile ends
        assert w.run()
        qtbot.wait(300)
        assert w.is_running() and w.result is None
        with qtbot.waitSignal(w.runFinished, timeout=60_000) as b:
            slow_warm_up.set()
        assert b.args[0] == "done" and w.result is not None
        qtbot.waitUntil(lambda: "once per install" not in w.kernel_label.text(), timeout=5000)
    finally:
        slow_warm_up.set()
        w.close()


# --------------------------------------------------------------------------- formula checks off the GUI thread
def test_a_slow_formula_check_never_blocks_the_window(qtbot, window, monkeypatch):
    """Every keystroke in a pathological field: the check runs in a worker, a QTimer keeps ticking meanwhile,
    and the answer of a stale text is dropped."""
    from qtpy.QtCore import QTimer

    import gcmh_studio.qt_formula_checks

    real = gcmh_studio.qt_formula_checks.check_key
    spans = []

    def slow(key):   # pure Python work, as a slow parse would be (holds the GIL by turns)
        t0 = time.perf_counter()
        x = 0
        while time.perf_counter() - t0 < 0.8:
            x += 1
        spans.append((t0, time.perf_counter(), key[1]))
        return real(key)

    monkeypatch.setattr(gcmh_studio.qt_formula_checks, "check_key", slow)
    p = window.formula_panel
    ticks = []
    timer = QTimer()
    timer.setInterval(20)
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start()
    pathological = "max(" + ", ".join(f"x{1 + i % 3}*{i}" for i in range(400))   # no closing parenthesis yet
    edit = p.formula_edits[0]
    edit.setText(pathological)
    qtbot.wait(400)             # the check starts after the pause
    qtbot.keyClicks(edit, ")")  # a keystroke while the old text is being checked: that answer is stale
    settle(qtbot, p)
    timer.stop()
    assert len(spans) >= 2
    t0, t1, _ = spans[0]
    during = [t for t in ticks if t0 <= t <= t1]
    assert len(during) >= 5, f"the GUI thread served {len(during)} timer events during a 0.8 s check"
    # the mark shows the answer for the text in the field now, not the stale one
    assert edit.text().endswith(")")
    msg = p.formula_errors[0].text()
    assert msg == (real(("real", edit.text(), tuple(p.variables()), 0))[0] or "")
    assert "never closed" not in msg


def test_run_pressed_during_a_check_waits_for_it(qtbot, window):
    p = window.formula_panel
    fill(qtbot, p, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"])
    p.formula_edits[0].setText("x1^2 + x2^2 + x3^2 - 2")
    assert p.checking()
    assert run_and_wait(qtbot, window) == "done"
    assert window.result.euler_characteristic() == 2
    p.formula_edits[0].setText("x1^2 + (x2")   # a typo: Run waits for its check, then refuses
    with qtbot.waitSignal(window.runFinished, timeout=20_000) as b:
        assert window.run()
    assert b.args[0] == "failed" and window.last_status.startswith("Cannot run")


# --------------------------------------------------------------------------- gcmh-app in the terminal
def _app(*args, **kw):
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-m", "gcmh_studio", *args], cwd=REPO, env=env, capture_output=True,
                          text=True,
                          timeout=kw.get("timeout", 120))


@pytest.mark.parametrize("args, words", [
    (["--screenshot", "{out}.png", "--size", "8192x8192"], "limit of 33,554,432"),
    (["--screenshot", "{out}.png", "--size", "9000x100"], "limit of 8192"),
    (["--animate", "tour", "--gif", "{out}.gif", "--frames", "10000", "--size", "400x300"], "limit of 2000"),
    (["--animate", "tour", "--gif", "{out}.gif", "--frames", "2000", "--size", "8000x4000"], "use fewer frames"),
])
def test_too_large_pictures_are_refused_before_anything_is_drawn(tmp_path, args, words):
    out = str(tmp_path / "x")
    r = _app("--example", "klein-bottle", *[a.format(out=out) for a in args])
    assert r.returncode == 2, r.stderr
    assert words in r.stderr and "Traceback" not in r.stderr
    assert len([line for line in r.stderr.splitlines() if line.startswith("gcmh-app:")]) == 1
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("extra, flag", [
    (["--slice", "z=0.3"], "--slice"),
    (["--rotate", "x-y=30", "--color", "x"], "--color, --rotate"),
    (["--example", "sphere"], "--example"),
    (["--animate", "tour", "--gif", "{out}.gif"], "--animate"),
])
def test_options_a_session_would_override_are_refused_not_ignored(tmp_path, extra, flag):
    # (the file need not exist: the clash is found from the command line alone, before anything is read)
    out = str(tmp_path / "x")
    r = _app("--session", str(tmp_path / "s.json"), "--screenshot", out + ".png", *[a.format(out=out) for a in extra],
             timeout=60)
    assert r.returncode == 2, r.stderr
    lines = [line for line in r.stderr.splitlines() if line.startswith("gcmh-app:")]
    assert len(lines) == 1 and lines[0].startswith("gcmh-app: error:") and "Traceback" not in r.stderr
    assert set(flag.split(", ")) <= {w.strip(",") for w in lines[0].split() if w.startswith("--")}
    assert "cannot go with --session" in lines[0]
    assert os.listdir(tmp_path) == []


def _caught_signals(pid: int) -> int:
    """The process's caught-signal mask (/proc/<pid>/status SigCgt); 0 once it is gone."""
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0
    return int(next(line.split()[1] for line in text.splitlines() if line.startswith("SigCgt:")), 16)


def _handlers_installed(pid: int) -> bool:
    """gcmh-app's own handlers are in place: it catches SIGTERM (Python alone leaves SIGTERM alone)."""
    return bool(_caught_signals(pid) >> (signal.SIGTERM - 1) & 1)


def _engine_running(pid: int) -> bool:
    """The handlers are in place and numba's compiler (llvmlite) is mapped: the run is under way."""
    try:
        return _handlers_installed(pid) and "llvmlite" in Path(f"/proc/{pid}/maps").read_text()
    except OSError:
        return False


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads the child's state in /proc")
@pytest.mark.parametrize("event", [_handlers_installed, _engine_running], ids=["imports", "run"])
def test_ctrl_c_ends_with_one_line_and_130(tmp_path, event):
    # Ctrl-C is sent when the child reaches a state read from /proc (during its imports, during the run),
    # not after a fixed delay: a delay hit the interpreter's start-up on a loaded machine, before
    # gcmh-app's first line had run, and Python printed its own traceback (the flaky test of issue 24).
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    proc = subprocess.Popen([sys.executable, "-m", "gcmh_studio", "--example", "complex-cosine", "--div", "160",
                             "--screenshot", str(tmp_path / "x.png"), "--size", "400x300"],
                            cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    while not event(proc.pid) and proc.poll() is None:
        time.sleep(0.002)   # polling /proc for the state; the assertion below says if it never came
    assert proc.poll() is None, "the child ended before reaching the state"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    lines = [line for line in err.splitlines() if line.startswith("gcmh-app")]
    assert proc.returncode == 130, err
    assert lines == ["gcmh-app: interrupted"] and "Traceback" not in err


# --------------------------------------------------------------------------- cancel in phases the engine does not poll
def test_cancel_does_not_wait_for_an_engine_phase_that_never_polls(qtbot, window, monkeypatch):
    """An engine call that ignores cancel (as the assembly does) for up to 60 s: Cancel still ends the run
    at once; the next run says it waits for the cancelled one and starts when that has stopped."""
    import gcmh_studio.worker
    from gcmh_studio.worker import STOPPING

    release = threading.Event()
    real = gcmh_studio.worker.run_job

    def deaf(job, progress=None, cancel=None):
        progress("assembling", 1.0)
        release.wait(60)   # no cancel poll here
        return real(job)

    fill(qtbot, window.formula_panel, 4, 2, [SPHERE, "x1 - x2"])
    monkeypatch.setattr(gcmh_studio.worker, "run_job", deaf)
    try:
        assert window.run()
        qtbot.waitUntil(lambda: window.progress.format().startswith("assembling"), timeout=20_000)
        with qtbot.waitSignal(window.runFinished, timeout=5000) as b:
            window.cancel()
        assert b.args[0] == "cancelled" and not release.is_set()
        monkeypatch.setattr(gcmh_studio.worker, "run_job", real)
        assert window.run()
        qtbot.waitUntil(lambda: window.progress.format().startswith(STOPPING), timeout=5000)
        with qtbot.waitSignal(window.runFinished, timeout=60_000) as b:
            release.set()
        assert b.args[0] == "done" and window.result is not None
    finally:
        release.set()


def test_the_panel_shows_the_runs_estimate_before_run(qtbot, window, monkeypatch):
    import dataclasses

    import gcmh_studio.qt_method_box

    p = window.formula_panel
    fill(qtbot, p, 4, 2, [SPHERE, "x1 - x2"], div="6")
    qtbot.waitUntil(lambda: p.run_estimate is not None, timeout=20_000)
    assert p.run_estimate.fits and "of memory" in p.estimate_label.text()
    real = gcmh_studio.qt_method_box.estimate_job
    monkeypatch.setattr(gcmh_studio.qt_method_box, "estimate_job",
                        lambda job: dataclasses.replace(real(job), peak_bytes=10**15))
    p.div_edit.setText("7")
    qtbot.waitUntil(lambda: p.run_estimate is not None and not p.run_estimate.fits, timeout=20_000)
    assert "too large" in p.estimate_label.text() and "c22" in p.estimate_label.styleSheet()


def test_every_undo_changes_what_the_panels_show(qtbot, window):
    """After a run of another system, the previous result's views do not apply to this one: undo passes
    over them, so no Ctrl+Z does nothing visible, and the first system comes back."""
    p, pp = window.formula_panel, window.projection_panel
    fill(qtbot, p, 3, 1, ["x1^2 + x2^2 + x3^2 - 1"])
    assert run_and_wait(qtbot, window) == "done"
    pp.sliders[0].setValue(30)   # a view of the 3-variable result
    window.model.history.merge_seconds = -1.0
    first = p.state()
    fill(qtbot, p, 4, 2, [SPHERE, "x1 - x2"])
    assert run_and_wait(qtbot, window) == "done"
    pp.sliders[0].setValue(20)
    while p.state() != first:
        before = (p.state(), pp.state())
        assert window.controller.undo(), "the history ended before the first system came back"
        assert (p.state(), pp.state()) != before
    assert window.controller.redo()
    assert p.state() != first


# --------------------------------------------------------------------------- parameters
def test_an_example_with_parameters_runs_and_its_values_are_used(qtbot, window):
    from gcmh_core.examples import load_example

    ex = load_example("hyperboloid")
    assert ex.params   # (a = 0.5: a hyperboloid of one sheet, chi = 0)
    window.load_example("hyperboloid", div=16)
    from app_helpers import wait_run

    assert wait_run(qtbot, window) == "done", window.last_status
    assert window.result.euler_characteristic() == 0
    p = window.formula_panel
    assert p.params() == ex.param_values()
    p.parameters.set_value("a", -0.5, commit=False)   # two sheets: two discs
    assert run_and_wait(qtbot, window) == "done"
    assert window.result.euler_characteristic() == 2


def test_a_glued_example_runs_closed_in_the_window(qtbot, window):
    # the closed Klein bottle's file glues t and s (t reversed): the panel carries it to the run
    with qtbot.waitSignal(window.runFinished, timeout=120_000) as b:
        window.load_example("klein-bottle-closed", div=[12, 12, 6, 12, 12])
    assert b.args[0] == "done", window.last_status
    assert window.formula_panel.periodic() == ["s:flip=t", "t"]
    cx = window.result
    assert cx.euler_characteristic() == 0 and len(cx.boundary_facets()) == 0
