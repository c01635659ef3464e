"""The same extraction over blocks of the grid on a Dask cluster (`extract(..., scheduler=...)`).

Every cube is processed independently and every vertex, edge and cell carries a
global key computed from grid indices alone (see `gcmh_core.kernels`), and `runner.assemble_records`
sorts by key: blocks processed on different machines merge without a second pass.

Whole-grid methods ("gcmh", "cms"): the grid of cubes is cut into n-D blocks, one
task per block.  The worker evaluates F on its block (it rebuilds F from the
formula *text*, parsed once per worker process), runs `Grid.process_block` and
returns the block's records; the client concatenates them in block order into
one `Grid` and assembles.  The result is the single-process result, bit for bit.

Continuation ("gcch", "ccs"): `continuation.run_continuation` runs the waves on the client;
each wave of at least `LOCAL_WAVE` cubes is split into chunks, one task per chunk
(`Grid.process_cubes` on the worker).  Smaller waves run in the client process:
shipping them costs more than processing them.

Identified axes (`identify`, periodic=): tasks build the `identify.IdentifiedGrid`
from (spec, bounds); a block ending on a seam copies that face's values from the
vertices identified with it (F evaluated there, wherever they lie), and the client's
`IdentifiedGrid.assemble` canonicalises the seam keys: the single-process result again.
Sampled data can't be checked for periodicity, so it is refused with periodic axes.

Sampled data (an array of F's values): with scheduler="local" the array is saved
once to a temporary .npy that workers open with mmap (they read only their
block); with a remote scheduler the workers may not share the client's disk, so
each block's slice is scattered to the cluster (continuation scatters the whole
array once to every worker, since a wave can touch any part of it).  Values read
from memory-mapped files (`data_files.MappedValues`, what `extract_data` runs on
a cluster) are never written whole: local workers reopen the files' maps (the
object pickles as its recipe) and read their block from them; for a remote
scheduler the client reads each block's slice from its maps and scatters it.

Memory per block of b_1 x ... x b_n cubes, V = (b_1+1)...(b_n+1) vertices:
F's values 8k V bytes, the candidate pass about (k + 6) V bytes (sign codes,
finiteness masks, the OR over corners), F's full-size temporaries (8 V bytes
each, t = 1 or 2 for usual formulas), and the records of the block's part of M
(small next to the values unless M fills the block): about (9k + 8t + 6) V bytes,
on top of a worker process with numpy, numba and the kernels loaded.  The
default block keeps V <= BLOCK_VERTICES (2^23: ~270 MB at k = 2, ~400 MB at k = 3 by
that count; a worker measured 100 MB over idle for the cosine's 6.1M-vertex blocks) and
gives at least BLOCKS_PER_WORKER blocks per worker thread.  Smaller blocks (2^21) made
four times as many tasks, and scheduling them cost more than the work saved.

dask is imported here only, and only when a scheduler is asked for.
"""

from __future__ import annotations

import functools
import logging
import os
import re
import shutil
import socket
import tempfile
import threading
import time
import uuid
from typing import TYPE_CHECKING

import numpy as np

from ._validate import per_axis_ints
from .continuation import run_continuation
from .errors import Cancelled, InputError
from .formula import parse_system
from .runner import CONTINUATION_METHODS, Grid, block_values

if TYPE_CHECKING:  # (dask is optional: imported where a run needs it)
    from distributed import Client, LocalCluster

# Default block: at most this many vertices (bounds a worker's memory, see the module doc) ...
BLOCK_VERTICES = 1 << 23
# ... and at least this many blocks per worker thread (load balance as blocks finish unevenly).
BLOCKS_PER_WORKER = 4
# Continuation waves with fewer cubes than this run in the client process.
LOCAL_WAVE = 4096
# Smallest chunk of a continuation wave sent to a worker.
MIN_CHUNK = 1024
# Seconds to reach a scheduler, and to wait for its first worker.
CONNECT_TIMEOUT = 5.0
# Seconds between two polls of `cancel` while tasks run.
POLL = 0.05
# meta keys that say how a run went on the cluster, not what it produced: the JSON summary shows
# them; `CellComplex.save` leaves them out (complex.VOLATILE_META), so the file has the
# single-process bytes
RUN_META = ("scheduler", "workers", "tasks", "blocks", "block")

