"""QtRunController: the life-cycle of runs and refinements (start, progress, cancel, end).

One run (:class:`gcmh_studio.worker.ExtractWorker`) and one refinement
(:class:`gcmh_studio.worker.RefineWorker`) at a time, each in its own thread. The
controller relays what the current worker says and drops what a replaced
one still says; it keeps finished workers until their threads end, and
waits for all of them on :meth:`shutdown`. It draws nothing: the window
connects to its signals.
"""

from __future__ import annotations

import time

from qtpy.QtCore import QObject, Signal

from .jobs import Job
from .worker import ExtractWorker, RefineWorker, wait_for_helpers


class QtRunController(QObject):
    """Start, cancel and refine; see the module docstring.

    Signals
    -------
    busyChanged(bool)
        A run started (True) or ended (False).
    progress(phase, fraction, seconds)
        From the running worker only.
    done(cx, geometry, report)
        The run's complex, its drawing arrays (gcmh_studio.geometry.Geometry or None) and topology report (or None).
    failed(message), cancelled(seconds), declined()
        The run ended without a result (declined: the user did not want a run that won't fit).
    estimated(est)
        The running job's gcmh_core.budget.Estimate, before the engine starts.
    confirm(est)
        The run won't fit: the window asks the user and calls :meth:`answer`.
    refined(serial, cx, geometry, report, before, after)
        A refinement of the result ``serial`` ended (max |F| at the vertices before and after).
    refineFailed(message)
    """

    busyChanged = Signal(bool)
    progress = Signal(str, float, float)
    done = Signal(object, object, object)
    failed = Signal(str)
    cancelled = Signal(float)
    declined = Signal()
    estimated = Signal(object)
    confirm = Signal(object)
    refined = Signal(int, object, object, object, float, float)
    refineFailed = Signal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.worker: ExtractWorker | None = None
        self.refiner: RefineWorker | None = None
        self._old_workers: list = []   # finished runs and refinements, until their threads end
        self._t0 = 0.0

    # ------------------------------------------------------------ runs
    def start(self, job: Job) -> bool:
        """Start a run of ``job``; False if one is already running."""
        if self.worker is not None:
            return False
        w = ExtractWorker(job, self)
        w.progress.connect(self._on_progress)
        w.done.connect(self._on_done)
        w.failed.connect(self._on_failed)
        w.cancelled.connect(self._on_cancelled)
        w.declined.connect(self._on_declined)
        w.estimated.connect(lambda est, w=w: w is self.worker and self.estimated.emit(est))
        w.confirm.connect(lambda est, w=w: w is self.worker and self.confirm.emit(est))
        w.finished.connect(lambda w=w: self._on_thread_finished(w))
        self.worker = w
        self._t0 = time.perf_counter()
        self.busyChanged.emit(True)
        w.start()
        return True

    def cancel(self) -> bool:
        """Ask the running worker to stop (it ends with ``cancelled``); False if nothing runs."""
        if self.worker is None:
            return False
        self.worker.cancel()
        return True

    def answer(self, what) -> None:
        """Pass the user's answer to ``confirm`` to the running worker ("run", "gcch" or None)."""
        if self.worker is not None:
            self.worker.answer(what)

    def is_running(self) -> bool:
        return self.worker is not None

    def running_job(self) -> Job | None:
        """The job of the run under way, or None."""
        return self.worker.job if self.worker is not None else None

    def elapsed(self) -> float:
        """Seconds since the last run started."""
        return time.perf_counter() - self._t0

    def _current(self) -> bool:
        return self.sender() is self.worker and self.worker is not None

    def _on_progress(self, phase: str, fraction: float, seconds: float) -> None:
        if self._current():
            self.progress.emit(phase, fraction, seconds)

    def _finish(self) -> None:
        w, self.worker = self.worker, None
        if w is not None:
            self._old_workers.append(w)
        self.busyChanged.emit(False)

    def _on_done(self, cx, geometry=None) -> None:
        if not self._current():
            return
        report = self.worker.report
        self._finish()
        self.done.emit(cx, geometry, report)

    def _on_failed(self, message: str) -> None:
        if self._current():
            self._finish()
            self.failed.emit(message)

    def _on_cancelled(self) -> None:
        if self._current():
            seconds = self.elapsed()
            self._finish()
            self.cancelled.emit(seconds)

    def _on_declined(self) -> None:
        if self._current():
            self._finish()
            self.declined.emit()

    def _on_thread_finished(self, w) -> None:
        if w in self._old_workers:
            self._old_workers.remove(w)
        w.deleteLater()

    # ------------------------------------------------------------ refinement
    def refine(self, cx, job: Job, serial: int) -> bool:
        """Start moving the vertices of ``cx`` (result number ``serial``) onto M; False if one already runs."""
        if self.refiner is not None:
            return False
        w = RefineWorker(cx, job, self)
        w.done.connect(lambda cx, geometry, report, before, after:
                       self._on_refined(serial, cx, geometry, report, before, after))
        w.failed.connect(self._on_refine_failed)
        w.finished.connect(lambda w=w: self._on_thread_finished(w))
        self.refiner = w
        self._old_workers.append(w)  # (waited for on shutdown)
        w.start()
        return True

    def is_refining(self) -> bool:
        return self.refiner is not None

    def _on_refined(self, serial, cx, geometry, report, before, after) -> None:
        self.refiner = None
        self.refined.emit(serial, cx, geometry, report, before, after)

    def _on_refine_failed(self, message: str) -> None:
        self.refiner = None
        self.refineFailed.emit(message)

    # ------------------------------------------------------------ closing
    def shutdown(self, msecs: int = 5000) -> None:
        """Cancel every worker and wait up to ``msecs`` for each thread (on closing the window)."""
        for w in [self.worker] + list(self._old_workers):
            if w is not None:
                w.cancel()
                w.wait(msecs)
        self.worker = None
        wait_for_helpers(msecs / 1000)   # engine calls a cancel left running (they stop at their next poll)
