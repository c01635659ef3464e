"""GCMH on a chunk of candidate cubes (paper 3.1): the tables' kernel, and the choice of kernel."""

import numba as nb
import numpy as np

from .._config import JIT
from .cells import _face_key, cells_of_chunk, tables_faces
from .lazy import cubes_chunk_lazy
from .records import _records_upto, grown_chunk, new_chunk
from .solve import _simplex_crosses_call, _zero_side, simplex_crosses
from .walk import _link, _walk_edges


@nb.njit(**JIT)
def _vertices_edges(start, hi, lo, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex,
                    tables, cube_v0, cube_e0, vertex_key, vertex_point, vertex_face, vertex_perm, vertex_ksimplex,
                    edge_a, edge_b, edge_face, used_v, used_e):
    """Steps 1 and 2 of GCMH (paper 3.1.1) with the tables' Kuhn simplices, on the cubes start..hi-1 of
    a chunk (lo its first; arguments as `cubes_chunk`'s): each cube's vertices and edges into the
    chunk's arrays (`records.new_chunk`) after rows used_v, used_e, until a cube might not fit.
    Returns (the cube it stopped at, used_v, used_e, degenerate events)."""
    n = tables.n
    k = tables.k
    face_start = tables.face_start
    face_free = tables.face_free
    face_fixed = tables.face_fixed
    face_rank = tables.face_rank
    n_subsets = tables.n_subsets
    kfact = tables.simplices_per_kface
    ksimplex_corners = tables.ksimplex_corners
    ksimplex_face = tables.ksimplex_face
    ksimplex_perm = tables.ksimplex_perm
    walk_simplex_corners = tables.walk_simplex_corners
    walk_simplex_nodes = tables.walk_simplex_nodes
    walk_interior_corners = tables.walk_interior_corners
    n_boundary = tables.walk_boundary_nodes
    walk_corner_map = tables.walk_corner_map
    walk_boundary_simplex = tables.walk_boundary_simplex
    ksimplex_corner_mask = tables.ksimplex_corner_mask
    kface_corner_mask = tables.kface_corner_mask
    k1face_corner_mask = tables.k1face_corner_mask
    n_ksimplices = ksimplex_corners.shape[0]
    n_nodes = n_boundary + walk_interior_corners.shape[0]
    vertex_of_ksimplex = np.empty(n_ksimplices, np.int64)
    corner_signs = np.empty(1 << n, np.int64)
    masked = ksimplex_corner_mask.shape[0] > 0  # corner sets as bit masks (n <= 6)
    positive_corners = np.zeros(k, np.int64)  # bit c: F_j >= 0 at corner c
    mat = np.empty((k, k), np.float64)
    rhs = np.empty(k, np.float64)
    lam = np.empty(k + 1, np.float64)
    interior_simplex = np.empty((1, k + 1), np.int64)  # one interior node's corners, as a table
    walk_next0 = np.empty(n_nodes, np.int64)
    walk_next1 = np.empty(n_nodes, np.int64)
    interior_crossed = np.empty(max(walk_interior_corners.shape[0], 1), np.int8)
    boundary_found = np.empty(n_boundary, np.int64)
    walked = np.empty(n_boundary, np.int8)
    found_vertex = np.empty(n_boundary, np.int64)
    node_id = np.arange(n_boundary + walk_interior_corners.shape[0])  # (the walk's rows are its nodes here)
    max_edges = (face_start[k + 2] - face_start[k + 1]) * (n_boundary // 2)
    n_corners = 1 << n
    all_signs = (np.int64(1) << k) - 1
    degenerate = 0
    stop = hi
    for ci in range(start, hi):
        if used_v + n_ksimplices > vertex_key.shape[0] or used_e + max_edges > edge_a.shape[0]:
            stop = ci
            break  # the chunk's arrays might not hold this cube: `cubes_chunk` grows them
        cube_v0[ci - lo] = used_v
        cube_e0[ci - lo] = used_e
        o = cube_row[ci]
        g_vertex = cube_vertex[ci]
        for j in range(k):
            positive_corners[j] = 0
        for c in range(n_corners):
            p = np.int64(0)
            r0 = o + corner_row[c]
            for j in range(k):
                if values[r0, j] >= 0.0:
                    p |= np.int64(1) << j
                    positive_corners[j] |= np.int64(1) << c
            corner_signs[c] = p

        # 1. Vertices on the CFK k-simplices of the k-faces (paper 3.1.1)
        kface0 = face_start[k]
        nv = 0
        for s in range(n_ksimplices):
            vertex_of_ksimplex[s] = -1
        for kf in range(n_ksimplices // kfact):  # a k-face's k! simplices lie one after the other
            # the sign prune, written out: most faces and simplices stop here.  (Shared
            # with simplices_chunk as a helper it cost 1 us more per cube inlined, and
            # doubled the kernel time as a plain call: see _face_key.)  With bit masks
            # a whole face is tested at once, and a simplex in 2k operations.
            if masked:
                m = kface_corner_mask[kf]
                out = False
                for j in range(k):
                    on = positive_corners[j] & m
                    if on == 0 or on == m:  # F_j has one sign on every corner
                        out = True
                if out:
                    continue
            else:  # the same test over the face's 2^k corners: at k = 8 one test instead of 8! (n = 10: 2x faster)
                free = face_free[kface0 + kf]
                fixed = face_fixed[kface0 + kf]
                any_pos = 0
                all_pos = all_signs
                sub = free
                while True:  # every subset of the free axes
                    p = corner_signs[fixed | sub]
                    any_pos |= p
                    all_pos &= p
                    if sub == 0:
                        break
                    sub = (sub - 1) & free
                if any_pos != all_signs or all_pos != 0:
                    continue
            for s in range(kf * kfact, (kf + 1) * kfact):
                if masked:
                    m = ksimplex_corner_mask[s]
                    out = False
                    for j in range(k):
                        on = positive_corners[j] & m
                        if on == 0 or on == m:
                            out = True
                    if out:
                        continue
                else:
                    any_pos = 0
                    all_pos = all_signs
                    for i in range(k + 1):
                        p = corner_signs[ksimplex_corners[s, i]]
                        any_pos |= p
                        all_pos &= p
                    if any_pos != all_signs or all_pos != 0:
                        continue
                hit = simplex_crosses(
                    values, o, corner_row, ksimplex_corners, s, k, corner_signs, all_signs, mat, rhs, lam
                )
                if hit == 2:
                    hit = _zero_side(values, o, corner_row, ksimplex_corners, s, k, lam)
                if hit:
                    vertex_of_ksimplex[s] = nv
                    row = used_v + nv
                    vertex_ksimplex[row] = s
                    vertex_perm[row] = ksimplex_perm[s]
                    f = kface0 + ksimplex_face[s]
                    vertex_face[row] = f
                    vertex_key[row] = (
                        _face_key(g_vertex + corner_vertex[face_fixed[f]], n_subsets[k], face_rank[f]) * kfact
                        + ksimplex_perm[s]
                    )
                    for a in range(n):
                        x = 0.0
                        for i in range(k + 1):
                            x += lam[i] * grid_lines[a, cube_origin[ci, a] + ((ksimplex_corners[s, i] >> a) & 1)]
                        vertex_point[row, a] = x
                    nv += 1
        used_v += nv
        if nv == 0:
            continue

        # 2. Edges on the (k+1)-faces: two vertices are joined, more by the walk (paper 3.1.1)
        k1 = k + 1
        k1face0 = face_start[k1]
        n_k1faces = face_start[k1 + 1] - k1face0
        ne = used_e  # (an int64, passed to _walk_edges: see _config)
        n_interior = walk_interior_corners.shape[0]
        for kf1 in range(n_k1faces):
            if masked:  # no vertex on a face where some F_j has one sign
                m = k1face_corner_mask[kf1]
                out = False
                for j in range(k):
                    on = positive_corners[j] & m
                    if on == 0 or on == m:
                        out = True
                if out:
                    continue
            n_found = 0
            for b in range(n_boundary):
                if vertex_of_ksimplex[walk_boundary_simplex[kf1, b]] >= 0:
                    boundary_found[n_found] = b
                    n_found += 1
            if n_found == 0:
                continue
            if n_found == 2:
                edge_a[ne] = vertex_of_ksimplex[walk_boundary_simplex[kf1, boundary_found[0]]]
                edge_b[ne] = vertex_of_ksimplex[walk_boundary_simplex[kf1, boundary_found[1]]]
                edge_face[ne] = k1face0 + kf1
                ne += 1
                continue
            # The walk (Fig. 3): in each crossed (k+1)-simplex of the face, link its two crossed
            # k-facets (nodes); then follow the links from each boundary node to the next.
            for i in range(n_boundary + n_interior):
                walk_next0[i] = -1
                walk_next1[i] = -1
            for i in range(n_interior):
                interior_crossed[i] = -1
            for t in range(walk_simplex_corners.shape[0]):
                any_pos = 0
                all_pos = all_signs
                for j in range(k1 + 1):
                    p = corner_signs[walk_corner_map[kf1, walk_simplex_corners[t, j]]]
                    any_pos |= p
                    all_pos &= p
                if any_pos != all_signs or all_pos != 0:
                    continue
                n_crossed = 0
                node_a = -1
                node_b = -1
                for j in range(k1 + 1):
                    node = walk_simplex_nodes[t, j]
                    if node < n_boundary:
                        crossed = vertex_of_ksimplex[walk_boundary_simplex[kf1, node]] >= 0
                    else:
                        ii = node - n_boundary
                        if interior_crossed[ii] < 0:
                            for q in range(k + 1):
                                interior_simplex[0, q] = walk_corner_map[kf1, walk_interior_corners[ii, q]]
                            hit = _simplex_crosses_call(
                                values, o, corner_row, interior_simplex, np.int64(0), k, corner_signs, all_signs, mat,
                                rhs, lam,
                            )
                            if hit == 2:
                                hit = _zero_side(values, o, corner_row, interior_simplex, np.int64(0), k, lam)
                            interior_crossed[ii] = hit
                        crossed = interior_crossed[ii] == 1
                    if crossed:
                        if n_crossed == 0:
                            node_a = node
                        elif n_crossed == 1:
                            node_b = node
                        n_crossed += 1
                degenerate += _link(walk_next0, walk_next1, n_crossed, node_a, node_b)
            for q in range(n_found):
                found_vertex[q] = vertex_of_ksimplex[walk_boundary_simplex[kf1, boundary_found[q]]]
            # np.int64: numba typed n_found here as Literal[int](0) and compiled the walk a second time
            ne, events = _walk_edges(walk_next0, walk_next1, node_id, n_boundary, n_boundary + n_interior + 1,
                                     boundary_found, found_vertex, np.int64(n_found), walked, edge_a, edge_b,
                                     edge_face, ne, k1face0 + kf1)
            degenerate += events
        used_e = ne
    cube_v0[stop - lo] = used_v
    cube_e0[stop - lo] = used_e
    return stop, used_v, used_e, degenerate


@nb.njit(**JIT)
def cubes_chunk(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex, tables):
    """GCMH on the candidate cubes lo..hi-1, in the calling thread, in phases over the chunk:
    vertices and edges (`_vertices_edges`, again from the first cube that did not fit once the
    chunk's arrays have grown), then cells (`cells.cells_of_chunk`).

    values (NV, k) float64: F at grid vertices; corner c of cube i is row cube_row[i] + corner_row[c].
    cube_origin (m, n): the global multi-index of each cube's origin; cube_vertex (m,): its global
    linear vertex index (corner c adds corner_vertex[c]; keys come from these, never from rows).
    grid_lines (n, max vertices per axis): the (perturbed) grid lines.  tables: `tables.CubeTables`.
    Returns (vertex keys, vertex points, edges, cells, incidences) records in cube order,
    each cube's crossed-facet mask, the number of degenerate events, and where M_A joins
    pieces of G_H through a face of the cube (`_joined_pieces`: cells that are not balls;
    n <= 7): rows (cube - lo, face, pieces joined).
    """
    # a cube has at most one vertex per k-simplex and one edge per two boundary nodes of a (k+1)-face's walk
    per_cube_v = tables.ksimplex_corners.shape[0]
    per_cube_e = (tables.face_start[tables.k + 2] - tables.face_start[tables.k + 1]) * (tables.walk_boundary_nodes // 2)
    rows = 8 * (hi - lo) + 16
    # rows for 8 a cube on average, and one cube's worst case beyond: the phase stops where the next
    # cube's worst case might not fit (with max(rows, worst case), every second cube of a
    # continuation's small wave in R^5 did: 650 restarts in 1,820 waves of the Klein bottle)
    (cube_v0, cube_e0, crossed_facets, vertex_key, vertex_point, vertex_face, vertex_perm, vertex_ksimplex, edge_a,
     edge_b, edge_face, edge_out) = new_chunk(hi - lo, rows + per_cube_v, rows + per_cube_e, tables.n)
    used_v = used_e = np.int64(0)
    degenerate = 0
    start = lo
    while True:
        start, used_v, used_e, events = _vertices_edges(
            start, hi, lo, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex, tables,
            cube_v0, cube_e0, vertex_key, vertex_point, vertex_face, vertex_perm, vertex_ksimplex, edge_a, edge_b,
            edge_face, used_v, used_e,
        )
        degenerate += events
        if start == hi:
            break
        (vertex_key, vertex_point, vertex_face, vertex_perm, vertex_ksimplex, edge_a, edge_b, edge_face,
         edge_out) = grown_chunk(vertex_key, vertex_point, vertex_face, vertex_perm, vertex_ksimplex, edge_a, edge_b,
                                 edge_face, edge_out, used_v, used_e)
    c_out, i_out, used_c, used_i, non_ball, events = cells_of_chunk(
        lo, hi, values, cube_row, corner_row, cube_vertex, corner_vertex, tables_faces(tables), tables.binom,
        tables.kuhn, tables.ksimplex_kuhn, cube_v0, cube_e0, crossed_facets,
        vertex_key, vertex_face, vertex_perm, vertex_ksimplex, edge_a, edge_b, edge_face, edge_out, rows,
        max(4 * per_cube_v, per_cube_e), per_cube_v,
    )
    records = _records_upto(vertex_key, vertex_point, edge_out, c_out, i_out, used_v, used_e, used_c, used_i)
    return records, crossed_facets, degenerate + events, non_ball


_cubes_chunk_tables = cubes_chunk


# The runner calls `cubes_chunk`; the numba kernel above keeps that name (compile notices and
# tests/core/test_first_run.py know it by it), and this picks the kernel by the tables it gets.
def cubes_chunk(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex,  # type: ignore[no-redef]
                tables):
    """GCMH on candidate cubes lo..hi-1: the tables' kernel (`_cubes_chunk_tables`), or
    `cubes_chunk_lazy` where the tables hold no Kuhn simplices (`_tables.lazy_tables`)."""
    kernel = cubes_chunk_lazy if tables.ksimplex_corners.shape[0] == 0 else _cubes_chunk_tables
    return kernel(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex, tables)
