"""One extraction as data, and what showing its result needs (pure Python, no Qt).

:class:`Job` is everything ``gcmh_core.extract`` needs for one run; ``run_job``
runs it synchronously (the headless path, and the worker threads of
:mod:`app.worker`, call it); ``view_data`` prepares the drawing arrays and the
topology report of a result off the GUI thread.
"""

from __future__ import annotations

import traceback
from dataclasses import dataclass, field


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
