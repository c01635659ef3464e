"""gcmh_core.kernels.tables: the vectorised cube tables against the loop builder they replaced.

`loop_cube_tables` is the builder of the tables up to issue 14, kept here as the slow,
obviously correct twin: faces, Kuhn chains and the walk built by Python loops, simplices
found by their corner sets in dicts.  The new builder must give the same arrays in the
same order (the kernels and every global key depend on them) for every (n, k) up to R^7
and a few larger; the largest twins take a minute and run with GCMH_TABLES_PROFILE=long.
Where `lazy_tables` (n >= 8, large k) the tables hold the faces only (the lazy kernel needs no more): the same
faces, the Kuhn simplices and the walk left out, and built in full on request.
"""

import os
from functools import cache
from itertools import combinations, permutations
from math import comb, factorial

import numpy as np
import pytest

from gcmh_core.errors import Cancelled, InputError
from gcmh_core.kernels import tables as _tables
from gcmh_core.kernels.tables import MASKED_N, CubeTables, SimplexTables, _faces, cube_tables, simplex_tables

LONG = os.environ.get("GCMH_TABLES_PROFILE") == "long"


# ----------------------------------------------------------------------------- the twin
def _kuhn_chain(fixed, order):
    chain = [fixed]
    for axis in order:
        chain.append(chain[-1] | (1 << axis))
    return chain


def _face_corners(free, fixed):
    axes = [a for a in range(free.bit_length()) if free >> a & 1]
    return [fixed | sum(((sub >> i) & 1) << a for i, a in enumerate(axes)) for sub in range(1 << len(axes))]


def _corner_masks(n, corner_sets):
    if n > MASKED_N:
        return np.zeros(0, np.int64)
    masks = [sum(1 << int(c) for c in set(cs)) for cs in corner_sets]
    return np.array(masks, np.uint64).view(np.int64)


@cache
def loop_simplex_tables(n: int, k: int) -> SimplexTables:
    """The simplicial baselines' tables as `_tables.simplex_tables` built them up to issue 14."""
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


def loop_cube_tables(n: int, k: int) -> CubeTables:
    """The cube tables as `_tables.cube_tables` built them up to issue 14 (Python loops)."""
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

    kfaces = _faces(n, k)
    ks_corners, ks_face, ks_perm = [], [], []
    simplex_of_cornerset = {}
    for fi, (free, fixed, _) in enumerate(kfaces):
        axes = [a for a in range(n) if free >> a & 1]
        for pr, order in enumerate(permutations(axes)):
            chain = _kuhn_chain(fixed, order)
            simplex_of_cornerset[frozenset(chain)] = len(ks_corners)
            ks_corners.append(chain)
            ks_face.append(fi)
            ks_perm.append(pr)

    m = k + 1
    boundary_node = {}
    boundary_chains = []
    for free, fixed, _ in _faces(m, k):
        axes = [a for a in range(m) if free >> a & 1]
        for order in permutations(axes):
            chain = _kuhn_chain(fixed, order)
            boundary_node[frozenset(chain)] = len(boundary_chains)
            boundary_chains.append(chain)
    nb = len(boundary_chains)
    interior_node = {}
    interior = []
    t_corners, t_facets = [], []
    for order in permutations(range(m)):
        chain = _kuhn_chain(0, order)
        t_corners.append(chain)
        row = []
        for j in range(m + 1):
            facet = chain[:j] + chain[j + 1:]
            if j == 0 or j == m:
                row.append(boundary_node[frozenset(facet)])
            else:
                t = tuple(facet)
                if t not in interior_node:
                    interior_node[t] = nb + len(interior)
                    interior.append(facet)
                row.append(interior_node[t])
        t_facets.append(row)

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
        kuhn = loop_simplex_tables(n, k)
        row_of = {tuple(int(c) for c in kuhn.corners[i, : k + 1]): i for i in range(kuhn.start[k], kuhn.start[k + 1])}
        ksimplex_kuhn = as_i64([row_of[tuple(int(c) for c in cs)] for cs in np.reshape(ks_corners, (-1, k + 1))])
    else:
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


# ----------------------------------------------------------------------------- the comparison
def assert_same_tables(new, old):
    """Every field equal: same values, same order, same shape, same dtype."""
    assert type(new) is type(old)
    for name in old._fields:
        a, b = getattr(new, name), getattr(old, name)
        if isinstance(b, tuple):  # the Kuhn triangulation's own named tuple
            assert_same_tables(a, b)
        elif isinstance(b, np.ndarray):
            assert isinstance(a, np.ndarray), name
            assert a.dtype == b.dtype and a.shape == b.shape, (name, a.dtype, a.shape, b.dtype, b.shape)
            assert a.flags.c_contiguous, name
            np.testing.assert_array_equal(a, b, err_msg=name)
        else:
            assert a == b and type(a) is type(b), (name, a, b)


SMALL = [(n, k) for n in range(2, 8) for k in range(1, n)]
LARGER = [(8, 1), (8, 4), (9, 2), (10, 1)]
SLOW = [(8, 6), (8, 7), (9, 7)]  # the twin takes 5 s to a minute (lazy tables)


def _quiet(*_):
    pass


