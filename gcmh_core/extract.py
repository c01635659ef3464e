"""`extract`: the public entry point of the engine (GCMH over the whole grid).

public function (validates every argument)  ->  `_run_gcmh` (slabs, assembly)
->  `_kernels.cubes_chunk` (numba, one compile for all F, n and k; chunks side by side on threads).
"""

from __future__ import annotations

import re
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from math import factorial
from numbers import Integral, Real
from typing import Callable, Sequence

import numba
import numpy as np

from . import _kernels
from ._hashtable import IntTable
from ._tables import cube_tables, simplex_tables
from .complex import CellComplex, _frozen
from .errors import Cancelled, InputError
from .grid import PERTURBATION, candidate_corner_sets, candidate_origins, candidate_scan, perturbed_axes

METHODS = ("gcmh", "gcch", "cms", "ccs")
# continuation methods start from points and follow M; the others sweep the whole grid
CONTINUATION_METHODS = ("gcch", "ccs")
# the simplicial baselines (paper Section 4): marching simplices over the CFK triangulation
SIMPLICIAL_METHODS = ("cms", "ccs")

# Vertices evaluated per slab: bounds the memory of a run independently of div along axis 0.
_SLAB_VERTICES = 1 << 22


# ----------------------------------------------------------------------------- validation
def per_axis_ints(value, n: int, what: str) -> np.ndarray:
    """(n,) int64 from one positive integer (the same on every axis) or one per axis;
    a clear InputError naming `what` otherwise (bools, fractions, strings, wrong length)."""
    if isinstance(value, (Integral, np.integer)) and not isinstance(value, bool):
        value = [int(value)] * n
    try:
        if isinstance(value, (str, bytes)):
            raise TypeError
        items = list(value)
        if any(isinstance(v, bool) for v in items) or any(float(v) != int(v) for v in items):
            raise ValueError
        arr = [int(v) for v in items]
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} must be a positive integer or one per axis, got {value!r}") from None
    if len(arr) != n:
        raise InputError(f"{what} has {len(arr)} entries but there are n = {n} axes")
    for a, d in enumerate(arr):
        if d < 1:
            raise InputError(f"{what} must be at least 1 cube on every axis (axis {a + 1} has {d})")
    return np.array(arr, np.int64)


def _as_div(div, n: int) -> np.ndarray:
    return per_axis_ints(div, n, "div")


def _number(x, what: str) -> float:
    if isinstance(x, str):
        from .formula import evaluate_constant  # noqa: PLC0415  (numbers like "-pi/2", parsed safely)

        try:
            x = evaluate_constant(x)
        except InputError as err:
            raise InputError(f"{what}: {err}") from None
    if not isinstance(x, (Real, np.floating, np.integer)) or isinstance(x, bool):
        raise InputError(f"{what} must be a number, got {x!r}")
    x = float(x)
    if not np.isfinite(x):
        raise InputError(f"{what} must be finite, got {x}")
    return x


def _as_bounds(bounds, n: int) -> np.ndarray:
    if bounds is None:
        raise InputError("bounds are required: one (lo, hi) pair, or one per axis")
    if isinstance(bounds, np.ndarray):
        bounds = bounds.tolist()
    try:
        pairs = list(bounds)
    except TypeError:
        raise InputError(f"bounds must be (lo, hi) pairs, got {bounds!r}") from None
    if len(pairs) == 2 and not any(isinstance(p, (list, tuple, np.ndarray)) for p in pairs):
        pairs = [pairs] * n
    if len(pairs) == 1 and n > 1:
        pairs = pairs * n
    if len(pairs) != n:
        raise InputError(f"bounds has {len(pairs)} intervals but there are n = {n} axes")
    out = np.empty((n, 2))
    for a, pair in enumerate(pairs):
        if not isinstance(pair, (list, tuple, np.ndarray)) or len(pair) != 2:
            raise InputError(f"bounds for axis {a + 1} must be a (lo, hi) pair, got {pair!r}")
        lo = _number(pair[0], f"lower bound of axis {a + 1}")
        hi = _number(pair[1], f"upper bound of axis {a + 1}")
        if not lo < hi:
            raise InputError(f"axis {a + 1}: lower bound {lo:g} is not below upper bound {hi:g}")
        out[a] = lo, hi
    return out


