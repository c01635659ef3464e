"""StudioController without Qt or a display: runs, parameter steps, examples, undo, sessions, live play.

The worker is replaced by a synchronous fake (:class:`FakeRunner`: a run is extracted at once, or held until
``finish()``), the Manifold tab by a fake form that makes the job of the model's system, and the window by
:class:`FakeView`. This module imports no Qt; it runs with ``-p no:xvfb``.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gcmh_studio import studio_io
from gcmh_studio.animation import ROTATE_PERIOD
from gcmh_studio.controller import StudioController, example_state, full_div
from gcmh_studio.jobs import Job, continuation_methods, run_job
from gcmh_studio.model import StudioModel

REPO = Path(__file__).resolve().parents[2]


class FakeRunner:
    """QtRunController's part, synchronous: ``hold`` keeps a run in flight until :meth:`finish`."""

    def __init__(self):
        self.controller = None
        self.job = None
        self.started: list[Job] = []
        self.hold = False
        self.answers = []

    def start(self, job):
        if self.job is not None:
            return False
        self.job = job
        self.started.append(job)
        if not self.hold:
            self.finish()
        return True

    def finish(self):
        job, self.job = self.job, None
        self.controller.on_done(run_job(job), None, None)

    def cancel(self):
        if self.job is None:
            return False
        self.job = None
        self.controller.on_cancelled(0.0)
        return True

    def answer(self, what):
        self.answers.append(what)

    def is_running(self):
        return self.job is not None

    def running_job(self):
        return self.job

    def elapsed(self):
        return 0.0

    def refine(self, cx, job, serial):
        from gcmh_core.analysis import refine_vertices
        from gcmh_core.formula import parse_system

        refined, before, after = refine_vertices(cx, parse_system(job.formulas, job.variables))
        self.controller.on_refined(serial, refined, None, None, before, after)
        return True


class FakeView:
    """The window's part: a result shown is the model's; a big run is answered by ``answer``."""

    def __init__(self, model):
        self.model = model
        self.shown = []
        self.answer = "run"
        self.cameras = []

    def show_result(self, cx, names, view=None, title="", geometry=None, report=None, keep_view=False,
                    labels=None, moving=False):
        keep = self.model.present(cx, names, title, labels, view, keep_view)
        self.shown.append(dict(cx=cx, view=view, title=title, keep=keep, moving=moving))

    def confirm_big_run(self, est):
        return self.answer

    def restore_camera(self, camera, keep):
        self.cameras.append((camera, keep))

    def camera(self):
        return {"position": [3.0, 0.0, 0.0], "focal_point": [0.0, 0.0, 0.0], "up": [0.0, 0.0, 1.0]}


def fake_form(model):
    """What the Manifold tab does: the job of each system shown, checked at once."""
    def on_system(d):
        params = {p: s["value"] for p, s in (d.get("params") or {}).items()}
        job = Job(formulas=list(d["formulas"]), variables=list(d["variables"]),
                  bounds=[tuple(float(x) for x in b) for b in d["bounds"]], div=d["div"], method=d["method"],
                  seed=int(d.get("seed", 0)), params=params or None,
                  start=d.get("start") if d["method"] in continuation_methods() else None)
        model.set_checks(True, False, {}, job)
    model.events.system.connect(on_system)


@pytest.fixture
def studio():
    model = StudioModel()
    fake_form(model)
    runner = FakeRunner()
    view = FakeView(model)
    c = runner.controller = StudioController(model, runner, view)
    said = []
    c.events.finished.connect(said.append)
    c.said = said
    return c


def test_importing_the_controller_loads_no_qt():
    code = ("import sys, gcmh_studio.controller, gcmh_studio.latest\n"
            "gui = ('PyQt5', 'PySide2', 'PySide6', 'PyQt6', 'qtpy', 'vtk', 'vtkmodules', 'pyvista', 'pyvistaqt')\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} & set(gui)))")
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


