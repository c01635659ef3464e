"""The continuation's bookkeeping against plain Python: the table of visited cubes
against a dict, the step to the next wave against a loop."""

import os
import sys

import numpy as np
import pytest

from gcmh_core._hashtable import IntTable

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from naive import naive_facet_neighbours, naive_insert


@pytest.mark.parametrize("seed", range(5))
def test_insert_matches_dict_across_growth(seed):
    rng = np.random.default_rng(seed)
    table, known = IntTable(capacity=16), {}
    for batch in range(40):
        # small key ranges give repeats within and across batches; huge ones stress the hash
        high = [50, 5_000, 2**62][batch % 3]
        keys = rng.integers(0, high, size=int(rng.integers(0, 2_000)))
        slots, is_new = table.insert(keys)
        want_slots, want_new = naive_insert(known, keys.tolist())
        np.testing.assert_array_equal(slots, want_slots)
        np.testing.assert_array_equal(is_new, want_new)
    assert len(table) == len(known)
    np.testing.assert_array_equal(table.keys(), np.array(list(known), np.int64))


def test_grid_like_keys_and_empty_batches():
    table = IntTable()
    keys = (np.arange(30)[:, None] * 1_000_003 + np.arange(300)[None]).reshape(-1)  # runs, as grid ids are
    slots, is_new = table.insert(np.concatenate([keys, keys[::-1]]))
    assert is_new[: len(keys)].all() and not is_new[len(keys):].any()
    np.testing.assert_array_equal(slots[len(keys):], np.arange(len(keys))[::-1])
    slots, is_new = table.insert(np.zeros(0, np.int64))
    assert len(slots) == 0 and len(table) == len(keys)


def test_negative_keys_refused():
    with pytest.raises(ValueError):
        IntTable().insert(np.array([3, -1]))


@pytest.mark.parametrize("n", [1, 2, 4, 6])
def test_facet_neighbours_match_naive(n):
    from gcmh_core.kernels.candidates import facet_neighbours

    rng = np.random.default_rng(n)
    for trial in range(20):
        div = rng.integers(1, 5, n)
        m = int(rng.integers(0, 30))
        wave = np.stack([rng.integers(0, d, m) for d in div], axis=1).astype(np.int64).reshape(m, n)
        masks = rng.integers(0, 1 << (2 * n), m).astype(np.int64)  # every facet, at the grid's edges too
        strides = np.cumprod(np.r_[div[1:], 1][::-1])[::-1].astype(np.int64)
        cubes, keys = facet_neighbours(wave, masks, div.astype(np.int64), strides)
        want = naive_facet_neighbours(wave, masks, div.tolist())
        assert [tuple(c) for c in cubes.tolist()] == want, (n, trial)
        np.testing.assert_array_equal(keys, np.array([np.ravel_multi_index(c, div) for c in want], np.int64))