_ADDRESS = re.compile(r"^tcp://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})$")


# ----------------------------------------------------------------------------- public
def run_distributed(method, n, k, axes, bounds, system, sampled, starts, scheduler, block, progress, cancel,
                    spec=(), check_cells=None):
    """Run `method` on a Dask cluster; returns the same CellComplex as a single-process run.

    method : "gcmh"/"cms" (blocks of the whole grid) or "gcch"/"ccs" (continuation waves).
    n, k : dimensions; axes : n arrays of grid lines (div_a + 1,) float64 (already perturbed);
    bounds (n, 2) float64; system : formula.System or None; sampled : (d1+1, ..., dn+1, k)
    float64 or None; starts : continuation start points (or "auto") or None.
    scheduler : "local" (a LocalCluster sized to this machine, closed at the end) or
        "tcp://host:port" (a running `dask scheduler`).
    block : None (default size, see the module doc), an int, or n ints: cubes per block per axis.
    progress(phase, fraction), cancel() -> bool : as in `extract`.
    spec : identified axes, ((p, (b, ...)), ...) as `_validate.as_periodic` gives them (axes then
        from `identify.identified_axes`): every task builds the `identify.IdentifiedGrid`.
    check_cells : as `runner.Grid`'s; every task's grid gets the run's answer.
    """
    address = check_scheduler(scheduler)
    div = np.array([len(a) - 1 for a in axes], np.int64)
    block_ = _check_block(block, n)
    if block_ is not None and method in CONTINUATION_METHODS:
        raise InputError(f"block applies to whole-grid methods; {method!r} sends waves of cubes, not blocks")
    try:
        import distributed  # noqa: F401 - only whether it is installed
    except ImportError:
        raise InputError(
            'scheduler needs dask.distributed, which is not installed: pip install -e ".[cluster]"'
        ) from None
    ident = _identification(spec, bounds, sampled)
    grid = _new_grid(n, k, axes, method, ident, check_cells)  # validates the grid's size before any cluster starts
    grid.set_source(system, sampled)  # (the tasks' deferred refinements run here, at the assembly)
    if progress is not None:  # starting a cluster takes a second or two: say so
        progress("starting a local dask cluster" if address == "local" else f"connecting to {address}", 0.0)
    with _Session(address, sampled) as session:
        if method in CONTINUATION_METHODS:
            process = functools.partial(_process_wave, session, method, system, sampled, cancel, ident)
            cx = run_continuation(n, k, axes, bounds, system, sampled, starts, progress, cancel,
                                  grid=grid, process=process)
        else:
            cx = _run_blocks(session, grid, method, div, block_, system, sampled, progress, cancel, ident)
        cx.meta["scheduler"] = scheduler
        cx.meta["workers"] = session.workers if session.started else 0
        cx.meta["tasks"] = session.tasks
    return cx


