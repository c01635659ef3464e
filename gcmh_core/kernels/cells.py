"""Cells and their r-faces (paper 3.1.2): faces of the cube, local codes and keys, pieces of G_H."""

import numba as nb
import numpy as np

from .._config import INLINE_JIT, JIT
from .solve import _simplex_crosses_call, _zero_side


@nb.njit(**INLINE_JIT)
def _find(parent, v):
    while parent[v] != v:
        parent[v] = parent[parent[v]]
        v = parent[v]
    return v


@nb.njit(**JIT)
def _face_in_face(g_free, g_fixed, f_free, f_fixed):
    """Is the cube face (g_free, g_fixed) contained in the face (f_free, f_fixed)?"""
    return (g_free & ~f_free) == 0 and (g_fixed & ~f_free) == f_fixed


@nb.njit(**JIT)
def _local_code(f_free, g_free, g_fixed, perm, k, kfact, binom):
    """Code of the vertex (k-face g, permutation perm) inside the face f that holds g."""
    pos = 0
    rank = 0
    i = 0
    bits = 0
    j = 0
    a = 0
    while (f_free >> a) != 0:
        if (f_free >> a) & 1:
            if (g_free >> a) & 1:
                i += 1
                rank += binom[pos, i]  # colex rank of g's axes among f's
            else:
                bits |= ((g_fixed >> a) & 1) << j
                j += 1
            pos += 1
        a += 1
    return (rank * (np.int64(1) << j) + bits) * kfact + perm


@nb.njit(**JIT)
def _face_key(face_corner, n_subsets_dim, rank):
    """Global key of a cube face: its first corner's grid vertex, then its axes' rank."""
    return face_corner * n_subsets_dim + rank


@nb.njit(**JIT)
def _joined_pieces(values, o, corner_row, corner_signs, all_signs, kuhn, ksimplex_kuhn, vertex_ksimplex,
                   f_free, f_fixed, cells, first, last, kuhn_parent, mat, rhs, lam):
    """How many of the r-cells cells[first:last] (pieces of G_H in the cube face (f_free,
    f_fixed), cells[c, 1] a vertex of each) M_A joins through the face: the cells minus the
    pieces of M_A in f that hold them, found by marching the face's CFK simplices (CMS).
    Not 0: a piece of M_A in f is not a ball (a tube through f meets its boundary in
    several spheres), and GCMH's cells there do not have M_A's topology.
    """
    k = kuhn.k
    start = kuhn.start
    corners = kuhn.corners
    facets = kuhn.facets
    for s in range(start[k], start[kuhn.n + 1]):
        kuhn_parent[s] = -1  # not crossed, or not in f
    dim = 0
    for a in range(kuhn.n):
        dim += (f_free >> a) & 1
    for d in range(k, dim + 1):
        for s in range(start[d], start[d + 1]):
            # a chain lies in f when its first and last corners do
            if (corners[s, 0] & ~f_free) != f_fixed or (corners[s, d] & ~f_free) != f_fixed:
                continue
            if d == k:
                hit = _simplex_crosses_call(
                    values, o, corner_row, corners, s, k, corner_signs, all_signs, mat, rhs, lam
                )
                if hit == 2:
                    hit = _zero_side(values, o, corner_row, corners, s, k, lam)
                if hit:
                    kuhn_parent[s] = s
                continue
            for j in range(d + 1):
                t = facets[s, j]
                if kuhn_parent[t] >= 0:
                    if kuhn_parent[s] < 0:
                        kuhn_parent[s] = s
                    ra = _find(kuhn_parent, s)
                    rb = _find(kuhn_parent, t)
                    if ra != rb:
                        kuhn_parent[rb] = ra
    joined = 0
    for c in range(first, last):
        rc = _find(kuhn_parent, ksimplex_kuhn[vertex_ksimplex[cells[c, 1]]])
        for c2 in range(first, c):
            if _find(kuhn_parent, ksimplex_kuhn[vertex_ksimplex[cells[c2, 1]]]) == rc:
                joined += 1
                break
    return joined
