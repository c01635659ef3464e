"""GCMH for n = 3, k = 1 in one pass over the grid's layers: the Combinatorial Marching
Cubes case of the paper (Section 3 with n = 3, k = 1), written like a marching-cubes code.

For k = 1 a k-simplex is a grid edge and it is crossed exactly when F changes sign
along it (a value 0 counts as positive), so everything the general kernel
(`gcmh.cubes_chunk`) finds in a cube but the vertices' positions is fixed by its
8 corner signs: the vertex of M_A on each crossed edge, the edges of M_A on each
square (the walk of Section 3.1.1 pairs four crossings), the 2-cells (pieces of G_H
in the cube, Section 3.1.2) and the pieces M_A joins through the cube (`non_ball_cells`).
`cube_cases` derives these tables once from the general kernel's own `tables.CubeTables`,
by the same steps run on signs instead of values.

`march_layers` then walks the grid layer by layer along axis 0 and writes the complex
directly in the general path's order: vertices keyed (grid vertex, axis), edges
(square's anchor, its axes, smallest local code), 2-cells (cube, smallest code), so the
ids are assigned in key order as things are found: no hashing, no sort, no assembly.
A layer t arrives with F's values; then, lagging behind it,
  S(t)   signs of layer t, and per row (fixed t, j) whether it is all >= 0, all < 0 or mixed;
  V(t-1) the vertices on the edges starting in layer t-1 (positions from F's values);
  E(t-2) the edges of M_A on the squares anchored in layer t-2 (they need V(t-1));
  C(t-3) the 2-cells of the cubes in layer t-3 (they need E(t-2)).
A layer's signs are kept as bit rows (64 grid vertices a word), so the crossed edges,
squares and cubes of a row are found 64 at a time by bitwise operations; rows whose
neighbourhood has one sign throughout are skipped whole (flying edges' trick).

The result is the general path's complex bit for bit (tests/core/test_marching3.py):
the positions are computed by the same arithmetic as `solve.simplex_crosses` for k = 1.
Where that arithmetic could differ from a pure sign test (a value that is not finite,
or a difference F(b) - F(a) that overflows) the pass stops and says so; the caller
then runs the general path.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numba as nb
import numpy as np
from numba.cpython.unsafe.numbers import trailing_zeros as _trailing_zeros

from .._config import INLINE_JIT, JIT
from .tables import cube_tables

# an intrinsic, called from compiled code with one argument (its type stub also lists the typing context)
trailing_zeros: Any = _trailing_zeros

__all__ = ["cube_cases", "march_layers", "room_per_layer", "OK", "NOT_FINITE", "OVERFLOW"]

# march_layers' status
OK, NOT_FINITE, OVERFLOW = 0, 1, 2


# ----------------------------------------------------------------------------- the tables
def _local_code(f_free: int, g_free: int, g_fixed: int) -> int:
    """`cells._local_code` for k = 1 (perm 0, kfact 1)."""
    pos = rank = bits = j = 0
    for a in range(3):
        if f_free >> a & 1:
            if g_free >> a & 1:
                rank += pos  # binom[pos, 1]
            else:
                bits |= (g_fixed >> a & 1) << j
                j += 1
            pos += 1
    return rank * (1 << j) + bits


def _square_edges(tab, kf1: int, positive) -> list[tuple[int, int]]:
    """The edges of M_A on the cube's square kf1 (its (k+1)-face), as pairs of cube
    edges (k-simplices), in the order `cubes_chunk` emits them; positive[c]: F >= 0
    at cube corner c.  The same steps as the kernel's, on signs."""
    crossed = [positive[a] != positive[b] for a, b in tab.ksimplex_corners.tolist()]
    n_boundary = tab.walk_boundary_nodes
    wbs = tab.walk_boundary_simplex[kf1].tolist()
    cmap = tab.walk_corner_map[kf1].tolist()
    found = [b for b in range(n_boundary) if crossed[wbs[b]]]
    if len(found) == 0:
        return []
    if len(found) == 2:
        return [(wbs[found[0]], wbs[found[1]])]
    interior = tab.walk_interior_corners.tolist()
    links: dict[int, list[int]] = {}
    for corners, nodes in zip(tab.walk_simplex_corners.tolist(), tab.walk_simplex_nodes.tolist()):
        signs = {positive[cmap[c]] for c in corners}
        if len(signs) != 2:
            continue
        hit = []
        for node in nodes:
            if node < n_boundary:
                if crossed[wbs[node]]:
                    hit.append(node)
            else:
                a, b = interior[node - n_boundary]
                if positive[cmap[a]] != positive[cmap[b]]:
                    hit.append(node)
        if len(hit) != 2:
            raise AssertionError("a triangle with a sign change crosses two of its edges")
        for u, w in (hit, hit[::-1]):
            links.setdefault(u, []).append(w)
            if len(links[u]) > 2:
                raise AssertionError("a node of the walk is linked thrice")
    edges: list = []
    walked: set = set()
    for start in found:
        if start in walked:
            continue
        before, at, end = -1, start, -1
        for _ in range(len(links) + 2):
            nxt = [w for w in links.get(at, []) if w != before]
            if not nxt:
                break
            before, at = at, nxt[0]
            if at < n_boundary:
                end = at
                break
        if end < 0 or end == start:
            raise AssertionError("the walk ends where it started")
        walked.update((start, end))
        edges.append((wbs[start], wbs[end]))
    return edges


