"""GCMH where the tables hold the faces only (n >= 8, large k): Kuhn simplices found, not listed."""

import numba as nb
import numpy as np

from .._config import JIT
from .cells import _face_in_face, _face_key, cells_of_chunk, tables_faces
from .records import EDGE_COLS, _grown_keys, _grown_rows, _records_upto, new_chunk
from .solve import _simplex_crosses_call, _zero_side, crossable_face
from .walk import _link, _walk_edges

# ----------------------------------------------------------------------------- large n: simplices found, not listed
# Where `_tables.lazy_tables` (n >= 8, large k) a k-face's k! Kuhn simplices (40,320 at k = 8, 3.6M
# at k = 10) are not in the tables: `cubes_chunk_lazy` walks the permutations of the face's axes
# depth first, in the tables' order (lexicographic), and drops a whole subtree when some linear
# functional h(F) has one sign on every corner the subtree's simplices can use.  Prefix (p_1..p_j)
# reaches the chain's first j + 1 corners and the corners above its last one (the sub-cube over
# the remaining axes).  Zero in a simplex is a convex combination of F at its corners, so h(F) takes both signs there:
# * h = F_j, with the sign prune's rule (a value 0 counts as +epsilon): exact;
# * h = differences of rows of W F, W the inverse of F's mean slope on the face: F ~ F(c0) + J x
#   gives W F ~ x - t, so the differences order the coordinates as the simplex does, and one
#   chain of k! survives where M is flat.  These prune only with a margin far above the
#   rounding of the solve (`simplex_crosses` accepts lam_i >= -1e-9): a simplex it would accept
#   is never dropped.
# The chains that survive are solved as the tables' kernel solves them, corners in the same order:
# the output is the same bit for bit, only the simplices never solved are not listed.

# Margin of the model functionals, relative to sum_j |w_j| max |F_j| on the face.
_MODEL_MARGIN = 1e-6
# Differences of W F's rows i and i' whose model coordinates are at most this far apart in order
# (1 orders a flat M's chain alone; 2 prunes more where F bends; all k(k-1)/2 pairs cost 2x at k = 10)
_MODEL_NEIGHBOURS = 2


@nb.njit(**JIT)
def _face_functionals(values, o, corner_row, fixed, axes, dim, k, model, cc, jac, sub, inv, hv, up_lo, up_hi,
                      pos_thr, neg_thr):
    """The prune's functionals on the face (fixed, local axes axes[0..dim-1]), dim = k or k + 1.

    Fills cc[c] (cube corner of local corner c, bit a: +1 along axes[a]), hv[h, c] (functional h
    at local corner c), up_lo/up_hi[h, c] (its min/max over the corners above c) and the
    thresholds: prune where min >= pos_thr[h] or max < neg_thr[h].  h < k are F's components;
    with `model`, differences of the rows of W F follow.  Returns the number of functionals.
    """
    n_local = 1 << dim
    for c in range(n_local):
        corner = fixed
        for a in range(dim):
            if (c >> a) & 1:
                corner |= np.int64(1) << axes[a]
        cc[c] = corner
    for j in range(k):
        for c in range(n_local):
            hv[j, c] = values[o + corner_row[cc[c]], j]
        pos_thr[j] = 0.0
        neg_thr[j] = 0.0
    nh = k
    if model:
        nh = _model_functionals(dim, k, jac, sub, inv, hv, pos_thr, neg_thr)
    for h in range(nh):
        for c in range(n_local):
            up_lo[h, c] = hv[h, c]
            up_hi[h, c] = hv[h, c]
        for a in range(dim):
            bit = 1 << a
            for c in range(n_local):
                if not c & bit:
                    if up_lo[h, c | bit] < up_lo[h, c]:
                        up_lo[h, c] = up_lo[h, c | bit]
                    if up_hi[h, c | bit] > up_hi[h, c]:
                        up_hi[h, c] = up_hi[h, c | bit]
    return nh


