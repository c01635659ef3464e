"""Identified axes on a Dask cluster (gcmh_core.distributed with identify.IdentifiedGrid): blocks
and continuation waves give the single-process complex, bit for bit, for the closed Klein
bottle, the Moebius band and the torus of angles; blocks that end on a seam, blocks one cube
thick at it, a block holding both sides of a seam, blocks across the mirror line of a
reversed axis; records merged in any order."""

from types import SimpleNamespace

import numpy as np
import pytest

from gcmh_core import InputError, extract
from gcmh_core._validate import as_periodic, prepare
from gcmh_core.continuation import as_starts
from gcmh_core.examples import load_example
from gcmh_core.grid import PERTURBATION
from gcmh_core.identify import IdentifiedGrid, identified_axes

distributed = pytest.importorskip("distributed")

from test_distributed import _assert_identical  # noqa: E402  (rootdir-style import; `cluster`: conftest.py)

from gcmh_core import distributed as gd  # noqa: E402

KLEIN = load_example("klein-bottle-closed")  # s:flip=t, t
MOEBIUS = load_example("moebius-band")  # s:flip=t (t not glued)
TORUS = load_example("torus-angles")  # s, t
# (axis 3 is s, axis 4 is t; divs even along t, which a flip needs)
DIVS = {"klein": (KLEIN, [8, 8, 4, 8, 8]), "moebius": (MOEBIUS, [12, 12, 6, 12, 4]),
        "torus": (TORUS, [10, 10, 4, 9, 8])}


def _setup(ex, div, seed=0):
    """What `extract` hands `run_distributed` for an example with its glued axes."""
    n, k, bounds, d, system, _ = prepare(ex.formulas, ex.variables, None, None, ex.bounds, div, None)
    spec = as_periodic(ex.periodic, ex.variables, d)
    return n, k, bounds, d, system, spec, identified_axes(bounds, d, seed, PERTURBATION, spec)


def _single(ex, div, method, seed=0):
    start = ex.start if method in ("gcch", "ccs") else None
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic, method=method,
                   seed=seed, start=start)


def _on_cluster(ex, div, method, address, block=None, seed=0):
    n, k, bounds, d, system, spec, axes = _setup(ex, div, seed)
    starts = as_starts(ex.start, n) if method in ("gcch", "ccs") else None
    return gd.run_distributed(method, n, k, axes, bounds, system, None, starts, address, block, None, None,
                              spec=spec)


def _blocks_here(ex, div, method, block, seed=0, reverse=False):
    """The blocks' tasks run in this process, their records merged by the client's grid
    (in reverse order if asked): what a cluster does, without one."""
    n, k, bounds, d, system, spec, axes = _setup(ex, div, seed)
    client = IdentifiedGrid(n, k, axes, method, spec=spec, bounds=bounds)
    template = gd._new_grid(n, k, axes, method, gd._identification(spec, bounds, None))
    packed = []
    for lo, hi in gd._blocks(d, np.minimum(np.broadcast_to(block, (n,)), d)):
        task = template.empty_copy()
        task.process_block(task.block_values(system, lo, hi), lo, hi)
        packed.append(task.packed_records())
    for records in packed[::-1] if reverse else packed:
        client.add_records(records)
    return client.assemble()


@pytest.mark.parametrize("name, blocks", [
    # whole s in one block (both sides of its seam) / one cube thick along s / uneven: across t's mirror line
    ("klein", [[8, 8, 4, 8, 3], [8, 8, 4, 1, 8], [3, 5, 3, 3, 3]]),
    ("moebius", [[12, 12, 6, 12, 3], [12, 12, 6, 1, 4], [5, 7, 4, 5, 3]]),
    ("torus", [[10, 10, 4, 9, 3], [10, 10, 4, 1, 8], [4, 6, 3, 4, 3]]),
])
@pytest.mark.parametrize("method", ["gcmh", "cms"])
def test_blocks_in_any_order_give_the_single_process_bytes(name, blocks, method):
    ex, div = DIVS[name]
    single = _single(ex, div, method)
    assert single.euler_characteristic() == 0 and single.counts()[0] > 0
    for i, block in enumerate(blocks):
        _assert_identical(single, _blocks_here(ex, div, method, block, reverse=i % 2 == 1))


def test_another_seed_and_div_in_reverse_order():
    div = [12, 12, 6, 10, 12]
    single = _single(KLEIN, div, "gcmh", seed=3)
    _assert_identical(single, _blocks_here(KLEIN, div, "gcmh", [5, 5, 5, 4, 5], seed=3, reverse=True))


