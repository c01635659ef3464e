"""Topology is the truth test: closed manifolds have the right Euler characteristic,
no boundary facets, and every facet of a top cell lies in one or two top cells."""

import numpy as np
import pytest

from gcmh_core import CellComplex, InputError, extract
from gcmh_core.examples import load_example
from gcmh_core.formula import parse_system
from gcmh_core.grid import perturbed_axes

CLOSED = [
    # name, formulas, variables, bounds, div, Euler characteristic
    ("sphere", ["x^2 + y^2 + z^2 - 1"], "x,y,z", (-1.3, 1.3), 12, 2),
    ("torus", ["(sqrt(x^2 + y^2) - 1)^2 + z^2 - 0.16"], "x,y,z", (-1.6, 1.6), 20, 0),
    ("genus two", ["(x*(x-1)^2*(x-2) + y^2)^2 + z^2 - 0.01"], "x,y,z", [(-0.4, 2.4), (-1, 1), (-0.3, 0.3)],
     [40, 30, 12], -2),
    ("circle in R^3", ["x^2 + y^2 + z^2 - 1", "x + 0.3*y - 0.2*z - 0.1"], "x,y,z", (-1.4, 1.4), 10, 0),
    ("circle in R^2", ["x^2 + 2*y^2 - 1"], "x,y", (-1.5, 1.5), 9, 0),
    ("clifford torus", ["x1^2 + x2^2 - 0.5", "x3^2 + x4^2 - 0.5"], None, (-1, 1), 8, 0),
    ("S^3", ["x1^2 + x2^2 + x3^2 + x4^2 - 1"], None, (-1.3, 1.3), 6, 0),
    ("S^2 in R^4", ["x1^2 + x2^2 + x3^2 + x4^2 - 1", "x4 - 0.2*x1 - 0.1"], None, (-1.3, 1.3), 7, 2),
    ("three-torus", ["x1^2+x2^2-1/4", "x3^2+x4^2-1", "x5^2+x6^2-4"],
     None, [(-0.6, 0.6)] * 2 + [(-1.1, 1.1)] * 2 + [(-2.1, 2.1)] * 2, 4, 0),
]


def _check_complex(cx: CellComplex):
    """Every facet of a top cell is in one or two top cells; edges have two distinct vertices."""
    assert np.all(cx.edges[:, 0] != cx.edges[:, 1])
    cofaces = cx.facet_cofaces()
    assert cofaces.min() >= 1 and cofaces.max() <= 2
    for r in range(2, cx.dim + 1):
        offsets, faces = cx.cells[r]
        assert np.all(np.diff(offsets) >= r + 1)  # an r-cell has at least r+1 facets
        for i in range(min(len(offsets) - 1, 500)):  # no face listed twice in a cell
            f = faces[offsets[i]:offsets[i + 1]]
            assert len(np.unique(f)) == len(f)


@pytest.mark.parametrize("name, formulas, variables, bounds, div, chi", CLOSED, ids=[c[0] for c in CLOSED])
def test_closed_manifolds(name, formulas, variables, bounds, div, chi):
    cx = extract(formulas, bounds, div, variables=variables)
    assert cx.counts()[-1] > 0
    assert cx.euler_characteristic() == chi
    assert len(cx.boundary_facets()) == 0
    assert cx.connected_components() == 1
    _check_complex(cx)


