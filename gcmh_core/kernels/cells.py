"""Cells and their r-faces (paper 3.1.2): faces of the cube, local codes and keys, pieces of G_H."""

import numba as nb
import numpy as np

from .._config import INLINE_JIT, JIT
from .records import CELL_COLS, INC_COLS, _grown_rows
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
def tables_faces(tables):
    """The faces' arrays of `tables.CubeTables`, as `cells_phase` takes them."""
    return tables.face_start, tables.face_free, tables.face_fixed, tables.face_rank, tables.n_subsets, tables.n_codes


@nb.njit(**JIT)
def cells_phase(start, stop, lo, values, cube_row, corner_row, cube_vertex, corner_vertex, faces, binom, kuhn,
                ksimplex_kuhn, cube_v0, cube_e0, crossed_facets, vertex_key, vertex_face, vertex_perm, vertex_ksimplex,
                edge_a, edge_b, edge_face, edge_out, c_out, i_out, non_ball, levels, union, used):
    """The cells step of GCMH (paper 3.1.2) on the cubes start..stop-1 of a chunk (lo its first),
    for both kernels, once their vertices and edges are in the chunk's arrays (`records.new_chunk`).

    Per cube, for r = 1..n-k, the r-cells are the connected pieces of the vertex-edge graph G_H
    inside each (r+k)-face; for r = 1 they are the edges themselves.  Writes each cube's
    crossed facets (from its vertices' faces), the edge records (rows of the edges), and the
    cell and incidence records (c_out, i_out) and the rows (cube - lo, face, pieces joined) of
    non_ball after used = (rows of c_out, of i_out, of non_ball); levels and union (parent,
    cell_of_root) are scratch.  faces: `tables.CubeTables`' (face_start, face_free, face_fixed,
    face_rank, n_subsets, n_codes); binom, kuhn, ksimplex_kuhn: its fields.  Where a face
    holds several pieces and the tables list the cube's Kuhn triangulation, `_joined_pieces`
    says whether M_A joins them there.  Rows are committed per cube: where a cube's do
    not fit, it stops before that cube.
    Returns (the cube it stopped at (stop when done), cells, incidences, non_ball rows,
    degenerate events).

    One compiled function over the chunk: its arrays are counted once per call.  (Inlined
    into each kernel's loop over cubes, they were counted in and out for every cube.)  The
    arrays come one by one, and not the whole `tables`: each function that passes a large named
    tuple of arrays on took numba seconds more to compile.
    """
    face_start, face_free, face_fixed, face_rank, n_subsets, n_codes = faces
    used_c, used_i, n_non_ball = used
    parent = union[0]
    cell_of_root = union[1]
    n = binom.shape[0] - 1
    k = values.shape[1]
    kfact = np.int64(1)
    for i in range(2, k + 1):
        kfact *= i
    check_balls = ksimplex_kuhn.shape[0] > 0
    kuhn_parent = np.empty(kuhn.corners.shape[0], np.int64)
    corner_signs = np.empty(1 << n, np.int64)
    mat = np.empty((k, k), np.float64)
    rhs = np.empty(k, np.float64)
    lam = np.empty(k + 1, np.float64)
    all_signs = (np.int64(1) << k) - 1
    k1 = k + 1
    degenerate = 0
    for ci in range(start, stop):
        v0 = cube_v0[ci - lo]
        nv = cube_v0[ci - lo + 1] - v0
        e0 = cube_e0[ci - lo]
        ne = cube_e0[ci - lo + 1] - e0
        # facets of the cube that M_A crosses (bit 2a + side): where continuation goes next
        facets = np.int64(0)
        for v in range(v0, v0 + nv):
            f = vertex_face[v]
            for a in range(n):
                if not (face_free[f] >> a) & 1:
                    facets |= np.int64(1) << (2 * a + ((face_fixed[f] >> a) & 1))
        crossed_facets[ci - lo] = facets
        if nv == 0:
            continue
        if nv > union.shape[1] or ne > levels.shape[1]:
            return ci, used_c, used_i, n_non_ball, degenerate
        g_vertex = cube_vertex[ci]
        events = 0
        n_joined = n_non_ball
        signs_known = False
        low = 0  # levels[low]: the (r-1)-cells, rows (face, a vertex of the piece, key); levels[1 - low]: the r-cells
        for e in range(ne):
            f = edge_face[e0 + e]
            va = v0 + edge_a[e0 + e]
            vb = v0 + edge_b[e0 + e]
            ca = _local_code(face_free[f], face_free[vertex_face[va]], face_fixed[vertex_face[va]], vertex_perm[va],
                             k, kfact, binom)
            cb = _local_code(face_free[f], face_free[vertex_face[vb]], face_fixed[vertex_face[vb]], vertex_perm[vb],
                             k, kfact, binom)
            levels[low, e, 0] = f
            levels[low, e, 1] = edge_a[e0 + e]
            levels[low, e, 2] = (
                _face_key(g_vertex + corner_vertex[face_fixed[f]], n_subsets[k1], face_rank[f]) * n_codes[k1]
                + min(ca, cb)
            )
            edge_out[e0 + e, 0] = levels[low, e, 2]
            edge_out[e0 + e, 1] = vertex_key[va]
            edge_out[e0 + e, 2] = vertex_key[vb]
        n_lower = ne
        n_cells = 0
        n_incidences = 0
        for r in range(2, n - k + 1):
            high = 1 - low
            dim = r + k
            face0 = face_start[dim]
            n_faces = face_start[dim + 1] - face0
            n_here = np.int64(0)
            for fi in range(n_faces):
                f = face0 + fi
                n_in = 0
                for v in range(nv):
                    g = vertex_face[v0 + v]
                    if _face_in_face(face_free[g], face_fixed[g], face_free[f], face_fixed[f]):
                        parent[v] = v
                        n_in += 1
                    else:
                        parent[v] = -1
                if n_in == 0:
                    continue
                has_edge = False
                for e in range(e0, e0 + ne):
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
                for e in range(e0, e0 + ne):
                    if _face_in_face(face_free[edge_face[e]], face_fixed[edge_face[e]], face_free[f], face_fixed[f]):
                        cell_of_root[_find(parent, edge_a[e])] = -2
                if n_here + n_in > levels.shape[1]:
                    return ci, used_c, used_i, n_non_ball, degenerate
                first = n_here
                ff = face_free[f]
                for v in range(nv):  # a root is its piece's smallest vertex index: it comes first
                    if parent[v] >= 0:
                        root = _find(parent, v)
                        g = vertex_face[v0 + v]
                        code = _local_code(ff, face_free[g], face_fixed[g], vertex_perm[v0 + v], k, kfact, binom)
                        if root == v:
                            if cell_of_root[v] != -2:
                                continue
                            cell_of_root[v] = n_here
                            levels[high, n_here, 0] = f
                            levels[high, n_here, 1] = v
                            levels[high, n_here, 2] = code
                            n_here += 1
                        else:
                            c = cell_of_root[root]
                            if c >= 0 and code < levels[high, c, 2]:
                                levels[high, c, 2] = code
                if used_c + n_cells + n_here > c_out.shape[0]:
                    return ci, used_c, used_i, n_non_ball, degenerate
                fkey = _face_key(g_vertex + corner_vertex[face_fixed[f]], n_subsets[dim], face_rank[f]) * n_codes[dim]
                for c in range(first, n_here):
                    levels[high, c, 2] += fkey
                    row = used_c + n_cells + c
                    c_out[row, 0] = r
                    c_out[row, 1] = levels[high, c, 2]
                if n_here - first >= 2 and check_balls:  # several pieces: does M_A join them in f?
                    if not signs_known:
                        _signs(values, cube_row[ci], corner_row, k, corner_signs)
                        signs_known = True
                    joined = _joined_pieces(
                        values, cube_row[ci], corner_row, corner_signs, all_signs, kuhn, ksimplex_kuhn,
                        vertex_ksimplex[v0:v0 + nv], face_free[f], face_fixed[f], levels[high], first, n_here,
                        kuhn_parent, mat, rhs, lam,
                    )
                    if joined:
                        if n_joined >= non_ball.shape[0]:
                            return ci, used_c, used_i, n_non_ball, degenerate
                        non_ball[n_joined, 0] = ci - lo
                        non_ball[n_joined, 1] = f
                        non_ball[n_joined, 2] = joined
                        n_joined += 1
                # its (r-1)-faces: each lower-level piece in a face g of f lies in one piece of f
                for y in range(n_lower):
                    g = levels[low, y, 0]
                    if not _face_in_face(face_free[g], face_fixed[g], face_free[f], face_fixed[f]):
                        continue
                    rep = levels[low, y, 1]
                    if parent[rep] < 0:
                        events += 1
                        continue
                    row = used_i + n_incidences
                    if row >= i_out.shape[0]:
                        return ci, used_c, used_i, n_non_ball, degenerate
                    i_out[row, 0] = r
                    i_out[row, 1] = levels[high, cell_of_root[_find(parent, rep)], 2]
                    i_out[row, 2] = levels[low, y, 2]
                    n_incidences += 1
            n_cells += n_here
            low = high
            n_lower = n_here
        used_c += n_cells
        used_i += n_incidences
        n_non_ball = n_joined
        degenerate += events
    return stop, used_c, used_i, n_non_ball, degenerate


