"""The row-major layout of a grid of vertex values, as the GCMH kernels take it (tests only)."""

import numpy as np


def grid_layout(dims):
    """(origins, cube_row, corner_row) of a grid with ``dims`` vertices per axis, values in C order:
    every cube's lowest corner, its row, and each corner mask's offset from that row."""
    dims = np.asarray(dims, np.int64)
    n = len(dims)
    strides = np.ones(n, np.int64)
    for a in range(n - 2, -1, -1):
        strides[a] = strides[a + 1] * dims[a + 1]
    origins = np.array(list(np.ndindex(*(dims - 1))), np.int64).reshape(-1, n)
    corner_row = np.array([sum(int(strides[a]) for a in range(n) if c >> a & 1) for c in range(1 << n)], np.int64)
    return origins, origins @ strides, corner_row
