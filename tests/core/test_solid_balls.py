"""Cells that are balls in solids (issue 13, item 1, n - k >= 3): a piece of M_A in a cube that
is not a ball (a thickened tube is a shell S^2 x I; on noisy data, solid tori and discs with
handles) is found by the kernel (pieces of G_H that M_A joins) or, where a cube has at most
`_cost.CHECK_SIMPLICES` Kuhn simplices, by comparing GCMH's Euler characteristic with CMS's
in every open face of every cube; the cube's cells are then replaced by CMS's (`_balls.refine_cube`), and its cells
on faces shared with neighbours by their CMS cells in every incidence.  The truth is CMS on the
same grid."""

import itertools

import numpy as np
import pytest

from gcmh_core import _balls, extract
from gcmh_core.analysis import boundary_components
from gcmh_core.kernels.gcmh import cubes_chunk
from gcmh_core.kernels.tables import cube_tables

from naive import naive_cube_euler_cms, naive_hidden_pieces_cms, naive_records_cube_euler, structure_problems

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

MEAN = "(x1+x2+x3+x4)/4"
TUBE4 = "+".join(f"(x{a}-{MEAN})^2" for a in range(1, 5)) + "-0.04"  # S^2 x R around the diagonal


def topology(cx):
    return cx.euler_characteristic(), cx.connected_components(), boundary_components(cx)


def one_cube(n, method="gcmh"):
    """One n-cube whose corners 0 and 1...1 are negative: M_A is a shell S^(n-2) x I."""
    values = np.ones((2,) * n + (1,))
    values[(0,) * n] = values[(1,) * n] = -1.0
    return extract(values, [(0, 1)] * n, method=method)


@pytest.mark.parametrize("n", [4, 5])
def test_one_cube_shell_is_cms(n):
    cx = one_cube(n)
    assert cx.meta["non_ball_split"] >= 1 and cx.meta["non_ball_left"] == 0
    assert topology(cx) == topology(one_cube(n, "cms")) == (1 + (-1) ** n, 1, 2)
    assert structure_problems(cx, [(0, 1)] * n, 1) == []


@pytest.mark.parametrize("method", ["gcmh", "gcch"])
@pytest.mark.parametrize("div", [6, 8])
def test_tube_in_r4_is_one_shell_like_cms(method, div):
    """Before: one 3-ball per end in each cube the tube runs through (7 components at div 6)."""
    bounds = [(-1, 1)] * 4
    kw = dict(method=method, start="auto" if method == "gcch" else None)
    cx = extract([TUBE4], bounds, div, **kw)
    assert cx.meta["non_ball_left"] == 0 and cx.meta["non_ball_split"] >= div - 1
    assert topology(cx) == topology(extract([TUBE4], bounds, div, method="cms")) == (2, 1, 2)
    assert structure_problems(cx, bounds, div) == []


@settings(max_examples=25, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**31 - 1), div=st.integers(1, 3))
def test_random_samples_in_r4_like_cms(seed, div):
    """Noise in R^4 (k = 1): many cells that are not balls, of every kind; every one is found
    and refined, and the complex is CMS's topology with every cell regular."""
    rng = np.random.default_rng(seed)
    values = rng.normal(size=(div + 1,) * 4 + (1,)) + rng.normal(scale=0.3)
    box = [(0.0, 1.0)] * 4
    cx = extract(values, box)
    assert cx.meta["non_ball_left"] == 0 and cx.meta["cells_checked"]
    assert topology(cx) == topology(extract(values, box, method="cms"))
    assert structure_problems(cx, box, div) == []


@pytest.mark.parametrize("n,k", [(3, 1), (4, 1), (4, 2), (5, 2), (5, 1)])
def test_cube_euler_chunk_matches_naive(n, k):
    rng = np.random.default_rng(n * 10 + k)
    values = rng.normal(size=(3,) * n + (k,))
    if k == 1:  # exact zeros too (the kernels resolve them by simulation of simplicity)
        values[rng.random(values.shape) < 0.1] = 0.0
    tab = cube_tables(n, k)
    strides = np.array([3 ** (n - 1 - a) for a in range(n)], np.int64)
    corner_row = np.array([sum(int(strides[a]) for a in range(n) if c >> a & 1) for c in range(1 << n)], np.int64)
    origins = np.array(list(itertools.product(range(2), repeat=n)), np.int64)
    got, hidden = _balls.cms_cube_euler(tab, values.reshape(-1, k), origins @ strides, corner_row, 0, len(origins))
    assert got.tolist() == [naive_cube_euler_cms(tab, values, o) for o in origins.tolist()]
    assert hidden.tolist() == [naive_hidden_pieces_cms(tab, values, o) for o in origins.tolist()]
    assert np.abs(got).sum() > 0  # (not vacuous)


