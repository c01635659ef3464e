"""gcmh_core.homology against known spaces, the slow twin (tests/core/naive_homology.py)
and GUDHI (a test dependency; skipped when it is not installed)."""

import sys

import numpy as np
import pytest
from naive_homology import (
    RP2,
    boundary_matrices,
    boundary_of_boundary,
    cone_triangulation,
    naive_homology,
    rank_mod2,
    simplicial_complex,
)

from gcmh_core import CellComplex, InputError, extract
from gcmh_core.examples import load_example
from gcmh_core.homology import Homology, homology, incidences, summary, summary_line

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

QUICK = settings(max_examples=25, deadline=None, derandomize=True,
                 suppress_health_check=[HealthCheck.too_slow])


def example(name, div):
    ex = load_example(name)
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic or None,
                   params=ex.param_values() or None)


# small grids: the topology is already right there, and the tests stay quick
EXAMPLES = {
    "klein-bottle-closed": ([12, 12, 6, 12, 12], [1, 1, 0], [1, 2, 1], [[], [2], []]),
    "moebius-band": ([16, 16, 6, 16, 4], [1, 1, 0], [1, 1, 0], [[], [], []]),
    "sphere": (8, [1, 0, 1], [1, 0, 1], [[], [], []]),
    "torus": ([16, 16, 6], [1, 2, 1], [1, 2, 1], [[], [], []]),
    "torus-angles": ([12, 12, 6, 12, 10], [1, 2, 1], [1, 2, 1], [[], [], []]),
    "pentagon-linkage": (8, [1, 8, 1], [1, 8, 1], [[], [], []]),
    "genus-two": ([26, 16, 10], [1, 4, 1], [1, 4, 1], [[], [], []]),
    "three-torus": (5, [1, 3, 3, 1], [1, 3, 3, 1], [[], [], [], []]),
    "three-sphere": (6, [1, 0, 0, 1], [1, 0, 0, 1], [[], [], [], []]),
}


@pytest.fixture(scope="module")
def results():
    return {name: example(name, spec[0]) for name, spec in EXAMPLES.items()}


def check_generators(cx, h, ranks=None):
    """Each generator is a cycle; the free ones are independent modulo boundaries over Q;
    one of order s is a boundary s times over Q and (s even) not a boundary mod 2.  (The
    ranks are dense: checked on complexes of at most 400 cells a dimension unless asked.)"""
    if ranks is None:
        ranks = max(cx.counts()) <= 400
    D = boundary_matrices(cx) + [np.zeros((cx.count(cx.dim), 0), dtype=np.int64)]
    for q, cycles in enumerate(h.generators):
        assert len(cycles) == h.betti[q] + len(h.torsion[q])
        assert sorted(c.order for c in cycles if c.order) == h.torsion[q]
        vectors = []
        for c in cycles:
            z = np.zeros(cx.count(q), dtype=np.int64)
            z[c.cells] = c.coefficients
            assert c.dim == q and np.all(c.coefficients != 0)
            if q > 0:
                assert not (D[q] @ z).any(), f"H{q} generator is not a cycle"
            vectors.append(z)
        if not ranks:
            continue
        image = D[q + 1]
        r = np.linalg.matrix_rank(image.astype(float)) if image.size else 0
        free = [z for z, c in zip(vectors, cycles) if c.order == 0]
        if free:
            assert np.linalg.matrix_rank(np.column_stack([image, *free]).astype(float)) == r + len(free)
        for z, c in zip(vectors, cycles):
            if c.order:
                assert np.linalg.matrix_rank(np.column_stack([image, z]).astype(float)) == r
                if c.order % 2 == 0:
                    assert rank_mod2(np.column_stack([image, z])) == rank_mod2(image) + 1


@pytest.mark.parametrize("name", list(EXAMPLES))
def test_examples(results, name):
    cx = results[name]
    h = homology(cx)
    _, betti, betti2, torsion = EXAMPLES[name]
    assert (h.betti, h.betti_mod2, h.torsion) == (betti, betti2, torsion)
    assert h.euler_characteristic == cx.euler_characteristic()
    check_generators(cx, h)
    # the Morse complex is small: at most a few cells beyond the Betti numbers
    assert sum(h.critical) <= sum(betti2) + 4


