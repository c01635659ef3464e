"""Regular cells at every dimension (issue 25, item 3): what the assembly can't collapse is coned
(`_balls.cone_lens_balls`, after `_regular.subdivide_double_edges`, as `runner.complex_of` runs them).

The complexes here are built by hand, each the smallest of its kind for r = 2..5: two r-cells with
the same boundary (closed: a sphere of two cells, "a pillow"; or the two faces of an (r+1)-cell, a
lens), and an r-cell of three faces whose faces' own faces are three (r-2)-cells with one boundary
(a "theta": at r = 3 three edges with the same two ends and three lens 2-cells, as (8, 3) gave).
Every cell must come out with at least r + 1 faces, no two cells with the same faces, every
boundary a sphere, and chi unchanged."""

import itertools

import numpy as np
import pytest
from naive_balls import naive_same_faces_candidates
from test_regular_high_n import regularity_problems

from gcmh_core._balls import _same_faces, cone_lens_balls
from gcmh_core._regular import subdivide_double_edges
from gcmh_core.complex import CellComplex
from gcmh_core.kernels.cell_check import same_faces_candidates

from naive import structure_problems


class Builder:
    """Cells by name: add(dim, faces) -> name; complex(n) numbers them (vertices at random points)."""

    def __init__(self):
        self.faces: dict = {}
        self.dims: dict = {}

    def add(self, dim, faces=()):
        name = len(self.dims)
        self.dims[name], self.faces[name] = dim, list(faces)
        return name

    def simplex_boundary(self, d):
        """The proper faces of a d-simplex (a regular sphere S^(d-1)): {vertex set: name}, the d-faces
        not included; returns (names of the (d-1)-faces, the dict)."""
        cells = {}
        for size in range(1, d + 1):
            for subset in itertools.combinations(range(d + 1), size):
                faces = [cells[s] for s in itertools.combinations(subset, size - 1)] if size > 1 else []
                cells[subset] = self.add(size - 1, faces)
        return [cells[s] for s in itertools.combinations(range(d + 1), d)], cells

    def complex(self, n, seed=0):
        ids: dict = {}
        by_dim: dict = {}
        for name in sorted(self.dims):
            ids[name] = len(by_dim.setdefault(self.dims[name], []))
            by_dim[self.dims[name]].append(name)
        vertices = np.random.default_rng(seed).normal(size=(len(by_dim[0]), n))
        edges = np.array([[ids[v] for v in self.faces[x]] for x in by_dim.get(1, [])], np.int64).reshape(-1, 2)
        cells = {}
        for r in sorted(by_dim):
            if r >= 2:
                rows = [[ids[y] for y in self.faces[x]] for x in by_dim[r]]
                offsets = np.concatenate([[0], np.cumsum([len(row) for row in rows])]).astype(np.int64)
                cells[r] = (offsets, np.array([y for row in rows for y in row], np.int64))
        return CellComplex(n, n - max(by_dim), vertices, edges, cells)


def pillow(r, lens):
    b = Builder()
    sphere, _ = b.simplex_boundary(r)
    x1, x2 = b.add(r, sphere), b.add(r, sphere)
    if lens:
        b.add(r + 1, [x1, x2])
    return b.complex(r + 3)


def theta(r):
    """An r-cell X of faces A, B1, B2 ((r-1)-cells) on three (r-2)-cells E1, E2, D with one boundary."""
    b = Builder()
    if r == 3:
        u, v = b.add(0), b.add(0)
        e1, e2, d = (b.add(1, [u, v]) for _ in range(3))
    else:
        sigma, _ = b.simplex_boundary(r - 2)
        e1, e2, d = (b.add(r - 2, sigma) for _ in range(3))
    a, b1, b2 = b.add(r - 1, [e1, e2]), b.add(r - 1, [e1, d]), b.add(r - 1, [e2, d])
    b.add(r, [a, b1, b2])
    return b.complex(r + 3)


def regularised(cx):
    vertices, edges, cells, _ = subdivide_double_edges(cx.vertices, cx.edges, cx.cells)
    vertices, edges, cells, coned = cone_lens_balls(vertices, edges, cells)
    return CellComplex(cx.n, cx.k, vertices, edges, cells), coned


@pytest.mark.parametrize("kind,r", [(kind, r) for kind in ("pillow", "lens", "theta") for r in (2, 3, 4, 5)
                                    if (kind, r) != ("theta", 2)])  # (a 2-cell of three faces is a triangle)
def test_every_cell_comes_out_regular(kind, r):
    cx = theta(r) if kind == "theta" else pillow(r, kind == "lens")
    assert regularity_problems(cx) != []  # (the input is what the cone is for)
    out, coned = regularised(cx)
    assert coned > 0
    assert regularity_problems(out) == [] and structure_problems(out) == []
    assert out.euler_characteristic() == cx.euler_characteristic()
    assert out.dim == cx.dim and len(out.cells[out.dim][0]) >= len(cx.cells[cx.dim][0])
    # nothing left to do: the cone of a regular complex is the complex itself
    again, coned_again = regularised(out)
    assert coned_again == 0 and again.counts() == out.counts()


def test_a_lens_keeps_one_face_and_cones_the_other():
    # r = 4: the 5-cell's second face becomes the cones over the 5 tetrahedra of its boundary
    cx = pillow(4, lens=True)
    out, coned = regularised(cx)
    assert coned == 1
    assert np.diff(out.cells[5][0]).tolist() == [1 + 5]
    assert out.counts() == [c + d for c, d in zip(cx.counts(), [1, 5, 10, 10, 5 - 1, 0])]


def test_regular_input_is_returned_as_it_is():
    b = Builder()
    sphere, _ = b.simplex_boundary(4)
    b.add(4, sphere)
    cx = b.complex(6)
    vertices, edges, cells, coned = cone_lens_balls(cx.vertices, cx.edges, cx.cells)
    assert coned == 0 and vertices is cx.vertices and edges is cx.edges and cells is cx.cells


def random_csr(rng, m, n_faces, twins):
    rows = [rng.choice(n_faces, size=rng.integers(2, 6), replace=False) for _ in range(m)]
    for _ in range(twins):  # some rows again, their faces in another order
        rows.insert(int(rng.integers(0, len(rows) + 1)), rng.permutation(rows[int(rng.integers(0, len(rows)))]))
    offsets = np.concatenate([[0], np.cumsum([len(row) for row in rows])]).astype(np.int64)
    return offsets, np.concatenate(rows).astype(np.int64)


@pytest.mark.parametrize("seed", range(6))
def test_same_faces_candidates_matches_naive(seed):
    rng = np.random.default_rng(seed)
    offsets, faces = random_csr(rng, int(rng.integers(1, 300)), int(rng.integers(6, 40)), int(rng.integers(0, 8)))
    got = same_faces_candidates(offsets, faces)
    assert np.array_equal(got, naive_same_faces_candidates(offsets, faces))
    # the twins: every marked cell but the first of each set of faces
    marked = np.flatnonzero(got)
    firsts = {frozenset(faces[offsets[x] : offsets[x + 1]].tolist()): x for x in marked[::-1].tolist()}
    assert _same_faces((offsets, faces)).tolist() == [x for x in marked.tolist() if x not in firsts.values()]
