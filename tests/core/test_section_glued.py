"""gcmh_core.section on glued (periodic) domains: the section of the glued space, cut along a periodic
variable, a variable reversed across a seam, or an oblique direction where its levels are sets of the
glued space: the topology of the true section, valid closed complexes, points on the levels."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_section import assert_valid  # (rootdir-style import, as test_properties does)

from gcmh_core import InputError, extract
from gcmh_core.examples import load_example
from gcmh_core.homology import homology
from gcmh_core.section import Sectioner, section, section_profile, section_summary

TAU = 2 * np.pi
GRAPH = ["w - 0.4*cos(a)*cos(b)*sin(c)"]          # a graph over the angles (a, b, c): one copy of their space
ANGLES = [(0, TAU), (0, TAU), (0, TAU), (-1, 1)]


@pytest.fixture(scope="module")
def three_torus():
    """T^3: the graph over three periodic angles."""
    return extract(GRAPH, ANGLES, [8, 8, 8, 6], variables=list("abcw"), periodic=["a", "b", "c"])


@pytest.fixture(scope="module")
def klein_circle():
    """K x S^1: crossing a = 2pi reverses b (cos(-b) = cos(b), so F is the same there), c a circle."""
    return extract(GRAPH, ANGLES, [8, 8, 8, 6], variables=list("abcw"), periodic=["a:flip=b", "b", "c"])


def example(name, div):
    ex = load_example(name)
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic)


@pytest.fixture(scope="module")
def klein():
    return example("klein-bottle-closed", [20, 20, 10, 20, 20])


@pytest.fixture(scope="module")
def band():
    return example("moebius-band", [24, 24, 8, 24, 8])


@pytest.fixture(scope="module")
def torus_angles():
    return example("torus-angles", 12)


def topology(sec):
    return sec.euler_characteristic(), sec.connected_components(), int(sec.boundary_facets().size)


def in_box(cx, sec):
    B = np.asarray(cx.meta["bounds"], dtype=float)
    return np.all((sec.vertices >= B[:, 0] - 1e-9) & (sec.vertices <= B[:, 1] + 1e-9))


# ------------------------------------------------------------------------------------ along periodic axes
@pytest.mark.parametrize("axis", ["a", "b", "c"])
@pytest.mark.parametrize("c", [0.0, 0.4, np.pi, 4.0, TAU - 0.05, TAU])
def test_the_three_torus_cut_along_a_glued_angle_is_a_two_torus(three_torus, axis, c):
    """{a = c} of T^3 is one 2-torus, the seam's value c = 0 = 2pi too; its points lie on a = c (mod 2pi)."""
    assert topology(three_torus) == (0, 1, 0)
    sec = section(three_torus, axis, c)
    assert topology(sec) == (0, 1, 0) and sec.dim == 2
    assert_valid(sec, closed=True)
    i = "abcw".index(axis)
    off = np.mod(sec.vertices[:, i] - c + np.pi, TAU) - np.pi
    assert np.allclose(off, 0, atol=1e-9) and in_box(three_torus, sec)


@pytest.mark.parametrize("u", [[1, 1, 0, 0], [0, 1, -1, 0], [1, 2, 0, 0], [2, 0, 1, 0]])
@pytest.mark.parametrize("t", [0.1, 0.5, 0.83])
def test_oblique_cuts_of_the_three_torus_wind_round_it(three_torus, u, t):
    """a + b = c (or a + 2b = c) is a 2-torus of T^3 whatever c: one piece, chi 0, closed."""
    s = Sectioner(three_torus, np.asarray(u, dtype=float))
    assert s.circle.mode == "shift" and s.circle.period == pytest.approx(TAU)
    lo, hi = s.range()
    sec = s.section(lo + t * (hi - lo))
    assert topology(sec) == (0, 1, 0)
    assert_valid(sec, closed=True)
    h = sec.vertices @ np.asarray(u, dtype=float)
    assert np.allclose(np.mod(h - (lo + t * (hi - lo)) + np.pi, TAU) - np.pi, 0, atol=1e-9)


def test_incommensurate_windings_and_mixed_reversed_axes_are_refused(three_torus, klein_circle):
    with pytest.raises(InputError, match="multiples of one another"):
        Sectioner(three_torus, np.array([1.0, np.sqrt(2), 0, 0]))
    with pytest.raises(InputError, match="reversed across the seam of a"):
        Sectioner(klein_circle, np.array([1.0, 1.0, 0, 0]))
    with pytest.raises(InputError, match="reversed across the seam of a"):
        Sectioner(klein_circle, np.array([0, 1.0, 0, 0.5]))