def test_klein_bottle_as_the_issue_says(results):
    h = homology(results["klein-bottle-closed"])
    assert h.as_dict() == {"betti": [1, 1, 0], "betti_mod2": [1, 2, 1], "torsion": [[], [2], []]}
    assert h.describe() == "H0 = Z, H1 = Z + Z/2, H2 = 0"
    d, line = summary(results["klein-bottle-closed"])
    assert d == h.as_dict() and "H1 = Z + Z/2" in line and "mod 2 Betti 1, 2, 1" in line
    assert summary_line(d) == line
    assert summary_line({"error": "2-cell 0 is not a ball"}) == "homology: not computed: 2-cell 0 is not a ball"


@pytest.mark.parametrize("name", ["klein-bottle-closed", "moebius-band"])
def test_orientation_cycle_on_non_orientable_surfaces(results, name):
    cx = results[name]
    loop = homology(cx).orientation_cycle
    assert loop is not None and loop.size
    # a Z/2 cycle relative to the boundary: every vertex off the boundary meets an even number of its edges
    # (on the Moebius band it is an arc across the band)
    degree = np.bincount(np.asarray(cx.edges)[loop].ravel(), minlength=cx.count(0))
    on_boundary = np.zeros(cx.count(0), dtype=bool)
    on_boundary[np.asarray(cx.edges)[cx.boundary_facets()].ravel()] = True
    assert not (degree[~on_boundary] % 2).any()
    assert on_boundary.any() == (name == "moebius-band")


@pytest.mark.parametrize("name", ["torus", "sphere", "torus-angles", "three-torus"])
def test_no_orientation_cycle_on_orientable_results(results, name):
    assert homology(results[name]).orientation_cycle is None


@pytest.mark.parametrize("name", ["klein-bottle-closed", "moebius-band", "torus"])
def test_orientation_cycle_reverses_orientation(results, name):
    """The orientation runs each interior edge both ways, except on the w1 loop, whose edges
    its two polygons run the same way: the normals flip there and nowhere else."""
    cx = results[name]
    h = homology(cx)
    off, fac = cx.cells[2]
    signs = incidences(cx)[2]
    first = np.asarray(off)[:-1]
    # h.orientation is the sense of each cell's first edge; the incidences give the others
    eps = np.repeat(h.orientation * signs[first], np.diff(off))
    total = np.zeros(cx.count(1), dtype=np.int64)
    np.add.at(total, np.asarray(fac), eps * signs)
    on_two = np.bincount(np.asarray(fac), minlength=cx.count(1)) == 2
    loop = np.zeros(cx.count(1), dtype=bool)
    if h.orientation_cycle is not None:
        loop[h.orientation_cycle] = True
    assert np.all(np.abs(total[loop]) == 2)
    assert not total[on_two & ~loop].any()
    assert set(np.unique(h.orientation)) <= {-1, 1}


def test_real_projective_plane_has_torsion():
    cx = simplicial_complex(RP2)
    h = homology(cx)
    assert (h.betti, h.betti_mod2, h.torsion) == ([1, 0, 0], [1, 1, 1], [[], [2], []])
    assert h.orientation_cycle is not None
    check_generators(cx, h)


def test_small_spaces_by_hand():
    circle = simplicial_complex([(0, 1), (1, 2), (0, 2)])
    assert homology(circle).describe() == "H0 = Z, H1 = Z"
    two_points = CellComplex(2, 2, [[0, 0], [1, 1]], np.zeros((0, 2), dtype=np.int64))
    assert homology(two_points).betti == [2]
    assert [len(c) for c in homology(two_points).generators[0]] == [1, 1]
    # the torus from a 3 x 3 grid of squares, each cut into two triangles
    tris = []
    for i in range(3):
        for j in range(3):
            a, b = 3 * i + j, 3 * i + (j + 1) % 3
            c, d = 3 * ((i + 1) % 3) + j, 3 * ((i + 1) % 3) + (j + 1) % 3
            tris += [(a, b, d), (a, c, d)]
    torus = simplicial_complex(tris)
    h = homology(torus)
    assert (h.betti, h.torsion) == ([1, 2, 1], [[], [], []])
    check_generators(torus, h)
    # a bigon (two edges between the same two vertices) and a loop edge: still balls
    bigon = CellComplex(2, 0, [[0, 0], [1, 0]], [[0, 1], [1, 0]], {2: ([0, 2], [0, 1])})
    assert homology(bigon).betti == [1, 0, 0]
    loop = CellComplex(2, 0, [[0, 0]], [[0, 0]], {2: ([0, 1], [0])})
    assert homology(loop).betti == [1, 0, 0]