@pytest.mark.parametrize("n,k,seed,div", [(4, 2, 3, 3), (5, 3, 1, 2), (5, 2, 0, 2)])
def test_hidden_pieces_match_naive(n, k, seed, div):
    """Pieces of M_A inside an open face that reach none of its lower faces (a closed loop inside
    a (k+1)-face: no GCMH vertex, chi 0), on noise where they occur."""
    rng = np.random.default_rng(seed)
    values = rng.normal(size=(div + 1,) * n + (k,)) + rng.normal(scale=0.3)
    tab = cube_tables(n, k)
    strides = np.array([(div + 1) ** (n - 1 - a) for a in range(n)], np.int64)
    corner_row = np.array([sum(int(strides[a]) for a in range(n) if c >> a & 1) for c in range(1 << n)], np.int64)
    origins = np.array(list(itertools.product(range(div), repeat=n)), np.int64)
    _, hidden = _balls.cms_cube_euler(tab, values.reshape(-1, k), origins @ strides, corner_row, 0, len(origins))
    assert hidden.tolist() == [naive_hidden_pieces_cms(tab, values, o) for o in origins.tolist()]
    assert hidden.sum() > 0  # (not vacuous)


@pytest.mark.parametrize("n,k", [(4, 1), (5, 2), (5, 1)])
def test_records_cube_euler_matches_naive(n, k):
    rng = np.random.default_rng(7 * n + k)
    values = rng.normal(size=(3,) * n + (k,))
    tab = cube_tables(n, k)
    dims = np.full(n, 3, np.int64)
    strides = np.array([3 ** (n - 1 - a) for a in range(n)], np.int64)
    corner_row = np.array([sum(int(strides[a]) for a in range(n) if c >> a & 1) for c in range(1 << n)], np.int64)
    origins = np.array(list(itertools.product(range(2), repeat=n)), np.int64)
    keys = origins @ strides
    axes = np.tile(np.linspace(0.0, 1.0, 3), (n, 1))
    records = cubes_chunk(0, len(origins), values.reshape(-1, k), keys, origins, keys, axes, corner_row,
                                   corner_row, tab)[0]
    got = _balls.cube_euler(tab, records, origins, strides, dims)
    assert got.tolist() == naive_records_cube_euler(tab, records, origins, strides, dims).tolist()
    assert np.abs(got).sum() > 0


@pytest.mark.parametrize("n,k", [(4, 1), (5, 2)])
def test_a_flat_piece_counts_the_same_both_ways(n, k):
    """Where M_A is flat in every cube (F affine), every cell is a ball: GCMH's count is CMS's."""
    rng = np.random.default_rng(n + k)
    grid = np.stack(np.meshgrid(*[np.arange(3.0)] * n, indexing="ij"), axis=-1)
    values = grid @ rng.normal(size=(n, k)) + rng.normal(size=k) + 0.5
    tab = cube_tables(n, k)
    strides = np.array([3 ** (n - 1 - a) for a in range(n)], np.int64)
    corner_row = np.array([sum(int(strides[a]) for a in range(n) if c >> a & 1) for c in range(1 << n)], np.int64)
    origins = np.array(list(itertools.product(range(2), repeat=n)), np.int64)
    keys = origins @ strides
    axes = np.tile(np.linspace(0.0, 1.0, 3), (n, 1))
    flat = values.reshape(-1, k)
    records = cubes_chunk(0, len(origins), flat, keys, origins, keys, axes, corner_row, corner_row, tab)[0]
    gcmh = _balls.cube_euler(tab, records, origins, strides, np.full(n, 3, np.int64))
    cms, hidden = _balls.cms_cube_euler(tab, flat, keys, corner_row, 0, len(origins))
    assert gcmh.tolist() == cms.tolist() and (cms != 0).any() and not hidden.any()


