"""Exports of the studio window that need the GUI: an animation rendered off screen under a progress dialog.

The files themselves are written by :mod:`gcmh_studio.studio_io` and :mod:`gcmh_studio.headless`; the
window (:class:`gcmh_studio.qt_main_window.QtMainWindow`) calls :func:`export_animation`.
"""

from __future__ import annotations

import copy
import os

from qtpy.QtCore import Qt


def with_progress(parent, title: str, text: str, steps: int, work, show: bool):
    """``work(progress, cancel)`` under a window-modal progress dialog of ``steps`` steps (or none)."""
    from qtpy.QtWidgets import QApplication, QProgressDialog

    dlg = None
    if show:
        dlg = QProgressDialog(text, "Cancel", 0, steps, parent)
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


def export_animation(window, path, frames: int | None = None, fps: float | None = None, size=None,
                     show_progress: bool = True) -> int:
    """Render the Animate tab's animation (the model's settings) off screen and write ``path`` (.gif or .mp4).

    The window's view is not changed. Returns the number of frames written (0 when cancelled: the file is
    removed). A parameter sweep extracts the last run's system at each frame's value
    (:func:`gcmh_studio.headless.export_param_sweep`).
    """
    from gcmh_core.errors import InputError

    from .projection import ProjectionModel

    model, viewer = window.model, window.viewer
    if model.result is None or viewer.scene.complex is None:
        raise ValueError("nothing to animate yet: run first")
    settings = model.animation
    n = int(frames or settings.frames)
    fps = float(fps or settings.fps)
    window.animation_panel.set_playing(False)
    projection = ProjectionModel.from_dict(model.projection.n, model.projection.to_dict())
    projection.share_principal(model.projection)
    w, h = (int(s) // 2 * 2 for s in (size or viewer.size()))
    name = os.path.basename(str(path))
    if settings.mode == "param":
        from .animation import parse_spec
        from .headless import export_param_sweep

        if model.job is None:   # (a complex opened from a file has no system to sweep)
            raise ValueError("a parameter sweep needs a run of a system with parameters: run first")
        names = model.names
        spec = parse_spec(settings.spec, names, params=list(settings.params))
        what, steps = ("Parameter sweep", f"Extracting and rendering {name}\u2026"), 2 * n

        def write(progress, cancel):   # progress by phase: the extractions, then the frames
            written, _ = export_param_sweep(
                [path], model.job, spec, n, names, projection, copy.copy(viewer.scene.style), (w, h), fps,
                mapping=projection.mapping, camera=viewer.plotter.camera, cancel=cancel,
                progress=lambda phase, k: progress(k if phase == "extract" else n + k))
            return written
    else:
        seq, window_ = window.controller.animation_frames(n, projection)
        what, steps = ("Animation", f"Rendering {name}\u2026"), n

        def write(progress, cancel):
            return viewer.write_animation(path, seq, window_, projection, (w, h), fps, progress=progress,
                                          cancel=cancel)
    try:
        written = with_progress(window, f"Export {what[0].lower()}", what[1], steps, write, show_progress)
    except InputError as e:   # (a sweep that won't fit, or an output that can't be written: said first)
        raise ValueError(str(e)) from None
    if written < n:
        model.set_status(f"Export cancelled after {written} of {n} frames; nothing written.")
        return 0
    model.set_status(f"{what[0]} saved to {path} ({n} frames, {w}\u00d7{h}, {settings.spec})")
    return written
