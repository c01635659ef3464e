"""gcmh_core.section: sections of complexes by hyperplanes have the topology of the true sections and are
valid complexes (checked cell by cell), whatever the value (vertices on the hyperplane included)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gcmh_core import CellComplex, InputError, extract
from gcmh_core.section import Sectioner, section, section_profile, section_summary

SPHERE3 = ["x**2 + y**2 + z**2 + w**2 - 1"]
TORUS = ["(x**2 + y**2 + z**2 + 0.84)**2 - 4*(x**2 + y**2)"]      # R = 1, r = 0.4, round the z axis
TORUS3 = ["x1**2 + x2**2 - 1/4", "x3**2 + x4**2 - 1", "x5**2 + x6**2 - 4"]


@pytest.fixture(scope="module")
def sphere3():
    return extract(SPHERE3, (-1.25, 1.25), 10, variables=list("xyzw"))


@pytest.fixture(scope="module")
def torus():
    return extract(TORUS, [(-1.6, 1.6), (-1.6, 1.6), (-0.6, 0.6)], [32, 32, 12], variables=list("xyz"))


@pytest.fixture(scope="module")
def torus3():
    return extract(TORUS3, [(-0.6, 0.6), (-0.6, 0.6), (-1.1, 1.1), (-1.1, 1.1), (-4.1, 4.1), (-4.1, 4.1)], 6)


def faces_of(cx, r):
    """The faces of every r-cell (r >= 1) as a list of arrays."""
    if r == 1:
        return list(np.asarray(cx.edges))
    off, fac = cx.cells[r]
    return [fac[off[i]:off[i + 1]] for i in range(off.size - 1)]


def assert_valid(sec, closed):
    """Every r-cell has >= r + 1 distinct faces; an edge joins two vertices; the faces of a 2-cell make one
    cycle; the boundary of every r-cell (r >= 2) is closed (each of its faces' faces met twice); with
    ``closed``, every (d-1)-cell of the section has two cofaces."""
    for r in range(1, sec.dim + 1):
        for i, f in enumerate(faces_of(sec, r)):
            assert len(set(f.tolist())) == len(f) >= r + 1, (r, i, f)
            if r == 1:
                assert f[0] != f[1]
            if r >= 2:
                sub = np.concatenate([faces_of(sec, r - 1)[j] for j in f]) if r > 2 else \
                    np.asarray(sec.edges)[f].ravel()
                _, times = np.unique(sub, return_counts=True)
                assert np.all(times == 2), (r, i)
            if r == 2:   # one cycle: the edges' graph is connected
                E = np.asarray(sec.edges)[f]
                seen = {int(E[0, 0])}
                for _ in range(len(E)):
                    for a, b in E.tolist():
                        if a in seen or b in seen:
                            seen |= {a, b}
                assert len(seen) == len(E)
    if closed and sec.dim >= 1:
        assert sec.boundary_facets().size == 0
        if sec.dim >= 2:
            assert np.all(sec.facet_cofaces() == 2)


def piece_chis(sec):
    """chi of each connected piece of ``sec`` (pieces by the vertices' component labels)."""
    labels = sec.component_labels()
    roots = np.unique(labels)
    chi = {int(r): 0 for r in roots}
    for r in range(sec.dim + 1):
        off, ids = sec.cell_vertices(r)
        first = ids[off[:-1]] if ids.size else np.zeros(0, np.int64)
        for lab in labels[first].tolist():
            chi[lab] += (-1) ** r
    return sorted(chi.values())


# ------------------------------------------------------------------------------------- examples
@pytest.mark.parametrize("c", [-0.85, -0.5, -0.1, 0.0, 0.33, 0.7, 0.9])
def test_three_sphere_sections_are_two_spheres(sphere3, c):
    sec = section(sphere3, "w", c)
    assert sec.dim == 2 and sec.n == 4 and sec.k == 2
    assert sec.euler_characteristic() == 2 and sec.connected_components() == 1
    assert_valid(sec, closed=True)
    V = np.asarray(sec.vertices)
    assert np.all(V[:, 3] == pytest.approx(c, abs=1e-12))
    # on the 2-sphere of radius sqrt(1 - c^2), to the grid's accuracy
    radius = np.linalg.norm(V[:, :3], axis=1)
    assert np.allclose(radius, np.sqrt(1 - c * c), atol=0.05)


@pytest.mark.parametrize("c", [-1.2, 1.1, 5.0])
def test_three_sphere_sections_outside_are_empty(sphere3, c):
    sec = section(sphere3, 3, c)
    assert sec.counts() == [0, 0, 0] and sec.euler_characteristic() == 0


def test_three_sphere_section_agrees_with_extracting_the_hyperplane_too():
    """The section by w = c against GCMH run on the system (F, w - c): both 2-spheres."""
    cx = extract(SPHERE3, (-1.25, 1.25), 8, variables=list("xyzw"))
    direct = extract(SPHERE3 + ["w - 0.3"], (-1.25, 1.25), 8, variables=list("xyzw"))
    sec = section(cx, "w", 0.3)
    assert sec.euler_characteristic() == direct.euler_characteristic() == 2


@pytest.mark.parametrize("axis, c", [("x1", 0.2), ("x2", -0.37), ("x3", 0.5), ("x5", -1.5), ("x6", 0.01)])
def test_three_torus_sections_are_two_tori(torus3, axis, c):
    """x_i = c meets its circle in two points, so the section is two 2-tori (S^1 x S^1 each)."""
    sec = section(torus3, axis, c)
    assert sec.dim == 2
    assert_valid(sec, closed=True)
    assert sec.connected_components() == 2
    assert piece_chis(sec) == [0, 0]


@pytest.mark.parametrize("c, pieces", [(-1.2, 1), (-0.8, 1), (-0.4, 2), (0.0, 2), (0.3, 2), (0.9, 1), (1.3, 1)])
def test_torus_sections_are_circles(torus, c, pieces):
    sec = section(torus, "x", c)
    assert sec.dim == 1
    assert_valid(sec, closed=True)
    assert sec.euler_characteristic() == 0
    assert sec.connected_components() == pieces


@pytest.mark.parametrize("critical", [0.6, -0.6])
def test_torus_at_its_saddle_with_a_vertex_on_the_hyperplane(torus, critical):
    """At x = +-(R - r) the true section is a figure-eight; the discrete one, cut through the vertex
    nearest the saddle (so a vertex lies exactly on the hyperplane), is one or two closed curves, the
    same as just below that value."""
    V = np.asarray(torus.vertices)
    v = np.argmin(np.linalg.norm(V - [critical, 0, 0], axis=1))
    c = float(V[v, 0])
    sec = section(torus, "x", c)
    assert_valid(sec, closed=True)
    assert sec.euler_characteristic() == 0 and sec.connected_components() in (1, 2)
    below = section(torus, "x", c - 1e-12)
    assert below.counts() == sec.counts()
    assert below.connected_components() == sec.connected_components()


def test_vertices_on_the_hyperplane_count_above():
    """A square cut through two of its corners: the corners count as above, so the cut is the segment
    the perturbed line h = c - eps gives (a valid edge, not a corner or nothing)."""
    square = CellComplex(2, 0, [[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1], [1, 2], [2, 3], [3, 0]],
                         {2: ([0, 4], [0, 1, 2, 3])})
    sec = section(square, "x1", 0.0)      # the left side lies on the line: the whole square is above
    assert sec.counts() == [0, 0]
    sec = section(square, "x1", 1.0)      # the right side on the line: cut just left of it
    assert sec.counts() == [2, 1]
    assert sorted(map(tuple, sec.vertices.tolist())) == [(1.0, 0.0), (1.0, 1.0)]
    diag = section(square, [1.0, 1.0], 1.0)   # through corners 1 and 3: above, the cut is near corner 0
    assert diag.counts() == [2, 1]
    assert sorted(map(tuple, diag.vertices.tolist())) == [(0.0, 1.0), (1.0, 0.0)]


def test_a_polygon_crossed_four_times_gives_two_segments():
    """A non-convex 2-cell (a 'U') crossed four times: one segment per arc of its loop below the line (the
    base's two ends, then the notch's), the one rule every 2-cell of a complex follows, so that the cells
    that share its edges get the same points."""
    U = [[0, 0], [3, 0], [3, 2], [2, 2], [2, 1], [1, 1], [1, 2], [0, 2]]
    edges = [[i, (i + 1) % 8] for i in range(8)]
    cx = CellComplex(2, 0, U, edges, {2: ([0, 8], list(range(8)))})
    sec = section(cx, "x2", 1.5)
    assert sec.counts() == [4, 2]
    assert_valid(sec, closed=False)
    pairs = sorted(tuple(sorted(np.asarray(sec.vertices)[e, 0].tolist())) for e in np.asarray(sec.edges))
    assert pairs == [(0.0, 3.0), (1.0, 2.0)]


def test_a_direction_vector_cuts_the_sphere_in_a_circle():
    cx = extract(["x**2 + y**2 + z**2 - 1"], (-1.5, 1.5), 14, variables=list("xyz"))
    u = np.array([1.0, 2.0, -0.5])
    c = 0.4 * np.linalg.norm(u)
    sec = section(cx, u, c)
    assert sec.euler_characteristic() == 0 and sec.connected_components() == 1
    assert np.allclose(np.asarray(sec.vertices) @ u, c)
    assert sec.meta["section"]["value"] == c


def test_sources_name_the_cells_each_piece_lies_in(sphere3):
    sc = Sectioner(sphere3, "w").cells(0.2)
    sec = sc.complex
    E = np.asarray(sphere3.edges)
    # each vertex lies on its edge
    a, b = E[sc.sources[0], 0], E[sc.sources[0], 1]
    X = np.asarray(sphere3.vertices)
    t = (sec.vertices[:, 3] - X[a, 3]) / (X[b, 3] - X[a, 3])
    assert np.allclose(X[a] + t[:, None] * (X[b] - X[a]), sec.vertices)
    # each edge's ends come from edges of its 2-cell
    off, fac = sphere3.cells[2]
    for i, cell in enumerate(sc.sources[1][:200]):
        ends = sc.sources[0][np.asarray(sec.edges)[i]]
        assert set(ends.tolist()) <= set(fac[off[cell]:off[cell + 1]].tolist())
    assert len(sc.sources) == 3 and sc.sources[2].size == sec.count(2)
    assert np.all(np.diff(sc.sources[2]) >= 0)


def test_glued_complexes_are_cut_along_unglued_axes_as_before():
    from gcmh_core.examples import load_example

    ex = load_example("torus-angles")
    cx = extract(ex.formulas, ex.bounds, 12, variables=ex.variables, periodic=ex.periodic)
    lo, hi = Sectioner(cx, "x").range()
    sec = section(cx, "x", 0.5 * (lo + hi) + 0.01)
    assert_valid(sec, closed=True)
    assert sec.euler_characteristic() == 0 and sec.count(0) > 0
    B = np.asarray(cx.meta["bounds"], dtype=float)
    assert np.all((sec.vertices >= B[:, 0] - 1e-12) & (sec.vertices <= B[:, 1] + 1e-12))
    assert Sectioner(cx, "x").circle.mode == "plain"


# ------------------------------------------------------------------------------------- properties
@pytest.fixture(scope="module")
def closed_surfaces(torus):
    genus2 = ["((x**2 + y**2)**2 - x**2 + y**2)**2 + z**2 - 0.01"]   # two holes, side by side
    return [torus, extract(["x**2 + y**2 + z**2 - 1"], (-1.3, 1.3), 9, variables=list("xyz")),
            extract(genus2, [(-1.3, 1.3), (-0.8, 0.8), (-0.3, 0.3)], [28, 18, 8], variables=list("xyz"))]


@settings(max_examples=60, deadline=None)
@given(which=st.integers(0, 2),
       u=st.lists(st.floats(-1, 1, allow_nan=False), min_size=3, max_size=3).filter(lambda u: max(map(abs, u)) > 0.05),
       t=st.floats(0.0, 1.0))
def test_sections_of_closed_surfaces_are_closed_curves(closed_surfaces, which, u, t):
    """Any hyperplane meets a closed surface in closed curves: every vertex of the section on two of its
    edges, so chi = 0."""
    cx = closed_surfaces[which]
    assert cx.boundary_facets().size == 0
    sec_maker = Sectioner(cx, np.asarray(u))
    lo, hi = sec_maker.range()
    sec = sec_maker.section(lo + t * (hi - lo))
    assert sec.euler_characteristic() == 0
    assert np.all(sec.facet_cofaces() == 2)
    assert_valid(sec, closed=True)


@settings(max_examples=25, deadline=None)
@given(u=st.lists(st.floats(-1, 1, allow_nan=False), min_size=4, max_size=4).filter(lambda u: max(map(abs, u)) > 0.1),
       t=st.floats(0.02, 0.98))
def test_sections_of_the_three_sphere_are_closed_surfaces(sphere3, u, t):
    """Any hyperplane meets the 3-sphere in a closed surface (each edge on two faces); the round sphere's
    sections are 2-spheres away from the ends of the range."""
    s = Sectioner(sphere3, np.asarray(u))
    lo, hi = s.range()
    sec = s.section(lo + t * (hi - lo))
    assert_valid(sec, closed=True)
    if 0.1 < t < 0.9:
        assert sec.euler_characteristic() == 2 and sec.connected_components() == 1


# ------------------------------------------------------------------------------------- profile, CLI, checks
def test_profile_shows_where_the_torus_changes(torus):
    prof = section_profile(torus, "x", np.linspace(-1.5, 1.5, 61))
    assert np.all(prof.chi == 0)
    inside = np.abs(prof.values) < 0.55
    between = (np.abs(prof.values) > 0.65) & (np.abs(prof.values) < 1.35)
    assert np.all(prof.pieces[inside] == 2) and np.all(prof.pieces[between] == 1)
    assert np.all(prof.pieces[np.abs(prof.values) > 1.45] == 0)
    jumps = prof.values[prof.changes()]
    for critical in (-1.4, -0.6, 0.6, 1.4):
        assert np.min(np.abs(jumps - critical)) < 0.1


def test_profile_default_values_of_the_three_sphere(sphere3):
    prof = section_profile(sphere3, "w", count=21)
    assert prof.values.size == 21 and prof.along == "w"
    assert np.all(prof.chi == 2) and np.all(prof.pieces == 1)


def test_section_summary_for_the_command_line(sphere3):
    sec, summary, line = section_summary(sphere3, "w=-pi/8", ["x", "y", "z", "w"])
    assert summary["along"] == "w" and summary["value"] == pytest.approx(-np.pi / 8)
    assert summary["euler_characteristic"] == 2 and summary["pieces"] == 1 and summary["boundary_facets"] == 0
    assert summary["counts"] == sec.counts() and sec.dim == 2
    assert "w = -0.392699" in line and "chi = 2" in line and "1 piece," in line and "closed" in line
    _, summary, line = section_summary(sphere3, "w = 3", ["x", "y", "z", "w"])
    assert summary["counts"] == [0, 0, 0] and "empty" in line
    for bad, msg in (("w", "VAR=C"), ("q=1", "not a variable"), ("w=abc", "cannot|number")):
        with pytest.raises(InputError, match=msg):
            section_summary(sphere3, bad, ["x", "y", "z", "w"])


def test_saved_sections_load_back(tmp_path, sphere3):
    sec = section(sphere3, "w", 0.5)
    sec.save(tmp_path / "cut.npz")
    back = CellComplex.load(tmp_path / "cut.npz")
    assert back.counts() == sec.counts() and back.meta["section"]["along"] == "w"


@pytest.mark.parametrize("direction, value, msg", [
    ("q", 0.0, "no variable"), (7, 0.0, "does not exist"), ([1.0, 0.0], 0.0, "4 components"),
    ([0.0, 0.0, 0.0, 0.0], 0.0, "not 0"), ([np.nan, 1, 0, 0], 0.0, "finite"), (True, 0.0, "axis"),
    ("w", float("inf"), "finite"), ("w", "x", "number"), ("w", None, "number")])
def test_bad_arguments_are_refused_with_a_message(sphere3, direction, value, msg):
    with pytest.raises(InputError, match=msg):
        section(sphere3, direction, value)


def test_points_have_no_sections():
    pts = CellComplex(2, 2, [[0.0, 0.0]], np.zeros((0, 2), np.int64))
    with pytest.raises(InputError, match="dimension 0"):
        section(pts, 0, 0.0)
    with pytest.raises(InputError, match="CellComplex"):
        section("not a complex", 0, 0.0)
