"""The newer kernels of gcmh_core._homology_kernels against their slow twins
(tests/core/homology_naive.py) on random inputs."""

import numpy as np
import pytest
from homology_naive import edge_classes, orient_top, shortest_distances, tree_xor
from test_homology import simplicial

from gcmh_core._homology_kernels import _coreduce, _edge_classes, _orient_top, _shortest_tree, _tree_xor
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


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.integers(2, 40), st.integers(0, 2**31 - 1))
def test_shortest_tree_against_naive(n, seed):
    rng = np.random.default_rng(seed)
    m = int(rng.integers(1, 3 * n))
    edges = rng.integers(0, n, (m, 2))
    weight = rng.random(m)
    root = int(rng.integers(0, n))
    dist, pred_edge, pred, order = _shortest_tree(*_adjacency(edges, n), weight, root)
    want = shortest_distances(n, edges.tolist(), weight.tolist(), root)
    assert np.allclose(dist, want) and np.array_equal(np.isinf(dist), np.isinf(want))
    # the tree: each reached vertex but the root hangs from its predecessor by an edge of the graph
    reached = np.isfinite(dist)
    assert sorted(order.tolist()) == np.flatnonzero(reached).tolist() and order[0] == root
    for x in np.flatnonzero(reached & (np.arange(n) != root)):
        e = pred_edge[x]
        assert sorted(edges[e]) == sorted((pred[x], x))
        assert np.isclose(dist[x], dist[pred[x]] + weight[e])
    assert np.all(np.diff(dist[order]) >= 0)   # nearest first
    # the xor of bits down the tree
    bits = rng.integers(0, 2**63, n, dtype=np.uint64)
    tree_bits = np.where(pred_edge >= 0, bits, np.uint64(0))
    assert _tree_xor(order, pred, tree_bits).tolist() == tree_xor(order, pred, tree_bits)


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
