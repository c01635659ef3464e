"""Continuation (GCCH and CCS, paper Section 5): only the cubes M passes through.

From the start cubes, each wave is the set of cubes first reached across facets
that the previous wave's cells cross; a wave is one batch (F at its corners in one
vectorised call, then one kernel run).  Start points are projected onto M by
Gauss-Newton (`newton.gauss_newton`, all points in one batch).
"""

from __future__ import annotations

import numpy as np

from ._hashtable import IntTable
from .complex import CellComplex, _frozen
from .errors import Cancelled, InputError
from .grid import candidate_corner_sets, candidate_origins
from .kernels.candidates import facet_neighbours
from .newton import CONVERGED, LEFT_DOMAIN, MOVING, NOT_FINITE, gauss_newton
from .runner import Grid, unique_first
from .sweep import enclosure_of, surviving_blocks

__all__ = ["run_continuation", "as_starts", "start_cubes", "project_onto_M", "PreviousResult"]


class PreviousResult:
    """start=<a CellComplex>: continue from a previous result (a parameter step).  Its
    vertices are projected onto the new M in one batch; those that fail are dropped."""

    def __init__(self, vertices: np.ndarray):
        self.vertices = vertices

    def __repr__(self):
        return f"PreviousResult({len(self.vertices)} vertices)"


_NEWTON_STEPS = 50