def _infer_n(F, variables, bounds, div, n):
    if n is not None:
        return int(n)
    if variables is not None:
        return len(variables)
    if bounds is not None:
        b = bounds.tolist() if isinstance(bounds, np.ndarray) else bounds
        if isinstance(b, (list, tuple)) and b and isinstance(b[0], (list, tuple)) and len(b) > 1:
            return len(b)
    if isinstance(div, (list, tuple, np.ndarray)):
        return len(div)
    texts = [F] if isinstance(F, str) else list(F)
    indices = [int(m) for t in texts for m in re.findall(r"\bx(\d+)\b", str(t))]
    if indices:
        return max(indices)
    raise InputError("cannot tell n: give variables, one bounds pair per axis, or n")


def _prepare(F, variables, n, k, bounds, div):
    """Returns (n, k, bounds, div, system or None, sampled array or None)."""
    from .formula import System, parse_system  # noqa: PLC0415

    if isinstance(variables, str):
        variables = [v.strip() for v in variables.split(",")]
    if isinstance(F, np.ndarray) or (hasattr(F, "__array__") and not isinstance(F, (str, list, tuple))):
        values = np.asarray(F)
        if values.dtype.kind not in "fiu":
            raise InputError(f"sampled values must be numbers, got dtype {values.dtype}")
        if values.ndim < 2:
            raise InputError("sampled values must have shape (d1+1, ..., dn+1, k)")
        n_s = values.ndim - 1
        if n is not None and int(n) == values.ndim:  # (d1+1, ..., dn+1) with k = 1
            values = values[..., None]
            n_s = values.ndim - 1
        n_ = n_s
        k_ = values.shape[-1]
        if k is not None and int(k) != k_:
            raise InputError(f"sampled values have k = {k_} components, not {k}")
        shape_div = np.array(values.shape[:-1], np.int64) - 1
        if np.any(shape_div < 1):
            raise InputError(f"sampled values need at least 2 samples per axis, got shape {values.shape}")
        if div is not None and not np.array_equal(_as_div(div, n_), shape_div):
            raise InputError(f"div {div} does not match the sampled array's shape {values.shape}")
        if not 1 <= k_ < n_:
            raise InputError(f"need 1 <= k < n, got n = {n_}, k = {k_}")
        return n_, k_, _as_bounds(bounds, n_), shape_div, None, np.ascontiguousarray(values, np.float64)
    if isinstance(F, System):
        system = F
    else:
        if isinstance(F, str):
            F = [F]
        if not isinstance(F, (list, tuple)) or not all(isinstance(t, str) for t in F):
            raise InputError("F must be formula text, a list of formula texts, a System or an array of values")
        n_ = _infer_n(F, variables, bounds, div, n)
        system = parse_system(list(F), variables, n=n_, k=k)
    if n is not None and int(n) != system.n:
        raise InputError(f"n = {n} but the formulas have {system.n} variables")
    if k is not None and int(k) != system.k:
        raise InputError(f"k = {k} but there are {system.k} formulas")
    if not 1 <= system.k < system.n:
        raise InputError(f"need 1 <= k < n, got n = {system.n}, k = {system.k}")
    if div is None:
        div = 10
    return system.n, system.k, _as_bounds(bounds, system.n), _as_div(div, system.n), system, None


def estimate_work(n: int, k: int, div) -> dict:
    """Rough size of a full-grid run: cubes, and peak bytes of the slab buffers."""
    d = _as_div(div, n)
    cubes = int(np.prod(d.astype(np.float64)))
    layer = int(np.prod((d[1:] + 1).astype(np.float64)))
    per_slab = max(2 * layer, _SLAB_VERTICES)
    # values (8k bytes) + sign codes + candidate mask per slab vertex, plus output ~ M_A's size
    slab_bytes = per_slab * (8 * k + 16)
    out_bytes = int(cubes ** ((n - k) / n) * 2 ** (n - k) * (8 * n + 200)) if cubes else 0
    return dict(cubes=cubes, bytes=int(slab_bytes + out_bytes))


