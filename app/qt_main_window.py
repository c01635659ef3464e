"""QtMainWindow: the GCMH Studio window.

Layout: a side panel (tabs "Manifold" = :class:`QtFormulaPanel` and "View" =
:class:`QtProjectionPanel`, with Run / Cancel, a progress bar and a status line
always visible below) and a ``pyvistaqt.QtInteractor`` in the centre, drawn by
an :class:`app.scene.Scene`.

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
from .qt_formula_panel import QtFormulaPanel
from .qt_projection_panel import QtProjectionPanel
from .scene import Scene, Style, default_camera, describe, render_image
from .worker import ExtractWorker

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

    def __init__(self, example: str | None = DEFAULT_EXAMPLE, parent=None, div=None, method: str = "gcmh"):
        super().__init__(parent)
        self.setWindowTitle("GCMH Studio")
        self.resize(1400, 900)
        self.result = None            # the CellComplex on screen
        self.result_names: list[str] = []
        self.result_title = ""
        self.worker: ExtractWorker | None = None
        self._old_workers: list[ExtractWorker] = []
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
        self.tabs = QTabWidget()
        for w, name in ((self.formula_panel, "Manifold"), (self.projection_panel, "View")):
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
        self.projection_panel.projectionChanged.connect(self._on_projection)
        self.projection_panel.baseChanged.connect(self._on_base)
        self.projection_panel.styleChanged.connect(self._on_style)
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

        self.examples_menu = mb.addMenu("&Examples")
        self.example_actions = {}
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
        if self.formula_panel.method() != "gcch" and est and avail and est.get("bytes", 0) > 0.8 * avail:
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
        try:
            self.show_result(cx, job.variables, view=self._pending_view, title=title, geometry=geometry)
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
    def show_result(self, cx, names, view: dict | None = None, title: str = "", geometry=None) -> None:
        """Put a CellComplex on screen (GUI thread)."""
        names = list(names)
        prev_dim = self.result.dim if self.result is not None else None
        prev_names = self.result_names
        self.result = cx
        self.result_names = names
        self.result_title = title
        pp = self.projection_panel
        pp.set_variables(names, keep=(names == prev_names))
        pp.model.set_vertices(cx.vertices)
        if prev_dim is None or (prev_dim <= 2) != (cx.dim <= 2):
            pp.set_style_defaults(cx.dim)
        if view:
            pp.apply_view(view)
        self.scene.set_complex(cx, names, pp.matrix(), self._style(), geometry=geometry)
        self.reset_camera()
        self.resultChanged.emit(cx)

    def _style(self) -> Style:
        pp = self.projection_panel
        sub = describe(self.result, self.result_names, pp.color_by()) if self.result is not None else ""
        return Style(color_by=pp.color_by(), opacity=pp.opacity(), show_edges=pp.show_edges(),
                     title=self.result_title, subtitle=sub)

    def _on_projection(self) -> None:
        if self.scene.mesh is None:
            return
        self.scene.set_projection(self.projection_panel.matrix())

    def _on_base(self) -> None:
        if self.scene.mesh is None:
            return
        self.scene.set_projection(self.projection_panel.matrix(), render=False)
        self.reset_camera()

    def _on_style(self) -> None:
        if self.scene.mesh is None:
            return
        st = self._style()
        old = self.scene.style
        if st.color_by == old.color_by and st.title == old.title and st.subtitle == old.subtitle:
            self.scene.style = st
            self.scene.set_opacity(st.opacity, render=False)
            self.scene.set_show_edges(st.show_edges, render=False)
            self.plotter.render()
        else:
            self.scene.set_style(st)

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

    def _export_complex_dialog(self):
        if self.result is None:
            self.set_status("Nothing to export yet: run first.", error=True)
            return
        p = self._file_dialog(True, "Export complex", "Cell complex (*.npz);;VTK unstructured grid (*.vtu)")
        if p:
            self._guard("Export", self.export_complex, p)

    def _export_mesh_dialog(self):
        if self.result is None:
            self.set_status("Nothing to export yet: run first.", error=True)
            return
        p = self._file_dialog(True, "Export projected mesh",
                              "PLY (*.ply);;Wavefront OBJ (*.obj);;VTK polydata (*.vtp)")
        if p:
            if not os.path.splitext(p)[1]:
                p += ".ply"
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
