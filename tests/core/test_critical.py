"""Critical values found wherever they are (issue 25, item 4): the critical points of M are solved
for from the cubes M crosses (`gcmh_core.critical`), not read off the vertices that happen to land
near them."""

import numpy as np
import pytest

from gcmh_core import critical, extract
from gcmh_core.examples import load_example
from gcmh_core.formula import parse_system


def _run(name, div, **params):
    ex = load_example(name)
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, params=params)


@pytest.mark.parametrize("div", [5, 7, 8, 12, 13, 16, 21, 32])
def test_the_cone_is_flagged_at_every_div(div):
    cx = _run("hyperboloid", div, a=0)
    (point,) = cx.meta["critical_points"]
    assert np.allclose(point["x"], 0.0, atol=1e-9) and point["rank"] == 0
    assert cx.meta["singular_vertices"] > 0  # (the app's and the CLI's notice)


@pytest.mark.parametrize("div", [7, 13, 32])
@pytest.mark.parametrize("a", [0.3, -0.3])
def test_no_notice_away_from_the_critical_value(a, div):
    cx = _run("hyperboloid", div, a=a)
    assert cx.meta["critical_points"] == [] and cx.meta["singular_vertices"] == 0


@pytest.mark.parametrize("div", [9, 16])
def test_the_cusp_of_the_milnor_fibre(div):
    """k = 2: z^2 + w^3 = 0 in C^2 = R^4 is singular at the origin, where the real 2 x 4 Jacobian
    vanishes (rank 0); t = 0.1 is a regular value.  (A degenerate critical point, w^3: Newton
    converges to it linearly, so it is located to a small fraction of a cube, not to rounding.)"""
    (point,) = _run("milnor-fibre", div, t=0).meta["critical_points"]
    assert np.allclose(point["x"], 0.0, atol=0.01 * 2 / div) and point["rank"] == 0
    assert _run("milnor-fibre", div, t=0.1).meta["critical_points"] == []


def test_a_rank_drop_of_one_and_any_scale():
    """A cone in R^4 cut by a hyperplane (k = 2): at the origin J = [[0, 0, 0, 0], [-0.1, 0, 0, 1]]
    has rank 1.  Each component may have any scale: the same point with them times 1e6 and 1e-6."""
    bounds, div = np.array([(-1.0, 1.0)] * 4), np.full(4, 10)
    texts = ["x1^2 + x2^2 - x3^2 - x4^2", "x4 - 0.1*x1"]
    cx = extract(texts, bounds, 10)
    plain = critical.critical_points(parse_system(texts, "x1,x2,x3,x4"), cx.vertices, bounds, div)
    scaled = critical.critical_points(parse_system(["1e6*(" + texts[0] + ")", "1e-6*(" + texts[1] + ")"],
                                                   "x1,x2,x3,x4"), cx.vertices, bounds, div)
    assert len(plain) == len(scaled) == 1 and np.allclose(plain[0]["x"], scaled[0]["x"], atol=1e-9)
    assert np.allclose(plain[0]["x"], 0.0, atol=1e-9) and plain[0]["rank"] == scaled[0]["rank"] == 1


def test_cli_names_the_critical_value(capsys):
    from gcmh_core.cli import main

    assert main(["extract", "--example", "hyperboloid", "--param", "a=0", "--div", "13"]) == 0
    assert "notice:" in capsys.readouterr().out
    assert main(["extract", "--example", "hyperboloid", "--param", "a=0.3", "--div", "13"]) == 0
    assert "notice:" not in capsys.readouterr().out


@pytest.mark.parametrize("div", [5, 7, 9, 11, 13, 17, 23])
@pytest.mark.parametrize("name, texts, bounds, where", [
    # F vanishes to higher order at the point: Newton converges linearly there (`critical._STEPS`)
    ("a torus pinched to a point", ["(x^2 + y^2 + z^2)^2 - (x^2 + y^2) + 0*a"], [(-1.2, 1.2)] * 3, (0, 0, 0)),
    ("two spheres touching", ["(x^2 + y^2 + z^2 - 1)*((x - 2)^2 + y^2 + z^2 - 1) + 0*a"],
     [(-1.5, 3.5), (-1.5, 1.5), (-1.5, 1.5)], (1, 0, 0)),
])
def test_degenerate_critical_points_are_found_at_every_div(name, texts, bounds, where, div):
    """Where no grid vertex lands near the point (all these divs but one), the solve still reaches it,
    and the run counts at least one vertex near it, so every notice that reads singular_vertices shows."""
    cx = extract(texts, bounds, div, variables=["x", "y", "z"], params={"a": 0.0})
    (point,) = cx.meta["critical_points"]
    spacing = max(hi - lo for lo, hi in bounds) / div
    assert np.allclose(point["x"], where, atol=0.01 * spacing) and point["rank"] == 0
    assert cx.meta["singular_vertices"] > 0
