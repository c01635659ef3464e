"""The grid runner: the records every method's kernel runs produce, and their assembly.

`Grid` holds the grid's shape and the per-run constants (cube or simplex tables,
strides, the corner offsets of a cube), runs the per-cube kernels on batches of
candidate cubes (`run_kernel`, side by side on threads), and keeps what they emit:
vertices keyed by (global k-face, Kuhn simplex), edges keyed by their global
(k+1)-face, r-cells and their incidences.  `assemble` identifies what neighbouring
cubes emitted twice (paper Theorem 3.4: the keys come from grid indices alone) and
builds the CellComplex.

Who drives it: `sweep.run_sweep` (every cube, slab by slab), `continuation.run_continuation`
(the waves of cubes M passes through) and `distributed` (blocks and waves on a Dask
cluster, records merged with `Grid.add_records`).
"""

from __future__ import annotations

import copy
import functools
import itertools
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from . import _balls
from ._balls import cone_lens_balls
from ._cost import checks_cells, kernel_batch_cubes
from ._hashtable import IntTable
from ._methods import CONTINUATION_METHODS, METHODS, SIMPLICIAL_METHODS
from ._regular import collapse_lenses, subdivide_double_edges
from .complex import CellComplex
from .errors import Cancelled, InputError
from .grid import candidate_corner_sets, candidate_scan
from .kernels.cell_check import graph_certified_chunk
from .kernels.cms import simplices_chunk
from .kernels.gcmh import cubes_chunk
from .kernels.records import CELL_COLS, EDGE_COLS, INC_COLS
from .kernels.tables import cube_tables, simplex_tables

__all__ = ["METHODS", "CONTINUATION_METHODS", "SIMPLICIAL_METHODS", "Grid", "assemble_records", "block_values",
           "complex_of"]



# Below this many cubes a kernel run stays in the calling thread: waking the thread
# pool costs milliseconds, which small continuation waves would pay hundreds of times.
_SERIAL_CUBES = 256
# Pieces a kernel run is cut into per thread (pieces of unequal cost even out).
_CHUNKS_PER_THREAD = 2
# Candidate cubes per kernel run at most (fewer where a cube costs more, `_cost.kernel_batch_cubes`):
# a run of the three-torus's costliest cubes takes about 0.2 s, so a cancel is answered within that.
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


