"""The simplicial baselines CMS and CCS (paper Section 4): marching the Kuhn simplices of a cube."""

import numba as nb
import numpy as np

from .._config import INLINE_JIT, JIT
from .records import _grown_keys, _grown_rows, _new_records, _records_upto
from .solve import _zero_side, crossable_chain, crossable_mask, simplex_crosses

# ----------------------------------------------------------------------------- simplicial baselines (CMS, CCS)
# Marching simplices over the CFK triangulation (paper Section 4): every simplex of
# dimension d = r + k of the cube's triangulation that M_A crosses is one r-cell (the
# zero set of a linear map on a simplex is one convex polytope).  A vertex is a
# crossed k-simplex; an edge joins the two crossed k-facets of a (k+1)-simplex; an
# r-cell's faces are its crossed facets.  Keys are the simplices' own keys (see
# `tables.SimplexTables`), so records merge with the same assembly as GCMH's.


@nb.njit(**INLINE_JIT)
def _simplex_key(g_vertex, corner_vertex, simplex_c0, simplex_code, key_base, s):
    return (g_vertex + corner_vertex[simplex_c0[s]]) * key_base + simplex_code[s]


@nb.njit(**JIT)
def simplices_chunk(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex, tables):
    """`cubes_chunk`'s twin for the simplicial baselines: same inputs (but tables is a
    `tables.SimplexTables`), same records.

    Every simplex of the cube's triangulation that M_A crosses is written; the
    degenerate events are crossed facets that can't bound a convex polytope.
    """
    n = tables.n
    k = tables.k
    dim_start = tables.start
    simplex_corners = tables.corners
    simplex_c0 = tables.c0
    simplex_code = tables.code
    simplex_facets = tables.facets
    simplex_cube_facets = tables.cube_facets
    key_base = tables.key_base
    simplex_corner_mask = tables.corner_mask

    crossed = np.empty(dim_start[n + 1], np.int64)  # 1 where the simplex holds a cell of M_A
    corner_signs = np.empty(1 << n, np.int64)
    mat = np.empty((k, k), np.float64)
    rhs = np.empty(k, np.float64)
    lam = np.empty(k + 1, np.float64)
    vk_out, vp_out, e_out, c_out, i_out = _new_records(16 * (hi - lo) + 16, n)
    used_v = used_e = used_c = used_i = np.int64(0)  # rows written (int64 from the start: see _config)
    crossed_facets = np.zeros(hi - lo, np.int64)
    all_signs = (np.int64(1) << k) - 1
    masked = simplex_corner_mask.shape[0] > 0  # corner sets as bit masks (n <= 6)
    positive_corners = np.zeros(k, np.int64)
    degenerate = 0
    for ci in range(lo, hi):
        o = cube_row[ci]
        g_vertex = cube_vertex[ci]
        for j in range(k):
            positive_corners[j] = 0
        for c in range(1 << n):
            p = np.int64(0)
            r0 = o + corner_row[c]
            for j in range(k):
                if values[r0, j] >= 0.0:
                    p |= np.int64(1) << j
                    positive_corners[j] |= np.int64(1) << c
            corner_signs[c] = p
        # vertices: the crossed k-simplices
        nv = 0
        facets = np.int64(0)
        for s in range(dim_start[k], dim_start[k + 1]):
            crossed[s] = 0
            if masked:  # the sign prune first (`solve`)
                if not crossable_mask(positive_corners, simplex_corner_mask[s], k):
                    continue
            elif not crossable_chain(corner_signs, simplex_corners, s, k + 1, all_signs):
                continue
            hit = simplex_crosses(values, o, corner_row, simplex_corners, s, k, corner_signs, all_signs, mat, rhs, lam)
            if hit == 2:
                hit = _zero_side(values, o, corner_row, simplex_corners, s, k, lam)
            if hit:
                crossed[s] = 1
                facets |= simplex_cube_facets[s]
                if used_v >= vk_out.shape[0]:
                    vk_out = _grown_keys(vk_out, used_v)
                    vp_out = _grown_rows(vp_out, used_v)
                vk_out[used_v] = _simplex_key(g_vertex, corner_vertex, simplex_c0, simplex_code, key_base, s)
                for a in range(n):
                    x = 0.0
                    for i in range(k + 1):
                        x += lam[i] * grid_lines[a, cube_origin[ci, a] + ((simplex_corners[s, i] >> a) & 1)]
                    vp_out[used_v, a] = x
                used_v += 1
                nv += 1
        crossed_facets[ci - lo] = facets
        if nv == 0:
            continue
        # r-cells, r = d - k >= 1: the crossed d-simplices, with their crossed facets
        for d in range(k + 1, n + 1):
            r = d - k
            for s in range(dim_start[d], dim_start[d + 1]):
                crossed[s] = 0
                nf = 0
                for j in range(d + 1):
                    f = simplex_facets[s, j]
                    if f >= 0:  # (-1: a facet a cube's own table leaves out, `kuhn_cube`: not crossed)
                        nf += crossed[f]
                if nf == 0:
                    continue
                # a segment has 2 ends; an r-polytope (r >= 2) at least r + 1 facets
                if (r == 1 and nf != 2) or nf < r + 1:
                    degenerate += 1
                    continue
                crossed[s] = 1
                key = _simplex_key(g_vertex, corner_vertex, simplex_c0, simplex_code, key_base, s)
                if r == 1:
                    if used_e >= e_out.shape[0]:
                        e_out = _grown_rows(e_out, used_e)
                    e_out[used_e, 0] = key
                    q = 1
                    for j in range(d + 1):
                        f = simplex_facets[s, j]
                        if f >= 0 and crossed[f]:
                            e_out[used_e, q] = _simplex_key(
                                g_vertex, corner_vertex, simplex_c0, simplex_code, key_base, f
                            )
                            q += 1
                    used_e += 1
                    continue
                if used_c >= c_out.shape[0]:
                    c_out = _grown_rows(c_out, used_c)
                c_out[used_c, 0] = r
                c_out[used_c, 1] = key
                used_c += 1
                for j in range(d + 1):
                    f = simplex_facets[s, j]
                    if f >= 0 and crossed[f]:
                        if used_i >= i_out.shape[0]:
                            i_out = _grown_rows(i_out, used_i)
                        i_out[used_i, 0] = r
                        i_out[used_i, 1] = key
                        i_out[used_i, 2] = _simplex_key(g_vertex, corner_vertex, simplex_c0, simplex_code, key_base, f)
                        used_i += 1
    return (
        _records_upto(vk_out, vp_out, e_out, c_out, i_out, used_v, used_e, used_c, used_i), crossed_facets, degenerate,
        np.zeros((0, 3), np.int64),  # (no pieces of G_H here: every cell is a convex polytope)
    )
