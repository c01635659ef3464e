"""QtMainWindow: the GCMH Studio window, which lays out and wires the studio's parts.

Layout: a side panel (tabs "Manifold" = :class:`QtFormulaPanel`, "View" =
:class:`QtProjectionPanel` (projection, mapping, slice, style), "Animate" =
:class:`QtAnimationPanel` and, when the library has its analysis module,
"Topology" = ``QtTopologyPanel``; with Run / Cancel, a progress bar and a
status line always visible below, and the example's description above them) and
the 3D view (:class:`gcmh_studio.qt_viewer.QtViewer`) in the centre. Double-click a cell
to see its vertices' coordinates in R^n and its grid cube.

Parameters are live: moving a slider of the Manifold tab re-extracts on a coarse
grid while it is held and on the full one when it is let go (:meth:`QtMainWindow.parameter_step`:
the newest value wins, the view and camera stay, continuation starts from the result on
screen), and a result at a critical value says so.

Waits explain themselves: the kernels compile (once per install) in the
background from the start (:func:`gcmh_studio.jobs.start_warm_up`, said in the status
bar), a run first shows its estimate (memory and time) and asks before one that
won't fit. Edit > Undo / Redo (Ctrl+Z, Ctrl+Shift+Z) step through the system
and the view (:class:`gcmh_studio.model.History`).

The parts: the state is an :class:`gcmh_studio.model.StudioModel` (no Qt); runs and
refinements go through an :class:`gcmh_studio.qt_run_controller.QtRunController` (worker
threads: the previous result stays on screen and can be turned while a new one
computes); menus and file dialogs are :class:`gcmh_studio.qt_actions.StudioActions`;
sessions and exports are written by :mod:`gcmh_studio.studio_io`, animations rendered
off screen by :mod:`gcmh_studio.headless`. Only the GUI thread touches VTK.
"""

from __future__ import annotations

import copy
import os
import time