def test_twisted_three_tori():
    """w = 0.3 in a glued box: T^3, the Klein bottle times a circle, and the mapping torus
    of the half turn of T^2 (identify.py's flips)."""
    cases = {
        ("x", "y", "z"): "H0 = Z, H1 = Z^3, H2 = Z^3, H3 = Z",
        ("x:flip=y", "y", "z"): "H0 = Z, H1 = Z^2 + Z/2, H2 = Z + Z/2, H3 = 0",
        ("x:flip=y,z", "y", "z"): "H0 = Z, H1 = Z + Z/2 + Z/2, H2 = Z, H3 = Z",
    }
    for periodic, expected in cases.items():
        cx = extract("w - 0.3", bounds=[(0, 1)] * 3 + [(-1, 1)], div=[4, 4, 4, 3], variables="x, y, z, w",
                     periodic=list(periodic))
        h = homology(cx)
        assert h.describe() == expected, periodic
        assert (h.betti, h.betti_mod2, h.torsion) == naive_homology(cx)
        check_generators(cx, h)


@QUICK
@given(st.integers(1, 5), st.integers(1, 5), st.integers(0, 2**31 - 1))
def test_smith_transforms(m, n, seed):
    """L A R = diag(s) with L L^-1 = I and R R^-1 = I, s dividing down the diagonal."""
    from gcmh_core.homology import _matmul, _smith

    rng = np.random.default_rng(seed)
    A = rng.integers(-4, 5, (m, n)).tolist()
    s, R, Rinv, Linv, L = _smith([row[:] for row in A], m, n, True)
    D = _matmul(_matmul(L, A, m, m, n), R, m, n, n)
    assert D == [[s[i] if i == j and i < len(s) else 0 for j in range(n)] for i in range(m)]
    assert _matmul(L, Linv, m, m, m) == [[int(i == j) for j in range(m)] for i in range(m)]
    assert _matmul(R, Rinv, n, n, n) == [[int(i == j) for j in range(n)] for i in range(n)]
    assert all(b % a == 0 for a, b in zip(s, s[1:]))


def test_odd_torsion_gets_a_short_loop(monkeypatch):
    """A Moore space M(Z/3, 1) (a disk whose rim winds three times round a circle): its generator of order 3
    is a simple loop that is not a boundary mod 3, shorter than the Smith form's cycle shortened across
    2-cells (what odd torsion kept before, invisible to the masks mod 2)."""
    from homology_naive import moore_space, rank_mod_p

    hmod = sys.modules["gcmh_core.homology"]   # (gcmh_core.homology is also the function's name)
    cx = moore_space(8, 3)
    h = homology(cx)
    assert (h.betti, h.betti_mod2, h.torsion) == ([1, 0, 0], [1, 0, 0], [[], [3], []])
    assert (h.betti, h.betti_mod2, h.torsion) == naive_homology(cx)
    check_generators(cx, h)
    (g,) = h.generators[1]
    assert g.order == 3 and np.all(np.abs(g.coefficients) == 1)
    degree = np.bincount(np.asarray(cx.edges)[g.cells].ravel())
    assert set(degree[degree > 0].tolist()) == {2}
    D1, D2 = boundary_matrices(cx)[1:3]
    z = np.zeros(cx.count(1), dtype=np.int64)
    z[g.cells] = g.coefficients
    assert rank_mod_p(np.column_stack([D2, z]), 3) == rank_mod_p(D2, 3) + 1
    length = hmod._edge_lengths(cx)
    monkeypatch.setattr(hmod, "_loops_read", lambda *args: [])   # no loop for odd torsion: the Smith form's
    (old,) = homology(cx).generators[1]
    assert np.abs(g.coefficients) @ length[g.cells] < 0.6 * (np.abs(old.coefficients) @ length[old.cells])


def test_incidences_square_to_zero(results):
    for name in ("klein-bottle-closed", "three-torus"):
        cx = results[name]
        for r in range(2, cx.dim + 1):
            assert boundary_of_boundary(cx, r) == 0
        signs = incidences(cx)
        assert all(np.isin(s, (-1, 1)).all() for s in signs[1:])


