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

For n >= 8 and large k (`lazy_tables`) the tables are the faces only: k! Kuhn simplices per
k-face would be 0.9 GB at n = 10, k = 8, and `lazy.cubes_chunk_lazy` finds the few it needs.

The fields' names follow the paper (Sections 3-4); the glossary in
docs/architecture.md maps the paper's terms to them.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from functools import lru_cache
from itertools import combinations
from math import comb, factorial
from typing import Any, NamedTuple

import numpy as np

from ..errors import Cancelled, InputError

# Where the tables hold the faces only (`lazy_tables`): `lazy.cubes_chunk_lazy` finds a face's
# Kuhn simplices by a pruned walk over their permutations instead of reading k! rows per k-face
# (at n = 10, k = 8 those rows and the walk template took 0.9 GB and most of a run's time).  From
# LAZY_N on, for k >= LAZY_K or more than LAZY_SIMPLICES k-simplices in a cube: below, the tables'
# kernel keeps its bit masks (n <= 6) and the Kuhn triangulation (n = 7), and with up to 5! simplices
# a face it reads them 10-45% faster than the lazy kernel finds them where M bends in a cube.
LAZY_N = 8
LAZY_K = 6
LAZY_SIMPLICES = 1_000_000


def lazy_tables(n: int, k: int) -> bool:
    """Whether `cube_tables(n, k)` leaves the Kuhn simplices and the walk out (see LAZY_N)."""
    return n >= LAZY_N and (k >= LAZY_K or (comb(n, k) << (n - k)) * factorial(k) > LAZY_SIMPLICES)


class CubeTables(NamedTuple):
    """The n-cube's faces, the CFK (Kuhn) simplices of its k-faces and the walk template
    of its (k+1)-faces: everything `gcmh.cubes_chunk` knows about a cube, passed to
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
    # M_A is a k-simplex that M_A crosses, paper Section 3.1.1).  Where `lazy_tables`, the arrays
    # from here to walk_boundary_simplex are empty (no rows): the lazy kernel needs none.
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


_CACHE_SIZE = 32
_cache: OrderedDict[tuple[int, int], CubeTables] = OrderedDict()
_cache_lock = threading.Lock()


def cube_tables(
    n: int,
    k: int,
    progress: Callable[[str, float], None] | None = None,
    cancel: Callable[[], bool] | None = None,
) -> CubeTables:
    """The cube tables for (n, k), built once per process (the last 32 are kept).

    progress(phase, fraction) is called between the steps of a build (none when the tables
    are cached); cancel() is polled there too, and True raises `Cancelled`.  Tables with Kuhn
    simplices take up to a second (at most LAZY_SIMPLICES of them); lazy ones are the faces
    only, milliseconds at n = 12."""
    key = (int(n), int(k))
    with _cache_lock:
        if key in _cache:
            _cache.move_to_end(key)
            return _cache[key]
    if not (1 <= k < n):
        raise InputError(f"need 1 <= k < n, got n={n}, k={k}")

    def step(phase: str, fraction: float) -> None:
        if cancel is not None and cancel():
            raise Cancelled("extraction cancelled")
        if progress is not None:
            progress(f"cube tables: {phase}", fraction)

    step("faces", 0.0)
    tables = _build_cube_tables(*key, step)
    with _cache_lock:
        _cache[key] = tables
        while len(_cache) > _CACHE_SIZE:
            _cache.popitem(last=False)
    return tables


cube_tables.cache_clear = _cache.clear  # type: ignore[attr-defined]  # (as lru_cache's: tests and benchmarks rebuild)


# ----------------------------------------------------------------------------- the builder
# The tables are built with whole-array numpy operations: a permutation's simplex is found by
# arithmetic (the face's index * k! + the permutation's lexicographic rank), never by a lookup
# of its corner set, so k = 8 (40,320 simplices per k-face, 9! in the walk) builds in about a second.


def _permutations(m: int) -> np.ndarray:
    """(m!, m) uint8: the permutations of 0..m-1 in lexicographic (`itertools.permutations`)
    order, built from those of m - 1: first element f, then the rest shifted past f."""
    p = np.zeros((1, 0), np.uint8)
    for size in range(1, m + 1):
        out = np.empty((size * len(p), size), np.uint8)
        for f in range(size):
            block = out[f * len(p) : (f + 1) * len(p)]
            block[:, 0] = f
            block[:, 1:] = p + (p >= f)
        p = out
    return p


def _chains(perms: np.ndarray, axes: np.ndarray, dtype=np.int64) -> np.ndarray:
    """(len(perms), r + 1) Kuhn chains from corner 0: step j switches on axis axes[perms[:, j]]."""
    out = np.zeros((len(perms), perms.shape[1] + 1), dtype)
    np.cumsum(np.left_shift(1, axes[perms].astype(dtype)), axis=1, out=out[:, 1:])  # distinct bits: sum = OR
    return out


def _face_arrays(n: int, r: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(free, fixed, subsets) of the r-faces of the n-cube in `_faces` order: free (C(n,r),)
    masks, fixed (C(n,r), 2^(n-r)) anchors, subsets (C(n,r), r) the free axes ascending."""
    subsets = np.array(list(combinations(range(n), r)), np.int64).reshape(-1, r)
    inside = np.zeros((len(subsets), n), bool)
    inside[np.arange(len(subsets))[:, None], subsets] = True
    others = np.nonzero(~inside)[1].reshape(len(subsets), n - r)  # ascending in each row
    bits = np.arange(1 << (n - r), dtype=np.int64)
    fixed = np.zeros((len(subsets), 1 << (n - r)), np.int64)
    for i in range(n - r):  # bit i of the anchor's number -> its i-th fixed axis
        fixed |= ((bits >> i) & 1)[None, :] << others[:, i, None]
    free = (np.int64(1) << subsets).sum(axis=1)
    return free, fixed, subsets


