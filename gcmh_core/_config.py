"""Compiler flags for every numba kernel, in one place, and `compile_notice`.

nogil: a kernel running in a worker thread must not stall the GUI thread.
cache: kernels compile once per machine, not once per process (and never per F:
       kernels only ever see arrays of F's values).
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator
from typing import Any

JIT: dict[str, Any] = dict(nogil=True, cache=True, fastmath=False, error_model="numpy")
PARALLEL_JIT: dict[str, Any] = dict(JIT, parallel=True)
# Small helpers called in a kernel's inner loops take scalars.  Those that take only
# scalars (_face_key, _face_in_face, _local_code) are plain JIT calls: LLVM inlines them
# all the same (kernel time unchanged), and numba no longer types and lowers a copy per
# call site on a first run (the cube kernel compiled a fifth faster).  Those with an
# array (_find, simplex_crosses) are inlined by numba: as plain calls they cost 10% of
# the kernel's time.  Array arguments of an inlined call get reference-count
# updates (atomic, shared by all threads) that numba does not prune in functions
# as large as the chunk kernels (LLVM's refprune gives up past 1,000 basic blocks):
# they cost more than a cube's work.  (simplex_crosses takes arrays: it is called
# only for the few simplices that pass the sign prune.)  The loop over cubes runs
# inside one kernel function per chunk (`kernels.gcmh.cubes_chunk`), with scratch
# buffers it owns.
INLINE_JIT: dict[str, Any] = dict(JIT, inline="always")
# A kernel that calls another compiles the callee for the argument types type inference
# sees first: a counter started as `= 0` is Literal[int](0) there and int64 later, so
# the callee compiled twice (seconds each on a first run).  Counters and indices passed
# to another kernel start as np.int64(0).


def numba_without_scipy_blas() -> None:
    """Load numba.np.arraymath without scipy.linalg: numba imports scipy.linalg.cython_blas there only to
    choose np.correlate's inner product (no kernel here calls it), 0.5-0.6 s of every fresh process (the
    data command: 3.24 -> 2.52 s).  A kernel calling np.dot or np.linalg still finds scipy when it compiles."""
    import sys

    if "numba.np.arraymath" in sys.modules or "scipy.linalg.cython_blas" in sys.modules:
        return
    sys.modules["scipy.linalg.cython_blas"] = None  # type: ignore[assignment]  # (its import fails: no BLAS)
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        del sys.modules["scipy.linalg.cython_blas"]


@contextlib.contextmanager
def numba_events(kind: str, on_start: Callable, on_end: Callable | None = None) -> Iterator[None]:
    """Within the block, numba's events of ``kind`` (e.g. "numba:compile", "numba:compiler_lock")
    call ``on_start(event)`` and ``on_end(event)``, on whichever thread numba runs them."""
    from numba.core import event  # (numba loads with the engine)

    class _Listener(event.Listener):
        def on_start(self, ev: event.Event) -> None:
            on_start(ev)

        def on_end(self, ev: event.Event) -> None:
            if on_end is not None:
                on_end(ev)

    listener = _Listener()
    event.register(kind, listener)
    try:
        yield
    finally:
        event.unregister(kind, listener)


@contextlib.contextmanager
def compile_notice(callback: Callable[..., None], each_module: bool = False) -> Iterator[None]:
    """Within the block, call `callback()` once when a kernel of this package starts to
    compile: numba misses it in its on-disk cache (a new install, or a kernel no run has
    needed yet).  Loading a cached kernel says nothing (numba's "numba:compile" event
    comes after its cache lookup failed).  Which kernels a run needs depends on the run
    (n = 3 sweeps, n >= 8, the cell check, glued axes take their own), so this asks numba
    rather than looking for cache files.  The callback may run on a kernel thread.

    ``each_module``: call ``callback(module)`` instead, once for each module of this
    package whose kernels start to compile ("gcmh_core.kernels.lazy", ...): a caller can
    say which family of kernels a run waits for."""
    told: set[str] = set()
    lock = threading.Lock()

    def started(ev) -> None:
        func = getattr(ev.data.get("dispatcher"), "py_func", None)
        module = getattr(func, "__module__", "") or ""
        if not module.startswith(__package__ + "."):
            return
        key = module if each_module else ""
        with lock:
            if key in told:
                return
            told.add(key)
        if each_module:
            callback(module)
        else:
            callback()

    with numba_events("numba:compile", started):
        yield
