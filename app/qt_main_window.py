"""QtMainWindow: the GCMH Studio window, which lays out and wires the studio's parts.

Layout: a side panel (tabs "Manifold" = :class:`QtFormulaPanel`, "View" =
:class:`QtProjectionPanel` (projection, mapping, slice, style), "Animate" =
:class:`QtAnimationPanel` and, when the library has its analysis module,
"Topology" = ``QtTopologyPanel``; with :class:`gcmh_studio.qt_run_bar.QtRunBar`
(the example's description, Run / Cancel, a progress bar and a status line)
always visible below) and the 3D view (:class:`gcmh_studio.qt_viewer.QtViewer`) in
the centre. Double-click a cell to see its vertices' coordinates in R^n and its grid cube.

The parts: the state is a :class:`gcmh_studio.model.StudioModel` (no Qt), which every panel and the view
read, write and redraw from; what the buttons do (runs, parameter steps, examples, Undo / Redo, sessions,
refinement, live play) is a :class:`gcmh_studio.controller.StudioController` (no Qt), whose runner is a
:class:`gcmh_studio.qt_run_controller.QtRunController` (worker threads: the previous result stays on screen);
menus and file dialogs are :class:`gcmh_studio.qt_actions.StudioActions`; exports are written by
:mod:`gcmh_studio.studio_io` and :mod:`gcmh_studio.qt_exports`. The kernels compile (once per install) in the
background from the start (:func:`gcmh_studio.jobs.start_warm_up`). Only the GUI thread touches VTK.
"""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import Qt, QTimer, Signal
from qtpy.QtWidgets import QMainWindow, QSplitter, QTabWidget, QVBoxLayout, QWidget

from . import data_source, homology_surfaces, overlays, qt_exports, studio_io
from .controller import StudioController
from .jobs import continuation_methods, current_warm_up, engine_methods, start_warm_up
from .model import StudioModel
from .qt_actions import StudioActions, ask_big_run
from .qt_animation_panel import QtAnimationPanel
from .qt_data_panel import QtDataPanel
from .qt_file_opener import QtFileOpener
from .qt_formula_panel import QtFormulaPanel
from .qt_presentation import QtPresentation
from .qt_projection_panel import QtProjectionPanel
from .qt_run_bar import QtRunBar, QtWarmUpLabel
from .qt_run_controller import QtRunController
from .qt_viewer import QtViewer
from .qt_widgets import scrolled

try:   # written alongside this window; the window works without them
    from .qt_topology_panel import QtTopologyPanel
except ImportError:
    QtTopologyPanel = None
try:
    from .qt_gallery import QtGallery
except ImportError:
    QtGallery = None

