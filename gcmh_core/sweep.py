"""The full sweep: every cube of the grid (GCMH, paper Section 3; CMS, Section 4).

Plain: F is evaluated slab by slab along axis 0, so memory grows like div^(n-1);
each slab goes through the candidate pass (a cube where some component of F has
one strict sign at all 2^n corners cannot hold M) and the candidates through the
per-cube kernel of the `Grid` (hypercube cells for "gcmh", Kuhn simplices for "cms").

Pruned (when F is a formula): the grid's box of cubes is cut in halves, longest axis
first; a block where the interval enclosure of some component of F (`interval`)
excludes 0 holds no candidate cube and is dropped unevaluated, and the blocks left
when they are small (shrunk to what one more cut leaves) are processed exactly like
slabs, on as many threads as numba may use.  The work then grows with the
size of M rather than with div^n, and the complex is the plain sweep's, bit for bit:
a dropped block would have given the candidate pass nothing (no candidate, no
non-finite vertex), and the others give the same values and the same records.

n = 3, k = 1 (GCMH, no periodic axes): the marching pass (`kernels.marching3`) instead, F in
thin slabs, the complex written in its final order in one pass over the grid's layers;
the same bytes as the general path, which it hands over to when a value is not finite.

Periodic axes (an `identify.IdentifiedGrid`): the grid's own sweep, never pruned.
"""

from __future__ import annotations

import threading
import time
import weakref
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from .complex import CellComplex
from .errors import Cancelled
from .identify import IdentifiedGrid
from .interval import Enclosure
from .runner import Grid, complex_of

__all__ = ["run_sweep", "surviving_blocks", "enclosure_of", "SLAB_VERTICES", "PRUNE", "MARCHING3"]

# Vertices evaluated per slab: bounds the memory of a run independently of div along axis 0.
SLAB_VERTICES = 1 << 22
# None: prune when F is a formula and the grid has at least _PRUNE_MIN_CUBES cubes;
# True / False force either path (tests compare them).
PRUNE: bool | None = None
_PRUNE_MIN_CUBES = 1 << 16  # (below, the plain sweep takes a few milliseconds)
# Cubes of a block that is processed rather than cut again: smaller blocks are
# bounded more tightly, but each processed block costs a fixed ~0.1 ms of calls.
# Measured on the complex cosine at div 320 (blocks on one thread): 256 cubes 6.4 s,
# 1024 3.5 s, 4096 2.5 s, 16384 2.2 s; on two threads 2048..16384 within the noise.
_LEAF_CUBES = 4096
# Blocks per task of the threads that process them (progress and cancel between tasks).
_BLOCKS_PER_TASK = 128
# Sweep plainly when the blocks left have more vertices than this share of the grid's:
# F's bounds did not help (M fills the domain, or F has a function they cannot bound).
_GIVE_UP_SHARE = 0.5
# ... or when more blocks than this are left at one step of the cutting (their bounds
# would cost more than they save; the complex cosine at div 320 leaves 9,000)
_MAX_BLOCKS = 1 << 20
# Blocks bounded in one vectorised call (memory: a few (m,) arrays per node of F).
_BOUND_CHUNK = 1 << 16

# Vertices per slab of the marching pass: F's values and the pass's reading of them stay
# in the cache (the axis-0 slabs leave each row's values unchanged: same values as the
# plain sweep's).
MARCH_SLAB_VERTICES = 1 << 18
# A thread keeps each work array of the marching pass up to this size for its next run
# (at div 256: the values 2 MB, the ring buffers 14 MB).
_SCRATCH_KEEP_BYTES = 16 << 20
_scratch_arrays = threading.local()
# None: GCMH for n = 3, k = 1 takes the marching pass (`kernels.marching3`) unless PRUNE is True;
# False: never (tests compare it with the general path).  Periodic axes never take it.
MARCHING3: bool | None = None

_enclosures: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def enclosure_of(system) -> Enclosure | None:
    """One Enclosure per System (the tree is walked once); None if the tree defeats it
    (then the plain sweep runs: the bound is an optimisation, never a requirement)."""
    if system not in _enclosures:
        try:
            _enclosures[system] = Enclosure(system.exprs, system.symbols)
        except (RecursionError, TypeError, ValueError, ArithmeticError):
            _enclosures[system] = None
    return _enclosures[system]