def test_the_profile_along_a_glued_angle_is_flat(three_torus, torus_angles):
    """Every section of T^3 along an angle is a 2-torus; of the torus of angles along s or t, a circle."""
    prof = section_profile(three_torus, "b", count=25)
    assert np.all(prof.chi == 0) and np.all(prof.pieces == 1) and prof.changes().size == 0
    for axis in ("s", "t"):
        prof = section_profile(torus_angles, axis, count=25)
        assert np.all(prof.chi == 0) and np.all(prof.pieces == 1)


@settings(max_examples=40, deadline=None)
@given(u=st.sampled_from([[1, 0], [0, 1], [1, 1], [1, -1], [1, 2], [2, 1], [-3, 1]]), t=st.floats(0.0, 1.0))
def test_sections_of_the_torus_of_angles_are_closed_curves(torus_angles, u, t):
    """Any level of p s + q t (p, q integers) on the torus of angles: closed curves (chi 0), whose points lie
    on the level round the circle, all in the box."""
    v = np.zeros(5)
    v[3:] = u
    s = Sectioner(torus_angles, v)
    lo, hi = s.range()
    c = lo + t * (hi - lo)
    sec = s.section(c)
    assert sec.count(0) > 0 and sec.euler_characteristic() == 0 and sec.boundary_facets().size == 0
    assert_valid(sec, closed=True)
    assert np.allclose(np.mod(sec.vertices @ v - c + np.pi, TAU) - np.pi, 0, atol=1e-9)
    assert in_box(torus_angles, sec)
    if abs(u[0]) + abs(u[1]) == 1 or sorted(map(abs, u)) == [1, 1]:
        assert sec.connected_components() == 1      # a meridian, a parallel, a (1, +-1) curve


# ------------------------------------------------------------------------------------ reversed across a seam
@pytest.mark.parametrize("c", [0.3, 1.0, 2.5, np.pi - 0.4, 4.0, 5.5])
def test_the_closed_klein_bottle_cut_along_its_angles_gives_circles(klein, c):
    """s = c: the fibre circle (t round its circle); t = c: {t = c} U {t = 2pi - c}, the one set of the
    glued space holding t = c: one circle going twice round s.  Both closed, chi 0, one piece."""
    assert topology(klein) == (0, 1, 0)
    along_s = section(klein, "s", c)
    assert topology(along_s) == (0, 1, 0) and np.allclose(along_s.vertices[:, 3], c)
    along_t = Sectioner(klein, "t")
    assert along_t.circle.mode == "mirror"
    sec = along_t.section(c)
    assert topology(sec) == (0, 1, 0) and "asked" not in sec.meta["section"]
    t = sec.vertices[:, 4]
    assert np.all(np.isclose(t, c) | np.isclose(t, TAU - c))
    assert np.isclose(t, c).any() and np.isclose(t, TAU - c).any()
    assert_valid(along_s, closed=True)
    assert_valid(sec, closed=True)
    assert along_t.section(TAU - c).counts() == sec.counts()     # the same set


@pytest.mark.parametrize("c", [0.0, np.pi, TAU])
def test_at_a_value_the_mirror_fixes_the_cut_moves_just_beside_it(klein, c):
    """t = pi (and t = 0): both levels are one there and no side is kept across the seam; the cut is made
    at the nearest value beyond the edges the fixed value crosses, said in meta, still one circle."""
    sec = section(klein, "t", c)
    info = sec.meta["section"]
    assert info["asked"] == c and info["value"] != c
    assert abs(np.mod(info["value"] - c + np.pi, TAU) - np.pi) < 2 * np.pi / 20   # within a cube of it
    assert topology(sec) == (0, 1, 0)
    assert_valid(sec, closed=True)
    _, summary, line = section_summary(klein, f"t={c!r}")
    assert summary["asked"] == c and "cut at" in line and "chi = 0, 1 piece, closed" in line