@pytest.mark.parametrize("name, formulas, variables, bounds, div, chi", CLOSED[:6], ids=[c[0] for c in CLOSED[:6]])
def test_vertices_within_a_grid_cell_of_M(name, formulas, variables, bounds, div, chi):
    """Each vertex is a zero of the linear interpolant on a simplex of a grid cube, so it
    lies within a cube's diagonal of M: check by a few Newton steps towards M."""
    cx = extract(formulas, bounds, div, variables=variables)
    system = parse_system(formulas, variables.split(",") if variables else None, n=cx.n)
    h = max((hi - lo) / d for (lo, hi), d in zip(cx.meta["bounds"], cx.meta["div"]))
    x = cx.vertices.copy()
    for _ in range(8):  # Gauss-Newton: x <- x - J^+ F(x)
        F = system.evaluate_points(x)
        J = system.jacobian_points(x)
        x = x - np.einsum("mnk,mk->mn", np.linalg.pinv(J), F)
    assert np.abs(system.evaluate_points(x)).max() < 1e-9
    distance = np.linalg.norm(x - cx.vertices, axis=1)
    assert distance.max() <= h * np.sqrt(cx.n)


@pytest.fixture(scope="module")
def cosine():
    ex = load_example("complex-cosine")
    return lambda div, seed=0: extract(ex.formulas, ex.bounds, div, variables=ex.variables, seed=seed)


def test_complex_cosine_matches_the_authors_count_at_div_5(cosine):
    cx = cosine(5)
    assert cx.count(2) == 97  # the authors' MATLAB code under Octave: 97
    assert cx.euler_characteristic() == 1


def test_complex_cosine_is_a_disc(cosine):
    for div in (5, 10, 20, 40):
        cx = cosine(div)
        assert cx.euler_characteristic() == 1, div
        assert cx.connected_components() == 1
        _check_complex(cx)


def test_complex_cosine_div_10_near_the_authors_count(cosine):
    # At even div the real slice {Im w = 0, Im z = 0} of M lies in grid hyperplanes, so
    # which cubes it enters is decided by the perturbation: counts vary with the seed.
    counts = [cosine(10, seed).count(2) for seed in range(4)]
    assert any(abs(c - 397) <= 0.05 * 397 for c in counts), counts
    assert all(abs(c - 397) <= 0.1 * 397 for c in counts), counts


def test_every_edge_has_two_vertices_where_the_authors_code_merges(cosine):
    for div in (10, 20):
        cx = cosine(div)
        assert cx.edges.shape[1] == 2
        assert np.all(cx.edges[:, 0] != cx.edges[:, 1])
        # an edge is one piece: no two edges of one 2-cell share both endpoints' pair twice
        offsets, faces = cx.cells[2]
        loops_ok = np.diff(offsets) >= 3
        assert loops_ok.all()


def test_same_seed_same_bits_other_seed_same_topology():
    f = ["x1^2 + x2^2 - 0.5", "x3^2 + x4^2 - 0.5"]
    a = extract(f, (-1, 1), 7, seed=3)
    b = extract(f, (-1, 1), 7, seed=3)
    c = extract(f, (-1, 1), 7, seed=4)
    assert a.vertices.tobytes() == b.vertices.tobytes()
    assert np.array_equal(a.edges, b.edges)
    for r in a.cells:
        assert all(np.array_equal(x, y) for x, y in zip(a.cells[r], b.cells[r]))
    assert not np.array_equal(a.vertices, c.vertices)
    assert a.euler_characteristic() == c.euler_characteristic() == 0
    assert len(c.boundary_facets()) == 0


def test_result_does_not_depend_on_slabs(monkeypatch):
    import gcmh_core.sweep as module
    f = ["x^2 + y^2 + z^2 + w^2 - 1", "x + y - z*w"]
    one = extract(f, (-1.2, 1.2), 9, variables="x,y,z,w")
    monkeypatch.setattr(module, "SLAB_VERTICES", 1)  # one cube layer per slab
    many = extract(f, (-1.2, 1.2), 9, variables="x,y,z,w")
    assert one.vertices.tobytes() == many.vertices.tobytes()
    assert np.array_equal(one.edges, many.edges)
    assert all(np.array_equal(one.cells[2][i], many.cells[2][i]) for i in range(2))


def _same_complex(a, b):
    return (a.vertices.tobytes() == b.vertices.tobytes() and np.array_equal(a.edges, b.edges)
            and all(np.array_equal(x, y) for r in a.cells for x, y in zip(a.cells[r], b.cells[r])))