def run_sweep(n, k, axes, system, sampled, progress, cancel, grid=None) -> CellComplex:
    """Every cube of the grid: for n = 3, k = 1 in one marching pass (see MARCHING3);
    else pruned by F's bounds when F is a formula and the grid is large (see PRUNE), else
    in slabs along axis 0.  Same complex every way."""
    grid = Grid(n, k, axes) if grid is None else grid
    grid.set_source(system, sampled)
    if isinstance(grid, IdentifiedGrid):  # periodic axes: F's values on a seam are copies, not bounds
        return grid.sweep(system, progress, cancel)
    marching = MARCHING3
    if marching is None:
        marching = PRUNE is not True
    if marching and (grid.n, grid.k) == (3, 1) and not grid.simplicial:
        result = _marching_sweep(grid, axes, system, sampled, progress, cancel)
        if result is not None:
            return result
        grid.timings = dict.fromkeys(grid.timings, 0.0)  # (a value the pass can't take: the general path)
    prune = PRUNE
    if prune is None:
        prune = grid.stats["cubes"] >= _PRUNE_MIN_CUBES
    if prune and system is not None and sampled is None:
        result = _pruned_sweep(grid, axes, system, progress, cancel)
        if result is not None:
            return result
    return _plain_sweep(grid, axes, system, sampled, progress, cancel)