def _joined(tab, positive, pieces_vertices) -> int:
    """`cells._joined_pieces` for the whole cube, on signs: the pieces of G_H minus the
    pieces of M_A (marched over the cube's CFK triangulation) that hold them."""
    kuhn = tab.kuhn
    corners, facets, start = kuhn.corners, kuhn.facets, kuhn.start
    parent: dict = {}

    def find(s):
        while parent[s] != s:
            s = parent[s]
        return s

    for d in range(1, 4):
        for s in range(start[d], start[d + 1]):
            if d == 1:
                if positive[corners[s, 0]] != positive[corners[s, 1]]:
                    parent[s] = s
                continue
            for j in range(d + 1):
                t = int(facets[s, j])
                if t in parent:
                    parent.setdefault(s, s)
                    ra, rb = find(s), find(t)
                    if ra != rb:
                        parent[rb] = ra
    roots = [find(int(tab.ksimplex_kuhn[vs[0]])) for vs in pieces_vertices]
    return len(roots) - len(set(roots))


class Cases:
    """The 256 sign cases of a cube and the 16 of each square, as arrays for `march_layers`.

    A corner c is a bit mask (bit a: +1 along axis a); a square's rank q is that of its
    free axes (0: axes 0 and 1, 1: axes 0 and 2, 2: axes 1 and 2), as in `tables`.

    square_edges[q, case, slot, 0 or 1]: the grid edges (corner << 2 | axis, the corner
      relative to the square's anchor) joined by the edge `slot` of M_A in that square,
      slots in the order of their keys; square_count[q, case] of them.
    cube_pieces[case]: the number of 2-cells; cube_nonball[case]: the pieces of G_H that
      M_A joins through the cube.  piece_start[case, p]: the piece p's rows in piece_face
      (pieces in the order of their keys), each row an edge of M_A as
      (anchor corner << 3 | q << 1 | slot), rows in the order of the edges' keys.
    """

    def __init__(self):
        tab = cube_tables(3, 1)
        self.tab = tab
        face0 = int(tab.face_start[2])
        free = tab.face_free.tolist()
        fixed = tab.face_fixed.tolist()
        rank = tab.face_rank.tolist()
        ks = tab.ksimplex_corners.tolist()

        def grid_edge(s, anchor):  # cube edge s relative to a square anchored at corner `anchor`
            c0, c1 = ks[s]
            return ((c0 & ~anchor) << 2) | (c0 ^ c1).bit_length() - 1

        def edge_code(s, f):
            c0, c1 = ks[s]
            return _local_code(free[f], c0 ^ c1, c0)

        def square(kf1, positive):
            """The square's edges of M_A, sorted by key (smallest local code): (code, a, b)."""
            f = face0 + kf1
            out = [(min(edge_code(a, f), edge_code(b, f)), a, b) for a, b in _square_edges(tab, kf1, positive)]
            return sorted(out)

        self.square_edges = np.zeros((3, 16, 2, 2), np.int64)
        self.square_count = np.zeros((3, 16), np.int64)
        for kf1 in range(6):
            f = face0 + kf1
            if fixed[f] != 0:
                continue
            q = rank[f]
            cmap = tab.walk_corner_map[kf1].tolist()
            for case in range(16):
                positive = [False] * 8
                for local in range(4):
                    positive[cmap[local]] = bool(case >> local & 1)
                edges = square(kf1, positive)
                self.square_count[q, case] = len(edges)
                for slot, (_, a, b) in enumerate(edges):
                    self.square_edges[q, case, slot] = grid_edge(a, 0), grid_edge(b, 0)
        # each square of the cube: its anchor corner, rank, and local corners (for its case)
        self.square_anchor = np.array([fixed[face0 + kf1] for kf1 in range(6)], np.int64)
        self.square_rank = np.array([rank[face0 + kf1] for kf1 in range(6)], np.int64)
        self.square_corners = tab.walk_corner_map.copy()

        def order(anchor, q, slot):  # the edge's key order within a cube: anchor's grid index first
            lin = (anchor & 1) * 4 + (anchor >> 1 & 1) * 2 + (anchor >> 2 & 1)
            return (lin * 3 + q) * 2 + slot

        self.cube_pieces = np.zeros(256, np.int64)
        self.cube_nonball = np.zeros(256, np.int64)
        self.piece_start = np.zeros((256, 5), np.int64)
        faces: list = []
        for case in range(256):
            positive = [bool(case >> c & 1) for c in range(8)]
            crossed = [s for s in range(12) if positive[ks[s][0]] != positive[ks[s][1]]]
            parent = {s: s for s in crossed}

            def find(s, parent=parent):
                while parent[s] != s:
                    s = parent[s]
                return s

            cube_edges = []
            for kf1 in range(6):
                for slot, (_, a, b) in enumerate(square(kf1, positive)):
                    cube_edges.append((a, b, order(self.square_anchor[kf1], self.square_rank[kf1], slot)))
                    ra, rb = find(a), find(b)
                    if ra != rb:
                        parent[max(ra, rb)] = min(ra, rb)
            pieces: dict[int, list[int]] = {}
            for s in crossed:
                pieces.setdefault(find(s), []).append(s)
            cube_code = [edge_code(s, face0 + 6) for s in range(12)]  # codes in the cube itself
            by_key = sorted(pieces.values(), key=lambda vs: min(cube_code[s] for s in vs))
            self.cube_pieces[case] = len(by_key)
            if len(by_key) >= 2:  # in root order, as the kernel lists them
                self.cube_nonball[case] = _joined(tab, positive, sorted(pieces.values(), key=min))
            for p, vs in enumerate(by_key):
                self.piece_start[case, p] = len(faces)
                rows = sorted(key for a, _, key in cube_edges if find(a) == find(vs[0]))
                for key in rows:
                    slot, rest = key % 2, key // 2
                    q, lin = rest % 3, rest // 3
                    anchor = (lin >> 2 & 1) | (lin >> 1 & 1) << 1 | (lin & 1) << 2
                    faces.append(anchor << 3 | q << 1 | slot)
            for p in range(len(by_key), 5):
                self.piece_start[case, p] = len(faces)
        self.piece_face = np.array(faces, np.int64)


