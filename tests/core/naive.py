"""Slow, obviously correct reference implementation of GCMH (the "naive twin").

This is a line-by-line transcription of "The algorithm as the engine implements
it" (module contracts) and of Section 3 of the paper.  It is written for
readability, not speed: plain Python loops, ``itertools.permutations`` for the
Kuhn (CFK) simplices, ``numpy.linalg.solve`` for the barycentric system, dicts
keyed by global identities and a plain union-find.  The numba engine is tested
against it on small grids (tests/core/test_kernels_vs_naive.py).

Conventions
-----------
* A grid vertex is a multi-index tuple ``(i_0, ..., i_{n-1})``; it sits at
  ``(axes[0][i_0], ..., axes[n-1][i_{n-1}])``.
* A value ``>= 0`` is "positive", ``< 0`` is "negative".
* A face of the grid is ``(anchor, S)``: ``S`` the sorted tuple of free axes,
  ``anchor`` the multi-index of its corner with 0 on every free axis.  This is
  its global identity, shared by every cube that contains it.
* A Kuhn simplex of the face ``(anchor, S)`` is given by a permutation ``p`` of
  ``S``: ``v_0 = anchor``, ``v_j = v_{j-1} + e_{p[j-1]}``.
* A vertex of M_A is identified by ``(anchor, S, p)`` of its Kuhn k-simplex.
* An r-cell is identified by ``(face, frozenset of its vertex ids)`` where the
  face is the (r+k)-face of the grid it was found in.
"""
from __future__ import annotations

import functools
import itertools
from collections import defaultdict
from fractions import Fraction

import numpy as np

# --------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------

def is_positive(x):
    """Sign convention of the contract: >= 0 is positive, < 0 negative."""
    return x >= 0


def add_unit(vertex, axis):
    """vertex + e_axis (multi-indices are tuples)."""
    v = list(vertex)
    v[axis] += 1
    return tuple(v)


def kuhn_path(anchor, perm):
    """Vertices v_0..v_m of the Kuhn simplex of ``perm``, in path order."""
    path = [tuple(anchor)]
    for axis in perm:
        path.append(add_unit(path[-1], axis))
    return path


def subfaces(face, m):
    """All m-dimensional faces (anchor, T) of the face (anchor, S)."""
    anchor, S = face
    out = []
    for T in itertools.combinations(S, m):
        fixed = [a for a in S if a not in T]
        for bits in itertools.product((0, 1), repeat=len(fixed)):
            a = list(anchor)
            for axis, b in zip(fixed, bits):
                a[axis] += b
            out.append((tuple(a), tuple(T)))
    return out


class UnionFind:
    """Plain union-find with path halving."""

    def __init__(self):
        self.parent = {}

    def add(self, x):
        self.parent.setdefault(x, x)

    def find(self, x):
        self.add(x)
        while self.parent[x] != x:
            self.parent[x] = self.parent[self.parent[x]]
            x = self.parent[x]
        return x

    def union(self, a, b):
        ra, rb = self.find(a), self.find(b)
        if ra != rb:
            self.parent[rb] = ra


# --------------------------------------------------------------------------
# the barycentric solve
# --------------------------------------------------------------------------

def _poly_mul(p, q):
    """Product of polynomials in the symbols eps_t, {bit mask of the symbols: coefficient};
    a monomial never has a symbol twice here (each matrix entry is used once per term)."""
    out = defaultdict(Fraction)
    for e1, c1 in p.items():
        for e2, c2 in q.items():
            assert e1 & e2 == 0
            out[e1 | e2] += c1 * c2
    return out


def _perturbed_det(M):
    """Leibniz's formula on the (d, d) matrix M of polynomials: a polynomial."""
    d = len(M)
    total = defaultdict(Fraction)
    for perm in itertools.permutations(range(d)):
        sign = 1
        for i in range(d):
            for j in range(i + 1, d):
                if perm[i] > perm[j]:
                    sign = -sign
        term = {0: Fraction(sign)}
        for row, col in enumerate(perm):
            term = _poly_mul(term, M[row][col])
        for e, c in term.items():
            total[e] += c
    return {e: c for e, c in total.items() if c != 0}


def _leading(poly):
    """The dominant term (exponent, coefficient) of a polynomial in eps_t = eps^(2^t) as eps -> 0:
    the monomial of smallest exponent sum_t 2^t, i.e. the smallest bit mask."""
    e = min(poly)
    return e, poly[e]


