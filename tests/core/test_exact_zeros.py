"""Exact zeros and degenerate values by simulation of simplicity (issue 25, item 1).

F sampled on a grid through M: values exactly 0 at vertices, components 0 on whole grid
hyperplanes, quantized values whose images at a facet's corners are affinely dependent with 0
(a torus through grid vertices gave chi 138 for 0, 960 degenerate events).  The kernels read
F_j(v) as F_j(v) + eps^(2^order(v, j)) (`kernels.solve._zero_side`): every
method gives a valid regular complex with the right topology, and nothing is degenerate.
"""

import itertools

import numpy as np
import pytest

from gcmh_core import extract
from gcmh_core.kernels.solve import _zero_side, simplex_crosses

from naive import simplex_lambdas, structure_problems

METHODS = ["gcmh", "gcch", "cms", "ccs"]


def _solve(vals, k):
    """The kernels' answer on the simplex whose corners are vals' rows (chain order)."""
    m = k + 1
    idx = np.arange(m, dtype=np.int64)
    pos = np.array([sum(1 << j for j in range(k) if vals[c, j] >= 0) for c in range(m)], np.int64)
    mat, rhs, lam = np.empty((k, k)), np.empty(k), np.empty(m)
    got = simplex_crosses(np.ascontiguousarray(vals, np.float64), 0, idx, idx[None], 0, k, pos, (1 << k) - 1,
                          mat, rhs, lam)
    symbolic = got == 2
    if symbolic:
        got = _zero_side(np.ascontiguousarray(vals, np.float64), 0, idx, idx[None], 0, k, lam)
    return got, lam, symbolic


def _degenerate_values(rng, shape):
    """Small integers (a third of them 0), sometimes scaled per component: most simplices
    have zeros, repeated values or values affinely dependent with 0."""
    vals = rng.integers(-2, 3, shape).astype(np.float64)
    return vals * 10.0 ** rng.integers(-8, 9, shape[-1])


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_solve_matches_the_exact_twin_on_degenerate_values(k):
    """The kernel's solve (floats, `_sos_det`) against the twin's exact Cramer's rule in the
    eps symbols (`naive.simplex_lambdas`, rational arithmetic): the same answer, the same limit."""
    rng = np.random.default_rng(250 + k)
    hits = symbolic = 0
    for trial in range(600 if k < 4 else 200):
        vals = _degenerate_values(rng, (k + 1, k)) if trial % 4 else rng.normal(size=(k + 1, k))
        if trial % 2:  # the zero at the corners' centroid: inside, or on a facet when some are equal
            vals[k] = -vals[:k].sum(axis=0)
        got, lam, by_sos = _solve(vals, k)
        symbolic += by_sos
        want = simplex_lambdas(vals)
        assert bool(got) == (want is not None), (k, trial, vals, lam, want)
        if got:
            hits += 1
            assert np.allclose(lam, want, rtol=0, atol=1e-9), (k, trial, vals, lam, want)
    assert hits > 30 and symbolic >= 5  # the degenerate cases were reached (k = 1: 26 of 600, k = 4: 10 of 200)


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_a_simplex_has_an_even_number_of_crossed_facets(k):
    """On a (k+1)-simplex, M_A enters and leaves: 0 or 2 crossed k-facets, however degenerate the
    values.  Each facet is decided from its own corners (chain order), as every cube decides it."""
    rng = np.random.default_rng(260 + k)
    crossed_two = 0
    for _ in range(400 if k < 4 else 120):
        vals = _degenerate_values(rng, (k + 2, k))
        count = sum(bool(_solve(vals[list(facet)], k)[0]) for facet in itertools.combinations(range(k + 2), k + 1))
        assert count in (0, 2), vals
        crossed_two += count == 2
    assert crossed_two > 20


def _grid(n, points):
    """Integer coordinates centred on the box's middle vertex: exact values at every vertex."""
    c = (points - 1) // 2
    return [g - c for g in np.meshgrid(*[np.arange(points, dtype=np.float64)] * n, indexing="ij")]


def _circle(g, a, R):
    return g[a] ** 2 + g[a + 1] ** 2 - R * R


