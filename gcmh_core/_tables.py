"""Combinatorial tables of the n-cube for given (n, k), built once and cached.

Everything the kernels need to know about a cube's faces and their Kuhn (CFK)
triangulations is precomputed here as small integer arrays, so the numba kernels
are compiled once for all (n, k): a table is data, not a type.

Conventions
-----------
* A corner of the cube is a bitmask: bit ``a`` set means "+1 along axis a".
* A face is ``(free, fixed)``: ``free`` is the mask of its free axes, ``fixed``
  the bits of its anchor (minimum corner) on the other axes.
* The Kuhn simplex of a face for the permutation ``p`` of its free axes (sorted
  ascending, permutations in ``itertools`` order) is the corner chain
  ``v0 = fixed, v_j = v_{j-1} | (1 << p[j-1])``.  It is the restriction of the
  grid's global Freudenthal triangulation, so two cubes sharing a face split it
  the same way.

The fields' names follow the paper (Sections 3-4); the glossary at the top of
`_kernels` maps the paper's terms to them.
"""

from __future__ import annotations

from functools import lru_cache
from itertools import combinations, permutations
from math import comb, factorial
from typing import NamedTuple

import numpy as np

from .errors import InputError

# Largest walk template we agree to build (entries of the (k+1)-simplex facet table).
_MAX_TEMPLATE_ENTRIES = 40_000_000


class CubeTables(NamedTuple):
    """The n-cube's faces, the CFK (Kuhn) simplices of its k-faces and the walk template
    of its (k+1)-faces: everything `_kernels.cubes_chunk` knows about a cube, passed to
    it whole (numba takes a named tuple of arrays as one argument, and caches it)."""

    n: int
    k: int
    # The faces of every dimension r = k..n, concatenated: the r-faces are rows
    # face_start[r]:face_start[r + 1].  A face is (face_free, face_fixed), see above.
    face_start: np.ndarray  # (n + 2,) int64
    face_free: np.ndarray  # (NF,) int64
    face_fixed: np.ndarray  # (NF,) int64
    face_rank: np.ndarray  # (NF,) int64  rank of the free-axes subset among C(n, r)
    n_subsets: np.ndarray  # (n + 1,) int64  C(n, r)
    binom: np.ndarray  # (n + 1, n + 1) int64 binomial coefficients
    n_codes: np.ndarray  # (n + 1,) int64 vertex codes inside a face of dim D: C(D, k) 2^(D-k) k!
    # The CFK k-simplices of the cube's k-faces, k! per face, face after face (a vertex of
    # M_A is a k-simplex that M_A crosses, paper Section 3.1.1)
    simplices_per_kface: int  # k!
    ksimplex_corners: np.ndarray  # (NS, k+1) int64 corners in chain order
    ksimplex_face: np.ndarray  # (NS,) int64 its k-face, counted among the k-faces
    ksimplex_perm: np.ndarray  # (NS,) int64 rank of its permutation of the face's axes
    # The walk (paper Section 3.1.1, Fig. 3) on a local (k+1)-cube with axes 0..k: its
    # (k+1)! CFK (k+1)-simplices, and the nodes of the walk, their k-facets: boundary
    # nodes 0..walk_boundary_nodes-1 (k-simplices on the local cube's k-faces), then
    # interior nodes (k-simplices inside it, shared by two (k+1)-simplices).
    walk_simplex_corners: np.ndarray  # ((k+1)!, k+2) int64 local corners of each (k+1)-simplex
    walk_simplex_nodes: np.ndarray  # ((k+1)!, k+2) int64 node of its facet "drop corner j"
    walk_interior_corners: np.ndarray  # (NI, k+1) int64 local corners of each interior node
    walk_boundary_nodes: int  # 2 (k+1) k!
    # The template on each (k+1)-face of the cube: local corner -> cube corner, boundary
    # node -> cube k-simplex (a row of ksimplex_*)
    walk_corner_map: np.ndarray  # (NK1, 2^(k+1)) int64
    walk_boundary_simplex: np.ndarray  # (NK1, walk_boundary_nodes) int64
    # Corner sets as bit masks (bit c: cube corner c), for n <= MASKED_N (2^n corners in an
    # int64; empty for larger n): the sign prune tests a whole face or simplex at once.
    ksimplex_corner_mask: np.ndarray  # (NS,) int64
    kface_corner_mask: np.ndarray  # (number of k-faces,) int64
    k1face_corner_mask: np.ndarray  # (NK1,) int64, the (k+1)-faces
    # The cube's whole CFK triangulation (the simplicial baselines' tables, n <= 7; for larger
    # n empty, start all 0) and each k-simplex's row in it: to check, where a face of the
    # cube holds several pieces of G_H, that M_A doesn't join them through the face.
    kuhn: SimplexTables
    ksimplex_kuhn: np.ndarray  # (NS,) int64