def _plain_det(M):
    """The determinant of M's constant terms (the eps^0 term of `_perturbed_det(M)`), exactly, by
    Gaussian elimination on Fractions."""
    A = [[row[c].get(0, Fraction(0)) for c in range(len(row))] for row in M]
    d, det = len(A), Fraction(1)
    for c in range(d):
        p = next((r for r in range(c, d) if A[r][c] != 0), None)
        if p is None:
            return Fraction(0)
        if p != c:
            A[c], A[p] = A[p], A[c]
            det = -det
        det *= A[c][c]
        for r in range(c + 1, d):
            f = A[r][c] / A[c][c]
            if f:
                A[r] = [a - f * b for a, b in zip(A[r], A[c])]
    return det


def _leading_det(M):
    """`_leading(_perturbed_det(M))`: the plain determinant when it is not 0 (it is the eps^0 term,
    the dominant one); Leibniz's expansion in the eps symbols only when it is (k = 8: 9! terms)."""
    det = _plain_det(M)
    return (0, det) if det != 0 else _leading(_perturbed_det(M))


def _clear_float_lambdas(Fv):
    """The solution in floating point when it decides every sign beyond doubt, else None.

    With no value exactly 0, a well-conditioned system (cond < 1e6) and every |lam_i| above
    1e-6 (relative), the float error (about cond * 10 * 2^-53 < 1e-8) cannot flip a sign, and
    the exact lam_i are not 0, so the eps terms do not change the limit either.  Everything
    else goes to the exact path (k = 8 with Fractions: seconds per thousand simplices)."""
    if (Fv == 0).any():
        return None
    m = len(Fv)
    M = np.vstack([Fv.T, np.ones(m)])
    rhs = np.zeros(m)
    rhs[-1] = 1.0
    with np.errstate(all="ignore"):
        cond = np.linalg.cond(M)
        if not np.isfinite(cond) or cond > 1e6:
            return None
        lam = np.linalg.solve(M, rhs)
    if not np.isfinite(lam).all() or np.abs(lam).min() <= 1e-6 * max(1.0, np.abs(lam).max()):
        return None
    return lam


def simplex_lambdas(F_at_vertices, sign_shortcut=True):
    """Barycentric coordinates of the zero of the linear interpolant, by simulation of simplicity.

    ``F_at_vertices``: (k+1, k) array, row i = F(v_i), the simplex's corners in chain order (the
    grid's global vertex order).  Each value F_j(v_i) is read as F_j(v_i) + eps^(2^(i k + j)),
    eps -> 0 (so a value 0 is positive, and no configuration is degenerate).  Cramer's rule on
        sum_i lam_i F_j(v_i) = 0   (j = 0..k-1),    sum_i lam_i = 1
    in exact rational arithmetic: lam_i = D_i / D, D the determinant of the system and D_i the
    same with column i replaced by the right-hand side, both polynomials in the eps symbols.
    Returns the limit eps -> 0 of ``lam`` (k+1,) if every lam_i > 0 for small eps, else None.
    With ``sign_shortcut``, a simplex on which some component has one sign at every vertex
    (a value 0 counting as positive) is None before any solve: the answer is the same.
    """
    Fv = np.asarray(F_at_vertices, dtype=np.float64)
    m, k = Fv.shape
    assert m == k + 1
    if sign_shortcut:
        pos = is_positive(Fv)          # (m, k): one sign per vertex and component
        if (pos.all(axis=0) | ~pos.any(axis=0)).any():
            return None
    clear = _clear_float_lambdas(Fv)
    if clear is not None:
        return clear if (clear > 0).all() else None
    A = [[{0: Fraction(1)} for _ in range(m)] for _ in range(m)]  # row k: the ones of sum lam = 1
    for j in range(k):
        for i in range(m):
            A[j][i] = {0: Fraction(float(Fv[i, j])), 1 << (i * k + j): Fraction(1)}
    rhs = [{} for _ in range(k)] + [{0: Fraction(1)}]
    D = _leading_det(A)
    lam = []
    for i in range(m):
        Ai = [[rhs[r] if c == i else A[r][c] for c in range(m)] for r in range(m)]
        Di = _leading_det(Ai)
        if (Di[1] > 0) != (D[1] > 0):
            return None
        lam.append(float(Di[1] / D[1]) if Di[0] == D[0] else 0.0)
    return np.array(lam)


@functools.cache
def unit_chains(d):
    """The chains m_0 < m_1 < ... < m_j of the unit d-cube's corners (as bit masks: each a strict
    superset of the one before), by j: the simplices of the cube's Kuhn triangulations and their faces."""
    by_dim = defaultdict(list)

    def grow(prefix):
        by_dim[len(prefix) - 1].append(prefix)
        for m in range(1 << d):
            if m != prefix[-1] and m & prefix[-1] == prefix[-1]:
                grow(prefix + (m,))

    for m0 in range(1 << d):
        grow((m0,))
    return dict(by_dim)