@nb.njit(**JIT)
def _signs(values, o, corner_row, k, corner_signs):
    """corner_signs[c], bit j: F_j >= 0 at corner c of the cube whose first row is o."""
    for c in range(corner_signs.shape[0]):
        p = np.int64(0)
        for j in range(k):
            if values[o + corner_row[c], j] >= 0.0:
                p |= np.int64(1) << j
        corner_signs[c] = p


@nb.njit(**INLINE_JIT)
def cells_of_chunk(lo, hi, values, cube_row, corner_row, cube_vertex, corner_vertex, faces, binom, kuhn, ksimplex_kuhn,
                   cube_v0, cube_e0, crossed_facets, vertex_key, vertex_face, vertex_perm, vertex_ksimplex, edge_a,
                   edge_b, edge_face, edge_out, rows, level_rows, vertex_rows):
    """`cells_phase` on the cubes lo..hi-1 of a chunk, its rows grown until every cube fits: first
    `rows` cell and incidence rows, `level_rows` pieces of a level, `vertex_rows` vertices a cube.
    Returns (cell records, incidence records, their rows, rows (cube - lo, face, pieces joined),
    degenerate events)."""
    c_out = np.empty((rows, CELL_COLS), np.int64)
    i_out = np.empty((rows, INC_COLS), np.int64)
    non_ball = np.empty((4, 3), np.int64)
    used_c = used_i = n_non_ball = np.int64(0)
    degenerate = 0
    start = lo
    while True:
        start, used_c, used_i, n_non_ball, events = cells_phase(
            start, hi, lo, values, cube_row, corner_row, cube_vertex, corner_vertex, faces, binom, kuhn, ksimplex_kuhn,
            cube_v0, cube_e0, crossed_facets, vertex_key, vertex_face, vertex_perm, vertex_ksimplex, edge_a, edge_b,
            edge_face, edge_out, c_out, i_out, non_ball, np.empty((2, level_rows, 3), np.int64),
            np.empty((2, vertex_rows), np.int64), (used_c, used_i, n_non_ball),
        )
        degenerate += events
        if start == hi:
            return c_out, i_out, used_c, used_i, non_ball[:n_non_ball].copy(), degenerate
        # a cube did not fit (it is done again): everything twice as large
        c_out = _grown_rows(c_out, used_c)
        i_out = _grown_rows(i_out, used_i)
        non_ball = _grown_rows(non_ball, n_non_ball)
        level_rows = 2 * level_rows + 1
        vertex_rows = 2 * vertex_rows + 1
