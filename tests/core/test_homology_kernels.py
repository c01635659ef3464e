"""The newer kernels of gcmh_core._homology_kernels against their slow twins
(tests/core/homology_naive.py) on random inputs."""

import numpy as np
import pytest
from homology_naive import (
    edge_classes,
    greedy_basis,
    orient_top,
    polygon_areas,
    root_loops,
    shorten_chain,
    shortest_distances,
    tree_residues,
)
from test_homology import simplicial

from gcmh_core._homology_kernels import (
    _coreduce,
    _edge_classes,
    _greedy_basis,
    _orient_top,
    _polygon_areas,
    _root_loops,
    _shorten_chain,
    _tree_residues,
)
from gcmh_core.homology import _adjacency, _chain_complex, _incidences

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@st.composite
def cells_over_faces(draw):
    """Random top cells over a few faces: each cell 1 to 5 face entries, signs +-1 (a face
    on one, two or more entries, twice in one cell too)."""
    n_faces = draw(st.integers(1, 12))
    n_cells = draw(st.integers(1, 10))
    sizes = draw(st.lists(st.integers(1, 5), min_size=n_cells, max_size=n_cells))
    off = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    fac = np.array(draw(st.lists(st.integers(0, n_faces - 1), min_size=int(off[-1]), max_size=int(off[-1]))),
                   dtype=np.int64)
    sign = np.array(draw(st.lists(st.sampled_from([-1, 1]), min_size=fac.size, max_size=fac.size)),
                    dtype=np.int64)
    return off, fac, sign, n_faces


@settings(max_examples=200, deadline=None, derandomize=True)
@given(cells_over_faces())
def test_orient_top_against_naive(case):
    off, fac, sign, n_faces = case
    eps, bad = _orient_top(off, fac, sign, n_faces)
    eps2, bad2 = orient_top(off, fac, sign, n_faces)
    assert eps.tolist() == eps2 and bad.tolist() == bad2


@settings(max_examples=80, deadline=None, derandomize=True)
@given(st.integers(2, 40), st.integers(0, 2**31 - 1), st.booleans(), st.integers(0, 3))
def test_root_loops_against_naive(n, seed, bounded, others):
    """Random graphs (loops and parallel edges too), a radius or none, and `nearest` the distances
    to 0 to 3 other roots (as the farthest-point choice of roots has them)."""
    rng = np.random.default_rng(seed)
    m = int(rng.integers(1, 3 * n))
    edges = rng.integers(0, n, (m, 2))
    weight = rng.random(m)
    bits = rng.integers(0, 2**63, m, dtype=np.uint64)
    root = int(rng.integers(0, n))
    want = shortest_distances(n, edges.tolist(), weight.tolist(), root)
    finite = [d for d in want if np.isfinite(d)]
    radius = float(rng.uniform(0, max(finite))) if bounded else np.inf
    nearest = np.full(n, np.inf)
    for r in rng.integers(0, n, others):
        np.minimum(nearest, shortest_distances(n, edges.tolist(), weight.tolist(), int(r)), out=nearest)
    before = nearest.copy()
    loop_edges, lengths, masks, dist, pred_edge, pred = _root_loops(
        *_adjacency(edges, n), weight, edges[:, 0].copy(), edges[:, 1].copy(), bits, root, radius, nearest)
    twin, settled = root_loops(n, edges.tolist(), weight.tolist(), bits, pred_edge.tolist(), root, radius, before)
    settled = np.array(settled)
    # the settled vertices at their distances, the rest inf; nearest lowered to them
    assert np.allclose(dist[settled], np.array(want)[settled]) and np.isinf(dist[~settled]).all()
    assert np.allclose(nearest, np.minimum(before, np.where(settled, want, np.inf)))
    # the tree: each settled vertex but the root hangs from its predecessor by an edge of the graph
    assert pred_edge[root] == -1 and (pred_edge[~settled] == -1).all() and (pred[~settled] == -1).all()
    for x in np.flatnonzero(settled & (np.arange(n) != root)):
        e = pred_edge[x]
        assert settled[pred[x]] and sorted(edges[e]) == sorted((pred[x], x))
        assert np.isclose(dist[x], dist[pred[x]] + weight[e])
    assert loop_edges.tolist() == [e for e, _, _ in twin]
    assert np.allclose(lengths, [d for _, d, _ in twin])
    assert masks.tolist() == [k for _, _, k in twin]
    # sums of an integer cochain down the same tree, modulo 3 or 5
    modulus = int(rng.choice([3, 5]))
    value = rng.integers(-7, 8, m)
    res = _tree_residues(pred, pred_edge, edges[:, 0].copy(), value, modulus)
    assert res.tolist() == tree_residues(pred.tolist(), pred_edge.tolist(), edges.tolist(), value.tolist(), modulus)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(simplicial(), st.integers(0, 2**31 - 1))