def _faces(n: int, r: int):
    """All r-faces of the n-cube as (free, fixed, rank), grouped by free subset."""
    out = []
    for rank, subset in enumerate(combinations(range(n), r)):
        free = sum(1 << a for a in subset)
        others = [a for a in range(n) if a not in subset]
        for bits in range(1 << len(others)):
            fixed = sum(((bits >> i) & 1) << a for i, a in enumerate(others))
            out.append((free, fixed, rank))
    return out


def _kuhn_chain(fixed: int, order) -> list[int]:
    chain = [fixed]
    for axis in order:
        chain.append(chain[-1] | (1 << axis))
    return chain


@lru_cache(maxsize=32)
def cube_tables(n: int, k: int) -> CubeTables:
    if not (1 <= k < n):
        raise InputError(f"need 1 <= k < n, got n={n}, k={k}")
    if factorial(k + 1) * (k + 2) > _MAX_TEMPLATE_ENTRIES:
        raise InputError(f"k={k} is too large: a (k+1)-face has {factorial(k + 1):,} simplices")

    face_start = np.zeros(n + 2, np.int64)
    free_l, fixed_l, rank_l = [], [], []
    for r in range(n + 1):
        face_start[r] = len(free_l)
        if r >= k:
            for free, fixed, rank in _faces(n, r):
                free_l.append(free)
                fixed_l.append(fixed)
                rank_l.append(rank)
    face_start[n + 1] = len(free_l)

    # Kuhn k-simplices of the k-faces
    kfaces = _faces(n, k)
    ks_corners, ks_face, ks_perm = [], [], []
    simplex_of_cornerset: dict[frozenset, int] = {}
    for fi, (free, fixed, _) in enumerate(kfaces):
        axes = [a for a in range(n) if free >> a & 1]
        for pr, order in enumerate(permutations(axes)):
            chain = _kuhn_chain(fixed, order)
            simplex_of_cornerset[frozenset(chain)] = len(ks_corners)
            ks_corners.append(chain)
            ks_face.append(fi)
            ks_perm.append(pr)

    # Walk template on the local (k+1)-cube; nodes: boundary k-simplices first, then interior ones.
    m = k + 1
    boundary_node: dict[frozenset, int] = {}
    boundary_chains = []
    for free, fixed, _ in _faces(m, k):
        axes = [a for a in range(m) if free >> a & 1]
        for order in permutations(axes):
            chain = _kuhn_chain(fixed, order)
            boundary_node[frozenset(chain)] = len(boundary_chains)
            boundary_chains.append(chain)
    nb = len(boundary_chains)
    interior_node: dict[tuple, int] = {}
    interior = []
    t_corners, t_facets = [], []
    for order in permutations(range(m)):
        chain = _kuhn_chain(0, order)
        t_corners.append(chain)
        row = []
        for j in range(m + 1):
            facet = chain[:j] + chain[j + 1:]
            key = frozenset(facet)
            if j == 0 or j == m:
                row.append(boundary_node[key])
            else:
                # both simplices sharing this facet list it in the same (chain) order
                t = tuple(facet)
                if t not in interior_node:
                    interior_node[t] = nb + len(interior)
                    interior.append(facet)
                row.append(interior_node[t])
        t_facets.append(row)

    # Map the template onto every (k+1)-face of the cube.
    k1faces = _faces(n, m)
    cmap = np.zeros((len(k1faces), 1 << m), np.int64)
    bsimp = np.zeros((len(k1faces), nb), np.int64)
    for fi, (free, fixed, _) in enumerate(k1faces):
        axes = [a for a in range(n) if free >> a & 1]
        for local in range(1 << m):
            cmap[fi, local] = fixed | sum(((local >> i) & 1) << a for i, a in enumerate(axes))
        for node, chain in enumerate(boundary_chains):
            bsimp[fi, node] = simplex_of_cornerset[frozenset(int(cmap[fi, c]) for c in chain)]

    def as_i64(x, shape=None):
        a = np.array(x, np.int64)
        return np.ascontiguousarray(a.reshape(shape) if shape else a)

    if n <= 7:
        kuhn = simplex_tables(n, k)
        row_of = {tuple(int(c) for c in kuhn.corners[i, : k + 1]): i for i in range(kuhn.start[k], kuhn.start[k + 1])}
        ksimplex_kuhn = as_i64([row_of[tuple(int(c) for c in cs)] for cs in np.reshape(ks_corners, (-1, k + 1))])
    else:  # (the check is skipped: n! simplices per cube are too many to tabulate)
        z = np.zeros((0, n + 1), np.int64)
        e = np.zeros(0, np.int64)
        kuhn = SimplexTables(n, k, np.zeros(n + 2, np.int64), z, e, e, z, e, 1, e)
        ksimplex_kuhn = np.zeros(0, np.int64)

    return CubeTables(
        n=n,
        k=k,
        face_start=face_start,
        face_free=as_i64(free_l),
        face_fixed=as_i64(fixed_l),
        face_rank=as_i64(rank_l),
        n_subsets=as_i64([comb(n, r) for r in range(n + 1)]),
        binom=as_i64([[comb(a, b) for b in range(n + 1)] for a in range(n + 1)], (n + 1, n + 1)),
        n_codes=as_i64([comb(d, k) * 2 ** max(d - k, 0) * factorial(k) for d in range(n + 1)]),
        simplices_per_kface=factorial(k),
        ksimplex_corners=as_i64(ks_corners, (-1, k + 1)),
        ksimplex_face=as_i64(ks_face),
        ksimplex_perm=as_i64(ks_perm),
        walk_simplex_corners=as_i64(t_corners, (-1, m + 1)),
        walk_simplex_nodes=as_i64(t_facets, (-1, m + 1)),
        walk_interior_corners=as_i64(interior, (-1, k + 1)) if interior else np.zeros((0, k + 1), np.int64),
        walk_boundary_nodes=nb,
        walk_corner_map=cmap,
        walk_boundary_simplex=bsimp,
        ksimplex_corner_mask=_corner_masks(n, ks_corners),
        kface_corner_mask=_corner_masks(n, [_face_corners(free, fixed) for free, fixed, _ in kfaces]),
        k1face_corner_mask=_corner_masks(n, [_face_corners(free, fixed) for free, fixed, _ in k1faces]),
        kuhn=kuhn,
        ksimplex_kuhn=ksimplex_kuhn,
    )


