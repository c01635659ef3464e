"""Running ``gcmh_core.extract`` off the GUI thread.

:class:`ExtractWorker` is a ``QThread``: ``start()`` runs the extraction,
progress arrives as the ``progress(phase, fraction, seconds)`` signal (queued
to the GUI thread, at most ~20 per second), and exactly one of
``done(complex, geometry)`` (the drawing arrays of :class:`app.geometry.Geometry`
are prepared here too, so the GUI thread only hands them to VTK),
``failed(message)`` or ``cancelled()`` ends a run. ``cancel()`` sets a flag the
engine polls through its ``cancel`` callback; the engine then raises
``gcmh_core.errors.Cancelled``. No VTK, pyvista or widget is touched here.
"""

from __future__ import annotations

import threading
import time
import traceback
from dataclasses import dataclass, field

from qtpy.QtCore import QThread, Signal


@dataclass
class Job:
    """Everything ``gcmh_core.extract`` needs for one run."""

    formulas: list
    variables: list
    bounds: list
    div: object = 10
    method: str = "gcmh"
    seed: int = 0
    start: list | str | None = None   # for continuation: a point, or "auto"
    scheduler: str | None = None      # None: this process; "local" or "tcp://host:port": a Dask cluster
    extra: dict = field(default_factory=dict)

    def kwargs(self) -> dict:
        kw = dict(bounds=[tuple(b) for b in self.bounds], div=self.div, variables=list(self.variables),
                  seed=int(self.seed), method=self.method)
        if self.start is not None:
            kw["start"] = self.start if isinstance(self.start, str) else list(self.start)
        if self.scheduler:
            kw["scheduler"] = self.scheduler
        kw.update(self.extra)
        return kw


def run_job(job: Job, progress=None, cancel=None):
    """Run one job synchronously (the headless path and the worker share this)."""
    import gcmh_core

    return gcmh_core.extract(list(job.formulas), progress=progress, cancel=cancel, **job.kwargs())


def system_of(job: Job):
    """The parsed F of a job (a gcmh_core.formula.System)."""
    from gcmh_core.formula import parse_system

    return parse_system(list(job.formulas), list(job.variables))


def topology_of(cx, job: Job | None = None) -> dict | None:
    """The topology report of ``cx`` (with max |F| when the job's F parses); None without the analysis module."""
    try:
        from gcmh_core.analysis import topology_report
    except ImportError:
        return None
    try:
        system = system_of(job) if job is not None else None
    except Exception:  # noqa: BLE001 - sampled data or odd text: the report without F
        system = None
    try:
        return topology_report(cx, system)
    except Exception:  # noqa: BLE001 - the panel computes (and reports) it itself then
        return None


def view_data(cx, job: Job | None):
    """What the GUI thread needs to show ``cx``, made beforehand in a worker: (its drawing
    arrays, an app.geometry.Geometry or None; its topology report or None; the traceback
    when the Geometry failed: the GUI thread then builds it, and reports, itself)."""
    geometry, tb = None, None
    try:
        from .geometry import Geometry

        geometry = Geometry.build(cx)
    except Exception:  # noqa: BLE001
        tb = traceback.format_exc()
    return geometry, topology_of(cx, job), tb


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
