"""Slow, obviously correct twins of the numba kernels `gcmh_core._balls` calls (issue 25)."""

import numpy as np


def naive_same_faces_candidates(offsets, faces):
    """`kernels.cell_check.same_faces_candidates` with no hash: a cell is marked when another cell
    lists the same faces (as a multiset, in any order)."""
    rows = [tuple(sorted(faces[offsets[i] : offsets[i + 1]].tolist())) for i in range(len(offsets) - 1)]
    count: dict = {}
    for row in rows:
        count[row] = count.get(row, 0) + 1
    return np.array([count[row] > 1 for row in rows], bool)