# --------------------------------------------------------------------------
# candidates
# --------------------------------------------------------------------------

def cube_corners(origin):
    n = len(origin)
    return [tuple(o + b for o, b in zip(origin, bits))
            for bits in itertools.product((0, 1), repeat=n)]


def is_candidate(values, origin):
    """All 2^n corners finite and every component has both signs."""
    k = values.shape[-1]
    corner_values = [values[c] for c in cube_corners(origin)]
    if not all(np.all(np.isfinite(v)) for v in corner_values):
        return False
    for j in range(k):
        signs = [is_positive(v[j]) for v in corner_values]
        if all(signs) or not any(signs):
            return False
    return True


def naive_candidates(values):
    """Sorted list of origins (tuples) of the candidate cubes."""
    values = np.asarray(values, dtype=np.float64)
    dims = [s - 1 for s in values.shape[:-1]]
    out = []
    for origin in itertools.product(*[range(d) for d in dims]):
        if is_candidate(values, origin):
            out.append(tuple(origin))
    return sorted(out)


# --------------------------------------------------------------------------
# the extraction
# --------------------------------------------------------------------------

class NaiveGCMH:
    def __init__(self, values, axes, sign_shortcut=True):
        self.values = np.asarray(values, dtype=np.float64)
        self.axes = [np.asarray(a, dtype=np.float64) for a in axes]
        self.n = self.values.ndim - 1
        self.k = self.values.shape[-1]
        assert len(self.axes) == self.n
        for a in range(self.n):
            assert len(self.axes[a]) == self.values.shape[a]
        self.sign_shortcut = sign_shortcut
        # global tables
        self.vertex_ids = {}          # (anchor, S, perm) -> vertex id or None
        self.positions = []           # vertex id -> coordinates
        self.vertex_keys = []         # vertex id -> (anchor, S, perm)
        self._kface_vertices = {}     # k-face -> list of vertex ids
        self._face_edges = {}         # (k+1)-face -> list of frozenset pairs
        self._face_cells = {}         # (face, r) -> list of vertex frozensets
        self.walk_dead_ends = []      # (face, start vertex) where a walk failed
        self.walked_faces = []        # (k+1)-faces disambiguated by the walk

    # -- geometry ---------------------------------------------------------
    def x(self, v):
        return np.array([self.axes[a][v[a]] for a in range(self.n)])

    def F(self, v):
        return self.values[v]

    def lambdas(self, simplex):
        return simplex_lambdas([self.F(v) for v in simplex], self.sign_shortcut)

    # -- vertices on k-faces ------------------------------------------------
    def vertex(self, anchor, S, perm):
        """Vertex id of the Kuhn k-simplex (anchor, S, perm), or None."""
        key = (tuple(anchor), tuple(S), tuple(perm))
        if key not in self.vertex_ids:
            path = kuhn_path(anchor, perm)
            lam = self.lambdas(path)
            if lam is None:
                self.vertex_ids[key] = None
            else:
                pos = np.zeros(self.n)
                for lam_i, v in zip(lam, path):
                    pos = pos + lam_i * self.x(v)
                self.vertex_ids[key] = len(self.positions)
                self.positions.append(pos)
                self.vertex_keys.append(key)
        return self.vertex_ids[key]

    def kface_vertices(self, face):
        if face not in self._kface_vertices:
            anchor, S = face
            ids = []
            for perm in itertools.permutations(S):
                vid = self.vertex(anchor, S, perm)
                if vid is not None:
                    ids.append(vid)
            self._kface_vertices[face] = ids
        return self._kface_vertices[face]

    def vertices_in(self, face):
        """Vertices on all k-faces contained in ``face``."""
        out = set()
        for kf in subfaces(face, self.k):
            out.update(self.kface_vertices(kf))
        return out

    # -- edges on (k+1)-faces -------------------------------------------------
    def face_edges(self, face):
        if face not in self._face_edges:
            anchor, S = face
            boundary = []
            for kf in subfaces(face, self.k):
                boundary.extend(self.kface_vertices(kf))
            if len(boundary) == 0:
                edges = []
            elif len(boundary) == 2:
                edges = [frozenset(boundary)]
            else:
                edges = self.walk(face)
            self._face_edges[face] = edges
        return self._face_edges[face]

    def walk(self, face):
        """Pair the boundary vertices of a (k+1)-face through its Kuhn simplices."""
        anchor, S = face
        k = self.k
        self.walked_faces.append(face)
        links = defaultdict(list)       # facet key -> linked facet keys
        boundary_vertex = {}            # boundary facet key -> vertex id (crossing only)
        for q in itertools.permutations(S):
            w = kuhn_path(anchor, q)    # w_0 .. w_{k+1}
            crossing = []
            for m in range(k + 2):
                facet = w[:m] + w[m + 1:]
                key = frozenset(facet)
                if m == 0:
                    # all of w_1.. have coordinate q[0] = anchor+1: the k-face
                    # (anchor + e_{q0}, S \ {q0}) with Kuhn path q[1:]
                    sub_S = tuple(sorted(set(S) - {q[0]}))
                    vid = self.vertex(w[1], sub_S, q[1:])
                    is_crossing = vid is not None
                    if is_crossing:
                        boundary_vertex[key] = vid
                elif m == k + 1:
                    # all of w_0..w_k have coordinate q[k] = anchor: the k-face
                    # (anchor, S \ {q[k]}) with Kuhn path q[:k]
                    sub_S = tuple(sorted(set(S) - {q[k]}))
                    vid = self.vertex(anchor, sub_S, q[:k])
                    is_crossing = vid is not None
                    if is_crossing:
                        boundary_vertex[key] = vid
                else:
                    is_crossing = self.lambdas(facet) is not None
                if is_crossing:
                    crossing.append(key)
            if len(crossing) == 2:
                a, b = crossing
                links[a].append(b)
                links[b].append(a)

        edges = []
        paired = set()
        for start in sorted(boundary_vertex, key=lambda key: boundary_vertex[key]):
            if start in paired:
                continue
            prev, cur = None, start
            seen = {start}
            end = None
            while True:
                nxt = [f for f in links[cur] if f != prev and f not in seen]
                if not nxt:
                    break
                prev, cur = cur, nxt[0]
                seen.add(cur)
                if cur in boundary_vertex:
                    end = cur
                    break
            if end is None:
                self.walk_dead_ends.append((face, boundary_vertex[start]))
                continue
            paired.add(start)
            paired.add(end)
            edges.append(frozenset((boundary_vertex[start], boundary_vertex[end])))
        return edges

    # -- r-cells in (r+k)-faces -------------------------------------------------
    def face_cells(self, face, r):
        """The r-cells in an (r+k)-face: vertex sets of the connected components."""
        key = (face, r)
        if key not in self._face_cells:
            uf = UnionFind()
            touched = set()
            for ef in subfaces(face, self.k + 1):
                for e in self.face_edges(ef):
                    a, b = tuple(e)
                    uf.union(a, b)
                    touched.update((a, b))
            comps = defaultdict(set)
            for v in touched:
                comps[uf.find(v)].add(v)
            self._face_cells[key] = [frozenset(c) for c in comps.values()]
        return self._face_cells[key]

    # -- cells that are not balls (issue 13) -----------------------------------------
    def joined_pieces(self, face, r):
        """How many of the r-cells in ``face`` M_A joins through the face: the cells minus
        the pieces of M_A (marching simplices over the face's Kuhn triangulation: every
        chain of grid vertices c_0 < ... < c_d inside the face) that hold them."""
        cells = self.face_cells(face, r)
        if len(cells) < 2:
            return 0
        anchor, S = face
        axes = sorted(S)
        corner_of = []    # the face's corners by mask: bit i set = one step along axes[i]
        for m in range(1 << len(axes)):
            c = list(anchor)
            for i, a in enumerate(axes):
                c[a] += (m >> i) & 1
            corner_of.append(tuple(c))
        mask_of = {c: m for m, c in enumerate(corner_of)}
        by_dim = unit_chains(len(axes))   # every chain c_0 < ... < c_d of the face's corners, as masks
        uf = UnionFind()
        crossed = set()
        for ch in by_dim.get(self.k, ()):
            if self.lambdas([corner_of[m] for m in ch]) is not None:
                crossed.add(ch)
        for d in sorted(by_dim):
            if d <= self.k:
                continue
            for ch in by_dim[d]:
                for j in range(d + 1):
                    t = ch[:j] + ch[j + 1:]
                    if t in crossed:
                        crossed.add(ch)
                        uf.union(ch, t)
        roots = set()
        for X in cells:
            v = min(X)
            anchor_v, _, perm = self.vertex_keys[v]
            path = tuple(kuhn_path(anchor_v, perm))
            masks = tuple(mask_of.get(c) for c in path)
            roots.add(uf.find(path if None in masks else masks))
        return len(cells) - len(roots)

    # -- driver ---------------------------------------------------------------------
    def run(self):
        n, k = self.n, self.k
        dim = n - k
        cells = {r: {} for r in range(1, dim + 1)}   # r -> {(face, vset): faces}
        non_ball = 0  # counted per cube and face, as the kernel does
        for origin in naive_candidates(self.values):
            cube = (tuple(origin), tuple(range(n)))
            for kf in subfaces(cube, k):               # all vertices of the cube
                self.kface_vertices(kf)
            for r in range(1, dim + 1):
                for f in subfaces(cube, r + k):
                    if r >= 2 and n <= NON_BALL_MAX_N:
                        non_ball += self.joined_pieces(f, r)
                    for X in self.face_cells(f, r):
                        ident = (f, X)
                        if ident in cells[r]:
                            continue
                        if r == 1:
                            faces = X                  # the two vertex ids
                        else:
                            faces = set()
                            for g in subfaces(f, r + k - 1):
                                for Y in self.face_cells(g, r - 1):
                                    if Y <= X:
                                        faces.add((g, Y))
                            faces = frozenset(faces)
                        cells[r][ident] = faces
        # number the cells: r-cell -> index in its list
        out_cells = {}
        index = {}
        for r in range(1, dim + 1):
            idents = list(cells[r])
            index[r] = {ident: i for i, ident in enumerate(idents)}
            lst = []
            for ident in idents:
                faces = cells[r][ident]
                if r == 1:
                    face_ids = frozenset(faces)
                else:
                    face_ids = frozenset(index[r - 1][y] for y in faces)
                lst.append((ident[1], face_ids))
            out_cells[r] = lst
        vertices = (np.array(self.positions, dtype=np.float64).reshape(-1, n))
        return {
            "vertices": vertices,
            "cells": out_cells,
            "cell_faces": {r: [ident[0] for ident in cells[r]] for r in cells},
            "vertex_keys": list(self.vertex_keys),
            "candidates": naive_candidates(self.values),
            "walk_dead_ends": list(self.walk_dead_ends),
            "walked_faces": list(self.walked_faces),
            "non_ball_cells": non_ball if n <= NON_BALL_MAX_N else None,
        }


