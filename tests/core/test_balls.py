"""Cells that are balls (issue 13, item 1): a piece of M_A inside a cube that M_A joins
through the cube's interior, while it meets the cube's faces in several loops (a thin
tube along the cube's diagonal is an annulus there), is no GCMH cell.  The kernel finds
every such piece (meta["non_ball_cells"]); for surfaces `gcmh_core._balls` cuts it into
discs with M_A's topology (meta["non_ball_split"]), and what is left is reported
(meta["non_ball_left"], the CLI's summary).  The truth is CMS on the same grid: its cells
are convex polytopes.
"""

import numpy as np
import pytest

from gcmh_core import extract
from gcmh_core.analysis import boundary_components, orient_2cells

from naive import structure_problems

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

TUBE = "(x - (x+y+z)/3)^2 + (y - (x+y+z)/3)^2 + (z - (x+y+z)/3)^2 - 0.04"
BOX = [(-1, 1)] * 3


def topology(cx):
    """What a mathematician checks first: chi, components, orientable, boundary components."""
    return (cx.euler_characteristic(), cx.connected_components(), orient_2cells(cx).consistent,
            boundary_components(cx))


def one_cube(method):
    """One cube whose corners 000 and 111 are negative: M is an annulus around the diagonal."""
    values = np.ones((2, 2, 2, 1))
    values[0, 0, 0] = values[1, 1, 1] = -1.0
    return extract(values, [(0, 1)] * 3, method=method)


def test_one_cube_cms_is_an_annulus():
    cx = one_cube("cms")
    assert cx.euler_characteristic() == 0 and cx.connected_components() == 1
    # two loops of boundary edges, around 000 and 111, each crossing 3 cube edges and 3 face diagonals
    assert len(cx.boundary_facets()) == 12
    assert structure_problems(cx, [(0, 1)] * 3, 1) == []


def test_one_cube_gcmh_is_an_annulus_cut_into_two_discs():
    cx = one_cube("gcmh")
    assert cx.meta["non_ball_cells"] == 1 and cx.meta["non_ball_split"] == 1 and cx.meta["non_ball_left"] == 0
    assert topology(cx) == topology(one_cube("cms")) == (0, 1, True, 2)
    # GCMH's two triangles' six vertices and edges stay; two cuts join the loops, two discs of four or more edges
    assert cx.counts() == [6, 8, 2]
    sizes = sorted(np.diff(cx.polygons()[0]).tolist())
    assert sizes in ([4, 6], [5, 5])
    assert structure_problems(cx, [(0, 1)] * 3, 1) == []
    assert one_cube("cms").meta["non_ball_cells"] == 0


def tube(method, div):
    start = "auto" if method in ("gcch", "ccs") else None
    return extract([TUBE], BOX, div, variables="x,y,z", method=method, start=start)


@pytest.mark.parametrize("method", ["gcmh", "gcch"])
@pytest.mark.parametrize("div", [8, 12, 16])
def test_tube_is_one_annulus_like_cms(method, div):
    cms = tube("cms", div)
    assert topology(cms) == (0, 1, True, 2)
    cx = tube(method, div)
    assert topology(cx) == (0, 1, True, 2)
    assert cx.meta["non_ball_left"] == 0
    assert structure_problems(cx, BOX, div) == []


def test_tube_at_div_8_is_split_where_it_runs_along_diagonals():
    for method in ("gcmh", "gcch"):
        cx = tube(method, 8)
        assert cx.meta["non_ball_cells"] == 8 and cx.meta["non_ball_split"] == 8


def diagonal_torus(method, div=48):
    """A closed torus whose thin tube runs along cube diagonals near the origin.  If a split
    glued one end of a tube with the wrong turn, the torus would come out a Klein bottle."""
    R, r = 2.0, 0.14  # core circle through the origin, tangent (1,1,1) there, in the plane of (1,1,1), (1,-1,0)
    X, Y, Z = "(x + 2/sqrt(2))", "(y - 2/sqrt(2))", "z"
    pu, pv = f"(({X} + {Y} + {Z})/sqrt(3))", f"(({X} - {Y})/sqrt(2))"
    F = f"({X}^2 + {Y}^2 + {Z}^2 + {R * R - r * r})^2 - {4 * R * R}*({pu}^2 + {pv}^2)"
    start = "auto" if method == "gcch" else None
    return extract([F], [(-4.5, 4.5)] * 3, div, variables="x,y,z", method=method, start=start)


@pytest.mark.parametrize("method", ["gcmh", "gcch"])
def test_a_closed_torus_through_diagonals_stays_orientable(method):
    cx = diagonal_torus(method)
    assert cx.meta["non_ball_split"] >= 1 and cx.meta["non_ball_left"] == 0
    assert topology(cx) == topology(diagonal_torus("cms")) == (0, 1, True, 0)
    assert structure_problems(cx, [(-4.5, 4.5)] * 3, 48) == []


