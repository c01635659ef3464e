"""The GCMH kernel's phases over a chunk (`gcmh.cubes_chunk`): a phase stops before a cube whose rows
might not fit, the driver grows the chunk's arrays and runs it again from that cube.  On rough data
(random corner values: many vertices, edges and incidences a cube) a whole grid in one chunk goes
through those restarts; cube by cube, each cube alone in a chunk sized for it, it never does.  Both
give the same records, bit for bit, in cube order."""

import numpy as np
import pytest
from kernel_grids import grid_layout

from gcmh_core.kernels import gcmh
from gcmh_core.kernels import tables as _tables


def _grid(n, div, seed):
    """Random corner values on a grid of div^n cubes: the arrays `cubes_chunk` takes."""
    rng = np.random.default_rng(seed)
    origins, cube_row, corner_row = grid_layout(np.full(n, div + 1))
    lines = np.tile(np.arange(div + 1, dtype=np.float64), (n, 1)) + rng.uniform(-0.1, 0.1, (n, div + 1))
    return origins, cube_row, corner_row, lines, rng


@pytest.mark.parametrize("n, k, div, seed", [(4, 2, 4, 0), (4, 1, 3, 1), (5, 3, 2, 2), (5, 2, 2, 3)])
def test_one_chunk_with_restarts_is_every_cube_alone(n, k, div, seed):
    origins, cube_row, corner_row, lines, rng = _grid(n, div, seed)
    values = rng.normal(size=((div + 1) ** n, k))
    tab = _tables.cube_tables(n, k)
    m = len(origins)
    whole = gcmh.cubes_chunk(0, m, values, cube_row, origins, cube_row, lines, corner_row, corner_row, tab)
    alone = [gcmh.cubes_chunk(i, i + 1, values, cube_row, origins, cube_row, lines, corner_row, corner_row, tab)
             for i in range(m)]
    for part, name in enumerate(("vertex keys", "vertex points", "edges", "cells", "incidences")):
        got = whole[0][part]
        want = np.concatenate([a[0][part] for a in alone])
        assert got.shape == want.shape, name
        assert np.array_equal(got.view(np.int64), want.view(np.int64)), name  # bit for bit
    np.testing.assert_array_equal(whole[1], np.concatenate([a[1] for a in alone]))  # crossed facets
    assert whole[2] == sum(a[2] for a in alone)  # degenerate events
    non_ball = np.concatenate([a[3] + [i, 0, 0] for i, a in enumerate(alone)])
    np.testing.assert_array_equal(whole[3], non_ball.reshape(-1, 3))
    # the chunk's first arrays (8 rows a cube and 16) were too short: phase 1 and the cells phase restarted
    assert len(whole[0][0]) > 8 * m + 16 and len(whole[0][4]) > 8 * m + 16