@pytest.mark.parametrize("d", [1e-4, -1e-4, 0.05])
def test_beside_the_fixed_value_the_two_levels_are_cut_where_asked(klein, d):
    """t = pi + d: the grid plane t = pi bounds cubes, so no edge crosses it and no edge holds both levels:
    cut where asked, the two levels pi +- d one circle."""
    s = Sectioner(klein, "t")
    assert s.fold_low < 1e-12
    sec = s.section(np.pi + d)
    assert "asked" not in sec.meta["section"] and topology(sec) == (0, 1, 0)
    assert np.allclose(np.abs(sec.vertices[:, 4] - np.pi), abs(d))


@pytest.mark.parametrize("c", [0.05, 0.2, 0.4])
def test_the_glued_moebius_band_cut_across_and_along(band, c):
    """s = c: one segment across the band (chi 1, two ends); t = +-c: one circle twice round the hole."""
    assert band.euler_characteristic() == 0
    across = section(band, "s", c * 10)
    assert topology(across) == (1, 1, 2)
    for v in (c, -c):
        sec = section(band, "t", v)
        assert topology(sec) == (0, 1, 0)
        assert_valid(sec, closed=True)
        assert np.allclose(np.abs(sec.vertices[:, 4]), c)


def test_sections_of_the_klein_bottle_times_a_circle(klein_circle):
    """K x S^1 cut along c: a Klein bottle (Z/2 torsion in H_1); along a: the torus of (b, c); along the
    reversed b: {b = c} U {b = -c} x S^1, a torus."""
    assert topology(klein_circle) == (0, 1, 0)
    kb = section(klein_circle, "c", 1.0)
    assert topology(kb) == (0, 1, 0)
    assert homology(kb, generators=False).torsion[1] == [2]
    for axis, c in (("a", 2.0), ("b", 1.0), ("b", 4.5)):
        sec = section(klein_circle, axis, c)
        assert topology(sec) == (0, 1, 0)
        assert homology(sec, generators=False).torsion[1] == []
        assert_valid(sec, closed=True)


def test_the_command_line_cuts_a_glued_example(tmp_path, capsys):
    from gcmh_core.cli import main

    ex = load_example("torus-angles")
    out = tmp_path / "cut.npz"
    rc = main(["extract", "--example", "torus-angles", "--div", "12", "--section", "s=pi/3", "-o", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "section s = 1.0472: dimension 1" in text and "chi = 0, 1 piece, closed" in text
    from gcmh_core import CellComplex

    cut = CellComplex.load(str(out))
    assert cut.dim == 1 and np.allclose(cut.vertices[:, ex.variables.index("s")], np.pi / 3)


def test_levels_name_every_value_the_section_lies_on(torus_angles, klein, three_torus):
    """Where the app draws its bands: round a circle every c + 2pi k in range; across a reversed seam,
    2pi - c too; an unglued direction, c alone."""
    assert Sectioner(torus_angles, "s").levels(1.0, -0.5, 7.5) == pytest.approx([1.0, 1.0 + TAU])
    assert Sectioner(torus_angles, "x").levels(1.0, -5, 5) == [1.0]
    assert Sectioner(klein, "t").levels(1.0, -0.2, 6.5) == pytest.approx([1.0, TAU - 1.0])
    assert Sectioner(three_torus, np.array([1.0, 1, 0, 0])).levels(0.5, 0, 2 * TAU) == \
        pytest.approx([0.5, 0.5 + TAU])


@pytest.mark.parametrize("which, var, c, level", [
    ("klein", "t", 1.0, "cos(t) - cos(1.0)"),
    ("klein", "t", 2.2, "cos(t) - cos(2.2)"),
    ("band", "t", 0.2, "t**2 - 0.04"),
    ("klein_circle", "b", 1.0, "cos(b) - cos(1.0)"),
])
def test_a_reversed_cut_agrees_with_extracting_its_level_set(request, which, var, c, level):
    """An independent oracle: the same glued domain with one more equation, a function of the glued space
    whose zeros are {var = c} U {var = m - c} (cos(t) - cos(c) round a circle reversed by the seam, t^2 - c^2
    on the band), extracted by GCMH itself: the same chi, pieces and boundary."""
    cx = request.getfixturevalue(which)
    meta = cx.meta
    oracle = extract(list(meta["formulas"]) + [level], meta["bounds"], meta["div"], variables=meta["variables"],
                     periodic=meta["periodic"])
    sec = section(cx, var, c)
    assert oracle.dim == sec.dim
    assert topology(sec) == topology(oracle)
    if sec.dim == 2:
        assert homology(sec, generators=False).betti == homology(oracle, generators=False).betti