def project_onto_M(system, X0: np.ndarray, bounds: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Project the points X0 (m, n) onto M in one batch of Gauss-Newton steps.

    Returns (X (m, n) float64, ok (m,) bool, why (m,) str): X are the projected points,
    ok says which converged inside the domain, why says for the others what went wrong.
    Convergence is judged by the length of the Newton step (the first-order distance to
    M, in the domain's units), never by |F|: multiplying F by 1e10 or 1e-12 changes nothing.
    """
    scale = float(np.max(bounds[:, 1] - bounds[:, 0]))
    result = gauss_newton(system, X0, _NEWTON_STEPS, step_tol=1e-12 * scale, only_improving=False,
                          bounds=bounds, margin=1e-9 * scale)
    status = result.status
    # ran out of steps but the last step was short (what the one-point loop accepted)
    ok = (status == CONVERGED) | ((status == MOVING) & (result.step <= 1e-8 * scale))
    why = [""] * len(status)
    for i in np.flatnonzero(~ok):
        x = ", ".join(f"{v:g}" for v in result.x[i])
        why[i] = {
            NOT_FINITE: f"F is not finite near ({x})",
            LEFT_DOMAIN: "Newton's projection onto M left the domain",
            MOVING: f"Newton's projection onto M did not converge in {_NEWTON_STEPS} steps "
                    f"(last step {result.step[i]:.3g}); try a point closer to M",
        }.get(int(status[i]), "the Jacobian of F is not finite there")
    return result.x, ok, why


def as_starts(start, n: int) -> list | str | PreviousResult:
    """'auto', a list of start points (n,) float64, or a PreviousResult (from a
    CellComplex); InputError for anything else."""
    if isinstance(start, CellComplex):
        V = np.asarray(start.vertices, np.float64)
        if V.ndim != 2 or V.shape[1] != n:
            raise InputError(f"the previous result lies in R^{V.shape[-1]}, not in R^{n}")
        if len(V) == 0:
            raise InputError("the previous result is empty: start from 'auto' instead")
        return PreviousResult(V[np.all(np.isfinite(V), axis=1)])
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


def _cubes_of(axes, X: np.ndarray) -> np.ndarray:
    """Origins (m, n) int64 of the grid cubes holding the points X (m, n) (clamped to the grid)."""
    return np.stack(
        [np.clip(np.searchsorted(ax, X[:, a], side="right") - 1, 0, len(ax) - 2) for a, ax in enumerate(axes)], axis=1
    ).astype(np.int64)


# start='auto' cuts the grid down to single cubes by F's bounds (measured: cheaper than
# stopping at blocks of 2..32 cubes and testing all their cubes' corners) while at most
# this many blocks are left at a step
_AUTO_MAX_BLOCKS = 1 << 16


def _bounded_candidates(axes, system) -> np.ndarray | None:
    """Origins (m, n) of every candidate cube of the grid (those the full sweep hands to the
    kernel), found without a full sweep: the cubes F's interval bounds leave, tested at
    their corners.  None when the bounds leave too many blocks (`_AUTO_MAX_BLOCKS`)."""
    n = len(axes)
    dims = np.array([len(a) for a in axes], np.int64)
    enclosure = enclosure_of(system)
    if enclosure is None:
        return None
    found = surviving_blocks(enclosure, axes, np.zeros(n, np.int64), dims - 1, 1, max_blocks=_AUTO_MAX_BLOCKS)
    if found is None or len(found[0]) == 0:
        return found if found is None else found[0]
    origins = found[0]
    strides = np.ones(n, np.int64)
    for a in range(n - 2, -1, -1):
        strides[a] = strides[a + 1] * dims[a + 1]
    corner_off = np.array([sum(int(strides[a]) for a in range(n) if c >> a & 1) for c in range(1 << n)], np.int64)
    ids = ((origins @ strides)[:, None] + corner_off[None]).reshape(-1)
    inverse, first = IntTable(capacity=2 * len(ids)).insert(ids)  # each vertex once
    multi = np.unravel_index(ids[first], tuple(int(d) for d in dims))
    values = system.evaluate_points(np.stack([axes[a][multi[a]] for a in range(n)], axis=1))
    return origins[candidate_corner_sets(np.ascontiguousarray(values[inverse]), 1 << n)]


_SEED_BLOCK = 4  # start=<previous result>: seeds one vertex per block of 4^n grid cubes


def start_cubes(n, axes, bounds, system, sampled, starts, identified=None) -> np.ndarray:
    """Origins (m, n) of the cubes to start from.

    starts == "auto": with sampled data, every cube that crosses M; with a formula, every
    candidate cube F's bounds find (so continuation reaches every piece of M the full
    sweep finds, the small ones too), or when the bounds leave too much of the grid, the
    cubes of a lattice of points projected onto M.
    identified: an `identify.IdentifiedGrid` when axes are glued: Newton may then cross a
    seam, and the projected points are brought back into the domain.
    """
    if identified is not None:
        project = identified.project_wrapped(project_onto_M)
    else:
        project = project_onto_M
    if starts == "auto":
        if system is None:  # no Jacobian for sampled data: start from every cube that crosses M
            return candidate_origins(sampled)[0]
        seeds = _bounded_candidates(axes, system)
        if seeds is not None and len(seeds):
            return seeds
        # project a spread of points (a coarse 5^n lattice, capped) onto M
        per_axis = max(2, min(5, int(round(4096 ** (1.0 / n)))))
        lattice = np.stack(
            np.meshgrid(*[np.linspace(lo, hi, per_axis + 2)[1:-1] for lo, hi in bounds], indexing="ij"), -1
        ).reshape(-1, n)
        X, ok, _ = project(system, lattice, bounds)
        if not ok.any():
            raise InputError("start='auto' found no point of M in the domain")
        return np.unique(_cubes_of(axes, X[ok]), axis=0)
    if isinstance(starts, PreviousResult):
        V = np.clip(starts.vertices, bounds[:, 0], bounds[:, 1])  # (a new box may be smaller)
        # one vertex per block of _SEED_BLOCK^n cubes: continuation floods each piece from any
        # of its cubes, and projecting every vertex cost more than the waves (16k vertices: 73 ms)
        blocks = _cubes_of(axes, V) // _SEED_BLOCK
        V = V[np.sort(np.unique(blocks, axis=0, return_index=True)[1])]
        if system is None:
            return np.unique(_cubes_of(axes, V), axis=0)
        X, ok, _ = project(system, V, bounds)
        if not ok.any():
            raise InputError("no vertex of the previous result projects onto the new M in the domain: "
                             "start from 'auto' instead")
        return np.unique(_cubes_of(axes, X[ok]), axis=0)
    X0 = np.array(starts, np.float64).reshape(-1, n)
    for x0 in X0:
        outside = [a + 1 for a in range(n) if not bounds[a, 0] <= x0[a] <= bounds[a, 1]]
        if outside:
            point = ", ".join(f"{v:g}" for v in x0)
            raise InputError(f"start point ({point}) is outside the domain on axis {outside[0]}")
    if system is None:
        X = X0
    else:
        X, ok, why = project(system, X0, bounds)
        if not ok.all():
            i = int(np.flatnonzero(~ok)[0])
            raise InputError(f"start point ({', '.join(f'{v:g}' for v in X0[i])}): {why[i]}")
    return np.unique(_cubes_of(axes, X), axis=0)


def run_continuation(
    n, k, axes, bounds, system, sampled, starts, progress, cancel, grid=None, process=None
) -> CellComplex:
    """Continuation: process only cubes reached from the start cubes across crossed facets.

    Each wave (the cubes first reached in the same step) is one batch: F at its
    corners in one vectorised call, then one kernel run.  `grid` (a `Grid`) and
    `process(grid, origins) -> (masks, nonfinite ids)` let another executor run
    the waves (gcmh_core.distributed); by default `grid.process_cubes` runs them here.
    """
    grid = Grid(n, k, axes) if grid is None else grid
    grid.set_source(system, sampled)
    if process is None:
        def process(g, origins):
            return g.process_cubes(origins, system, sampled)
    div = grid.dims - 1
    cube_strides = np.ones(n, np.int64)
    for a in range(n - 2, -1, -1):
        cube_strides[a] = cube_strides[a + 1] * div[a + 1]
    visited = IntTable()
    wrapped = getattr(grid, "wrapped_neighbours", None)

    def unvisited(cubes):  # the cubes not seen before, each once; they count as seen now
        cubes = cubes[np.all((cubes >= 0) & (cubes < div), axis=1)]
        return cubes[visited.insert(cubes @ cube_strides)[1]]

    nonfinite = []
    identified = grid if wrapped is not None else None
    wave = unvisited(start_cubes(n, axes, bounds, system, sampled, starts, identified))
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
        if wrapped is not None:  # periodic axes: across a seam to the identified cube
            cubes, keys = wrapped(wave, masks, cube_strides)
        else:
            cubes, keys = facet_neighbours(wave, masks, div, cube_strides)
        wave = cubes[visited.insert(keys)[1]]  # (in any order: the output does not depend on it)
    if isinstance(starts, list) and not any(len(v) for v in grid.parts["vk"]):
        # (with "auto" an empty result is an answer: M does not cross the domain)
        raise InputError(
            "M_A does not pass through the start cube(s) or their neighbours: "
            + ("give a point in a grid cube where every component of F changes sign" if system is None
               else "the projected start point lies where M grazes the grid; try another start point or div")
        )
    if progress is not None:
        progress("assembling", 1.0)
    grid.stats["nonfinite_vertices"] = len(unique_first(np.concatenate(nonfinite))[0]) if nonfinite else 0
    grid.stats["visited_cubes"] = len(visited)
    grid.stats["waves"] = n_waves
    cx = grid.assemble()
    # the continuation's path, for showing how it went (an attribute: not saved with the complex)
    processed = np.sort(visited.keys())
    cubes = np.stack(np.unravel_index(processed, tuple(div)), axis=1).astype(np.int64)
    cx.processed_cubes = _frozen(cubes.reshape(-1, n))
    return cx


