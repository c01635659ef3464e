"""QtStillPicture: a see-through result's still picture, drawn in a worker process and shown over the 3D view.

A see-through result's still picture (0.3 s of software GL for the three-torus) is drawn by the worker
process of :mod:`gcmh_studio.still_process` from an off-screen copy (:class:`gcmh_studio.offscreen.StillJob`)
and shown over the view (a label) until the view renders again; the GUI looks for it every ``STILL_POLL_MS``
and never waits. When the worker fails (it died, hung, or failed too often) the window renders the picture
itself. A new result is drawn in short GUI steps of their own: the picture in the worker, or the window's
unshown render (:meth:`QtStillPicture.settle`) and then its own.
"""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import QEvent, QObject, Qt, QTimer
from qtpy.QtGui import QImage, QPixmap
from qtpy.QtWidgets import QLabel

from .camera import camera_values
from .offscreen import StillJob, draws_over
from .still_process import still_process

STILL_POLL_MS = 15       # how often the GUI looks whether the still picture drawn by the worker is there


class QtStillPicture:
    """The still picture of ``viewer`` (:class:`gcmh_studio.qt_viewer.QtViewer`)."""

    def __init__(self, viewer):
        self.viewer = viewer
        self.off_thread = True
        self.job: StillJob | None = None
        self.image: np.ndarray | None = None    # the last one shown
        self.settling = False
        self.fresh = False        # a new result the window has not drawn yet (its picture drawn by the worker)
        # what covers the view until the new result is on screen (the waiting picture): hiding a label over the
        # view repaints it, a render on the GUI thread, so it goes when the picture or the window's frame is there
        self.cover = None
        self.label = QLabel(viewer.widget)
        self.label.setAttribute(Qt.WA_TransparentForMouseEvents)   # the view under it gets the mouse
        self.label.hide()
        self.poll = QTimer(viewer.widget)
        self.poll.setInterval(STILL_POLL_MS)
        self.poll.timeout.connect(self._arrived)
        self._probe = None       # an off-screen plotter, never rendered (see _drawn_over)
        self.steps: list = []
        self.step = QTimer(viewer.widget)
        self.step.setSingleShot(True)
        self.step.setInterval(0)
        self.step.timeout.connect(self._next_step)
        viewer.plotter.ren_win.AddObserver("StartEvent", lambda *a: self._view_renders())
        # the worker's start-up (a second of imports) falls when the view is first shown, not on a result
        # (an unshown window, a session's screenshot, never starts it)
        self._shown = _ShowAndHide(self, viewer.widget)
        viewer.widget.installEventFilter(self._shown)

    def start(self) -> None:
        """A new result: its picture in steps of their own (one render asked)."""
        self.drop()
        self.fresh = self.in_worker()   # (the unshown render comes before the window's first)
        self.steps = [self.render] if self.fresh else [self.settle, self.render]
        self.step.start()

    def in_worker(self) -> bool:
        """Draw the still picture in the worker process: a see-through result (0.3 s of software GL for the
        three-torus) in a view on screen with nothing of the window's own drawn over it (the presentation's
        card), once the worker is ready (one starting, or started again after a failure, would keep a result
        off the screen for seconds: the window draws it meanwhile)."""
        v = self.viewer
        aa = v.scene.anti_aliasing   # (FXAA as asked: an EGL build falls back to super-sampling)
        if not (self.off_thread and v.scene.see_through() and v.widget.isVisible() and min(v.size()) > 0
                and (aa != "fxaa" or bool(v.plotter.renderer.GetUseFXAA()))):
            return False
        worker = still_process()
        worker.start()      # (none yet, or the last one failed: a new one, unless they failed too often)
        return worker.ready()

    def render(self) -> None:
        """The still look of the scene as it is, drawn by the worker, shown when it arrives (else the window
        renders it); the render was counted when it was asked for."""
        self.drop()
        if not self.in_worker():
            self._uncover()
            self.viewer.widget.update()
            return
        v = self.viewer
        try:   # (the presentation draws over the view: the window's own render)
            job = None if self._drawn_over() else StillJob(v.scene, v.plotter.ren_win.GetSize(),
                                                            camera_values(v.plotter.camera),
                                                            anti_aliasing=v.scene.anti_aliasing)
        except Exception:  # noqa: BLE001 - the window draws it itself
            job = None
        if job is None:
            self._uncover()
            self.viewer.widget.update()
            return
        self.job = job
        self.poll.start()

    def _drawn_over(self) -> bool:
        """The window draws something of its own over the view (:func:`gcmh_studio.offscreen.draws_over`, on
        an off-screen plotter kept for the question: making one costs 0.2 s; made again once drawn on, and
        closed when the view is hidden: a plotter that outlives the X server ends the process)."""
        v = self.viewer
        if not v.picture_decorators:
            return False
        if self._probe is None:
            import pyvista as pv

            self._probe = pv.Plotter(off_screen=True, window_size=[64, 48])
        drew = True
        try:
            drew = draws_over(v._decorate, self._probe)
        finally:
            if drew:
                self.close_probe()
        return drew

    def close_probe(self) -> None:
        if self._probe is not None:
            self._probe.close()
            self._probe = None

    def _next_step(self) -> None:
        if self.steps:
            self.steps.pop(0)()
        if self.steps:     # (started after the step: a timer due meanwhile, the GUI's, goes first)
            self.step.start()

    def _uncover(self) -> None:
        if self.cover is not None and self.cover.shown():
            self.cover.hide()

    def _view_renders(self) -> None:
        self.drop()
        if not self.settling:
            self._uncover()

    def drop(self) -> None:
        """The view renders itself (or changed): a still picture on its way or on screen is no longer it."""
        if self.settling:
            return
        self.steps = []
        self.step.stop()
        if self.job is not None:
            self.job.stale = True
            self.job = None
        if self.label.isVisible():
            self.label.hide()
            self.label.clear()

    def _arrived(self) -> None:
        job = self.job
        if job is None:
            self.poll.stop()
            return
        if not job.done():
            return
        self.poll.stop()
        self.job = None
        w, h = self.viewer.plotter.ren_win.GetSize()
        img = job.image
        if job.stale or img is None or img.shape[:2] != (h, w):   # failed, dropped, or the view changed size
            if not job.stale:
                self.viewer.render()
            return
        self.image = img
        qimg = QImage(img.data, w, h, 3 * w, QImage.Format_RGB888)
        pix = QPixmap.fromImage(qimg)    # (a copy: the array may go)
        pix.setDevicePixelRatio(w / max(self.viewer.widget.width(), 1))
        self.label.setGeometry(self.viewer.widget.rect())
        self.label.setPixmap(pix)
        self.label.show()
        self.label.raise_()
        self._uncover()

    def settle(self) -> None:
        """One cheap render of a new result, not shown, with the complex shrunk to a point: the colour bar lays
        its labels out from the frame before, and the window's first frame of a new result put them over the
        bar (the picture a result opened with, until the next render)."""
        self.fresh = False
        actor = self.viewer.scene.actor
        if actor is None or not self.viewer.widget.isVisible():
            return
        rw = self.viewer.plotter.ren_win
        ren = self.viewer.plotter.renderer
        fxaa = bool(ren.GetUseFXAA())
        self.settling = True
        try:
            actor.SetScale(1e-6, 1e-6, 1e-6)
            ren.SetUseFXAA(False)   # (nothing of it is seen)
            rw.SwapBuffersOff()     # (a frame not to be shown: the widget schedules no paint for it)
            rw.Render()
        except Exception:  # noqa: BLE001 - only the labels' first frame is at stake
            pass
        finally:
            rw.SwapBuffersOn()
            ren.SetUseFXAA(fxaa)
            actor.SetScale(1.0, 1.0, 1.0)
            self.settling = False

    def shown(self) -> bool:
        """The view shows a still picture drawn by the worker (tests and the benchmark ask)."""
        return self.label.isVisible()

    def pending(self) -> bool:
        """A new result's picture is on its way (its steps, or the worker)."""
        return bool(self.steps) or self.job is not None



class _ShowAndHide(QObject):
    """Starts the still picture's worker the first time the view is shown; closes the probe's plotter when
    the view is hidden (a closing window)."""

    def __init__(self, still: QtStillPicture, parent):
        super().__init__(parent)
        self.still = still
        self.started = False

    def eventFilter(self, obj, ev) -> bool:
        t = ev.type()
        if t == QEvent.Show and not self.started and self.still.off_thread:
            self.started = True
            still_process().start()
        elif t == QEvent.Hide:
            self.still.close_probe()
        return False