# The non-ball count marches every chain of corners of a face: fine up to R^5, minutes per
# grid in R^7.  Above this n the naive run leaves it out (non_ball_cells None).
NON_BALL_MAX_N = 6


def naive_extract(values, axes, sign_shortcut=True):
    """GCMH on sampled values, the slow way.

    values: (d_0+1, ..., d_{n-1}+1, k) float64 -- F at the grid vertices
    axes:   n 1-D arrays, the grid line coordinates (len d_a + 1)

    Returns a dict:
      'vertices': (V, n) float64
      'cells': {r: [(frozenset vertex ids, frozenset face ids), ...]} for
               r = 1..n-k; for r = 1 the faces are the two vertex ids, for
               r >= 2 they index into cells[r-1]
      'cell_faces': {r: [grid face (anchor, S) of each r-cell]}
      'vertex_keys': identity (anchor, S, perm) of each vertex
      'candidates': sorted candidate cube origins
      'walk_dead_ends': walks that did not reach a second boundary vertex
      'walked_faces': (k+1)-faces with more than two vertices (the walk ran)
    """
    return NaiveGCMH(values, axes, sign_shortcut).run()  # non_ball_cells None for n > NON_BALL_MAX_N


# --------------------------------------------------------------------------
# helpers for tests
# --------------------------------------------------------------------------