def _face_index(n: int, r: int, free: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """Row among the r-faces (`_faces(n, r)` order) of the faces (free, fixed): the rank of
    the free subset * 2^(n-r) + the anchor's bits on the other axes, packed."""
    rank_of = np.zeros(1 << n, np.int64)
    rank_of[_face_arrays(n, r)[0]] = np.arange(comb(n, r))
    bits = np.zeros(np.shape(free), np.int64)
    pos = np.zeros(np.shape(free), np.int64)
    for a in range(n):
        other = (free >> a & 1) == 0
        bits |= np.where(other, (fixed >> a & 1) << pos, 0)
        pos += other
    return rank_of[free] * (1 << (n - r)) + bits


def _corner_masks_of_faces(n: int, free: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """Each face's corners as bits of a uint64 viewed as int64 (n <= MASKED_N), else empty."""
    if n > MASKED_N:
        return np.zeros(0, np.int64)
    corners = np.arange(1 << n, dtype=np.uint64)
    member = (corners[None, :] & ~free[:, None].astype(np.uint64)) == fixed[:, None].astype(np.uint64)
    return np.bitwise_or.reduce(np.where(member, np.uint64(1) << corners, np.uint64(0)), axis=1).view(np.int64)


def _walk_template(k: int):
    """The walk on the local (k+1)-cube: (simplex corners, simplex nodes, interior corners,
    boundary nodes), as the loops of `cube_tables`' docstring order them.

    Simplex t is the t-th permutation P of the local axes (lexicographic).  Its facet j = 0
    lies in the k-face with axis P[0] fixed at 1 (row (m-1-P[0]) * 2 + 1 of the local
    k-faces), as the permutation P[1:], of rank t mod k!; facet j = m in the face with
    P[m-1] fixed at 0, as P[:m-1].  An interior facet j (chain minus corner j) is shared with
    the simplex that swaps P[j-1] and P[j]; it is numbered where it first appears, at the
    one of the two with P[j-1] < P[j] (the smaller rank), in (t, j) order."""
    m = k + 1
    kfact = factorial(k)
    perms = _permutations(m)
    nt = len(perms)
    small = np.int16 if m < 15 else np.int64  # local corners < 2^m
    corners = _chains(perms, np.arange(m), small)
    nb = 2 * m * kfact
    nodes = np.zeros((nt, m + 1), np.int64)
    t = np.arange(nt, dtype=np.int64)
    nodes[:, 0] = ((m - 1 - perms[:, 0].astype(np.int64)) * 2 + 1) * kfact + t % kfact
    # Lehmer digits of rank t: digit i of t in the factorial base (weights (m-1-i)!)
    weight = [factorial(m - 1 - i) for i in range(m)]
    digits = np.stack([(t // weight[i]) % (m - i) for i in range(m)], axis=1)
    last = perms[:, m - 1]
    head_rank = np.zeros(nt, np.int64)  # rank of P[:m-1] among the permutations of its elements
    for i in range(m - 1):
        head_rank += (digits[:, i] - (last < perms[:, i])) * factorial(m - 2 - i)
    nodes[:, m] = (m - 1 - last.astype(np.int64)) * 2 * kfact + head_rank
    if k >= 1:
        ascent = perms[:, :-1] < perms[:, 1:]  # (nt, k): column j-1 for facet j
        inner = np.zeros((nt, k), np.int64)
        n_interior = int(ascent.sum())
        inner[ascent] = nb + np.arange(n_interior)
        interior = np.zeros((n_interior, k + 1), np.int64)
        for j in range(1, k + 1):
            up = ascent[:, j - 1]
            down = ~up
            # the swap of P[j-1] > P[j]: Lehmer digits (d, e) at (j-1, j) become (e, d - 1)
            d, e = digits[down, j - 1], digits[down, j]
            partner = t[down] + (e - d) * weight[j - 1] + (d - 1 - e) * weight[j]
            inner[down, j - 1] = inner[partner, j - 1]
            interior[inner[up, j - 1] - nb] = np.delete(corners[up], j, axis=1)
        nodes[:, 1:m] = inner
    else:
        interior = np.zeros((0, k + 1), np.int64)
    return corners.astype(np.int64), nodes, interior, nb


def _build_cube_tables(n: int, k: int, step, lazy: bool | None = None) -> CubeTables:
    """The tables; lazy (default: `lazy_tables`) leaves the Kuhn simplices and the walk out
    (tests build both ways, to hold the lazy kernel to the tables' one)."""
    if lazy is None:
        lazy = lazy_tables(n, k)
    kfact = factorial(k)
    m = k + 1
    face_start = np.zeros(n + 2, np.int64)
    free_l, fixed_l, rank_l = [], [], []
    count = 0
    for r in range(n + 1):
        face_start[r] = count
        if r >= k:
            free, fixed, _ = _face_arrays(n, r)
            free_l.append(np.repeat(free, fixed.shape[1]))
            fixed_l.append(fixed.reshape(-1))
            rank_l.append(np.repeat(np.arange(len(free), dtype=np.int64), fixed.shape[1]))
            count += fixed.size
    face_start[n + 1] = count
    step("faces", 0.05)

    kfree, kfixed, ksubsets = _face_arrays(n, k)
    n_kfaces = kfixed.size
    k1free, k1fixed, k1subsets = _face_arrays(n, m)
    k1free_f = np.repeat(k1free, k1fixed.shape[1])
    k1fixed_f = k1fixed.reshape(-1)
    nb = 2 * m * kfact
    if lazy:  # the lazy kernel finds its simplices itself
        ks_corners = np.zeros((0, k + 1), np.int64)
        ks_face = ks_perm = np.zeros(0, np.int64)
        t_corners = t_nodes = np.zeros((0, m + 1), np.int64)
        interior = np.zeros((0, k + 1), np.int64)
        cmap = bsimp = np.zeros((0, 0), np.int64)
    else:
        # Kuhn k-simplices of the k-faces: face after face (subset-major, then anchor), k! each
        perms = _permutations(k)
        ks_corners = np.empty((n_kfaces * kfact, k + 1), np.int64)
        by_face = ks_corners.reshape(len(kfree), kfixed.shape[1], kfact, k + 1)
        for s in range(len(kfree)):
            np.bitwise_or(kfixed[s][:, None, None], _chains(perms, ksubsets[s])[None], out=by_face[s])
            step("k-simplices", 0.05 + 0.45 * (s + 1) / len(kfree))
        del perms

        t_corners, t_nodes, interior, _ = _walk_template(k)
        step("walk template", 0.8)

        # the template on every (k+1)-face: local corner -> cube corner; boundary node (local
        # k-face lf, permutation p) -> the cube k-face that lf maps to, same p (the map keeps
        # the axes' order, so the permutation's rank)
        k1axes = np.repeat(k1subsets, k1fixed.shape[1], axis=0)  # (NK1, m)
        local = np.arange(1 << m, dtype=np.int64)
        cmap = k1fixed_f[:, None] | (((local[None, :, None] >> np.arange(m)) & 1) << k1axes[:, None, :]).sum(axis=2)
        lf = np.arange(2 * m)
        dropped = m - 1 - lf // 2  # local k-face lf: local axis `dropped` fixed at lf % 2
        drop_axis = k1axes[:, dropped]  # (NK1, 2m)
        kface = _face_index(n, k, k1free_f[:, None] & ~(np.int64(1) << drop_axis),
                            k1fixed_f[:, None] | ((lf % 2) << drop_axis))
        bsimp = (kface[:, :, None] * kfact + np.arange(kfact)).reshape(len(k1free_f), nb)
        step("walk map", 0.9)

        ks_face = np.repeat(np.arange(n_kfaces, dtype=np.int64), kfact)
        ks_perm = np.tile(np.arange(kfact, dtype=np.int64), n_kfaces)
    if n <= 7:
        kuhn = simplex_tables(n, k)
        rows = kuhn.corners[kuhn.start[k] : kuhn.start[k + 1], : k + 1]
        # a chain's corners packed into one integer (n (k+1) <= 56 bits): sorted as the rows are
        ksimplex_kuhn = kuhn.start[k] + np.searchsorted(_packed(n, rows), _packed(n, ks_corners))
    else:  # (the check is skipped: n! simplices per cube are too many to tabulate)
        z = np.zeros((0, n + 1), np.int64)
        e = np.zeros(0, np.int64)
        kuhn = SimplexTables(n, k, np.zeros(n + 2, np.int64), z, e, e, z, e, 1, e)
        ksimplex_kuhn = np.zeros(0, np.int64)
    step("tables", 1.0)

    tables = CubeTables(
        n=n,
        k=k,
        face_start=face_start,
        face_free=np.concatenate(free_l),
        face_fixed=np.concatenate(fixed_l),
        face_rank=np.concatenate(rank_l),
        n_subsets=np.array([comb(n, r) for r in range(n + 1)], np.int64),
        binom=np.array([[comb(a, b) for b in range(n + 1)] for a in range(n + 1)], np.int64),
        n_codes=np.array([comb(d, k) * 2 ** max(d - k, 0) * kfact for d in range(n + 1)], np.int64),
        simplices_per_kface=kfact,
        ksimplex_corners=ks_corners,
        ksimplex_face=ks_face,
        ksimplex_perm=ks_perm,
        walk_simplex_corners=t_corners,
        walk_simplex_nodes=t_nodes,
        walk_interior_corners=interior,
        walk_boundary_nodes=nb,
        walk_corner_map=cmap,
        walk_boundary_simplex=bsimp,
        ksimplex_corner_mask=_corner_masks(n, ks_corners),
        kface_corner_mask=_corner_masks_of_faces(n, np.repeat(kfree, kfixed.shape[1]), kfixed.reshape(-1)),
        k1face_corner_mask=_corner_masks_of_faces(n, k1free_f, k1fixed_f),
        kuhn=kuhn,
        ksimplex_kuhn=ksimplex_kuhn,
    )
    # C order throughout: numba compiles the kernel once per array layout
    arrays: dict[str, Any] = {
        f: np.ascontiguousarray(a) for f, a in tables._asdict().items() if isinstance(a, np.ndarray)
    }
    return tables._replace(**arrays)


MASKED_N = 6  # up to this n a cube's corners fit the bits of an int64


def _corner_masks(n: int, corner_sets) -> np.ndarray:
    if n > MASKED_N:
        return np.zeros(0, np.int64)
    corners = np.asarray(corner_sets, np.int64)
    bits = np.where(corners >= 0, np.uint64(1) << np.maximum(corners, 0).astype(np.uint64), np.uint64(0))  # -1: padding
    return np.bitwise_or.reduce(bits, axis=1).view(np.int64)  # (bit 63, corner 63 of a 6-cube: the sign bit)


# ----------------------------------------------------------------------------- simplicial baselines (CMS, CCS)
class SimplexTables(NamedTuple):
    """The simplices of dimension k..n of the cube's CFK (Freudenthal) triangulation,
    for the simplicial baselines (`cms.simplices_chunk`, passed whole).

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
    start = np.zeros(n + 2, np.int64)
    by_dim = {}
    count = 0
    for d in range(n + 1):
        start[d] = count
        if d >= k:
            by_dim[d] = _strict_chains(n, d)
            count += len(by_dim[d][0])
    start[n + 1] = count
    corners = -np.ones((count, n + 1), np.int64)
    facets = -np.ones((count, n + 1), np.int64)
    c0 = np.zeros(count, np.int64)
    code = np.zeros(count, np.int64)
    cube_facets = np.zeros(count, np.int64)
    for d, (chains, labels, _) in by_dim.items():
        rows = slice(start[d], start[d + 1])
        corners[rows, : d + 1] = chains
        c0[rows] = chains[:, 0]
        for a in range(n):
            label = labels[:, a].astype(np.int64)
            code[rows] += np.where(label <= d, label, 0) * (n + 1) ** a  # (label 0: in c0, d + 1: never)
            cube_facets[rows] |= np.where(label == 0, 1 << (2 * a + 1), np.where(label == d + 1, 1 << (2 * a), 0))
        if d > k:
            below = by_dim[d - 1][2]
            for j in range(d + 1):
                facets[rows, j] = start[d - 1] + np.searchsorted(below, _packed(n, np.delete(chains, j, axis=1)))
    return SimplexTables(n, k, start, corners, c0, code, facets, cube_facets, (n + 1) ** n, _corner_masks(n, corners))


def _packed(n: int, chains: np.ndarray) -> np.ndarray:
    """Each chain's corners as the digits of one integer (base 2^n, first corner highest): for
    chains of one length, sorted as the tuples (n (n + 1) <= 56 bits for n <= 7)."""
    shift = n * np.arange(chains.shape[1] - 1, -1, -1, dtype=np.int64)
    return (chains << shift).sum(axis=1)


def _strict_chains(n: int, d: int):
    """The strict chains c0 < c1 < ... < cd of the n-cube's corners, sorted as tuples:
    (chains (rows, d + 1), labels (rows, n), packed keys).  Axis a has label 0 (in c0),
    j in 1..d (switched on at link j; each j labels some axis) or d + 1 (never)."""
    every = np.indices((d + 2,) * n, dtype=np.uint8).reshape(n, -1)[::-1]  # (n, (d+2)^n): row a, axis a
    onto = np.ones(every.shape[1], bool)
    for j in range(1, d + 1):
        onto &= (every == j).any(axis=0)
    labels = np.ascontiguousarray(every[:, onto].T)
    chains = np.zeros((len(labels), d + 1), np.int64)
    for a in range(n):
        chains += (labels[:, a, None] <= np.arange(d + 1)) * np.int64(1 << a)
    keys = _packed(n, chains)
    order = np.argsort(keys, kind="stable")
    return chains[order], labels[order], keys[order]
