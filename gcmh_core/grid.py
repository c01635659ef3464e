"""The perturbed domain grid and the cheap whole-grid pass that finds candidate cubes."""

from __future__ import annotations

import numpy as np

# Grid lines move by at most this fraction of the spacing.  The paper perturbs
# grid vertices so that none lies exactly on M.  We perturb each grid *line*
# (the offset of line j on axis a depends only on (seed, a, j)): a vertex then
# gets the same vector in every cube that holds it, and the grid stays a tensor
# product, so a subexpression of F in a few variables is evaluated on the
# sub-grid of those axes and broadcast.
PERTURBATION = 1e-3


def perturbed_axes(bounds, div, seed: int = 0, amplitude: float = PERTURBATION) -> list[np.ndarray]:
    """Coordinates of the grid lines, one (div[a] + 1,) float64 array per axis.

    bounds (n, 2) float64, div (n,) int.  Line j of axis a sits at
    lo + j h (+ a seeded offset of at most amplitude*h).  The domain's own
    boundary lines move too, inwards only (F is never evaluated outside the
    box): left in place, a bound that is a "nice" number (0, 2 pi, the extent of
    M) can make a component of F vanish at every vertex of a boundary face, and
    then a zero of the interpolant lies on a (k-1)-face of the grid, which the
    Kuhn simplices disagree about (degenerate events, a wrong complex).
    Interior offsets don't depend on the boundary ones.
    Same (bounds, div, seed), same bits.
    """
    bounds = np.asarray(bounds, np.float64)
    axes = []
    for a, (lo, hi) in enumerate(bounds):
        d = int(div[a])
        h = (hi - lo) / d
        line = lo + h * np.arange(d + 1, dtype=np.float64)
        line[-1] = hi
        if amplitude:
            rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, a, 0x67636D68])
            line[1:-1] += amplitude * h * rng.uniform(-1.0, 1.0, d - 1)
            inward = amplitude * h * rng.uniform(0.0, 1.0, 2)  # drawn after: interior lines unchanged
            line[0] += inward[0]
            line[-1] -= inward[1]
        axes.append(line)
    return axes


def _code_dtype(k: int):
    # two bits per component (has >= 0, has < 0) plus one "non-finite" bit
    bits = 2 * k + 1
    for dt in (np.uint8, np.uint16, np.uint32, np.uint64):
        if bits <= np.iinfo(dt).bits:
            return dt
    raise ValueError("k too large")


def _candidate_flags(values: np.ndarray, first_layer=None) -> tuple[np.ndarray, np.ndarray]:
    """(d0+1, ..., d_{n-1}+1) bool: at vertex v, whether the cube with origin v is a
    candidate (meaningless on each axis's last layer, where no cube starts); and the
    sign codes of the last layer along axis 0, OR-ed along the other axes.

    The OR of the corners' sign codes is separable, so it costs one parallel
    in-place pass per axis (numba) instead of 2^n gathers per cube.  first_layer:
    the previous slab's returned codes, when values[0] is that slab's last layer
    (its codes are not computed again: with thin slabs that was half the work).
    """
    from . import _kernels  # noqa: PLC0415  (numba compiles on first use, not on import)

    values = np.ascontiguousarray(values, np.float64)
    dims = values.shape[:-1]
    k = values.shape[-1]
    layer = int(np.prod(dims[1:]))
    code = np.empty(int(np.prod(dims)), _code_dtype(k))  # the narrowest: the OR passes are memory-bound
    skip = 0 if first_layer is None else layer
    if skip:
        code[:layer] = first_layer
    fresh = code[skip:]
    _kernels.vertex_sign_codes(values.reshape(-1, k)[skip:], fresh)
    stride = 1
    for axis in range(len(dims) - 1, 0, -1):  # within each layer
        length = dims[axis]
        if length > 1:
            _kernels.or_with_next_along_axis(fresh, fresh.size // (length * stride), length, stride)
        stride *= length
    last = code[-layer:].copy()  # (the pass along axis 0 leaves the last layer as it is)
    if dims[0] > 1:
        _kernels.or_with_next_along_axis(code, 1, dims[0], layer)
    out = np.empty(code.size, np.bool_)
    _kernels.codes_to_candidates(code, k, out)
    return out.reshape(dims), last


def candidate_cubes(values: np.ndarray) -> np.ndarray:
    """Boolean (d0, ..., d_{n-1}) mask of cubes where every component has both signs.

    values (d0+1, ..., d_{n-1}+1, k).  A cube with a non-finite corner is never a
    candidate.
    """
    flags = _candidate_flags(values)[0]
    return flags[tuple(slice(0, d - 1) for d in flags.shape)]


def candidate_origins(values: np.ndarray, first_layer=None) -> tuple[np.ndarray, np.ndarray]:
    """(m, n) int64 origins of the candidate cubes, in C order (`candidate_cubes`'s
    True entries, found on the contiguous flags: np.nonzero on the strided mask took
    as long as the rest of the pass); and the codes to pass on as the next slab's
    `first_layer` (see `_candidate_flags`)."""
    flags, last = _candidate_flags(values, first_layer)
    dims = flags.shape
    origins = np.stack(np.unravel_index(np.flatnonzero(flags), dims), axis=1).astype(np.int64, copy=False)
    return origins[np.all(origins < np.array(dims) - 1, axis=1)], last


def candidate_corner_sets(corner_values: np.ndarray, n_corners: int) -> np.ndarray:
    """(m,) bool: the same test as `candidate_cubes` for m cubes given corner by corner.

    corner_values (m * n_corners, k): each cube's corner values, one cube after the
    other (continuation gathers them so for a wave of scattered cubes).
    """
    from . import _kernels  # noqa: PLC0415

    values = np.ascontiguousarray(corner_values, np.float64)
    out = np.empty(len(values) // n_corners, np.bool_)
    _kernels.corner_sets_to_candidates(values, n_corners, out)
    return out
