"""The studio's menus, their actions and shortcuts, and the dialogs behind them.

:class:`StudioActions` fills a window's menu bar (File, Edit, Run, View, Examples)
and connects each action to the window's public methods; the File menu's
entries ask for a path here and hand it to the window, whose status line
reports what happened.
"""

from __future__ import annotations

import os

from qtpy.QtGui import QKeySequence
from qtpy.QtWidgets import (
    QAction,
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QMessageBox,
    QSpinBox,
)

from .inputs import human_bytes, human_seconds


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


def big_run_text(est, gcch: bool) -> str:
    """What the big-run question says about ``est`` (a gcmh_core.budget.Estimate that doesn't fit)."""
    if not est.fits_memory:
        what = (f"This run needs about {human_bytes(est.peak_bytes)} of memory "
                f"({est.cubes:,} cubes), but only {human_bytes(est.available_bytes)} is available.")
    else:
        what = (f"This run would take about {human_seconds(est.seconds)} ({est.cubes:,} cubes; "
                f"{human_bytes(est.peak_bytes)} of memory).")
    return (what + "\n\nChoose a smaller div"
            + (", or use continuation (GCCH), which only visits the cubes the manifold passes through."
               if gcch else ".")
            + "\n\nRun anyway?")


def ask_big_run(parent, est, gcch: bool):
    """Ask whether to start a run that won't fit (``est``: its gcmh_core.budget.Estimate).

    Returns "run" (go ahead), "gcch" (switch to continuation and run; offered when ``gcch``) or None.
    """
    msg = big_run_text(est, gcch)
    box = QMessageBox(QMessageBox.Warning, "A very large run", msg, QMessageBox.NoButton, parent)
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