def cell_vertex_sets(result, r):
    """List of frozensets of vertex ids of the r-cells of a naive result."""
    return [vs for vs, _ in result["cells"][r]]


def signature(result, vertex_map=None):
    """{r: list of (frozenset vertices, frozenset of faces-as-vertex-sets)}.

    ``vertex_map`` renames vertex ids (e.g. naive id -> engine id)."""
    m = (lambda v: v) if vertex_map is None else (lambda v: vertex_map[v])
    out = {}
    for r, lst in result["cells"].items():
        sig = []
        for vs, faces in lst:
            X = frozenset(m(v) for v in vs)
            if r == 1:
                Fs = frozenset(frozenset([m(v)]) for v in faces)
            else:
                Fs = frozenset(frozenset(m(v) for v in result["cells"][r - 1][f][0])
                               for f in faces)
            sig.append((X, Fs))
        out[r] = sig
    return out


def euler_characteristic(result):
    chi = len(result["vertices"])
    for r, lst in result["cells"].items():
        chi += (-1) ** r * len(lst)
    return chi


# --------------------------------------------------------------------------
# the simplicial baseline (CMS, paper Section 4), the slow way
# --------------------------------------------------------------------------

def naive_cms(values, axes):
    """Marching simplices over the Kuhn (CFK) triangulation of every candidate cube.

    Each cube is split into its n! Kuhn n-simplices (one per permutation of the
    axes); their faces of dimension k..n are the simplices of the triangulation,
    identified globally by the frozenset of their grid vertices.  A crossed
    k-simplex holds a vertex; a (k+1)-simplex with exactly two crossed facets is
    an edge; an (r+k)-simplex (r >= 2) with at least r + 1 facets that are
    (r-1)-cells is an r-cell.  Same output dict as ``naive_extract``.
    """
    values = np.asarray(values, dtype=np.float64)
    n = values.ndim - 1
    k = values.shape[-1]
    simplices = {d: set() for d in range(k, n + 1)}
    for origin in naive_candidates(values):
        for perm in itertools.permutations(range(n)):
            path = kuhn_path(origin, perm)
            for d in range(k, n + 1):
                for pts in itertools.combinations(path, d + 1):
                    simplices[d].add(frozenset(pts))
    vertex_of = {}
    vertices = []
    for s in sorted(simplices[k], key=lambda s: sorted(s)):
        chain = sorted(s, key=sum)  # a chain: each point is the previous plus unit steps
        lam = simplex_lambdas([values[p] for p in chain])
        if lam is None:
            continue
        vertex_of[s] = len(vertices)
        vertices.append(sum(li * np.array([axes[a][p[a]] for a in range(n)]) for li, p in zip(lam, chain)))
    cells = {}
    alive = {s: ("v", vertex_of[s]) for s in vertex_of}
    for d in range(k + 1, n + 1):
        r = d - k
        cells[r] = []
        index = {}
        for s in sorted(simplices[d], key=lambda s: sorted(s)):
            faces = [alive[s - {p}] for p in s if (s - {p}) in alive]
            if (r == 1 and len(faces) != 2) or len(faces) < r + 1:
                continue
            ids = frozenset(f[1] for f in faces)
            if r == 1:
                vs = ids
            else:
                vs = frozenset().union(*(cells[r - 1][i][0] for i in ids))
            index[s] = len(cells[r])
            cells[r].append((vs, ids))
        alive = {s: ("c", i) for s, i in index.items()}
    return {"vertices": np.array(vertices).reshape(-1, n), "cells": cells}


