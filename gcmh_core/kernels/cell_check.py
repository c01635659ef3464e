"""The cell check: the Euler characteristic of M_A in each open face of a cube, by CMS's count and
by GCMH's records (`runner.Grid.check_cells`)."""

import numba as nb
import numpy as np

from .._config import JIT
from .cells import _find
from .solve import _simplex_crosses_call, _zero_side, crossable_mask


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

    tables: `tables.SimplexTables`; cofaces[coface_start[s]:coface_start[s + 1]]: the simplices
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
            if masked and not crossable_mask(positive_corners, corner_mask[s], k):
                continue  # a simplex on which some F_j has one sign holds no zero
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
                        if g < 0 or not crossed[g]:  # (-1: left out of a cube's own table: not crossed)
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
    # the grid vertices that anchor a face of some checked cube (its origin plus a corner's offset):
    # only the records whose face has such an anchor are sorted and counted (the checked cubes are
    # few where the certificate vouches for the rest; a sort of all of a run's keys was most of the cost)
    near = np.empty(m << n, np.int64)
    for i in range(m):
        for step in range(1 << n):
            key = sorted_keys[i]
            for a in range(n):
                if (step >> a) & 1:
                    key += strides[a]
            near[(i << n) + step] = key
    near = np.unique(near)
    for r in range(offsets.shape[0] - 1):
        dim = r + k
        mine = keys[offsets[r] : offsets[r + 1]]
        keep = np.zeros(mine.shape[0], np.bool_)
        for i in range(mine.shape[0]):
            anchor = mine[i] // n_codes[dim] // n_subsets[dim]
            j = np.searchsorted(near, anchor)
            keep[i] = j < near.shape[0] and near[j] == anchor
        here = np.sort(mine[keep])
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


@nb.njit(**JIT)
def graph_certified_chunk(values, cube_row, corner_row, k, subsets):
    """For each cube i: whether its piece of M_A is, for sure, a graph over a face of the cube
    (`runner.graph_certified` says why that holds).  The interval matrix A (k, n): column a is
    the hull of F(c + e_a) - F(c) over the cube's edges along a; the cube is certified when for
    one row of subsets (k axes S) A_S is regular: with P the inverse of its midpoint,
    max_i sum_j |I - P mid|_ij + (|P| rad)_ij < 1.  A non-finite value certifies nothing.

    values (NV, k); corner c of cube i is row cube_row[i] + corner_row[c]; subsets (S, k) int64.
    Returns (m,) bool.
    """
    n = 0
    while (1 << n) < corner_row.shape[0]:
        n += 1
    m = cube_row.shape[0]
    out = np.zeros(m, np.bool_)
    lo = np.empty((k, n), np.float64)
    hi = np.empty((k, n), np.float64)
    mid = np.empty((k, k), np.float64)
    rad = np.empty((k, k), np.float64)
    aug = np.empty((k, 2 * k), np.float64)
    here = np.empty((1 << n, k), np.float64)
    have = np.zeros(n, np.bool_)
    n_subsets = subsets.shape[0]
    last = 0
    for i in range(m):
        o = cube_row[i]
        finite = True
        for c in range(1 << n):  # (the corners' values once, then the differences from them)
            for j in range(k):
                x = values[o + corner_row[c], j]
                finite = finite and np.isfinite(x)
                here[c, j] = x
        if not finite:
            continue
        have[:] = False  # (a column's hull when a subset asks for it: a certified cube needs only k of n)
        for step in range(n_subsets):
            q = (last + step) % n_subsets  # (neighbouring cubes: the axes that served the last one first)
            for s in range(k):
                a = subsets[q, s]
                if have[a]:
                    continue
                have[a] = True
                bit = 1 << a
                for j in range(k):
                    low = np.inf
                    high = -np.inf
                    for c in range(1 << n):
                        if c & bit:
                            continue
                        d = here[c | bit, j] - here[c, j]
                        low = min(low, d)  # (branch-free: the differences' signs are random on noise)
                        high = max(high, d)
                    lo[j, a] = low
                    hi[j, a] = high
            for r in range(k):
                for s in range(k):
                    a = subsets[q, s]
                    mid[r, s] = 0.5 * (lo[r, a] + hi[r, a])
                    rad[r, s] = 0.5 * (hi[r, a] - lo[r, a])
                    aug[r, s] = mid[r, s]
                    aug[r, k + s] = 1.0 if r == s else 0.0
            # P = mid^-1 by Gauss-Jordan with partial pivoting; a pivot below 1e-12 of its row's
            # scale: mid is (nearly) singular, no certificate from these axes
            usable = True
            for col in range(k):
                best = col
                for r in range(col + 1, k):
                    if abs(aug[r, col]) > abs(aug[best, col]):
                        best = r
                scale = 0.0
                for s in range(k):
                    scale = max(scale, abs(aug[best, s]))
                if not abs(aug[best, col]) > 1e-12 * scale:
                    usable = False
                    break
                if best != col:
                    for s in range(2 * k):
                        aug[col, s], aug[best, s] = aug[best, s], aug[col, s]
                piv = aug[col, col]
                for s in range(2 * k):
                    aug[col, s] /= piv
                for r in range(k):
                    if r != col:
                        f = aug[r, col]
                        if f != 0.0:
                            for s in range(2 * k):
                                aug[r, s] -= f * aug[col, s]
            if not usable:
                continue
            worst = 0.0
            for r in range(k):
                row = 0.0
                for s in range(k):
                    pm = 0.0
                    pr = 0.0
                    for t in range(k):
                        p = aug[r, k + t]
                        pm += p * mid[t, s]
                        pr += abs(p) * rad[t, s]
                    row += abs((1.0 if r == s else 0.0) - pm) + pr
                worst = max(worst, row)
            if worst < 1.0:
                out[i] = True
                last = q
                break
    return out


@nb.njit(**JIT)
def _mix64(x):
    """splitmix64's finaliser: a uint64 to a well-spread uint64."""
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


@nb.njit(**JIT)
def same_faces_candidates(offsets, faces):
    """The cells of a CSR (offsets, faces) that may have the same set of faces as another cell: a hash
    per cell that no order of its faces changes (a wrapping sum of the faces' mixed ids), and a table
    of the hashes seen (open addressing).  Cells with the same faces are always marked, others only
    on a 64-bit collision: `_balls._same_faces` compares the marked ones exactly.  One pass, no sort
    (every run pays it on every cell of every dimension: a sort of a sphere's 190,000 hashes took as
    long as a tenth of its run)."""
    m = len(offsets) - 1
    h = np.empty(m, np.uint64)
    for i in range(m):
        s = _mix64(np.uint64(offsets[i + 1] - offsets[i]))
        for j in range(offsets[i], offsets[i + 1]):
            s += _mix64(np.uint64(faces[j]) + np.uint64(0x9E3779B97F4A7C15))
        h[i] = s
    size = 2
    while size < 2 * m:
        size *= 2
    mask = np.uint64(size - 1)
    table = np.full(size, -1, np.int64)
    out = np.zeros(m, np.bool_)
    for i in range(m):
        slot = np.int64(h[i] & mask)
        while True:
            j = table[slot]
            if j < 0:
                table[slot] = i
                break
            if h[j] == h[i]:
                out[i] = True
                out[j] = True
                break
            slot = (slot + 1) & (size - 1)
    return out
