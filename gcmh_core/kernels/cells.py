"""Cells and their r-faces (paper 3.1.2): faces of the cube, local codes and keys, pieces of G_H."""

import numba as nb
import numpy as np

from .._config import INLINE_JIT, JIT
from .records import _grown_rows
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


@nb.njit(**INLINE_JIT)
def _cube_cells(cube, g_vertex, corner_vertex, n, k, kfact, binom, faces, nv, vertices, ne, edges, parent,
                cell_of_root, lower, cells, records, used_e, used_c, used_i, values, o, corner_row, corner_signs,
                all_signs, balls, solve_scratch, non_ball, n_non_ball):
    """The cells step of GCMH on one cube (paper 3.1.2), for both kernels (`gcmh.cubes_chunk`,
    `lazy.cubes_chunk_lazy`): for r = 1..n-k, the r-cells are the connected pieces of the
    vertex-edge graph (vertices 0..nv-1, edges 0..ne-1) inside each (r+k)-face; for r = 1
    they are the edges themselves.  Rows of lower/cells: (face, a vertex of the piece, key);
    the buffers swap per level.  Where a face holds several pieces and balls' check_balls,
    `_joined_pieces` says whether M_A joins them there: rows (cube, face, pieces joined) of
    non_ball.  Writes the edge, cell and incidence records from rows used_e, used_c, used_i.
    Returns ((e_out, c_out, i_out), cells, incidences, degenerate events, non_ball, n_non_ball).

    Inlined, and the arrays come in tuples: Python passes a call of more than 30 arguments
    as one tuple, which numba cannot inline; as a plain call per cube, the arrays' reference
    counts cost more than a cube's work.
    """
    face_start, face_free, face_fixed, face_rank, n_subsets, n_codes = faces
    vertex_face, vertex_perm, vertex_key, vertex_ksimplex = vertices
    edge_a, edge_b, edge_face = edges
    e_out, c_out, i_out = records
    check_balls, kuhn, ksimplex_kuhn, kuhn_parent = balls
    mat, rhs, lam = solve_scratch
    k1 = k + 1
    degenerate = 0
    if lower.shape[0] < ne:
        lower = np.empty((ne, 3), np.int64)
    for e in range(ne):
        f = edge_face[e]
        ca = _local_code(
            face_free[f], face_free[vertex_face[edge_a[e]]], face_fixed[vertex_face[edge_a[e]]],
            vertex_perm[edge_a[e]], k, kfact, binom,
        )
        cb = _local_code(
            face_free[f], face_free[vertex_face[edge_b[e]]], face_fixed[vertex_face[edge_b[e]]],
            vertex_perm[edge_b[e]], k, kfact, binom,
        )
        lower[e, 0] = f
        lower[e, 1] = edge_a[e]
        lower[e, 2] = (
            _face_key(g_vertex + corner_vertex[face_fixed[f]], n_subsets[k1], face_rank[f]) * n_codes[k1]
            + min(ca, cb)
        )
        row = used_e + e
        if row >= e_out.shape[0]:
            e_out = _grown_rows(e_out, row)
        e_out[row, 0] = lower[e, 2]
        e_out[row, 1] = vertex_key[edge_a[e]]
        e_out[row, 2] = vertex_key[edge_b[e]]
    n_lower = ne
    n_cells = 0
    n_incidences = 0
    for r in range(2, n - k + 1):
        dim = r + k
        face0 = face_start[dim]
        n_faces = face_start[dim + 1] - face0
        n_here = np.int64(0)
        for fi in range(n_faces):
            f = face0 + fi
            n_in = 0
            for v in range(nv):
                if _face_in_face(
                    face_free[vertex_face[v]], face_fixed[vertex_face[v]], face_free[f], face_fixed[f]
                ):
                    parent[v] = v
                    n_in += 1
                else:
                    parent[v] = -1
            if n_in == 0:
                continue
            has_edge = False
            for e in range(ne):
                if _face_in_face(face_free[edge_face[e]], face_fixed[edge_face[e]], face_free[f], face_fixed[f]):
                    has_edge = True
                    ra = _find(parent, edge_a[e])
                    rb = _find(parent, edge_b[e])
                    if ra != rb:
                        parent[max(ra, rb)] = min(ra, rb)
            if not has_edge:
                continue
            # a piece needs an edge: a vertex left alone in f (degenerate data) is no r-cell
            for v in range(nv):
                cell_of_root[v] = -1
            for e in range(ne):
                if _face_in_face(face_free[edge_face[e]], face_fixed[edge_face[e]], face_free[f], face_fixed[f]):
                    cell_of_root[_find(parent, edge_a[e])] = -2
            if cells.shape[0] < n_here + n_in:  # rare: grow the buffer (n_in <= its first size)
                cells = _grown_rows(cells, n_here)
            first = n_here
            ff = face_free[f]
            for v in range(nv):  # a root is its piece's smallest vertex index: it comes first
                if parent[v] >= 0:
                    root = _find(parent, v)
                    code = _local_code(
                        ff, face_free[vertex_face[v]], face_fixed[vertex_face[v]],
                        vertex_perm[v], k, kfact, binom,
                    )
                    if root == v:
                        if cell_of_root[v] != -2:
                            continue
                        cell_of_root[v] = n_here
                        cells[n_here, 0] = f
                        cells[n_here, 1] = v
                        cells[n_here, 2] = code
                        n_here += 1
                    else:
                        c = cell_of_root[root]
                        if c >= 0 and code < cells[c, 2]:
                            cells[c, 2] = code
            fkey = _face_key(g_vertex + corner_vertex[face_fixed[f]], n_subsets[dim], face_rank[f]) * n_codes[dim]
            for c in range(first, n_here):
                cells[c, 2] += fkey
                row = used_c + n_cells + c
                if row >= c_out.shape[0]:
                    c_out = _grown_rows(c_out, row)
                c_out[row, 0] = r
                c_out[row, 1] = cells[c, 2]
            if n_here - first >= 2 and check_balls:  # several pieces: does M_A join them in f?
                joined = _joined_pieces(
                    values, o, corner_row, corner_signs, all_signs, kuhn, ksimplex_kuhn, vertex_ksimplex,
                    face_free[f], face_fixed[f], cells, first, n_here, kuhn_parent, mat, rhs, lam,
                )
                if joined:
                    if n_non_ball >= non_ball.shape[0]:
                        non_ball = _grown_rows(non_ball, n_non_ball)
                    non_ball[n_non_ball, 0] = cube
                    non_ball[n_non_ball, 1] = f
                    non_ball[n_non_ball, 2] = joined
                    n_non_ball += 1
            # its (r-1)-faces: each lower-level piece in a face g of f lies in one piece of f
            for y in range(n_lower):
                if not _face_in_face(face_free[lower[y, 0]], face_fixed[lower[y, 0]], face_free[f], face_fixed[f]):
                    continue
                rep = lower[y, 1]
                if parent[rep] < 0:
                    degenerate += 1
                    continue
                row = used_i + n_incidences
                if row >= i_out.shape[0]:
                    i_out = _grown_rows(i_out, row)
                i_out[row, 0] = r
                i_out[row, 1] = cells[cell_of_root[_find(parent, rep)], 2]
                i_out[row, 2] = lower[y, 2]
                n_incidences += 1
        n_cells += n_here
        swap = lower
        lower = cells
        cells = swap
        n_lower = n_here
    return (e_out, c_out, i_out), n_cells, n_incidences, degenerate, non_ball, n_non_ball