def test_input_is_checked():
    with pytest.raises(InputError, match="needs a CellComplex"):
        homology("torus")
    cx = simplicial_complex([(0, 1, 2)])
    with pytest.raises(InputError, match="True or False"):
        homology(cx, generators="yes")
    # an annulus as one 2-cell: its boundary is two circles, not one
    annulus = CellComplex(2, 0, np.zeros((6, 2)), [[0, 1], [1, 2], [2, 0], [3, 4], [4, 5], [5, 3]],
                          {2: ([0, 6], [0, 1, 2, 3, 4, 5])})
    with pytest.raises(InputError, match="2-cell 0 is not a ball: its boundary has 2 pieces"):
        homology(annulus)
    # a 2-cell with a dangling edge: a vertex on one of its edges only
    fan = CellComplex(2, 0, np.zeros((4, 2)), [[0, 1], [1, 2], [2, 0], [0, 3]], {2: ([0, 4], [0, 1, 2, 3])})
    with pytest.raises(InputError, match="2-cell 0 is not a ball"):
        homology(fan)
    marked = CellComplex(cx.n, cx.k, cx.vertices, cx.edges, cx.cells, {"non_ball_left": 2})
    with pytest.raises(InputError, match="not balls"):
        homology(marked)


# ----------------------------------------------------------------------------
# random inputs: the kernels against the slow twin
# ----------------------------------------------------------------------------

@st.composite
def simplicial(draw):
    """A random simplicial complex on at most 7 vertices, of dimension 1 to 3."""
    top = draw(st.integers(1, 3))
    nv = draw(st.integers(top + 1, 7))
    from itertools import combinations

    faces = list(combinations(range(nv), top + 1))
    chosen = draw(st.lists(st.sampled_from(faces), min_size=1, max_size=14, unique=True))
    return simplicial_complex(chosen, seed=draw(st.integers(0, 9)))


@QUICK
@given(simplicial())
def test_random_simplicial_complexes_against_naive(cx):
    h = homology(cx)
    assert (h.betti, h.betti_mod2, h.torsion) == naive_homology(cx)
    check_generators(cx, h)


def quadric_result(n, k, div, seed):
    rng = np.random.default_rng(seed)
    texts = []
    for _ in range(k):
        q = rng.integers(-2, 3, n)
        lin = rng.normal(size=n).round(3)
        terms = [f"{int(q[a])}*x{a + 1}^2" for a in range(n) if q[a]]
        terms += [f"{float(lin[a])!r}*x{a + 1}" for a in range(n)]
        texts.append(" + ".join(terms + [repr(round(float(rng.normal() * 0.3), 3))]))
    return extract(texts, [(-1.0, 1.0)] * n, div)


SHAPES = [(3, 1, 5), (4, 2, 4), (5, 3, 3), (4, 1, 3)]


@QUICK
@given(shape=st.sampled_from(SHAPES), seed=st.integers(0, 2**31 - 1))
def test_random_results_against_naive(shape, seed):
    cx = quadric_result(*shape, seed)
    if cx.meta.get("non_ball_left", 0) or sum(cx.counts()) > 1500:
        return
    h = homology(cx)
    assert (h.betti, h.betti_mod2, h.torsion) == naive_homology(cx)
    # chi is the alternating sum of the Betti numbers, over Q and over Z/2
    chi = cx.euler_characteristic()
    assert h.euler_characteristic == chi
    assert sum((-1) ** q * b for q, b in enumerate(h.betti_mod2)) == chi
    check_generators(cx, h)


# ----------------------------------------------------------------------------
# GUDHI: Betti numbers of a coned triangulation, over Z/2 and Z/11
# ----------------------------------------------------------------------------

def gudhi_betti(cx, field):
    gudhi = pytest.importorskip("gudhi")
    st_ = gudhi.SimplexTree()
    for s in cone_triangulation(cx):
        st_.insert(list(s))
    st_.compute_persistence(homology_coeff_field=field, persistence_dim_max=True)
    betti = list(st_.betti_numbers())
    return (betti + [0] * (cx.dim + 1))[:cx.dim + 1]


@pytest.mark.parametrize("name", list(EXAMPLES))
def test_examples_against_gudhi(results, name):
    pytest.importorskip("gudhi")
    cx = results[name]
    h = homology(cx, generators=False)
    assert gudhi_betti(cx, 2) == h.betti_mod2
    assert gudhi_betti(cx, 11) == h.betti