def test_an_example_runs_with_its_title_and_view(studio):
    m, view = studio.model, studio.view
    described = []
    studio.events.described.connect(lambda title, text: described.append(title))
    assert studio.load_example("sphere", div=8)
    assert studio.said == ["done"] and described == ["Unit sphere in R^3"]
    assert m.title == "Unit sphere in R^3" and m.names == ["x", "y", "z"] and m.result.euler_characteristic() == 2
    assert view.shown[0]["view"]["color"] == "z" and m.style.color_by == "z"
    assert m.status == "" and not studio.is_running()
    assert not studio.load_example("no-such-example") and m.status_error


def test_run_waits_for_the_formula_checks_then_starts(studio):
    m, runner = studio.model, studio.runner
    asked = []
    m.events.check_now.connect(lambda: asked.append(True))
    m.set_system(example_state(__import__("gcmh_core.examples").examples.load_example("sphere"), div=8))
    job = m.checks.job
    m.set_checks(False, True, {})                    # a formula still being checked
    assert studio.run() and studio.run_waiting and asked == [True] and runner.started == []
    assert studio.is_running()
    assert not studio.run() and "already in progress" in m.status
    m.set_checks(True, False, {}, job)               # the answer came
    assert not studio.run_waiting and len(runner.started) == 1 and studio.said == ["done"]


def test_a_wrong_system_is_refused_and_a_waiting_run_cancelled(studio):
    m = studio.model
    m.set_checks(False, False, {"div": "not a number"})
    assert not studio.run() and m.status == "Cannot run: div: not a number" and m.status_error
    m.set_checks(False, True, {})
    assert studio.run()
    studio.cancel()
    assert studio.said == ["cancelled"] and not studio.is_running() and "before the run started" in m.status
    m.set_checks(False, False, {"F1": "empty formula"})
    assert studio.said == ["cancelled"]              # (no run was waiting any more)


def test_parameter_steps_the_newest_wins(studio):
    m, runner = studio.model, studio.runner
    assert studio.load_example("hyperboloid", div=16, method="gcch")
    full = m.result
    runner.hold = True
    system = dict(m.system, params={"a": {"value": -0.5, "min": -1.0, "max": 1.0}})
    m.set_system(system)
    assert studio.parameter_step(coarse=True, moved="a")      # starts at once: a coarse grid
    coarse = runner.job
    assert coarse.step == "coarse" and full_div(coarse) < [16] * 3 and coarse.params == {"a": -0.5}
    assert coarse.start is full                                # continuation from the result on screen
    studio.parameter_step(coarse=True)                         # waits for the coarse step in flight
    studio.parameter_step(coarse=False)                        # the slider let go: the coarse one is cancelled
    assert runner.job.step == "full" and studio.said[-1] == "cancelled"
    runner.finish()
    assert [j.step for j in runner.started] == [None, "coarse", "full"]
    assert studio.said[-1] == "done" and m.result.meta["params"] == {"a": -0.5}
    assert studio.view.shown[-1]["keep"] and studio.last_step_seconds is not None


def test_a_user_run_in_flight_gives_way_to_a_step(studio):
    m, runner = studio.model, studio.runner
    assert studio.load_example("hyperboloid", div=12)
    runner.hold = True
    assert studio.run() and runner.job.step is None
    assert studio.parameter_step(coarse=False)
    assert runner.job.step == "full" and studio.said[-1] == "cancelled"
    assert "Cancelled" not in m.status                         # (superseded: nothing to say)


def test_undo_redo_and_a_slider_brought_back(studio):
    m, runner = studio.model, studio.runner
    assert studio.load_example("hyperboloid", div=12)
    m.history.merge_seconds = 0.0
    before = len(runner.started)
    m.set_system(dict(m.system, params={"a": {"value": -0.5, "min": -1.0, "max": 1.0}}))
    assert studio.undo() and m.system["params"]["a"]["value"] == 0.5
    assert len(runner.started) == before + 1 and runner.started[-1].step == "full"   # the manifold follows
    assert studio.redo() and m.system["params"]["a"]["value"] == -0.5
    assert not studio.redo() and m.status == "Nothing to redo."


