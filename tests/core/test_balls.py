"""Cells that are balls (issue 13, item 1): a piece of M_A inside a cube that M_A joins
through the cube's interior, while it meets the cube's faces in several spheres (a thin
tube along the cube's diagonal is an annulus there), is no GCMH cell.  The engine
detects every such piece (meta["non_ball_cells"], the CLI's summary); representing it
by cells is not built yet: those tests are marked xfail (strict) and name the case.
"""

import numpy as np
import pytest

from gcmh_core import extract

from naive import structure_problems

TUBE = "(x - (x+y+z)/3)^2 + (y - (x+y+z)/3)^2 + (z - (x+y+z)/3)^2 - 0.04"
BOX = [(-1, 1)] * 3
NOT_BUILT = "issue 13 item 1: non-ball pieces are detected, not yet split into cells"


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


def test_one_cube_gcmh_reports_the_piece_that_is_not_a_ball():
    cx = one_cube("gcmh")
    assert cx.meta["non_ball_cells"] == 1  # two discs that M joins through the cube
    assert one_cube("cms").meta["non_ball_cells"] == 0


@pytest.mark.xfail(strict=True, reason=NOT_BUILT)
def test_one_cube_gcmh_is_an_annulus():
    cx = one_cube("gcmh")
    assert cx.euler_characteristic() == 0 and cx.connected_components() == 1


def tube(method, div):
    start = "auto" if method in ("gcch", "ccs") else None
    return extract([TUBE], BOX, div, variables="x,y,z", method=method, start=start)


@pytest.mark.parametrize("method", ["gcmh", "gcch"])
@pytest.mark.parametrize("div", [8, 12, 16])
def test_tube_is_one_annulus_like_cms(method, div):
    cms = tube("cms", div)
    assert cms.euler_characteristic() == 0 and cms.connected_components() == 1
    cx = tube(method, div)
    if cx.meta["non_ball_cells"]:  # at div 8 the tube passes along 8 cubes' diagonals
        assert div == 8
        pytest.xfail(NOT_BUILT)
    assert cx.euler_characteristic() == 0 and cx.connected_components() == 1
    assert structure_problems(cx, BOX, div) == []


def test_tube_at_div_8_is_reported():
    assert tube("gcmh", 8).meta["non_ball_cells"] == 8
    assert tube("gcch", 8).meta["non_ball_cells"] == 8


def test_cli_summary_names_the_events():
    from gcmh_core.cli import _summary

    cx = one_cube("gcmh")
    s = _summary(cx, {"div": [1, 1, 1], "method": "gcmh", "name": None}, [])
    assert s["non_ball_cells"] == 1 and s["degenerate"] == 0