# ----------------------------------------------------------------------------- the run
def extract(
    F,
    bounds=None,
    div=None,
    *,
    variables: Sequence[str] | str | None = None,
    n: int | None = None,
    k: int | None = None,
    seed: int = 0,
    method: str = "gcmh",
    start=None,
    progress: Callable[[str, float], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    scheduler=None,
    block=None,
) -> CellComplex:
    """Approximate M = F^-1(0), F: R^n -> R^k, by a cell complex (GCMH).

    Parameters
    ----------
    F : str, sequence of str, formula.System, or ndarray (d1+1, ..., dn+1, k)
        The k components of F as formula text over the variables, or F's values
        sampled on the grid (then `div` comes from the array's shape).
    bounds : (lo, hi) or sequence of n (lo, hi)
        The domain box.
    div : int or sequence of n ints
        Grid cubes per axis (default 10; for sampled values, the array's shape).
    variables : names of the n variables (default x1..xn).
    seed : the grid perturbation's seed; same seed, same output bit for bit.
    method : "gcmh" (every cube of the grid) or "gcch" (continuation: only the cubes
        M passes through, reached from the start cubes; paper Section 5); "cms" and
        "ccs", the simplicial baselines the paper compares with (Section 4): marching
        simplices over the CFK triangulation of the grid (n! simplices per cube), over
        the whole grid or by continuation.  Same CellComplex, with many more cells.
    start : for "gcch" and "ccs": a point (n,), several points (m, n), or "auto" (default):
        each point is projected onto M by Gauss-Newton with F's exact Jacobian;
        "auto" projects a lattice of points and continues from each component found.
    progress : callable(phase, fraction), called between slabs.
    cancel : callable() -> bool, polled between slabs; True raises `Cancelled`.
    scheduler : None (this process), "local" (a dask LocalCluster sized to the machine)
        or a dask scheduler address "tcp://host:port": the grid is cut into blocks of
        cubes processed by the cluster's workers; the result is the same, bit for bit.
    block : cubes per block along each axis for `scheduler` (int or one per axis).

    Returns
    -------
    CellComplex with vertices (V, n) float64 and cells of every dimension 1..n-k; `meta`
    holds timings and counts.  After continuation, `processed_cubes` (m, n) int64 are the
    grid indices of every cube it visited (not saved by `save`).

    Examples
    --------
    >>> sphere = extract("x1^2 + x2^2 + x3^2 - 1", bounds=(-1.5, 1.5), div=16)
    >>> sphere.euler_characteristic()
    2
    """
    t0 = time.perf_counter()
    if method not in METHODS:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(METHODS)}")
    if isinstance(seed, bool) or not isinstance(seed, (Integral, np.integer)):
        raise InputError(f"seed must be an integer, got {seed!r}")
    if isinstance(div, (list, tuple)) and len(div) == 1:
        div = div[0]
    n_, k_, bounds_, div_, system, sampled = _prepare(F, variables, n, k, bounds, div)
    amplitude = 0.0 if sampled is not None else PERTURBATION  # sampled data can't be moved: its positions are exact
    axes = perturbed_axes(bounds_, div_, seed, amplitude)
    continuation = method in CONTINUATION_METHODS
    if continuation:
        starts = _as_starts("auto" if start is None else start, n_)
    elif start is not None:
        raise InputError(f"a start point is used by continuation only: pass method={' or '.join(map(repr, CONTINUATION_METHODS))}")
    else:
        starts = None
    if block is not None and scheduler is None:
        raise InputError("block is the block size of a distributed run: pass scheduler too")
    if scheduler is not None:
        from .distributed import run_distributed  # noqa: PLC0415  (dask is imported only when asked for)

        result = run_distributed(method, n_, k_, axes, bounds_, system, sampled, starts, scheduler, block, progress, cancel)
    elif continuation:
        result = _run_gcch(n_, k_, axes, bounds_, system, sampled, starts, progress, cancel, grid=_Grid(n_, k_, axes, method, cancel))
    else:
        result = _run_gcmh(n_, k_, axes, system, sampled, progress, cancel, grid=_Grid(n_, k_, axes, method, cancel))
    result.meta.update(
        method=method,
        div=div_.tolist(),
        bounds=bounds_.tolist(),
        seed=int(seed),
        formulas=list(system.texts) if system is not None else None,
        variables=list(system.variables) if system is not None else [f"x{i + 1}" for i in range(n_)],
        seconds=time.perf_counter() - t0,
    )
    return result