@lru_cache(maxsize=1)
def cube_cases() -> Cases:
    return Cases()


# ----------------------------------------------------------------------------- the pass
_BIG = 1.7976931348623157e308  # the largest float64: |v| <= _BIG is False for NaN and inf


@nb.njit(**JIT)
def _signs(x, bits, rowc):
    """S(t): F's signs on layer x (d1, d2) as bit rows, bits (d1, W) uint64 (bit col of row j:
    F >= 0 at (j, col); bits past d2 are 0), and each row's class; False if a value is not finite."""
    d1, d2 = x.shape
    words = bits.shape[1]
    full = d2 // 64
    tail = d2 - 64 * full
    tail_mask = (np.uint64(1) << np.uint64(tail)) - np.uint64(1)
    finite = True
    for j in range(d1):
        ok = True
        any_pos = np.uint64(0)
        all_pos = ~np.uint64(0)
        for w in range(full):
            word = np.uint64(0)
            for b in range(64):
                v = x[j, 64 * w + b]
                ok &= abs(v) <= _BIG
                word |= np.uint64(1 if v >= 0.0 else 0) << np.uint64(b)
            bits[j, w] = word
            any_pos |= word
            all_pos &= word
        if tail:
            word = np.uint64(0)
            for b in range(tail):
                v = x[j, 64 * full + b]
                ok &= abs(v) <= _BIG
                word |= np.uint64(1 if v >= 0.0 else 0) << np.uint64(b)
            bits[j, full] = word
            any_pos |= word
            all_pos &= word | ~tail_mask
        for w in range(full + (1 if tail else 0), words):
            bits[j, w] = 0
        finite &= ok
        rowc[j] = 1 if all_pos == ~np.uint64(0) else (0 if any_pos == 0 else 2)
    return finite


