"""One extraction as data, and what showing its result needs (pure Python, no Qt).

:class:`Job` is everything ``gcmh_core.extract`` needs for one run; ``run_job``
runs it synchronously (the headless path, and the worker threads of
:mod:`gcmh_studio.worker`, call it), ``estimate_job`` says beforehand what it will cost;
``view_data`` prepares the drawing arrays and the topology report of a result off
the GUI thread.

The numba kernels compile once per install (cached on disk), about 22 s for all four methods on two cores
the first time: :func:`start_warm_up` compiles (or loads) them in a background
thread as the app starts, with a tiny extraction by each method, so the first
Run rarely waits; a run started meanwhile waits for it (:class:`WarmUp`).
"""

from __future__ import annotations

import os
import threading
import time
import traceback
from dataclasses import dataclass, field
from typing import Any

# what the first run on a new install waits while the kernels compile (measured on 2 cores: gcmh 23 s quiet,
# 43 s busy; then gcch 1.4 s, cms 9.5 s, ccs 0.01 s)
COMPILE_NOTE = "about 20 seconds"
# phases of a run (the worker's progress) whose fraction means nothing: shown without a percentage
COMPILING = "compiling kernels (once per install)"
LOADING = "loading the compiled kernels"
STOPPING = "stopping the cancelled run"
ENGINE = "starting the engine"
WAITING_PHASES = ("starting", "estimating", COMPILING, LOADING, STOPPING, ENGINE, "preparing the view")

# The kernels a run may compile the first time it needs them, by module: what the family is called, and its
# first compile in seconds on 2 quiet cores.  Measured with an empty cache (NUMBA_CACHE_DIR=<new folder>
# python /tmp/gcmh-measure/measure.py, which times numba's "numba:compile" events per module) at a load
# average of 15.5 on 2 cores, then divided by that load per core (7.8): the warm-up of the four methods took
# 567 s there, gcmh 381 s of it, cms 53, candidates 43, the cell check 42, marching3 37, the hash table 4.
KERNEL_FAMILIES = {
    "gcmh_core.kernels.gcmh": ("the cube kernels", 49.0),
    "gcmh_core.kernels.cms": ("the CMS kernels", 6.9),
    "gcmh_core.kernels.candidates": ("the candidate test", 5.5),
    "gcmh_core.kernels.cell_check": ("the cell check", 5.5),
    "gcmh_core.kernels.marching3": ("the surface kernels for n = 3", 4.7),
    "gcmh_core._hashtable": ("the hash table", 0.5),
    "gcmh_core.kernels.lazy": ("the kernels for n >= 8", 10.0),
}
WARM_UP_SECONDS = 73.0    # the whole warm-up's first compile (the sum above), 2 quiet cores


def busy_factor() -> float:
    """How much slower than on quiet cores a compile runs now: the load average per core (at least 1)."""
    try:
        load = os.getloadavg()[0]
    except (OSError, AttributeError):
        return 1.0
    return max(1.0, load / max(1, os.cpu_count() or 1))


def kernel_family(module: str) -> tuple[str, float]:
    """(what the family of kernels in ``module`` is called, its first compile in seconds now)."""
    name, quiet = KERNEL_FAMILIES.get(module, ("the numerical kernels", 10.0))
    return name, quiet * busy_factor()


def compile_phase(module: str) -> str:
    """The progress phase while ``module``'s kernels compile: which, and a measured estimate."""
    name, seconds = kernel_family(module)
    return f"{COMPILING}: {name}, about {about_seconds(seconds)}"


def about_seconds(seconds: float) -> str:
    """"12 s", "2 min": a wait as a person reads it (rounded up to a round value)."""
    if seconds < 60:
        return f"{max(1, int(5 * -(-seconds // 5)))} s"
    return f"{int(-(-seconds // 60))} min"


def continuation_methods() -> tuple[str, ...]:
    """The methods that start from points and follow M (they take a start point)."""
    try:
        from gcmh_core import CONTINUATION_METHODS
        return tuple(CONTINUATION_METHODS)
    except ImportError:
        return ("gcch",)


