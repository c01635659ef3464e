"""The numba kernels of GCMH.  They see only arrays: F's values at grid vertices,
the grid lines, and the cube tables of `_tables`.  Nothing here depends on F.

Per candidate cube the kernel computes, in the cube's own frame:
  1. vertices of M_A on the Kuhn k-simplices of its k-faces (barycentric solve);
  2. edges on its (k+1)-faces (two vertices: join them; more: the paper's walk
     through the face's Kuhn (k+1)-simplices);
  3. for r = 2..n-k, the r-cells: connected components of the vertex-edge graph
     restricted to each (r+k)-face, with their (r-1)-faces.
Everything is emitted with global keys computed from grid indices alone, so
the same vertex, edge or cell produced by two neighbouring cubes is recognised
in the global assembly (`extract._assemble`).

A chunk of cubes returns its records in cube order, and chunks are joined in
order: the output does not depend on the number of threads.
"""

import numba as nb
import numpy as np
from numba import prange

from ._config import INLINE_JIT, JIT, PARALLEL_JIT

# Columns of the emitted records.
# An r-cell (r >= 1) is one connected piece of M_A in a grid face f of dimension
# r + k; its key is face_key(f) * n_codes(r + k) + the smallest local code, within
# f, of its vertices.  A vertex's local code in f depends only on where its k-face
# and Kuhn simplex sit inside f, so both cubes sharing f compute the same key.
EDGE_COLS = 3  # edge key, vertex key a, vertex key b
CELL_COLS = 2  # r, cell key
INC_COLS = 3  # r, key of the r-cell X, key of its (r-1)-face Y


@nb.njit(**INLINE_JIT)
def simplex_crosses(vals, o, value_off, table, s, k, pos_mask, full, mat, rhs, lam):
    """Does the Kuhn simplex with cube corners table[s, 0..k] (chain order) hold a zero?

    vals (NV, k) values; corner c of the cube is row o + value_off[c]; lam (k+1,) receives the
    barycentric coordinates.  Sign prune first: every component needs a value >= 0
    and one < 0 among the simplex's corners, else there is no solve at all.
    The simplex comes as a table and a row, not as the row itself: a slice made per
    simplex costs reference counting that was once most of a cube's work.  Kernels
    prune in their own loops first and call this for the few simplices that pass.
    """
    m = k + 1
    any_pos = 0
    all_pos = full
    for i in range(m):
        p = pos_mask[table[s, i]]
        any_pos |= p
        all_pos &= p
    if any_pos != full or all_pos != 0:
        return False
    # Solve sum_{i>=1} lam_i (F(v_i) - F(v_0)) = -F(v_0), a k x k system.
    r0 = o + value_off[table[s, 0]]
    for j in range(k):
        f0 = vals[r0, j]
        rhs[j] = -f0
        for i in range(1, m):
            mat[j, i - 1] = vals[o + value_off[table[s, i]], j] - f0
    scale = 0.0
    for j in range(k):
        for i in range(k):
            a = abs(mat[j, i])
            if a > scale:
                scale = a
    if scale == 0.0:
        return False
    tiny = scale * 1e-14
    for c in range(k):  # Gaussian elimination with partial pivoting
        piv = c
        best = abs(mat[c, c])
        for rr in range(c + 1, k):
            a = abs(mat[rr, c])
            if a > best:
                best = a
                piv = rr
        if best <= tiny:
            return False
        if piv != c:
            for i in range(k):
                t = mat[c, i]
                mat[c, i] = mat[piv, i]
                mat[piv, i] = t
            t = rhs[c]
            rhs[c] = rhs[piv]
            rhs[piv] = t
        for rr in range(c + 1, k):
            fac = mat[rr, c] / mat[c, c]
            if fac != 0.0:
                for i in range(c, k):
                    mat[rr, i] -= fac * mat[c, i]
                rhs[rr] -= fac * rhs[c]
    total = 0.0
    for c in range(k - 1, -1, -1):
        s = rhs[c]
        for i in range(c + 1, k):
            s -= mat[c, i] * lam[i + 1]
        lam[c + 1] = s / mat[c, c]
        total += lam[c + 1]
    lam[0] = 1.0 - total
    for i in range(m):
        if not (lam[i] >= 0.0):
            return False
    return True