def _plain_sweep(grid, axes, system, sampled, progress, cancel) -> CellComplex:
    """Every cube of the grid, in slabs along axis 0 (F on one slab's vertices at a time)."""
    n, k = grid.n, grid.k
    dims = grid.dims
    layer = int(np.prod(dims[1:]))
    thickness = int(max(1, min(dims[0] - 1, SLAB_VERTICES // max(layer * k, 1))))
    # one buffer for every slab's values: a fresh array per slab cost more in page
    # faults (first touch) than evaluating F into it
    buffer = None if sampled is not None else np.empty((thickness + 1, *(int(d) for d in dims[1:]), k))
    values = None
    codes = None  # the candidate pass's codes of the slab's first layer (the last one's last)
    n_slabs = -(-(int(dims[0]) - 1) // thickness)
    lo = np.zeros(n, np.int64)
    hi = dims - 1
    for si, i0 in enumerate(range(0, int(dims[0]) - 1, thickness)):
        if cancel is not None and cancel():
            raise Cancelled("extraction cancelled")
        if progress is not None:
            progress("extracting", si / n_slabs)
        i1 = min(i0 + thickness, int(dims[0]) - 1)  # cubes i0..i1-1, vertex layers i0..i1
        lo[0], hi[0] = i0, i1
        t = time.perf_counter()
        if sampled is not None:
            values = sampled[i0 : i1 + 1]
        else:  # the slab's first layer is the previous slab's last: evaluate it once
            assert buffer is not None  # (made when nothing is sampled)
            if values is not None:
                buffer[0] = values[-1]
            values = buffer[: i1 - i0 + 1]
            first = 0 if si == 0 else 1
            system.evaluate_grid([axes[0][i0 + first : i1 + 1]] + list(axes[1:]), out=values[first:])
        grid.timings["evaluate"] += time.perf_counter() - t
        codes = grid.process_block(values, lo, hi, codes)
    if progress is not None:
        progress("assembling", 1.0)
    return grid.assemble()


def _marching_sweep(grid, axes, system, sampled, progress, cancel) -> CellComplex | None:
    """`_march`, with the thread's kept work arrays marked as in use meanwhile."""
    busy = getattr(_scratch_arrays, "busy", False)
    try:
        return _march(grid, axes, system, sampled, progress, cancel)
    finally:
        _scratch_arrays.busy = busy


def _march(grid, axes, system, sampled, progress, cancel) -> CellComplex | None:
    """n = 3, k = 1: F slab by slab along axis 0 as in `_plain_sweep` (thinner slabs: each
    row of values is computed alike, so the values are the same), each slab through
    `kernels.marching3.march_layers`, which writes the complex in its final order.  None when a
    value is not finite or a difference overflows (the general path then runs: it
    counts and skips such vertices), and when M_A joins two pieces of G_H through a cube
    (the general path splits those cells: rare, and found in the first slab that has one)."""
    from .kernels import marching3 as _marching3  # (compiled on first use only)

    cases = _marching3.cube_cases()
    d0, d1, d2 = (int(d) for d in grid.dims)
    thickness = int(max(1, min(d0 - 1, MARCH_SLAB_VERTICES // (d1 * d2))))
    buffer = None if sampled is not None else _scratch("values", (thickness + 1, d1, d2, 1), np.float64)
    # the pass's ring buffers (see march_layers)
    sg = _scratch("sg", (4, d1, -(-d2 // 64)), np.uint64)
    rowc = _scratch("rowc", (4, d1), np.uint8)
    vid = _scratch("vid", (3, d1, d2, 3), np.int64)
    eid = _scratch("eid", (3, d1, d2, 3, 2), np.int64)
    _scratch_arrays.busy = True  # (until this run ends: a run started by a callback gets its own)
    # (room for a surface crossing the grid twice, and for the last layer's steps: memory
    # is only touched where written)
    room = 2 * (d0 * d1 + d1 * d2 + d0 * d2) + 64
    last = [3 * r for r in _marching3.room_per_layer(d1, d2)]
    vert = np.empty((room + last[0], 3))
    edges = np.empty((2 * room + last[1], 2), np.int64)
    offsets = np.zeros(room + last[2] + 1, np.int64)
    faces = np.empty(4 * room + last[3], np.int64)
    counts = np.zeros(7, np.int64)
    tables = (cases.square_edges, cases.square_count, cases.cube_pieces, cases.cube_nonball, cases.piece_start,
              cases.piece_face)
    values = None
    n_slabs = -(-(d0 - 1) // thickness)
    for si, i0 in enumerate(range(0, d0 - 1, thickness)):
        if cancel is not None and cancel():
            raise Cancelled("extraction cancelled")
        if progress is not None:
            progress("extracting", si / n_slabs)
        i1 = min(i0 + thickness, d0 - 1)
        t = time.perf_counter()
        if sampled is not None:
            values = np.ascontiguousarray(sampled[i0 : i1 + 1, :, :, 0], np.float64)
        else:
            assert buffer is not None  # (made when nothing is sampled)
            if values is not None:
                buffer[0] = values[-1]
            values = buffer[: i1 - i0 + 1]
            first = 0 if si == 0 else 1
            system.evaluate_grid([axes[0][i0 + first : i1 + 1]] + list(axes[1:]), out=values[first:])
        t2 = time.perf_counter()
        grid.timings["evaluate"] += t2 - t
        layer = 0 if si == 0 else i0 + 1
        while layer <= i1:
            layer = _marching3.march_layers(values[..., 0] if sampled is None else values, i0, layer, i1, d0,
                                            grid.axes_arr, sg, rowc, vid, eid, vert, edges, offsets, faces, counts,
                                            *tables)
            if layer <= i1:  # out of room: twice the arrays, or what the last layer's steps need
                vert = _grown(vert, int(counts[0]) + last[0])
                edges = _grown(edges, int(counts[1]) + last[1])
                offsets = _grown(offsets, int(counts[2]) + last[2] + 1)
                faces = _grown(faces, int(counts[3]) + last[3])
        grid.timings["kernel"] += time.perf_counter() - t2
        if counts[6] != _marching3.OK or counts[5]:  # (a cell that is not a ball: `_balls` splits it there)
            return None
    if progress is not None:
        progress("assembling", 1.0)
    t = time.perf_counter()
    nv, ne, nc, nf = (int(c) for c in counts[:4])
    grid.stats["candidate_cubes"] += int(counts[4])
    grid.stats["non_ball_cells"] += int(counts[5])
    cx = complex_of(3, 1, vert[:nv], edges[:ne], {2: (offsets[: nc + 1], faces[:nf])})
    grid.timings["assemble"] = time.perf_counter() - t
    cx.meta.update(grid.stats)
    cx.meta["non_ball_left"] = 0  # (the pass stops at the first: the general path splits them)
    cx.meta["cells_checked"] = grid.check_cells  # (surfaces: False, as on the general path)
    cx.meta["timings"] = grid.timings
    return cx


def _scratch(name: str, shape: tuple, dtype) -> np.ndarray:
    """A work array of the marching pass, kept by the calling thread for its next run when
    small (first touching fresh pages cost more than a small grid's whole pass)."""
    size = int(np.prod(shape))
    if getattr(_scratch_arrays, "busy", False):  # (a run inside a run's callback: its own arrays)
        return np.empty(shape, dtype)
    kept = getattr(_scratch_arrays, name, None)
    if kept is not None and kept.dtype == dtype and kept.size >= size:
        return kept[:size].reshape(shape)
    array = np.empty(size, dtype)
    if array.nbytes <= _SCRATCH_KEEP_BYTES:
        setattr(_scratch_arrays, name, array)
    return array.reshape(shape)


def _grown(a: np.ndarray, need: int) -> np.ndarray:
    """a with at least `need` rows (twice as many, or need), the first rows kept."""
    if len(a) >= need:
        return a
    b = np.zeros((max(2 * len(a), need), *a.shape[1:]), a.dtype)
    b[: len(a)] = a
    return b


def surviving_blocks(enclosure, axes, lo, hi, leaf_cubes, cancel=None, max_blocks=None):
    """The blocks of at most leaf_cubes cubes that F's bounds leave in the block of cubes
    lo..hi-1 (per axis): (lo, hi) (m, n) int64; None if more than max_blocks are left
    at some step (F's bounds do not help, or M is large at that scale).

    Blocks are cut in halves, longest axis (in cubes) first; a block where `enclosure`
    shows some component of F to have one sign throughout (so no cube in it is a
    candidate) is dropped.
    """
    n = len(axes)
    blo = np.asarray(lo, np.int64).reshape(1, n)
    bhi = np.asarray(hi, np.int64).reshape(1, n)
    leaves_lo, leaves_hi = [], []
    while len(blo):
        if cancel is not None and cancel():
            raise Cancelled("extraction cancelled")
        if max_blocks is not None and len(blo) > max_blocks:
            return None
        keep = np.empty(len(blo), bool)
        for i in range(0, len(blo), _BOUND_CHUNK):  # (the bound's temporaries: a few per node)
            xlo = np.stack([axes[a][blo[i : i + _BOUND_CHUNK, a]] for a in range(n)], axis=1)
            xhi = np.stack([axes[a][bhi[i : i + _BOUND_CHUNK, a]] for a in range(n)], axis=1)
            keep[i : i + _BOUND_CHUNK] = ~enclosure.excludes_zero(xlo, xhi)
        blo, bhi = blo[keep], bhi[keep]
        leaf = np.prod(bhi - blo, axis=1) <= leaf_cubes
        leaves_lo.append(blo[leaf])
        leaves_hi.append(bhi[leaf])
        blo, bhi = blo[~leaf], bhi[~leaf]
        side = bhi - blo
        axis = np.argmax(side, axis=1)
        rows = np.arange(len(blo))
        mid = blo[rows, axis] + side[rows, axis] // 2
        lo2, hi1 = blo.copy(), bhi.copy()
        hi1[rows, axis] = mid
        lo2[rows, axis] = mid
        blo = np.concatenate([blo, lo2])
        bhi = np.concatenate([hi1, bhi])
    return np.concatenate(leaves_lo), np.concatenate(leaves_hi)


def _shrink(enclosure, axes, blo, bhi):
    """Each block cut once more, in halves along every axis of 2 cubes or more, and
    replaced by the bounding box of the pieces F's bounds leave (blocks with none
    are dropped): about half the vertices to evaluate, for one more bound per piece.

    Exact like the cutting: a candidate cube lies in one piece, which is left; a vertex
    the smaller block no longer owns (its new upper faces) is in a dropped piece, so finite.
    """
    m, n = blo.shape
    side = bhi - blo
    mid = blo + side // 2
    bits = (np.arange(1 << n)[:, None] >> np.arange(n)[None]) & 1  # (2^n, n)
    split = side[:, None, :] >= 2
    clo = np.where(split & (bits[None] == 1), mid[:, None, :], blo[:, None, :])
    chi = np.where(split & (bits[None] == 0), mid[:, None, :], bhi[:, None, :])
    real = ~np.any(~split & (bits[None] == 1), axis=2)  # (an unsplit axis: one piece, not two)
    owner = np.broadcast_to(np.arange(m)[:, None], real.shape)[real]
    clo, chi = clo[real], chi[real]
    keep = np.empty(len(clo), bool)
    for i in range(0, len(clo), _BOUND_CHUNK):
        xlo = np.stack([axes[a][clo[i : i + _BOUND_CHUNK, a]] for a in range(n)], axis=1)
        xhi = np.stack([axes[a][chi[i : i + _BOUND_CHUNK, a]] for a in range(n)], axis=1)
        keep[i : i + _BOUND_CHUNK] = ~enclosure.excludes_zero(xlo, xhi)
    owner, clo, chi = owner[keep], clo[keep], chi[keep]
    if not len(owner):
        return clo, chi
    starts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])  # (pieces stay grouped by block)
    return np.minimum.reduceat(clo, starts, axis=0), np.maximum.reduceat(chi, starts, axis=0)


def _pruned_sweep(grid, axes, system, progress, cancel) -> CellComplex | None:
    """The blocks F's bounds leave, each processed like a slab; None when the bounds
    leave most of the grid (then the plain sweep is faster)."""
    n = grid.n
    t = time.perf_counter()
    enclosure = enclosure_of(system)
    if enclosure is None:
        return None
    blocks = surviving_blocks(enclosure, axes, np.zeros(n, np.int64), grid.dims - 1, _LEAF_CUBES, cancel,
                              max_blocks=_MAX_BLOCKS)
    if blocks is None:
        return None
    blo, bhi = _shrink(enclosure, axes, *blocks)
    bound_seconds = time.perf_counter() - t
    # the blocks' vertices (shared faces count once per block) against the grid's
    if np.prod(bhi - blo + 1, axis=1).sum() > _GIVE_UP_SHARE * np.prod(grid.dims.astype(np.float64)):
        return None
    grid.timings["bound"] = bound_seconds
    size = np.prod(bhi - blo, axis=1)
    total = grid.stats["cubes"]
    kept = int(size.sum())
    decided = total - kept  # (the dropped cubes)
    stop = threading.Event()
    template = grid.empty_copy()  # (empty_copy keeps the stats: start each part from zero)
    template.stats = {key: value if key == "cubes" else 0 for key, value in grid.stats.items()}

    def work(lo_rows, hi_rows):
        """Blocks on a copy of the grid, numba serial in this thread: a small block's
        candidate pass took ~3 ms waking numba's parallel threads, 30 times the pass."""
        numba.set_num_threads(1)
        part = template.empty_copy()
        for lo, hi in zip(lo_rows, hi_rows):
            if stop.is_set():
                break
            t = time.perf_counter()
            values = system.evaluate_grid([axes[a][lo[a] : hi[a] + 1] for a in range(n)])
            part.timings["evaluate"] += time.perf_counter() - t
            part.process_block(values, lo, hi)
        return part.packed_records()

    workers = numba.get_num_threads()  # (the caller's: 1 in a distributed worker, say)
    cuts = list(range(0, len(blo), _BLOCKS_PER_TASK)) + [len(blo)]
    with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="gcmh-pruned") as pool:
        futures = [pool.submit(work, blo[i:j], bhi[i:j]) for i, j in zip(cuts[:-1], cuts[1:])]
        try:
            for f, i, j in zip(futures, cuts[:-1], cuts[1:]):
                if progress is not None:
                    progress("extracting", decided / total)
                if cancel is not None and cancel():
                    raise Cancelled("extraction cancelled")
                grid.add_records(f.result())
                decided += int(size[i:j].sum())
        finally:  # (after a cancel or an error: tasks not started are dropped, the others
            stop.set()  # end at their next block)
            for f in futures:
                f.cancel()
    if progress is not None:
        progress("assembling", 1.0)
    result = grid.assemble()
    result.meta["pruned_cubes"] = total - kept
    return result