MASKED_N = 6  # up to this n a cube's corners fit the bits of an int64


def _face_corners(free: int, fixed: int) -> list[int]:
    """The cube corners of a face: `fixed` plus every subset of the `free` axes."""
    axes = [a for a in range(free.bit_length()) if free >> a & 1]
    return [fixed | sum(((sub >> i) & 1) << a for i, a in enumerate(axes)) for sub in range(1 << len(axes))]


def _corner_masks(n: int, corner_sets) -> np.ndarray:
    if n > MASKED_N:
        return np.zeros(0, np.int64)
    masks = [sum(1 << int(c) for c in set(cs)) for cs in corner_sets]
    return np.array(masks, np.uint64).view(np.int64)  # (bit 63, corner 63 of a 6-cube: the sign bit)


# ----------------------------------------------------------------------------- simplicial baselines (CMS, CCS)
class SimplexTables(NamedTuple):
    """The simplices of dimension k..n of the cube's CFK (Freudenthal) triangulation,
    for the simplicial baselines (`_kernels.simplices_chunk`, passed whole).

    A simplex is a strict chain of corners c0 < c1 < ... < cd (each a subset of the
    next).  Its key inside the grid is (global vertex of c0) * (n+1)^n + code, where
    code = sum_a step_a (n+1)^a and step_a is the link j of the chain at which axis a
    is switched on (0: never).  Two cubes sharing the simplex compute the same key.
    Simplices are concatenated by dimension: dim d is rows start[d]:start[d+1].
    """

    n: int
    k: int
    start: np.ndarray  # (n + 2,) int64
    corners: np.ndarray  # (NS, n + 1) int64 chain, padded with -1
    c0: np.ndarray  # (NS,) int64 first corner
    code: np.ndarray  # (NS,) int64
    facets: np.ndarray  # (NS, n + 1) int64 row of the facet "drop c_j" (dims > k), -1 padded
    cube_facets: np.ndarray  # (NS,) int64 mask of cube facets (bit 2a + side) holding the simplex
    key_base: int  # (n + 1)^n
    corner_mask: np.ndarray  # (NS,) int64 its corners as bits, for n <= MASKED_N (else empty)