@nb.njit(**JIT)
def _det_or_inverse(sub, k, inv, want_inverse):
    """|det| of sub (k x k, rows scaled to max 1 first; overwritten), and with want_inverse its
    inverse into inv (of the rows as given).  0 where a pivot is below 1e-12 or not finite."""
    for i in range(k):
        for q in range(k):
            inv[i, q] = 1.0 if i == q else 0.0
    for i in range(k):
        scale = 0.0
        for q in range(k):
            scale = max(scale, abs(sub[i, q]))
        if not (scale > 0.0) or not np.isfinite(scale):
            return 0.0
        for q in range(k):
            sub[i, q] /= scale
        inv[i, i] = 1.0 / scale
    det = 1.0
    for c in range(k):
        piv = c
        for r in range(c + 1, k):
            if abs(sub[r, c]) > abs(sub[piv, c]):
                piv = r
        if not (abs(sub[piv, c]) > 1e-12):
            return 0.0
        if piv != c:
            for q in range(k):
                t = sub[c, q]
                sub[c, q] = sub[piv, q]
                sub[piv, q] = t
                t = inv[c, q]
                inv[c, q] = inv[piv, q]
                inv[piv, q] = t
        det *= abs(sub[c, c])
        if not want_inverse:
            for r in range(c + 1, k):
                fac = sub[r, c] / sub[c, c]
                for q in range(c, k):
                    sub[r, q] -= fac * sub[c, q]
            continue
        p = sub[c, c]
        for q in range(k):
            sub[c, q] /= p
            inv[c, q] /= p
        for r in range(k):
            if r != c:
                fac = sub[r, c]
                if fac != 0.0:
                    for q in range(k):
                        sub[r, q] -= fac * sub[c, q]
                        inv[r, q] -= fac * inv[c, q]
    return det


@nb.njit(**JIT)
def _model_functionals(dim, k, jac, sub, inv, hv, pos_thr, neg_thr):
    """`_face_functionals`' model part: rows k.. of hv.  F's mean slope J (k x dim) along each
    local axis; on a (k+1)-face the axis whose column leaves the best k x k part is left out.
    W = that part's inverse; W F ~ x - x*, and the differences of its rows for coordinates near
    one another in x*'s order (the rows alone never prune: every subtree reaches corner 0 and the
    far corner).  Returns the count (k if the slope is singular)."""
    n_local = 1 << dim
    half = n_local // 2
    for j in range(k):
        for a in range(dim):
            bit = 1 << a
            s = 0.0
            for c in range(n_local):
                if not c & bit:
                    s += hv[j, c | bit] - hv[j, c]
            jac[j, a] = s / half
    drop = -1
    if dim > k:
        best = 0.0
        for d in range(dim):
            for j in range(k):
                q = 0
                for a in range(dim):
                    if a != d:
                        sub[j, q] = jac[j, a]
                        q += 1
            det = _det_or_inverse(sub, k, inv, False)
            if det > best:
                best = det
                drop = d
        if drop < 0:
            return k
    for j in range(k):
        q = 0
        for a in range(dim):
            if a != drop:
                sub[j, q] = jac[j, a]
                q += 1
    if _det_or_inverse(sub, k, inv, True) == 0.0:
        return k
    for i in range(k):
        for j in range(k):
            if not np.isfinite(inv[i, j]):
                return k
    maxabs = np.zeros(k)
    mean = np.zeros(k)
    for j in range(k):
        for c in range(n_local):
            maxabs[j] = max(maxabs[j], abs(hv[j, c]))
            mean[j] += hv[j, c]
        mean[j] /= n_local
    # W F ~ x - x*: x* the model's zero (the dropped axis at 1/2), its coordinates in order
    order = np.empty(k, np.int64)
    zero = np.empty(k)
    for i in range(k):
        x = 0.5
        for j in range(k):
            x -= inv[i, j] * mean[j]
        zero[i] = x
        q = i
        while q > 0 and zero[order[q - 1]] > x:
            order[q] = order[q - 1]
            q -= 1
        order[q] = i
    w = np.empty(k)
    h = k
    for p in range(k):
        for step in range(1, _MODEL_NEIGHBOURS + 1):
            if p + step >= k:
                break
            a = order[p]
            b = order[p + step]
            size = 0.0
            for j in range(k):
                w[j] = inv[a, j] - inv[b, j]
                size += abs(w[j]) * maxabs[j]
            for c in range(n_local):
                x = 0.0
                for j in range(k):
                    x += w[j] * hv[j, c]
                hv[h, c] = x
            pos_thr[h] = _MODEL_MARGIN * size
            neg_thr[h] = -_MODEL_MARGIN * size
            h += 1
    return h


