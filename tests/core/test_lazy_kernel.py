"""The lazy kernel (`_tables.lazy_tables`, n >= 8 and large k: Kuhn simplices found by a pruned walk over
permutations, not read from tables) against the tables' kernel on the same arrays: the same records bit for bit, vertex
positions included, the same crossed facets and degenerate events.  Both run on any n (the
tables' kernel gets full tables for n >= 8 from `_build_cube_tables(lazy=False)`), so the prune's
margin is held to the solve on smooth systems, on random corner values (walks through (k+1)-faces
with several vertices) and on values with exact zeros (the sign prune's rule, `_zero_side`)."""

import numpy as np
import pytest
from kernel_grids import grid_layout

from gcmh_core import grid
from gcmh_core.kernels import gcmh
from gcmh_core.kernels import tables as _tables
from gcmh_core.kernels.lazy import cubes_chunk_lazy


def _tables_pair(n, k):
    quiet = lambda *a: None  # noqa: E731
    return _tables._build_cube_tables(n, k, quiet, lazy=False), _tables._build_cube_tables(n, k, quiet, lazy=True)


def _run(kernel, values, axes, tables):
    """kernel on every cube of the grid whose vertex values are `values` (dims..., k)."""
    n, k = len(axes), values.shape[-1]
    dims = np.array(values.shape[:-1], np.int64)
    origins, cube_row, corner_row = grid_layout(dims)
    lines = np.zeros((n, int(dims.max())))
    for a in range(n):
        lines[a, : dims[a]] = axes[a]
    flat = np.ascontiguousarray(values.reshape(-1, k), np.float64)
    return kernel(0, len(origins), flat, cube_row, origins, cube_row, lines, corner_row, corner_row, tables)


def assert_same_output(values, axes):
    n, k = len(axes), values.shape[-1]
    full, lazy = _tables_pair(n, k)
    assert lazy.ksimplex_corners.shape[0] == 0 < full.ksimplex_corners.shape[0]
    want = _run(gcmh._cubes_chunk_tables, values, axes, full)
    got = _run(cubes_chunk_lazy, values, axes, lazy)
    for a, b, name in zip(got[0], want[0], ("vertex keys", "vertex points", "edges", "cells", "incidences")):
        assert a.shape == b.shape, (name, a.shape, b.shape)
        assert np.array_equal(a.view(np.int64), b.view(np.int64)), name  # bit for bit
    np.testing.assert_array_equal(got[1], want[1])  # crossed facets
    assert got[2] == want[2]  # degenerate events
    return len(want[0][0])


def _axes(n, div, seed):
    return grid.perturbed_axes(np.array([(-1.0, 1.0)] * n), np.full(n, div, np.int64), seed)


def _smooth(axes, k, seed):
    """Random quadratics: F_j = c_j + b_j . x + x^T A_j x, shifted to vanish near the middle."""
    rng = np.random.default_rng(seed)
    n = len(axes)
    X = np.stack(np.meshgrid(*axes, indexing="ij"), -1)
    out = []
    for _ in range(k):
        A = rng.normal(size=(n, n)) * 0.4
        b = rng.normal(size=n)
        out.append(np.einsum("...i,ij,...j->...", X, A, X) + X @ b - 0.1 * rng.normal())
    return np.stack(out, -1)


@pytest.mark.parametrize("n, k, div, seed", [
    (4, 2, 3, 0), (5, 3, 2, 1), (6, 4, 2, 2), (6, 5, 2, 3), (7, 3, 2, 4), (7, 5, 2, 5), (8, 3, 2, 6),
    (8, 5, 2, 7), (8, 6, 1, 8), (8, 7, 1, 9),
])
def test_smooth_systems(n, k, div, seed):
    assert assert_same_output(_smooth(_axes(n, div, seed), k, seed), _axes(n, div, seed)) > 0


@pytest.mark.parametrize("n, k, seed", [(4, 3, 0), (5, 3, 1), (6, 4, 2), (7, 5, 3), (8, 6, 4), (8, 7, 5)])
def test_random_corner_values(n, k, seed):
    """Values drawn per vertex: rough data, many vertices per face and walks through (k+1)-faces."""
    rng = np.random.default_rng(seed)
    axes = _axes(n, 1, seed)
    values = rng.normal(size=(2,) * n + (k,))
    assert_same_output(values, axes)


@pytest.mark.parametrize("n, k, seed", [(4, 2, 0), (5, 3, 1), (6, 4, 2), (7, 4, 3), (8, 5, 4)])
def test_values_with_exact_zeros(n, k, seed):
    """Small integers, zeros among them: simplices with zeros on whole facets, decided by the
    sign prune's rule (0 counts as +epsilon) and `_zero_side`."""
    rng = np.random.default_rng(seed)
    axes = _axes(n, 1, seed)
    values = rng.integers(-2, 3, size=(2,) * n + (k,)).astype(np.float64)
    assert_same_output(values, axes)
