"""Exact zeros in F's values (issue 25, item 1): sampled data, or F vanishing on a grid line.

A value F_j(v) = 0, and any other degenerate configuration (F's values at a facet's corners
affinely dependent with 0: quantized data, a torus through grid vertices), is resolved by
simulation of simplicity (Edelsbrunner and Muecke) inside the kernels, never by moving values:

* every value F_j(v) is read as F_j(v) + eps^(2^order(v, j)), eps -> 0, with order(v, j) =
  q k + j where q is v's place in its simplex's chain of corners.  A chain's corners come in
  the grid's global vertex order (each step adds +1 along one axis), so the order agrees in
  every cube, slab, block, thread and wave that holds the simplex, and in every method (GCMH,
  GCCH, CMS, CCS and the cell check share `kernels.solve`);
* a sign test reads a value 0 as positive (the sign prune: 0 is +eps^order);
* the solve on a Kuhn simplex decides, where the zero is on a facet up to rounding or the
  simplex is flat, by the signs of the facets' determinants in the perturbed values
  (`kernels.solve._zero_side`, `_sos_det`): each depends on its facet only, so the simplices
  that share a facet agree, and a (k+1)-simplex has 0 or 2 crossed k-facets; the vertex
  is the limit eps -> 0 of the perturbed zero.

Formulas whose values have no such degeneracy never reach that path: their output is the
same bit for bit.  The values the kernels see are F's own, so continuation's Newton, the
sweep and a worker evaluate the same numbers.

The finite shift this module made before (a zero became +2^-30 of F_j's scale times a hash of
the vertex) left the solve degenerate on grids through M and is gone: `zero_shift` now says
"no shift" to the callers that still ask for one.
"""

from __future__ import annotations

import numpy as np

__all__ = ["shift_grid", "shift_points", "zero_shift"]


def zero_shift(system=None, bounds=None, sampled=None) -> None:
    """The finite shift of exact zeros: None, none (the kernels resolve zeros symbolically)."""
    return None


def shift_grid(values: np.ndarray, axes, delta) -> None:
    """Leaves the grid's values as they are (delta is `zero_shift`'s None)."""
    if delta is not None:
        raise ValueError("exact zeros are resolved symbolically by the kernels, not shifted")


def shift_points(values: np.ndarray, P: np.ndarray, delta) -> None:
    """Leaves the points' values as they are (delta is `zero_shift`'s None)."""
    shift_grid(values, None, delta)