def sampled(shape, n, points):
    """(values, chi, components) of a shape through grid vertices, radius (points - 1) / 4 grid units."""
    g = _grid(n, points)
    R = (points - 1) // 4
    if shape == "sphere":  # S^(n-1), k = 1
        return np.stack([sum(x * x for x in g) - R * R], -1), 1 + (-1) ** (n - 1), 1
    if shape == "sphere-cut":  # S^(n-2): x_n is exactly 0 on the grid hyperplane through the centre
        return np.stack([sum(x * x for x in g) - R * R, g[n - 1]], -1), 1 + (-1) ** (n - 2), 1
    if shape == "sphere-half-zero":  # min(x1, 0) is exactly 0 on half the grid: S^(n-2) where x1 turns negative
        return np.stack([sum(x * x for x in g) - R * R, np.minimum(g[0], 0.0)], -1), 1 + (-1) ** (n - 2), 1
    if shape == "torus":  # the torus of revolution in R^3, tube radius R/2
        rho2 = g[0] ** 2 + g[1] ** 2
        r = R / 2
        return np.stack([(rho2 + g[2] ** 2 + R * R - r * r) ** 2 - 4 * R * R * rho2], -1), 0, 1
    if shape == "flat-torus":  # S^1 x S^1 in R^4, then in flats x5 = 0, x6 = 0 (k = 2, 3, 4)
        comps = [_circle(g, 0, R), _circle(g, 2, R)] + [g[a] for a in range(4, n)]
        return np.stack(comps, -1), 0, 1
    if shape == "three-torus":  # S^1 x S^1 x S^1 in R^6, k = 3
        return np.stack([_circle(g, 0, R), _circle(g, 2, R), _circle(g, 4, R)], -1), 0, 1
    raise ValueError(shape)


CASES = [
    # (shape, n, grid points)
    ("sphere", 3, 5), ("sphere", 3, 9), ("sphere", 3, 13), ("sphere", 3, 17),
    ("torus", 3, 9), ("torus", 3, 17),
    ("sphere-cut", 3, 9), ("sphere-half-zero", 3, 9),
    ("sphere", 4, 5), ("sphere", 4, 9),
    ("sphere-cut", 4, 9), ("sphere-cut", 4, 13), ("sphere-half-zero", 4, 9),
    ("flat-torus", 4, 5), ("flat-torus", 4, 9), ("flat-torus", 4, 13), ("flat-torus", 4, 17),
    ("sphere-cut", 5, 5), ("flat-torus", 5, 5), ("flat-torus", 5, 9),
    ("flat-torus", 6, 5), ("three-torus", 6, 5),
]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("shape, n, points", CASES)
def test_grids_through_M_give_valid_complexes(shape, n, points, method):
    values, chi, pieces = sampled(shape, n, points)
    if method in ("cms", "ccs") and n * points > 30:
        pytest.skip("CMS's n! simplices per cube: the small grids cover it")
    assert (values == 0).any()
    bounds = [(-1.0, 1.0)] * n
    start = "auto" if method in ("gcch", "ccs") else None
    cx = extract(values, bounds, method=method, start=start)
    assert cx.meta["degenerate"] == 0
    assert structure_problems(cx, bounds, points - 1) == []
    assert cx.euler_characteristic() == chi
    assert cx.connected_components() == pieces
    assert len(cx.boundary_facets()) == 0


def test_the_issue_torus_through_grid_vertices():
    """The case of the issue: chi 138, 88 2-cells of one or two edges, 960 degenerate events."""
    g = np.meshgrid(*[np.linspace(-1, 1, 9)] * 4, indexing="ij")
    values = np.stack([g[0] ** 2 + g[1] ** 2 - 0.25, g[2] ** 2 + g[3] ** 2 - 0.25], -1)
    assert (values == 0).all(axis=-1).sum() == 16  # M passes through 16 grid vertices
    out = {}
    for method in METHODS:
        start = "auto" if method in ("gcch", "ccs") else None
        cx = extract(values, [(-1, 1)] * 4, method=method, start=start)
        assert cx.meta["degenerate"] == 0 and structure_problems(cx, [(-1, 1)] * 4, 8) == []
        assert cx.euler_characteristic() == 0 and len(cx.boundary_facets()) == 0 and cx.connected_components() == 1
        out[method] = cx
    # continuation meets the same cells as the sweep: the order of zeros is the grid's, not the run's
    for a, b in [("gcmh", "gcch"), ("cms", "ccs")]:
        assert out[a].counts() == out[b].counts()
        assert np.array_equal(np.sort(out[a].vertices, axis=0), np.sort(out[b].vertices, axis=0))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("flip, pieces", [(False, 2), (True, 1)])
def test_zeros_across_a_seam(method, flip, pieces):
    """min(y, 0) is exactly 0 on half the grid, which wraps along the periodic x: the two lines
    y = 0-, z = +-0.7 close into two circles, or into one where the seam reverses z."""
    spec = {"x": {"flip": ["z"]}} if flip else {"x": True}
    start = "auto" if method in ("gcch", "ccs") else None
    B = [(-1, 1)] * 3
    cx = extract(["y^2+z^2-0.49", "min(y,0)"], B, 6, variables="x,y,z", method=method, start=start, periodic=spec)
    assert cx.meta["degenerate"] == 0 and structure_problems(cx) == []
    assert cx.euler_characteristic() == 0 and cx.connected_components() == pieces
    assert len(cx.boundary_facets()) == 0