@nb.njit(**INLINE_JIT)
def _quiet(c00, c01, c10, c11):
    """Four row classes (rows outside the grid given as a copy of c00): all of one sign."""
    return c00 != 2 and c01 == c00 and c10 == c00 and c11 == c00


@nb.njit(**INLINE_JIT)
def _up(x, x_next):
    """A word of a bit row shifted down by one (bit col: the row's bit col + 1), from the word
    and the next one (the helpers take words, not rows: see `_config`)."""
    return (x >> np.uint64(1)) | (x_next << np.uint64(63))


@nb.njit(**INLINE_JIT)
def _at(x, x_next, b):
    """Bits b and b + 1 of a bit row, from its word x that holds bit b (b <= 63) and the next word."""
    lo = (x >> np.uint64(b)) & np.uint64(1)
    hi = ((x >> np.uint64(b + 1)) & np.uint64(1)) if b < 63 else (x_next & np.uint64(1))
    return lo, hi


@nb.njit(**INLINE_JIT)
def _lam(f0, f1):
    """`simplex_crosses`' arithmetic for k = 1 on an edge with values f0, f1 of opposite
    signs: (lam0, lam1) from the 1 x 1 solve, or (-1, -1) where that arithmetic would
    not find the crossing (an overflow)."""
    m = f1 - f0
    scale = abs(m)
    if not (scale * (1.0 / scale) > 1e-14):  # (the solve's pivot test: fails for an infinite m)
        return -1.0, -1.0
    lam1 = -f0 / m
    lam0 = 1.0 - (0.0 + lam1)
    if not (lam0 >= 0.0 and lam1 >= 0.0):
        return -1.0, -1.0
    return lam0, lam1


@nb.njit(**INLINE_JIT)
def _mix(lam0, lam1, g0, g1):
    """A coordinate of the vertex: the sum over the simplex's corners, as the kernel adds it."""
    x = 0.0
    x += lam0 * g0
    x += lam1 * g1
    return x