@nb.njit(**INLINE_JIT)
def _find(parent, v):
    while parent[v] != v:
        parent[v] = parent[parent[v]]
        v = parent[v]
    return v


@nb.njit(**INLINE_JIT)
def _face_in_face(g_free, g_fixed, f_free, f_fixed):
    """Is the cube face (g_free, g_fixed) contained in the face (f_free, f_fixed)?"""
    return (g_free & ~f_free) == 0 and (g_fixed & ~f_free) == f_fixed


@nb.njit(**INLINE_JIT)
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


@nb.njit(**INLINE_JIT)
def _face_key(face_corner, n_subsets_dim, rank):
    """Global key of a cube face: its first corner's grid vertex, then its axes' rank."""
    return face_corner * n_subsets_dim + rank


# A helper inlined into a kernel loop takes scalars, not arrays: in functions as large
# as the chunk kernels numba leaves the reference counts of array arguments of an
# inlined call unpruned, and those atomic updates cost more than the work.


@nb.njit(**JIT)
def _new_records(rows, n):
    return (
        np.empty(rows, np.int64),
        np.empty((rows, n), np.float64),
        np.empty((rows, EDGE_COLS), np.int64),
        np.empty((rows, CELL_COLS), np.int64),
        np.empty((rows, INC_COLS), np.int64),
    )


@nb.njit(**JIT)
def _grown_keys(a, used):
    """a's first `used` entries in an array twice as long."""
    b = np.empty(2 * a.shape[0] + 1, a.dtype)
    b[:used] = a[:used]
    return b


@nb.njit(**JIT)
def _grown_rows(a, used):
    """a's first `used` rows in an array with twice the rows."""
    b = np.empty((2 * a.shape[0] + 1, a.shape[1]), a.dtype)
    b[:used] = a[:used]
    return b


@nb.njit(**JIT)
def _records_upto(vk, vp, e, c, i, used_v, used_e, used_c, used_i):
    """The written rows, copied out of the (up to twice too long) growing arrays."""
    return vk[:used_v].copy(), vp[:used_v].copy(), e[:used_e].copy(), c[:used_c].copy(), i[:used_i].copy()


