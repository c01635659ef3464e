"""Two edges with the same ends and no lens between them are made distinct (issue 13, item 2):
`gcmh_core._regular.subdivide_double_edges` halves the later one; chi is unchanged."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from gcmh_core import CellComplex
from gcmh_core._regular import subdivide_double_edges


def test_a_circle_of_two_edges_gets_a_third_vertex():
    vertices = np.array([[0.0, 0.0], [1.0, 0.0]])
    edges = np.array([[0, 1], [1, 0]])
    v, e, cells, halved = subdivide_double_edges(vertices, edges, {})
    assert halved == 1 and len(v) == 3 and e.tolist() == [[0, 1], [1, 2], [2, 0]]
    assert np.allclose(v[2], [0.5, 0.0])
    assert CellComplex(2, 1, v, e).euler_characteristic() == 0


def test_both_halves_bound_the_cells_that_had_the_edge():
    # two triangles 0-1-2 and 0-1-3 glued along two different edges joining 0 and 1 (a pillow's seam)
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0]], float)
    edges = np.array([[0, 1], [1, 2], [2, 0], [1, 0], [1, 3], [3, 0]])
    cells = {2: (np.array([0, 3, 6]), np.array([0, 1, 2, 3, 4, 5]))}
    v, e, out, halved = subdivide_double_edges(vertices, edges, cells)
    assert halved == 1
    offsets, faces = out[2]
    assert sorted(faces[offsets[1]:offsets[2]].tolist()) == [3, 4, 5, 6]
    assert faces[offsets[0]:offsets[1]].tolist() == [0, 1, 2]
    before = CellComplex(3, 1, vertices, edges, cells).euler_characteristic()
    assert CellComplex(3, 1, v, e, out).euler_characteristic() == before


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.lists(st.tuples(st.integers(0, 5), st.integers(0, 5)).filter(lambda t: t[0] != t[1]), min_size=1,
                max_size=14))
def test_no_two_edges_share_their_ends_after_and_chi_holds(pairs):
    vertices = np.random.default_rng(len(pairs)).normal(size=(6, 3))
    edges = np.array(pairs, np.int64)
    v, e, _, halved = subdivide_double_edges(vertices, edges, {})
    ends = np.sort(e, axis=1)
    assert len(np.unique(ends, axis=0)) == len(ends)
    assert halved == len(edges) - len(np.unique(np.sort(edges, axis=1), axis=0))
    assert len(v) - len(e) == len(vertices) - len(edges)