@nb.njit(**JIT)
def _vstep(values, base, u, d0, lines, sg, rowc, vid, vert, counts, valid, valid2):
    """V(u): the vertices on the edges that start in layer u, in key order (grid vertex, axis).
    valid, valid2: per word, the bits col < d2 and col < d2 - 1."""
    if u < 0 or u >= d0:
        return
    d1 = sg.shape[1]
    words = sg.shape[2]
    top = u + 1 < d0
    s0 = u % 4
    s1 = (u + 1) % 4 if top else s0
    ids = u % 3
    nv = counts[0]
    zero = np.uint64(0)
    for j in range(d1):
        jb = j + 1 if j + 1 < d1 else j
        if _quiet(rowc[s0, j], rowc[s0, jb], rowc[s1, j], rowc[s1, jb]):
            continue
        for w in range(words):
            a = sg[s0, j, w]
            a_next = sg[s0, j, w + 1] if w + 1 < words else zero
            m0 = (a ^ sg[s1, j, w]) & valid[w]
            m1 = (a ^ sg[s0, jb, w]) & valid[w]
            m2 = (a ^ _up(a, a_next)) & valid2[w]
            m = m0 | m1 | m2
            while m != zero:
                b = trailing_zeros(m)
                m &= m - np.uint64(1)
                col = 64 * w + b
                f0 = values[u - base, j, col]
                x0 = lines[0, u]
                y0 = lines[1, j]
                z0 = lines[2, col]
                for axis in range(3):
                    ma = m0 if axis == 0 else (m1 if axis == 1 else m2)
                    if not ((ma >> np.uint64(b)) & np.uint64(1)):
                        continue
                    if axis == 0:
                        f1 = values[u + 1 - base, j, col]
                    elif axis == 1:
                        f1 = values[u - base, j + 1, col]
                    else:
                        f1 = values[u - base, j, col + 1]
                    lam0, lam1 = _lam(f0, f1)
                    if lam0 < 0.0:
                        counts[6] = 2
                        return
                    vert[nv, 0] = _mix(lam0, lam1, x0, lines[0, u + 1] if axis == 0 else x0)
                    vert[nv, 1] = _mix(lam0, lam1, y0, lines[1, j + 1] if axis == 1 else y0)
                    vert[nv, 2] = _mix(lam0, lam1, z0, lines[2, col + 1] if axis == 2 else z0)
                    vid[ids, j, col, axis] = nv
                    nv += 1
    counts[0] = nv


@nb.njit(**JIT)
def _estep(u, d0, sg, rowc, vid, eid, edges, counts, square_edges, square_count, valid, valid2):
    """E(u): the edges of M_A on the squares anchored in layer u, in key order (anchor,
    rank of the square's axes, slot)."""
    if u < 0 or u >= d0:
        return
    d1 = sg.shape[1]
    words = sg.shape[2]
    top = u + 1 < d0
    s0 = u % 4
    s1 = (u + 1) % 4 if top else s0
    ids = u % 3
    ne = counts[1]
    zero = np.uint64(0)
    for j in range(d1):
        side = j + 1 < d1
        jb = j + 1 if side else j
        if _quiet(rowc[s0, j], rowc[s0, jb], rowc[s1, j], rowc[s1, jb]):
            continue
        for w in range(words):
            # the rows A (u, j), B (u, j+1), C (u+1, j), D (u+1, j+1): words w and w + 1
            a = sg[s0, j, w]
            bb = sg[s0, jb, w]
            c = sg[s1, j, w]
            d = sg[s1, jb, w]
            if w + 1 < words:
                an = sg[s0, j, w + 1]
                bn = sg[s0, jb, w + 1]
                cn = sg[s1, j, w + 1]
            else:
                an = bn = cn = zero
            # a square is crossed where its corners have both signs
            m0 = ((a | bb | c | d) & ~(a & bb & c & d)) & valid[w] if top and side else zero
            a1 = _up(a, an)
            m1 = zero
            if top:
                c1 = _up(c, cn)
                m1 = ((a | c | a1 | c1) & ~(a & c & a1 & c1)) & valid2[w]
            m2 = zero
            if side:
                b1 = _up(bb, bn)
                m2 = ((a | bb | a1 | b1) & ~(a & bb & a1 & b1)) & valid2[w]
            m = m0 | m1 | m2
            while m != zero:
                b = trailing_zeros(m)
                m &= m - np.uint64(1)
                col = 64 * w + b
                pa, pa1 = _at(a, an, b)
                pb, pb1 = _at(bb, bn, b)
                pc, pc1 = _at(c, cn, b)
                pd = (d >> np.uint64(b)) & np.uint64(1)
                for q in range(3):
                    if q == 0:
                        if not ((m0 >> np.uint64(b)) & np.uint64(1)):
                            continue
                        case = pa | pc << np.uint64(1) | pb << np.uint64(2) | pd << np.uint64(3)
                    elif q == 1:
                        if not ((m1 >> np.uint64(b)) & np.uint64(1)):
                            continue
                        case = pa | pc << np.uint64(1) | pa1 << np.uint64(2) | pc1 << np.uint64(3)
                    else:
                        if not ((m2 >> np.uint64(b)) & np.uint64(1)):
                            continue
                        case = pa | pb << np.uint64(1) | pa1 << np.uint64(2) | pb1 << np.uint64(3)
                    ci = np.int64(case)
                    for slot in range(square_count[q, ci]):
                        for end in range(2):
                            g = square_edges[q, ci, slot, end]
                            corner = g >> 2
                            edges[ne, end] = vid[(u + (corner & 1)) % 3, j + (corner >> 1 & 1), col + (corner >> 2 & 1),
                                                 g & 3]
                        eid[ids, j, col, q, slot] = ne
                        ne += 1
    counts[1] = ne