@nb.njit(**JIT)
def cubes_chunk(
    lo, hi, vals, cube_lin, cube_origin, cube_key, axes, value_off, corner_off, n, k,
    face_start, face_free, face_fixed, face_rank, n_subsets,
    ks_corners, ks_face, ks_perm, kfact, binom, n_codes,
    t_corners, t_facets, t_interior, nb_nodes, w_cmap, w_bsimp, ks_cmask, kf_cmask, k1f_cmask,
):
    """GCMH on cubes lo..hi-1, in the calling thread, with one set of scratch buffers.

    vals (NV, k) float64: F at grid vertices; corner c of cube i is row cube_lin[i] + value_off[c];
    cube_origin (m, n) global multi-index of each cube's origin; cube_key (m,) its global
    linear vertex index (corner c adds corner_off[c]; keys come from these, never from rows).
    Returns (vertex keys, vertex points, edges, cells, incidences) records in cube order,
    each cube's crossed-facet mask, and the number of degenerate events.
    """
    ns = ks_corners.shape[0]
    n_nodes = nb_nodes + t_interior.shape[0]
    simp_vertex = np.empty(ns, np.int64)
    pos_mask = np.empty(1 << n, np.int64)
    masked = ks_cmask.shape[0] > 0  # corner sets as bit masks (n <= 6)
    pos_bits = np.zeros(k, np.int64)  # bit c: F_j >= 0 at corner c
    mat = np.empty((k, k), np.float64)
    rhs = np.empty(k, np.float64)
    lam = np.empty(k + 1, np.float64)
    corners_buf = np.empty((1, k + 1), np.int64)  # one simplex, as a table
    link0 = np.empty(n_nodes, np.int64)
    link1 = np.empty(n_nodes, np.int64)
    memo = np.empty(max(t_interior.shape[0], 1), np.int8)
    found = np.empty(nb_nodes, np.int64)
    paired = np.empty(nb_nodes, np.int8)
    vsimp = np.empty(ns, np.int64)
    vface = np.empty(ns, np.int64)
    vkey = np.empty(ns, np.int64)
    max_edges = (face_start[k + 2] - face_start[k + 1]) * (nb_nodes // 2)
    ea = np.empty(max_edges, np.int64)
    eb = np.empty(max_edges, np.int64)
    ef = np.empty(max_edges, np.int64)
    parent = np.empty(ns, np.int64)
    comp_of_root = np.empty(ns, np.int64)
    comps_a = np.empty((4 * ns, 3), np.int64)
    comps_b = np.empty((4 * ns, 3), np.int64)
    vk_out, vp_out, e_out, c_out, i_out = _new_records(8 * (hi - lo) + 16, n)
    used_v = used_e = used_c = used_i = 0  # rows written
    masks = np.zeros(hi - lo, np.int64)
    ncorner = 1 << n
    full = (np.int64(1) << k) - 1
    degenerate = 0
    for ci in range(lo, hi):
        o = cube_lin[ci]
        g_lin = cube_key[ci]
        for j in range(k):
            pos_bits[j] = 0
        for c in range(ncorner):
            p = np.int64(0)
            r0 = o + value_off[c]
            for j in range(k):
                if vals[r0, j] >= 0.0:
                    p |= np.int64(1) << j
                    pos_bits[j] |= np.int64(1) << c
            pos_mask[c] = p

        # 1. vertices on k-simplices of k-faces
        kf0 = face_start[k]
        nv = 0
        for s in range(ns):
            simp_vertex[s] = -1
        for fi in range(ns // kfact):  # a k-face's k! simplices lie one after the other
            # the sign prune, written out: most faces and simplices stop here.  (Shared
            # with simplices_chunk as a helper it cost 1 us more per cube inlined, and
            # doubled the kernel time as a plain call: see _face_key.)  With bit masks
            # a whole face is tested at once, and a simplex in 2k operations.
            if masked:
                m = kf_cmask[fi]
                out = False
                for j in range(k):
                    on = pos_bits[j] & m
                    if on == 0 or on == m:  # F_j has one sign on every corner
                        out = True
                if out:
                    continue
            for s in range(fi * kfact, (fi + 1) * kfact):
                if masked:
                    m = ks_cmask[s]
                    out = False
                    for j in range(k):
                        on = pos_bits[j] & m
                        if on == 0 or on == m:
                            out = True
                    if out:
                        continue
                else:
                    any_pos = 0
                    all_pos = full
                    for i in range(k + 1):
                        p = pos_mask[ks_corners[s, i]]
                        any_pos |= p
                        all_pos &= p
                    if any_pos != full or all_pos != 0:
                        continue
                if simplex_crosses(vals, o, value_off, ks_corners, s, k, pos_mask, full, mat, rhs, lam):
                    simp_vertex[s] = nv
                    vsimp[nv] = s
                    row = used_v + nv
                    if row >= vk_out.shape[0]:
                        vk_out = _grown_keys(vk_out, row)
                        vp_out = _grown_rows(vp_out, row)
                    f = kf0 + ks_face[s]
                    vface[nv] = f
                    vkey[nv] = _face_key(g_lin + corner_off[face_fixed[f]], n_subsets[k], face_rank[f]) * kfact + ks_perm[s]
                    vk_out[row] = vkey[nv]
                    for a in range(n):
                        x = 0.0
                        for i in range(k + 1):
                            x += lam[i] * axes[a, cube_origin[ci, a] + ((ks_corners[s, i] >> a) & 1)]
                        vp_out[row, a] = x
                    nv += 1
        # facets of the cube that M_A crosses (bit 2a + side): where continuation goes next
        facets = np.int64(0)
        for v in range(nv):
            f = vface[v]
            for a in range(n):
                if not (face_free[f] >> a) & 1:
                    facets |= np.int64(1) << (2 * a + ((face_fixed[f] >> a) & 1))
        masks[ci - lo] = facets
        if nv == 0:
            continue

        # 2. edges on (k+1)-faces
        k1 = k + 1
        f10 = face_start[k1]
        nk1 = face_start[k1 + 1] - f10
        ne = 0
        n_int = t_interior.shape[0]
        for fi in range(nk1):
            if masked:  # no vertex on a face where some F_j has one sign
                m = k1f_cmask[fi]
                out = False
                for j in range(k):
                    on = pos_bits[j] & m
                    if on == 0 or on == m:
                        out = True
                if out:
                    continue
            cnt = 0
            for b in range(nb_nodes):
                if simp_vertex[w_bsimp[fi, b]] >= 0:
                    found[cnt] = b
                    cnt += 1
            if cnt == 0:
                continue
            if cnt == 2:
                ea[ne] = simp_vertex[w_bsimp[fi, found[0]]]
                eb[ne] = simp_vertex[w_bsimp[fi, found[1]]]
                ef[ne] = f10 + fi
                ne += 1
                continue
            # The walk (paper 3.1.1): link crossing facets of the face's Kuhn (k+1)-simplices.
            for i in range(nb_nodes + n_int):
                link0[i] = -1
                link1[i] = -1
            for i in range(n_int):
                memo[i] = -1
            for t in range(t_corners.shape[0]):
                any_pos = 0
                all_pos = full
                for j in range(k1 + 1):
                    p = pos_mask[w_cmap[fi, t_corners[t, j]]]
                    any_pos |= p
                    all_pos &= p
                if any_pos != full or all_pos != 0:
                    continue
                nc = 0
                n_a = -1
                n_b = -1
                for j in range(k1 + 1):
                    node = t_facets[t, j]
                    if node < nb_nodes:
                        cr = simp_vertex[w_bsimp[fi, node]] >= 0
                    else:
                        ii = node - nb_nodes
                        if memo[ii] < 0:
                            for q in range(k + 1):
                                corners_buf[0, q] = w_cmap[fi, t_interior[ii, q]]
                            memo[ii] = 1 if simplex_crosses(vals, o, value_off, corners_buf, 0, k, pos_mask, full, mat, rhs, lam) else 0
                        cr = memo[ii] == 1
                    if cr:
                        if nc == 0:
                            n_a = node
                        elif nc == 1:
                            n_b = node
                        nc += 1
                if nc == 2:
                    for pair in range(2):
                        u = n_a if pair == 0 else n_b
                        w = n_b if pair == 0 else n_a
                        if link0[u] < 0:
                            link0[u] = w
                        elif link1[u] < 0:
                            link1[u] = w
                        else:
                            degenerate += 1
                elif nc != 0:
                    degenerate += 1
            for q in range(cnt):
                paired[q] = 0
            for q in range(cnt):
                if paired[q]:
                    continue
                start = found[q]
                prev = -1
                cur = start
                end = -1
                for _step in range(nb_nodes + n_int + 1):
                    nxt = link0[cur] if link0[cur] != prev else link1[cur]
                    if nxt < 0:
                        break
                    prev = cur
                    cur = nxt
                    if cur < nb_nodes:
                        end = cur
                        break
                if end < 0 or end == start:
                    degenerate += 1
                    paired[q] = 1
                    continue
                for q2 in range(cnt):
                    if found[q2] == end:
                        paired[q2] = 1
                paired[q] = 1
                ea[ne] = simp_vertex[w_bsimp[fi, start]]
                eb[ne] = simp_vertex[w_bsimp[fi, end]]
                ef[ne] = f10 + fi
                ne += 1

        # 3. r-cells, r = 1..n-k: connected pieces of the vertex-edge graph inside each
        # (r+k)-face; for r = 1 they are the edges themselves.  Rows of prev/cur:
        # (face, a vertex of the piece, key); the two buffers swap roles per level.
        prev = comps_a
        cur = comps_b
        if prev.shape[0] < ne:
            prev = np.empty((ne, 3), np.int64)
        for e in range(ne):
            f = ef[e]
            ca = _local_code(face_free[f], face_free[vface[ea[e]]], face_fixed[vface[ea[e]]], ks_perm[vsimp[ea[e]]], k, kfact, binom)
            cb = _local_code(face_free[f], face_free[vface[eb[e]]], face_fixed[vface[eb[e]]], ks_perm[vsimp[eb[e]]], k, kfact, binom)
            prev[e, 0] = f
            prev[e, 1] = ea[e]
            prev[e, 2] = _face_key(g_lin + corner_off[face_fixed[f]], n_subsets[k1], face_rank[f]) * n_codes[k1] + min(ca, cb)
            row = used_e + e
            if row >= e_out.shape[0]:
                e_out = _grown_rows(e_out, row)
            e_out[row, 0] = prev[e, 2]
            e_out[row, 1] = vkey[ea[e]]
            e_out[row, 2] = vkey[eb[e]]
        nprev = ne
        ncell = 0
        ninc = 0
        for r in range(2, n - k + 1):
            dim = r + k
            fs = face_start[dim]
            nf = face_start[dim + 1] - fs
            ncur = 0
            for fl in range(nf):
                f = fs + fl
                nin = 0
                for v in range(nv):
                    if _face_in_face(face_free[vface[v]], face_fixed[vface[v]], face_free[f], face_fixed[f]):
                        parent[v] = v
                        nin += 1
                    else:
                        parent[v] = -1
                if nin == 0:
                    continue
                has_edge = False
                for e in range(ne):
                    if _face_in_face(face_free[ef[e]], face_fixed[ef[e]], face_free[f], face_fixed[f]):
                        has_edge = True
                        ra = _find(parent, ea[e])
                        rb = _find(parent, eb[e])
                        if ra != rb:
                            parent[max(ra, rb)] = min(ra, rb)
                if not has_edge:
                    continue
                # a piece needs an edge: a vertex left alone in f (degenerate data) is no r-cell
                for v in range(nv):
                    comp_of_root[v] = -1
                for e in range(ne):
                    if _face_in_face(face_free[ef[e]], face_fixed[ef[e]], face_free[f], face_fixed[f]):
                        comp_of_root[_find(parent, ea[e])] = -2
                if cur.shape[0] < ncur + nin:  # rare: grow the buffer
                    grown = np.empty((2 * (ncur + nin), 3), np.int64)
                    grown[:ncur] = cur[:ncur]
                    cur = grown
                first = ncur
                ff = face_free[f]
                for v in range(nv):  # a root is its piece's smallest vertex index: it comes first
                    if parent[v] >= 0:
                        root = _find(parent, v)
                        code = _local_code(ff, face_free[vface[v]], face_fixed[vface[v]], ks_perm[vsimp[v]], k, kfact, binom)
                        if root == v:
                            if comp_of_root[v] != -2:
                                continue
                            comp_of_root[v] = ncur
                            cur[ncur, 0] = f
                            cur[ncur, 1] = v
                            cur[ncur, 2] = code
                            ncur += 1
                        else:
                            c = comp_of_root[root]
                            if c >= 0 and code < cur[c, 2]:
                                cur[c, 2] = code
                fkey = _face_key(g_lin + corner_off[face_fixed[f]], n_subsets[dim], face_rank[f]) * n_codes[dim]
                for c in range(first, ncur):
                    cur[c, 2] += fkey
                    row = used_c + ncell + c
                    if row >= c_out.shape[0]:
                        c_out = _grown_rows(c_out, row)
                    c_out[row, 0] = r
                    c_out[row, 1] = cur[c, 2]
                # incidences: each previous-level piece in a face g of f lies in one piece of f
                for y in range(nprev):
                    if not _face_in_face(face_free[prev[y, 0]], face_fixed[prev[y, 0]], face_free[f], face_fixed[f]):
                        continue
                    rep = prev[y, 1]
                    if parent[rep] < 0:
                        degenerate += 1
                        continue
                    row = used_i + ninc
                    if row >= i_out.shape[0]:
                        i_out = _grown_rows(i_out, row)
                    i_out[row, 0] = r
                    i_out[row, 1] = cur[comp_of_root[_find(parent, rep)], 2]
                    i_out[row, 2] = prev[y, 2]
                    ninc += 1
            ncell += ncur
            swap = prev
            prev = cur
            cur = swap
            nprev = ncur
        used_v += nv
        used_e += ne
        used_c += ncell
        used_i += ninc
    return _records_upto(vk_out, vp_out, e_out, c_out, i_out, used_v, used_e, used_c, used_i), masks, degenerate


# ----------------------------------------------------------------------------- simplicial baselines (CMS, CCS)
# Marching simplices over the CFK triangulation (paper Section 4): every simplex of
# dimension d = r + k of the cube's triangulation that M_A crosses is one r-cell (the
# zero set of a linear map on a simplex is one convex polytope).  A vertex is a
# crossed k-simplex; an edge joins the two crossed k-facets of a (k+1)-simplex; an
# r-cell's faces are its crossed facets.  Keys are the simplices' own keys (see
# `_tables.SimplexTables`), so records merge with the same `_assemble` as GCMH's.


@nb.njit(**INLINE_JIT)
def _simplex_key(g_lin, corner_off, s_c0, s_code, key_base, s):
    return (g_lin + corner_off[s_c0[s]]) * key_base + s_code[s]


@nb.njit(**JIT)
def simplices_chunk(
    lo, hi, vals, cube_lin, cube_origin, cube_key, axes, value_off, corner_off, n, k,
    s_start, s_corners, s_c0, s_code, s_facets, s_cube_facets, key_base, s_cmask,
):
    """`cubes_chunk`'s twin for the simplicial baselines: same inputs, same records.

    Every simplex of the cube's triangulation that M_A crosses is written; the
    degenerate events are crossed facets that can't bound a convex polytope.
    """
    alive = np.empty(s_start[n + 1], np.int64)  # 1 where the simplex holds a cell of M_A
    pos_mask = np.empty(1 << n, np.int64)
    mat = np.empty((k, k), np.float64)
    rhs = np.empty(k, np.float64)
    lam = np.empty(k + 1, np.float64)
    vk_out, vp_out, e_out, c_out, i_out = _new_records(16 * (hi - lo) + 16, n)
    used_v = used_e = used_c = used_i = 0  # rows written
    masks = np.zeros(hi - lo, np.int64)
    full = (np.int64(1) << k) - 1
    masked = s_cmask.shape[0] > 0  # corner sets as bit masks (n <= 6)
    pos_bits = np.zeros(k, np.int64)
    degenerate = 0
    for ci in range(lo, hi):
        o = cube_lin[ci]
        g_lin = cube_key[ci]
        for j in range(k):
            pos_bits[j] = 0
        for c in range(1 << n):
            p = np.int64(0)
            r0 = o + value_off[c]
            for j in range(k):
                if vals[r0, j] >= 0.0:
                    p |= np.int64(1) << j
                    pos_bits[j] |= np.int64(1) << c
            pos_mask[c] = p
        nv = 0
        facets = np.int64(0)
        for s in range(s_start[k], s_start[k + 1]):
            alive[s] = 0
            # the sign prune, written out as in cubes_chunk
            if masked:
                m = s_cmask[s]
                out = False
                for j in range(k):
                    on = pos_bits[j] & m
                    if on == 0 or on == m:
                        out = True
                if out:
                    continue
            else:
                any_pos = 0
                all_pos = full
                for i in range(k + 1):
                    p = pos_mask[s_corners[s, i]]
                    any_pos |= p
                    all_pos &= p
                if any_pos != full or all_pos != 0:
                    continue
            if simplex_crosses(vals, o, value_off, s_corners, s, k, pos_mask, full, mat, rhs, lam):
                alive[s] = 1
                facets |= s_cube_facets[s]
                if used_v >= vk_out.shape[0]:
                    vk_out = _grown_keys(vk_out, used_v)
                    vp_out = _grown_rows(vp_out, used_v)
                vk_out[used_v] = _simplex_key(g_lin, corner_off, s_c0, s_code, key_base, s)
                for a in range(n):
                    x = 0.0
                    for i in range(k + 1):
                        x += lam[i] * axes[a, cube_origin[ci, a] + ((s_corners[s, i] >> a) & 1)]
                    vp_out[used_v, a] = x
                used_v += 1
                nv += 1
        masks[ci - lo] = facets
        if nv == 0:
            continue
        for d in range(k + 1, n + 1):
            r = d - k
            for s in range(s_start[d], s_start[d + 1]):
                alive[s] = 0
                nf = 0
                for j in range(d + 1):
                    nf += alive[s_facets[s, j]]
                if nf == 0:
                    continue
                # a segment has 2 ends; an r-polytope (r >= 2) at least r + 1 facets
                if (r == 1 and nf != 2) or nf < r + 1:
                    degenerate += 1
                    continue
                alive[s] = 1
                key = _simplex_key(g_lin, corner_off, s_c0, s_code, key_base, s)
                if r == 1:
                    if used_e >= e_out.shape[0]:
                        e_out = _grown_rows(e_out, used_e)
                    e_out[used_e, 0] = key
                    q = 1
                    for j in range(d + 1):
                        f = s_facets[s, j]
                        if alive[f]:
                            e_out[used_e, q] = _simplex_key(g_lin, corner_off, s_c0, s_code, key_base, f)
                            q += 1
                    used_e += 1
                    continue
                if used_c >= c_out.shape[0]:
                    c_out = _grown_rows(c_out, used_c)
                c_out[used_c, 0] = r
                c_out[used_c, 1] = key
                used_c += 1
                for j in range(d + 1):
                    f = s_facets[s, j]
                    if alive[f]:
                        if used_i >= i_out.shape[0]:
                            i_out = _grown_rows(i_out, used_i)
                        i_out[used_i, 0] = r
                        i_out[used_i, 1] = key
                        i_out[used_i, 2] = _simplex_key(g_lin, corner_off, s_c0, s_code, key_base, f)
                        used_i += 1
    return _records_upto(vk_out, vp_out, e_out, c_out, i_out, used_v, used_e, used_c, used_i), masks, degenerate


# ----------------------------------------------------------------------------- the candidate pass
# Which cubes can hold a piece of M_A: every component of F has a value >= 0 and one < 0
# among the cube's corners, and no corner value is NaN or infinite.  A per-vertex code
# (bit 2j: F_j >= 0, bit 2j+1: F_j < 0, bit 2k: not finite) OR-ed over the corners is
# separable.  A block's vertices are cut into planes (fixed indices on axes 0 and 1, the
# other axes contiguous): each plane is coded and OR-ed along its own axes while it is in
# cache, and a cube's code is then the OR of four plane codes at one offset.  (Whole-block
# passes, one per axis, read the block five times and took twice as long as evaluating F.)


@nb.njit(**PARALLEL_JIT)
def plane_codes(vals, code, first, inner_dims):
    """vals (Q, P, k): F at the vertices of Q planes of P vertices each (C order over
    inner_dims); code (Q, P) unsigned: for planes first..Q-1, each vertex's code OR-ed
    over the in-plane corners of the cube it is the origin of (along every inner axis).
    Returns how many of those vertices have a value that is not finite.
    """
    q_count, p_count, k = vals.shape
    bad = np.uint64(1) << np.uint64(2 * k)
    nonfinite = 0
    for q in prange(first, q_count):
        here = 0
        for v in range(p_count):
            c = np.uint64(0)
            for j in range(k):
                x = vals[q, v, j]
                if not np.isfinite(x):
                    c = bad
                    here += 1
                    break
                c |= np.uint64(1 if x >= 0.0 else 2) << np.uint64(2 * j)
            code[q, v] = c
        nonfinite += here
        stride = 1
        for a in range(inner_dims.shape[0] - 1, -1, -1):
            length = inner_dims[a]
            block = length * stride
            for o in range(0, p_count, block):  # in increasing index: code[v + stride] is read unchanged
                for v in range(o, o + block - stride):
                    code[q, v] |= code[q, v + stride]
            stride = block
    return nonfinite


@nb.njit(**PARALLEL_JIT)
def scan_candidates(code, d0, d1, inner_dims, k, counts, offsets, out):
    """The candidate cubes of a block whose planes (see `plane_codes`) are code (d0 * d1, P).

    Cube plane t = i0 * (d1 - 1) + i1 holds the cubes with origin (i0, i1, ...).  With
    an empty `out`, counts[t] = its number of candidates; else its candidates' origins
    are written, in C order, to out[offsets[t]:] (n columns).
    """
    full = np.uint64(0)
    for j in range(k):
        full |= np.uint64(3) << np.uint64(2 * j)
    mask = full | (np.uint64(1) << np.uint64(2 * k))
    nd = inner_dims.shape[0]
    last = inner_dims[nd - 1] if nd > 0 else 2  # (no inner axis: one vertex per plane)
    rows = code.shape[1] // last if nd > 0 else 1
    write = out.shape[0] > 0
    for t in prange((d0 - 1) * (d1 - 1)):
        i0 = t // (d1 - 1)
        i1 = t % (d1 - 1)
        q = i0 * d1 + i1
        found = 0
        p = offsets[t] if write else 0
        for r in range(rows):
            rem = r
            inside = True
            for a in range(nd - 2, -1, -1):  # the row's indices on the inner axes but the last
                if rem % inner_dims[a] == inner_dims[a] - 1:
                    inside = False
                rem //= inner_dims[a]
            if not inside:
                continue
            for j in range(last - 1):
                v = r * last + j if nd > 0 else 0
                c = code[q, v] | code[q + 1, v] | code[q + d1, v] | code[q + d1 + 1, v]
                if (c & mask) != full:
                    continue
                if write:
                    out[p, 0] = i0
                    out[p, 1] = i1
                    rem = r
                    for a in range(nd - 2, -1, -1):
                        out[p, 2 + a] = rem % inner_dims[a]
                        rem //= inner_dims[a]
                    if nd > 0:
                        out[p, 1 + nd] = j
                    p += 1
                else:
                    found += 1
        if not write:
            counts[t] = found


@nb.njit(**JIT)
def corner_sets_to_candidates(vals, n_corners, out):
    """out[i]: the candidate test of `codes_to_candidates` for cube i, whose corners are the
    rows i * n_corners .. (i + 1) * n_corners - 1 of vals (continuation gathers them so).

    Serial and fused: a wave is small, and two parallel launches per wave cost more
    than the test.
    """
    k = vals.shape[1]
    full = (np.int64(1) << (2 * k)) - 1
    for i in range(out.shape[0]):
        code = np.int64(0)
        finite = True
        for r in range(i * n_corners, (i + 1) * n_corners):
            for j in range(k):
                x = vals[r, j]
                if not np.isfinite(x):
                    finite = False
                code |= np.int64(1 if x >= 0.0 else 2) << (2 * j)
        out[i] = finite and code == full



# ----------------------------------------------------------------------------- continuation
@nb.njit(**JIT)
def facet_neighbours(wave, masks, div, cube_strides):
    """The cubes across the crossed facets of a wave's cubes, inside the grid.

    wave (m, n) cube origins; masks (m,) crossed-facet bits (bit 2a + side: side 0 leads
    to the cube below on axis a, side 1 above); div (n,) cubes per axis.  Returns
    (cubes (M, n), their linear keys (M,) by cube_strides), cube by cube, facets in bit
    order; a cube reached twice appears twice.
    """
    m, n = wave.shape
    total = 0
    for i in range(m):
        for f in range(2 * n):
            if masks[i] >> f & 1:
                total += 1
    cubes = np.empty((total, n), np.int64)
    keys = np.empty(total, np.int64)
    p = 0
    for i in range(m):
        for f in range(2 * n):
            if not masks[i] >> f & 1:
                continue
            a = f // 2
            to = wave[i, a] + (1 if f & 1 else -1)
            if to < 0 or to >= div[a]:
                continue
            key = 0
            for b in range(n):
                x = to if b == a else wave[i, b]
                cubes[p, b] = x
                key += x * cube_strides[b]
            keys[p] = key
            p += 1
    return cubes[:p], keys[:p]