def test_replace_refined_cells():
    """(-r, K, S) rows: K's rows go, and an incidence (r + 1, X, K) becomes one per S."""
    e = np.array([[10, 1, 2], [11, 2, 3], [-5, 1, 9], [-6, 9, 2]], np.int64)
    c = np.array([[2, 100], [2, 101]], np.int64)
    inc = np.array([[2, 100, 10], [2, 100, 11], [2, 101, 10], [-1, 10, -5], [-1, 10, -6], [-1, 10, -5]], np.int64)
    e2, c2, inc2 = _balls.replace_refined_cells(e, c, inc)
    assert sorted(e2[:, 0].tolist()) == [-6, -5, 11]
    assert c2.tolist() == c.tolist()
    assert sorted(map(tuple, inc2.tolist())) == [(2, 100, -6), (2, 100, -5), (2, 100, 11), (2, 101, -6), (2, 101, -5)]


def test_refined_keys_follow_a_mirrored_frame():
    """A refined cell's key names its Kuhn simplex: `identify` maps it as CMS's keys."""
    from gcmh_core.identify import IdentifiedGrid, identified_axes

    bounds = np.array([(-1.0, 1.0)] * 3 + [(0.0, 2 * np.pi)])
    spec = ((3, (0,)),)
    axes = identified_axes(bounds, np.array([4, 4, 4, 6]), 0, 0.0, spec)
    grid = IdentifiedGrid(4, 1, axes, spec=spec, bounds=bounds)
    simplex = np.array([(1 * grid.strides[0] + 2 * grid.strides[3]) * 5**4 + 1 + 2 * 5], np.int64)
    keys = _balls.refined_key(simplex)
    mapped = grid._frame_keys(keys, 2, [0])
    assert (mapped < _balls.REFINED_BELOW).all() and mapped.tolist() != keys.tolist()
    assert grid._frame_keys(mapped, 2, [0]).tolist() == keys.tolist()
    far = _balls.refined_key(np.array([6 * grid.strides[3] * 5**4 + 1], np.int64))  # on the seam's far side
    moved, which = grid._seam_keys(far, 1)
    assert which.tolist() == [True] and moved[0] < _balls.REFINED_BELOW and moved[0] != far[0]


def test_refined_on_a_cluster_gives_the_single_process_bytes(cluster):
    kw = dict(variables="x1,x2,x3,x4")
    on = extract([TUBE4], [(-1, 1)] * 4, 6, scheduler=cluster[0].scheduler_address, block=[3, 3, 3, 3], **kw)
    one = extract([TUBE4], [(-1, 1)] * 4, 6, **kw)
    assert on.meta["non_ball_split"] == one.meta["non_ball_split"] > 0 and topology(on) == (2, 1, 2)
    assert np.array_equal(on.vertices, one.vertices) and np.array_equal(on.edges, one.edges)
    for r in (2, 3):
        assert all(np.array_equal(a, b) for a, b in zip(on.cells[r], one.cells[r]))


def random_quadrics(n, k, rng):
    """k random quadratic polynomials in x1..xn (coefficients of a quadratic form ~0.7)."""
    names = [f"x{a}" for a in range(1, n + 1)]
    out = []
    for _ in range(k):
        terms = [f"{rng.normal():.3f}"] + [f"{rng.normal():.3f}*{v}" for v in names]
        terms += [f"{0.7 * rng.normal():.3f}*{a}*{b}" for i, a in enumerate(names) for b in names[i:]]
        out.append("+".join(terms))
    return out


@pytest.mark.parametrize("n,k", [(3, 1), (4, 2), (5, 3), (6, 3), (6, 4)])
@settings(max_examples=6, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**31 - 1), grid_seed=st.integers(0, 3))
def test_random_polynomial_systems_have_cms_topology(n, k, seed, grid_seed):
    """The issue's property: on random polynomial systems and grid seeds every cell is regular
    (no two edges with the same ends, no 2-cell of fewer than three edges, every cell's boundary
    a sphere) and GCMH's chi and components are CMS's (with the check asked for: by default it
    runs for solids up to n = 5)."""
    F = random_quadrics(n, k, np.random.default_rng(seed))
    bounds, div = [(-1, 1)] * n, 3 if n == 6 else 4
    cx = extract(F, bounds, div, seed=grid_seed, check_cells=True)
    cms = extract(F, bounds, div, seed=grid_seed, method="cms")
    assert (cx.euler_characteristic(), cx.connected_components()) == (cms.euler_characteristic(),
                                                                       cms.connected_components())
    assert cx.meta["non_ball_left"] == 0 and cx.meta["cells_checked"] == (n >= 4)
    assert structure_problems(cx, bounds, div) == []