import numpy as np
from qtpy.QtCore import Qt, QTimer, Signal
from qtpy.QtWidgets import (
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QProgressBar,
    QPushButton,
    QScrollArea,
    QSplitter,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from . import inputs, studio_io
from .jobs import COMPILE_NOTE, current_warm_up, start_warm_up
from .model import EMPTY_RESULT, StudioModel, animation_frames, telling_plane
from .qt_actions import StudioActions, ask_big_run
from .qt_animation_panel import QtAnimationPanel
from .qt_formula_panel import QtFormulaPanel
from .qt_presentation import QtPresentation
from .qt_projection_panel import QtProjectionPanel
from .qt_run_controller import QtRunController
from .qt_viewer import QtViewer
from .steps import CoarseAim, critical_notice, step_key
from .worker import COMPILING, ENGINE, STOPPING

# phases whose fraction means nothing: shown without a percentage
_WAITING_PHASES = ("starting", "estimating", COMPILING, STOPPING, ENGINE, "preparing the view")

try:   # written alongside this window; the window works without them
    from .qt_topology_panel import QtTopologyPanel
except ImportError:
    QtTopologyPanel = None
try:
    from .qt_gallery import QtGallery
except ImportError:
    QtGallery = None

DEFAULT_EXAMPLE = "klein-bottle"

class QtMainWindow(QMainWindow):
    """The application window. ``example``: the example to open and run at start (None: nothing)."""

    resultChanged = Signal(object)
    runFinished = Signal(str)   # "done", "cancelled", "failed" or "declined" (a run that won't fit, refused)
    refineFinished = Signal(str)  # "done", "failed" or "dropped" (the result changed meanwhile)

    def __init__(self, example: str | None = DEFAULT_EXAMPLE, parent=None, div=None, method: str = "gcmh",
                 warm_up: bool = True):
        super().__init__(parent)
        self.setWindowTitle("GCMH Studio")
        self.resize(1400, 900)
        self._closing = False
        self._run_waiting = False   # Run was pressed while a formula check was under way
        self.last_estimate = None   # the gcmh_core.budget.Estimate of the last run started
        self._session: tuple[dict, dict | None] = ({}, None)   # the view and camera of the session being opened
        # parameter steps (a slider moved): the newest one waiting for the run in flight (never a queue), the
        # coarse grid's scale for the system (key) being stepped, and when the step on its way started
        self._next_step = None
        self._superseded = False
        self._coarse = CoarseAim()
        self._step_t0 = 0.0
        self.last_step_seconds: float | None = None   # from a slider's change to the result drawn (the benchmark)
        self.model = StudioModel()
        self.runs = QtRunController(self)

        # --- side panel
        self.formula_panel = QtFormulaPanel()
        self.projection_panel = QtProjectionPanel()
        self.animation_panel = QtAnimationPanel()
        self.topology_panel = QtTopologyPanel() if QtTopologyPanel is not None else None
        self.tabs = QTabWidget()
        pages = [(self.formula_panel, "Manifold"), (self.projection_panel, "View"), (self.animation_panel, "Animate")]
        if self.topology_panel is not None:
            pages.append((self.topology_panel, "Topology"))
        for w, name in pages:
            sc = QScrollArea()
            sc.setWidgetResizable(True)
            sc.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
            sc.setWidget(w)
            self.tabs.addTab(sc, name)

        self.run_button = QPushButton("Run")
        self.run_button.setToolTip("extract the manifold (Ctrl+R)")
        self.run_button.setDefault(True)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setToolTip("stop the running extraction (Esc)")
        self.cancel_button.setEnabled(False)
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setValue(0)
        self.progress.setFormat("idle")
        self.progress.setTextVisible(True)
        self.status_label = QLabel("")
        self.status_label.setWordWrap(True)
        self.status_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.status_label.setMinimumHeight(36)
        self.result_label = QLabel(self.model.summary())
        self.result_label.setWordWrap(True)
        self.result_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.result_label.setStyleSheet("font-weight: bold;")
        self.pick_label = QLabel("")
        self.pick_label.setWordWrap(True)
        self.pick_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.pick_label.setStyleSheet("font-family: monospace; font-size: 11px;")
        self.pick_label.setVisible(False)
        # the example's description, kept in view while its result is on screen
        self.about_box = QGroupBox("")
        self.about_label = QLabel("")
        self.about_label.setWordWrap(True)
        self.about_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.about_label.setStyleSheet("font-size: 11px;")
        QVBoxLayout(self.about_box).addWidget(self.about_label)
        self.about_box.setVisible(False)

        side = QWidget()
        sl = QVBoxLayout(side)
        sl.setContentsMargins(6, 6, 6, 6)
        sl.addWidget(self.tabs, 1)
        sl.addWidget(self.about_box)
        br = QHBoxLayout()
        br.addWidget(self.run_button, 1)
        br.addWidget(self.cancel_button)
        sl.addLayout(br)
        sl.addWidget(self.progress)
        sl.addWidget(self.result_label)
        sl.addWidget(self.pick_label)
        sl.addWidget(self.status_label)
        side.setMinimumWidth(430)

        # --- viewer
        self.viewer = QtViewer(self.model, self.projection_panel, self)
        self.plotter, self.scene = self.viewer.plotter, self.viewer.scene

        split = QSplitter(Qt.Horizontal)
        split.addWidget(side)
        split.addWidget(self.viewer.widget)
        split.setStretchFactor(0, 0)
        split.setStretchFactor(1, 1)
        split.setSizes([440, 960])
        self.setCentralWidget(split)

        self.menu_actions = StudioActions(self, with_gallery=QtGallery is not None)
        self.statusBar()   # shows the menus' status tips (example descriptions)
        self.kernel_label = QLabel("")   # the kernels' warm-up (hidden by the menus' tips while they show)
        self.statusBar().addWidget(self.kernel_label, 1)
        self._timer = QTimer(self)
        self._timer.setInterval(100)
        self._timer.timeout.connect(self._tick)
        self._wire()
        self._update_buttons()
        self.set_status("Choose an example or type a system, then Run (Ctrl+R).")
        self.model.set_system(self.formula_panel.state())   # the first state Undo comes back to
        self._sync_view()
        self.warm_up = start_warm_up(self.formula_panel.methods) if warm_up else current_warm_up()
        self._warm_timer = QTimer(self)
        self._warm_timer.setInterval(250)
        self._warm_timer.timeout.connect(self._show_warm_up)
        if self.warm_up is not None and self.warm_up.running():
            self._warm_timer.start()

        self.presentation = QtPresentation(self)   # F11, the typeset formula, axes, next example

        if example:
            QTimer.singleShot(0, lambda: self.load_example(example, div=div, method=method))

    def _wire(self) -> None:
        m, v, pp, ap = self.model, self.viewer, self.projection_panel, self.animation_panel
        m.events.status.connect(self._show_status)
        m.events.picked.connect(self._show_pick)
        self.run_button.clicked.connect(self.run)
        self.cancel_button.clicked.connect(self.cancel)
        self.formula_panel.validityChanged.connect(self._update_buttons)
        self.formula_panel.changed.connect(lambda: m.set_system(self.formula_panel.state()))
        for signal, slot in ((pp.projectionChanged, v.on_projection), (pp.baseChanged, v.on_base),
                             (pp.styleChanged, v.on_style), (pp.sliceChanged, v.on_slice)):
            signal.connect(slot)
            signal.connect(self._sync_view)
        ap.tick.connect(self._on_anim_tick)
        ap.playingChanged.connect(self._on_anim_playing)
        ap.modeChanged.connect(lambda *_: self._on_anim_playing(ap.is_playing()))
        ap.exportRequested.connect(self.menu_actions.export_animation_dialog)
        self.runs.busyChanged.connect(self._on_busy)
        self.runs.progress.connect(self._on_progress)
        self.runs.done.connect(self._on_done)
        self.runs.failed.connect(self._on_failed)
        self.runs.cancelled.connect(self._on_cancelled)
        self.runs.declined.connect(self._on_declined)
        self.runs.estimated.connect(self._on_estimated)
        self.runs.confirm.connect(self._on_confirm)
        self.formula_panel.checked.connect(self._on_checked)
        fpp = self.formula_panel.parameters
        fpp.dragging.connect(lambda *_: self.parameter_step(coarse=True))
        fpp.committed.connect(lambda *_: self.parameter_step(coarse=False))
        fpp.changed.connect(lambda: ap.set_parameters(fpp.state()))   # the Animate tab sweeps them
        self.formula_panel.changed.connect(lambda: ap.set_parameters(fpp.state()))
        self.runFinished.connect(self._start_next_step)
        m.events.history.connect(self.menu_actions.set_history)
        self.runs.refined.connect(self._on_refined)
        self.runs.refineFailed.connect(self._on_refine_failed)
        if self.topology_panel is not None:
            tp = self.topology_panel
            tp.refineRequested.connect(self.refine_result)
            # the topology panel's view switches and the View tab's are the same switches, kept in step
            for theirs, mine in ((tp.boundary_check, pp.boundary_check), (tp.path_check, pp.grid_check),
                                 (tp.two_sided_check, pp.two_sided_check)):
                theirs.toggled.connect(mine.setChecked)    # setChecked with the same value emits nothing: no loop
                mine.toggled.connect(theirs.setChecked)
        try:   # double-click a cell: its coordinates in R^n and its grid cube
            self.plotter.track_click_position(self._on_click, side="left", double=True, viewport=True)
        except Exception:  # noqa: BLE001 - picking is a convenience
            pass

    # ------------------------------------------------------------------ the model's state, as the tests read it
    @property
    def result(self):
        """The CellComplex on screen (None before the first result)."""
        return self.model.result

    @property
    def result_names(self) -> list[str]:
        return self.model.names

    @property
    def last_status(self) -> str:
        return self.model.status

    @property
    def last_refinement(self) -> dict | None:
        return self.model.last_refinement

    # ------------------------------------------------------------------ status
    def set_status(self, text: str, error: bool = False) -> None:
        """The message line under the result (errors in red)."""
        self.model.set_status(text, error)

    def _show_status(self, text: str, error: bool) -> None:
        self.status_label.setStyleSheet("color: #c22;" if error else "")
        self.status_label.setText(text)

    def _show_pick(self, info) -> None:
        self.pick_label.setText(self.model.pick_text())
        self.pick_label.setVisible(info is not None)

    def _sync_view(self) -> None:
        playing = self.animation_panel.is_playing()
        self.model.recording = not playing   # a playing animation is not a step to undo (its end is)
        try:
            self.model.set_view(self.projection_panel.state())
        finally:
            self.model.recording = True

    def _show_warm_up(self) -> None:
        """The status bar while the kernels compile; a second after a cached load, nothing is said."""
        warm = self.warm_up
        if warm is None:
            return
        if warm.running():
            if warm.elapsed() > 1.0:
                self.kernel_label.setText(
                    f"Compiling the numerical kernels: once per install, {COMPILE_NOTE} "
                    f"({warm.elapsed():.0f} s so far); later runs start at once.")
            return
        self._warm_timer.stop()
        if warm.error:
            self.kernel_label.setText(f"Kernel warm-up failed ({warm.error}); the first run compiles them.")
        elif warm.seconds is not None and warm.seconds > 3.0:
            self.kernel_label.setText(f"Kernels compiled in {warm.seconds:.0f} s; they are kept for later runs.")
            # a timer owned by the label: it dies with the window instead of firing on a deleted label
            clear = QTimer(self.kernel_label)
            clear.setSingleShot(True)
            clear.timeout.connect(self.kernel_label.clear)
            clear.start(15_000)
        else:
            self.kernel_label.setText("")

    # ------------------------------------------------------------------ undo / redo
    def undo(self) -> bool:
        """Back to the previous system and view (Ctrl+Z); False at the start of the history."""
        return self._step(self.model.undo, "undo")

    def redo(self) -> bool:
        """Forward again after an undo (Ctrl+Shift+Z); False when nothing was undone."""
        return self._step(self.model.redo, "redo")

    def _step(self, step, what: str) -> bool:
        """Step through the history until something on screen changes (a step whose view belongs to
        another result's variables changes nothing here, and is passed over)."""
        while True:
            state = step()
            if state is None:
                self.set_status(f"Nothing to {what}.")
                return False
            before = self.formula_panel.state()
            if self._restore(state):
                self._follow_parameters(before)
                return True

    def _follow_parameters(self, before: dict) -> None:
        """An undo or redo that changed only the parameters' values of the system on screen shows the
        manifold at the values it brought back (as a slider let go would)."""
        after = self.formula_panel.state()
        values = [{p: s["value"] for p, s in (d.get("params") or {}).items()} for d in (before, after)]
        rest = [{key: v for key, v in d.items() if key != "params"} for d in (before, after)]
        job = self.model.job
        if (values[0] != values[1] and rest[0] == rest[1] and self.result is not None and job is not None
                and list(job.formulas) == self.formula_panel.formulas()):
            self.parameter_step(coarse=False)

    def _restore(self, state: dict) -> bool:
        """Show ``state`` (a History entry) in the panels; False if nothing changed."""
        fp, pp = self.formula_panel, self.projection_panel
        changed = False
        self.model.recording = False
        try:
            if state.get("system") and state["system"] != fp.state():
                fp.set_state(state["system"])
                changed = True
            view = state.get("view")
            current = pp.state()
            # a view belongs to a result's variables: one of another result's is passed over
            if view and view != current and view.get("planes") == current.get("planes"):
                pp.set_state(view)
                changed = True
        finally:
            self.model.recording = True
        self.model.system, self.model.view = fp.state(), pp.state()
        if changed:   # the panels' reading of it (a passed-over entry keeps its own view)
            self.model.history.sync(self.model.snapshot())
        return changed

    def _update_buttons(self, *_):
        running = self.is_running()
        ok = self.formula_panel.is_valid() and not running
        self.run_button.setEnabled(ok)
        self.cancel_button.setEnabled(running)
        self.menu_actions.set_running(running, ok)
        if not self.formula_panel.is_valid() and not running:
            first = next(iter(self.formula_panel.errors.items()), None)
            self.run_button.setToolTip(f"fix first: {first[1]}" if first else "")
        else:
            self.run_button.setToolTip("extract the manifold (Ctrl+R)")

    def guard(self, what: str, fn, *a, **kw):
        """Call ``fn``; an error becomes "<what> failed: ..." on the status line (and None is returned)."""
        try:
            return fn(*a, **kw)
        except Exception as e:  # noqa: BLE001 - file errors go to the status line
            self.set_status(f"{what} failed: {e}", error=True)
            return None

    # ------------------------------------------------------------------ examples
    def load_example(self, name: str, run: bool = True, div=None, method: str = "gcmh") -> bool:
        """Fill the panel from an example, run it, and show its suggested view."""
        from gcmh_core.examples import load_example

        try:
            ex = load_example(name)
        except Exception as e:  # noqa: BLE001
            self.set_status(str(e), error=True)
            return False
        state = dict(
            n=ex.n, k=ex.k, variables=list(ex.variables), formulas=list(ex.formulas),
            bounds=[list(b) for b in ex.bounds], div=div if div is not None else ex.div,
            method=method, seed=0, start=list(ex.start) if ex.start else None,
            params={p: dict(spec) for p, spec in (getattr(ex, "params", None) or {}).items()},
            periodic=list(getattr(ex, "periodic", None) or []))
        if getattr(ex, "complex", None):   # as on the blackboard: the equations over C^m, split by the panel
            state.update(complex=list(ex.complex), complex_variables=list(ex.complex_variables),
                         formulas=list(ex.formulas)[2 * len(ex.complex):])
        self.formula_panel.set_state(state)
        self.model.expect(ex.title, ex.formulas, ex.variables, view=ex.view or {})
        self.setWindowTitle(f"GCMH Studio \u2014 {ex.title}")
        self.show_description(ex.title, " ".join(str(ex.description).split()))
        self.set_status("")
        if run:
            return self.run()
        return True

    def show_description(self, title: str, text: str) -> None:
        """The example's title and description above Run (hidden for a system typed in)."""
        self.about_box.setTitle(title)
        self.about_label.setText(text)
        self.about_box.setVisible(bool(title or text))

    def open_gallery(self):
        """Show the example gallery (window-modal, not blocking); choosing an example opens and runs it."""
        if QtGallery is None:
            return None
        g = QtGallery(self)
        g.exampleChosen.connect(lambda name: self.load_example(name))
        g.setAttribute(Qt.WA_DeleteOnClose)
        self.gallery = g
        g.open()
        return g

    # ------------------------------------------------------------------ runs
    def confirm_big_run(self, est):
        """Ask before a run that won't fit (``est``: its gcmh_core.budget.Estimate; tests may replace this).

        Returns "run" (go ahead), "gcch" (switch to continuation and run) or None (don't run).
        """
        fp = self.formula_panel
        return ask_big_run(self, est, gcch="gcch" in fp.methods and not fp.continuation())

    def run(self) -> bool:
        """Start an extraction with the panel's contents; False if refused.

        While a formula is still being checked, the run starts when the answer comes (True is returned:
        ``runFinished`` says how it ended). The worker waits for the kernels' warm-up, estimates the run
        and, when it won't fit, asks (:meth:`confirm_big_run`) before the engine starts."""
        if self.is_running():
            self.set_status("A run is already in progress: cancel it first (Esc).", error=True)
            return False
        if self.formula_panel.checking():
            self._run_waiting = True
            self.formula_panel.check_now()
            self.progress.setValue(0)
            self.progress.setFormat("checking the formulas\u2026")
            self._update_buttons()
            return True
        if not self.formula_panel.is_valid():
            errs = self.formula_panel.errors
            self.set_status("Cannot run: " + "; ".join(f"{k}: {v}" for k, v in errs.items()), error=True)
            return False
        job = self.formula_panel.job()
        self._next_step = None   # (a Run is newer than any slider step waiting)
        self.model.job = job
        self._suggest_complex_view(job)
        self.progress.setValue(0)
        warm = current_warm_up()
        self.progress.setFormat(f"{COMPILING}\u2026" if warm is not None and warm.waits_for(job.method)
                                else "starting\u2026")
        return self.runs.start(job)

    def _suggest_complex_view(self, job) -> None:
        """A new system typed in complex mode opens as a graph: the first variable's plane flat, the real part
        of the second as height, coloured by its imaginary part (gcmh_core.complex_equations.complex_view)."""
        fp = self.formula_panel
        if not fp.is_complex() or list(job.variables) == self.model.names:
            return
        try:
            from gcmh_core.complex_equations import complex_view

            self.model.suggest_view(complex_view(fp.complex_variables(), list(job.variables)))
        except Exception:  # noqa: BLE001 - one complex variable (a curve in C): the default view
            pass

    # ------------------------------------------------------------------ parameter steps (a slider moved)
    def parameter_step(self, coarse: bool) -> bool:
        """Re-extract at the parameters' values on show: while a slider is held (``coarse``) on a coarse grid,
        when it is let go on the full one. The newest step wins: it waits for the coarse step in flight (which
        is shown: the picture follows the slider), and a full step or a user's run in flight is cancelled for
        it; older waiting steps are dropped. Continuation starts from the result on screen. False when the
        panel can't run now (a wrong field, a check under way, a Run waiting for it)."""
        fp = self.formula_panel
        if self._closing or self._run_waiting or not fp.is_valid() or fp.checking():
            return False
        job = fp.job_unchecked()
        job.step = "coarse" if coarse else "full"
        if coarse:
            job.div = self._coarse.div(job, fp.div_list())
        prev = self.model.job
        same = prev is not None and self.result is not None and step_key(prev) == step_key(job)
        if same and prev.force and not coarse:
            job.force = True   # the user agreed to this run's size already
        if same and fp.continuation() and not job.scheduler:
            job.start = self.result   # continue from the result on screen (gcmh_core: start=<CellComplex>)
        self._next_step = job
        if self.runs.is_running():
            running = self.runs.worker.job
            if not (coarse and running.step == "coarse"):
                self._superseded = True
                self.runs.cancel()
            return True
        return self._start_next_step()

    def _start_next_step(self, *_) -> bool:
        """Start the parameter step waiting, if any (after the run in flight ended)."""
        job, self._next_step = self._next_step, None
        if job is None or self._closing or self.runs.is_running():
            self._next_step = self._next_step or job
            return False
        self._superseded = False   # (the run it replaced has ended, cancelled or not)
        self._step_t0 = time.perf_counter()
        self.model.job = job
        return self.runs.start(job)

    def _on_checked(self) -> None:
        """The formula checks are answered: a Run pressed meanwhile starts now (or is refused)."""
        if not self._run_waiting:
            return
        self._run_waiting = False
        self._update_buttons()
        if self.formula_panel.is_valid():
            if self.run():
                return
        else:
            self.run()   # says "Cannot run: ..." on the status line
        self.progress.setFormat("idle")
        self.runFinished.emit("failed")

    def cancel(self) -> None:
        if self._run_waiting:
            self._run_waiting = False
            self._update_buttons()
            self.progress.setFormat("cancelled")
            self.set_status("Cancelled before the run started.")
            self.runFinished.emit("cancelled")
        elif self.runs.cancel():
            self.progress.setFormat("cancelling\u2026")

    def is_running(self) -> bool:
        """A run under way (or waiting for its formulas' check)."""
        return self.runs.is_running() or self._run_waiting

    def _on_estimated(self, est) -> None:
        self.last_estimate = est
        if self.model.job is not None and self.model.job.step is not None:
            return   # (a slider step: the status line keeps what the result says)
        self.set_status(f"This run: about {inputs.human_bytes(est.peak_bytes)} of memory "
                        f"(of {inputs.human_bytes(est.available_bytes)} available), "
                        f"about {inputs.human_seconds(est.seconds)}.")

    def _on_confirm(self, est) -> None:
        answer = self.confirm_big_run(est)
        if answer == "gcch":
            self.formula_panel.set_method("gcch")
        self.runs.answer(answer)

    def _on_declined(self) -> None:
        self.progress.setValue(0)
        self.progress.setFormat("not started")
        self.set_status("Run not started: choose a smaller div, or continuation (GCCH).", error=True)
        self.runFinished.emit("declined")

    def _on_busy(self, running: bool) -> None:
        (self._timer.start if running else self._timer.stop)()
        self._update_buttons()

    def _tick(self) -> None:
        if not self.runs.is_running():
            return
        fmt = self.progress.format()
        phase = fmt.split(" \u00b7 ")[0] if fmt else "running"
        self.progress.setFormat(f"{phase} \u00b7 {self.runs.elapsed():.1f} s")

    def _on_progress(self, phase: str, fraction: float, seconds: float) -> None:
        self.progress.setValue(int(round(1000 * max(0.0, min(1.0, fraction)))))
        if phase.startswith(_WAITING_PHASES):
            self.progress.setFormat(f"{phase}\u2026 \u00b7 {seconds:.1f} s")
        else:
            self.progress.setFormat(f"{phase} {100 * fraction:.0f}% \u00b7 {seconds:.1f} s")
        if phase == COMPILING:
            self.set_status(f"The numerical kernels compile once per install ({COMPILE_NOTE}); "
                            "this run starts when they are ready.")

    def _on_done(self, cx, geometry, report) -> None:
        job = self.model.job
        self.progress.setValue(1000)
        self.progress.setFormat(f"done \u00b7 {self.runs.elapsed():.1f} s")
        computed = time.perf_counter() - self._step_t0   # (a step's computing, before it is drawn)
        # a parameter step of the system on screen keeps the whole view: projection, turns, slice, colour, camera
        keep = job.step is not None and self.result is not None and list(job.variables) == self.model.names
        view = None if keep else self.model.take_view()
        title = self.model.title_for(job.formulas, job.variables)
        if not title:   # a system typed in: the last example's description no longer applies
            self.show_description("", "")
            title = job.title
        camera = studio_io.camera_state(self.plotter.camera) if keep else None
        try:
            self.show_result(cx, job.variables, view=view, title=title, geometry=geometry, report=report,
                             keep_view=keep, labels=job.labels, moving=job.step == "coarse")
            if camera is not None:
                studio_io.apply_camera(self.plotter.camera, camera)
                self.plotter.renderer.ResetCameraClippingRange()
        except Exception as e:  # noqa: BLE001 - a drawing problem must not take the window down
            self.set_status(f"Could not draw the result: {type(e).__name__}: {e}", error=True)
            self.runFinished.emit("failed")
            return
        notice = critical_notice(cx, self.formula_panel.parameters.last_moved)
        self.formula_panel.parameters.set_notice(notice)
        if notice and self.topology_panel is not None:
            euler = self.topology_panel.values.get("euler")
            if euler is not None:
                euler.setText(f"{euler.text()}  (critical value)")
                euler.setStyleSheet("color: #a04000; font-weight: bold;")
        if cx.count(0) == 0:
            self.set_status(EMPTY_RESULT, error=True)
        elif notice:
            self.set_status(notice)
        else:
            self.set_status(cx.meta.get("start_note", "") if job.step is None else "")
        if job.step is not None:
            self.last_step_seconds = time.perf_counter() - self._step_t0
            if job.step == "coarse":
                self._coarse.learn(job, computed)   # aim the next coarse grid
        self.runFinished.emit("done")

    def _on_failed(self, message: str) -> None:
        self.progress.setValue(0)
        self.progress.setFormat("failed")
        self.set_status(f"Error: {message}", error=True)
        self.runFinished.emit("failed")

    def _on_cancelled(self, seconds: float) -> None:
        if self._superseded:   # a newer parameter step took its place: it starts now
            self._superseded = False
            self.runFinished.emit("cancelled")
            return
        self.progress.setValue(0)
        self.progress.setFormat("cancelled")
        keep = " The previous result stays on screen." if self.result is not None else ""
        self.set_status(f"Cancelled after {seconds:.1f} s.{keep}")
        self.runFinished.emit("cancelled")

    # ------------------------------------------------------------------ showing a result
    def show_result(self, cx, names, view: dict | None = None, title: str = "", geometry=None,
                    report: dict | None = None, keep_view: bool = False, labels: dict | None = None,
                    moving: bool = False) -> None:
        """Put a CellComplex on screen (GUI thread). ``report``: its topology report if already made;
        ``keep_view``: the same system at other parameters (the View tab is left as it is); ``labels``: what
        the variables mean ({"u": "Re w"})."""
        names = list(names)
        if keep_view and self.result is not None and names == self.model.names:
            self.model.set_result(cx, names, title, labels)
            self._sync_view()
            self.viewer.show(geometry, moving=moving)
            self.result_label.setText(self.model.summary())
            if self.topology_panel is not None:
                self._show_topology(cx, report)
            self.resultChanged.emit(cx)
            return
        prev_dim = self.result.dim if self.result is not None else None
        prev_names = self.model.names
        self.model.set_result(cx, names, title, labels)
        pp = self.projection_panel
        pp.set_variables(names, keep=(names == prev_names))
        pp.model.set_vertices(cx.vertices)
        self.animation_panel.set_variables(names)
        if names != prev_names:
            self.animation_panel.set_plane(telling_plane(pp.model.matrix()))
        if prev_dim is None or (prev_dim <= 2) != (cx.dim <= 2):
            pp.set_style_defaults(cx.dim)
        if view:
            pp.apply_view(view)
        self._sync_view()
        self.viewer.show(geometry)
        self.result_label.setText(self.model.summary())
        if self.topology_panel is not None:
            self._show_topology(cx, report)
        self.resultChanged.emit(cx)

    def _show_topology(self, cx, report=None) -> None:
        from .jobs import topology_of

        try:
            if report is None:
                report = topology_of(cx, self.model.job)
            if report is None:
                self.topology_panel.clear()
            else:
                self.topology_panel.set_report(report)
        except Exception as e:  # noqa: BLE001
            self.set_status(f"Topology report failed: {e}", error=True)

    def reset_camera(self) -> None:
        self.viewer.reset_camera()

    def screenshot_array(self) -> np.ndarray:
        """The current view as an (h, w, 3) uint8 array."""
        return self.viewer.screenshot_array()

    # ------------------------------------------------------------------ picking
    def pick_cell(self, cell_id: int) -> dict:
        """Select cell ``cell_id`` (a 2-cell, or an edge of a curve): show and return its facts.

        Returns dict(cell, vertices (ids), coords (m, n), cube (n,) grid index or None).
        """
        return self.viewer.pick_cell(cell_id)

    def pick_at(self, display_xy):
        """Pick the cell drawn at pixel (x, y) (from the bottom left); None if nothing is there."""
        return self.viewer.pick_at(display_xy)

    def _on_click(self, pos) -> None:
        try:
            self.pick_at(pos[:2])
        except Exception as e:  # noqa: BLE001 - a failed pick is a message, never a crash
            self.set_status(f"Picking failed: {e}", error=True)

    # ------------------------------------------------------------------ refinement
    def refine_result(self) -> bool:
        """Start moving the vertices closer to M (Gauss-Newton) in a worker thread; the
        refined complex replaces the result when it is done (`refineFinished`).  False if
        there is nothing to refine or a refinement already runs."""
        if self.result is None or self.model.job is None:
            self.set_status("Nothing to refine yet: run first.", error=True)
            return False
        if not self.runs.refine(self.result, self.model.job, self.model.serial):
            self.set_status("A refinement is already running.", error=True)
            return False
        if self.topology_panel is not None:
            self.topology_panel.set_refine_enabled(False)
        self.set_status("Refining the vertices onto M\u2026")
        return True

    def _refine_ended(self) -> None:
        if self.topology_panel is not None:
            self.topology_panel.set_refine_enabled(True)

    def _on_refined(self, serial: int, cx, geometry, report, before: float, after: float) -> None:
        self._refine_ended()
        if self._closing:
            return
        if self.model.serial != serial:  # a run (or a file) put another result on screen meanwhile
            self.set_status("Refinement dropped: the result changed while it ran.")
            self.refineFinished.emit("dropped")
            return
        try:
            self.show_result(cx, self.model.names, title=self.model.title, geometry=geometry, report=report)
        except Exception as e:  # noqa: BLE001 - a drawing problem must not take the window down
            self.set_status(f"Could not draw the refined result: {type(e).__name__}: {e}", error=True)
            self.refineFinished.emit("failed")
            return
        if self.topology_panel is not None:
            self.topology_panel.show_refinement(before, after)
        self.set_status(f"Refined: max |F| at the vertices {before:.3g} \u2192 {after:.3g}")
        self.model.set_refinement(before, after)
        self.refineFinished.emit("done")

    def _on_refine_failed(self, message: str) -> None:
        self._refine_ended()
        if not self._closing:
            self.set_status(f"Refining failed: {message}", error=True)
            self.refineFinished.emit("failed")

    # ------------------------------------------------------------------ animation
    def toggle_play(self) -> None:
        self.animation_panel.set_playing(not self.animation_panel.is_playing())

    def _on_anim_playing(self, on: bool) -> None:
        ap, pp = self.animation_panel, self.projection_panel
        self.model.animation.start(pp.model.angles)
        plane = ap.plane()
        still = (on and ap.mode() == "rotate" and plane is not None and pp.model.mapping == "orthographic"
                 and np.allclose(pp.model.matrix()[:, list(plane)], 0.0))
        if on and ap.mode() == "slice" and pp.slice_window() is None:
            ap.show_message("Turn the slice on in the View tab first.")
            ap.set_playing(False)
        elif on and self.result is None:
            ap.show_message("Nothing to animate yet: run first.")
            ap.set_playing(False)
        elif on:
            ap.show_message("Both axes of this plane are hidden: turning it moves nothing on screen. "
                            "Pick a plane with a shown axis." if still else "")
            if ap.mode() == "slice":   # start the sweep where the slider is
                self.model.animation.start(pp.model.angles, slice_centre=pp.slice_fractions()[0])

    def _on_anim_tick(self, dt: float) -> None:
        """Advance the playing animation by ``dt`` seconds (times the speed), in place."""
        if self.result is None:
            return
        ap, pp, clock = self.animation_panel, self.projection_panel, self.model.animation
        mode = ap.mode()
        if mode == "rotate":
            plane = ap.plane()
            if plane is not None:
                pp.set_angles(clock.rotate_step(pp.model.angles, pp.model.planes.index(tuple(plane)), dt))
        elif mode == "tour":
            pp.set_angles(clock.tour_step(dt))
        elif mode == "slice":
            pp.set_slice_center(clock.sweep_step(dt))

    def animation_frames(self, n_frames: int, projection=None):
        """Frames of the animation chosen in the Animate tab (from the current view) and the slice to use."""
        projection = projection or self.projection_panel.model
        ap = self.animation_panel
        return animation_frames(ap.mode(), ap.plane(), projection, n_frames, self.viewer.slice_params(projection))

    def export_animation(self, path, frames: int | None = None, fps: float | None = None, size=None,
                         show_progress: bool = True) -> int:
        """Render the Animate tab's animation off screen and write ``path`` (.gif or .mp4).

        The window's view is not changed. Returns the number of frames written
        (0 when cancelled: the file is removed). A parameter sweep extracts the last run's
        system at each frame's value (gcmh_studio.headless.export_param_sweep).
        """
        from gcmh_core.errors import InputError

        from .projection import ProjectionModel

        if self.result is None or self.scene.complex is None:
            raise ValueError("nothing to animate yet: run first")
        ap = self.animation_panel
        n = int(frames or ap.frames_spin.value())
        fps = float(fps or ap.fps_spin.value())
        ap.set_playing(False)
        projection = ProjectionModel.from_dict(self.projection_panel.model.n, self.projection_panel.model.to_dict())
        projection.share_principal(self.projection_panel.model)
        w, h = (int(s) // 2 * 2 for s in (size or self.viewer.size()))
        name = os.path.basename(str(path))
        if ap.mode() == "param":
            from .animation import parse_spec
            from .headless import export_param_sweep

            if self.model.job is None:   # (a complex opened from a file has no system to sweep)
                raise ValueError("a parameter sweep needs a run of a system with parameters: run first")
            names = self.result_names
            spec = parse_spec(ap.spec_text(), names, params=list(ap.params))
            what, steps = ("Parameter sweep", f"Extracting and rendering {name}\u2026"), 2 * n

            def write(progress, cancel):   # progress by phase: the extractions, then the frames
                written, _ = export_param_sweep(
                    [path], self.model.job, spec, n, names, projection, copy.copy(self.scene.style), (w, h), fps,
                    mapping=projection.mapping, camera=self.plotter.camera, cancel=cancel,
                    progress=lambda phase, k: progress(k if phase == "extract" else n + k))
                return written
        else:
            seq, window = self.animation_frames(n, projection)
            what, steps = ("Animation", f"Rendering {name}\u2026"), n

            def write(progress, cancel):
                return self.viewer.write_animation(path, seq, window, projection, (w, h), fps, progress=progress,
                                                   cancel=cancel)
        try:
            written = self._with_progress(f"Export {what[0].lower()}", what[1], steps, write, show_progress)
        except InputError as e:   # (a sweep that won't fit, or an output that can't be written: said first)
            raise ValueError(str(e)) from None
        if written < n:
            self.set_status(f"Export cancelled after {written} of {n} frames; nothing written.")
            return 0
        self.set_status(f"{what[0]} saved to {path} ({n} frames, {w}\u00d7{h}, {ap.spec_text()})")
        return written

    def _with_progress(self, title: str, text: str, steps: int, work, show: bool):
        """``work(progress, cancel)`` under a window-modal progress dialog of ``steps`` steps (or none)."""
        from qtpy.QtWidgets import QApplication, QProgressDialog

        dlg = None
        if show:
            dlg = QProgressDialog(text, "Cancel", 0, steps, self)
            dlg.setWindowTitle(title)
            dlg.setWindowModality(Qt.WindowModal)
            dlg.setMinimumDuration(0)
            dlg.setValue(0)

        def progress(k):
            if dlg is not None:
                dlg.setValue(k)
            QApplication.processEvents()

        try:
            return work(progress, (lambda: dlg.wasCanceled()) if dlg is not None else None)
        finally:
            if dlg is not None:
                dlg.close()

    # ------------------------------------------------------------------ sessions and exports
    def session(self) -> dict:
        self.model.set_system(self.formula_panel.state())
        self._sync_view()
        return studio_io.session_dict(self.model, **self.viewer.camera_session())

    def save_session(self, path) -> None:
        path = studio_io.write_session(path, self.session())
        self.set_status(f"Session saved to {path}")

    def open_session(self, path, run: bool = True) -> bool:
        """Restore a session: fill the panel, run, then restore the view (projection, angles, colour)."""
        try:
            d = studio_io.read_session(path)
        except (OSError, ValueError) as e:
            self.set_status(f"Cannot open {path}: {e}", error=True)
            return False
        self.formula_panel.set_state(d["system"])
        self.model.expect(d.get("title", ""), self.formula_panel.formulas(), self.formula_panel.variables())
        self._session = (d.get("view") or {}, d["camera"], d["keep_camera"])
        if run and (self.formula_panel.is_valid() or self.formula_panel.checking()):
            self.runFinished.connect(self._apply_session_view)
            return self.run()
        return True

    def _apply_session_view(self, how: str) -> None:
        try:
            self.runFinished.disconnect(self._apply_session_view)
        except (TypeError, RuntimeError):
            pass
        if how != "done":
            return
        view, camera, keep = self._session
        self.projection_panel.set_state(view)
        self.viewer.restore_camera(camera, keep)

    def export_complex(self, path) -> None:
        path = studio_io.export_complex(self.result, path)
        self.set_status(f"Complex saved to {path}")

    def export_mesh(self, path) -> None:
        dim = None if self.result is None else self.result.dim
        path = studio_io.export_mesh(self.scene.projected_mesh(), path, dim)
        self.set_status(f"Projected mesh saved to {path}")

    def save_screenshot(self, path, size=None, transparent: bool = False) -> np.ndarray:
        """Write a PNG of the current view at ``size`` (w, h) pixels, re-rendered off screen."""
        size = size or self.viewer.size()
        img = self.viewer.save_screenshot(path, size, transparent)
        self.set_status(f"Screenshot saved to {path} ({size[0]}\u00d7{size[1]})")
        return img

    # ------------------------------------------------------------------ closing
    def closeEvent(self, event) -> None:
        self._closing = True
        self._timer.stop()
        self._warm_timer.stop()
        self.animation_panel.set_playing(False)
        self.runs.shutdown()
        try:
            self.plotter.close()
        except Exception:  # noqa: BLE001
            pass
        super().closeEvent(event)