@pytest.mark.parametrize("n", [4, 5, 6])
def test_the_tube_lifted_to_higher_n_is_split_too(n):
    """The tube times a point in R^n (k = n - 2): the cells are split in the n-cubes."""
    tube_n = TUBE.replace("x", "x1").replace("y", "x2").replace("z", "x3")
    extra = [f"x{a} - 0.1*x1 + 0.05*x2 - 0.137" for a in range(4, n + 1)]
    bounds = [(-1, 1)] * n
    div = [8, 8, 8] + [2] * (n - 3)
    gcmh = extract([tube_n] + extra, bounds, div)
    cms = extract([tube_n] + extra, bounds, div, method="cms")
    assert gcmh.meta["non_ball_split"] == gcmh.meta["non_ball_cells"] > 0
    assert topology(gcmh) == topology(cms) == (0, 1, True, 2)
    assert structure_problems(gcmh, bounds, div) == []


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**31 - 1), div=st.integers(1, 4))
def test_random_samples_in_r3_split_like_cms(seed, div):
    """Random values (many pieces that are not balls): GCMH's topology is CMS's, every cell regular."""
    rng = np.random.default_rng(seed)
    values = rng.normal(size=(div + 1,) * 3 + (1,)) + rng.normal(scale=0.3)
    box = [(0.0, 1.0)] * 3
    gcmh = extract(values, box)
    assert gcmh.meta["non_ball_left"] == 0 and gcmh.meta["non_ball_split"] == gcmh.meta["non_ball_cells"]
    assert topology(gcmh) == topology(extract(values, box, method="cms"))
    assert structure_problems(gcmh, box, div) == []


def test_cli_summary_names_the_events():
    from gcmh_core.cli import _summary

    cx = one_cube("gcmh")
    s = _summary(cx, {"div": [1, 1, 1], "method": "gcmh", "name": None}, [])
    assert s["non_ball_cells"] == 0 and s["non_ball_split"] == 1 and s["degenerate"] == 0


def test_a_piece_that_cannot_be_split_is_still_reported(monkeypatch):
    from gcmh_core import runner
    from gcmh_core.cli import _summary

    monkeypatch.setattr(runner._balls, "split_joined_pieces", lambda *args: None)
    monkeypatch.setattr(runner._balls, "refine_cube", lambda *args, **kw: None)
    cx = one_cube("gcmh")
    assert cx.meta["non_ball_left"] == 1
    s = _summary(cx, {"div": [1, 1, 1], "method": "gcmh", "name": None}, [])
    assert s["non_ball_cells"] == 1
    from gcmh_core.cli import _human

    job = {"name": "tube", "periodic": None}
    assert "use --method cms, or a finer --div" in _human(s, job)
    # (the simplicial baselines stop at n = 7: in R^8 only a finer grid helps)
    assert "use a finer --div" in _human({**s, "n": 8, "k": 6}, job)
    assert "at 1 place a piece of M" in _human(s, job)
    # a mended cell where the check is partial (n >= 8) does not make the whole topology right
    mended = {**s, "non_ball_cells": 0, "non_ball_split": 1}
    assert "so the topology is right" in _human({**mended, "topology_unchecked": None}, job)
    said = _human({**mended, "n": 8, "k": 4, "topology_unchecked": "in R^8 only the boundaries ..."}, job)
    assert "so those cells are balls now" in said and "topology is right" not in said


def test_cut_keys_follow_a_mirrored_frame():
    """A cut's key -(1 + K room + j) names the cube's cell key K: `identify` maps K like any key."""
    from gcmh_core._balls import cut_key_room
    from gcmh_core.identify import IdentifiedGrid, identified_axes
    from gcmh_core.kernels import tables as _tables

    bounds = np.array([(-1.0, 1.0), (-1.0, 1.0), (0.0, 2 * np.pi)])
    spec = ((2, (0,)),)
    axes = identified_axes(bounds, np.array([4, 4, 6]), 0, 0.0, spec)
    grid = IdentifiedGrid(3, 1, axes, spec=spec, bounds=bounds)
    room = cut_key_room(_tables.cube_tables(3, 1).n_codes[3])
    cell = np.array([grid._encode(np.array([[1, 2, 3]]), (np.array([0]), np.array([5])), 3)[0]])
    cuts = -(1 + cell * room + np.array([0, 1]))
    mapped = grid._frame_keys(cuts, 2, [0])
    assert (mapped < 0).all() and ((-mapped - 1) % room).tolist() == [0, 1]
    assert ((-mapped - 1) // room).tolist() == grid._frame_keys(cell, 3, [0]).tolist() * 2
    assert grid._frame_keys(mapped, 2, [0]).tolist() == cuts.tolist()
    assert grid._seam_keys(cuts, 2)[0].tolist() == cuts.tolist()


@pytest.mark.parametrize("method", ["gcmh", "gcch"])
def test_split_on_a_cluster_gives_the_single_process_bytes(cluster, method):
    """Blocks and waves run on Dask workers split their cubes as one process does."""
    block = [3, 3, 3] if method == "gcmh" else None
    start = "auto" if method == "gcch" else None
    kw = dict(variables="x,y,z", method=method, start=start)
    on = extract([TUBE], BOX, 8, scheduler=cluster[0].scheduler_address, block=block, **kw)
    one = extract([TUBE], BOX, 8, **kw)
    assert on.meta["non_ball_split"] == 8 and topology(on) == (0, 1, True, 2)
    assert np.array_equal(on.vertices, one.vertices) and np.array_equal(on.edges, one.edges)
    assert all(np.array_equal(a, b) for a, b in zip(on.cells[2], one.cells[2]))