def test_a_seam_reversing_two_axes():
    """Three mirrored frames (t, u, both): which frame's copy of a vertex is kept does not
    depend on the order in which blocks come back."""
    ex = SimpleNamespace(formulas=["x - cos(s/2)*t - sin(s/2)*u", "t^2 + u^2 - 0.25"], variables=["x", "s", "t", "u"],
                         bounds=[[-1, 1], [0, "2*pi"], [-0.6, 0.6], [-0.6, 0.6]], periodic=["s:flip=t,u"])
    div = [7, 12, 10, 6]
    for method in ("gcmh", "cms"):
        single = _single(ex, div, method)
        assert (single.euler_characteristic(), len(single.boundary_facets())) == (0, 0)
        _assert_identical(single, _blocks_here(ex, div, method, [2, 12, 3, 5], reverse=True))


def test_seam_values_are_copies_of_the_identified_vertices():
    """A block ending on both seams of the Klein bottle: line d of s holds line 0's values
    with t reversed, line d of t holds line 0's; the rest is F evaluated there."""
    n, k, bounds, d, system, spec, axes = _setup(KLEIN, [6, 6, 4, 6, 8])
    grid = IdentifiedGrid(n, k, axes, spec=spec, bounds=bounds)
    whole = grid.block_values(system, np.zeros(n, np.int64), d)
    lo, hi = np.array([2, 1, 0, 4, 5]), d.copy()
    block = grid.block_values(system, lo, hi)
    assert block.tobytes() == whole[2:, 1:, :, 4:, 5:].tobytes()
    assert whole[:, :, :, -1, :].tobytes() == whole[:, :, :, 0, ::-1].tobytes()
    assert whole[..., -1, :].tobytes() == whole[..., 0, :].tobytes()
    inner = system.evaluate_grid([ax[:-1] if a >= 3 else ax for a, ax in enumerate(axes)])
    assert whole[:, :, :, :-1, :-1].tobytes() == inner.tobytes()


@pytest.mark.parametrize("name, blocks", [
    ("klein", [[4, 4, 4, 4, 4], [3, 8, 4, 3, 5]]),  # ending exactly at the seams / across t's mirror line
    ("moebius", [[6, 6, 6, 6, 2], [5, 12, 6, 5, 3]]),
    ("torus", [[5, 5, 4, 3, 4], [4, 10, 4, 4, 3]]),
])
def test_blocks_through_the_cluster(cluster, name, blocks):
    address = cluster[0].scheduler_address
    ex, div = DIVS[name]
    for method, some in (("gcmh", blocks), ("cms", blocks[1:])):  # (cms: its frames as gcmh's, one size)
        single = _single(ex, div, method)
        for block in some:
            cx = _on_cluster(ex, div, method, address, block)
            _assert_identical(single, cx)
            assert cx.meta["blocks"] > 1


@pytest.mark.parametrize("name, method", [("klein", "gcch"), ("moebius", "gcch"), ("torus", "gcch"),
                                          ("moebius", "ccs")])
def test_continuation_waves_through_the_cluster(cluster, monkeypatch, name, method):
    monkeypatch.setattr(gd, "LOCAL_WAVE", 8)  # send the waves of these small runs to the workers
    monkeypatch.setattr(gd, "MIN_CHUNK", 4)
    ex, div = DIVS[name]
    single = _single(ex, div, method)
    cx = _on_cluster(ex, div, method, cluster[0].scheduler_address)
    _assert_identical(single, cx)
    assert cx.meta["tasks"] > 2 and cx.meta["visited_cubes"] == single.meta["visited_cubes"]
    assert cx.euler_characteristic() == 0


def test_sampled_values_with_glued_axes_are_refused():
    n, k, bounds, d, system, spec, axes = _setup(TORUS, [6, 6, 4, 6, 6])
    sampled = np.zeros((*(d + 1).tolist(), k))
    with pytest.raises(InputError, match="periodic axes need F as formulas"):
        gd.run_distributed("gcmh", n, k, axes, bounds, None, sampled, None, "local", None, None, None, spec=spec)


def test_extract_with_a_scheduler_and_glued_axes(cluster):
    """The public door: extract(..., periodic=, scheduler=) gives the single-process bytes (the closed Klein
    bottle: chi 0, no boundary)."""
    ex, div = DIVS["klein"]
    single = _single(ex, div, "gcmh")
    cx = extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic,
                 scheduler=cluster[0].scheduler_address, block=4)
    _assert_identical(single, cx)
    assert cx.meta["blocks"] > 1 and cx.euler_characteristic() == 0 and cx.boundary_facets().size == 0