@nb.njit(**JIT)
def _perm_rank(perm, first, last, fact):
    """Lexicographic rank of perm[first:last] among the orders of its (distinct) entries."""
    rank = 0
    for i in range(first, last):
        smaller = 0
        for q in range(i + 1, last):
            if perm[q] < perm[i]:
                smaller += 1
        rank += smaller * fact[last - 1 - i]
    return rank


@nb.njit(**JIT)
def _kuhn_chains(dim, nh, hv, up_lo, up_hi, pos_thr, neg_thr, fact, corner, nxt, rank_at, perm, p_lo, p_hi,
                 out_perm, out_rank):
    """The Kuhn chains of a dim-face that the functionals of `_face_functionals` leave, in
    lexicographic order of their permutations: out_perm[i, :dim] (local axes), out_rank[i].
    Returns how many; past the outputs' length only the count goes on (the caller grows them)."""
    for h in range(nh):
        if up_lo[h, 0] >= pos_thr[h] or up_hi[h, 0] < neg_thr[h]:
            return 0
        p_lo[0, h] = hv[h, 0]
        p_hi[0, h] = hv[h, 0]
    corner[0] = 0
    rank_at[0] = 0
    found = 0
    d = 1
    nxt[1] = 0
    while d >= 1:
        prev = corner[d - 1]
        a = nxt[d]
        while a < dim and (prev >> a) & 1:
            a += 1
        if a >= dim:
            d -= 1
            continue
        nxt[d] = a + 1
        c = prev | (1 << a)
        out = False
        for h in range(nh):
            v = hv[h, c]
            lo = min(p_lo[d - 1, h], v)
            hi = max(p_hi[d - 1, h], v)
            p_lo[d, h] = lo
            p_hi[d, h] = hi
            if min(lo, up_lo[h, c]) >= pos_thr[h] or max(hi, up_hi[h, c]) < neg_thr[h]:
                out = True
                break
        if out:
            continue
        below = 0  # a's digit in the factorial base: the unused axes below it
        for b in range(a):
            if not (prev >> b) & 1:
                below += 1
        corner[d] = c
        perm[d - 1] = a
        rank_at[d] = rank_at[d - 1] + below * fact[dim - d]
        if d == dim:
            if found < out_rank.shape[0]:
                for i in range(dim):
                    out_perm[found, i] = perm[i]
                out_rank[found] = rank_at[d]
            found += 1
        else:
            d += 1
            nxt[d] = 0
    return found


@nb.njit(**JIT)
def _node_slot(slot_key, node):
    """The slot of `node` in the open-addressing table slot_key (a power of two long, -1 free):
    where it is, or the free slot where it goes."""
    mask = slot_key.shape[0] - 1
    i = (node * np.int64(0x9E3779B1)) & mask
    while slot_key[i] != -1 and slot_key[i] != node:
        i = (i + 1) & mask
    return i


@nb.njit(**JIT)
def _node_index(slot_key, slot_node, node):
    """The walk node's row, -1 if it has none yet."""
    i = _node_slot(slot_key, node)
    return slot_node[i] if slot_key[i] == node else -1


