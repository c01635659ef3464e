"""`extract`: the public entry point of the engine. It validates and dispatches.

public function (validates every argument, `_validate`)
  -> `sweep.run_sweep` (GCMH/CMS: every cube, slab by slab)
   | `continuation.run_continuation` (GCCH/CCS: the cubes M passes through)
   | `distributed.run_distributed` (either, on a Dask cluster)
  -> `runner.Grid` (kernel runs on threads, records, assembly) -> `gcmh_core.kernels` (numba);
     with glued axes (periodic=), `identify.IdentifiedGrid`, a Grid whose seams wrap.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from numbers import Integral
from typing import TYPE_CHECKING

import numpy as np

from ._methods import CONTINUATION_METHODS, METHODS, SIMPLICIAL_METHODS
from ._validate import as_div, as_periodic, describe_periodic, prepare
from .budget import check_budget, estimate_run
from .complex import CellComplex
from .errors import InputError

if TYPE_CHECKING:
    from .formula import System

# one (lo, hi) pair for every axis, or one per axis; entries are numbers or constant text ("-pi/2")
Bound = float | str
Bounds = tuple[Bound, Bound] | Sequence[tuple[Bound, Bound]] | Sequence[Sequence[Bound]] | np.ndarray

__all__ = ["METHODS", "CONTINUATION_METHODS", "SIMPLICIAL_METHODS", "extract", "estimate_work"]


def estimate_work(n: int, k: int, div: int | Sequence[int], method: str = "gcmh") -> dict:
    """A quick estimate of a run before F is known: cubes, peak bytes and seconds, with M
    taken to cross the grid like an (n-k)-plane (`budget.estimate_run` without a probe of
    F; `budget.estimate` probes F too)."""
    if method not in METHODS:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(METHODS)}")
    d = as_div(div, int(n))
    e = estimate_run(int(n), int(k), d, method=method)
    return dict(cubes=e.cubes, bytes=e.peak_bytes, seconds=e.seconds, fits=e.fits)


def extract(
    F: str | Sequence[str] | System | np.ndarray,
    bounds: Bounds | None = None,
    div: int | Sequence[int] | None = None,
    *,
    variables: Sequence[str] | str | None = None,
    n: int | None = None,
    k: int | None = None,
    seed: int = 0,
    method: str = "gcmh",
    start: str | Sequence[float] | Sequence[Sequence[float]] | np.ndarray | None = None,
    progress: Callable[[str, float], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    scheduler: str | None = None,
    block: int | Sequence[int] | None = None,
    force: bool = False,
    params: dict[str, float | str] | None = None,
    periodic: dict | Sequence | None = None,
    check_cells: bool | None = None,
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
    start : for "gcch" and "ccs": a point (n,), several points (m, n), "auto" (default), or
        a previous result (a CellComplex in the same R^n): each point is projected onto M
        by Gauss-Newton with F's exact Jacobian; "auto" starts from every cube F's bounds
        leave (or projects a lattice of points); a previous result's vertices are projected
        onto the new M in one batch (those that fail are dropped), so a parameter step
        continues from the last result -- pieces of M born away from it are not found.
    progress : callable(phase, fraction), called between slabs.
    cancel : callable() -> bool, polled between slabs; True raises `Cancelled`.
    scheduler : None (this process), "local" (a dask LocalCluster sized to the machine)
        or a dask scheduler address "tcp://host:port": the grid is cut into blocks of
        cubes processed by the cluster's workers; the result is the same, bit for bit.
    block : cubes per block along each axis for `scheduler` (int or one per axis).
    params : values of the formulas' parameters, {name: number or constant text}: any
        name in the formulas that is not a variable, constant or function (see
        `formula.find_parameters`); each value is used as if written in the text.
        The result's meta holds them ("params") and, with parameters, the critical
        points of M found ("critical_points": [{"x": point, "rank": rank of J}], solved for
        from the cubes M crosses, `critical`) and the number of vertices where F's Jacobian
        nearly loses rank or that lie within a cube of a critical point ("singular_vertices":
        the parameter is at or near a critical value).
    periodic : identified axes (`identify`): {"t": True, "s": {"flip": ["t"]}} or
        ["t", "s:flip=t"]: each named axis is periodic (its lo and hi are one point), and
        crossing its seam reverses the axes in "flip" (x_b -> lo_b + hi_b - x_b).  F must be
        invariant under each identification (checked at a few hundred random points); a
        flipped axis needs an even div.  With s periodic reversing t and t periodic, the
        paper's Klein bottle is closed (chi 0, non-orientable) instead of cut open.
    check_cells : check the cubes' cells against CMS's Euler characteristic face by face and
        refine the cubes where a cell is not a ball (`_balls`) or a small closed curve hides in
        a cube, for n = 3..7 (not surfaces in R^3, the marching pass).  None (default): the
        cubes where a cell can be wrong, those whose values do not certify M_A a graph over a
        face (`runner.graph_certified`; formulas and sampled data alike): on smooth inputs few
        cubes, on noise most; True: every cube (2 to 3 times the run for surfaces, 7 to 11 at
        n = 6); False: none, only the pieces of G_H that M_A joins are found.  For n >= 8 the
        default checks that each such cube's cells are bounded by spheres (and refines a cube
        where one is not; curves have no such boundary and are checked only when asked for);
        True compares every cube with CMS's count there too.
        meta["cells_checked"] says whether a check ran, meta["checked_cubes"] on how many cubes,
        and meta["topology_unchecked"] what a run's check leaves unchecked and why (n >= 8 by
        default, or check_cells=False).
    force : run even when `budget.estimate_run` says the run needs more memory than is
        available or more than the time limit; by default that raises `budget.TooLargeError`
        (an InputError naming the estimate) before any work.

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
    # the engine (numba kernels) loads with the first run: `import gcmh_core` stays light
    from .continuation import as_starts, run_continuation
    from .grid import PERTURBATION, perturbed_axes
    from .runner import Grid
    from .sweep import run_sweep

    t0 = time.perf_counter()
    if method not in METHODS:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(METHODS)}")
    if isinstance(seed, bool) or not isinstance(seed, (Integral, np.integer)):
        raise InputError(f"seed must be an integer, got {seed!r}")
    if isinstance(div, (list, tuple)) and len(div) == 1:
        div = div[0]
    # (a sweep in this process reads sampled values slice by slice: a float32 volume is not copied whole)
    n_, k_, bounds_, div_, system, sampled = prepare(F, variables, n, k, bounds, div, params,
                                                     slices=method not in CONTINUATION_METHODS and scheduler is None)
    cost = estimate_run(n_, k_, div_, method=method, bounds=bounds_, system=system, sampled=sampled,
                        scheduler=scheduler, check_cells=check_cells)
    check_budget(cost, force)
    amplitude = 0.0 if sampled is not None else PERTURBATION  # sampled data can't be moved: its positions are exact
    names = list(system.variables) if system is not None else [f"x{i + 1}" for i in range(n_)]
    spec = as_periodic(periodic, names, div_)
    if spec:
        from .identify import IdentifiedGrid, check_invariance, identified_axes

        if sampled is not None:
            raise InputError("periodic axes need F as formulas: sampled values can't be checked for periodicity")
        check_invariance(system, bounds_, spec)
        axes = identified_axes(bounds_, div_, seed, amplitude, spec)
    else:
        axes = perturbed_axes(bounds_, div_, seed, amplitude)
    # (exact zeros and other degenerate values are resolved in the kernels by simulation of
    # simplicity, `kernels.solve._zero_side`: F's values are never moved)

    def new_grid():
        if spec:
            return IdentifiedGrid(n_, k_, axes, method, cancel, spec=spec, bounds=bounds_, progress=progress,
                                  check_cells=check_cells)
        return Grid(n_, k_, axes, method, cancel, progress, check_cells)

    continuation = method in CONTINUATION_METHODS
    if continuation:
        starts = as_starts("auto" if start is None else start, n_)
    elif start is not None:
        methods = " or ".join(map(repr, CONTINUATION_METHODS))
        raise InputError(f"a start point is used by continuation only: pass method={methods}")
    else:
        starts = None
    if block is not None and scheduler is None:
        raise InputError("block is the block size of a distributed run: pass scheduler too")
    if scheduler is not None:
        from .distributed import run_distributed  # (dask is imported only when asked for)

        result = run_distributed(method, n_, k_, axes, bounds_, system, sampled, starts, scheduler, block,
                                 progress, cancel, spec=spec, check_cells=check_cells)
    elif continuation:
        result = run_continuation(n_, k_, axes, bounds_, system, sampled, starts, progress, cancel,
                                  grid=new_grid())
    else:
        result = run_sweep(n_, k_, axes, system, sampled, progress, cancel, grid=new_grid())
    result.meta.update(
        method=method,
        div=div_.tolist(),
        bounds=bounds_.tolist(),
        seed=int(seed),
        formulas=list(system.texts) if system is not None else None,
        variables=list(system.variables) if system is not None else [f"x{i + 1}" for i in range(n_)],
        params=dict(system.params) if system is not None else {},
    )
    if spec:
        result.meta["periodic"] = describe_periodic(spec, names)
    if system is not None and system.params:
        from .critical import singular_report

        # critical points solved for from the cubes M crosses, not only where vertices land
        result.meta["singular_vertices"], result.meta["critical_points"] = singular_report(
            system, result.vertices, bounds_, div_)
    result.meta["seconds"] = time.perf_counter() - t0
    return result


def singular_vertices(system: System, X: np.ndarray) -> int:
    """How many of the points X (m, n) have a nearly rank-deficient exact Jacobian
    (`critical.singular_vertices`; a run's meta counts also the vertices near a critical point
    found, `critical.singular_report`)."""
    from .critical import singular_vertices as count

    return count(system, X)
