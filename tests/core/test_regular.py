"""Lens cells (a 2-cell bounded by two edges with the same ends) are collapsed."""

import numpy as np
import pytest

from gcmh_core import CellComplex, extract
from gcmh_core._regular import collapse_lenses
from gcmh_core.examples import load_example


def lens_count(cx):
    if 2 not in cx.cells:
        return 0
    return int((np.diff(cx.cells[2][0]) < 3).sum())


def duplicate_edges(cx):
    return len(cx.edges) - len(np.unique(np.sort(cx.edges, axis=1), axis=0))


def test_a_lens_between_two_squares_collapses():
    # two squares 0-1-2-3 and 0-3-4-5 glued along a lens: edges 3 and 6 both join 0 and 3
    V = np.zeros((6, 3))
    E = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [3, 4], [4, 5], [5, 0]])
    E = np.vstack([E, [[0, 3]]])  # edge 7 joins 0 and 3 again
    cells = {2: (np.array([0, 4, 6, 10]), np.array([0, 1, 2, 3, 3, 7, 7, 4, 5, 6]))}
    cx = CellComplex(3, 1, V, E, cells)
    edges, out, collapsed, left = collapse_lenses(cx.edges, cx.cells)
    fixed = CellComplex(3, 1, V, edges, out)
    assert (collapsed, left) == (1, 0)
    assert fixed.counts() == [6, 7, 2] and fixed.euler_characteristic() == cx.euler_characteristic()
    assert duplicate_edges(fixed) == 0 and lens_count(fixed) == 0
    # the second square now uses the kept edge 3
    assert sorted(fixed.cells[2][1][4:8].tolist()) == [3, 4, 5, 6]


def test_a_lens_that_is_a_whole_disc_becomes_a_triangle():
    """A lens whose edges are in no other 2-cell is a disc of its own (M_A's small cap on the box's
    boundary): collapsing it would leave an edge in no 2-cell and lose a boundary circle."""
    from gcmh_core._regular import subdivide_double_edges
    from gcmh_core.analysis import boundary_components

    V = np.array([[0.0, 0, 0], [1, 0, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]])
    E = np.array([[0, 1], [0, 1], [2, 3], [3, 4], [4, 2]])  # a lens 0-1 and, apart, a triangle
    cells = {2: (np.array([0, 2, 5]), np.array([0, 1, 2, 3, 4]))}
    edges, out, collapsed, left = collapse_lenses(E, cells)
    assert (collapsed, left) == (0, 0) and len(edges) == 5
    V2, E2, out2, halved = subdivide_double_edges(V, edges, out)
    fixed = CellComplex(3, 1, V2, E2, out2)
    assert halved == 1 and fixed.counts() == [6, 6, 2] and lens_count(fixed) == 0 and duplicate_edges(fixed) == 0
    assert fixed.euler_characteristic() == 2 and boundary_components(fixed) == 2
    assert (fixed.facet_cofaces() == 1).all()


def test_lens_faces_leave_their_3_cells():
    E = np.array([[0, 1], [0, 1], [1, 2], [2, 0]])
    cells = {2: (np.array([0, 2, 5, 8]), np.array([0, 1, 0, 2, 3, 1, 2, 3])),
             3: (np.array([0, 3]), np.array([0, 1, 2]))}
    edges, out, collapsed, left = collapse_lenses(E, cells)
    assert (collapsed, left) == (1, 0)
    assert out[3][1].tolist() == [0, 1] and np.array_equal(out[3][0], [0, 2])
    assert len(edges) == 3 and out[2][1].tolist() == [0, 1, 2, 0, 1, 2]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_klein_bottle_default_grid_has_no_lens(seed):
    ex = load_example("klein-bottle")
    cx = extract(ex.formulas, ex.bounds, ex.div, variables=ex.variables, seed=seed)
    assert lens_count(cx) == 0 and duplicate_edges(cx) == 0
    assert cx.meta["lenses_left"] == 0
    assert cx.euler_characteristic() == 1  # the cut-open square: chi as before the collapse
    if seed == 0:
        assert cx.meta["collapsed_lenses"] > 0  # this grid had lenses before (5 at seed 0)


@pytest.mark.parametrize("name, div", [("klein-bottle", 12), ("complex-cosine", 12), ("three-torus", 4),
                                       ("genus-two", [26, 16, 9]), ("whitney-umbrella", 16)])
@pytest.mark.parametrize("method", ["gcmh", "cms"])
def test_no_lens_on_examples(name, div, method):
    ex = load_example(name)
    for seed in (0, 3):
        cx = extract(ex.formulas, ex.bounds, div, variables=ex.variables, seed=seed, method=method)
        assert lens_count(cx) == 0 and duplicate_edges(cx) == 0