@nb.njit(**JIT)
def cubes_chunk_lazy(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex,
                     tables):
    """`cubes_chunk` for tables that hold faces only (`_tables.lazy_tables`) (no k-simplices, no walk
    template): the same records, bit for bit, by the same phases: vertices and edges
    (`_vertices_edges_lazy`), then the cells (`cells.cells_phase`).
    (No check of joined pieces: `cubes_chunk` has none for n > 7 either.)"""
    (cube_v0, cube_e0, crossed_facets, vertex_key, vertex_point, vertex_face, vertex_perm, no_ksimplex, edge_a, edge_b,
     edge_face, edge_out, used_v, used_e, degenerate) = _vertices_edges_lazy(
        lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex, tables)
    c_out, i_out, used_c, used_i, non_ball, events = cells_of_chunk(
        lo, hi, values, cube_row, corner_row, cube_vertex, corner_vertex, tables_faces(tables), tables.binom,
        tables.kuhn, tables.ksimplex_kuhn, cube_v0, cube_e0, crossed_facets,
        vertex_key, vertex_face, vertex_perm, no_ksimplex, edge_a, edge_b, edge_face, edge_out, 8 * (hi - lo) + 16,
        64, 16,
    )
    records = _records_upto(vertex_key, vertex_point, edge_out, c_out, i_out, used_v, used_e, used_c, used_i)
    return records, crossed_facets, degenerate + events, non_ball