@nb.njit(**JIT)
def _cstep(u, d0, sg, rowc, eid, offsets, faces, counts, cube_pieces, cube_nonball, piece_start, face_place,
           valid2):
    """C(u): the 2-cells of the cubes in layer u, in key order (cube, smallest code), each
    with its edges in id order.  face_place[u % 3, r]: the place of the edge piece_face[r]
    in eid (flat) relative to the cube's anchor (see march_layers)."""
    if u < 0 or u >= d0 - 1:
        return
    d1 = sg.shape[1]
    words = sg.shape[2]
    s0 = u % 4
    s1 = (u + 1) % 4
    d2 = eid.shape[2]
    nc = counts[2]
    nf = counts[3]
    candidates = 0
    nonball = 0
    zero = np.uint64(0)
    flat = eid.reshape(-1)
    face_at = face_place[u % 3]
    for j in range(d1 - 1):
        if _quiet(rowc[s0, j], rowc[s0, j + 1], rowc[s1, j], rowc[s1, j + 1]):
            continue
        for w in range(words):
            a = sg[s0, j, w]
            bb = sg[s0, j + 1, w]
            c = sg[s1, j, w]
            d = sg[s1, j + 1, w]
            if w + 1 < words:
                an = sg[s0, j, w + 1]
                bn = sg[s0, j + 1, w + 1]
                cn = sg[s1, j, w + 1]
                dn = sg[s1, j + 1, w + 1]
            else:
                an = bn = cn = dn = zero
            x = a | bb | c | d
            y = a & bb & c & d
            m = (x | _up(x, an | bn | cn | dn)) & ~(y & _up(y, an & bn & cn & dn)) & valid2[w]
            while m != zero:
                b = trailing_zeros(m)
                m &= m - np.uint64(1)
                col = 64 * w + b
                pa, pa1 = _at(a, an, b)
                pb, pb1 = _at(bb, bn, b)
                pc, pc1 = _at(c, cn, b)
                pd, pd1 = _at(d, dn, b)
                case = np.int64(pa | pc << np.uint64(1) | pb << np.uint64(2) | pd << np.uint64(3)
                                | pa1 << np.uint64(4) | pc1 << np.uint64(5) | pb1 << np.uint64(6)
                                | pd1 << np.uint64(7))
                candidates += 1
                nonball += cube_nonball[case]
                at = (j * d2 + col) * 6
                for p in range(cube_pieces[case]):
                    for r in range(piece_start[case, p], piece_start[case, p + 1]):
                        faces[nf] = flat[at + face_at[r]]
                        nf += 1
                    nc += 1
                    offsets[nc] = nf
    counts[2] = nc
    counts[3] = nf
    counts[4] += candidates
    counts[5] += nonball


def room_per_layer(d1: int, d2: int) -> tuple[int, int, int, int]:
    """The most vertices, edges, 2-cells and face rows one layer's steps can write."""
    return 3 * d1 * d2, 6 * d1 * d2, 4 * d1 * d2, 12 * d1 * d2


@nb.njit(**JIT)
def _has_room(vert, edges, offsets, faces, counts, d1, d2, layers):
    """Room in the output arrays for `layers` layers' steps (see room_per_layer)."""
    per = d1 * d2
    return (counts[0] + 3 * per * layers <= vert.shape[0]
            and counts[1] + 6 * per * layers <= edges.shape[0]
            and counts[2] + 4 * per * layers + 1 <= offsets.shape[0]
            and counts[3] + 12 * per * layers <= faces.shape[0])


