"""Running ``gcmh_core.extract`` off the GUI thread.

:class:`ExtractWorker` is a ``QThread``: ``start()`` runs the extraction,
progress arrives as the ``progress(phase, fraction, seconds)`` signal (queued
to the GUI thread, at most ~20 per second), and exactly one of
``done(complex, geometry)`` (the drawing arrays of :class:`gcmh_studio.geometry.Geometry`
are prepared here too, so the GUI thread only hands them to VTK),
``failed(message)`` or ``cancelled()`` ends a run. ``cancel()`` sets a flag the
engine polls through its ``cancel`` callback; the engine then raises
``gcmh_core.errors.Cancelled``. No VTK, pyvista or widget is touched here.

The engine's calls run in helper threads the worker waits on, looking at the cancel
flag every few milliseconds: Cancel ends a run within a second in every phase, also
in those the engine does not poll (its assembly, the drawing arrays). What a
cancelled call still computes runs out unseen, and the next run waits for it
("stopping the cancelled run"), so two runs never hold memory at once.

Before the engine starts, the worker waits (cancellably) for the kernels' warm-up
(:func:`gcmh_studio.jobs.start_warm_up`) and estimates the run (``estimated(est)``); a run
that won't fit asks first (``confirm(est)``, answered by :meth:`ExtractWorker.answer`
from the GUI thread: "run", "gcch" or None, which ends the run with ``declined()``).
What a run computes (:class:`gcmh_studio.jobs.Job`, ``run_job``, ``view_data``) is in
:mod:`gcmh_studio.jobs`, without Qt: the headless path runs the same code.
"""

from __future__ import annotations

import threading
import time
import traceback

from qtpy.QtCore import QThread, Signal

from .jobs import (  # (run_job and estimate_job are looked up here: tests replace them)
    COMPILING,
    ENGINE,
    LOADING,
    STOPPING,
    Job,
    current_warm_up,
    estimate_job,
    run_job,
    system_of,
    view_data,
)

_helpers: list[threading.Thread] = []   # engine calls made for runs, until they end
_helpers_lock = threading.Lock()


def helpers_running() -> bool:
    """Is an engine call of some run (maybe a cancelled one) still computing?"""
    with _helpers_lock:
        _helpers[:] = [t for t in _helpers if t.is_alive()]
        return bool(_helpers)


def wait_for_helpers(timeout: float) -> bool:
    """Wait up to ``timeout`` seconds for every engine call to end (on quitting); True if they did."""
    deadline = time.perf_counter() + timeout
    with _helpers_lock:
        threads = list(_helpers)
    for t in threads:
        t.join(max(0.0, deadline - time.perf_counter()))
    return not helpers_running()


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
    estimated = Signal(object)             # the run's gcmh_core.budget.Estimate
    confirm = Signal(object)               # the Estimate of a run that won't fit: answer() says what to do
    declined = Signal()                    # the user did not want the run that won't fit

    PROGRESS_INTERVAL = 0.05
    POLL = 0.1   # seconds between looks at the cancel flag while waiting

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
        self.estimate = None
        self._answer = None
        self._answered = threading.Event()

    # called from the GUI thread
    def cancel(self) -> None:
        self._cancel.set()

    def answer(self, what) -> None:
        """The user's answer to ``confirm``: "run" (force), "gcch" (continuation instead) or None (don't run)."""
        self._answer = what
        self._answered.set()

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

    def _wait(self, done, pause=None) -> None:
        """Wait until ``done()`` (which may block up to POLL seconds), looking at the cancel flag in between;
        ``pause()``: how to wait between looks (default 20 ms of sleep; a thread's join ends the wait as soon
        as the thread does, which a parameter step's 50 ms budget needs)."""
        from gcmh_core.errors import Cancelled

        while not done():
            if self._cancel.is_set():
                raise Cancelled("cancelled while waiting")
            (pause or (lambda: time.sleep(0.02)))()

    def _wait_for_kernels(self) -> None:
        warm = current_warm_up()
        if warm is not None and warm.waits_for(self.job.method):
            # compiling only while numba really compiles (a cache load is "loading")
            self.progress.emit(COMPILING if warm.compiling else LOADING, 0.0, time.perf_counter() - self._t0)
            self._wait(lambda: warm.wait(self.POLL) or not warm.waits_for(self.job.method))

    def _in_helper(self, fn, *args, **kwargs):
        """``fn(*args, **kwargs)`` in a helper thread; its value, or its exception raised here. Cancel raises
        Cancelled at once (the call runs out unseen)."""
        out: dict = {}

        def body():
            try:
                out["value"] = fn(*args, **kwargs)
            except BaseException as e:  # noqa: BLE001 - raised again in the worker
                out["error"] = e

        t = threading.Thread(target=body, name=f"gcmh-{getattr(fn, '__name__', 'call')}", daemon=True)
        with _helpers_lock:
            _helpers.append(t)
        t.start()
        self._wait(lambda: not t.is_alive(), pause=lambda: t.join(0.02))
        if "error" in out:
            raise out["error"]
        return out["value"]

    def _estimate(self):
        return self._in_helper(estimate_job, self.job)

    def _estimate_and_ask(self) -> bool:
        """Estimate the run; when it won't fit, ask (through ``confirm``) and follow the answer.
        False: the user declined."""
        if self.job.step is not None:
            # a slider step: the grid of a run the user started (or a coarser one), so no estimate first (its
            # helper thread's hand-off is a tenth of a coarse step); the engine still refuses what won't fit
            return True
        self.progress.emit("estimating", 0.0, time.perf_counter() - self._t0)
        est = self.estimate = self._estimate()
        self.estimated.emit(est)
        if est.fits or self.job.force:
            return True
        self.confirm.emit(est)
        self._wait(self._answered.is_set)
        if self._answer == "gcch":
            self.job.method = "gcch"
            self.job.start = self.job.start or "auto"
            est = self.estimate = self._estimate()
            self.estimated.emit(est)
            self.job.force = not est.fits   # the user agreed to run this one
            return True
        if self._answer == "run":
            self.job.force = True
            return True
        return False

    def run(self) -> None:  # the thread body
        from gcmh_core.errors import Cancelled, InputError

        self._t0 = time.perf_counter()
        self.progress.emit("starting", 0.0, 0.0)
        try:
            if self._cancel.is_set():
                raise Cancelled("cancelled before start")
            self._wait_for_kernels()
            if helpers_running():
                self.progress.emit(STOPPING, 0.0, time.perf_counter() - self._t0)
                self._wait(lambda: not helpers_running(), pause=lambda: wait_for_helpers(0.02))
            if not self._estimate_and_ask():
                self.declined.emit()
                return
            self.progress.emit(ENGINE, 0.0, time.perf_counter() - self._t0)   # (grid and cube tables: no progress)
            cx = self._in_helper(run_job, self.job, progress=self._on_progress, cancel=self._should_cancel)
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
            try:
                geometry, self.report, tb = self._in_helper(view_data, cx, self.job, progress=self._on_progress,
                                                            cancel=self._should_cancel)
            except Cancelled:
                self.cancelled.emit()
                return
            self.traceback = tb or self.traceback
        if self._cancel.is_set():
            self.cancelled.emit()
            return
        self.result = cx
        self.done.emit(cx, geometry)
