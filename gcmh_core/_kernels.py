"""The numba kernels of GCMH.  They see only arrays: F's values at grid vertices,
the grid lines, and the cube tables of `_tables`.  Nothing here depends on F.

Per candidate cube H, `cubes_chunk` follows paper Section 3.1, in the cube's own frame:
  1. vertices of M_H on the CFK k-simplices of its k-faces (barycentric solve);
  2. edges of M_H on its (k+1)-faces: two vertices are joined; more are paired by
     the walk of Section 3.1.1 (Fig. 3) through the face's CFK (k+1)-simplices;
  3. cells (Section 3.1.2): for r = 2..n-k, the r-cells are the connected pieces of
     the vertex-edge graph G_H restricted to each (r+k)-face of H, written with their
     (r-1)-faces.
Where the tables list no Kuhn simplices (`_tables.lazy_tables`: n >= 8, large k), `cubes_chunk`
runs `cubes_chunk_lazy`, which finds the ones it needs by a pruned walk over permutations:
the same records, bit for bit.
Everything is emitted with global keys computed from grid indices alone, so
the same vertex, edge or cell produced by two neighbouring cubes is recognised
in the global assembly (`runner.assemble_records`).  `simplices_chunk` does the same
for the simplicial baselines CMS and CCS (Section 4).

A chunk of cubes returns its records in cube order, and chunks are joined in
order: the output does not depend on the number of threads.

The three steps stay in one function.  Tried as three functions called per cube, each
taking some 20 arrays, they cost 0.5 to 1.6 us more per cube, where a sphere's whole cube
takes 0.6 us.  Even names move this function's speed (numba orders its reference
counts by variable name): a renaming is timed like any other change to it.

Glossary: the paper's terms -> the names here and in `_tables`
--------------------------------------------------------------
F = (F_1..F_k), its values    `values[row, j]`: F_j at a grid vertex.  Corner c of cube i
                              is row `cube_row[i] + corner_row[c]`
hypercube H, its corners      a cube; a corner is a bit mask c (bit a: +1 along axis a)
r-face of H (Def. 2.9)        `CubeTables` row f: free axes `face_free[f]`, anchor corner
                              `face_fixed[f]`; the r-faces are rows face_start[r]:face_start[r+1]
face label l(f) (Def. 3.1)    `_face_key`: f's anchor grid vertex and the rank of its free axes
CFK triangulation of a k-face `ksimplex_*`: the k! Kuhn k-simplices of each k-face (a chain of
                              corners, one per permutation of the face's axes)
lambda_0..lambda_k (3.1.1)    `lam`, found by `simplex_crosses`
sign of F_j at the corners    `corner_signs[c]` (bit j: F_j >= 0 at c) and
                              `positive_corners[j]` (bit c: the same), for the sign prune
vertex of M_H                 a crossed k-simplex s: `vertex_of_ksimplex[s]` >= 0; the vertex
                              v sits on the k-face `vertex_face[v]`, global key `vertex_key[v]`
edge of M_H on a (k+1)-face   `edge_a[e]`, `edge_b[e]` (vertices) on the face `edge_face[e]`
the walk (3.1.1, Fig. 3)      `walk_*`: a (k+1)-face's CFK (k+1)-simplices; the walk's nodes are
                              their k-facets, boundary nodes (the face's own k-simplices) first,
                              then interior ones; `walk_next0/1[node]` link the crossed nodes
graph G_H (step 2.1)          the cube's vertices and edges
r-cell of M_H (step 2.2)      a connected piece (union-find `parent`) of G_H in an (r+k)-face
                              of H, keyed by the face and its smallest vertex code `_local_code`
its (r-1)-faces (Alg. 1)      the (r-1)-cells in the faces of that (r+k)-face: incidence rows
crossed facets (Sec. 5.2)     `crossed_facets[i]`, bit 2a + side: where continuation goes next
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


@nb.njit(**JIT)
def _zero_side(vals, o, value_off, table, s, k, lam):
    """`simplex_crosses`'s answer 2 decided: 1 if the zero is inside the simplex, else 0.

    A value 0 counts as +epsilon (the sign prune's rule, a symbolic perturbation).  Where
    some F_j is 0 on the whole facet opposite corner i and < 0 at i, the solve finds
    lam_i = 0 up to rounding, and the perturbed zero lies inside: lam_i = 0+.  Any other
    slightly negative lam_i is outside.  (Called from the kernels' own loops, rarely: as a
    branch inside the inlined solve it slowed every cube by a fifth.)
    """
    for i in range(k + 1):
        if lam[i] >= 0.0:
            continue
        inside = False
        for j in range(k):
            if vals[o + value_off[table[s, i]], j] < 0.0:
                on_facet = True
                for q in range(k + 1):
                    if q != i and vals[o + value_off[table[s, q]], j] != 0.0:
                        on_facet = False
                if on_facet:
                    inside = True
        if not inside:
            return 0
        lam[i] = 0.0
    return 1

@nb.njit(**INLINE_JIT)
def simplex_crosses(vals, o, value_off, table, s, k, pos_mask, full, mat, rhs, lam):
    """Does the CFK simplex with cube corners table[s, 0..k] (chain order) hold a zero?
    1 yes, 0 no, 2 only up to rounding on a facet: then `_zero_side` decides.

    vals (NV, k): F's values (`values` in the kernels); corner c of the cube is row
    o + value_off[c] (`corner_row`); pos_mask and full are the kernels' `corner_signs`
    and `all_signs`; lam (k+1,) receives the barycentric coordinates.  Sign prune
    first: every component needs a value >= 0 and one < 0 among the simplex's corners,
    else there is no solve at all.  The simplex comes as a table and a row, not as the
    row itself: a slice made per simplex costs reference counting that was once most of
    a cube's work.  Kernels prune in their own loops first and call this for the few
    simplices that pass.  (The parameters keep their old names: renamed like the
    kernels' variables, they made the inlined code 10% slower on the complex cosine.)
    """
    m = k + 1
    any_pos = 0
    all_pos = full
    for i in range(m):
        p = pos_mask[table[s, i]]
        any_pos |= p
        all_pos &= p
    if any_pos != full or all_pos != 0:
        return 0
    # Solve sum_{i>=1} lam_i (F(v_i) - F(v_0)) = -F(v_0), a k x k system.
    r0 = o + value_off[table[s, 0]]
    for j in range(k):
        f0 = vals[r0, j]
        rhs[j] = -f0
        for i in range(1, m):
            mat[j, i - 1] = vals[o + value_off[table[s, i]], j] - f0
    # Scaled partial pivoting: each pivot is weighed against the largest entry of its
    # own row (component F_j) as it came, so multiplying F_j by any positive factor
    # changes neither the pivots nor the singularity test.  lam holds the rows'
    # inverse scales until the back substitution writes it.
    for j in range(k):
        scale = 0.0
        for i in range(k):
            a = abs(mat[j, i])
            if a > scale:
                scale = a
        if scale == 0.0:
            return 0
        lam[j] = 1.0 / scale
    for c in range(k):  # Gaussian elimination
        piv = c
        best = abs(mat[c, c]) * lam[c]
        for rr in range(c + 1, k):
            a = abs(mat[rr, c]) * lam[rr]
            if a > best:
                best = a
                piv = rr
        if not (best > 1e-14):  # (also NaN, from a subnormal row)
            return 0
        if piv != c:
            for i in range(k):
                t = mat[c, i]
                mat[c, i] = mat[piv, i]
                mat[piv, i] = t
            t = rhs[c]
            rhs[c] = rhs[piv]
            rhs[piv] = t
            t = lam[c]
            lam[c] = lam[piv]
            lam[piv] = t
        for rr in range(c + 1, k):
            fac = mat[rr, c] / mat[c, c]
            if fac != 0.0:
                for i in range(c, k):
                    mat[rr, i] -= fac * mat[c, i]
                rhs[rr] -= fac * rhs[c]
    total = 0.0
    for c in range(k - 1, -1, -1):
        acc = rhs[c]
        for i in range(c + 1, k):
            acc -= mat[c, i] * lam[i + 1]
        lam[c + 1] = acc / mat[c, c]
        total += lam[c + 1]
    lam[0] = 1.0 - total
    near = False
    for i in range(m):
        if not (lam[i] >= 0.0):
            if not (lam[i] > -1e-9):
                return 0
            near = True  # on a facet up to rounding: `_zero_side` decides
    return 2 if near else 1


# The same solve as a plain call, for the rare callers (a walk's interior nodes, `_joined_pieces`):
# each inlined copy costs the first run's compile more than a call costs these callers.
_simplex_crosses_call = nb.njit(**JIT)(simplex_crosses.py_func)


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


# Copies are loops: a slice assignment (b[:used] = a[:used]) brings numba's shape-mismatch
# error path, whose message formatting compiled for seconds on a first run.
@nb.njit(**JIT)
def _grown_keys(a, used):
    """a's first `used` entries in an array twice as long."""
    b = np.empty(2 * a.shape[0] + 1, a.dtype)
    for i in range(used):
        b[i] = a[i]
    return b


@nb.njit(**JIT)
def _grown_rows(a, used):
    """a's first `used` rows in an array with twice the rows."""
    b = np.empty((2 * a.shape[0] + 1, a.shape[1]), a.dtype)
    for i in range(used):
        for j in range(a.shape[1]):
            b[i, j] = a[i, j]
    return b


@nb.njit(**JIT)
def _records_upto(vk, vp, e, c, i, used_v, used_e, used_c, used_i):
    """The written rows, copied out of the (up to twice too long) growing arrays."""
    return vk[:used_v].copy(), vp[:used_v].copy(), e[:used_e].copy(), c[:used_c].copy(), i[:used_i].copy()


@nb.njit(**JIT)
def cubes_chunk(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex, tables):
    """GCMH on the candidate cubes lo..hi-1, in the calling thread, with one set of scratch buffers.

    values (NV, k) float64: F at grid vertices; corner c of cube i is row cube_row[i] + corner_row[c].
    cube_origin (m, n): the global multi-index of each cube's origin; cube_vertex (m,): its global
    linear vertex index (corner c adds corner_vertex[c]; keys come from these, never from rows).
    grid_lines (n, max vertices per axis): the (perturbed) grid lines.  tables: `_tables.CubeTables`.
    Returns (vertex keys, vertex points, edges, cells, incidences) records in cube order,
    each cube's crossed-facet mask, the number of degenerate events, and where M_A joins
    pieces of G_H through a face of the cube (`_joined_pieces`: cells that are not balls;
    n <= 7): rows (cube - lo, face, pieces joined).
    """
    n = tables.n
    k = tables.k
    face_start = tables.face_start
    face_free = tables.face_free
    face_fixed = tables.face_fixed
    face_rank = tables.face_rank
    n_subsets = tables.n_subsets
    binom = tables.binom
    n_codes = tables.n_codes
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
    vertex_ksimplex = np.empty(n_ksimplices, np.int64)
    vertex_face = np.empty(n_ksimplices, np.int64)
    vertex_key = np.empty(n_ksimplices, np.int64)
    max_edges = (face_start[k + 2] - face_start[k + 1]) * (n_boundary // 2)
    edge_a = np.empty(max_edges, np.int64)
    edge_b = np.empty(max_edges, np.int64)
    edge_face = np.empty(max_edges, np.int64)
    parent = np.empty(n_ksimplices, np.int64)
    cell_of_root = np.empty(n_ksimplices, np.int64)
    cells_buf_a = np.empty((4 * n_ksimplices, 3), np.int64)
    cells_buf_b = np.empty((4 * n_ksimplices, 3), np.int64)
    vk_out, vp_out, e_out, c_out, i_out = _new_records(8 * (hi - lo) + 16, n)
    used_v = used_e = used_c = used_i = np.int64(0)  # rows written (int64 from the start: see _config)
    crossed_facets = np.zeros(hi - lo, np.int64)
    n_corners = 1 << n
    all_signs = (np.int64(1) << k) - 1
    degenerate = 0
    kuhn = tables.kuhn
    ksimplex_kuhn = tables.ksimplex_kuhn
    check_balls = ksimplex_kuhn.shape[0] > 0
    kuhn_parent = np.empty(kuhn.corners.shape[0], np.int64)
    non_ball = np.empty((4, 3), np.int64)  # rows (cube - lo, face, pieces joined)
    n_non_ball = np.int64(0)  # (int64 from the start: see _config)
    for ci in range(lo, hi):
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
                    vertex_ksimplex[nv] = s
                    row = used_v + nv
                    if row >= vk_out.shape[0]:
                        vk_out = _grown_keys(vk_out, row)
                        vp_out = _grown_rows(vp_out, row)
                    f = kface0 + ksimplex_face[s]
                    vertex_face[nv] = f
                    vertex_key[nv] = (
                        _face_key(g_vertex + corner_vertex[face_fixed[f]], n_subsets[k], face_rank[f]) * kfact
                        + ksimplex_perm[s]
                    )
                    vk_out[row] = vertex_key[nv]
                    for a in range(n):
                        x = 0.0
                        for i in range(k + 1):
                            x += lam[i] * grid_lines[a, cube_origin[ci, a] + ((ksimplex_corners[s, i] >> a) & 1)]
                        vp_out[row, a] = x
                    nv += 1
        # facets of the cube that M_A crosses (bit 2a + side): where continuation goes next
        facets = np.int64(0)
        for v in range(nv):
            f = vertex_face[v]
            for a in range(n):
                if not (face_free[f] >> a) & 1:
                    facets |= np.int64(1) << (2 * a + ((face_fixed[f] >> a) & 1))
        crossed_facets[ci - lo] = facets
        if nv == 0:
            continue

        # 2. Edges on the (k+1)-faces: two vertices are joined, more by the walk (paper 3.1.1)
        k1 = k + 1
        k1face0 = face_start[k1]
        n_k1faces = face_start[k1 + 1] - k1face0
        ne = 0
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
                if n_crossed == 2:
                    for pair in range(2):
                        u = node_a if pair == 0 else node_b
                        w = node_b if pair == 0 else node_a
                        if walk_next0[u] < 0:
                            walk_next0[u] = w
                        elif walk_next1[u] < 0:
                            walk_next1[u] = w
                        else:
                            degenerate += 1
                elif n_crossed != 0:
                    degenerate += 1
            for q in range(n_found):
                walked[q] = 0
            for q in range(n_found):
                if walked[q]:
                    continue
                start = boundary_found[q]
                before = -1
                at = start
                end = -1
                for _step in range(n_boundary + n_interior + 1):
                    nxt = walk_next0[at] if walk_next0[at] != before else walk_next1[at]
                    if nxt < 0:
                        break
                    before = at
                    at = nxt
                    if at < n_boundary:
                        end = at
                        break
                if end < 0 or end == start:
                    degenerate += 1
                    walked[q] = 1
                    continue
                for q2 in range(n_found):
                    if boundary_found[q2] == end:
                        walked[q2] = 1
                walked[q] = 1
                edge_a[ne] = vertex_of_ksimplex[walk_boundary_simplex[kf1, start]]
                edge_b[ne] = vertex_of_ksimplex[walk_boundary_simplex[kf1, end]]
                edge_face[ne] = k1face0 + kf1
                ne += 1

        # 3. Cells (paper 3.1.2): for r = 1..n-k, the r-cells are the connected pieces of the
        # vertex-edge graph inside each (r+k)-face; for r = 1 they are the edges themselves.
        # Rows of lower/cells: (face, a vertex of the piece, key); the buffers swap per level.
        lower = cells_buf_a
        cells = cells_buf_b
        if lower.shape[0] < ne:
            lower = np.empty((ne, 3), np.int64)
        for e in range(ne):
            f = edge_face[e]
            ca = _local_code(
                face_free[f], face_free[vertex_face[edge_a[e]]], face_fixed[vertex_face[edge_a[e]]],
                ksimplex_perm[vertex_ksimplex[edge_a[e]]], k, kfact, binom,
            )
            cb = _local_code(
                face_free[f], face_free[vertex_face[edge_b[e]]], face_fixed[vertex_face[edge_b[e]]],
                ksimplex_perm[vertex_ksimplex[edge_b[e]]], k, kfact, binom,
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
                            ksimplex_perm[vertex_ksimplex[v]], k, kfact, binom,
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
                        non_ball[n_non_ball, 0] = ci - lo
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
        used_v += nv
        used_e += ne
        used_c += n_cells
        used_i += n_incidences
    return (
        _records_upto(vk_out, vp_out, e_out, c_out, i_out, used_v, used_e, used_c, used_i), crossed_facets, degenerate,
        non_ball[:n_non_ball].copy(),
    )


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
    template): the same records, bit for bit.  A k-face's Kuhn simplices and, where a walk runs,
    a (k+1)-face's come from `_kuhn_chains`; a vertex carries its permutation's rank itself.
    (No check of joined pieces: `cubes_chunk` has none for n > 7 either.)"""
    n = tables.n
    k = tables.k
    face_start = tables.face_start
    face_free = tables.face_free
    face_fixed = tables.face_fixed
    face_rank = tables.face_rank
    n_subsets = tables.n_subsets
    binom = tables.binom
    n_codes = tables.n_codes
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
    vertex_face = np.empty(16, np.int64)
    vertex_perm = np.empty(16, np.int64)
    vertex_key = np.empty(16, np.int64)
    edge_a = np.empty(16, np.int64)
    edge_b = np.empty(16, np.int64)
    edge_face = np.empty(16, np.int64)
    found_node = np.empty(16, np.int64)
    found_vertex = np.empty(16, np.int64)
    walked = np.empty(16, np.int8)
    node_id = np.empty(64, np.int64)
    node_slot = np.empty(64, np.int64)
    slot_key = np.full(256, -1, np.int64)  # node -> row (a walk through a curved face meets 10^5 nodes)
    slot_node = np.empty(256, np.int64)
    node_crossed = np.empty(64, np.int8)
    next0 = np.empty(64, np.int64)
    next1 = np.empty(64, np.int64)
    parent = np.empty(16, np.int64)
    cell_of_root = np.empty(16, np.int64)
    cells_buf_a = np.empty((64, 3), np.int64)
    cells_buf_b = np.empty((64, 3), np.int64)
    vk_out, vp_out, e_out, c_out, i_out = _new_records(8 * (hi - lo) + 16, n)
    used_v = used_e = used_c = used_i = np.int64(0)
    crossed_facets = np.zeros(hi - lo, np.int64)
    n_corners = 1 << n
    all_signs = (np.int64(1) << k) - 1
    degenerate = 0
    kface0 = face_start[k]
    n_kfaces = face_start[k + 1] - kface0
    k1face0 = face_start[k1]
    n_k1faces = face_start[k1 + 1] - k1face0
    for ci in range(lo, hi):
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
            any_pos = 0
            all_pos = all_signs
            sub_mask = free
            while True:  # the sign prune over the face's corners first: most faces stop here
                p = corner_signs[fixed | sub_mask]
                any_pos |= p
                all_pos &= p
                if sub_mask == 0:
                    break
                sub_mask = (sub_mask - 1) & free
            if any_pos != all_signs or all_pos != 0:
                continue
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
                if nv >= vertex_face.shape[0]:
                    vertex_face = _grown_keys(vertex_face, nv)
                    vertex_perm = _grown_keys(vertex_perm, nv)
                    vertex_key = _grown_keys(vertex_key, nv)
                row = used_v + nv
                if row >= vk_out.shape[0]:
                    vk_out = _grown_keys(vk_out, row)
                    vp_out = _grown_rows(vp_out, row)
                vertex_face[nv] = f
                vertex_perm[nv] = leaf_rank[leaf]
                vertex_key[nv] = (
                    _face_key(g_vertex + corner_vertex[fixed], n_subsets[k], face_rank[f]) * kfact + leaf_rank[leaf]
                )
                vk_out[row] = vertex_key[nv]
                for a in range(n):
                    x = 0.0
                    for i in range(k + 1):
                        x += lam[i] * grid_lines[a, cube_origin[ci, a] + ((chain[0, i] >> a) & 1)]
                    vp_out[row, a] = x
                nv += 1
        facets = np.int64(0)
        for v in range(nv):
            f = vertex_face[v]
            for a in range(n):
                if not (face_free[f] >> a) & 1:
                    facets |= np.int64(1) << (2 * a + ((face_fixed[f] >> a) & 1))
        crossed_facets[ci - lo] = facets
        if nv == 0:
            continue

        # 2. Edges on the (k+1)-faces: two vertices are joined, more by the walk (paper 3.1.1)
        if found_node.shape[0] < nv:
            found_node = np.empty(2 * nv, np.int64)
            found_vertex = np.empty(2 * nv, np.int64)
            walked = np.empty(2 * nv, np.int8)
        ne = 0
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
                g = vertex_face[v]
                if not _face_in_face(face_free[g], face_fixed[g], ff, fx):
                    continue
                dropped = 0
                while axes[dropped] != _lowest_bit(ff & ~face_free[g]):
                    dropped += 1
                side = (face_fixed[g] >> axes[dropped]) & 1
                node = ((k1 - 1 - dropped) * 2 + side) * kfact + vertex_perm[v]
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
                if n_crossed == 2:
                    for pair in range(2):
                        u = node_a if pair == 0 else node_b
                        w = node_b if pair == 0 else node_a
                        if next0[u] < 0:
                            next0[u] = w
                        elif next1[u] < 0:
                            next1[u] = w
                        else:
                            degenerate += 1
                elif n_crossed != 0:
                    degenerate += 1
            for q in range(n_found):
                walked[q] = 0
            for q in range(n_found):
                if walked[q]:
                    continue
                start = _node_index(slot_key, slot_node, found_node[q])
                before = -1
                at = start
                end = -1
                if start >= 0:
                    for _step in range(n_nodes + 1):
                        nxt = next0[at] if next0[at] != before else next1[at]
                        if nxt < 0:
                            break
                        before = at
                        at = nxt
                        if node_id[at] < n_boundary:
                            end = at
                            break
                if end < 0 or end == start:
                    degenerate += 1
                    walked[q] = 1
                    continue
                for q2 in range(n_found):
                    if found_node[q2] == node_id[end]:
                        walked[q2] = 1
                        edge_b[ne] = found_vertex[q2]
                walked[q] = 1
                edge_a[ne] = found_vertex[q]
                edge_face[ne] = f1
                ne += 1
            for i in range(n_nodes):  # the table empty for the next walk
                slot_key[node_slot[i]] = -1

        # 3. Cells (paper 3.1.2), as in `cubes_chunk`
        if parent.shape[0] < nv:
            parent = np.empty(2 * nv, np.int64)
            cell_of_root = np.empty(2 * nv, np.int64)
        if cells_buf_a.shape[0] < 4 * nv or cells_buf_a.shape[0] < ne:
            cells_buf_a = np.empty((4 * nv + ne, 3), np.int64)
            cells_buf_b = np.empty((4 * nv + ne, 3), np.int64)
        lower = cells_buf_a
        cells = cells_buf_b
        for e in range(ne):
            f = edge_face[e]
            ca = _local_code(face_free[f], face_free[vertex_face[edge_a[e]]], face_fixed[vertex_face[edge_a[e]]],
                             vertex_perm[edge_a[e]], k, kfact, binom)
            cb = _local_code(face_free[f], face_free[vertex_face[edge_b[e]]], face_fixed[vertex_face[edge_b[e]]],
                             vertex_perm[edge_b[e]], k, kfact, binom)
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
                for v in range(nv):
                    cell_of_root[v] = -1
                for e in range(ne):
                    if _face_in_face(face_free[edge_face[e]], face_fixed[edge_face[e]], face_free[f], face_fixed[f]):
                        cell_of_root[_find(parent, edge_a[e])] = -2
                if cells.shape[0] < n_here + n_in:
                    cells = _grown_rows(cells, n_here)
                first = n_here
                ff = face_free[f]
                for v in range(nv):
                    if parent[v] >= 0:
                        root = _find(parent, v)
                        code = _local_code(ff, face_free[vertex_face[v]], face_fixed[vertex_face[v]], vertex_perm[v],
                                           k, kfact, binom)
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
        used_v += nv
        used_e += ne
        used_c += n_cells
        used_i += n_incidences
    return (
        _records_upto(vk_out, vp_out, e_out, c_out, i_out, used_v, used_e, used_c, used_i), crossed_facets, degenerate,
        np.zeros((0, 3), np.int64),
    )


@nb.njit(**JIT)
def _lowest_bit(x):
    """Index of x's lowest set bit."""
    a = 0
    while not (x >> a) & 1:
        a += 1
    return a


_cubes_chunk_tables = cubes_chunk


# The runner calls `cubes_chunk`; the numba kernel above keeps that name (compile notices and
# tests/core/test_first_run.py know it by it), and this picks the kernel by the tables it gets.
def cubes_chunk(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex,  # noqa: F811
                tables):
    """GCMH on candidate cubes lo..hi-1: the tables' kernel (`_cubes_chunk_tables`), or
    `cubes_chunk_lazy` where the tables hold no Kuhn simplices (`_tables.lazy_tables`)."""
    kernel = cubes_chunk_lazy if tables.ksimplex_corners.shape[0] == 0 else _cubes_chunk_tables
    return kernel(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex, tables)


# ----------------------------------------------------------------------------- simplicial baselines (CMS, CCS)
# Marching simplices over the CFK triangulation (paper Section 4): every simplex of
# dimension d = r + k of the cube's triangulation that M_A crosses is one r-cell (the
# zero set of a linear map on a simplex is one convex polytope).  A vertex is a
# crossed k-simplex; an edge joins the two crossed k-facets of a (k+1)-simplex; an
# r-cell's faces are its crossed facets.  Keys are the simplices' own keys (see
# `_tables.SimplexTables`), so records merge with the same assembly as GCMH's.


@nb.njit(**INLINE_JIT)
def _simplex_key(g_vertex, corner_vertex, simplex_c0, simplex_code, key_base, s):
    return (g_vertex + corner_vertex[simplex_c0[s]]) * key_base + simplex_code[s]


@nb.njit(**JIT)
def simplices_chunk(lo, hi, values, cube_row, cube_origin, cube_vertex, grid_lines, corner_row, corner_vertex, tables):
    """`cubes_chunk`'s twin for the simplicial baselines: same inputs (but tables is a
    `_tables.SimplexTables`), same records.

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
            # the sign prune, written out as in cubes_chunk
            if masked:
                m = simplex_corner_mask[s]
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
                    p = corner_signs[simplex_corners[s, i]]
                    any_pos |= p
                    all_pos &= p
                if any_pos != all_signs or all_pos != 0:
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
                    nf += crossed[simplex_facets[s, j]]
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
                        if crossed[f]:
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
                    if crossed[f]:
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


@nb.njit(**JIT)
def cube_euler_chunk(lo, hi, values, cube_row, corner_row, tables, carrier, n_faces, face_dim, coface_start,
                     cofaces):
    """The Euler characteristic of M_A in each open face of each cube lo..hi-1 by CMS's count
    (paper Section 4): each crossed Kuhn simplex of dimension k + r is an r-cell, a convex
    polytope, counted (-1)^r in the face whose relative interior holds it (carrier[s], a
    `CubeTables` face row; n_faces rows of dimension face_dim).  GCMH's cells in the same face
    count the same when they are all balls (`runner.Grid.check_cells` compares the two).

    Also the hidden pieces: the pieces of M_A inside an open face (of dimension > k) that reach
    none of its lower faces, counted in that face (a closed loop inside a (k+1)-face, a closed
    surface inside a (k+2)-face).  GCMH has no vertex on them (paper 3.1), so it has none of
    their cells, and a loop's Euler characteristic is 0: the count alone can't see it, and a
    neighbour across the face would not know that a refined cube emits it.  The pieces are found
    on the vertices and edges alone (the cells are convex: a piece's 1-skeleton is connected):
    two vertices inside a face are in one piece when an edge with that carrier joins them, and a
    piece reaches a lower face when such an edge has its other end there.

    tables: `_tables.SimplexTables`; cofaces[coface_start[s]:coface_start[s + 1]]: the simplices
    that have s as a facet.  (No records and no positions: a simplex of dimension > k is crossed
    when one of its facets is, as in `simplices_chunk`, which also counts a polytope with too few
    facets; so the crossed simplices of each dimension are the cofaces of the crossed ones below,
    and only those are visited.)  Returns (euler, hidden), each (hi - lo, n_faces).
    """
    n = tables.n
    k = tables.k
    start = tables.start
    corners = tables.corners
    facets = tables.facets
    crossed = np.empty(start[k + 1], np.int64)  # the k-simplices' (above k: the cofaces walked, `seen`)
    parent = np.empty(start[k + 1], np.int64)  # pieces in one open face (union-find over crossed k-simplices)
    reaches = np.empty(start[k + 1], np.bool_)  # the piece reaches a lower face (at its root)
    listed = np.empty(start[k + 1], np.int64)  # the crossed k-simplices inside faces of dimension > k
    corner_signs = np.empty(1 << n, np.int64)
    mat = np.empty((k, k), np.float64)
    rhs = np.empty(k, np.float64)
    lam = np.empty(k + 1, np.float64)
    all_signs = (np.int64(1) << k) - 1
    corner_mask = tables.corner_mask
    masked = corner_mask.shape[0] > 0  # corner sets as bit masks (n <= 6): a simplex's signs at once
    positive_corners = np.zeros(k, np.int64)
    out = np.zeros((hi - lo, n_faces), np.int64)
    hidden = np.zeros((hi - lo, n_faces), np.int64)
    front = np.empty(start[n + 1], np.int64)  # the crossed simplices of one dimension
    following = np.empty(start[n + 1], np.int64)  # and of the next
    seen = np.zeros(start[n + 1], np.int64)  # the cube (ci + 1) that last listed a simplex
    for ci in range(lo, hi):
        o = cube_row[ci]
        for j in range(k):
            positive_corners[j] = 0
        for c in range(1 << n):
            p = np.int64(0)
            for j in range(k):
                if values[o + corner_row[c], j] >= 0.0:
                    p |= np.int64(1) << j
                    positive_corners[j] |= np.int64(1) << c
            corner_signs[c] = p
        n_listed = 0
        n_front = 0
        for s in range(start[k], start[k + 1]):
            crossed[s] = 0
            if masked:  # a simplex on which some F_j has one sign holds no zero
                m = corner_mask[s]
                out_of = False
                for j in range(k):
                    on = positive_corners[j] & m
                    if on == 0 or on == m:
                        out_of = True
                        break
                if out_of:
                    continue
            hit = _simplex_crosses_call(values, o, corner_row, corners, s, k, corner_signs, all_signs, mat, rhs, lam)
            if hit == 2:
                hit = _zero_side(values, o, corner_row, corners, s, k, lam)
            if hit:
                crossed[s] = 1
                out[ci - lo, carrier[s]] += 1
                parent[s] = s
                reaches[s] = False
                if face_dim[carrier[s]] > k:
                    listed[n_listed] = s
                    n_listed += 1
                front[n_front] = s
                n_front += 1
        stamp = ci + 1
        for d in range(k + 1, n + 1):
            sign = 1 if (d - k) % 2 == 0 else -1
            n_next = 0
            for i in range(n_front):
                f = front[i]
                for q in range(coface_start[f], coface_start[f + 1]):
                    s = cofaces[q]
                    if seen[s] == stamp:
                        continue
                    seen[s] = stamp
                    following[n_next] = s
                    n_next += 1
                    out[ci - lo, carrier[s]] += sign
                    if d > k + 1:
                        continue
                    # an edge: its crossed ends inside its face are one piece, which reaches a lower
                    # face when an end lies there
                    root = -1
                    outside = False
                    for j in range(d + 1):
                        g = facets[s, j]
                        if not crossed[g]:
                            continue
                        if carrier[g] != carrier[s]:
                            outside = True
                        elif root < 0:
                            root = _find(parent, g)
                        else:
                            b = _find(parent, g)
                            if b != root:
                                parent[b] = root
                                reaches[root] = reaches[root] or reaches[b]
                    if outside and root >= 0:
                        reaches[root] = True
            front, following = following, front
            n_front = n_next
        for i in range(n_listed):
            s = listed[i]
            if parent[s] == s and not reaches[s]:
                hidden[ci - lo, carrier[s]] += 1
    return out, hidden


@nb.njit(**JIT)
def records_cube_euler(keys, offsets, cube_keys, strides, dims, n_codes, n_subsets, free_of_rank, face_row, k):
    """The Euler characteristic of GCMH's cells in each open face of each cube of a kernel run:
    every vertex, edge and cell of the run's records (keys[offsets[r]:offsets[r + 1]]: the
    r-cells' keys, repeats allowed) counted (-1)^r once in each of the run's cubes (cube_keys:
    their origins' grid vertices) that holds its face, in that face's row (face_row[free, fixed]:
    the `CubeTables` row).  A cube writes every cell of its faces, so the run's records hold all
    of them.  `cube_euler_chunk`'s count where every cell is a ball.  Returns (m, faces)."""
    n = strides.shape[0]
    order = np.argsort(cube_keys)
    sorted_keys = cube_keys[order]
    m = sorted_keys.shape[0]
    chi = np.zeros((m, face_row.max() + 1), np.int64)
    multi = np.empty(n, np.int64)
    for r in range(offsets.shape[0] - 1):
        dim = r + k
        here = np.sort(keys[offsets[r] : offsets[r + 1]])
        sign = 1 if r % 2 == 0 else -1
        for i in range(here.shape[0]):
            if i > 0 and here[i] == here[i - 1]:
                continue
            face_key = here[i] // n_codes[dim]
            anchor = face_key // n_subsets[dim]
            free = free_of_rank[dim, face_key % n_subsets[dim]]
            for a in range(n):
                multi[a] = (anchor // strides[a]) % dims[a]
            for step in range(1 << n):  # the cubes below the face's anchor along its fixed axes
                if step & free:
                    continue
                key = anchor
                for a in range(n):
                    if (step >> a) & 1:
                        if multi[a] == 0:
                            key = -1
                            break
                        key -= strides[a]
                if key < 0:
                    continue
                j = np.searchsorted(sorted_keys, key)
                if j < m and sorted_keys[j] == key:  # in that cube the face is fixed at 1 along `step`
                    chi[order[j], face_row[free, step]] += sign
    return chi


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