def test_a_big_run_can_switch_to_continuation(studio):
    m = studio.model
    assert studio.load_example("sphere", div=8)
    studio.view.answer = "gcch"
    studio.on_confirm(object())
    assert m.system["method"] == "gcch" and studio.runner.answers == ["gcch"]


def test_a_session_runs_then_restores_its_view(studio, tmp_path):
    m = studio.model
    assert studio.load_example("sphere", div=8)
    m.set_style(color_by="x", keep_camera=True)
    m.set_angles([10.0, 20.0, 30.0])
    path = studio_io.write_session(tmp_path / "s.json", studio.session())
    m.set_style(color_by="y", keep_camera=False)
    m.set_angles([0.0, 0.0, 0.0])
    assert studio.open_session(path)
    assert studio.said[-1] == "done" and m.style.color_by == "x"
    assert np.allclose(m.projection.angles, [10.0, 20.0, 30.0])
    assert studio.view.cameras[-1] == (studio.view.camera(), True)
    assert not studio.open_session(tmp_path / "missing.json") and m.status_error


def test_refinement_replaces_the_result_of_its_serial(studio):
    m = studio.model
    assert not studio.refine() and "run first" in m.status
    assert studio.load_example("sphere", div=8)
    seen = []
    studio.events.refined.connect(seen.append)
    assert studio.refine()
    assert seen == ["done"] and m.last_refinement["after"] < m.last_refinement["before"]


def test_live_play_turns_the_model(studio):
    m = studio.model
    assert studio.play(True) == (False, "Nothing to animate yet: run first.")
    assert studio.load_example("sphere", div=8)
    m.animation.mode, m.animation.plane = "rotate", (0, 1)
    assert studio.play(True) == (True, "")
    studio.tick(ROTATE_PERIOD / 4)
    assert m.projection.angles[0] == pytest.approx(90.0)
    assert not m.recording                                     # frames are not steps to undo
    studio.play(False)
    assert m.recording and m.snapshot() == m.history.current
    m.animation.mode = "slice"
    assert studio.play(True) == (False, "Turn the slice on in the View tab first.")


def test_live_play_sweeps_a_parameter_coarse_then_full_at_rest(studio):
    """A playing parameter sweep asks for its values (each a coarse step) there and back from where the
    parameter is, and when it stops for the full grid at the value it reached."""
    from gcmh_studio.animation import PARAM_PERIOD

    m = studio.model
    asked = []
    studio.events.sweep.connect(lambda name, v, final: asked.append((name, v, final)))
    assert studio.load_example("hyperboloid", div=8)
    m.animation.mode, m.animation.sweep = "param", ("a", -1.0, 1.0)
    m.set_system(dict(m.system, params={"a": {"value": 0.0, "min": -1.0, "max": 1.0}}))
    assert studio.play(True) == (True, "")
    studio.tick(PARAM_PERIOD / 8)            # from the middle, an eighth of the way there and back
    studio.tick(PARAM_PERIOD / 8)
    assert [a[0] for a in asked] == ["a", "a"] and not any(a[2] for a in asked)
    v1, v2 = asked[0][1], asked[1][1]
    assert 0.0 < v1 < v2 <= 1.0 and v2 == pytest.approx(1.0)   # a quarter period from the middle: the top
    studio.tick(PARAM_PERIOD / 4)
    assert asked[-1][1] == pytest.approx(0.0, abs=1e-9)        # and back through the middle
    assert not m.recording
    studio.play(False)
    assert asked[-1] == ("a", pytest.approx(0.0, abs=1e-9), True) and m.recording
    n = len(asked)
    studio.play(False)                       # stopped already: nothing more asked
    assert len(asked) == n
    m.animation.sweep = ("b", -1.0, 1.0)     # a parameter the system does not have
    assert studio.play(True)[0] is False


def test_example_state_keeps_complex_equations():
    from gcmh_core.examples import load_example

    ex = load_example("complex-cosine")
    state = example_state(ex, div=12)
    assert state["complex"] == list(ex.complex) and state["div"] == 12
    assert state["formulas"] == list(ex.formulas)[2 * len(ex.complex):]