@nb.njit(**JIT)
def march_layers(values, base, t_first, t_last, d0, lines, sg, rowc, vid, eid,
                 vert, edges, offsets, faces, counts,
                 square_edges, square_count, cube_pieces, cube_nonball, piece_start, piece_face):
    """Layers t_first..t_last of the grid through the steps S, V, E, C (module docstring);
    at t = d0 - 1 the steps left are run too.  Returns the layer to go on from: t_last + 1,
    or a layer the output arrays have no room for (grow them by `room_per_layer` and call
    again from there; numba growing them itself took seconds to compile).

    values (L, d1, d2): F at layers base..base+L-1, with base = t_first - 1 (the last call's
    last layer) or base = t_first = 0.  lines (3, max vertices per axis): the grid lines.
    Ring buffers kept between calls: sg (4, d1, W) uint64 sign bits of rows (W = words of
    d2 bits), rowc (4, d1) uint8 row classes (0: all < 0, 1: all >= 0, 2: mixed),
    vid (3, d1, d2, 3) vertex ids by edge, eid (3, d1, d2, 3, 2) edge ids by square and
    slot.  Outputs: vertices (V, 3), edges (E, 2), 2-cell offsets (offsets[0] = 0) and
    faces; counts: vertices, edges, 2-cells, faces, candidate cubes, non-ball cells,
    status (OK, NOT_FINITE or OVERFLOW: then the pass stops).
    """
    d1 = values.shape[1]
    d2 = values.shape[2]
    words = sg.shape[2]
    valid = np.zeros(words, np.uint64)  # per word, the bits col < d2 and col < d2 - 1
    valid2 = np.zeros(words, np.uint64)
    for col in range(d2):
        valid[col >> 6] |= np.uint64(1) << np.uint64(col & 63)
        if col < d2 - 1:
            valid2[col >> 6] |= np.uint64(1) << np.uint64(col & 63)
    # each face row's place in eid (flat) relative to its cube's anchor, for each ring slot
    # of the cube's layer (no modulo per face)
    face_place = np.empty((3, piece_face.shape[0]), np.int64)
    for ring in range(3):
        for r in range(piece_face.shape[0]):
            code = piece_face[r]
            corner = code >> 3
            slot = (ring + (corner & 1)) % 3
            face_place[ring, r] = slot * d1 * d2 * 6 + ((corner >> 1 & 1) * d2 + (corner >> 2 & 1)) * 6 + (code & 7)
    for t in range(t_first, t_last + 1):
        if counts[6] != 0:
            return t_last + 1
        if not _has_room(vert, edges, offsets, faces, counts, d1, d2, 3 if t == d0 - 1 else 1):
            return t
        if not _signs(values[t - base], sg[t % 4], rowc[t % 4]):
            counts[6] = 1
            return t_last + 1
        _vstep(values, base, t - 1, d0, lines, sg, rowc, vid, vert, counts, valid, valid2)
        _estep(t - 2, d0, sg, rowc, vid, eid, edges, counts, square_edges, square_count, valid, valid2)
        _cstep(t - 3, d0, sg, rowc, eid, offsets, faces, counts, cube_pieces, cube_nonball, piece_start,
               face_place, valid2)
        if t == d0 - 1 and counts[6] == 0:  # the last layer: drain (ring slots are reused in this order)
            _vstep(values, base, t, d0, lines, sg, rowc, vid, vert, counts, valid, valid2)
            _estep(t - 1, d0, sg, rowc, vid, eid, edges, counts, square_edges, square_count, valid, valid2)
            _cstep(t - 2, d0, sg, rowc, eid, offsets, faces, counts, cube_pieces, cube_nonball, piece_start,
                   face_place, valid2)
            _estep(t, d0, sg, rowc, vid, eid, edges, counts, square_edges, square_count, valid, valid2)
            _cstep(t - 1, d0, sg, rowc, eid, offsets, faces, counts, cube_pieces, cube_nonball, piece_start,
                   face_place, valid2)
    return t_last + 1