def faces_only(tables: CubeTables) -> CubeTables:
    """The tables as `lazy_tables` has them: no Kuhn simplices, no walk (empty, same dtypes)."""
    k = tables.k
    none = np.zeros(0, np.int64)
    return tables._replace(
        ksimplex_corners=np.zeros((0, k + 1), np.int64), ksimplex_face=none, ksimplex_perm=none,
        walk_simplex_corners=np.zeros((0, k + 2), np.int64), walk_simplex_nodes=np.zeros((0, k + 2), np.int64),
        walk_interior_corners=np.zeros((0, k + 1), np.int64), walk_corner_map=np.zeros((0, 0), np.int64),
        walk_boundary_simplex=np.zeros((0, 0), np.int64),
    )


@pytest.mark.parametrize("n, k", SMALL + LARGER + (SLOW if LONG else []))
def test_tables_equal_the_loop_builder(n, k):
    cube_tables.cache_clear()
    twin = loop_cube_tables(n, k)
    lazy = _tables.lazy_tables(n, k)
    assert_same_tables(cube_tables(n, k), faces_only(twin) if lazy else twin)
    if lazy:  # in full on request (test_lazy_kernel holds the lazy kernel to the tables' one)
        assert_same_tables(_tables._build_cube_tables(n, k, _quiet, lazy=False), twin)


@pytest.mark.parametrize("n, k", [(8, 6), (10, 8), (11, 9), (12, 10)])
def test_from_lazy_n_on_the_tables_are_the_faces_only(n, k):
    """k! Kuhn simplices per k-face are not listed: R^12 with k = 10 is kilobytes.  With k <= 5 only
    where a cube would have over LAZY_SIMPLICES k-simplices."""
    assert not _tables.lazy_tables(7, 6) and not _tables.lazy_tables(8, 5) and not _tables.lazy_tables(10, 5)
    assert _tables.lazy_tables(11, 5) and _tables.lazy_tables(12, 4)
    tables = cube_tables(n, k)
    assert tables.ksimplex_corners.shape == (0, k + 1) and tables.walk_corner_map.size == 0
    assert tables.simplices_per_kface == factorial(k) and tables.walk_boundary_nodes == 2 * (k + 1) * factorial(k)
    assert len(tables.face_free) == sum(comb(n, r) << (n - r) for r in range(k, n + 1))
    assert sum(a.nbytes for a in tables if isinstance(a, np.ndarray)) < 100_000


@pytest.mark.parametrize("k", [1, 2, 5, 8])
def test_walk_template_links_each_simplex_to_its_facets(k):
    """Beyond the twin's reach too (k = 8): facet j of every (k+1)-simplex is its chain
    without corner j; boundary nodes are the k-simplices of the local cube's k-faces, each in
    one simplex; interior ones are shared by exactly two."""
    corners, nodes, interior, nb = _tables._walk_template(k)
    m = k + 1
    assert corners.shape == (factorial(m), m + 1) and nodes.shape == corners.shape
    boundary = _tables._build_cube_tables(m, k, _quiet, lazy=False).ksimplex_corners
    assert nb == len(boundary) == 2 * m * factorial(k)
    np.testing.assert_array_equal(boundary[nodes[:, 0]], corners[:, 1:])
    np.testing.assert_array_equal(boundary[nodes[:, m]], corners[:, :m])
    for j in range(1, m):
        np.testing.assert_array_equal(interior[nodes[:, j] - nb], np.delete(corners, j, axis=1))
    uses = np.bincount(nodes.ravel(), minlength=nb + len(interior))
    assert np.all(uses[:nb] == 1) and np.all(uses[nb:] == 2)


@pytest.mark.parametrize("n, k", SMALL)
def test_simplex_tables_equal_the_loop_builder(n, k):
    simplex_tables.cache_clear()
    assert_same_tables(simplex_tables(n, k), loop_simplex_tables(n, k))


def test_permutations_are_lexicographic():
    for m in range(1, 8):
        np.testing.assert_array_equal(_tables._permutations(m), np.array(list(permutations(range(m))), np.uint8))


def test_progress_rises_to_one_and_cancel_stops_the_build():
    cube_tables.cache_clear()
    seen = []
    cube_tables(7, 5, progress=lambda phase, f: seen.append((phase, f)))
    fractions = [f for _, f in seen]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0 and len(seen) > 3
    assert all(phase.startswith("cube tables") for phase, _ in seen)
    seen.clear()
    cube_tables(7, 5, progress=lambda phase, f: seen.append(f))
    assert seen == []  # cached: nothing to report
    polls = []

    def cancel():
        polls.append(1)
        return len(polls) > 2

    with pytest.raises(Cancelled):
        cube_tables(7, 6, cancel=cancel)
    assert_same_tables(cube_tables(7, 6), cube_tables(7, 6))  # (not cached half-built: builds whole)
    assert cube_tables(7, 6).ksimplex_corners.shape == (comb(7, 6) * 2 * factorial(6), 7)


@pytest.mark.parametrize("n, k, words", [(3, 0, "1 <= k < n"), (3, 3, "1 <= k < n"), (12, 12, "1 <= k < n")])
def test_bad_sizes_are_refused(n, k, words):
    with pytest.raises(InputError, match=words):
        cube_tables(n, k)