@QUICK
@given(shape=st.sampled_from(SHAPES), seed=st.integers(0, 2**31 - 1))
def test_random_results_against_gudhi(shape, seed):
    pytest.importorskip("gudhi")
    cx = quadric_result(*shape, seed)
    if cx.meta.get("non_ball_left", 0):
        return
    h = homology(cx, generators=False)
    assert gudhi_betti(cx, 2) == h.betti_mod2
    assert gudhi_betti(cx, 11) == h.betti


def test_result_type():
    h = homology(simplicial_complex(RP2), generators=False)
    assert isinstance(h, Homology) and h.generators is None and h.orientation_cycle is None
    with pytest.raises(AttributeError):
        h.betti = [0]


def test_short_generators_on_a_torus():
    """The torus of radii 1 and 0.4: the H1 generators are about a meridian (2 pi 0.4) and the
    inner equator (2 pi 0.6), not loops wandering round it; still a basis of H1 over Z/2 and Q."""
    cx = example("torus", [24, 24, 10])
    h = homology(cx)
    X, E = np.asarray(cx.vertices), np.asarray(cx.edges)
    lengths = sorted(float(np.linalg.norm(X[E[c.cells, 0]] - X[E[c.cells, 1]], axis=1) @ np.abs(c.coefficients))
                     for c in h.generators[1])
    assert np.allclose(lengths, [2 * np.pi * 0.4, 2 * np.pi * 0.6], rtol=0.06), lengths
    D = boundary_matrices(cx)
    Z = np.zeros((cx.count(1), 2), dtype=np.int64)
    for i, c in enumerate(h.generators[1]):
        Z[c.cells, i] = c.coefficients
        assert np.all(np.abs(c.coefficients) == 1)   # simple loops
    assert not (D[1] @ Z).any()
    assert rank_mod2(np.column_stack([D[2], Z])) == rank_mod2(D[2]) + 2
    assert np.linalg.matrix_rank(np.column_stack([D[2], Z]).astype(float)) == \
        np.linalg.matrix_rank(D[2].astype(float)) + 2


@pytest.mark.parametrize("name", ["pentagon-linkage", "klein-bottle-closed"])
def test_h1_generators_are_simple_loops(results, name):
    """Each generator (the Klein bottle's of order 2 too) runs once round one loop: every vertex on
    it meets two of its edges."""
    cx = results[name]
    h = homology(cx)
    assert len(h.generators[1]) == h.betti[1] + len(h.torsion[1])
    for c in h.generators[1]:
        assert np.all(np.abs(c.coefficients) == 1)
        degree = np.bincount(np.asarray(cx.edges)[c.cells].ravel())
        assert set(degree[degree > 0].tolist()) == {2}


def test_h2_generators_of_a_three_manifold_are_locally_smallest(results):
    """No 3-cell lets an H2 generator of the three-torus shrink: swapping it across one (z - t d(c))
    never lowers its weighted size (cells first, area second)."""
    from gcmh_core.homology import _cell_weights

    cx = results["three-torus"]
    h = homology(cx)
    weight = _cell_weights(cx, 2)
    D3 = boundary_matrices(cx)[3]
    for c in h.generators[2]:
        z = np.zeros(cx.count(2), dtype=np.int64)
        z[c.cells] = c.coefficients
        size = weight @ np.abs(z)
        for t in (1, -1):
            moved = np.abs(z[:, None] - t * D3)             # every 3-cell at once
            assert (weight @ moved >= size - 1e-9).all()


@pytest.mark.parametrize("name", ["klein-bottle-closed", "moebius-band"])
def test_w1_loop_is_locally_shortest(results, name):
    """Reversing any one 2-cell (which toggles its interior edges on or off the loop) never
    shortens the w1 loop (weighted: edges first, length second)."""
    from gcmh_core.homology import _cell_weights

    cx = results[name]
    loop = homology(cx).orientation_cycle
    weight = _cell_weights(cx, 1)
    off, fac = (np.asarray(a) for a in cx.cells[2])
    count = np.bincount(fac, minlength=cx.count(1))
    on = np.zeros(cx.count(1), dtype=bool)
    on[loop] = True
    for c in range(off.size - 1):
        edges = fac[off[c]:off[c + 1]]
        once = [e for e in edges if count[e] == 2 and (edges == e).sum() == 1]
        assert sum(weight[e] * (-1 if on[e] else 1) for e in once) >= -1e-9