def naive_insert(known: dict, keys):
    """IntTable.insert's twin: a dict of key -> slot, slots in order of first sight."""
    slots, is_new = [], []
    for key in keys:
        is_new.append(key not in known)
        if key not in known:
            known[key] = len(known)
        slots.append(known[key])
    return np.array(slots, np.int64), np.array(is_new, bool)


def naive_facet_neighbours(wave, masks, div):
    """facet_neighbours' twin: for each cube, for each crossed facet (bit 2a + side) in
    bit order, the cube across it, if inside the grid."""
    out = []
    for origin, mask in zip(wave.tolist(), masks.tolist()):
        for f in range(2 * len(origin)):
            if mask >> f & 1:
                a, step = f // 2, (1 if f % 2 else -1)
                cube = list(origin)
                cube[a] += step
                if 0 <= cube[a] < div[a]:
                    out.append(tuple(cube))
    return out


# --------------------------------------------------------------------------
# structural checks of a CellComplex (issue 13), the slow way
# --------------------------------------------------------------------------

def _cell_faces(cx, r):
    """List of lists: the (r-1)-faces of each r-cell (r >= 1; for r = 1, its two vertices)."""
    if r == 1:
        return [list(e) for e in np.asarray(cx.edges).tolist()]
    offsets, faces = cx.cells[r]
    return [faces[offsets[i]:offsets[i + 1]].tolist() for i in range(len(offsets) - 1)]


def _closure(cx, r, cell, faces=None):
    """{dimension: set of ids} of the cells in the closure of r-cell `cell`, below r.
    faces: {r: _cell_faces(cx, r)}, when the caller has them."""
    faces = faces if faces is not None else {d: _cell_faces(cx, d) for d in range(1, r + 1)}
    out = {d: set() for d in range(r)}
    todo = {r - 1: set(faces[r][cell]) if r >= 1 else set()}
    for d in range(r - 1, -1, -1):
        here = todo.get(d, set())
        out[d] |= here
        if d >= 1:
            todo[d - 1] = {y for x in here for y in faces[d][x]}
    return out


