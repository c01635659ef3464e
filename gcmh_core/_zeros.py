"""Exact zeros in F's values (issue 13, item 3): sampled data, or F vanishing on a grid line.

For k = 1 a value 0 is read as +epsilon by the sign tests, and a crossing is decided by signs
alone, so the complex is well formed.  For k >= 2 a crossing is decided by a solve, and values
0 at corners put zeros exactly on facets of Kuhn simplices, where neighbouring simplices
decided apart from each other (hundreds of malformed cells on sampled data with zeros).

Here a value F_j(v) = 0 becomes +delta_j (1 + u(v, j)) before any kernel sees it, with
delta_j = 2^-30 of F_j's scale over the domain and u in [0, 1) a hash of the vertex's
coordinates and j.  The shift depends on the vertex and the component only, so every cube,
slab, wave and worker sees the same values, and values that were 0 are now generic: the
zero set is that of F moved by about 1e-9 of its scale where it was 0, a move far below
the grid's own error.  (A finite shift, not the symbolic perturbation of Edelsbrunner and
Muecke's simulation of simplicity: that needs exact determinants.  It keeps the sign rule
of k = 1, where 0 counts as positive.)
"""

from __future__ import annotations

import numpy as np

__all__ = ["ZERO_SHIFT", "shift_grid", "shift_points", "zero_shift"]

ZERO_SHIFT = 2.0**-30  # of a component's scale
_SAMPLES = 512  # random points that measure F's scale when F is given as formulas

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)


def _mix(h: np.ndarray) -> np.ndarray:
    """splitmix64's finaliser (arrays only: numpy integer arrays wrap around silently)."""
    h = h ^ (h >> np.uint64(30))
    h = h * _M1
    h = h ^ (h >> np.uint64(27))
    h = h * _M2
    return h ^ (h >> np.uint64(31))


def _axis_hash(a: int, x: np.ndarray) -> np.ndarray:
    bits = np.ascontiguousarray(x, np.float64).view(np.uint64)
    return _mix(bits + np.full(bits.shape, a + 1, np.uint64) * _GOLDEN)


def _shifted(h: np.ndarray, j: int, delta: float) -> np.ndarray:
    u = (_mix(h + np.full(h.shape, j + 1, np.uint64) * _M2) >> np.uint64(11)).astype(np.float64) * 2.0**-53
    return delta * (1.0 + u)


def shift_grid(values: np.ndarray, axes, delta: np.ndarray) -> None:
    """In place: the zeros of values (d_0, ..., d_{n-1}, k), F on the grid axes[0] x ... ."""
    if values.all():  # (the common case: one pass, no temporary)
        return
    hashes = None
    for j in range(values.shape[-1]):
        zero = values[..., j] == 0.0
        if not zero.any():
            continue
        if hashes is None:
            hashes = [_axis_hash(a, np.asarray(ax, np.float64).reshape(-1)) for a, ax in enumerate(axes)]
        where = np.nonzero(zero)
        h = np.zeros(len(where[0]), np.uint64)
        for a, idx in enumerate(where):
            h = h + hashes[a][idx]
        values[..., j][where] = _shifted(h, j, float(delta[j]))


def shift_points(values: np.ndarray, P: np.ndarray, delta: np.ndarray) -> None:
    """In place: the zeros of values (m, k), F at the points P (m, n); the same shift a grid
    vertex with those coordinates gets from `shift_grid`."""
    if values.all():
        return
    for j in range(values.shape[-1]):
        zero = values[:, j] == 0.0
        if not zero.any():
            continue
        h = np.zeros(int(zero.sum()), np.uint64)
        for a in range(P.shape[1]):
            h = h + _axis_hash(a, P[zero, a])
        values[zero, j] = _shifted(h, j, float(delta[j]))


def zero_shift(system=None, bounds=None, sampled=None) -> np.ndarray:
    """delta_j for each component: ZERO_SHIFT times F_j's largest finite |value| over the
    sampled data, or at random points of the box (a fixed draw: the same run, the same shift)."""
    if sampled is not None:
        vals = sampled.reshape(-1, sampled.shape[-1])
    else:
        bounds = np.asarray(bounds, np.float64)
        rng = np.random.default_rng(0)
        P = bounds[:, 0] + rng.random((_SAMPLES, len(bounds))) * (bounds[:, 1] - bounds[:, 0])
        vals = system.evaluate_points(P)
    scale = np.where(np.isfinite(vals), np.abs(vals), 0.0).max(axis=0, initial=0.0)
    return ZERO_SHIFT * np.where(scale > 0, scale, 1.0)