@pytest.mark.parametrize("method", ["gcmh", "gcch", "cms"])
def test_result_does_not_depend_on_threads(method):
    # kernel chunks run on a pool of Python threads sized by numba's per-thread count;
    # one thread, and two extractions at once from two threads, give the same bits
    import threading

    import numba

    f = ["x^2 + y^2 + z^2 + w^2 - 1", "x + y - z*w"]
    kw = dict(variables="x,y,z,w", method=method, start=[0.7, 0, 0.7, 0] if method == "gcch" else None)
    want = extract(f, (-1.2, 1.2), 14, **kw)
    results = {}

    def run(name, threads):
        numba.set_num_threads(threads)  # (this thread only)
        results[name] = extract(f, (-1.2, 1.2), 14, **kw)

    threads = (("one", 1), ("all", numba.config.NUMBA_NUM_THREADS))
    workers = [threading.Thread(target=run, args=(name, t)) for name, t in threads]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    assert _same_complex(want, results["one"]) and _same_complex(want, results["all"])


def test_nonfinite_values_are_no_crossing_and_counted():
    # log of a negative number is NaN: the layer of vertices at x1 < 0 (the boundary
    # lines move inwards, so the grid never holds x1 = 0 exactly)
    bounds, div = [(-1, 3), (-1.5, 1.5), (-1.5, 1.5)], [4, 6, 6]
    cx = extract("log(x1) + x2^2 + x3^2 - 1", bounds, div, seed=1)
    x1 = perturbed_axes(np.array(bounds, float), np.array(div), 1)[0]
    assert cx.meta["nonfinite_vertices"] == 7 * 7 * np.count_nonzero(x1 <= 0) > 0
    assert cx.count(2) > 0
    nan = extract("sqrt(x1) - 1 + 0*x2*x3", [(-1, 2), (-1, 1), (-1, 1)], 6)
    assert nan.meta["nonfinite_vertices"] > 0


def test_sampled_data_4d_scan_and_two_fields():
    axes = [np.linspace(-1.2, 1.2, 9)] * 4
    x, y, z, t = np.meshgrid(*axes, indexing="ij")
    scan = (x**2 + y**2 + z**2 - (0.6 + 0.3 * t) ** 2)[..., None]  # a growing sphere: n=4, k=1
    cx = extract(scan, bounds=(-1.2, 1.2))
    assert cx.n == 4 and cx.k == 1 and cx.count(3) > 0
    assert cx.euler_characteristic() == 2  # S^2 x [a, b]: chi(S^2) chi(I) = 2
    assert len(cx.boundary_facets()) > 0  # the spheres at t = -1.2 and t = 1.2
    axes3 = [np.linspace(-1.5, 1.5, 13)] * 3
    x, y, z = np.meshgrid(*axes3, indexing="ij")
    fields = np.stack([x**2 + y**2 + z**2 - 1, z - 0.3], axis=-1)  # n=3, k=2: a circle
    circle = extract(fields, bounds=(-1.5, 1.5))
    assert circle.euler_characteristic() == 0 and len(circle.boundary_facets()) == 0


def test_bad_arguments_say_what_is_wrong():
    with pytest.raises(InputError, match="div"):
        extract("x1^2 + x2^2 - 1", (-1, 1), 0)
    with pytest.raises(InputError, match="lower bound"):
        extract("x1^2 + x2^2 - 1", [(1, -1), (-1, 1)], 5)
    with pytest.raises(InputError, match="k < n|1 <= k"):
        extract(["x1", "x2"], [(-1, 1), (-1, 1)], 5)
    with pytest.raises(InputError, match="method"):
        extract("x1^2 + x2^2 - 1", (-1, 1), 5, method="nope")
    with pytest.raises(InputError, match="bounds"):
        extract("x1^2 + x2^2 - 1", [(-1, 1)] * 3, 5, variables="x1,x2")

