"""StudioController: what the studio does, without Qt (runs, parameter steps, examples, undo, sessions).

The window lays out and wires; the behaviour behind its buttons lives here and is
tested without a display (tests/app/test_controller.py, with a synchronous runner):

- runs: Run waits for the formula checks under way, refuses a wrong system, asks
  before a run that won't fit, and says how each run ended (``events.finished``:
  "done", "cancelled", "failed" or "declined");
- parameter steps (a slider moved): the newest step wins, on a coarse grid while
  a slider is held (:mod:`gcmh_studio.steps`) and on the full one when it is let
  go, keeping the view, continuing from the result on screen; a result at a
  critical value says so;
- an example becomes the Manifold tab's state (:func:`example_state`); Undo and
  Redo step through :class:`gcmh_studio.model.History`; a session is opened
  (its view restored once its run is done) and saved;
- refinements, and the Animate tab's live play (:class:`gcmh_studio.live_play.LivePlay`:
  the clock moves the model's angles or slice, or a parameter: ``events.sweep`` asks for
  its coarse steps while it plays and the full one when it stops).

It talks to a *runner* (:class:`Runner`: the window's
:class:`gcmh_studio.qt_run_controller.QtRunController`, or a fake) and to a *view*
(:class:`View`: the window: showing a result, asking about a big run, the camera),
and reports through the psygnal signals of ``events`` (:class:`ControllerEvents`).
"""

from __future__ import annotations

import copy
import time
from typing import Any, Protocol

from psygnal import Signal, SignalGroup

from . import studio_io
from .jobs import COMPILING, WAITING_PHASES, continuation_methods, current_warm_up
from .labels import gluing_title
from .live_play import LivePlay
from .model import EMPTY_RESULT, StudioModel
from .steps import CoarseAim, critical_notice, step_key


class Runner(Protocol):
    """Runs and refinements in the background (QtRunController)."""

    def start(self, job) -> bool: ...
    def cancel(self) -> bool: ...
    def answer(self, what) -> None: ...
    def is_running(self) -> bool: ...
    def running_job(self): ...
    def elapsed(self) -> float: ...
    def refine(self, cx, job, serial: int) -> bool: ...


class View(Protocol):
    """What the controller asks of the window."""

    def show_result(self, cx, names, view=None, title: str = "", geometry=None, report=None,
                    keep_view: bool = False, labels=None, moving: bool = False) -> None: ...
    def confirm_big_run(self, est) -> Any: ...
    def restore_camera(self, camera, keep: bool) -> None: ...
    def camera(self) -> dict: ...


class ControllerEvents(SignalGroup):
    """What the controller says, and who listens (the window)."""

    finished = Signal(str)           # how a run ended: "done", "cancelled", "failed", "declined"
    refined = Signal(str)            # how a refinement ended: "done", "failed", "dropped"
    refining = Signal(bool)          # a refinement started (True) or ended: the Topology tab's button
    progress = Signal(object, str)   # (fraction in [0, 1] or None to keep, text): the progress bar
    described = Signal(str, str)     # (title, description) of the example on show ("", "": none)
    busy = Signal()                  # Run's state changed (running, waiting for checks): the buttons
    sweep = Signal(str, float, bool)  # a playing parameter sweep: (parameter, value, final): the parameter's
    #                                   input sets it; not final: a coarse step follows, final: the full one


def example_state(ex, div=None, method: str = "gcmh") -> dict:
    """The Manifold tab's state for example ``ex`` (:func:`gcmh_core.examples.load_example`); ``div``
    replaces the example's grid. Complex examples keep their equations over C^m (split by the panel)."""
    state = dict(
        n=ex.n, k=ex.k, variables=list(ex.variables), formulas=list(ex.formulas),
        bounds=[list(b) for b in ex.bounds], div=div if div is not None else ex.div,
        method=method, seed=0, start=list(ex.start) if ex.start else None,
        params={p: dict(spec) for p, spec in (getattr(ex, "params", None) or {}).items()},
        periodic=list(getattr(ex, "periodic", None) or []))
    if getattr(ex, "complex", None):   # as on the blackboard: the equations over C^m
        state.update(complex=list(ex.complex), complex_variables=list(ex.complex_variables),
                     formulas=list(ex.formulas)[2 * len(ex.complex):])
    return state