def structure_problems(cx, bounds=None, div=None) -> list[str]:
    """What is wrong with cx as a regular cell complex of a manifold (empty if nothing):
    edges with one end or duplicated, 2-cells whose edges are not one cycle of >= 3, r-cells
    (r >= 3) whose boundary is not a closed connected (r-1)-pseudomanifold with the Euler
    characteristic of a sphere, facets with more than two top cells or none, and, given the box
    `bounds` ((lo, hi) per axis) and `div` (cubes per axis), boundary facets off the box's
    boundary (the outer grid lines are perturbed: within half a cube of it, on one line)."""
    problems = []
    E = np.asarray(cx.edges)
    if len(E) and (E[:, 0] == E[:, 1]).any():
        problems.append("an edge with one end")
    if len(E) and len({tuple(sorted(e)) for e in E.tolist()}) != len(E):
        problems.append("two edges with the same ends")
    dim = cx.dim
    all_faces = {r: _cell_faces(cx, r) for r in range(1, dim + 1)}
    for r in range(2, dim + 1):
        for i, faces in enumerate(all_faces[r]):
            if len(set(faces)) != len(faces):
                problems.append(f"{r}-cell {i} lists a face twice")
                continue
            if r == 2:
                if len(faces) < 3:
                    problems.append(f"2-cell {i} has {len(faces)} edges")
                    continue
                uf = UnionFind()
                degree = defaultdict(int)
                for e in faces:
                    a, b = E[e]
                    degree[a] += 1
                    degree[b] += 1
                    uf.union(a, b)
                if any(d != 2 for d in degree.values()) or len({uf.find(v) for v in degree}) != 1:
                    problems.append(f"2-cell {i}: its edges are not one cycle")
                continue
            # r >= 3: every (r-2)-face of the boundary in exactly two boundary cells,
            # connected, and the Euler characteristic of S^(r-1)
            below = all_faces[r - 1]
            count = defaultdict(int)
            uf = UnionFind()
            for y in faces:
                uf.add(("c", y))
                for z in below[y]:
                    count[z] += 1
                    uf.union(("c", y), ("f", z))
            closure = _closure(cx, r, i, all_faces)
            chi = sum((-1) ** d * len(ids) for d, ids in closure.items())
            if any(c != 2 for c in count.values()) or len({uf.find(("c", y)) for y in faces}) != 1 \
                    or chi != 1 + (-1) ** (r - 1):
                problems.append(f"{r}-cell {i}: its boundary is not a sphere")
    if dim >= 1:
        cofaces = cx.facet_cofaces()
        if (cofaces > 2).any():
            problems.append("a facet of more than two top cells")
        if (cofaces == 0).any():  # (a lens collapsed that was a whole disc left its other edge alone)
            problems.append("a facet of no top cell")
        if bounds is not None:
            V = np.asarray(cx.vertices)
            lo = np.array([b[0] for b in bounds], float)
            hi = np.array([b[1] for b in bounds], float)
            tol = 0.5 * (hi - lo) / np.asarray(div if div is not None else 1, float)
            for f in np.flatnonzero(cofaces == 1):
                vs = sorted(_closure(cx, dim - 1, f, all_faces)[0]) if dim >= 2 else [f]
                P = V[vs]
                one_line = (np.abs(P - P[0]) <= 1e-9 * (hi - lo)).all(axis=0)
                near = (np.abs(P[0] - lo) <= tol) | (np.abs(P[0] - hi) <= tol)
                on = (one_line & near).any()
                if not on:
                    problems.append(f"boundary facet {f} inside the box")
                    break
    return problems


# --------------------------------------------------------------------------
# n = 3, k = 1: the 256 sign cases of a cube (twin of kernels.marching3.cube_cases)
# --------------------------------------------------------------------------

def naive_marching_cases():
    """For each sign case of a cube in R^3 (bit c of the case: F >= 0 at corner c, bit a
    of c: +1 along axis a), GCMH on that one cube the slow way, with F = +1 / -1 at
    its corners: {case: (number of 2-cells, sorted list of their numbers of edges,
    number of edges of M_A on each of the cube's squares by (free axes, fixed side),
    non-ball cells)}."""
    axes = [np.array([0.0, 1.0])] * 3
    out = {}
    for case in range(256):
        values = np.empty((2, 2, 2, 1))
        for c in range(8):
            values[c & 1, c >> 1 & 1, c >> 2 & 1, 0] = 1.0 if case >> c & 1 else -1.0
        res = naive_extract(values, axes)
        two = res["cells"].get(2, [])
        per_square = defaultdict(int)
        for anchor, S in res["cell_faces"].get(1, []):
            per_square[(S, anchor)] += 1
        out[case] = (len(two), sorted(len(faces) for _, faces in two), dict(per_square), res["non_ball_cells"])
    return out


# --------------------------------------------------------------------------
# Euler characteristics per closed cube (the check that GCMH's cells are balls)
# --------------------------------------------------------------------------

