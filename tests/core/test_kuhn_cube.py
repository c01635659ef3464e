"""A cube's own Kuhn table (`kernels.kuhn_cube`, n >= 8) against its brute-force twin and the whole
table (`kernels.tables.simplex_tables`, n <= 7): the same crossed simplices, keys and records."""

import numpy as np
import pytest
from naive_balls import naive_chain_id, naive_cube_chains, naive_piece_labels

from gcmh_core._balls import _CubeKuhn
from gcmh_core.kernels.cms import simplices_chunk
from gcmh_core.kernels.kuhn_cube import cube_simplex_tables, piece_labels
from gcmh_core.kernels.tables import cube_tables, simplex_tables


def cube_values(n, k, seed):
    """One cube's corner values: noise (many crossings), noise shifted (few or none), an affine map
    with a value 0 at some corners (flat simplices: `_zero_side`)."""
    rng = np.random.default_rng(seed)
    kind = seed % 3
    if kind == 2:
        corners = ((np.arange(1 << n)[:, None] >> np.arange(n)) & 1).astype(float)
        values = corners @ rng.integers(-2, 3, (n, k)).astype(float) + rng.integers(-2, 3, k)
    else:
        values = rng.normal(size=(1 << n, k)) + (0.7 if kind else 0.0)
    return np.ascontiguousarray(values), np.arange(1 << n, dtype=np.int64)


def table_ids(st):
    n = st.n
    return {d: sorted((st.c0[s] * (n + 1) ** n + st.code[s]).tolist() for s in range(st.start[d], st.start[d + 1]))
            for d in range(st.k, n + 1)}


@pytest.mark.parametrize("n,k,seeds", [(4, 2, range(6)), (5, 2, range(3)), (5, 3, range(3)), (6, 4, [1, 2, 4])])
def test_the_cube_table_holds_the_chains_above_the_crossed_ones(n, k, seeds):
    for seed in seeds:
        check_the_chains(n, k, seed)


def check_the_chains(n, k, seed):
    values, corner_row = cube_values(n, k, seed)
    st = cube_simplex_tables(n, k, values, 0, corner_row)
    ids = table_ids(st)
    assert ids == naive_cube_chains(n, k, values, 0, corner_row)
    ids = {d: set(x) for d, x in ids.items()}
    # each row's chain, key parts and facets as the whole table has them
    full = simplex_tables(n, k)
    row_of = {naive_chain_id(n, [c for c in full.corners[s] if c >= 0]): s for s in range(full.start[n + 1])}
    for s in range(st.start[n + 1]):
        chain = [c for c in st.corners[s] if c >= 0]
        f = row_of[naive_chain_id(n, chain)]
        assert (st.corners[s] == full.corners[f]).all() and st.c0[s] == full.c0[f] and st.code[s] == full.code[f]
        assert st.cube_facets[s] == full.cube_facets[f]
        for j in range(len(chain)):
            if len(chain) - 1 > k:
                g = st.facets[s, j]
                drop = naive_chain_id(n, chain[:j] + chain[j + 1 :])
                assert (g >= 0) == (drop in ids[len(chain) - 2])
                assert g < 0 or naive_chain_id(n, [c for c in st.corners[g] if c >= 0]) == drop


def records(run):
    (vk, vp, e, c, inc), facets, degenerate, _ = run
    order = np.argsort(vk)
    return (vk[order].tolist(), np.round(vp[order], 12).tolist(), sorted(map(tuple, e.tolist())),
            sorted(map(tuple, c.tolist())), sorted(map(tuple, inc.tolist())), facets.tolist(), degenerate)


@pytest.mark.parametrize("n,k", [(5, 3), (6, 3), (6, 4), (7, 5)])
@pytest.mark.parametrize("seed", range(3))
def test_cms_and_the_cell_count_on_the_cube_table_equal_the_whole_tables(n, k, seed):
    """`simplices_chunk`'s records and `cube_euler_chunk`'s counts from a cube's own table equal those
    from the whole table."""
    values, corner_row = cube_values(n, k, seed)
    st = cube_simplex_tables(n, k, values, 0, corner_row)
    args = (values, np.zeros(1, np.int64), np.zeros((1, n), np.int64), np.array([7], np.int64),
            np.tile([0.0, 1.0], (n, 1)), corner_row, corner_row)
    assert records(simplices_chunk(0, 1, *args, st)) == records(simplices_chunk(0, 1, *args, simplex_tables(n, k)))
    tab = cube_tables(n, k)
    whole = _CubeKuhn.whole(tab)
    own = _CubeKuhn(tab, st, *_CubeKuhn.of_table(tab, st))
    for a, b in zip(own.euler(values, np.zeros(1, np.int64), corner_row),
                    whole.euler(values, np.zeros(1, np.int64), corner_row)):
        assert (a == b).all()


@pytest.mark.parametrize("seed", range(5))
def test_piece_labels_are_the_smallest_node_reached(seed):
    rng = np.random.default_rng(seed)
    n_nodes = int(rng.integers(1, 60))
    m = int(rng.integers(0, 80))
    a, b = rng.integers(0, n_nodes, m), rng.integers(0, n_nodes, m)
    keep = rng.random(m) < 0.7
    assert (piece_labels(n_nodes, a, b, keep) == naive_piece_labels(n_nodes, a, b, keep)).all()


@pytest.mark.parametrize("n,k,seed", [(5, 3, 0), (8, 5, 1), (8, 6, 0)])
def test_gcmh_vertices_are_the_crossed_kuhn_simplices_on_k_faces(n, k, seed):
    """`_balls._gcmh_vertex_keys` on a cube's own table (n = 8, also where the cube tables are lazy,
    k = 6) or the whole one (n = 5) keys each crossed k-simplex on a k-face as GCMH's kernel keys its
    vertex there: refined cells keep GCMH's vertices."""
    from gcmh_core._balls import _gcmh_vertex_keys, _simplex_keys
    from gcmh_core.kernels.gcmh import cubes_chunk

    values, corner_row = cube_values(n, k, seed)
    tab = cube_tables(n, k)
    strides = np.int64(1) << np.arange(n - 1, -1, -1)
    corner_off = ((corner_row[:, None] >> np.arange(n)) & 1) @ strides
    args = (values, np.zeros(1, np.int64), np.zeros((1, n), np.int64), np.array([0], np.int64),
            np.tile([0.0, 1.0], (n, 1)), corner_row, corner_off)
    (g_vk, *_), _, _, _ = cubes_chunk(0, 1, *args, tab)
    own = _CubeKuhn.of(tab, values, 0, corner_row)
    (c_vk, *_), _, _, _ = simplices_chunk(0, 1, *args, own.kuhn)
    keys = _gcmh_vertex_keys(tab, own.kuhn, 0, corner_off)
    row_of = {int(x): s for s, x in enumerate(_simplex_keys(own.kuhn, 0, corner_off))}
    on_kfaces = [keys[row_of[int(v)]] for v in c_vk if row_of[int(v)] in keys]
    assert len(g_vk) > 0 and sorted(on_kfaces) == sorted(g_vk.tolist())
