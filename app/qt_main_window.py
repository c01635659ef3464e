"""QtMainWindow: the GCMH Studio window.

Layout: a side panel (tabs "Manifold" = :class:`QtFormulaPanel`, "View" =
:class:`QtProjectionPanel` (projection, mapping, slice, style), "Animate" =
:class:`QtAnimationPanel` and, when the library has its analysis module,
"Topology" = ``QtTopologyPanel``; with Run / Cancel, a progress bar and a
status line always visible below) and a ``pyvistaqt.QtInteractor`` in the
centre, drawn by an :class:`app.scene.Scene`. Double-click a cell to see its
vertices' coordinates in R^n and its grid cube (:meth:`QtMainWindow.pick_cell`).

Runs go through :class:`app.worker.ExtractWorker` (a QThread); the previous
result stays on screen and can be turned while a new one computes. Only the
GUI thread touches VTK.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np
from qtpy.QtCore import Qt, QTimer, Signal
from qtpy.QtGui import QKeySequence
from qtpy.QtWidgets import (
    QAction, QCheckBox, QDialog, QDialogButtonBox, QFileDialog, QFormLayout, QHBoxLayout, QLabel,
    QMainWindow, QMessageBox, QProgressBar, QPushButton, QScrollArea, QSpinBox, QSplitter,
    QTabWidget, QVBoxLayout, QWidget,
)

from . import inputs
from .animation import Spec, frames_for, tour_angles, write_animation
from .qt_animation_panel import ROTATE_PERIOD, SLICE_PERIOD, TOUR_PERIOD, QtAnimationPanel
from .qt_formula_panel import QtFormulaPanel
from .qt_projection_panel import QtProjectionPanel
from .scene import (
    BOUNDARY_COLOR, GRID_COLOR, PICK_COLOR, Scene, Style, animation_images, copy_camera, default_camera, describe,
    render_image,
)
from .geometry import boundary_lines, cell_info, grid_cube_lines
from .slicing import window_range
from .worker import ExtractWorker, RefineWorker

try:   # written alongside this window; the window works without them
    from .qt_topology_panel import QtTopologyPanel
except ImportError:
    QtTopologyPanel = None
try:
    from .qt_gallery import QtGallery
except ImportError:
    QtGallery = None

SESSION_FORMAT = "gcmh-session/1"
DEFAULT_EXAMPLE = "klein-bottle"


def summarize(cx) -> str:
    """One status line: counts by dimension, Euler characteristic, boundary, time."""
    names = {0: "vertices", 1: "edges", 2: "faces", 3: "3-cells"}
    counts = cx.counts()
    parts = [f"{c:,} {names.get(r, f'{r}-cells')}" for r, c in enumerate(counts)]
    try:
        chi = cx.euler_characteristic()
    except Exception:  # noqa: BLE001
        chi = "?"
    try:
        nb = len(cx.boundary_facets())
    except Exception:  # noqa: BLE001
        nb = "?"
    secs = cx.meta.get("seconds")
    t = f" \u00b7 {secs:.2f} s" if isinstance(secs, (int, float)) else ""
    bword = "boundary vertices" if cx.dim == 1 else "boundary facets"
    return f"{', '.join(parts)} \u00b7 \u03c7 = {chi} \u00b7 {nb:,} {bword}{t}" if isinstance(nb, int) else \
        f"{', '.join(parts)} \u00b7 \u03c7 = {chi}{t}"


class QtScreenshotDialog(QDialog):
    """Asks for the picture size and a transparent background."""

    def __init__(self, size, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Screenshot")
        f = QFormLayout(self)
        self.w = QSpinBox()
        self.w.setRange(64, 8192)
        self.w.setValue(size[0])
        self.h = QSpinBox()
        self.h.setRange(64, 8192)
        self.h.setValue(size[1])
        row = QHBoxLayout()
        row.addWidget(self.w)
        row.addWidget(QLabel("\u00d7"))
        row.addWidget(self.h)
        f.addRow("size (pixels)", row)
        self.transparent = QCheckBox("transparent background")
        f.addRow(self.transparent)
        bb = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        bb.accepted.connect(self.accept)
        bb.rejected.connect(self.reject)
        f.addRow(bb)


class QtMainWindow(QMainWindow):
    """The application window. ``example``: the example to open and run at start (None: nothing)."""

    resultChanged = Signal(object)
    runFinished = Signal(str)   # "done", "cancelled" or "failed"
    refineFinished = Signal(str)  # "done", "failed" or "dropped" (the result changed meanwhile)

    def __init__(self, example: str | None = DEFAULT_EXAMPLE, parent=None, div=None, method: str = "gcmh"):
        super().__init__(parent)
        self.setWindowTitle("GCMH Studio")
        self.resize(1400, 900)
        self.result = None            # the CellComplex on screen
        self.result_serial = 0        # counts the results shown (a refinement belongs to one)
        self.result_names: list[str] = []
        self.result_title = ""
        self.worker: ExtractWorker | None = None
        self.refiner: RefineWorker | None = None
        self._old_workers: list = []   # finished runs and refinements, until their threads end
        self.last_refinement: dict | None = None  # max |F| before and after the last refinement shown
        self._pending_view: dict | None = None
        self._pending_title = ""
        self._title_system = None      # (formulas, variables) the pending title belongs to
        self._run_t0 = 0.0
        self._closing = False
        self.last_status = ""

        from pyvistaqt import QtInteractor

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
        self.result_label = QLabel("no result yet")
        self.result_label.setWordWrap(True)
        self.result_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.result_label.setStyleSheet("font-weight: bold;")
        self.pick_label = QLabel("")
        self.pick_label.setWordWrap(True)
        self.pick_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.pick_label.setStyleSheet("font-family: monospace; font-size: 11px;")
        self.pick_label.setVisible(False)
        self.picked: dict | None = None
        self._anim_t = 0.0
        self._anim_a0 = None

        side = QWidget()
        sl = QVBoxLayout(side)
        sl.setContentsMargins(6, 6, 6, 6)
        sl.addWidget(self.tabs, 1)
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
        self.plotter = QtInteractor(self, auto_update=False)
        self.scene = Scene(self.plotter)

        split = QSplitter(Qt.Horizontal)
        split.addWidget(side)
        split.addWidget(self.plotter.interactor)
        split.setStretchFactor(0, 0)
        split.setStretchFactor(1, 1)
        split.setSizes([440, 960])
        self.setCentralWidget(split)

        self._make_menus()
        self.statusBar()   # shows the menus' status tips (example descriptions)
        self._timer = QTimer(self)
        self._timer.setInterval(100)
        self._timer.timeout.connect(self._tick)

        self.run_button.clicked.connect(self.run)
        self.cancel_button.clicked.connect(self.cancel)
        self.formula_panel.validityChanged.connect(self._update_buttons)
        self.projection_panel.projectionChanged.connect(self._on_projection)  # points in place
        self.projection_panel.baseChanged.connect(self._on_base)
        self.projection_panel.styleChanged.connect(self._on_style)
        self.projection_panel.sliceChanged.connect(self._on_slice)
        self.animation_panel.tick.connect(self._on_anim_tick)
        self.animation_panel.playingChanged.connect(self._on_anim_playing)
        self.animation_panel.modeChanged.connect(lambda *_: self._on_anim_playing(self.animation_panel.is_playing()))
        self.animation_panel.exportRequested.connect(self._export_animation_dialog)
        if self.topology_panel is not None:
            self._connect_topology_panel()
        try:   # double-click a cell: its coordinates in R^n and its grid cube
            self.plotter.track_click_position(self._on_click, side="left", double=True, viewport=True)
        except Exception:  # noqa: BLE001 - picking is a convenience
            pass
        self._update_buttons()
        self.set_status("Choose an example or type a system, then Run (Ctrl+R).")

        if example:
            QTimer.singleShot(0, lambda: self.load_example(example, div=div, method=method))

    # ------------------------------------------------------------------ menus
    def _make_menus(self) -> None:
        mb = self.menuBar()
        fm = mb.addMenu("&File")

        def act(menu, text, slot, shortcut=None, tip=""):
            a = QAction(text, self)
            if shortcut:
                if isinstance(shortcut, (list, tuple)):
                    a.setShortcuts([QKeySequence(s) for s in shortcut])
                else:
                    a.setShortcut(QKeySequence(shortcut))
            a.setStatusTip(tip)
            a.triggered.connect(slot)
            menu.addAction(a)
            return a

        self.open_action = act(fm, "&Open session\u2026", self._open_dialog, "Ctrl+O", "open a saved session (.json)")
        self.save_action = act(fm, "&Save session\u2026", self._save_dialog, "Ctrl+S", "save the session as JSON")
        fm.addSeparator()
        act(fm, "Export &complex\u2026", self._export_complex_dialog, None, "the cell complex as .npz or .vtu")
        act(fm, "Export projected &mesh\u2026", self._export_mesh_dialog, None, "the current 3D projection as .ply, .obj or .vtp")
        self.screenshot_action = act(fm, "Screens&hot\u2026", self._screenshot_dialog,
                                     ["Ctrl+Shift+S", "F12"], "save a PNG picture of the view")
        fm.addSeparator()
        act(fm, "&Quit", self.close, "Ctrl+Q")

        rm = mb.addMenu("&Run")
        self.run_action = act(rm, "&Run", self.run, "Ctrl+R", "extract the manifold")
        self.cancel_action = act(rm, "&Cancel", self.cancel, "Esc", "stop the running extraction")

        vm = mb.addMenu("&View")
        act(vm, "Reset &rotations", self.projection_panel.reset, None, "all rotation angles to 0")
        act(vm, "Reset &camera", self.reset_camera, None, "fit the view")

        vm.addSeparator()
        self.play_action = act(vm, "&Play / pause animation", self._toggle_play, "Space",
                               "start or pause the animation chosen in the Animate tab")

        self.examples_menu = mb.addMenu("&Examples")
        self.example_actions = {}
        self.gallery_action = None
        if QtGallery is not None:
            self.gallery_action = act(self.examples_menu, "&Gallery\u2026", self.open_gallery, "Ctrl+G",
                                      "pictures of all examples: choose one to open")
            self.examples_menu.addSeparator()
        try:
            from gcmh_core.examples import list_examples
            examples = list_examples()
        except Exception as e:  # noqa: BLE001 - a broken examples folder must not stop the app
            examples = []
            a = QAction(f"(examples unavailable: {e})", self)
            a.setEnabled(False)
            self.examples_menu.addAction(a)
        for ex in examples:
            a = QAction(ex.title, self)
            desc = " ".join(str(ex.description).split())
            a.setToolTip(desc)
            a.setStatusTip(desc)
            a.triggered.connect(lambda _=False, name=ex.name: self.load_example(name))
            self.examples_menu.addAction(a)
            self.example_actions[ex.name] = a
        self.examples_menu.setToolTipsVisible(True)

    # ------------------------------------------------------------------ status
    def set_status(self, text: str, error: bool = False) -> None:
        """The message line under the result (errors in red)."""
        self.last_status = text
        self.status_label.setStyleSheet("color: #c22;" if error else "")
        self.status_label.setText(text)

    def _update_buttons(self, *_):
        running = self.worker is not None
        ok = self.formula_panel.is_valid() and not running
        self.run_button.setEnabled(ok)
        self.run_action.setEnabled(ok)
        self.cancel_button.setEnabled(running)
        self.cancel_action.setEnabled(running)
        if not self.formula_panel.is_valid() and not running:
            first = next(iter(self.formula_panel.errors.items()), None)
            self.run_button.setToolTip(f"fix first: {first[1]}" if first else "")
        else:
            self.run_button.setToolTip("extract the manifold (Ctrl+R)")

    # ------------------------------------------------------------------ examples
    def load_example(self, name: str, run: bool = True, div=None, method: str = "gcmh") -> bool:
        """Fill the panel from an example, run it, and show its suggested view."""
        from gcmh_core.examples import load_example

        try:
            ex = load_example(name)
        except Exception as e:  # noqa: BLE001
            self.set_status(str(e), error=True)
            return False
        self.formula_panel.set_state(dict(
            n=ex.n, k=ex.k, variables=list(ex.variables), formulas=list(ex.formulas),
            bounds=[list(b) for b in ex.bounds], div=div if div is not None else ex.div,
            method=method, seed=0, start=list(ex.start) if ex.start else None))
        self._pending_view = dict(ex.view or {})
        self._pending_title = ex.title
        self._title_system = ([f.strip() for f in ex.formulas], list(ex.variables))
        self.setWindowTitle(f"GCMH Studio \u2014 {ex.title}")
        self.set_status(" ".join(str(ex.description).split()))
        if run:
            return self.run()
        return True

    # ------------------------------------------------------------------ runs
    def confirm_big_run(self, est: dict, avail: int):
        """Ask before a run that would clearly exhaust memory (tests may replace this).

        Returns "run" (go ahead), "gcch" (switch to continuation and run) or None (don't run).
        """
        gcch = "gcch" in self.formula_panel.methods
        msg = (f"This run needs about {inputs.human_bytes(est.get('bytes', 0))} of memory "
               f"({est.get('cubes', 0):,} cubes), but only {inputs.human_bytes(avail)} is available.\n\n"
               "Choose a smaller div"
               + (", or use continuation (GCCH), which only visits the cubes the manifold passes through."
                  if gcch else ".")
               + "\n\nRun anyway?")
        box = QMessageBox(QMessageBox.Warning, "A very large run", msg, QMessageBox.NoButton, self)
        run_b = box.addButton("Run anyway", QMessageBox.DestructiveRole)
        gcch_b = box.addButton("Use continuation", QMessageBox.AcceptRole) if gcch else None
        box.addButton(QMessageBox.Cancel)
        box.exec_()
        clicked = box.clickedButton()
        if clicked is run_b:
            return "run"
        if gcch_b is not None and clicked is gcch_b:
            return "gcch"
        return None

    def run(self) -> bool:
        """Start an extraction with the panel's contents; False if refused."""
        if self.worker is not None:
            self.set_status("A run is already in progress: cancel it first (Esc).", error=True)
            return False
        if not self.formula_panel.is_valid():
            errs = self.formula_panel.errors
            self.set_status("Cannot run: " + "; ".join(f"{k}: {v}" for k, v in errs.items()), error=True)
            return False
        est = self.formula_panel.estimate()
        avail = inputs.available_memory()
        if not self.formula_panel.continuation() and est and avail and est.get("bytes", 0) > 0.8 * avail:
            answer = self.confirm_big_run(est, avail)
            if answer == "gcch":
                self.formula_panel.set_method("gcch")
            elif answer != "run":
                self.set_status("Run not started: choose a smaller div, or continuation (GCCH).", error=True)
                return False
        job = self.formula_panel.job()
        w = ExtractWorker(job, self)
        w.progress.connect(self._on_progress)
        w.done.connect(self._on_done)
        w.failed.connect(self._on_failed)
        w.cancelled.connect(self._on_cancelled)
        w.finished.connect(lambda w=w: self._on_thread_finished(w))
        self.worker = w
        self._job = job
        self._run_t0 = time.perf_counter()
        self.progress.setValue(0)
        self.progress.setFormat("starting\u2026")
        self._update_buttons()
        self._timer.start()
        w.start()
        return True

    def cancel(self) -> None:
        if self.worker is not None:
            self.worker.cancel()
            self.progress.setFormat("cancelling\u2026")

    def is_running(self) -> bool:
        return self.worker is not None

    def _tick(self) -> None:
        if self.worker is None:
            return
        el = time.perf_counter() - self._run_t0
        fmt = self.progress.format()
        phase = fmt.split(" \u00b7 ")[0] if fmt else "running"
        self.progress.setFormat(f"{phase} \u00b7 {el:.1f} s")

    def _on_progress(self, phase: str, fraction: float, seconds: float) -> None:
        if self.sender() is not self.worker:
            return
        self.progress.setValue(int(round(1000 * max(0.0, min(1.0, fraction)))))
        self.progress.setFormat(f"{phase} {100 * fraction:.0f}% \u00b7 {seconds:.1f} s")

    def _finish(self) -> None:
        self._timer.stop()
        w = self.worker
        self.worker = None
        if w is not None:
            self._old_workers.append(w)
        self._update_buttons()

    def _on_done(self, cx, geometry=None) -> None:
        if self.sender() is not self.worker:
            return
        job = self._job
        self._finish()
        self.progress.setValue(1000)
        self.progress.setFormat(f"done \u00b7 {time.perf_counter() - self._run_t0:.1f} s")
        same_system = self._title_system is not None and self._title_system == (job.formulas, job.variables)
        title = self._pending_title if same_system else ""
        report = getattr(self.sender(), "report", None)
        try:
            self.show_result(cx, job.variables, view=self._pending_view, title=title, geometry=geometry,
                             report=report)
        except Exception as e:  # noqa: BLE001 - a drawing problem must not take the window down
            self.set_status(f"Could not draw the result: {type(e).__name__}: {e}", error=True)
            self.runFinished.emit("failed")
            return
        finally:
            self._pending_view = None
        self.result_label.setText(summarize(cx))
        if cx.count(0) == 0:
            self.set_status("The result is empty: F has no sign change on this grid. Widen the domain, "
                            "raise div, or check the formulas.", error=True)
        else:
            self.set_status("")
        self.runFinished.emit("done")

    def _on_failed(self, message: str) -> None:
        if self.sender() is not self.worker:
            return
        self._finish()
        self.progress.setValue(0)
        self.progress.setFormat("failed")
        self.set_status(f"Error: {message}", error=True)
        self.runFinished.emit("failed")

    def _on_cancelled(self) -> None:
        if self.sender() is not self.worker:
            return
        el = time.perf_counter() - self._run_t0
        self._finish()
        self.progress.setValue(0)
        self.progress.setFormat("cancelled")
        keep = " The previous result stays on screen." if self.result is not None else ""
        self.set_status(f"Cancelled after {el:.1f} s.{keep}")
        self.runFinished.emit("cancelled")

    def _on_thread_finished(self, w) -> None:
        if w in self._old_workers:
            self._old_workers.remove(w)
        w.deleteLater()

    # ------------------------------------------------------------------ view
    def show_result(self, cx, names, view: dict | None = None, title: str = "", geometry=None,
                    report: dict | None = None) -> None:
        """Put a CellComplex on screen (GUI thread). ``report``: its topology report if already made."""
        names = list(names)
        prev_dim = self.result.dim if self.result is not None else None
        prev_names = self.result_names
        self.result = cx
        self.result_serial += 1
        self.result_names = names
        self.result_title = title
        pp = self.projection_panel
        pp.set_variables(names, keep=(names == prev_names))
        pp.model.set_vertices(cx.vertices)
        self.animation_panel.set_variables(names)
        if names != prev_names:
            self.animation_panel.set_plane(self._telling_plane())
        if prev_dim is None or (prev_dim <= 2) != (cx.dim <= 2):
            pp.set_style_defaults(cx.dim)
        if view:
            pp.apply_view(view)
        self.scene.set_complex(cx, names, pp.model.view(), self._style(), geometry=geometry)
        self._clear_pick()
        self._apply_overlays(self.scene)
        self._apply_slice(render=False)
        self.reset_camera()
        if self.topology_panel is not None:
            self._topology_set_result(cx, report)
        self.resultChanged.emit(cx)

    def _style(self) -> Style:
        pp = self.projection_panel
        two = pp.two_sided_check.isChecked()
        sub = describe(self.result, self.result_names, None if two else pp.color_by()) if self.result is not None else ""
        if two and self.result is not None:
            sub += " \u00b7 two sides: gold front, blue back"
        mapping = pp.model.mapping if pp.model.n >= 4 else "orthographic"
        if mapping != "orthographic":
            sub += f" \u00b7 {mapping}"
        return Style(color_by=pp.color_by(), opacity=pp.opacity(), show_edges=pp.show_edges(),
                     title=self.result_title, subtitle=sub, two_sided=pp.two_sided_check.isChecked())

    def _on_projection(self) -> None:
        if self.scene.complex is None:
            return
        pp = self.projection_panel
        self.scene.set_projection(pp.model.view(), render=False)
        sw = pp.slice_window()
        if sw is not None and sw.hidden:    # the hidden directions turn with the view
            self._apply_slice(render=False)
        if self.scene.style.subtitle != self._style().subtitle:
            self.scene.set_style(self._style(), render=False)
        self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.render()

    def _on_base(self) -> None:
        if self.scene.complex is None:
            return
        self._on_projection()
        self.reset_camera()

    def _on_style(self) -> None:
        if self.scene.complex is None:
            return
        st = self._style()
        old = self.scene.style
        if (st.color_by, st.title, st.subtitle, st.two_sided) == (old.color_by, old.title, old.subtitle,
                                                                    old.two_sided):
            self.scene.style = st
            self.scene.set_opacity(st.opacity, render=False)
            self.scene.set_show_edges(st.show_edges, render=False)
        else:
            self.scene.set_style(st, render=False)
        self._apply_overlays(self.scene)
        self.plotter.render()

    # ------------------------------------------------------------------ slicing
    def _slice_params(self, model=None):
        """(direction, lo, hi, c, w) of the panel's slice for the current result, or None."""
        pp = self.projection_panel
        sw = pp.slice_window()
        if sw is None or self.result is None:
            return None
        model = model or pp.model
        u = sw.direction(model.frame())
        lo, hi = window_range(self.result.vertices, u)
        cf, wf = pp.slice_fractions()
        span = max(hi - lo, 1e-12)
        return sw, u, lo, hi, lo + cf * span, wf * span

    def _apply_slice(self, render: bool = True) -> None:
        pp = self.projection_panel
        prm = self._slice_params()
        if prm is None:
            if self.scene.slice is not None:
                self.scene.set_slice(None, render=False)
            pp.set_slice_readout("")
        else:
            sw, u, lo, hi, c, w = prm
            k = self.scene.set_slice(u, c, w, render=False)
            what = sw.label(self.result_names)
            pp.set_slice_readout(f"{what} in [{c - w:.3g}, {c + w:.3g}] of [{lo:.3g}, {hi:.3g}] \u00b7 "
                                 f"{k:,} cells" + ("" if k else " (nothing here)"))
        if render:
            self.plotter.render()

    def _on_slice(self) -> None:
        if self.scene.complex is None:
            return
        self._apply_slice()

    # ------------------------------------------------------------------ overlays
    def _apply_overlays(self, scene) -> None:
        """Boundary facets and grid cubes as line overlays on ``scene``, as the View tab asks."""
        pp = self.projection_panel
        cx = self.result
        if cx is None or scene.complex is None:
            return
        if pp.boundary_check.isChecked():
            X, E = boundary_lines(cx)
            scene.set_overlay("boundary", X, E, BOUNDARY_COLOR, width=4.0, render=False)
        else:
            scene.remove_overlay("boundary", render=False)
        if pp.grid_check.isChecked():
            try:
                X, E = grid_cube_lines(cx)
            except ValueError as e:
                self.set_status(f"Grid cubes: {e}", error=True)
                scene.remove_overlay("grid", render=False)
            else:
                scene.set_overlay("grid", X, E, GRID_COLOR, width=1.0, opacity=0.18, render=False)
        else:
            scene.remove_overlay("grid", render=False)
        if self.picked is not None:
            X, E = self.picked["lines"]
            scene.set_overlay("pick", X, E, PICK_COLOR, width=5.0, render=False)

    # ------------------------------------------------------------------ picking
    def pick_cell(self, cell_id: int) -> dict:
        """Select cell ``cell_id`` (a 2-cell, or an edge of a curve): show and return its facts.

        Returns dict(cell, vertices (ids), coords (m, n), cube (n,) grid index or None).
        """
        cx = self.result
        if cx is None:
            raise ValueError("nothing to pick: no result yet")
        info = cell_info(cx, int(cell_id))
        self.picked = info
        names = self.result_names
        rows = [f"{'':>6}" + "".join(f"{nm:>10}" for nm in names)]
        for v, x in zip(info["vertices"][:12], info["coords"][:12]):
            rows.append(f"{v:>6}" + "".join(f"{t:>10.4f}" for t in x))
        if len(info["vertices"]) > 12:
            rows.append(f"\u2026 {len(info['vertices']) - 12} more vertices")
        what = "edge" if cx.dim == 1 else "2-cell"
        cube = "" if info["cube"] is None else f" \u00b7 grid cube {tuple(int(i) for i in info['cube'])}"
        self.pick_label.setText(f"{what} {info['cell']} ({len(info['vertices'])} vertices){cube}\n"
                                + "\n".join(rows))
        self.pick_label.setVisible(True)
        X, E = info["lines"]
        self.scene.set_overlay("pick", X, E, PICK_COLOR, width=5.0, render=False)
        self.plotter.render()
        return info

    def _clear_pick(self) -> None:
        self.picked = None
        self.pick_label.setVisible(False)
        self.scene.remove_overlay("pick", render=False)

    def pick_at(self, display_xy):
        """Pick the cell drawn at pixel (x, y) (from the bottom left); None if nothing is there."""
        cid = self.scene.cell_at(display_xy)
        if cid is None:
            self._clear_pick()
            self.plotter.render()
            return None
        return self.pick_cell(cid)

    def _on_click(self, pos) -> None:
        try:
            self.pick_at(pos[:2])
        except Exception as e:  # noqa: BLE001 - a failed pick is a message, never a crash
            self.set_status(f"Picking failed: {e}", error=True)

    # ------------------------------------------------------------------ animation
    def _toggle_play(self) -> None:
        self.animation_panel.set_playing(not self.animation_panel.is_playing())

    def _on_anim_playing(self, on: bool) -> None:
        # a tour starts from the view on screen; a sweep from the slider's place
        self._anim_t = 0.0
        self._anim_a0 = self.projection_panel.model.angles.copy()
        ap = self.animation_panel
        plane = ap.plane()
        still = (on and ap.mode() == "rotate" and plane is not None and self.projection_panel.model.mapping ==
                 "orthographic" and np.allclose(self.projection_panel.model.matrix()[:, list(plane)], 0.0))
        if on and ap.mode() == "slice" and self.projection_panel.slice_window() is None:
            ap.show_message("Turn the slice on in the View tab first.")
            ap.set_playing(False)
        elif on and self.result is None:
            ap.show_message("Nothing to animate yet: run first.")
            ap.set_playing(False)
        elif on:
            ap.show_message("Both axes of this plane are hidden: turning it moves nothing on screen. "
                            "Pick a plane with a shown axis." if still else "")
            if ap.mode() == "slice":   # start the sweep where the slider is
                c0 = self.projection_panel.slice_fractions()[0]
                self._anim_t = np.arccos(np.clip(1 - 2 * c0, -1, 1)) / (2 * np.pi)

    def _on_anim_tick(self, dt: float) -> None:
        """Advance the playing animation by ``dt`` seconds (times the speed), in place."""
        if self.result is None:
            return
        ap, pp = self.animation_panel, self.projection_panel
        mode = ap.mode()
        if mode == "rotate":
            plane = ap.plane()
            if plane is None:
                return
            angles = pp.model.angles.copy()
            row = pp.model.planes.index(tuple(plane))
            angles[row] = (angles[row] + 360.0 * dt / ROTATE_PERIOD + 180.0) % 360.0 - 180.0
            pp.set_angles(angles)
        elif mode == "tour":
            self._anim_t += dt / TOUR_PERIOD
            pp.set_angles(tour_angles(self._anim_a0, self._anim_t))
        else:
            self._anim_t += dt / SLICE_PERIOD
            pp.set_slice_center(0.5 * (1 - np.cos(2 * np.pi * self._anim_t)))

    def _telling_plane(self) -> tuple[int, int]:
        """A plane whose rotation changes the picture: the last shown axis with the first hidden one."""
        P = self.projection_panel.model.matrix()
        n = P.shape[1]
        shown = [i for i in range(n) if np.any(np.abs(P[:, i]) > 1e-9)]
        hidden = [i for i in range(n) if i not in shown]
        if not shown or not hidden:
            return (0, 1) if n >= 2 else (0, 0)
        a, b = shown[-1], hidden[0]
        return (min(a, b), max(a, b))

    def animation_frames(self, n_frames: int, model=None):
        """Frames of the animation chosen in the Animate tab (from the current view) and the slice to use."""
        ap = self.animation_panel
        model = model or self.projection_panel.model
        mode = ap.mode()
        prm = self._slice_params(model)
        window = None
        if prm is not None:
            sw, u, lo, hi, c, w = prm
            window = sw
            window.c, window.w = c, w
        if mode == "rotate":
            spec = Spec("rotate", plane=tuple(ap.plane()))
            rng = (0.0, 1.0)
        elif mode == "tour":
            spec, rng = Spec("tour"), (0.0, 1.0)
        else:
            if prm is None:
                raise ValueError("a slice sweep needs the slice turned on in the View tab")
            spec, rng = Spec("slice", var=0), (lo, hi)
        return frames_for(spec, model.angles.copy(), int(n_frames), slice_range=rng), window

    def export_animation(self, path, frames: int | None = None, fps: float | None = None, size=None,
                         show_progress: bool = True) -> int:
        """Render the Animate tab's animation off screen and write ``path`` (.gif or .mp4).

        The window's view is not changed. Returns the number of frames written
        (0 when cancelled: the file is removed).
        """
        import copy

        import pyvista as pv
        from qtpy.QtWidgets import QApplication, QProgressDialog

        from .projection import ProjectionModel

        if self.result is None or self.scene.complex is None:
            raise ValueError("nothing to animate yet: run first")
        ap = self.animation_panel
        n = int(frames or ap.frames_spin.value())
        fps = float(fps or ap.fps_spin.value())
        ap.set_playing(False)
        model = ProjectionModel.from_dict(self.projection_panel.model.n, self.projection_panel.model.to_dict())
        model._principal = self.projection_panel.model._principal
        seq, window = self.animation_frames(n, model)
        if size is None:
            size = (self.plotter.interactor.width(), self.plotter.interactor.height())
        w, h = (int(size[0]) // 2 * 2, int(size[1]) // 2 * 2)
        dlg = None
        if show_progress:
            dlg = QProgressDialog(f"Rendering {os.path.basename(str(path))}\u2026", "Cancel", 0, n, self)
            dlg.setWindowTitle("Export animation")
            dlg.setWindowModality(Qt.WindowModal)
            dlg.setMinimumDuration(0)
            dlg.setValue(0)

        def progress(k):
            if dlg is not None:
                dlg.setValue(k)
            QApplication.processEvents()

        pl = pv.Plotter(off_screen=True, window_size=[w, h])
        try:
            sc = Scene(pl)
            sc.set_complex(self.result, self.result_names, model.view(), copy.copy(self.scene.style),
                           geometry=self.scene.geometry)
            self._apply_overlays(sc)
            copy_camera(self.plotter.camera, pl.camera)
            written = write_animation(path, animation_images(sc, model, seq, window), fps=fps, progress=progress,
                                      cancel=(lambda: dlg.wasCanceled()) if dlg is not None else None)
        finally:
            pl.close()
            if dlg is not None:
                dlg.close()
        if written < n:
            self.set_status(f"Export cancelled after {written} of {n} frames; nothing written.")
            return 0
        self.set_status(f"Animation saved to {path} ({n} frames, {w}\u00d7{h}, {ap.spec_text()})")
        return written

    def _export_animation_dialog(self, fmt: str) -> None:
        ext = "." + fmt
        p = self._ask_save_path("Export animation", f"{fmt.upper()} (*{ext})", ext)
        if p:
            self._guard("Export", self.export_animation, p)

    # ------------------------------------------------------------------ analysis tools
    def _connect_topology_panel(self) -> None:
        """The topology panel's view switches and the View tab's are the same switches, kept in step."""
        tp = self.topology_panel
        pp = self.projection_panel
        tp.refineRequested.connect(self.refine_result)
        for theirs, mine in ((tp.boundary_check, pp.boundary_check), (tp.path_check, pp.grid_check),
                             (tp.two_sided_check, pp.two_sided_check)):
            theirs.toggled.connect(mine.setChecked)    # setChecked with the same value emits nothing: no loop
            mine.toggled.connect(theirs.setChecked)

    def _topology_set_result(self, cx, report=None) -> None:
        try:
            if report is not None:
                self.topology_panel.set_report(report)
                return
            from .worker import topology_of

            report = topology_of(cx, getattr(self, "_job", None))
            if report is None:
                self.topology_panel.clear()
            else:
                self.topology_panel.set_report(report)
        except Exception as e:  # noqa: BLE001
            self.set_status(f"Topology report failed: {e}", error=True)

    def refine_result(self) -> bool:
        """Start moving the vertices closer to M (Gauss-Newton) in a worker thread; the
        refined complex replaces the result when it is done (`refineFinished`).  False if
        there is nothing to refine or a refinement already runs."""
        if self.result is None or getattr(self, "_job", None) is None:
            self.set_status("Nothing to refine yet: run first.", error=True)
            return False
        if self.refiner is not None:
            self.set_status("A refinement is already running.", error=True)
            return False
        w = RefineWorker(self.result, self._job, self)
        base = self.result_serial
        w.done.connect(lambda cx, geometry, report, before, after, base=base:
                       self._on_refined(base, cx, geometry, report, before, after))
        w.failed.connect(self._on_refine_failed)
        w.finished.connect(lambda w=w: self._on_thread_finished(w))
        self.refiner = w
        self._old_workers.append(w)  # (waited for on close)
        if self.topology_panel is not None:
            self.topology_panel.set_refine_enabled(False)
        self.set_status("Refining the vertices onto M\u2026")
        w.start()
        return True

    def _refine_ended(self) -> None:
        self.refiner = None
        if self.topology_panel is not None:
            self.topology_panel.set_refine_enabled(True)

    def _on_refined(self, base, cx, geometry, report, before: float, after: float) -> None:
        self._refine_ended()
        if self._closing:
            return
        if self.result_serial != base:  # a run (or a file) put another result on screen meanwhile
            self.set_status("Refinement dropped: the result changed while it ran.")
            self.refineFinished.emit("dropped")
            return
        try:
            self.show_result(cx, self.result_names, title=self.result_title, geometry=geometry, report=report)
        except Exception as e:  # noqa: BLE001 - a drawing problem must not take the window down
            self.set_status(f"Could not draw the refined result: {type(e).__name__}: {e}", error=True)
            self.refineFinished.emit("failed")
            return
        self.result_label.setText(summarize(cx))
        if self.topology_panel is not None:
            self.topology_panel.show_refinement(before, after)
        self.set_status(f"Refined: max |F| at the vertices {before:.3g} \u2192 {after:.3g}")
        self.last_refinement = dict(before=before, after=after)
        self.refineFinished.emit("done")

    def _on_refine_failed(self, message: str) -> None:
        self._refine_ended()
        if not self._closing:
            self.set_status(f"Refining failed: {message}", error=True)
            self.refineFinished.emit("failed")

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

    def reset_camera(self) -> None:
        default_camera(self.plotter)
        self.plotter.render()

    def screenshot_array(self) -> np.ndarray:
        """The current view as an (h, w, 3) uint8 array."""
        self.plotter.render()
        return self.plotter.screenshot(return_img=True)

    # ------------------------------------------------------------------ files
    def session(self) -> dict:
        cam = self.plotter.camera
        return {
            "format": SESSION_FORMAT,
            "title": self.result_title,
            "system": self.formula_panel.state(),
            "view": self.projection_panel.state(),
            "camera": {"position": list(cam.position), "focal_point": list(cam.focal_point),
                       "up": list(cam.up), "parallel_scale": float(cam.parallel_scale),
                       "view_angle": float(cam.view_angle)},
        }

    def save_session(self, path) -> None:
        path = Path(path)
        path.write_text(json.dumps(self.session(), indent=2) + "\n", encoding="utf-8")
        self.set_status(f"Session saved to {path}")

    def open_session(self, path, run: bool = True) -> bool:
        """Restore a session: fill the panel, run, then restore the view (projection, angles, colour)."""
        try:
            d = json.loads(Path(path).read_text(encoding="utf-8"))
            if not isinstance(d, dict) or d.get("format") != SESSION_FORMAT:
                raise ValueError(f"not a GCMH session file (format {SESSION_FORMAT!r} expected)")
            system = d["system"]
        except (OSError, ValueError, KeyError, TypeError) as e:
            self.set_status(f"Cannot open {path}: {e}", error=True)
            return False
        self.formula_panel.set_state(system)
        self._pending_title = d.get("title", "")
        self._title_system = (self.formula_panel.formulas(), self.formula_panel.variables())
        self._session_view = d.get("view") or {}
        self._session_camera = d.get("camera")
        self._pending_view = None
        if run and self.formula_panel.is_valid():
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
        self.projection_panel.set_state(self._session_view)
        cam = self._session_camera
        if cam:
            c = self.plotter.camera
            c.position = cam["position"]
            c.focal_point = cam["focal_point"]
            c.up = cam["up"]
            c.view_angle = cam.get("view_angle", c.view_angle)
            c.parallel_scale = cam.get("parallel_scale", c.parallel_scale)
            self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.render()

    def export_complex(self, path) -> None:
        if self.result is None:
            raise ValueError("nothing to export: no result yet")
        path = str(path)
        if path.lower().endswith(".vtu"):
            self.result.save_vtu(path)
        else:
            if not path.lower().endswith(".npz"):
                path += ".npz"
            self.result.save(path)
        self.set_status(f"Complex saved to {path}")

    def export_mesh(self, path) -> None:
        m = self.scene.projected_mesh()
        path = str(path)
        ext = os.path.splitext(path)[1].lower()
        if ext not in (".ply", ".obj", ".vtp", ".stl", ".vtk"):
            raise ValueError(f"unknown mesh format {ext!r}: use .ply, .obj or .vtp")
        if ext in (".ply", ".obj", ".stl"):
            m = m.triangulate() if self.result is not None and self.result.dim >= 2 else m
        m.save(path)
        self.set_status(f"Projected mesh saved to {path}")

    def save_screenshot(self, path, size=None, transparent: bool = False) -> np.ndarray:
        """Write a PNG of the current view at ``size`` (w, h) pixels, re-rendered off screen."""
        if size is None:
            size = (self.plotter.interactor.width(), self.plotter.interactor.height())
        img = render_image(self.scene, path, size=tuple(int(s) for s in size), transparent=transparent,
                           camera=self.plotter.camera)
        self.set_status(f"Screenshot saved to {path} ({size[0]}\u00d7{size[1]})")
        return img

    def _file_dialog(self, save: bool, title: str, filt: str):
        fn = QFileDialog.getSaveFileName if save else QFileDialog.getOpenFileName
        path, _ = fn(self, title, "", filt)
        return path or None

    def _guard(self, what, fn, *a, **kw):
        try:
            return fn(*a, **kw)
        except Exception as e:  # noqa: BLE001 - file errors go to the status line
            self.set_status(f"{what} failed: {e}", error=True)
            return None

    def _open_dialog(self):
        p = self._file_dialog(False, "Open session", "GCMH session (*.json);;All files (*)")
        if p:
            self.open_session(p)

    def _save_dialog(self):
        p = self._file_dialog(True, "Save session", "GCMH session (*.json)")
        if p:
            if not p.lower().endswith(".json"):
                p += ".json"
            self._guard("Saving the session", self.save_session, p)

    def _ask_save_path(self, title: str, filt: str, default_ext: str, need_result: bool = True):
        """A save path with ``default_ext`` added when the user typed none; None if refused or nothing to save."""
        if need_result and self.result is None:
            self.set_status("Nothing to export yet: run first.", error=True)
            return None
        p = self._file_dialog(True, title, filt)
        if p and not os.path.splitext(p)[1]:
            p += default_ext
        return p

    def _export_complex_dialog(self):
        p = self._ask_save_path("Export complex", "Cell complex (*.npz);;VTK unstructured grid (*.vtu)", ".npz")
        if p:
            self._guard("Export", self.export_complex, p)

    def _export_mesh_dialog(self):
        p = self._ask_save_path("Export projected mesh", "PLY (*.ply);;Wavefront OBJ (*.obj);;VTK polydata (*.vtp)",
                                ".ply")
        if p:
            self._guard("Export", self.export_mesh, p)

    def _screenshot_dialog(self):
        if self.result is None:
            self.set_status("Nothing to show yet: run first.", error=True)
            return
        d = QtScreenshotDialog((self.plotter.interactor.width(), self.plotter.interactor.height()), self)
        if d.exec_() != QDialog.Accepted:
            return
        p = self._file_dialog(True, "Save screenshot", "PNG image (*.png)")
        if p:
            if not p.lower().endswith(".png"):
                p += ".png"
            self._guard("Screenshot", self.save_screenshot, p, (d.w.value(), d.h.value()),
                        d.transparent.isChecked())

    # ------------------------------------------------------------------ closing
    def closeEvent(self, event) -> None:
        self._closing = True
        self._timer.stop()
        self.animation_panel.set_playing(False)
        for w in [self.worker] + list(self._old_workers):
            if w is not None:
                w.cancel()
                w.wait(5000)
        self.worker = None
        try:
            self.plotter.close()
        except Exception:  # noqa: BLE001
            pass
        super().closeEvent(event)