def _crossed_kuhn_simplices(tab, values, origin):
    """The crossed Kuhn simplices of the cube at `origin`, {d: set of frozensets of grid points}
    (a k-simplex by the barycentric solve, a higher one when a facet is), and each simplex's face
    of the cube: (`tab`'s row, its dimension), spanned by its lowest and highest corners."""
    values = np.asarray(values, dtype=np.float64)
    n = values.ndim - 1
    k = values.shape[-1]
    row = {(int(fr), int(fx)): f for f, (fr, fx) in enumerate(zip(tab.face_free, tab.face_fixed))}
    simplices = {d: set() for d in range(k, n + 1)}
    for perm in itertools.permutations(range(n)):
        path = kuhn_path(tuple(origin), perm)
        for d in range(k, n + 1):
            for pts in itertools.combinations(path, d + 1):
                simplices[d].add(frozenset(pts))

    def face(s):
        lo, hi = min(s, key=sum), max(s, key=sum)
        fixed = sum(1 << a for a in range(n) if lo[a] > origin[a])
        free = sum(1 << a for a in range(n) if hi[a] != lo[a])
        return row[(free, fixed)], bin(free).count("1")

    crossed = {k: {s for s in simplices[k] if simplex_lambdas([values[p] for p in sorted(s, key=sum)]) is not None}}
    for d in range(k + 1, n + 1):
        crossed[d] = {s for s in simplices[d] if any((s - {p}) in crossed[d - 1] for p in s)}
    return crossed, face


def naive_cube_euler_cms(tab, values, origin):
    """cube_euler_chunk's twin: chi of M_A in each open face of the cube at `origin` (a list over
    `tab`'s face rows): every crossed Kuhn simplex of dimension k + r counted (-1)^r in the face
    spanned by its lowest and highest corners (a simplex above dimension k is crossed when a
    facet is)."""
    k = np.asarray(values).shape[-1]
    crossed, face = _crossed_kuhn_simplices(tab, values, origin)
    out = [0] * len(tab.face_free)
    for d, here in crossed.items():
        for s in here:
            out[face(s)[0]] += (-1) ** (d - k)
    return out


def naive_records_cube_euler(tab, records, origin, strides, dims):
    """records_cube_euler's twin: for each cube (origin (m, n)) and each of its faces (`tab`'s
    rows), the distinct vertices, edges and cells of the records whose face (decoded from the
    key) is that face of the cube, (-1)^r each."""
    n, k = tab.n, tab.k
    vk, _, e, c, _ = records
    by_dim = {k: set(vk.tolist()), k + 1: set(e[:, 0].tolist())}
    for r in range(2, n - k + 1):
        by_dim[r + k] = set(c[c[:, 0] == r, 1].tolist())
    free_of = {}
    for f in range(tab.face_start[k], tab.face_start[n + 1]):
        dim = bin(int(tab.face_free[f])).count("1")
        free_of[(dim, int(tab.face_rank[f]))] = int(tab.face_free[f])
    row = {(int(fr), int(fx)): f for f, (fr, fx) in enumerate(zip(tab.face_free, tab.face_fixed))}
    out = []
    for o in np.asarray(origin).tolist():
        chi = [0] * len(tab.face_free)
        for dim, keys in by_dim.items():
            for key in keys:
                anchor, rank = divmod(key // int(tab.n_codes[dim]), int(tab.n_subsets[dim]))
                free = free_of[(dim, rank)]
                multi = [(anchor // int(strides[a])) % int(dims[a]) for a in range(n)]
                if all(multi[a] == o[a] if free >> a & 1 else multi[a] in (o[a], o[a] + 1) for a in range(n)):
                    fixed = sum(1 << a for a in range(n) if not free >> a & 1 and multi[a] == o[a] + 1)
                    chi[row[(free, fixed)]] += (-1) ** (dim - k)
        out.append(chi)
    return np.array(out, np.int64)


def naive_hidden_pieces_cms(tab, values, origin):
    """cube_euler_chunk's hidden pieces, the slow way: for each face of the cube at `origin` (a
    list over `tab`'s face rows), the connected pieces of M_A in the open face (CMS's crossed Kuhn
    simplices whose lowest and highest corners span that face, joined when one is a facet of the
    other) that have no crossed facet on a lower face: a loop inside a (k+1)-face, a closed
    surface inside a (k+2)-face.  The k-faces count none."""
    k = np.asarray(values).shape[-1]
    crossed, face = _crossed_kuhn_simplices(tab, values, origin)
    uf = UnionFind()
    reaching = set()
    inside = [s for d in crossed for s in crossed[d] if face(s)[1] > k]
    for s in inside:
        uf.add(s)
    for s in inside:
        for p in s:
            f = s - {p}
            if len(f) > k and f in crossed[len(f) - 1]:
                if face(f) == face(s):
                    uf.union(s, f)
                else:
                    reaching.add(s)
    reach_roots = {uf.find(s) for s in reaching}
    out = [0] * len(tab.face_free)
    for root in {uf.find(s) for s in inside} - reach_roots:
        out[face(root)[0]] += 1
    return out