def full_div(job) -> list[int]:
    """A job's div as one int per axis."""
    d = job.div
    return [int(x) for x in d] if isinstance(d, (list, tuple)) else [int(d)] * len(job.variables)


class StudioController:
    """The studio's behaviour over ``model``; see the module docstring."""

    def __init__(self, model: StudioModel, runner: Runner, view: View):
        self.model = model
        self.runner = runner
        self.view = view
        self.events = ControllerEvents()
        self.closing = False
        self.run_waiting = False    # Run was pressed while a formula check was under way
        self.last_estimate = None   # the gcmh_core.budget.Estimate of the last run started
        self._session: tuple[dict, dict | None, bool] | None = None   # a session's view and camera, until its run
        # parameter steps: the newest one waiting for the run in flight (never a queue), whether the run in
        # flight was cancelled for it, the coarse grid's aim, and when the step on its way started
        self._next_step = None
        self._superseded = False
        self._coarse = CoarseAim()
        self._step_t0 = 0.0
        self.last_step_seconds: float | None = None   # from a slider's change to the result drawn (the benchmark)
        self.last_moved: str | None = None            # the parameter the user moved last
        self.live = LivePlay(model, self.events.sweep.emit)   # the Animate tab's live play
        model.events.checks.connect(self._on_checks)

    # ------------------------------------------------------------ runs
    def is_running(self) -> bool:
        """A run under way (or waiting for its formulas' check)."""
        return self.runner.is_running() or self.run_waiting

    def run(self) -> bool:
        """Start an extraction of the system on show; False if refused. While a formula is still being checked
        the run starts when the answer comes (True: ``finished`` says how it ended)."""
        m = self.model
        if self.is_running():
            m.set_status("A run is already in progress: cancel it first (Esc).", error=True)
            return False
        if m.checks.checking:
            self.run_waiting = True
            self.events.progress.emit(0.0, "checking the formulas\u2026")
            self.events.busy.emit()
            m.events.check_now.emit()
            return True
        if not m.checks.valid:
            errs = m.checks.errors
            m.set_status("Cannot run: " + "; ".join(f"{k}: {v}" for k, v in errs.items()), error=True)
            return False
        job = copy.deepcopy(m.checks.job)
        self._next_step = None   # (a Run is newer than any slider step waiting)
        m.job = job
        self._suggest_complex_view(job)
        warm = current_warm_up()
        self.events.progress.emit(0.0, f"{warm.phase()}\u2026" if warm is not None and warm.waits_for(job.method)
                                  else "starting\u2026")
        return self.runner.start(job)

    def _suggest_complex_view(self, job) -> None:
        """A new system typed in complex mode opens as a graph: the first variable's plane flat, the real part
        of the second as height, coloured by its imaginary part (gcmh_core.complex_equations.complex_view)."""
        system = self.model.system
        if not system.get("complex") or list(job.variables) == self.model.names:
            return
        try:
            from gcmh_core.complex_equations import complex_view

            self.model.suggest_view(complex_view(list(system.get("complex_variables") or []), list(job.variables)))
        except Exception:  # noqa: BLE001 - one complex variable (a curve in C): the default view
            pass

    def _on_checks(self) -> None:
        """The formula checks are answered: a Run pressed meanwhile starts now (or is refused)."""
        if not self.run_waiting or self.model.checks.checking:
            return
        self.run_waiting = False
        self.events.busy.emit()
        if self.model.checks.valid:
            if self.run():
                return
        else:
            self.run()   # says "Cannot run: ..." on the status line
        self.events.progress.emit(None, "idle")
        self.events.finished.emit("failed")

    def cancel(self) -> None:
        if self.run_waiting:
            self.run_waiting = False
            self.events.busy.emit()
            self.events.progress.emit(None, "cancelled")
            self.model.set_status("Cancelled before the run started.")
            self.events.finished.emit("cancelled")
        elif self.runner.cancel():
            self.events.progress.emit(None, "cancelling\u2026")

    # ------------------------------------------------------------ parameter steps (a slider moved)
    def parameter_step(self, coarse: bool, moved: str | None = None) -> bool:
        """Re-extract at the parameters' values on show: while a slider is held (``coarse``) on a coarse grid,
        when it is let go on the full one. The newest step wins: it waits for the coarse step in flight (which
        is shown: the picture follows the slider), and a full step or a user's run in flight is cancelled for
        it; older waiting steps are dropped. Continuation starts from the result on screen. False when the
        system can't run now (a wrong field, a check under way, a Run waiting for it)."""
        m = self.model
        if moved is not None:
            self.last_moved = moved
        if self.closing or self.run_waiting or not m.checks.valid or m.checks.checking:
            return False
        job = copy.deepcopy(m.checks.job)
        job.step = "coarse" if coarse else "full"
        if coarse:
            job.div = self._coarse.div(job, full_div(job))
        prev = m.job
        same = prev is not None and m.result is not None and step_key(prev) == step_key(job)
        if same and prev is not None and prev.force and not coarse:
            job.force = True   # the user agreed to this run's size already
        if same and job.method in continuation_methods() and not job.scheduler:
            job.start = m.result   # continue from the result on screen (gcmh_core: start=<CellComplex>)
        self._next_step = job
        if self.runner.is_running():
            running = self.runner.running_job()
            if not (coarse and running is not None and running.step == "coarse"):
                self._superseded = True
                self.runner.cancel()
            return True
        return self.start_next_step()

    def start_next_step(self, *_) -> bool:
        """Start the parameter step waiting, if any (after the run in flight ended)."""
        job, self._next_step = self._next_step, None
        if job is None or self.closing or self.runner.is_running():
            self._next_step = self._next_step or job
            return False
        self._superseded = False   # (the run it replaced has ended, cancelled or not)
        self._step_t0 = time.perf_counter()
        self.model.job = job
        return self.runner.start(job)

    def _finish(self, how: str) -> None:
        session, self._session = self._session, None
        if how == "done" and session is not None:   # a session's run: its view and camera now
            view, camera, keep = session
            self.model.set_view_state(view)
            self.view.restore_camera(camera, keep)
        self.events.finished.emit(how)
        self.start_next_step()

    # ------------------------------------------------------------ what the runner says
    def on_estimated(self, est) -> None:
        self.last_estimate = est
        if self.model.job is not None and self.model.job.step is not None:
            return   # (a slider step: the status line keeps what the result says)
        from .inputs import human_bytes, human_seconds

        self.model.set_status(f"This run: about {human_bytes(est.peak_bytes)} of memory "
                              f"(of {human_bytes(est.available_bytes)} available), "
                              f"about {human_seconds(est.seconds)}.")

    def on_confirm(self, est) -> None:
        answer = self.view.confirm_big_run(est)
        if answer == "gcch":
            self.model.set_system({**self.model.system, "method": "gcch"})
        self.runner.answer(answer)

    def on_progress(self, phase: str, fraction: float, seconds: float) -> None:
        fraction = max(0.0, min(1.0, fraction))
        if phase.startswith(WAITING_PHASES):
            self.events.progress.emit(fraction, f"{phase}\u2026 \u00b7 {seconds:.1f} s")
        else:
            self.events.progress.emit(fraction, f"{phase} {100 * fraction:.0f}% \u00b7 {seconds:.1f} s")
        if phase.startswith(COMPILING):   # (only while numba really compiles: WarmUp.phase, jobs.compile_phase)
            warm = current_warm_up()
            note = warm.notice() if warm is not None else ""
            self.model.set_status(note or f"The numerical kernels compile once per install{phase[len(COMPILING):]};"
                                  " this run goes on when they are ready.")

    def on_declined(self) -> None:
        self.events.progress.emit(0.0, "not started")
        self.model.set_status("Run not started: choose a smaller div, or continuation (GCCH).", error=True)
        self._finish("declined")

    def on_failed(self, message: str) -> None:
        self.events.progress.emit(0.0, "failed")
        self.model.set_status(f"Error: {message}", error=True)
        self._finish("failed")

    def on_cancelled(self, seconds: float) -> None:
        if self._superseded:   # a newer parameter step took its place: it starts now
            self._superseded = False
            self._finish("cancelled")
            return
        self.events.progress.emit(0.0, "cancelled")
        keep = " The previous result stays on screen." if self.model.result is not None else ""
        self.model.set_status(f"Cancelled after {seconds:.1f} s.{keep}")
        self._finish("cancelled")

    def on_done(self, cx, geometry, report) -> None:
        m = self.model
        job = m.job
        assert job is not None   # (set when the run started)
        self.events.progress.emit(1.0, f"done \u00b7 {self.runner.elapsed():.1f} s")
        computed = time.perf_counter() - self._step_t0   # (a step's computing, before it is drawn)
        # a parameter step of the system on screen keeps the whole view: projection, turns, slice, colour, camera
        keep = job.step is not None and m.result is not None and list(job.variables) == m.names
        view = None if keep else m.take_view()
        title = m.title_for(job.formulas, job.variables)
        if title:   # an example's equations glued otherwise are the example glued so (its title and story)
            title, story = gluing_title(title, job.formulas, job.variables, job.periodic)
            if story is not None:
                self.events.described.emit(title if story else "", story)
        if not title:   # a system typed in: the last example's description no longer applies
            self.events.described.emit("", "")
            title = job.title
        try:
            self.view.show_result(cx, job.variables, view=view, title=title, geometry=geometry, report=report,
                                  keep_view=keep, labels=job.labels, moving=job.step == "coarse")
        except Exception as e:  # noqa: BLE001 - a drawing problem must not take the window down
            m.set_status(f"Could not draw the result: {type(e).__name__}: {e}", error=True)
            self._finish("failed")
            return
        notice = critical_notice(cx, self.last_moved)
        m.set_notice(notice)
        if cx.count(0) == 0:
            m.set_status(EMPTY_RESULT, error=True)
        elif notice:
            m.set_status(notice)
        else:
            m.set_status(cx.meta.get("start_note", "") if job.step is None else "")
        if job.step is not None:
            self.last_step_seconds = time.perf_counter() - self._step_t0
            if job.step == "coarse":
                self._coarse.learn(job, computed)   # aim the next coarse grid
        self._finish("done")

    # ------------------------------------------------------------ examples and sessions
    def load_example(self, name: str, run: bool = True, div=None, method: str = "gcmh") -> bool:
        """Show an example's system, run it, and show its suggested view."""
        from gcmh_core.examples import load_example

        try:
            ex = load_example(name)
        except Exception as e:  # noqa: BLE001
            self.model.set_status(str(e), error=True)
            return False
        self.model.set_system(example_state(ex, div, method))
        self.model.expect(ex.title, ex.formulas, ex.variables, view=ex.view or {})
        self.events.described.emit(ex.title, " ".join(str(ex.description).split()))
        self.model.set_status("")
        return self.run() if run else True

    def session(self) -> dict:
        return studio_io.session_dict(self.model, self.view.camera())

    def open_session(self, path, run: bool = True) -> bool:
        """Restore a session: show its system, run, then restore the view (projection, angles, colour)."""
        try:
            d = studio_io.read_session(path)
        except (OSError, ValueError) as e:
            self.model.set_status(f"Cannot open {path}: {e}", error=True)
            return False
        self.model.set_system(d["system"])
        system = self.model.system   # (as the Manifold tab reads it)
        self.model.expect(d.get("title", ""), system.get("formulas") or [], system.get("variables") or [])
        if run and (self.model.checks.valid or self.model.checks.checking):
            self._session = (d.get("view") or {}, d["camera"], d["keep_camera"])
            return self.run()
        return True

    # ------------------------------------------------------------ undo / redo
    def undo(self) -> bool:
        """Back to the previous system and view; False at the start of the history."""
        return self._step(self.model.undo, "undo")

    def redo(self) -> bool:
        """Forward again after an undo; False when nothing was undone."""
        return self._step(self.model.redo, "redo")

    def _step(self, step, what: str) -> bool:
        before = copy.deepcopy(self.model.system)
        if step() is None:
            self.model.set_status(f"Nothing to {what}.")
            return False
        self._follow_parameters(before)
        return True

    def _follow_parameters(self, before: dict) -> None:
        """An undo or redo that changed only the parameters' values of the system on screen shows the
        manifold at the values it brought back (as a slider let go would)."""
        after = self.model.system
        values = [{p: s["value"] for p, s in (d.get("params") or {}).items()} for d in (before, after)]
        rest = [{key: v for key, v in d.items() if key != "params"} for d in (before, after)]
        job, now = self.model.job, self.model.checks.job
        if (values[0] != values[1] and rest[0] == rest[1] and self.model.result is not None and job is not None
                and now is not None and list(job.formulas) == list(now.formulas)):
            self.parameter_step(coarse=False)

    # ------------------------------------------------------------ refinement
    def refine(self) -> bool:
        """Start moving the vertices closer to M (Gauss-Newton); the refined complex replaces the result
        when it is done (``refined``). False if there is nothing to refine or a refinement already runs."""
        m = self.model
        if m.result is None or m.job is None:
            m.set_status("Nothing to refine yet: run first.", error=True)
            return False
        if not self.runner.refine(m.result, m.job, m.serial):
            m.set_status("A refinement is already running.", error=True)
            return False
        self.events.refining.emit(True)
        m.set_status("Refining the vertices onto M\u2026")
        return True

    def on_refined(self, serial: int, cx, geometry, report, before: float, after: float) -> None:
        self.events.refining.emit(False)
        m = self.model
        if self.closing:
            return
        if m.serial != serial:  # a run (or a file) put another result on screen meanwhile
            m.set_status("Refinement dropped: the result changed while it ran.")
            self.events.refined.emit("dropped")
            return
        try:
            self.view.show_result(cx, m.names, title=m.title, geometry=geometry, report=report)
        except Exception as e:  # noqa: BLE001 - a drawing problem must not take the window down
            m.set_status(f"Could not draw the refined result: {type(e).__name__}: {e}", error=True)
            self.events.refined.emit("failed")
            return
        m.set_refinement(before, after)
        m.set_status(f"Refined: max |F| at the vertices {before:.3g} \u2192 {after:.3g}")
        self.events.refined.emit("done")

    def on_refine_failed(self, message: str) -> None:
        self.events.refining.emit(False)
        if not self.closing:
            self.model.set_status(f"Refining failed: {message}", error=True)
            self.events.refined.emit("failed")

    # ------------------------------------------------------------ the Animate tab's live play
    # (gcmh_studio.live_play: the window's Animate tab and the exports call them here)
    def play(self, on: bool) -> tuple[bool, str]:
        """:meth:`gcmh_studio.live_play.LivePlay.play`: (may it play, what to say in the Animate tab)."""
        return self.live.play(on)

    def tick(self, dt: float) -> None:
        """:meth:`gcmh_studio.live_play.LivePlay.tick`: the playing animation ``dt`` seconds on."""
        self.live.tick(dt)

    def animation_frames(self, n_frames: int, projection=None):
        """:meth:`gcmh_studio.live_play.LivePlay.animation_frames`: an exported animation's frames."""
        return self.live.animation_frames(n_frames, projection)
