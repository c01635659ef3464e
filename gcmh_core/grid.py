"""The perturbed domain grid and the cheap whole-grid pass that finds candidate cubes."""

from __future__ import annotations

from numbers import Integral

import numpy as np

from .errors import InputError

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
    Same (bounds, div, seed), same bits; seed is any non-negative integer, and
    distinct seeds give distinct grids.
    """
    seed = check_seed(seed)
    bounds = np.asarray(bounds, np.float64)
    axes = []
    for a, (lo, hi) in enumerate(bounds):
        d = int(div[a])
        h = (hi - lo) / d
        line = lo + h * np.arange(d + 1, dtype=np.float64)
        line[-1] = hi
        if amplitude:
            rng = np.random.default_rng(_entropy(seed, a))
            line[1:-1] += amplitude * h * rng.uniform(-1.0, 1.0, d - 1)
            inward = amplitude * h * rng.uniform(0.0, 1.0, 2)  # drawn after: interior lines unchanged
            line[0] += inward[0]
            line[-1] -= inward[1]
        axes.append(line)
    return axes


def check_seed(seed) -> int:
    """The seed as an int: any non-negative integer (InputError otherwise)."""
    if isinstance(seed, bool) or not isinstance(seed, (Integral, np.integer)):
        raise InputError(f"seed must be a non-negative integer, got {seed!r}")
    if seed < 0:
        raise InputError(f"seed must be a non-negative integer, got {seed}")
    return int(seed)


def _entropy(seed: int, axis: int) -> list[int]:
    """The random stream of one axis.  Seeds below 2^32 keep the words they always had
    (outputs are pinned); a larger seed appends its high part, so it can't fall back on
    a small seed's grid (they were cut to 32 bits).  numpy's SeedSequence reads a
    missing fourth word as 0, which no seed >= 2^32 has: distinct seeds, distinct words."""
    words = [seed & 0xFFFFFFFF, axis, 0x67636D68]
    if seed >> 32:
        words.append(seed >> 32)
    return words


def _code_dtype(k: int):
    # two bits per component (has >= 0, has < 0) plus one "non-finite" bit
    bits = 2 * k + 1
    for dt in (np.uint8, np.uint16, np.uint32, np.uint64):
        if bits <= np.iinfo(dt).bits:
            return dt
    raise ValueError("k too large")


def candidate_scan(values: np.ndarray, first_layer=None) -> tuple[np.ndarray, np.ndarray, bool]:
    """The candidate cubes of a block of vertices, and what the next block along axis 0 needs.

    values (d0+1, ..., d_{n-1}+1, k).  Returns (origins (m, n) int64 in C order, the
    codes of the last layer to pass on as the next block's `first_layer`, whether any
    value is not finite).  first_layer: the previous block's returned codes, when
    values[0] is that block's last layer (its codes are not computed again: with thin
    slabs that was half the work).
    """
    from .kernels import candidates  # (numba compiles on first use, not on import)

    values = np.ascontiguousarray(values, np.float64)
    dims = values.shape[:-1]
    n, k = len(dims), values.shape[-1]
    if n == 1:  # no plane axes: a cube is two neighbouring vertices (nothing to carry)
        return _candidate_scan_1d(values)
    planes = values.reshape(dims[0] * dims[1], -1, k)
    code_type = _code_dtype(k)  # the narrowest: the passes are memory-bound
    code = np.empty(planes.shape[:2], code_type)
    first = 0
    carried_bad = False
    if first_layer is not None:
        first = dims[1]
        code[:first] = np.reshape(first_layer, (first, -1))
        carried_bad = bool(np.any(first_layer & code_type(1 << (2 * k))))
    inner = np.array(dims[2:], np.int64)
    nonfinite = candidates.plane_codes(planes, code, first, inner)
    counts = np.zeros(max((dims[0] - 1) * (dims[1] - 1), 0), np.int64)
    none = np.zeros((0, n), np.int64)
    candidates.scan_candidates(code, dims[0], dims[1], inner, k, counts, counts, none)
    offsets = np.zeros(len(counts), np.int64)
    np.cumsum(counts[:-1], out=offsets[1:])
    origins = np.empty((int(counts.sum()), n), np.int64)
    if len(origins):
        candidates.scan_candidates(code, dims[0], dims[1], inner, k, counts, offsets, origins)
    return origins, code[-dims[1]:].reshape(dims[1:]).copy(), bool(nonfinite) or carried_bad


def _candidate_scan_1d(values):
    """n = 1: cube i is the interval between vertices i and i + 1."""
    finite = np.isfinite(values).all(axis=1)
    pos = values >= 0
    both = finite[:-1] & finite[1:] & np.all(pos[:-1] != pos[1:], axis=1)
    return np.flatnonzero(both).astype(np.int64)[:, None], np.zeros(0, np.uint8), not finite.all()


def candidate_origins(values: np.ndarray, first_layer=None) -> tuple[np.ndarray, np.ndarray]:
    """(m, n) int64 origins of the candidate cubes, in C order, and the codes to pass on
    as the next slab's `first_layer` (see `candidate_scan`)."""
    origins, last, _ = candidate_scan(values, first_layer)
    return origins, last


def candidate_cubes(values: np.ndarray) -> np.ndarray:
    """Boolean (d0, ..., d_{n-1}) mask of cubes where every component has both signs.

    values (d0+1, ..., d_{n-1}+1, k).  A cube with a non-finite corner is never a
    candidate.
    """
    mask = np.zeros(tuple(s - 1 for s in np.shape(values)[:-1]), bool)
    mask[tuple(candidate_origins(values)[0].T)] = True
    return mask


def candidate_corner_sets(corner_values: np.ndarray, n_corners: int) -> np.ndarray:
    """(m,) bool: the same test as `candidate_cubes` for m cubes given corner by corner.

    corner_values (m * n_corners, k): each cube's corner values, one cube after the
    other (continuation gathers them so for a wave of scattered cubes).
    """
    from .kernels import candidates

    values = np.ascontiguousarray(corner_values, np.float64)
    out = np.empty(len(values) // n_corners, np.bool_)
    candidates.corner_sets_to_candidates(values, n_corners, out)
    return out
