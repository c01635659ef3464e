"""Running ``gcmh_core.extract`` off the GUI thread.

:class:`ExtractWorker` is a ``QThread``: ``start()`` runs the extraction,
progress arrives as the ``progress(phase, fraction, seconds)`` signal (queued
to the GUI thread, at most ~20 per second), and exactly one of
``done(complex, geometry)`` (the drawing arrays of :class:`app.geometry.Geometry`
are prepared here too, so the GUI thread only hands them to VTK),
``failed(message)`` or ``cancelled()`` ends a run. ``cancel()`` sets a flag the
engine polls through its ``cancel`` callback; the engine then raises
``gcmh_core.errors.Cancelled``. No VTK, pyvista or widget is touched here.
What a run computes (:class:`app.jobs.Job`, ``run_job``, ``view_data``) is in
:mod:`app.jobs`, without Qt: the headless path runs the same code.
"""

from __future__ import annotations

import threading
import time
import traceback

from qtpy.QtCore import QThread, Signal

from .jobs import Job, run_job, system_of, view_data  # noqa: F401 - run_job is looked up here (tests replace it)


class RefineWorker(QThread):
    """Gauss-Newton refinement of a result's vertices onto M, with its drawing arrays and
    topology report, off the GUI thread.  Ends with ``done(complex, geometry, report,
    before, after)`` (max |F| at the vertices before and after) or ``failed(message)``."""

    done = Signal(object, object, object, float, float)
    failed = Signal(str)

    def __init__(self, cx, job: Job, parent=None):
        super().__init__(parent)
        self.cx, self.job = cx, job
        self._cancel = threading.Event()

    def cancel(self) -> None:  # (refinement is short: a cancelled one runs out and is dropped)
        self._cancel.set()

    def run(self) -> None:
        try:
            from gcmh_core.analysis import refine_vertices

            cx, before, after = refine_vertices(self.cx, system_of(self.job))
            geometry, report, _ = view_data(cx, self.job)
        except Exception as e:  # noqa: BLE001 - to the status line
            self.failed.emit(f"{type(e).__name__}: {e}")
            return
        if not self._cancel.is_set():
            self.done.emit(cx, geometry, report, float(before), float(after))


class ExtractWorker(QThread):
    """One extraction in a thread. Create a new worker per run."""

    progress = Signal(str, float, float)   # phase, fraction in [0, 1], elapsed seconds
    done = Signal(object, object)          # the CellComplex, its Geometry (or None)
    failed = Signal(str)                   # a one-line message for the status area
    cancelled = Signal()

    PROGRESS_INTERVAL = 0.05

    def __init__(self, job: Job, parent=None):
        super().__init__(parent)
        self.job = job
        self._cancel = threading.Event()
        self._t0 = 0.0
        self._last_emit = 0.0
        self._last_phase = None
        self.result = None
        self.error: str | None = None
        self.traceback: str | None = None
        self.report: dict | None = None    # gcmh_core.analysis.topology_report of the result, when available

    # called from the GUI thread
    def cancel(self) -> None:
        self._cancel.set()

    def is_cancelled(self) -> bool:
        return self._cancel.is_set()

    def elapsed(self) -> float:
        return time.perf_counter() - self._t0 if self._t0 else 0.0

    # called from the worker thread (by the engine)
    def _on_progress(self, phase: str, fraction: float) -> None:
        now = time.perf_counter()
        if phase != self._last_phase or now - self._last_emit >= self.PROGRESS_INTERVAL or fraction >= 1.0:
            self._last_phase = phase
            self._last_emit = now
            self.progress.emit(str(phase), float(fraction), now - self._t0)

    def _should_cancel(self) -> bool:
        return self._cancel.is_set()

    def run(self) -> None:  # the thread body
        from gcmh_core.errors import Cancelled, InputError

        self._t0 = time.perf_counter()
        self.progress.emit("starting", 0.0, 0.0)
        try:
            if self._cancel.is_set():
                raise Cancelled("cancelled before start")
            cx = run_job(self.job, progress=self._on_progress, cancel=self._should_cancel)
        except Cancelled:
            self.cancelled.emit()
            return
        except InputError as e:
            self.error = str(e)
            self.failed.emit(str(e))
            return
        except MemoryError:
            self.error = "out of memory: try a smaller div or the continuation method (GCCH)"
            self.failed.emit(self.error)
            return
        except Exception as e:  # noqa: BLE001 - any engine error goes to the status line
            self.traceback = traceback.format_exc()
            self.error = f"{type(e).__name__}: {e}"
            self.failed.emit(self.error)
            return
        if self._cancel.is_set():
            self.cancelled.emit()
            return
        geometry = None
        if cx.count(0):
            self.progress.emit("preparing the view", 1.0, time.perf_counter() - self._t0)
            geometry, self.report, tb = view_data(cx, self.job)
            self.traceback = tb or self.traceback
        if self._cancel.is_set():
            self.cancelled.emit()
            return
        self.result = cx
        self.done.emit(cx, geometry)