@nb.njit(**JIT)
def _vertices_edges_lazy(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex,
                         tables):
    """Steps 1 and 2 of GCMH (paper 3.1.1) on the cubes lo..hi-1: each cube's vertices and edges, as
    the chunk `records.new_chunk` describes, its rows grown here as needed (only the arrays that
    grow are rebound in the loop: each costs a reference count per pass).  A k-face's Kuhn
    simplices and, where a walk runs, a (k+1)-face's come from `_kuhn_chains`; a vertex carries
    its permutation's rank itself.  Returns (the chunk's arrays, vertex rows, edge rows, degenerate events)."""
    rows = 8 * (hi - lo) + 16
    (cube_v0, cube_e0, crossed_facets, vertex_key, vertex_point, vertex_face, vertex_perm, no_ksimplex, edge_a,
     edge_b, edge_face, _) = new_chunk(hi - lo, rows, rows, tables.n)
    n = tables.n
    k = tables.k
    face_start = tables.face_start
    face_free = tables.face_free
    face_fixed = tables.face_fixed
    face_rank = tables.face_rank
    n_subsets = tables.n_subsets
    kfact = tables.simplices_per_kface
    k1 = k + 1
    n_boundary = 2 * k1 * kfact  # the walk's boundary nodes, numbered as in the tables
    fact = np.ones(k1 + 1, np.int64)
    for i in range(1, k1 + 1):
        fact[i] = fact[i - 1] * i
    nh_max = k + _MODEL_NEIGHBOURS * k
    model = k >= 3
    cc = np.empty(1 << k1, np.int64)
    jac = np.empty((k, k1), np.float64)
    sub = np.empty((k, k), np.float64)
    inv = np.empty((k, k), np.float64)
    hv = np.empty((nh_max, 1 << k1), np.float64)
    up_lo = np.empty((nh_max, 1 << k1), np.float64)
    up_hi = np.empty((nh_max, 1 << k1), np.float64)
    pos_thr = np.empty(nh_max, np.float64)
    neg_thr = np.empty(nh_max, np.float64)
    dfs_corner = np.empty(k1 + 1, np.int64)
    dfs_next = np.empty(k1 + 2, np.int64)
    dfs_rank = np.empty(k1 + 1, np.int64)
    dfs_perm = np.empty(k1, np.int64)
    p_lo = np.empty((k1 + 1, nh_max), np.float64)
    p_hi = np.empty((k1 + 1, nh_max), np.float64)
    leaf_perm = np.empty((64, k1), np.int64)
    leaf_rank = np.empty(64, np.int64)
    axes = np.empty(k1, np.int64)
    chain = np.empty((1, k + 1), np.int64)  # one simplex's cube corners, as a table
    perm_copy = np.empty(k1, np.int64)
    corner_signs = np.empty(1 << n, np.int64)
    mat = np.empty((k, k), np.float64)
    rhs = np.empty(k, np.float64)
    lam = np.empty(k + 1, np.float64)
    found_node = np.empty(16, np.int64)
    found_vertex = np.empty(16, np.int64)
    found_row = np.empty(16, np.int64)
    walked = np.empty(16, np.int8)
    node_id = np.empty(64, np.int64)
    node_slot = np.empty(64, np.int64)
    slot_key = np.full(256, -1, np.int64)  # node -> row (a walk through a curved face meets 10^5 nodes)
    slot_node = np.empty(256, np.int64)
    node_crossed = np.empty(64, np.int8)
    next0 = np.empty(64, np.int64)
    next1 = np.empty(64, np.int64)
    used_v = used_e = np.int64(0)
    n_corners = 1 << n
    all_signs = (np.int64(1) << k) - 1
    degenerate = 0
    kface0 = face_start[k]
    n_kfaces = face_start[k + 1] - kface0
    k1face0 = face_start[k1]
    n_k1faces = face_start[k1 + 1] - k1face0
    for ci in range(lo, hi):
        cube_v0[ci - lo] = used_v
        cube_e0[ci - lo] = used_e
        o = cube_row[ci]
        g_vertex = cube_vertex[ci]
        for c in range(n_corners):
            p = np.int64(0)
            r0 = o + corner_row[c]
            for j in range(k):
                if values[r0, j] >= 0.0:
                    p |= np.int64(1) << j
            corner_signs[c] = p

        # 1. Vertices on the Kuhn k-simplices of the k-faces (paper 3.1.1)
        nv = 0
        for kf in range(n_kfaces):
            f = kface0 + kf
            free = face_free[f]
            fixed = face_fixed[f]
            if not crossable_face(corner_signs, free, fixed, all_signs):
                continue  # the sign prune over the face's corners first: most faces stop here
            q = 0
            for a in range(n):
                if (free >> a) & 1:
                    axes[q] = a
                    q += 1
            nh = _face_functionals(values, o, corner_row, fixed, axes, k, k, model, cc, jac, sub, inv, hv, up_lo,
                                   up_hi, pos_thr, neg_thr)
            while True:
                count = _kuhn_chains(k, nh, hv, up_lo, up_hi, pos_thr, neg_thr, fact, dfs_corner, dfs_next,
                                     dfs_rank, dfs_perm, p_lo, p_hi, leaf_perm, leaf_rank)
                if count <= leaf_rank.shape[0]:
                    break
                leaf_perm = np.empty((2 * count, k1), np.int64)
                leaf_rank = np.empty(2 * count, np.int64)
            for leaf in range(count):
                local = 0
                chain[0, 0] = cc[0]
                for i in range(k):
                    local |= 1 << leaf_perm[leaf, i]
                    chain[0, i + 1] = cc[local]
                hit = _simplex_crosses_call(
                    values, o, corner_row, chain, np.int64(0), k, corner_signs, all_signs, mat, rhs, lam
                )
                if hit == 2:
                    hit = _zero_side(values, o, corner_row, chain, np.int64(0), k, lam)
                if not hit:
                    continue
                row = used_v + nv
                if row >= vertex_key.shape[0]:
                    vertex_key = _grown_keys(vertex_key, row)
                    vertex_point = _grown_rows(vertex_point, row)
                    vertex_face = _grown_keys(vertex_face, row)
                    vertex_perm = _grown_keys(vertex_perm, row)
                vertex_face[row] = f
                vertex_perm[row] = leaf_rank[leaf]
                vertex_key[row] = (
                    _face_key(g_vertex + corner_vertex[fixed], n_subsets[k], face_rank[f]) * kfact + leaf_rank[leaf]
                )
                for a in range(n):
                    x = 0.0
                    for i in range(k + 1):
                        x += lam[i] * grid_lines[a, cube_origin[ci, a] + ((chain[0, i] >> a) & 1)]
                    vertex_point[row, a] = x
                nv += 1
        if nv == 0:
            continue

        # 2. Edges on the (k+1)-faces: two vertices are joined, more by the walk (paper 3.1.1)
        if found_node.shape[0] < nv:
            found_node = np.empty(2 * nv, np.int64)
            found_vertex = np.empty(2 * nv, np.int64)
            found_row = np.empty(2 * nv, np.int64)
            walked = np.empty(2 * nv, np.int8)
        ne = used_e  # (an int64, passed to _walk_edges: see _config)
        for kf1 in range(n_k1faces):
            f1 = k1face0 + kf1
            ff = face_free[f1]
            fx = face_fixed[f1]
            q = 0
            for a in range(n):
                if (ff >> a) & 1:
                    axes[q] = a
                    q += 1
            # the vertices on its boundary, as the walk's boundary nodes (local k-face, permutation)
            n_found = 0
            for v in range(nv):
                g = vertex_face[used_v + v]
                if not _face_in_face(face_free[g], face_fixed[g], ff, fx):
                    continue
                dropped = 0
                while axes[dropped] != _lowest_bit(ff & ~face_free[g]):
                    dropped += 1
                side = (face_fixed[g] >> axes[dropped]) & 1
                node = ((k1 - 1 - dropped) * 2 + side) * kfact + vertex_perm[used_v + v]
                i = n_found
                while i > 0 and found_node[i - 1] > node:  # in node order, as the tables' kernel finds them
                    found_node[i] = found_node[i - 1]
                    found_vertex[i] = found_vertex[i - 1]
                    i -= 1
                found_node[i] = node
                found_vertex[i] = v
                n_found += 1
            if n_found == 0:
                continue
            while ne + n_found >= edge_a.shape[0]:
                edge_a = _grown_keys(edge_a, ne)
                edge_b = _grown_keys(edge_b, ne)
                edge_face = _grown_keys(edge_face, ne)
            if n_found == 2:
                edge_a[ne] = found_vertex[0]
                edge_b[ne] = found_vertex[1]
                edge_face[ne] = f1
                ne += 1
                continue
            # The walk (Fig. 3) through the face's Kuhn (k+1)-simplices that the prune leaves
            nh = _face_functionals(values, o, corner_row, fx, axes, k1, k, model, cc, jac, sub, inv, hv, up_lo,
                                   up_hi, pos_thr, neg_thr)
            while True:
                count = _kuhn_chains(k1, nh, hv, up_lo, up_hi, pos_thr, neg_thr, fact, dfs_corner, dfs_next,
                                     dfs_rank, dfs_perm, p_lo, p_hi, leaf_perm, leaf_rank)
                if count <= leaf_rank.shape[0]:
                    break
                leaf_perm = np.empty((2 * count, k1), np.int64)
                leaf_rank = np.empty(2 * count, np.int64)
            n_nodes = 0
            for leaf in range(count):
                n_crossed = 0
                node_a = -1
                node_b = -1
                for j in range(k1 + 1):
                    if j == 0:  # drop the first corner: the local k-face with P[0] at 1, permutation P[1:]
                        node = ((k1 - 1 - leaf_perm[leaf, 0]) * 2 + 1) * kfact + _perm_rank(
                            leaf_perm[leaf], 1, k1, fact)
                    elif j == k1:  # drop the last: P[k] at 0, permutation P[:k]
                        node = ((k1 - 1 - leaf_perm[leaf, k]) * 2) * kfact + _perm_rank(leaf_perm[leaf], 0, k, fact)
                    else:  # inside, shared with the simplex that swaps P[j-1] and P[j]: named by the smaller
                        rank = leaf_rank[leaf]
                        if leaf_perm[leaf, j - 1] > leaf_perm[leaf, j]:
                            for i in range(k1):
                                perm_copy[i] = leaf_perm[leaf, i]
                            perm_copy[j - 1] = leaf_perm[leaf, j]
                            perm_copy[j] = leaf_perm[leaf, j - 1]
                            rank = _perm_rank(perm_copy, 0, k1, fact)
                        node = n_boundary + rank * k + (j - 1)
                    at = _node_index(slot_key, slot_node, node)
                    if at < 0:
                        if node < n_boundary:
                            crossed = False
                            for i in range(n_found):
                                if found_node[i] == node:
                                    crossed = True
                        else:
                            local = 0
                            q = 0
                            for i in range(k1 + 1):
                                if i > 0:
                                    local |= 1 << leaf_perm[leaf, i - 1]
                                if i != j:
                                    chain[0, q] = cc[local]
                                    q += 1
                            hit = _simplex_crosses_call(
                                values, o, corner_row, chain, np.int64(0), k, corner_signs, all_signs, mat, rhs, lam
                            )
                            if hit == 2:
                                hit = _zero_side(values, o, corner_row, chain, np.int64(0), k, lam)
                            crossed = hit == 1
                        if n_nodes >= node_id.shape[0]:
                            node_id = _grown_keys(node_id, n_nodes)
                            node_slot = _grown_keys(node_slot, n_nodes)
                            next0 = _grown_keys(next0, n_nodes)
                            next1 = _grown_keys(next1, n_nodes)
                            node_crossed = _grown_keys(node_crossed, n_nodes)
                        if 2 * (n_nodes + 1) > slot_key.shape[0]:  # at most half full: rehash twice as long
                            slot_key = np.full(2 * slot_key.shape[0], -1, np.int64)
                            slot_node = np.empty(slot_key.shape[0], np.int64)
                            for i in range(n_nodes):
                                sl = _node_slot(slot_key, node_id[i])
                                slot_key[sl] = node_id[i]
                                slot_node[sl] = i
                                node_slot[i] = sl
                        at = n_nodes
                        sl = _node_slot(slot_key, node)
                        slot_key[sl] = node
                        slot_node[sl] = at
                        node_slot[at] = sl
                        node_id[at] = node
                        node_crossed[at] = 1 if crossed else 0
                        next0[at] = -1
                        next1[at] = -1
                        n_nodes += 1
                    if node_crossed[at]:
                        if n_crossed == 0:
                            node_a = at
                        elif n_crossed == 1:
                            node_b = at
                        n_crossed += 1
                degenerate += _link(next0, next1, n_crossed, node_a, node_b)
            for q in range(n_found):
                found_row[q] = _node_index(slot_key, slot_node, found_node[q])
            ne, events = _walk_edges(next0, next1, node_id, n_boundary, n_nodes + 1, found_row, found_vertex, n_found,
                                     walked, edge_a, edge_b, edge_face, ne, f1)
            degenerate += events
            for i in range(n_nodes):  # the table empty for the next walk
                slot_key[node_slot[i]] = -1

        used_v += nv
        used_e = ne
    cube_v0[hi - lo] = used_v
    cube_e0[hi - lo] = used_e
    return (cube_v0, cube_e0, crossed_facets, vertex_key, vertex_point, vertex_face, vertex_perm, no_ksimplex, edge_a,
            edge_b, edge_face, np.empty((edge_a.shape[0], EDGE_COLS), np.int64), used_v, used_e, degenerate)


@nb.njit(**JIT)
def _lowest_bit(x):
    """Index of x's lowest set bit."""
    a = 0
    while not (x >> a) & 1:
        a += 1
    return a