# Below this many cubes a kernel run stays in the calling thread: waking the thread
# pool costs milliseconds, which small continuation waves would pay hundreds of times.
_SERIAL_CUBES = 256
# Pieces a kernel run is cut into per thread (pieces of unequal cost even out).
_CHUNKS_PER_THREAD = 2
# Candidate cubes per kernel run: a run of the three-torus's costliest cubes takes
# about 0.2 s, so a cancel is answered within that.
_KERNEL_BATCH = 4096


_pool_lock = threading.Lock()
_pools: dict[int, ThreadPoolExecutor] = {}  # by size: numba's thread count is per thread


def _kernel_pool() -> ThreadPoolExecutor:
    """Threads that run kernel chunks side by side (the kernels release the GIL), as many
    as numba may use in the calling thread.  Pools are kept, never shut down: another
    thread may be mapping over one at any time."""
    want = numba.get_num_threads()
    with _pool_lock:
        pool = _pools.get(want)
        if pool is None:
            pool = _pools[want] = ThreadPoolExecutor(max_workers=want, thread_name_prefix="gcmh-kernel")
        return pool


class _Grid:
    """The grid's shape and the per-run constants every method needs, and the records
    its kernel runs have produced so far (`parts`), merged by `assemble`.

    method: "gcmh"/"gcch" run the hypercube kernel, "cms"/"ccs" the simplicial one.
    cancel: callable() -> bool, polled between kernel batches; True raises `Cancelled`.
    """

    def __init__(self, n, k, axes, method="gcmh", cancel=None):
        self.n, self.k, self.axes, self.cancel = n, k, axes, cancel
        self.simplicial = method in SIMPLICIAL_METHODS
        self.tab = cube_tables(n, k)
        self.dims = np.array([len(a) for a in axes], np.int64)  # vertices per axis
        self.strides = np.ones(n, np.int64)
        for a in range(n - 2, -1, -1):
            self.strides[a] = self.strides[a + 1] * self.dims[a + 1]
        self.corner_off = np.array(
            [sum(int(self.strides[a]) for a in range(n) if c >> a & 1) for c in range(1 << n)], np.int64
        )
        total = int(np.prod([int(d) for d in self.dims]))
        if self.simplicial:
            self.stab = simplex_tables(n, k)
            key_room = total * self.stab.key_base
        else:
            key_room = max(total * int(self.tab.n_subsets[d]) * int(self.tab.n_codes[d]) for d in range(k, n + 1))
        if key_room >= 2**63:
            raise InputError(f"the grid is too large to index ({total:,} vertices in R^{n}): use a smaller div")
        self.axes_arr = np.zeros((n, int(self.dims.max())))
        for a in range(n):
            self.axes_arr[a, : self.dims[a]] = axes[a]
        self.timings = dict(evaluate=0.0, candidates=0.0, kernel=0.0, assemble=0.0)
        self.stats = dict(candidate_cubes=0, cubes=int(np.prod(self.dims - 1)), nonfinite_vertices=0, degenerate=0)
        self.parts = dict(vk=[], vp=[], e=[], c=[], i=[])
        if self.simplicial:
            st = self.stab
            self.simplex_args = (st.start, st.corners, st.c0, st.code, st.facets, st.cube_facets, st.key_base, st.corner_mask)
        else:
            tab = self.tab
            self.cube_args = (
                tab.face_start, tab.face_free, tab.face_fixed, tab.face_rank, tab.n_subsets,
                tab.ksimp_corners, tab.ksimp_face, tab.ksimp_perm, factorial(k), tab.binom, tab.n_codes,
                tab.tmpl_corners, tab.tmpl_facets, tab.tmpl_interior, tab.n_boundary_nodes,
                tab.walk_corner_map, tab.walk_boundary_simplex, tab.ksimp_corner_mask, tab.kface_corner_mask,
                tab.k1face_corner_mask,
            )

    def run_kernel(self, values, cube_lin, origin, value_off) -> np.ndarray:
        """Process candidate cubes (in pieces side by side on the kernel threads); keep the records.

        values (NV, k); corner c of cube i is row cube_lin[i] + value_off[c].
        Returns each cube's crossed-facet mask (bit 2a + side).
        """
        m = len(cube_lin)
        if m > _KERNEL_BATCH:  # in batches: cancel is polled between them (records keep their order)
            return np.concatenate([
                self.run_kernel(values, cube_lin[i : i + _KERNEL_BATCH], origin[i : i + _KERNEL_BATCH], value_off)
                for i in range(0, m, _KERNEL_BATCH)
            ])
        if self.cancel is not None and self.cancel():
            raise Cancelled("extraction cancelled")
        t = time.perf_counter()
        cube_key = origin @ self.strides
        common = (values, cube_lin, origin, cube_key, self.axes_arr, value_off, self.corner_off, self.n, self.k)
        chunk, tables = (
            (_kernels.simplices_chunk, self.simplex_args) if self.simplicial else (_kernels.cubes_chunk, self.cube_args)
        )
        threads = numba.get_num_threads()
        pieces = 1 if m < _SERIAL_CUBES or threads == 1 else min(m, _CHUNKS_PER_THREAD * threads)
        cuts = [i * m // pieces for i in range(pieces + 1)]
        if pieces == 1:
            results = [chunk(0, m, *common, *tables)]
        else:
            results = list(_kernel_pool().map(lambda lo, hi: chunk(lo, hi, *common, *tables), cuts[:-1], cuts[1:]))
        for records, _, degenerate in results:
            for key, arr in zip(self.parts, records):
                self.parts[key].append(arr)
            self.stats["degenerate"] += int(degenerate)
        self.stats["candidate_cubes"] += m
        self.timings["kernel"] += time.perf_counter() - t
        return results[0][1] if pieces == 1 else np.concatenate([masks for _, masks, _ in results])

    def process_block(self, values, lo, hi, first_layer=None) -> np.ndarray:
        """The candidate cubes of the block of cubes lo..hi-1 (per axis, global indices).

        values (hi-lo+1 ..., k): F at the block's vertices.  Blocks may be processed in
        any order and on any machine: records carry global keys (see `_kernels`).
        first_layer: when values[0] is the previous block's last layer (slabs along
        axis 0), the codes this returned for it, so the candidate pass skips it.
        """
        lo = np.asarray(lo, np.int64)
        hi = np.asarray(hi, np.int64)
        values = np.ascontiguousarray(values, np.float64)
        t = time.perf_counter()
        origin, last_layer, nonfinite = candidate_scan(values, first_layer)
        if nonfinite:  # (rare: then count them; a vertex is counted by the block below it,
            # unless it is on the grid's last layer)
            owned = tuple(slice(None) if hi[a] == self.dims[a] - 1 else slice(None, -1) for a in range(self.n))
            self.stats["nonfinite_vertices"] += int(np.count_nonzero(~np.isfinite(values[owned]).all(axis=-1)))
        self.timings["candidates"] += time.perf_counter() - t
        if len(origin) == 0:
            return last_layer
        block_dims = np.array(values.shape[:-1], np.int64)
        block_strides = np.ones(self.n, np.int64)
        for a in range(self.n - 2, -1, -1):
            block_strides[a] = block_strides[a + 1] * block_dims[a + 1]
        value_off = np.array(
            [sum(int(block_strides[a]) for a in range(self.n) if c >> a & 1) for c in range(1 << self.n)], np.int64
        )
        cube_lin = origin @ block_strides
        origin += lo
        self.run_kernel(values.reshape(-1, self.k), cube_lin, origin, value_off)
        return last_layer

    def process_cubes(self, origins, system, sampled) -> tuple[np.ndarray, np.ndarray]:
        """The given cubes (m, n) alone: F at their corners only (one vectorised batch).

        Returns each cube's crossed-facet mask (0 where M_A misses it) and the
        global ids of the corners where F is not finite.
        """
        n, k = self.n, self.k
        t = time.perf_counter()
        corners = (origins @ self.strides)[:, None] + self.corner_off[None]  # (m, 2^n) global vertex ids
        # each vertex once (a small hash table per wave: faster than sorting, any order will do)
        ids = corners.reshape(-1)
        inverse, first = IntTable(capacity=2 * len(ids)).insert(ids)
        uniq = ids[first]
        if sampled is not None:
            uvals = sampled.reshape(-1, k)[uniq]
        else:
            multi = np.unravel_index(uniq, tuple(self.dims))
            uvals = system.evaluate_points(np.stack([self.axes[a][multi[a]] for a in range(n)], axis=1))
        if np.isfinite(uvals).all():  # (the common case, in one contiguous pass)
            nonfinite = uniq[:0]
        else:
            nonfinite = uniq[~np.isfinite(uvals).all(axis=1)]
        values = np.ascontiguousarray(uvals[inverse], np.float64)
        self.timings["evaluate"] += time.perf_counter() - t
        t = time.perf_counter()
        cand = candidate_corner_sets(values, 1 << n)
        self.timings["candidates"] += time.perf_counter() - t
        idx = np.nonzero(cand)[0]
        masks = np.zeros(len(origins), np.int64)
        if len(idx):
            value_off = np.arange(1 << n, dtype=np.int64)
            masks[idx] = self.run_kernel(values, idx.astype(np.int64) << n, origins[idx], value_off)
        return masks, nonfinite

    def assemble(self) -> CellComplex:
        t = time.perf_counter()
        n, k = self.n, self.k
        widths = dict(vk=None, vp=n, e=_kernels.EDGE_COLS, c=_kernels.CELL_COLS, i=_kernels.INC_COLS)
        cat = {
            key: np.concatenate(arrs) if arrs else np.zeros((0,) if w is None else (0, w), np.float64 if key == "vp" else np.int64)
            for (key, arrs), w in zip(self.parts.items(), widths.values())
        }
        cx = _assemble(n, k, cat["vk"], cat["vp"], cat["e"], cat["c"], cat["i"])
        self.timings["assemble"] = time.perf_counter() - t
        cx.meta.update(self.stats)
        cx.meta["timings"] = self.timings
        return cx


def _run_gcmh(n, k, axes, system, sampled, progress, cancel, grid=None) -> CellComplex:
    """Every cube of the grid, in slabs along axis 0 (F on one slab's vertices at a time)."""
    grid = _Grid(n, k, axes) if grid is None else grid
    dims = grid.dims
    layer = int(np.prod(dims[1:]))
    thickness = int(max(1, min(dims[0] - 1, _SLAB_VERTICES // max(layer * k, 1))))
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


def block_values(axes, system, sampled, lo, hi) -> np.ndarray:
    """F at the vertices of the block of cubes lo..hi-1 (per axis): (hi-lo+1 ..., k)."""
    if sampled is not None:
        return sampled[tuple(slice(int(a), int(b) + 1) for a, b in zip(lo, hi))]
    return system.evaluate_grid([ax[int(a) : int(b) + 1] for ax, a, b in zip(axes, lo, hi)])


# ----------------------------------------------------------------------------- continuation (GCCH)
_NEWTON_STEPS = 50


def _project_onto_M(system, x0: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """Gauss-Newton x <- x - J^+ F(x) with sympy's exact Jacobian; a clear error when it fails."""
    x = np.array(x0, np.float64)
    scale = float(np.max(bounds[:, 1] - bounds[:, 0]))
    where = "(" + ", ".join(f"{v:g}" for v in x0) + ")"
    for _ in range(_NEWTON_STEPS):
        F = system.evaluate_points(x[None])[0]
        if not np.all(np.isfinite(F)):
            raise InputError(f"start point {where}: F is not finite near ({', '.join(f'{v:g}' for v in x)})")
        if np.linalg.norm(F) <= 1e-12 * max(1.0, scale):
            break
        J = system.jacobian_points(x[None])[0]
        if not np.all(np.isfinite(J)):
            raise InputError(f"start point {where}: the Jacobian of F is not finite there")
        x = x - np.linalg.lstsq(J, F, rcond=None)[0]
        if np.any(x < bounds[:, 0] - 1e-9 * scale) or np.any(x > bounds[:, 1] + 1e-9 * scale):
            raise InputError(f"start point {where}: Newton's projection onto M left the domain")
    else:
        F = system.evaluate_points(x[None])[0]
        if not np.linalg.norm(F) <= 1e-8 * max(1.0, scale):
            raise InputError(
                f"start point {where}: Newton's projection onto M did not converge in {_NEWTON_STEPS} steps "
                f"(|F| = {np.linalg.norm(F):.3g}); try a point closer to M"
            )
    return x


def _as_starts(start, n: int) -> list | str:
    if isinstance(start, str):
        if start.strip().lower() == "auto":
            return "auto"
        raise InputError(f"start must be a point, a list of points or 'auto', got {start!r}")
    try:
        arr = np.array(start, np.float64)
    except (TypeError, ValueError):
        raise InputError(f"start must be a point of {n} numbers, a list of points or 'auto', got {start!r}") from None
    if arr.ndim == 1:
        arr = arr[None]
    if arr.ndim != 2 or arr.shape[1] != n or len(arr) == 0:
        raise InputError(f"a start point needs {n} coordinates, got {start!r}")
    if not np.all(np.isfinite(arr)):
        raise InputError("start point coordinates must be finite")
    return list(arr)


def _cube_of(axes, x) -> np.ndarray:
    return np.array(
        [min(max(int(np.searchsorted(ax, v, side="right")) - 1, 0), len(ax) - 2) for ax, v in zip(axes, x)], np.int64
    )


def _start_cubes(n, axes, bounds, system, sampled, starts) -> np.ndarray:
    """Origins (m, n) of the cubes to start from."""
    if starts == "auto":
        if system is None:  # no Jacobian for sampled data: start from every cube that crosses M
            return candidate_origins(sampled)[0]
        # project a spread of points (a coarse 5^n lattice, capped) onto M
        per_axis = max(2, min(5, int(round(4096 ** (1.0 / n)))))
        lattice = np.stack(
            np.meshgrid(*[np.linspace(lo, hi, per_axis + 2)[1:-1] for lo, hi in bounds], indexing="ij"), -1
        ).reshape(-1, n)
        origins = []
        for x0 in lattice:
            try:
                origins.append(_cube_of(axes, _project_onto_M(system, x0, bounds)))
            except InputError:
                continue
        if not origins:
            raise InputError("start='auto' found no point of M in the domain")
        return np.unique(np.array(origins), axis=0)
    origins = []
    for x0 in starts:
        outside = [a + 1 for a in range(n) if not bounds[a, 0] <= x0[a] <= bounds[a, 1]]
        if outside:
            raise InputError(f"start point ({', '.join(f'{v:g}' for v in x0)}) is outside the domain on axis {outside[0]}")
        x = x0 if system is None else _project_onto_M(system, x0, bounds)
        origins.append(_cube_of(axes, x))
    return np.unique(np.array(origins), axis=0)


def _run_gcch(n, k, axes, bounds, system, sampled, starts, progress, cancel, grid=None, process=None) -> CellComplex:
    """Continuation: process only cubes reached from the start cubes across crossed facets.

    Each wave (the cubes first reached in the same step) is one batch: F at its
    corners in one vectorised call, then one kernel run.  `grid` (a `_Grid`) and
    `process(grid, origins) -> (masks, nonfinite ids)` let another executor run
    the waves (gcmh_core.distributed); by default `grid.process_cubes` runs them here.
    """
    grid = _Grid(n, k, axes) if grid is None else grid
    if process is None:
        def process(g, origins):
            return g.process_cubes(origins, system, sampled)
    div = grid.dims - 1
    cube_strides = np.ones(n, np.int64)
    for a in range(n - 2, -1, -1):
        cube_strides[a] = cube_strides[a + 1] * div[a + 1]
    visited = IntTable()

    def unvisited(cubes):  # the cubes not seen before, each once; they count as seen now
        cubes = cubes[np.all((cubes >= 0) & (cubes < div), axis=1)]
        return cubes[visited.insert(cubes @ cube_strides)[1]]

    nonfinite = []
    wave = unvisited(_start_cubes(n, axes, bounds, system, sampled, starts))
    expanded_start = False
    n_waves = 0
    while len(wave):
        if cancel is not None and cancel():
            raise Cancelled("extraction cancelled")
        n_waves += 1
        if progress is not None:
            progress(f"continuation: wave {n_waves}, {len(visited):,} cubes", min(0.99, 1 - 1 / (1 + 0.01 * n_waves)))
        masks, bad = process(grid, wave)
        nonfinite.append(bad)
        if not masks.any() and not expanded_start:
            # the start cube held no piece of M_A (M grazes it): try its neighbourhood once
            expanded_start = True
            around = np.array(np.meshgrid(*[[-1, 0, 1]] * n, indexing="ij")).reshape(n, -1).T
            wave = unvisited((wave[:, None, :] + around[None]).reshape(-1, n))
            continue
        expanded_start = True
        cubes, keys = _kernels.facet_neighbours(wave, masks, div, cube_strides)
        wave = cubes[visited.insert(keys)[1]]  # (in any order: the output does not depend on it)
    if starts != "auto" and not any(len(v) for v in grid.parts["vk"]):
        # (with "auto" an empty result is an answer: M does not cross the domain)
        raise InputError(
            "M_A does not pass through the start cube(s) or their neighbours: "
            + ("give a point in a grid cube where every component of F changes sign" if system is None
               else "the projected start point lies where M grazes the grid; try another start point or div")
        )
    if progress is not None:
        progress("assembling", 1.0)
    grid.stats["nonfinite_vertices"] = len(_unique_first(np.concatenate(nonfinite))[0]) if nonfinite else 0
    grid.stats["visited_cubes"] = len(visited)
    grid.stats["waves"] = n_waves
    cx = grid.assemble()
    # the continuation's path, for showing how it went (an attribute: not saved with the complex)
    processed = np.sort(visited.keys())
    cx.processed_cubes = _frozen(np.stack(np.unravel_index(processed, tuple(div)), axis=1).astype(np.int64).reshape(-1, n))
    return cx


# ----------------------------------------------------------------------------- assembly
def _unique_first(keys: np.ndarray):
    """Sorted unique keys and the index of each one's first occurrence (sort-based: fast on int64)."""
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    keep = np.ones(len(sk), bool)
    keep[1:] = sk[1:] != sk[:-1]
    return sk[keep], order[keep]


def _assemble(n, k, vk, vp, e, c, inc) -> CellComplex:
    """Identify what neighbouring cubes emitted twice and build the CellComplex.

    Every entity carries a key computed from grid indices alone (see `_kernels`);
    ids in the result follow the sorted keys, so the output does not depend on
    the order in which cubes, slabs or threads produced it.
    """
    vkeys, first = _unique_first(vk)
    vertices = np.ascontiguousarray(vp[first])
    keys = {1: _unique_first(e[:, 0])}
    edges = np.searchsorted(vkeys, e[keys[1][1], 1:3]).astype(np.int64)
    cells = {}
    for r in range(2, n - k + 1):
        keys[r] = _unique_first(c[c[:, 0] == r, 1])
        rows = inc[inc[:, 0] == r]
        x = np.searchsorted(keys[r][0], rows[:, 1])
        y = np.searchsorted(keys[r - 1][0], rows[:, 2])
        n_lower = max(len(keys[r - 1][0]), 1)
        pairs = np.sort(x.astype(np.int64) * n_lower + y)
        keep = np.ones(len(pairs), bool)
        keep[1:] = pairs[1:] != pairs[:-1]
        pairs = pairs[keep]
        offsets = np.zeros(len(keys[r][0]) + 1, np.int64)
        np.cumsum(np.bincount(pairs // n_lower, minlength=len(keys[r][0])), out=offsets[1:])
        cells[r] = (offsets, (pairs % n_lower).astype(np.int64))
    return CellComplex(n, k, vertices, edges, cells)