def engine_methods() -> tuple[str, ...]:
    """The extraction methods the installed engine supports."""
    try:
        import gcmh_core
        m = getattr(gcmh_core, "METHODS", None)
        if m:
            return tuple(str(x).lower() for x in m)
    except ImportError:
        pass
    return ("gcmh",)


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
    force: bool = False               # run even when the estimate says it won't fit (the user agreed)
    params: dict | None = None        # the formulas' parameters, {name: value}
    periodic: list | None = None      # glued axes, e.g. ["t", "s:flip=t"] (extract's periodic=)
    labels: dict | None = None        # what the variables mean, {"u": "Re w"} (complex mode; not the engine's)
    title: str = ""                   # what a system typed in is called on screen (complex mode: its equations)
    step: str | None = None           # a parameter step: "coarse" (a slider held) or "full" (let go); None: a run
    extra: dict = field(default_factory=dict)

    def kwargs(self) -> dict:
        kw = dict(bounds=[tuple(b) for b in self.bounds], div=self.div, variables=list(self.variables),
                  seed=int(self.seed), method=self.method)
        if self.start is not None:   # a point, "auto", or the previous result (a CellComplex: continue from it)
            kw["start"] = self.start if isinstance(self.start, str) or hasattr(self.start, "vertices") \
                else list(self.start)
        if self.scheduler:
            kw["scheduler"] = self.scheduler
        if self.force:
            kw["force"] = True
        if self.params:
            kw["params"] = dict(self.params)
        if self.periodic:
            kw["periodic"] = list(self.periodic)
        kw.update(self.extra)
        return kw


def run_job(job: Job, progress=None, cancel=None):
    """Run one job synchronously (the headless path and the worker share this)."""
    import gcmh_core

    def announce(module: str) -> None:   # a family of kernels compiles for the first time: say so, and how long
        if progress is not None:
            progress(compile_phase(module), 0.0)

    with gcmh_core.compile_notice(announce, each_module=True):
        return _run_job(job, progress, cancel)


def _run_job(job: Job, progress=None, cancel=None):
    import gcmh_core

    kw = job.kwargs()
    previous = hasattr(kw.get("start"), "vertices")
    try:
        cx = gcmh_core.extract(list(job.formulas), progress=progress, cancel=cancel, **kw)
    except gcmh_core.InputError as err:
        # an example's start point lies on M at its default parameters only (and a previous
        # result's vertices may all miss the new M): after a parameter changes, continuation
        # starts from every piece F's bounds find instead
        text = str(err)
        if not (job.params and (isinstance(kw.get("start"), list) or previous)
                and (text.startswith("start point") or "start cube" in text or previous)):
            raise
        note = f"the {'previous result' if previous else 'start point'} did not reach M at these parameters ({text})"
    else:
        if not (previous and cx.count(0) == 0):
            return cx
        note = "continuing from the previous result found nothing"
    kw["start"] = "auto"
    cx = gcmh_core.extract(list(job.formulas), progress=progress, cancel=cancel, **kw)
    cx.meta["start_note"] = f"{note}; started from 'auto'"
    return cx


def estimate_job(job: Job):
    """What ``job`` will cost (a gcmh_core.budget.Estimate: peak memory, seconds, ``fits``), without
    running it. Bad input raises the InputError the run would."""

    from gcmh_core.budget import estimate

    F = system_of(job) if job.params else list(job.formulas)   # (the estimate takes parameters as a System)
    # glued axes: the identified grid's sweep is never pruned and evaluates F at every vertex (the closed
    # Klein bottle: 0.66 s estimated as if cut open and pruned; 18-21 s at a load of 13-16 on 2 cores)
    return estimate(F, [tuple(b) for b in job.bounds], job.div, variables=list(job.variables),
                    method=job.method, scheduler=job.scheduler or None,
                    periodic=list(job.periodic) if job.periodic else None)


def warm_up_kernels(methods, cancel=None, ready=None) -> None:
    """Compile (first time) or load (from numba's cache) the kernels of ``methods``: a tiny extraction by
    each (a sphere in R^3 on a 4^3 grid, and a curve in R^4 for k = 2). ``cancel()``: stop between runs;
    ``ready(method)``: called when a method's kernels are ready."""
    import gcmh_core
    from gcmh_core.extract import CONTINUATION_METHODS

    runs = [(m, ["x1^2 + x2^2 + x3^2 - 1"], 3) for m in methods]
    runs.insert(1, ("gcmh", ["x1^2 + x2^2 + x3^2 + x4^2 - 1", "x1 - x2"], 4))
    for method, formulas, n in runs:
        if cancel is not None and cancel():
            return
        if method not in methods:
            continue
        kw: dict[str, Any] = {"start": "auto"} if method in CONTINUATION_METHODS else {}
        gcmh_core.extract(formulas, bounds=[(-1.5, 1.5)] * n, div=4, variables=[f"x{i + 1}" for i in range(n)],
                          method=method, **kw)
        if ready is not None and n == 3:
            ready(method)


