"""Slow, obviously correct homology for tests of `gcmh_core.homology`.

The whole boundary matrices (no reduction, no Morse complex): Betti numbers over Q from
exact ranks (sympy), over Z/2 from Gaussian elimination mod 2, torsion from sympy's
invariant factors; and small complexes built by hand from lists of simplices.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
from sympy import ZZ, Matrix
from sympy.matrices.normalforms import invariant_factors

from gcmh_core import CellComplex
from gcmh_core.homology import incidences


def boundary_matrices(cx):
    """D[r] for r = 1..dim: (N_{r-1}, N_r) int64, from `incidences` (D[0] is None)."""
    signs = incidences(cx)
    D = [None]
    for r in range(1, cx.dim + 1):
        M = np.zeros((cx.count(r - 1), cx.count(r)), dtype=np.int64)
        if r == 1:
            for e, (u, v) in enumerate(np.asarray(cx.edges)):
                M[u, e] += signs[1][e, 0]
                M[v, e] += signs[1][e, 1]
        else:
            off, fac = cx.cells[r]
            for c in range(off.size - 1):
                for j in range(off[c], off[c + 1]):
                    M[fac[j], c] += signs[r][j]
        D.append(M)
    return D


def rank_mod2(M):
    A = (np.asarray(M) % 2).astype(bool)
    rank = 0
    rows, cols = A.shape
    for c in range(cols):
        pivot = next((i for i in range(rank, rows) if A[i, c]), None)
        if pivot is None:
            continue
        A[[rank, pivot]] = A[[pivot, rank]]
        below = np.flatnonzero(A[:, c])
        below = below[below != rank]
        A[below] ^= A[rank]
        rank += 1
    return rank


def naive_homology(cx):
    """(betti, betti_mod2, torsion) from the full boundary matrices."""
    D = boundary_matrices(cx)
    n = cx.counts()
    factors = [[]]
    ranks2 = [0]
    for r in range(1, cx.dim + 1):
        M = D[r]
        if M.size == 0:
            factors.append([])
            ranks2.append(0)
            continue
        f = invariant_factors(Matrix(M.tolist()), domain=ZZ)
        factors.append([abs(int(x)) for x in f if x != 0])
        ranks2.append(rank_mod2(M))
    factors.append([])
    ranks2.append(0)
    betti = [n[q] - len(factors[q]) - len(factors[q + 1]) for q in range(cx.dim + 1)]
    betti2 = [n[q] - ranks2[q] - ranks2[q + 1] for q in range(cx.dim + 1)]
    torsion = [sorted(f for f in factors[q + 1] if f > 1) for q in range(cx.dim + 1)]
    return betti, betti2, torsion


def simplicial_complex(simplices, n=None, seed=0):
    """A CellComplex (k = 0) whose cells are the faces of the given simplices (vertex
    tuples); the vertices at random points of R^n (n = the top dimension)."""
    simplices = [tuple(sorted(s)) for s in simplices]
    top = max(len(s) for s in simplices) - 1
    n = n or max(top, 1)
    levels = [set() for _ in range(top + 1)]
    for s in simplices:
        for r in range(len(s)):
            levels[r].update(combinations(s, r + 1))
    verts = sorted(v for (v,) in levels[0])
    ids = [{s: i for i, s in enumerate(sorted(level))} for level in levels]
    ids[0] = {(v,): i for i, v in enumerate(verts)}
    edges = [[ids[0][(a,)], ids[0][(b,)]] for (a, b) in sorted(levels[1])] if top >= 1 else []
    cells = {}
    for r in range(2, top + 1):
        offsets, faces = [0], []
        for s in sorted(levels[r]):
            faces += [ids[r - 1][f] for f in combinations(s, r)]
            offsets.append(len(faces))
        cells[r] = (offsets, faces)
    rng = np.random.default_rng(seed)
    return CellComplex(n, n - top, rng.normal(size=(len(verts), n)),
                       np.array(edges, dtype=np.int64).reshape(-1, 2), cells)


# the minimal triangulation of the real projective plane (6 vertices, 10 triangles)
RP2 = [(1, 2, 3), (1, 3, 4), (1, 4, 5), (1, 5, 6), (1, 6, 2), (2, 3, 5), (3, 4, 6), (4, 5, 2), (5, 6, 3),
       (6, 2, 4)]


def cone_triangulation(cx):
    """Top simplices (vertex-id tuples) of a simplicial subdivision of `cx` (dim <= 3):
    each 2-cell coned from a new vertex, each 3-cell coned over its coned faces."""
    nv = cx.count(0)
    simplices = [(int(v),) for v in range(nv)]
    simplices += [tuple(int(x) for x in e) for e in np.asarray(cx.edges)]
    if cx.dim < 2:
        return simplices
    off2, fac2 = cx.cells[2]
    face_tris = []
    for f in range(off2.size - 1):
        c = nv
        nv += 1
        tris = [(c, int(cx.edges[e][0]), int(cx.edges[e][1])) for e in fac2[off2[f]:off2[f + 1]]]
        face_tris.append(tris)
        simplices += tris
    if cx.dim >= 3:
        off3, fac3 = cx.cells[3]
        for s in range(off3.size - 1):
            c = nv
            nv += 1
            for f in fac3[off3[s]:off3[s + 1]]:
                simplices += [(c, *t) for t in face_tris[f]]
    if cx.dim > 3:
        raise ValueError("cone_triangulation handles dim <= 3")
    return simplices


def boundary_of_boundary(cx, r):
    """The nonzero entries of D[r-1] @ D[r] (should be none), from the incidences' lists
    (sparse: a product of dense matrices of a 3-torus would take gigabytes)."""
    signs = incidences(cx)

    def entries(level):
        if level == 1:
            e = np.asarray(cx.edges)
            return np.repeat(np.arange(len(e)), 2), e.ravel(), signs[1].ravel()
        off, fac = cx.cells[level]
        return np.repeat(np.arange(off.size - 1), np.diff(off)), np.asarray(fac), signs[level]

    c, f, s = entries(r)
    f2, g, t = entries(r - 1)
    order = np.argsort(f2, kind="stable")
    f2, g, t = f2[order], g[order], t[order]
    start = np.searchsorted(f2, f, side="left")
    stop = np.searchsorted(f2, f, side="right")
    counts = stop - start
    rep = np.repeat(np.arange(f.size), counts)
    idx = np.repeat(start, counts) + np.arange(rep.size) - np.repeat(np.cumsum(counts) - counts, counts)
    key = c[rep] * (cx.count(r - 2) + 1) + g[idx]
    uniq, inverse = np.unique(key, return_inverse=True)
    total = np.bincount(inverse, weights=s[rep] * t[idx], minlength=uniq.size)
    return int(np.count_nonzero(total))