DEFAULT_EXAMPLE = "klein-bottle-closed"   # chi 0, non-orientable: the glued one, and its story


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
        m = self.model = StudioModel()
        self.runs = QtRunController(self)
        self.controller = StudioController(m, self.runs, self)
        self.formula_panel = QtFormulaPanel(m)
        self.projection_panel = QtProjectionPanel(m)
        self.animation_panel = QtAnimationPanel(m)
        self.topology_panel = QtTopologyPanel(m) if QtTopologyPanel is not None else None
        self.tabs = QTabWidget()
        for w, name in ((self.formula_panel, "Manifold"), (self.projection_panel, "View"),
                        (self.animation_panel, "Animate"), (self.topology_panel, "Topology")):
            if w is not None:
                self.tabs.addTab(scrolled(w), name)
        side = QWidget()
        sl = QVBoxLayout(side)
        sl.setContentsMargins(6, 6, 6, 6)
        sl.addWidget(self.tabs, 1)
        b = self.bar = QtRunBar(m, self.runs.elapsed, sl, self)
        self.run_button, self.cancel_button, self.progress = b.run_button, b.cancel_button, b.progress
        self.status_label, self.result_label, self.pick_label = b.status_label, b.result_label, b.pick_label
        self.about_box, self.about_label = b.about_box, b.about_label
        side.setMinimumWidth(330)   # (the View tab fits 1024 // 3; the side a third of a 1024-pixel window)
        self.viewer = QtViewer(m, self)
        self.plotter, self.scene = self.viewer.plotter, self.viewer.scene
        split = QSplitter(Qt.Horizontal)
        split.addWidget(side)
        split.addWidget(self.viewer.widget)
        split.setStretchFactor(0, 0)
        split.setStretchFactor(1, 1)
        split.setSizes([360, 1040])
        self.setCentralWidget(split)

        self.data_panel = QtDataPanel(self)   # (a "Data" tab once a data file is opened)
        self.data_source: data_source.DataSource | None = None
        self.files = QtFileOpener(self)   # File -> Open, Open data... and drops
        self.setAcceptDrops(True)   # data files, saved results and sessions dropped on the window open
        self.menu_actions = StudioActions(self, with_gallery=QtGallery is not None)
        self.statusBar()   # shows the menus' status tips (example descriptions)
        self._wire()
        self._update_buttons()
        self.set_status("Choose an example or type a system, then Run (Ctrl+R).")
        self.warm_up = start_warm_up(engine_methods()) if warm_up else current_warm_up()
        self.kernel_label = QtWarmUpLabel(self.warm_up)   # (hidden by the menus' tips while they show)
        self.statusBar().addWidget(self.kernel_label, 1)
        self.presentation = QtPresentation(self)   # F11, the typeset formula, axes, next example
        if example:
            QTimer.singleShot(0, lambda: self.load_example(example, div=div, method=method))

    def _wire(self) -> None:
        m, c, r, bar = self.model, self.controller, self.runs, self.bar
        ap, fp = self.animation_panel, self.formula_panel
        m.events.checks.connect(self._update_buttons)
        m.events.history.connect(self.menu_actions.set_history)
        bar.run_button.clicked.connect(self.run)
        bar.cancel_button.clicked.connect(self.cancel)
        fp.stepRequested.connect(lambda coarse, name: c.parameter_step(coarse, moved=name))
        ap.tick.connect(c.tick)
        ap.playingChanged.connect(self._on_anim_playing)
        ap.modeChanged.connect(lambda *_: self._on_anim_playing(ap.is_playing()))
        ap.exportRequested.connect(self.menu_actions.export_animation_dialog)
        r.busyChanged.connect(bar.set_ticking)
        r.busyChanged.connect(self._update_buttons)
        for signal, slot in ((r.progress, c.on_progress), (r.done, self._on_done), (r.failed, c.on_failed),
                             (r.cancelled, c.on_cancelled), (r.declined, c.on_declined),
                             (r.estimated, c.on_estimated), (r.confirm, c.on_confirm), (r.refined, c.on_refined),
                             (r.refineFailed, c.on_refine_failed)):
            signal.connect(slot)
        c.events.finished.connect(lambda how: self.runFinished.emit(how))
        c.events.refined.connect(self._on_refined)
        c.events.progress.connect(bar.show_progress)
        c.events.described.connect(self.show_description)
        c.events.busy.connect(self._update_buttons)
        if self.topology_panel is not None:
            tp = self.topology_panel
            tp.refineRequested.connect(c.refine)
            c.events.refining.connect(lambda on: tp.set_refine_enabled(not on))
            # the homology box says what to draw (generators, the w1 loop, curvature); the scene draws it
            hb = tp.homology_box
            hb.overlays.connect(lambda specs: overlays.draw_homology(self.scene, specs))
            hb.surfaces.connect(lambda specs: homology_surfaces.draw_homology_surfaces(self.scene, specs))
            hb.curvature.connect(lambda values: overlays.colour_by_values(self.scene, self.model.result, values))
        try:   # double-click a cell: its coordinates in R^n and its grid cube
            self.plotter.track_click_position(self._on_click, side="left", double=True, viewport=True)
        except Exception:  # noqa: BLE001 - picking is a convenience
            pass

    # ------------------------------------------------------------------ the state, as the tests read it
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

    def set_status(self, text: str, error: bool = False) -> None:
        """The message line under the result (errors in red)."""
        self.model.set_status(text, error)

    def guard(self, what: str, fn, *a, **kw):
        """Call ``fn``; an error becomes "<what> failed: ..." on the status line (and None is returned)."""
        try:
            return fn(*a, **kw)
        except Exception as e:  # noqa: BLE001 - file errors go to the status line
            self.set_status(f"{what} failed: {e}", error=True)
            return None

    def _update_buttons(self, *_) -> None:
        running = self.controller.is_running()
        ok = self.model.checks.valid and not running
        self.bar.set_running(running, self.model.checks.valid, self.model.checks.errors)
        self.menu_actions.set_running(running, ok)

    # ------------------------------------------------------------------ what the controller does
    def run(self) -> bool:
        return self.controller.run()

    def cancel(self) -> None:
        self.controller.cancel()

    def is_running(self) -> bool:
        return self.controller.is_running()

    def load_example(self, name: str, run: bool = True, div=None, method: str = "gcmh") -> bool:
        return self.controller.load_example(name, run=run, div=div, method=method)

    def _on_done(self, cx, geometry, report) -> None:
        self.controller.on_done(cx, geometry, report)

    def _on_refined(self, how: str) -> None:
        if how == "done" and self.topology_panel is not None:
            self.topology_panel.show_refinement(**self.model.last_refinement)
        self.refineFinished.emit(how)

    def confirm_big_run(self, est):
        """Ask before a run that won't fit (``est``: its gcmh_core.budget.Estimate; tests may replace this).
        Returns "run" (go ahead), "gcch" (switch to continuation and run) or None (don't run)."""
        job = self.model.job
        return ask_big_run(self, est, gcch="gcch" in engine_methods() and job is not None
                           and job.method not in continuation_methods())

    def show_description(self, title: str, text: str) -> None:
        """The example's title and description above Run (hidden for a system typed in)."""
        self.setWindowTitle(f"GCMH Studio \u2014 {title}" if title else "GCMH Studio")
        self.bar.show_description(title, text)

    def open_gallery(self):
        """Show the example gallery (window-modal, not blocking); choosing an example opens and runs it."""
        if QtGallery is None:
            return None
        g = self.gallery = QtGallery(self)
        g.exampleChosen.connect(lambda name: self.load_example(name))
        g.dataChosen.connect(self.files.open_entry)   # (a data source opened lately)
        g.setAttribute(Qt.WA_DeleteOnClose)
        g.open()
        return g

    # ------------------------------------------------------------------ the view (the controller's View)
    def show_result(self, cx, names, view: dict | None = None, title: str = "", geometry=None,
                    report: dict | None = None, keep_view: bool = False, labels: dict | None = None,
                    moving: bool = False) -> None:
        """Put a CellComplex on screen (:meth:`gcmh_studio.model.StudioModel.present`; ``keep_view``: the camera
        stays too). ``report``: its topology report if already made."""
        # (read only when a view can be kept: pyvista's first look at the camera resets it and renders)
        camera = studio_io.camera_state(self.plotter.camera) if keep_view and self.model.result is not None else None
        if self.model.present(cx, names, title, labels, view, keep_view) and camera is not None:
            self.viewer.show(geometry, moving=moving)
            studio_io.apply_camera(self.plotter.camera, camera)
            self.plotter.renderer.ResetCameraClippingRange()
        else:
            self.viewer.show(geometry, moving=moving)
        if self.topology_panel is not None:
            self._show_topology(cx, report)
        self.resultChanged.emit(cx)

    def _show_topology(self, cx, report=None) -> None:
        from .jobs import topology_of

        try:
            report = report if report is not None else topology_of(cx, self.model.job)
            (self.topology_panel.clear() if report is None else self.topology_panel.set_report(report))
        except Exception as e:  # noqa: BLE001
            self.set_status(f"Topology report failed: {e}", error=True)

    def restore_camera(self, camera, keep: bool) -> None:
        self.viewer.restore_camera(camera, keep)

    def camera(self) -> dict:
        return studio_io.camera_state(self.plotter.camera)

    def screenshot_array(self) -> np.ndarray:
        """The current view as an (h, w, 3) uint8 array."""
        return self.viewer.screenshot_array()

    def _on_click(self, pos) -> None:
        self.guard("Picking", self.viewer.pick_at, pos[:2])

    # ------------------------------------------------------------------ animation
    def _on_anim_playing(self, on: bool) -> None:
        ok, message = self.controller.play(on)
        if on:
            self.animation_panel.show_message(message)
            if not ok:
                self.animation_panel.set_playing(False)

    def export_animation(self, path, frames: int | None = None, fps: float | None = None, size=None,
                         show_progress: bool = True) -> int:
        """Render the Animate tab's animation off screen to ``path`` (:func:`qt_exports.export_animation`)."""
        return qt_exports.export_animation(self, path, frames, fps, size, show_progress)

    # ------------------------------------------------------------------ sessions and exports
    def session(self) -> dict:
        """What a session file keeps of the window (saved, and autosaved): the controller's state, and the data
        files by path with their levels when the result on screen is theirs (opened again from them)."""
        session = self.controller.session()
        if self.showing_data():
            session[data_source.SESSION_KEY] = self.data_source.session_entry()
        return session

    def save_session(self, path) -> None:
        path = studio_io.write_session(path, self.session())
        self.set_status(f"Session saved to {path}")

    def showing_data(self) -> bool:
        """Is the result on screen the data source's (not a formula's run or a saved result)?"""
        meta = getattr(self.result, "meta", None) or {}
        data = meta.get("data") if isinstance(meta.get("data"), dict) else {}
        return self.data_source is not None and data.get("files") == self.data_source.specs

    def export_complex(self, path) -> None:
        path = studio_io.export_complex(self.result, path)
        self.set_status(f"Complex saved to {path}")

    def export_mesh(self, path) -> None:
        dim = None if self.result is None else self.result.dim
        path = studio_io.export_mesh(self.scene.projected_mesh(), path, dim)
        cycles = overlays.export_cycles(self.scene, path)  # the generators on show, each cell with its cycle
        if cycles is not None:
            path += " and its cycles to " + cycles
        self.set_status(f"Projected mesh saved to {path}")

    def save_screenshot(self, path, size=None, transparent: bool = False) -> np.ndarray:
        """Write a PNG of the current view at ``size`` (w, h) pixels, re-rendered off screen."""
        size = size or self.viewer.size()
        img = self.viewer.save_screenshot(path, size, transparent)
        self.set_status(f"Screenshot saved to {path} ({size[0]}\u00d7{size[1]})")
        return img

    # ------------------------------------------------------------------ files: data, results, sessions
    def open_data(self, specs, levels=None) -> bool:
        return self.files.open_data(specs, levels)

    def open_result(self, path) -> bool:
        return self.files.open_result(path)

    def open_file(self, path) -> bool:
        return self.files.open_file(path)

    def dropped_files(self, mime) -> list[str]:
        return self.files.dropped_files(mime)

    def dragEnterEvent(self, event) -> None:
        self.files.drag_enter(event)

    def dropEvent(self, event) -> None:
        self.files.drop(event)

    def closeEvent(self, event) -> None:
        self.data_panel.stop()
        self.controller.closing = True
        self.kernel_label.stop()
        self.bar.set_ticking(False)
        self.animation_panel.set_playing(False)
        self.runs.shutdown()
        try:
            self.plotter.close()
        except Exception:  # noqa: BLE001
            pass
        super().closeEvent(event)