def test_shorten_chain_against_naive(cx, seed):
    """Random integer q-chains (cycles or not) of random simplicial complexes, random weights."""
    if cx.dim < 2:
        return
    rng = np.random.default_rng(seed)
    base, dims, bd_off, bd, bdv, cb_off, cb = _chain_complex(cx, _incidences(cx))
    q = int(rng.integers(1, cx.dim))
    n_q = cx.count(q)
    cells = rng.integers(0, n_q, int(rng.integers(1, n_q + 3))) + base[q]
    coefs = rng.choice([-2, -1, 1, 2], cells.size)
    weight = rng.uniform(1, 2, n_q)
    out, vals = _shorten_chain(cells, coefs, int(base[q]), bd_off, bd, bdv, cb_off, cb, weight)
    want = shorten_chain(cells.tolist(), coefs.tolist(), int(base[q]), bd_off, bd, bdv, cb_off, cb, weight.tolist())
    assert (out.tolist(), vals.tolist()) == want
    # and it is no larger, in the same class: the difference is a boundary (d of the difference is d z's)
    before = np.zeros(n_q, dtype=np.int64)
    np.add.at(before, cells - base[q], coefs)
    after = np.zeros(n_q, dtype=np.int64)
    after[out - base[q]] = vals
    assert weight @ np.abs(after) <= weight @ np.abs(before) + 1e-9


@settings(max_examples=40, deadline=None, derandomize=True)
@given(simplicial())
def test_edge_classes_against_naive(cx):
    signs = _incidences(cx)
    base, dims, bd_off, bd, bdv, cb_off, cb = _chain_complex(cx, signs)
    partner, time, critical = _coreduce(dims, cx.dim, bd_off, bd, cb_off, cb)
    b1, n_edges = int(base[1]), cx.count(1)
    crit1 = np.sort(critical[dims[critical] == 1])
    if crit1.size == 0:
        return
    pos = np.full(dims.size, -1, dtype=np.int64)
    pos[crit1] = np.arange(crit1.size)
    order = np.argsort(time[b1:b1 + n_edges], kind="stable").astype(np.int64)
    phi, overflow = _edge_classes(order, b1, dims, partner, bd_off, bd, bdv, pos, crit1.size)
    assert not overflow
    assert phi.tolist() == edge_classes(order, b1, dims, partner, bd_off, bd, bdv, pos, crit1.size)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(st.integers(1, 8), st.integers(2, 6), st.integers(0, 2**31 - 1))
def test_polygon_areas_against_naive(n_poly, n, seed):
    """Random polygons of 1 to 6 corners in R^n (repeated corners too)."""
    rng = np.random.default_rng(seed)
    sizes = rng.integers(1, 7, n_poly)
    offs = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    X = rng.normal(size=(10, n))
    verts = rng.integers(0, 10, int(offs[-1])).astype(np.int64)
    assert np.allclose(_polygon_areas(offs, verts, X), polygon_areas(offs, verts, X))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.integers(0, 40), st.integers(1, 12), st.integers(0, 2**31 - 1))
def test_greedy_basis_against_naive(n_masks, bits, seed):
    """Random masks of a few bits (many dependent, zeros too) over a random starting basis in elimination
    order; the picks also independent by rank."""
    from gcmh_core.homology import _echelon

    rng = np.random.default_rng(seed)
    mask = rng.integers(0, 2**bits, n_masks).astype(np.uint64)
    basis = np.array(_echelon(int(x) for x in rng.integers(0, 2**bits, int(rng.integers(0, 4)))), dtype=np.uint64)
    want = int(rng.integers(0, bits + 1))
    picked = _greedy_basis(mask, basis, want)
    assert picked.tolist() == greedy_basis(mask.tolist(), basis.tolist(), want)
    assert len(_echelon([*basis.tolist(), *mask[picked].tolist()])) == basis.size + picked.size