class StudioActions:
    """The menus of ``window`` (a :class:`gcmh_studio.qt_main_window.QtMainWindow`) and their actions.

    Attributes: ``open``, ``save``, ``screenshot``, ``run``, ``cancel``, ``play``, ``gallery`` (None
    without the gallery) and ``examples`` (name -> action) among others.
    """

    def __init__(self, window, with_gallery: bool = True):
        self.window = window
        w = window
        mb = w.menuBar()
        fm = mb.addMenu("&File")
        self.open = self._add(fm, "&Open\u2026", self.open_dialog, "Ctrl+O",
                              "open a saved session (.json) or a saved result (.npz)")
        self.open_data = self._add(fm, "Open &data\u2026", self.open_data_dialog, "Ctrl+Shift+O",
                                   "volumes and time series from files: .npy, .npz, .vti, .vtk, .nrrd, .mha, .nii, "
                                   ".h5 (several files: one component of F each)")
        self.save = self._add(fm, "&Save session\u2026", self.save_dialog, "Ctrl+S", "save the session as JSON")
        fm.addSeparator()
        self.export_complex = self._add(fm, "Export &complex\u2026", self.export_complex_dialog, None,
                                        "the cell complex as .npz or .vtu")
        self.export_mesh = self._add(fm, "Export projected &mesh\u2026", self.export_mesh_dialog, None,
                                     "the current 3D projection as .ply, .obj or .vtp")
        self.screenshot = self._add(fm, "Screens&hot\u2026", self.screenshot_dialog, ["Ctrl+Shift+S", "F12"],
                                    "save a PNG picture of the view")
        fm.addSeparator()
        self.quit = self._add(fm, "&Quit", w.close, "Ctrl+Q")

        em = mb.addMenu("&Edit")
        self.undo = self._add(em, "&Undo", w.controller.undo, "Ctrl+Z", "back to the previous system or view")
        self.redo = self._add(em, "&Redo", w.controller.redo, ["Ctrl+Shift+Z", "Ctrl+Y"],
                              "forward again after an undo")
        self.set_history(False, False)

        rm = mb.addMenu("&Run")
        self.run = self._add(rm, "&Run", w.run, "Ctrl+R", "extract the manifold")
        self.cancel = self._add(rm, "&Cancel", w.cancel, "Esc", "stop the running extraction")

        vm = mb.addMenu("&View")
        self.reset_rotations = self._add(vm, "Reset &rotations", w.projection_panel.reset, None,
                                         "all rotation angles to 0")
        self.reset_camera = self._add(vm, "Reset &camera", w.viewer.reset_camera, None, "fit the view")
        vm.addSeparator()
        self.play = self._add(vm, "&Play / pause animation", w.animation_panel.toggle_play, "Space",
                              "start or pause the animation chosen in the Animate tab")

        self.examples_menu = mb.addMenu("&Examples")
        self.examples: dict[str, QAction] = {}
        self.gallery = None
        if with_gallery:
            self.gallery = self._add(self.examples_menu, "&Gallery\u2026", w.open_gallery, "Ctrl+G",
                                     "pictures of all examples: choose one to open")
            self.examples_menu.addSeparator()
        try:
            from gcmh_core.examples import list_examples
            examples = list_examples()
        except Exception as e:  # noqa: BLE001 - a broken examples folder must not stop the app
            examples = []
            a = QAction(f"(examples unavailable: {e})", w)
            a.setEnabled(False)
            self.examples_menu.addAction(a)
        for ex in examples:
            a = QAction(ex.title, w)
            desc = " ".join(str(ex.description).split())
            a.setToolTip(desc)
            a.setStatusTip(desc)
            a.triggered.connect(lambda _=False, name=ex.name: w.load_example(name))
            self.examples_menu.addAction(a)
            self.examples[ex.name] = a
        self.examples_menu.setToolTipsVisible(True)

    def _add(self, menu, text: str, slot, shortcut=None, tip: str = "") -> QAction:
        a = QAction(text, self.window)
        if shortcut:
            if isinstance(shortcut, (list, tuple)):
                a.setShortcuts([QKeySequence(s) for s in shortcut])
            else:
                a.setShortcut(QKeySequence(shortcut))
        a.setStatusTip(tip)
        a.triggered.connect(slot)
        menu.addAction(a)
        return a

    def set_history(self, can_undo: bool, can_redo: bool) -> None:
        self.undo.setEnabled(can_undo)
        self.redo.setEnabled(can_redo)

    def set_running(self, running: bool, can_run: bool) -> None:
        self.run.setEnabled(can_run)
        self.cancel.setEnabled(running)

    # ------------------------------------------------------------ dialogs
    def _file_dialog(self, save: bool, title: str, filt: str):
        fn = QFileDialog.getSaveFileName if save else QFileDialog.getOpenFileName
        path, _ = fn(self.window, title, "", filt)
        return path or None

    def _ask_save_path(self, title: str, filt: str, default_ext: str, need_result: bool = True):
        """A save path with ``default_ext`` added when the user typed none; None if refused or nothing to save."""
        if need_result and self.window.result is None:
            self.window.set_status("Nothing to export yet: run first.", error=True)
            return None
        p = self._file_dialog(True, title, filt)
        if p and not os.path.splitext(p)[1]:
            p += default_ext
        return p

    def open_dialog(self) -> None:
        p = self._file_dialog(False, "Open", "GCMH session or result (*.json *.npz);;GCMH session (*.json);;"
                                             "Cell complex (*.npz);;All files (*)")
        if p:
            self.window.open_file(p)

    def open_data_dialog(self) -> None:
        from gcmh_core.data_files import DATA_SUFFIXES

        patterns = " ".join(f"*{s}" for s in DATA_SUFFIXES)
        paths, _ = QFileDialog.getOpenFileNames(self.window, "Open data (several files: one component each)", "",
                                                f"Data ({patterns});;All files (*)")
        if paths:
            self.window.open_data(paths)

    def save_dialog(self) -> None:
        p = self._file_dialog(True, "Save session", "GCMH session (*.json)")
        if p:
            if not p.lower().endswith(".json"):
                p += ".json"
            self.window.guard("Saving the session", self.window.save_session, p)

    def export_complex_dialog(self) -> None:
        p = self._ask_save_path("Export complex", "Cell complex (*.npz);;VTK unstructured grid (*.vtu)", ".npz")
        if p:
            self.window.guard("Export", self.window.export_complex, p)

    def export_mesh_dialog(self) -> None:
        p = self._ask_save_path("Export projected mesh", "PLY (*.ply);;Wavefront OBJ (*.obj);;VTK polydata (*.vtp)",
                                ".ply")
        if p:
            self.window.guard("Export", self.window.export_mesh, p)

    def export_animation_dialog(self, fmt: str) -> None:
        ext = "." + fmt
        p = self._ask_save_path("Export animation", f"{fmt.upper()} (*{ext})", ext)
        if p:
            self.window.guard("Export", self.window.export_animation, p)

    def screenshot_dialog(self) -> None:
        w = self.window
        if w.result is None:
            w.set_status("Nothing to show yet: run first.", error=True)
            return
        d = QtScreenshotDialog((w.plotter.interactor.width(), w.plotter.interactor.height()), w)
        if d.exec_() != QDialog.Accepted:
            return
        p = self._file_dialog(True, "Save screenshot", "PNG image (*.png)")
        if p:
            if not p.lower().endswith(".png"):
                p += ".png"
            w.guard("Screenshot", w.save_screenshot, p, (d.w.value(), d.h.value()), d.transparent.isChecked())
