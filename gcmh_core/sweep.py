"""The full sweep: every cube of the grid (GCMH, paper Section 3; CMS, Section 4).

F is evaluated slab by slab along axis 0, so memory grows like div^(n-1); each
slab goes through the candidate pass (a cube where some component of F has one
strict sign at all 2^n corners cannot hold M) and the candidates through the
per-cube kernel of the `Grid` (hypercube cells for "gcmh", Kuhn simplices for "cms").
"""

from __future__ import annotations

import time

import numpy as np

from .complex import CellComplex
from .errors import Cancelled
from .runner import Grid

__all__ = ["run_sweep", "SLAB_VERTICES"]

# Vertices evaluated per slab: bounds the memory of a run independently of div along axis 0.
SLAB_VERTICES = 1 << 22


def run_sweep(n, k, axes, system, sampled, progress, cancel, grid=None) -> CellComplex:
    """Every cube of the grid, in slabs along axis 0 (F on one slab's vertices at a time)."""
    grid = Grid(n, k, axes) if grid is None else grid
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