def default_block(div, workers: int) -> np.ndarray:
    """Cubes per block per axis (n,) int64 for a grid of `div` (n,) cubes and `workers` threads.

    Halves the longest side of the block (the first such axis on ties) until a block
    has at most BLOCK_VERTICES vertices and there are BLOCKS_PER_WORKER blocks per
    worker.  Near-cubic blocks keep the vertices two blocks share (evaluated by
    both) few: a block of b_a cubes per axis evaluates prod((b_a+1)/b_a) times
    the vertices it owns.
    """
    div = np.asarray(div, np.int64)
    block = div.copy()
    want = BLOCKS_PER_WORKER * max(int(workers), 1)

    def too_big():
        return np.prod((block + 1).astype(np.float64)) > BLOCK_VERTICES

    def too_few():
        return np.prod((-(-div // block)).astype(np.float64)) < want

    while (too_big() or too_few()) and block.max() > 1:
        a = int(np.argmax(block))
        block[a] = -(-block[a] // 2)
    return block


# ----------------------------------------------------------------------------- validation
def check_scheduler(scheduler) -> str:
    if not isinstance(scheduler, str):
        raise InputError(f"scheduler must be 'local' or an address 'tcp://host:port', got {scheduler!r}")
    text = scheduler.strip()
    if text.lower() == "local":
        return "local"
    m = _ADDRESS.match(text)
    if not m:
        raise InputError(f"scheduler must be 'local' or an address 'tcp://host:port', got {scheduler!r}")
    if not 1 <= int(m.group(2)) <= 65535:
        raise InputError(f"scheduler {scheduler!r}: port {m.group(2)} is not in 1..65535")
    return text


def _check_block(block, n: int) -> np.ndarray | None:
    return None if block is None else per_axis_ints(block, n, "block")


def _identification(spec, bounds, sampled) -> tuple | None:
    """What a task needs to build the `IdentifiedGrid` (spec, bounds as nested tuples), or None."""
    if not spec:
        return None
    if sampled is not None:  # (extract refuses this first; a direct caller gets the same words)
        raise InputError("periodic axes need F as formulas: sampled values can't be checked for periodicity")
    spec = tuple((int(p), tuple(int(b) for b in flips)) for p, flips in spec)
    return spec, tuple(map(tuple, np.asarray(bounds, np.float64).tolist()))


def _new_grid(n, k, axes, method, ident, check_cells=None) -> Grid:
    if ident is None:
        return Grid(n, k, axes, method, check_cells=check_cells)
    from .identify import IdentifiedGrid

    return IdentifiedGrid(n, k, axes, method, spec=ident[0], bounds=np.array(ident[1], np.float64),
                          check_cells=check_cells)


# ----------------------------------------------------------------------------- the cluster
class _Session:
    """A Dask client for one run.  "local" starts a LocalCluster on first use (a run
    whose continuation waves all stay small never starts one); an address is
    connected at once, so a bad one fails before any work."""

    def __init__(self, address: str, sampled):
        self.address, self.sampled = address, sampled
        self.cluster: LocalCluster | None = None
        self._client: Client | None = None
        self.tmpdir: str | None = None
        self.sampled_ref: object = None  # how tasks reach the sampled array: ("npy", path) or a future
        self.workers = 0
        self.tasks = 0
        self._per_host: dict[str, int] | None = None
        self.run = uuid.uuid4().hex[:12]

    def __enter__(self):
        if self.address != "local":
            self.client  # noqa: B018  (connect now)
        return self

    def __exit__(self, *exc):
        try:
            if self._client is not None:
                self._client.close()
        finally:
            try:
                if self.cluster is not None:
                    self.cluster.close()
            finally:
                if self.tmpdir is not None:
                    shutil.rmtree(self.tmpdir, ignore_errors=True)

    @property
    def started(self) -> bool:
        return self._client is not None

    @property
    def client(self):
        if self._client is None:
            self._client = self._connect()
            self.workers = sum(self._client.nthreads().values())
        return self._client

    def _connect(self):
        from distributed import Client, LocalCluster

        if self.address == "local":
            cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
            # one single-threaded process per core: numpy evaluation holds the GIL, and each
            # task's kernels then get one core to themselves (see kernel_threads)
            self.cluster = LocalCluster(
                n_workers=cores, threads_per_worker=1, processes=True,
                # no dashboard, and its HTTP server on a free port (8787 may be another cluster's)
                dashboard_address=":0", scheduler_kwargs={"dashboard": False}, silence_logs=logging.ERROR,
            )
            return Client(self.cluster, set_as_default=False)
        _probe(self.address)
        _identify(self.address)
        try:
            client = Client(self.address, timeout=CONNECT_TIMEOUT, set_as_default=False)
        except Exception as err:  # noqa: BLE001  (anything here means: not a usable scheduler)
            raise InputError(f"cannot connect to the dask scheduler at {self.address}: {_first_line(err)}") from None
        try:
            client.wait_for_workers(1, timeout=2 * CONNECT_TIMEOUT)
        except Exception:  # noqa: BLE001
            client.close()
            raise InputError(
                f"the dask scheduler at {self.address} has no workers (waited {2 * CONNECT_TIMEOUT:g} s): "
                f"start some with `dask worker {self.address}`"
            ) from None
        return client

    def sampled_for_tasks(self, whole: bool):
        """What a task needs to read the sampled array: ("npy", path), the values read from files
        (a `data_files.MappedValues`, which the workers reopen), a future of the whole array
        (remote continuation), or None (remote blocks get their own slices)."""
        if self.sampled is None:
            return None
        if self.sampled_ref is None:
            client = self.client
            if self.cluster is not None and not isinstance(self.sampled, np.ndarray):  # read from the files' maps
                self.sampled_ref = self.sampled
            elif self.cluster is not None:  # workers share this disk
                self.tmpdir = tempfile.mkdtemp(prefix="gcmh-dask-")
                path = os.path.join(self.tmpdir, "sampled.npy")
                np.save(path, self.sampled)
                self.sampled_ref = ("npy", path)
            elif whole:
                self.sampled_ref = client.scatter(self.sampled, broadcast=True, hash=False)
            else:
                return None
        return self.sampled_ref

    def kernel_threads(self) -> dict:
        """Task threads per worker host {host: threads}, as the run starts: a task gives
        the numba kernels the host's cores divided by this (they would otherwise start
        one thread per core in every worker process, and the processes would fight)."""
        if self._per_host is not None:
            return self._per_host
        from distributed.comm import get_address_host

        per_host: dict = {}
        for address, info in self.client.scheduler_info(n_workers=-1)["workers"].items():
            host = get_address_host(address)
            per_host[host] = per_host.get(host, 0) + int(info.get("nthreads", 1))
        self._per_host = per_host
        return per_host

    def key(self, what: str) -> str:
        """A key unique to this run and task (dask would reuse the result of a repeated key)."""
        self.tasks += 1
        return f"gcmh-{what}-{self.run}-{self.tasks}"


def _probe(address: str) -> None:
    """A plain TCP connect first: fails in well under a second for a closed port or an
    unknown host (a failed dask Client waits out its timeout, then again when collected)."""
    m = _ADDRESS.match(address)
    assert m is not None  # (check_scheduler accepted the address)
    host, port = m.group(1).strip("[]"), int(m.group(2))
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT).close()
    except OSError as err:
        reason = err.strerror or str(err) or type(err).__name__
        raise InputError(f"cannot reach the dask scheduler at {address}: {reason}") from None


def _identify(address: str) -> None:
    """Ask whatever listens at `address` who it is, with a deadline.  dask's Client waits
    forever for the handshake of a server that accepts TCP but is not dask (a web
    server, say).  The question runs on its own thread and event loop, so this works
    from a thread that already runs one (a notebook); on a timeout the thread is
    abandoned (a daemon, it holds one socket)."""
    import asyncio

    from distributed.core import rpc

    answer: dict = {}

    async def ask():
        remote = rpc(address, timeout=CONNECT_TIMEOUT)
        try:
            return await asyncio.wait_for(remote.identity(), CONNECT_TIMEOUT)
        finally:
            await remote.close_rpc()

    def run():
        try:
            answer["identity"] = asyncio.run(ask())
        except BaseException as err:  # noqa: BLE001  (reported to the caller below)
            answer["error"] = err

    thread = threading.Thread(target=run, name="gcmh-dask-identify", daemon=True)
    thread.start()
    thread.join(CONNECT_TIMEOUT + 1.0)
    if thread.is_alive() or "error" in answer:
        why = "no answer" if thread.is_alive() else _first_line(answer["error"])
        raise InputError(f"{address} does not answer as a dask scheduler ({why}); is `dask scheduler` running there?")
    kind = answer["identity"].get("type") if isinstance(answer.get("identity"), dict) else None
    if kind != "Scheduler":
        raise InputError(f"{address} is a dask {kind or 'server'}, not a scheduler: give the scheduler's address")


def _first_line(err) -> str:
    text = str(err).strip().splitlines()
    return text[0] if text else type(err).__name__


def _gather(session, futures, cancel, on_done=None) -> list:
    """Results of `futures` in submission order, polling `cancel` while they run.

    on_done(done, total) after each completion.  On cancel or on a task's error the
    other futures are cancelled.
    """
    from distributed import as_completed
    from distributed.scheduler import KilledWorker

    index = {f.key: i for i, f in enumerate(futures)}
    results = [None] * len(futures)
    done = 0
    ac = as_completed(futures, loop=session.client.loop)  # no default client: ours is set_as_default=False
    try:
        while done < len(futures):
            if cancel is not None and cancel():
                raise Cancelled("extraction cancelled")
            if not ac.has_ready():
                time.sleep(POLL)
                continue
            for f in ac.next_batch(block=False):
                try:
                    results[index[f.key]] = f.result()  # re-raises a task's error here
                except KilledWorker:
                    raise InputError(
                        "a task killed dask workers again and again (out of memory?): "
                        "use a smaller block, or workers with more memory"
                    ) from None
                f.release()
                done += 1
                if on_done is not None:
                    on_done(done, len(futures))
    except BaseException:
        session.client.cancel(futures)
        raise
    return results


# ----------------------------------------------------------------------------- whole grid
def _blocks(div, block):
    """(lo, hi) cube ranges (n,) int64 of every block, in C order of the block grid."""
    counts = -(-div // block)
    for index in np.ndindex(*counts.tolist()):
        lo = np.array(index, np.int64) * block
        yield lo, np.minimum(lo + block, div)


def _run_blocks(session, grid, method, div, block, system, sampled, progress, cancel, ident=None):
    client = session.client
    if block is None:
        block = default_block(div, session.workers)
    block = np.minimum(block, div)
    formula = None if system is None else (tuple(system.texts), tuple(system.variables), system.params or None)
    shared = session.sampled_for_tasks(whole=False)
    threads = session.kernel_threads()
    futures = []
    for lo, hi in _blocks(div, block):
        if sampled is not None and shared is None:  # remote: ship the block's own slice
            data = client.scatter(block_values(grid.axes, None, sampled, lo, hi), hash=False)
        else:
            data = shared
        futures.append(client.submit(
            _block_task, grid.n, grid.k, method, grid.axes, formula, data, lo, hi, threads, ident,
            check_cells=grid.check_request, key=session.key("block"), pure=False,
        ))
    if progress is not None:
        progress(f"extracting: 0/{len(futures)} blocks", 0.0)

    def on_done(done, total):
        if progress is not None:
            progress(f"extracting: {done}/{total} blocks", done / total)

    for result in _gather(session, futures, cancel, on_done):
        grid.add_records(result)
    if progress is not None:
        progress("assembling", 1.0)
    cx = grid.assemble()
    cx.meta["blocks"] = len(futures)
    cx.meta["block"] = block.tolist()
    return cx


# ----------------------------------------------------------------------------- continuation
def _process_wave(session, method, system, sampled, cancel, ident, grid, origins):
    """`process` hook of `continuation.run_continuation`: one wave's cubes (m, n) -> (masks (m,), nonfinite ids)."""
    m = len(origins)
    if m < LOCAL_WAVE:
        return grid.process_cubes(origins, system, sampled)
    client = session.client
    nchunks = max(1, min(2 * session.workers, m // MIN_CHUNK))
    formula = None if system is None else (tuple(system.texts), tuple(system.variables), system.params or None)
    data = session.sampled_for_tasks(whole=True)
    threads = session.kernel_threads()
    # scattered, not passed inline: a big wave's origins would make a large task graph (dask warns)
    chunks = client.scatter(np.array_split(origins, nchunks), hash=False)
    futures = [
        client.submit(_cubes_task, grid.n, grid.k, method, grid.axes, formula, data, chunk, threads, ident,
                      check_cells=grid.check_request, key=session.key("wave"), pure=False)
        for chunk in chunks
    ]
    masks, nonfinite = [], []
    for result in _gather(session, futures, cancel):
        grid.add_records(result)
        masks.append(result["masks"])
        nonfinite.append(result["nonfinite"])
    return np.concatenate(masks), np.concatenate(nonfinite)


# ----------------------------------------------------------------------------- on the workers
# A worker process may run several tasks at once (dask worker --nthreads > 1); numba's
# default threading layer must not be entered by two threads at once, so kernel work
# holds this lock (uncontended with one thread per worker, the recommended setup).
_KERNEL_LOCK = threading.Lock()


@functools.lru_cache(maxsize=4)
def _worker_sampled(path):
    return np.load(path, mmap_mode="r")


_GRIDS: dict = {}


def _worker_grid(n, k, method, axes, ident=None, check_cells=None):
    """A fresh `Grid` (empty parts, zero stats) copied from a per-process template
    (an `IdentifiedGrid` when ident gives identified axes)."""
    key = (n, k, method, tuple(a.tobytes() for a in axes), ident, check_cells)
    template = _GRIDS.get(key)
    if template is None:
        if len(_GRIDS) >= 4:
            _GRIDS.clear()
        template = _GRIDS[key] = _new_grid(n, k, axes, method, ident, check_cells)
    return template.empty_copy()


def _sampled_array(data):
    if isinstance(data, tuple) and data and data[0] == "npy":
        return _worker_sampled(data[1])
    return data


def _set_threads(per_host) -> None:
    """Numba threads for this task: this host's cores / the task threads its workers run."""
    import numba
    from distributed import get_worker
    from distributed.comm import get_address_host

    worker = get_worker()
    busy = per_host.get(get_address_host(worker.address), worker.state.nthreads)
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    # (numba.config sets its names at run time: mypy cannot see them)
    most = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]
    numba.set_num_threads(max(1, min(cores // max(busy, 1), most)))  # this thread only


def _block_task(n, k, method, axes, formula, data, lo, hi, threads, ident=None, check_cells=None) -> dict:
    """One block of cubes lo..hi-1 on a worker: F's values, candidates, kernel."""
    _set_threads(threads)
    grid = _worker_grid(n, k, method, axes, ident, check_cells)
    t = time.perf_counter()
    system = None if formula is None else parse_system(formula[0], formula[1], params=formula[2])
    sampled = _sampled_array(data)
    if isinstance(data, np.ndarray):  # a remote block's own slice
        values = sampled
    elif ident is not None:  # a seam's values are copies from the other side (`IdentifiedGrid.block_values`)
        values = grid.block_values(system, lo, hi)
    else:
        values = block_values(axes, system, sampled, lo, hi)
    grid.timings["evaluate"] += time.perf_counter() - t
    with _KERNEL_LOCK:
        grid.process_block(values, lo, hi)
    return grid.packed_records()


def _cubes_task(n, k, method, axes, formula, data, origins, threads, ident=None, check_cells=None) -> dict:
    """One chunk of a continuation wave on a worker."""
    _set_threads(threads)
    grid = _worker_grid(n, k, method, axes, ident, check_cells)
    system = None if formula is None else parse_system(formula[0], formula[1], params=formula[2])
    with _KERNEL_LOCK:
        masks, nonfinite = grid.process_cubes(origins, system, _sampled_array(data))
    out = grid.packed_records()
    out.update(masks=masks, nonfinite=nonfinite)
    return out