class Grid:
    """The grid's shape and the per-run constants every method needs, and the records
    its kernel runs have produced so far (`parts`), merged by `assemble`.

    method: "gcmh"/"gcch" run the hypercube kernel, "cms"/"ccs" the simplicial one.
    cancel: callable() -> bool, polled between kernel batches; True raises `Cancelled`.
    progress: callable(phase, fraction), told how the cube tables' build goes (k >= 8 takes seconds);
    cancel is polled there too.
    check_cells: check the cells against CMS's Euler characteristic (`_cubes_off_euler`): True, every
    cube's; None (default), the cubes where they can be wrong (`graph_certified` can't vouch for
    them); False, none.  Not for surfaces in R^3 or the baselines; from n = 8 on by default only the
    boundaries of the cells, curves not at all (`_cost.checks_cells`, `unchecked_reason`).
    """

    # n >= 8 by default: a cube is refined with its neighbours at the assembly (`refine_deferred`), found
    # by grid index (an identified grid keys a cube across a seam otherwise: there, within the run)
    defers_refinement = True

    def __init__(self, n, k, axes, method="gcmh", cancel=None, progress=None, check_cells=None):
        self.n, self.k, self.axes, self.cancel = n, k, axes, cancel
        self.simplicial = method in SIMPLICIAL_METHODS
        self.tab = cube_tables(n, k, progress=progress, cancel=cancel)
        # candidate cubes per kernel run: a run ends within about a quarter second (k = 10: 71 cubes)
        self.kernel_batch = kernel_batch_cubes(n, k, most=_KERNEL_BATCH)
        self.dims = np.array([len(a) for a in axes], np.int64)  # vertices per axis
        self.strides = np.ones(n, np.int64)
        for a in range(n - 2, -1, -1):
            self.strides[a] = self.strides[a + 1] * self.dims[a + 1]
        self.corner_off = _balls._corner_offsets(n, self.strides)
        total = int(np.prod([int(d) for d in self.dims]))
        if self.simplicial:
            self.stab = simplex_tables(n, k)
            key_room = total * self.stab.key_base
        else:
            key_room = max(total * int(self.tab.n_subsets[d]) * int(self.tab.n_codes[d]) for d in range(k, n + 1))
        if key_room >= 2**63:
            raise InputError(f"the grid is too large to index ({total:,} vertices in R^{n}): use a smaller div")
        # cells are checked against CMS's Euler characteristic face by face where they can be wrong:
        # by default every cube the certificate can't vouch for (`graph_certified`), asked for: all
        self.check_request = check_cells  # (what the caller asked: a distributed run's tasks get it)
        self.check_cells = checks_cells(n, k, self.simplicial, check_cells)
        self.check_all = bool(check_cells)
        # the Euler check (CMS's count, face by face) where cells are checked; for n >= 8 only when asked
        # for (every cube builds its own Kuhn table, `kernels.kuhn_cube`: 0.01 to 0.5 s a cube), by
        # default there the boundaries of GCMH's cells (`_balls.cubes_with_bad_boundaries`)
        self.euler_checked = self.check_cells and (n <= 7 or self.check_all)
        self.axes_arr = np.zeros((n, int(self.dims.max())))
        for a in range(n):
            self.axes_arr[a, : self.dims[a]] = axes[a]
        self.timings = dict(evaluate=0.0, candidates=0.0, kernel=0.0, assemble=0.0)
        self.stats = dict(candidate_cubes=0, cubes=int(np.prod(self.dims - 1)), nonfinite_vertices=0, degenerate=0,
                          non_ball_cells=0, non_ball_split=0, checked_cubes=0)
        self.parts: dict[str, list[np.ndarray]] = dict(vk=[], vp=[], e=[], c=[], i=[])
        # n >= 8 by default: cubes to refine with their neighbours once every cube has run (each with the
        # pieces it joins; `refine_deferred`), and where F's values come from then (`set_source`)
        self.deferred: list[tuple[tuple, int]] = []
        self.source: tuple | None = None
        # the kernel's tables, one named tuple (`kernels.tables.CubeTables` or `SimplexTables`)
        self.kernel_tables = self.stab if self.simplicial else self.tab

    def run_kernel(self, values, cube_lin, origin, value_off) -> np.ndarray:
        """Process candidate cubes (in pieces side by side on the kernel threads); keep the records.

        values (NV, k); corner c of cube i is row cube_lin[i] + value_off[c].
        Returns each cube's crossed-facet mask (bit 2a + side).
        """
        m = len(cube_lin)
        batch = self.kernel_batch
        if m > batch:  # in batches: cancel is polled between them (records keep their order)
            return np.concatenate([
                self.run_kernel(values, cube_lin[i : i + batch], origin[i : i + batch], value_off)
                for i in range(0, m, batch)
            ])
        if self.cancel is not None and self.cancel():
            raise Cancelled("extraction cancelled")
        t = time.perf_counter()
        cube_key = origin @ self.strides
        common = (values, cube_lin, origin, cube_key, self.axes_arr, value_off, self.corner_off, self.kernel_tables)
        chunk = simplices_chunk if self.simplicial else cubes_chunk

        def run(lo, hi):
            result = chunk(lo, hi, *common)
            return result, (self._cubes_off_euler(result[0], common, lo, hi) if self.check_cells else (None, 0))

        # (numba.get_num_threads only for a batch worth splitting: it costs more than a wave's small batch)
        threads = numba.get_num_threads() if m >= _SERIAL_CUBES else 1
        pieces = 1 if threads == 1 else min(m, _CHUNKS_PER_THREAD * threads)
        cuts = [i * m // pieces for i in range(pieces + 1)]
        if pieces == 1:
            both = [run(0, m)]
        else:
            both = list(_kernel_pool().map(run, cuts[:-1], cuts[1:]))
        results = [result for result, _ in both]
        for lo, ((records, _, degenerate, non_ball), (off_euler, checked)) in zip(cuts, both):
            # cubes with cells that are not balls, once per such cell: pieces of G_H that M_A joins
            # (the kernel); cubes where GCMH's count differs from CMS's or M_A hides in a face (the check)
            # (the numpy calls only where there are cubes: a continuation wave is small, and they cost more)
            cubes = np.repeat(non_ball[:, 0] + lo, non_ball[:, 2]) if len(non_ball) else non_ball[:0, 0]
            if off_euler is not None and len(off_euler):
                cubes = np.concatenate([cubes, off_euler[~np.isin(off_euler, cubes)]]) if len(cubes) else off_euler
            if len(cubes):
                # (.get: identify's per-parity grids start from their own stats)
                self.stats["non_ball_cells"] = self.stats.get("non_ball_cells", 0) + len(cubes)
                records = split_non_ball_cells(self, records, cubes, common)
            for key, arr in zip(self.parts, records):
                self.parts[key].append(arr)
            self.stats["degenerate"] += int(degenerate)
            self.stats["checked_cubes"] = self.stats.get("checked_cubes", 0) + checked
        self.stats["candidate_cubes"] += m
        self.timings["kernel"] += time.perf_counter() - t
        return results[0][1] if pieces == 1 else np.concatenate([result[1] for result in results])

    def _cubes_off_euler(self, records, common, lo, hi) -> tuple[np.ndarray, int]:
        """The cubes lo..hi-1 of a kernel run (a kernel thread's piece), of those checked (every one
        when asked, else those `graph_certified` can't vouch for; also returned: how many), where
        GCMH's cells count another Euler characteristic than CMS's in some open face of the cube: a cell there is not
        a ball (a solid torus, a disc with a handle), though no two pieces of G_H need be joined;
        and those with a piece of M_A hidden inside a face (a loop inside a (k+1)-face: no GCMH
        vertex, chi 0), which every cube on that face finds alike, so all of them are refined."""
        values, cube_lin, origin, _, _, value_off, _, _ = common
        if self.check_all:
            cubes = np.arange(lo, hi)
        else:  # only the cubes whose piece of M_A the certificate can't show to be a graph over a face
            cubes = lo + np.flatnonzero(~graph_certified(values, cube_lin[lo:hi], value_off, self.k))
        if len(cubes) == 0:
            return cubes, 0
        if not self.euler_checked:  # (n >= 8 by default: CMS's count takes 0.01 to 0.5 s a cube there)
            return cubes[_balls.cubes_with_bad_boundaries(self.tab, records, origin[cubes], self.strides,
                                                          self.dims)], len(cubes)
        cms, hidden = _balls.cms_cube_euler(self.tab, values, cube_lin[cubes], value_off, 0, len(cubes))
        gcmh = _balls.cube_euler(self.tab, records, origin[cubes], self.strides, self.dims)
        return cubes[(cms != gcmh).any(axis=1) | hidden.any(axis=1)], len(cubes)

    def process_block(self, values, lo, hi, first_layer=None) -> np.ndarray:
        """The candidate cubes of the block of cubes lo..hi-1 (per axis, global indices).

        values (hi-lo+1 ..., k): F at the block's vertices.  Blocks may be processed in
        any order and on any machine: records carry global keys (see `gcmh_core.kernels`).
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
        value_off = _balls._corner_offsets(self.n, block_strides)
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
        return self.cubes_from_corner_values(values, origins, self.run_kernel), nonfinite

    def cubes_from_corner_values(self, values, origins, run) -> np.ndarray:
        """The candidate pass and `run` (run_kernel or a subclass's) on cubes whose 2^n corner
        values are rows i * 2^n + c of values; returns each cube's crossed-facet mask."""
        n = self.n
        t = time.perf_counter()
        cand = candidate_corner_sets(values, 1 << n)
        self.timings["candidates"] += time.perf_counter() - t
        idx = np.nonzero(cand)[0]
        masks = np.zeros(len(origins), np.int64)
        if len(idx):
            value_off = np.arange(1 << n, dtype=np.int64)
            masks[idx] = run(values, idx.astype(np.int64) << n, origins[idx], value_off)
        return masks

    def set_source(self, system, sampled) -> None:
        """Where F's values at any cube's corners come from (the formulas, or the sampled array), for
        the refinement of cubes with their neighbours at the assembly (`refine_deferred`)."""
        self.source = (system, sampled)

    def one_cube(self, origin) -> tuple | None:
        """`refine_cube`'s arguments for the cube at grid index origin (F at its corners as a sweep's
        block of one cube takes them: the same values), or None outside the grid or with no source."""
        o = np.asarray(origin, np.int64)
        if self.source is None or (o < 0).any() or (o >= self.dims - 1).any():
            return None
        system, sampled = self.source
        values = np.ascontiguousarray(block_values(self.axes, system, sampled, o, o + 1), np.float64)
        values = values.reshape(-1, self.k)
        value_off = _balls._corner_offsets(self.n, 1 << np.arange(self.n - 1, -1, -1, dtype=np.int64))  # (2, ..., 2, k)
        return (self.tab, values, np.zeros(1, np.int64), o[None].copy(), np.array([o @ self.strides], np.int64),
                self.axes_arr, value_off, self.corner_off)

    def refine_deferred(self) -> None:
        """Refine the deferred cubes, each with the cubes its pieces bulge into (`_refine_with_neighbours`),
        now that F's values at any cube's corners can be had (`set_source`): the neighbours of a cube
        are in other kernel runs, slabs or blocks.  In grid order, so the records do not depend on the
        order the runs came in; a cube refined once is not refined again."""
        done: dict[tuple, tuple | None] = {}
        for origin, pieces in sorted(self.deferred):
            refined = _refine_with_neighbours(self, origin, self.one_cube, done)
            if refined is None:
                continue
            for more in refined:
                for key, arr in zip(self.parts, more):
                    self.parts[key].append(arr)
            self.stats["non_ball_split"] = self.stats.get("non_ball_split", 0) + pieces
        self.deferred = []

    def assemble(self) -> CellComplex:
        if self.deferred and self.source is not None:
            t = time.perf_counter()
            self.refine_deferred()
            self.timings["kernel"] += time.perf_counter() - t
        t = time.perf_counter()
        n, k = self.n, self.k
        widths = dict(vk=None, vp=n, e=EDGE_COLS, c=CELL_COLS, i=INC_COLS)
        cat = {
            key: np.concatenate(arrs) if arrs
            else np.zeros((0,) if w is None else (0, w), np.float64 if key == "vp" else np.int64)
            for (key, arrs), w in zip(self.parts.items(), widths.values())
        }
        cx = assemble_records(n, k, cat["vk"], cat["vp"], cat["e"], cat["c"], cat["i"])
        self.timings["assemble"] = time.perf_counter() - t
        cx.meta.update(self.stats)
        cx.meta["non_ball_left"] = non_ball_left(self.stats)
        cx.meta["cells_checked"] = bool(self.check_cells)
        reason = unchecked_reason(n, k, self.simplicial, self.check_request)
        if reason:
            cx.meta["topology_unchecked"] = reason
        cx.meta["timings"] = self.timings
        return cx

    # ------------------------------------------------------------------ records (for distributed runs)
    def empty_copy(self) -> Grid:
        """The same grid and tables with no records, zero stats and timings (a worker's fresh start)."""
        grid = copy.copy(self)
        grid.parts = {key: [] for key in self.parts}
        grid.deferred = []
        grid.stats = dict(self.stats)
        grid.timings = dict.fromkeys(self.timings, 0.0)
        return grid

    def packed_records(self) -> dict:
        """The records as one array per kind (fewer, larger messages), stats and timings."""
        parts = {key: (np.concatenate(arrs) if len(arrs) > 1 else arrs[0]) if arrs else None
                 for key, arrs in self.parts.items()}
        return dict(parts=parts, stats=dict(self.stats), timings=dict(self.timings), deferred=list(self.deferred))

    def add_records(self, packed: dict) -> None:
        """Add another grid's `packed_records` (a block's or a wave's), in order."""
        for key, arr in packed["parts"].items():
            if arr is not None:
                self.parts[key].append(arr)
        for key, value in packed["stats"].items():
            if key != "cubes":  # the grid's total, not a per-block count
                self.stats[key] = self.stats.get(key, 0) + value
        for key, value in packed["timings"].items():
            self.timings[key] = self.timings.get(key, 0.0) + value
        self.deferred += packed.get("deferred", [])


@functools.lru_cache(maxsize=16)
def _axis_subsets(n: int, k: int) -> np.ndarray:
    """The k-subsets of the n axes, (comb(n, k), k) int64 (`graph_certified` tries each)."""
    return np.array(list(itertools.combinations(range(n), k)), np.int64).reshape(-1, k)


def graph_certified(values, cube_row, corner_row, k) -> np.ndarray:
    """(m,) bool: cubes whose piece of M_A is, for sure, a graph over a face of the cube, so that
    their cells need no check (`kernels.cell_check.graph_certified_chunk`).

    M_A in a cube is F's interpolant on the cube's Kuhn simplices (paper Section 4).  Along a Kuhn
    simplex's chain each step crosses one axis a, so the interpolant's partial derivative along a
    is F(c + e_a) - F(c) on one of the cube's 2^(n-1) edges along a (grid steps as units): the
    Jacobians of all its affine pieces lie in the interval matrix A whose column a is the hull of
    those differences.  Where some k columns S make a regular interval matrix (every member
    invertible), the map x_S -> F(x_S, y) is one to one for each value y of the other axes (its
    mean Jacobian between two points lies in A_S), so M_A is a graph x_S = g(y) over a face of
    dimension n - k, and so is its piece in every face holding the axes S.  Row scales cancel in
    the test: no component's numbers are compared with another's.  Only F's values are used, so
    formulas and sampled data are certified alike (noise, whose differences change sign, is not).

    values (NV, k); corner c of cube i is row cube_row[i] + corner_row[c].
    """
    n = len(corner_row).bit_length() - 1
    return graph_certified_chunk(values, np.ascontiguousarray(cube_row, np.int64),
                                 np.ascontiguousarray(corner_row, np.int64), k, _axis_subsets(n, k))


def unchecked_reason(n: int, k: int, simplicial: bool, check_request: bool | None) -> str | None:
    """Why GCMH's cells were not (or only partly) checked against CMS's where they can be wrong (a piece
    of M in a cube that is not a ball gives a wrong chi or count of pieces), or None: they were, or
    can't be wrong (surfaces in R^3, whose marching pass hands a cube it can't cut to the general kernel;
    curves in the plane; the simplicial baselines, whose cells are convex)."""
    if simplicial or n - k < 1 or n <= 2 or (n, k) == (3, 1):
        return None
    if check_request is False:
        return "the cell check was turned off (check_cells=False)"
    if n >= 8 and not check_request and n - k == 1:
        return (f"in R^{n} a curve's small closed loops inside one cube (with no vertex on a face of it) are not "
                "looked for by default; --check-cells compares every cube with CMS's count (0.01 to 0.5 s "
                "a cube)")
    if n >= 8 and not check_request:
        return (f"in R^{n} only the boundaries of the cells are checked by default (each must be a sphere, and "
                "a cube where one is not is refined by CMS): a cell that is not a ball but is bounded by a sphere "
                "(a disc with a handle) or a piece of M inside a cube's face is not found; --check-cells "
                "compares every cube with CMS's count (0.01 to 0.5 s a cube)")
    return None


def non_ball_left(stats: dict) -> int:
    """Pieces M_A joins through a cube that are still cells that are not balls (not split)."""
    return int(stats.get("non_ball_cells", 0)) - int(stats.get("non_ball_split", 0))


def split_non_ball_cells(grid: Grid, records: tuple, cubes: np.ndarray, common: tuple) -> tuple:
    """A kernel run's records with the cells that are not balls split (`_balls`): a surface's
    piece is cut into discs, other cubes' cells are replaced by CMS's; meta["non_ball_split"]
    counts the pieces joined that are now split.

    cubes: the run's cubes where the kernel found joined pieces, once per piece joined; common:
    the kernel's arguments after (lo, hi), for the whole run.
    """
    values, cube_lin, origin, cube_key, axes_arr, value_off, corner_off, tab = common
    vk, vp, e, c, inc = records
    cubes, joined = np.unique(cubes, return_counts=True)
    for i, pieces in zip(cubes.tolist(), joined.tolist()):
        one = slice(i, i + 1)
        cube = (tab, values, cube_lin[one], origin[one], cube_key[one], axes_arr, value_off, corner_off)
        # (where every cube is checked a surface's cube is refined too: its neighbours may be)
        split = _balls.split_joined_pieces(*cube) if grid.n - grid.k == 2 and not grid.check_cells else None
        if split is not None:
            drop, new_edges, new_inc, pieces = split
            keep = ~((inc[:, 0] == 2) & np.isin(inc[:, 1], drop))
            e = np.concatenate([e, new_edges])
            inc = np.concatenate([inc[keep], new_inc])
        else:  # solids, or a surface's piece that can't be cut: the cube's cells become CMS's
            if grid.check_cells and not grid.euler_checked:
                # (n >= 8 by default: no neighbour is checked, those M_A bulges into are refined too; they
                # may be in another run, so where F's values can be had again it is done at the assembly)
                if grid.defers_refinement:
                    grid.deferred.append((tuple(origin[i].tolist()), pieces))
                    continue
                at = {tuple(o): j for j, o in enumerate(origin.tolist())}

                def in_run(o, at=at):
                    j = at.get(tuple(o.tolist()))
                    return None if j is None else (tab, values, cube_lin[j : j + 1], origin[j : j + 1],
                                                   cube_key[j : j + 1], axes_arr, value_off, corner_off)

                refined = _refine_with_neighbours(grid, tuple(origin[i].tolist()), in_run, {})
            else:
                refined = _balls.refine_cube(*cube, neighbours_checked=grid.euler_checked)
                refined = None if refined is None else [refined]
            if refined is None:
                continue
            for more in refined:
                vk, vp, e, c, inc = (np.concatenate([a, b]) for a, b in zip((vk, vp, e, c, inc), more))
        grid.stats["non_ball_split"] = grid.stats.get("non_ball_split", 0) + pieces
    return vk, vp, e, c, inc


# Cubes refined together at most where no neighbour is checked (`_refine_with_neighbours`)
_REFINED_TOGETHER = 16


def _refine_with_neighbours(grid: Grid, start: tuple, cube_of, done: dict) -> list | None:
    """The records of the cube at grid index start refined (`_balls.refine_cube`), with every cube across
    a face where M_A has cells none of the cube's GCMH cells holds (a piece bulging through it: its
    neighbours have no cell there either) or where two of them lie on one piece of M_A, and theirs in
    turn; None where one of them can't be had (cube_of(origin): `refine_cube`'s arguments, or None) or
    refined, or more than _REFINED_TOGETHER would be.  done: origin -> its records or None, kept across
    calls (a cube is refined once; records already returned are not returned again)."""
    order: list[tuple] = [start]
    out: list[tuple] = []
    for o in order:
        if o not in done:
            if grid.cancel is not None and grid.cancel():  # (a cube's refinement takes up to seconds)
                raise Cancelled("extraction cancelled")
            bulges: list = []
            cube = cube_of(np.array(o, np.int64))
            if cube is None:
                refined = None
            else:
                tab, values, row, origin, key, axes_arr, value_off, corner_off = cube
                refined = _balls.refine_cube(tab, values, row, origin, key, axes_arr, value_off, corner_off,
                                             neighbours_checked=True, bulges=bulges)
            done[o] = None if refined is None else (refined, bulges, False)
        if done[o] is None:
            return None
        refined, bulges, _ = done[o]
        out.append(o)
        for free, fixed in bulges:
            # the other cubes holding the face: origin moved by -1 or +1 on some of its fixed axes
            fixed_axes = [a for a in range(grid.n) if not (free >> a) & 1]
            for moved in itertools.product((0, 1), repeat=len(fixed_axes)):
                if not any(moved):
                    continue
                other = list(o)
                for a, m in zip(fixed_axes, moved):
                    other[a] += (1 if (fixed >> a) & 1 else -1) * m
                if min(other) < 0 or any(x >= d - 1 for x, d in zip(other, grid.dims.tolist())):
                    continue  # (the face is on the box's boundary there)
                if tuple(other) not in order:
                    order.append(tuple(other))
                    if len(order) > _REFINED_TOGETHER:
                        return None
    records = [done[o][0] for o in out if not done[o][2]]
    for o in out:  # (returned once)
        done[o] = (done[o][0], done[o][1], True)
    return records


def block_values(axes, system, sampled, lo, hi) -> np.ndarray:
    """F at the vertices of the block of cubes lo..hi-1 (per axis): (hi-lo+1 ..., k)."""
    if sampled is not None:
        return sampled[tuple(slice(int(a), int(b) + 1) for a, b in zip(lo, hi))]
    return system.evaluate_grid([ax[int(a) : int(b) + 1] for ax, a, b in zip(axes, lo, hi)])


# ----------------------------------------------------------------------------- assembly
def unique_first(keys: np.ndarray):
    """Sorted unique keys and the index of each one's first occurrence (sort-based: fast on int64)."""
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    keep = np.ones(len(sk), bool)
    keep[1:] = sk[1:] != sk[:-1]
    return sk[keep], order[keep]


def assemble_records(n, k, vk, vp, e, c, inc) -> CellComplex:
    """Identify what neighbouring cubes emitted twice and build the CellComplex.

    Every entity carries a key computed from grid indices alone (see `gcmh_core.kernels`);
    ids in the result follow the sorted keys, so the output does not depend on
    the order in which cubes, slabs or threads produced it.  Lens 2-cells (two edges
    with the same ends) are collapsed last (`_regular`); meta counts them.
    """
    vkeys, first = unique_first(vk)
    vertices = np.ascontiguousarray(vp[first])
    e, c, inc = _balls.replace_refined_cells(e, c, inc)
    keys = {1: unique_first(e[:, 0])}
    edges = np.searchsorted(vkeys, e[keys[1][1], 1:3]).astype(np.int64)
    cells = {}
    for r in range(2, n - k + 1):
        keys[r] = unique_first(c[c[:, 0] == r, 1])
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
    return complex_of(n, k, vertices, edges, cells)


def complex_of(n, k, vertices, edges, cells) -> CellComplex:
    """The CellComplex of assembled cells (ids in key order), lens 2-cells collapsed
    (`_regular`); meta counts them.  (Also the end of `sweep`'s marching pass for n = 3.)"""
    edges, cells, collapsed, left = collapse_lenses(edges, cells)
    vertices, edges, cells, halved = subdivide_double_edges(vertices, edges, cells)
    # a 3-cell of two faces that is a whole piece of M on the box's boundary: one face coned (regular)
    vertices, edges, cells, coned = cone_lens_balls(vertices, edges, cells)
    meta = dict(collapsed_lenses=collapsed, lenses_left=left, halved_edges=halved)
    if coned:
        meta["coned_lens_balls"] = coned
    return CellComplex(n, k, vertices, edges, cells, meta)