class WarmUp:
    """The kernels' warm-up in a daemon thread: ``running()``, ``wait(timeout)``, ``seconds`` when done,
    ``error`` (a one-line message) if it failed (the first run then compiles what it needs itself)."""

    def __init__(self, methods) -> None:
        self.methods = tuple(methods)
        self.compiling = False         # numba really compiles (not a load from its cache): the window says so
        self.modules: list[str] = []   # the modules whose kernels compiled
        self.compiled: dict[str, float] = {}   # seconds each module's kernels took to compile, as they end
        self.seconds: float | None = None
        self.error: str | None = None
        self.ready: set[str] = set()   # the methods whose kernels are ready
        self._done = threading.Event()
        self._stop = threading.Event()
        self._t0 = 0.0

    def start(self) -> WarmUp:
        self._t0 = time.perf_counter()
        threading.Thread(target=self._run, name="gcmh-warm-up", daemon=True).start()
        return self

    def _run(self) -> None:
        import gcmh_core
        from gcmh_core._config import numba_events

        starts: dict = {}

        def began(ev):   # (numba compiles one kernel at a time, under its lock: the outermost call is the kernel)
            f = getattr(ev.data.get("dispatcher"), "py_func", None)
            starts.setdefault(threading.get_ident(), []).append((getattr(f, "__module__", ""), time.perf_counter()))

        def ended(ev):
            stack = starts.get(threading.get_ident())
            if stack:
                module, t0 = stack.pop()
                if not stack:
                    self.compiled[module] = self.compiled.get(module, 0.0) + time.perf_counter() - t0

        try:
            with gcmh_core.compile_notice(self._compiles, each_module=True), \
                    numba_events("numba:compile", began, ended):
                warm_up_kernels(self.methods, cancel=self._stop.is_set, ready=self.ready.add)
        except Exception as e:  # noqa: BLE001 - a failed warm-up only means the first run compiles
            self.error = f"{type(e).__name__}: {e}"
        self.seconds = time.perf_counter() - self._t0
        self._done.set()

    def _compiles(self, module: str) -> None:
        self.modules.append(module)
        self.compiling = True

    def running(self) -> bool:
        return not self._done.is_set()

    def phase(self) -> str:
        """What a run waiting for the warm-up waits for: kernels compiling, or loading from numba's cache."""
        return COMPILING if self.compiling else LOADING

    def seconds_left(self) -> float:
        """A measured estimate of the warm-up's compile still to come: once a tenth of it has compiled, what
        that part took here scaled to the whole (by the parts' shares in KERNEL_FAMILIES); before, the
        quiet machine's time times the load now."""
        done = dict(self.compiled)
        share = sum(KERNEL_FAMILIES.get(m, ("", 0.0))[1] for m in done) / WARM_UP_SECONDS
        if share >= 0.1:
            total = self.elapsed() * min(1.0 / share, 20.0)
        else:
            total = WARM_UP_SECONDS * busy_factor()
        return max(0.0, total - self.elapsed())

    def notice(self) -> str:
        """The window's word while the kernels compile ("" while they only load)."""
        if not (self.running() and self.compiling):
            return ""
        left = self.seconds_left()
        more = f"about {about_seconds(left)} left" if left >= 1 else "nearly done"
        return (f"Compiling the numerical kernels: once per install, {self.elapsed():.0f} s so far, {more}; "
                "later runs start at once.")

    def waits_for(self, method: str) -> bool:
        """Would a run of ``method`` wait for kernels still being compiled here?"""
        return self.running() and method not in self.ready

    def elapsed(self) -> float:
        return self.seconds if self.seconds is not None else time.perf_counter() - self._t0

    def wait(self, timeout: float | None = None) -> bool:
        """True once the warm-up has ended."""
        return self._done.wait(timeout)

    def stop(self) -> None:
        """Stop after the extraction under way (on quitting)."""
        self._stop.set()


_WARM_UP: WarmUp | None = None


def start_warm_up(methods) -> WarmUp:
    """The process's warm-up, started on the first call (every later window shares it)."""
    global _WARM_UP
    if _WARM_UP is None:
        _WARM_UP = WarmUp(methods).start()
    return _WARM_UP


def current_warm_up() -> WarmUp | None:
    return _WARM_UP


def system_of(job: Job):
    """The parsed F of a job (a gcmh_core.formula.System)."""
    from gcmh_core.formula import parse_system

    return parse_system(list(job.formulas), list(job.variables), params=dict(job.params) if job.params else None)


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


def view_data(cx, job: Job | None, progress=None, cancel=None):
    """What the GUI thread needs to show ``cx``, made beforehand in a worker: (its drawing
    arrays, an gcmh_studio.geometry.Geometry or None; its topology report or None; the traceback
    when the Geometry failed: the GUI thread then builds it, and reports, itself).
    ``progress(phase, fraction)`` names each step; ``cancel()`` is asked between them
    (a cancelled call returns without the report)."""
    geometry, tb = None, None
    if progress is not None:
        progress("preparing the view: drawing arrays", 0.0)
    try:
        from .geometry import Geometry

        geometry = Geometry.build(cx)
    except Exception:  # noqa: BLE001
        tb = traceback.format_exc()
    if cancel is not None and cancel():
        return geometry, None, tb
    if progress is not None:
        progress("preparing the view: topology", 0.5)
    return geometry, topology_of(cx, job), tb