@lru_cache(maxsize=32)
def simplex_tables(n: int, k: int) -> SimplexTables:
    if not (1 <= k < n):
        raise InputError(f"need 1 <= k < n, got n={n}, k={k}")
    if n > 7:
        raise InputError(f"the simplicial baselines split an n-cube into n! simplices: n = {n} is too many (at most 7)")
    by_dim: dict[int, list[tuple[int, ...]]] = {d: [] for d in range(k, n + 1)}

    def chains(prefix):
        d = len(prefix) - 1
        if d >= k:
            by_dim[d].append(tuple(prefix))
        top = prefix[-1]
        rest = [a for a in range(n) if not top >> a & 1]
        for size in range(1, len(rest) + 1):
            for add in combinations(rest, size):
                chains(prefix + [top | sum(1 << a for a in add)])

    for c0 in range(1 << n):
        chains([c0])
    start = np.zeros(n + 2, np.int64)
    rows: list[tuple[int, ...]] = []
    for d in range(n + 1):
        start[d] = len(rows)
        if d >= k:
            rows.extend(sorted(by_dim[d]))
    start[n + 1] = len(rows)
    row_of = {c: i for i, c in enumerate(rows)}
    ns = len(rows)
    corners = -np.ones((ns, n + 1), np.int64)
    facets = -np.ones((ns, n + 1), np.int64)
    c0 = np.zeros(ns, np.int64)
    code = np.zeros(ns, np.int64)
    cube_facets = np.zeros(ns, np.int64)
    for i, chain in enumerate(rows):
        d = len(chain) - 1
        corners[i, : d + 1] = chain
        c0[i] = chain[0]
        for j in range(1, d + 1):
            for a in range(n):
                if (chain[j] ^ chain[j - 1]) >> a & 1:
                    code[i] += j * (n + 1) ** a
        for a in range(n):
            if not (chain[0] ^ chain[-1]) >> a & 1:
                cube_facets[i] |= 1 << (2 * a + (chain[0] >> a & 1))
        if d > k:
            for j in range(d + 1):
                facets[i, j] = row_of[chain[:j] + chain[j + 1 :]]
    return SimplexTables(n, k, start, corners, c0, code, facets, cube_facets, (n + 1) ** n, _corner_masks(n, rows))