def test_a_piece_with_no_gcmh_vertex_is_found():
    """A piece of M_A that meets no k-face of the grid has no GCMH vertex (paper 3.1), so GCMH
    misses it; the check finds it (the cube's count differs from CMS's) and the cube is refined.
    Random quadrics in R^6, k = 4, seed 5: CMS has chi 3 in 3 pieces; GCMH alone 1 in 2."""
    F = random_quadrics(6, 4, np.random.default_rng(5))
    bounds = [(-1, 1)] * 6
    cms = extract(F, bounds, 3, method="cms")
    on, off = (extract(F, bounds, 3, check_cells=flag) for flag in (True, False))
    assert (on.euler_characteristic(), on.connected_components()) == (cms.euler_characteristic(),
                                                                       cms.connected_components()) == (3, 3)
    assert (off.euler_characteristic(), off.connected_components()) == (1, 2)
    assert on.meta["cells_checked"] and not off.meta["cells_checked"] and on.meta["non_ball_split"] > 0


def test_cli_check_cells(capsys):
    """The cells are checked by default where they can be wrong (n = 4..7), --check-cells checks every
    cube; the summary says whether the check ran."""
    import json

    from gcmh_core.cli import main

    argv = ["extract", "--f", "x1^2+x2^2+x3^2+x4^2-1", "--f", "x5-0.1*x1-0.2*x2", "--f", "x6-0.3*x3+0.1*x4",
            "--n", "6", "--bounds=-1.3:1.3", "--div", "4"]
    assert main(argv) == 0
    assert "topology is not fully checked" not in capsys.readouterr().out
    assert main(argv + ["--check-cells", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["cells_checked"] is True and summary["euler_characteristic"] == 0
    # a surface's tube: its cubes are checked by default, so refined like a solid's (cut into discs
    # only with check_cells=False: `runner.split_non_ball_cells`)
    tube = ["--f", "+".join(f"(x{a}-(x1+x2+x3)/3)^2" for a in (1, 2, 3)) + "-0.04",
            "--f", "x4-0.1*x1+0.05*x2-0.137", "--n", "4", "--bounds=-1:1", "--div", "8,8,8,3"]
    assert main(["extract"] + tube) == 0
    assert "replaced by the simplicial (CMS) cells" in capsys.readouterr().out
    assert main(["extract"] + tube + ["--check-cells"]) == 0
    assert "replaced by the simplicial (CMS) cells" in capsys.readouterr().out


def noise(seed, n, k, div):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(div + 1,) * n + (k,)) + rng.normal(scale=0.3)


@pytest.mark.parametrize("n,k,div", [(4, 2, 3), (5, 3, 2), (6, 4, 2)])
@settings(max_examples=8, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**31 - 1))
def test_surfaces_on_noise_with_the_check_like_cms(n, k, div, seed):
    """Surfaces on noise, check asked for: pieces joined through a cube, cells with handles and
    loops of M_A hidden inside a (k+1)-face (no GCMH vertex: every cube on the face finds them
    and is refined) are all repaired; every cell is regular and chi and components are CMS's."""
    values = noise(seed, n, k, div)
    box = [(0.0, 1.0)] * n
    cx = extract(values, box, check_cells=True)
    cms = extract(values, box, method="cms")
    assert cx.meta["non_ball_left"] == 0 and cx.meta["cells_checked"]
    assert (cx.euler_characteristic(), cx.connected_components()) == (cms.euler_characteristic(),
                                                                       cms.connected_components())
    assert structure_problems(cx, box, div) == []


def test_a_loop_hidden_in_a_face_is_no_part_of_its_arc():
    """Noise in R^5 (k = 3, seed 13), check off: a refined cube's face holds one GCMH edge and a
    loop of M_A with no GCMH vertex; the edge is replaced by its own arc only (before, by the arc
    and the loop: the neighbour's 2-cell had two cycles).  The cube whose loop its unchecked
    neighbour can't have declines and is counted."""
    values = noise(13, 5, 3, 2)
    cx = extract(values, [(0.0, 1.0)] * 5, check_cells=False)
    assert structure_problems(cx, [(0.0, 1.0)] * 5, 2) == []
    assert cx.meta["non_ball_left"] >= 1 and not cx.meta["cells_checked"]
