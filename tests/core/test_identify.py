"""Identified domain axes (gcmh_core.identify): the closed Klein bottle, the Moebius band,
the torus of angles and a linkage's configuration space, with every method; seams checked
like any other cells; refused input with one clear message."""

import json

import numpy as np
import pytest

from gcmh_core import InputError, extract
from gcmh_core._validate import as_periodic
from gcmh_core.analysis import orient_2cells, topology_report
from gcmh_core.cli import main
from gcmh_core.examples import load_example
from gcmh_core.grid import PERTURBATION
from gcmh_core.identify import identified_axes

KLEIN = load_example("klein-bottle-closed")
MOEBIUS = load_example("moebius-band")
TORUS = load_example("torus-angles")


def _run(ex, div, **kw):
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic, **kw)


def _check_manifold(cx, ex, div, seed):
    """Every facet in one or two top cells; no vertex on the hi side of a seam (it is the
    vertex on the lo side); every boundary vertex on the domain's boundary along an unglued axis."""
    cofaces = cx.facet_cofaces()
    assert cofaces.min() >= 1 and cofaces.max() <= 2
    assert cx.meta["degenerate"] == 0 and cx.meta.get("non_ball_cells", 0) == 0
    assert topology_report(cx)["orientation"]["nonmanifold_edges"] == 0
    bounds = np.array(ex.bounds)
    spec = as_periodic(ex.periodic, ex.variables, div)
    axes = identified_axes(bounds, div, seed, PERTURBATION, spec)
    for p, _ in spec:
        assert np.all(np.abs(cx.vertices[:, p] - axes[p][-1]) > 1e-9)
    boundary = cx.boundary_facets()
    V = cx.vertices[np.unique(cx.edges[boundary])]
    h = (bounds[:, 1] - bounds[:, 0]) / np.array(div)
    near = (np.abs(V - bounds[:, 0]) < 0.01 * h) | (np.abs(V - bounds[:, 1]) < 0.01 * h)
    near[:, [p for p, _ in spec]] = False
    assert np.all(near.any(axis=1))


@pytest.mark.parametrize("method", ["gcmh", "gcch", "cms"])
@pytest.mark.parametrize("seed, div", [(0, [12, 12, 6, 12, 12]), (3, [16, 16, 8, 14, 16])])
def test_klein_bottle_closes(method, seed, div):
    cx = _run(KLEIN, div, seed=seed, method=method)
    report = topology_report(cx)
    assert report["euler_characteristic"] == 0
    assert report["boundary_facets"] == 0 and report["closed"]
    assert report["connected_components"] == 1
    assert not orient_2cells(cx).consistent and report["orientation"]["orientable_components"] == 0
    _check_manifold(cx, KLEIN, div, seed)
    assert cx.meta["periodic"] == ["s:flip=t", "t"]


@pytest.mark.parametrize("method", ["gcmh", "gcch", "cms"])
@pytest.mark.parametrize("seed, div", [(0, [16, 16, 8, 16, 4]), (5, [24, 24, 8, 24, 6])])
def test_moebius_band(method, seed, div):
    cx = _run(MOEBIUS, div, seed=seed, method=method)
    report = topology_report(cx)
    assert report["euler_characteristic"] == 0
    assert report["boundary_facets"] > 0 and report["boundary_components"] == 1
    assert not report["orientation"]["consistent"]
    _check_manifold(cx, MOEBIUS, div, seed)


@pytest.mark.parametrize("method", ["gcmh", "gcch", "cms"])
@pytest.mark.parametrize("seed, div", [(0, [14, 14, 6, 12, 10]), (2, [20, 20, 8, 15, 13])])
def test_angle_torus(method, seed, div):
    cx = _run(TORUS, div, seed=seed, method=method)
    report = topology_report(cx)
    assert (report["euler_characteristic"], report["boundary_facets"]) == (0, 0)
    assert report["orientation"]["consistent"]
    _check_manifold(cx, TORUS, div, seed)


def test_cut_open_versions_unchanged():
    """Without `periodic` the same formulas give the cut-open squares, as before."""
    klein = load_example("klein-bottle")
    assert klein.periodic == [] and klein.formulas == KLEIN.formulas
    cut = extract(klein.formulas, klein.bounds, [12, 12, 6, 12, 12], variables=klein.variables)
    report = topology_report(cut)
    assert report["euler_characteristic"] == 1 and report["boundary_components"] == 1
    assert report["orientation"]["consistent"]
    strip = load_example("moebius-strip")
    assert strip.periodic == [] and strip.formulas == MOEBIUS.formulas


def test_pentagon_linkage_is_a_genus_four_surface():
    ex = load_example("pentagon-linkage")
    glued = extract(ex.formulas, ex.bounds, 12, variables=ex.variables, periodic=ex.periodic)
    report = topology_report(glued)
    assert (report["euler_characteristic"], report["boundary_facets"]) == (-6, 0)
    assert report["orientation"]["consistent"] and report["connected_components"] == 1
    cut = extract(ex.formulas, ex.bounds, 12, variables=ex.variables)  # as the description says
    assert (cut.euler_characteristic(), cut.connected_components()) == (6, 6)


@pytest.mark.parametrize("ex, cont, full", [(KLEIN, "gcch", "gcmh"), (MOEBIUS, "ccs", "cms")])
def test_continuation_crosses_seams(ex, cont, full):
    """From one start point, continuation reaches the whole glued surface: the full sweep's
    complex, bit for bit."""
    div = [16, 16, 8, 12, 12] if ex is KLEIN else [16, 16, 8, 16, 4]
    a = _run(ex, div, method=cont, start=ex.start)
    b = _run(ex, div, method=full)
    assert a.counts() == b.counts()
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.edges, b.edges)
    for r in b.cells:
        assert all(np.array_equal(x, y) for x, y in zip(a.cells[r], b.cells[r]))


def test_grid_lines_wrap_and_mirror():
    bounds = np.array([[-1.0, 1.0], [0.0, 2 * np.pi], [-0.5, 0.5], [0.0, 2 * np.pi]])
    spec = ((1, (2, 3)), (3, ()))
    for seed in range(3):
        axes = identified_axes(bounds, [5, 8, 6, 10], seed, 1e-3, spec)
        for a in (1, 3):
            assert axes[a][-1] == axes[a][0] + bounds[a, 1] - bounds[a, 0]
        for b in (2, 3):
            c = bounds[b].sum()
            d = len(axes[b]) - 1
            for j in range(d // 2 + 1):  # (line d - j is computed as c - line j)
                assert axes[b][d - j] == c - axes[b][j]
            assert np.all(np.diff(axes[b]) > 0)
        assert axes[3][0] == 0.0  # (periodic and mirrored: line d = line 0 + P = c - line 0)
        assert axes[2][0] > -0.5  # (not periodic: still moved inwards)


def test_f_that_is_not_periodic_is_refused():
    with pytest.raises(InputError, match=r"F is not 2pi-periodic in s: F\(x=.*\) = .* but F\(x=.*s=.* \+ 2pi"):
        extract(["cos(s/2) - x", "sin(t) - y"], [[-2, 2], [-2, 2], [0, "2*pi"], [0, "2*pi"]], 8,
                variables="x,y,s,t", periodic=["s"])
    # the Klein bottle's s seam without its reflection of t is not an identification of F
    with pytest.raises(InputError, match="F is not 2pi-periodic in s: .*; it is with t reversed too: s:flip=t$"):
        extract(KLEIN.formulas, KLEIN.bounds, 8, variables=KLEIN.variables, periodic=["s", "t"])
    with pytest.raises(InputError, match="F is not 2pi-periodic in s with t reversed"):
        extract(TORUS.formulas, TORUS.bounds, 8, variables=TORUS.variables, periodic=["s:flip=t"])


@pytest.mark.parametrize("periodic, message", [
    (["u"], "periodic axis 'u' is not a variable (variables: x, y, z, s, t)"),
    (["s:flip=u"], "flip of 's': 'u' is not a variable"),
    (["s:flip=s"], "cannot reverse itself"),
    (["s", "s"], "periodic axis 's' is given twice"),
    (["s:mirror=t"], "write NAME or NAME:flip=A,B"),
    ({"s": {"flop": ["t"]}}, "unknown option 'flop'"),
    ({"s": 3}, "must be True, False or"),
    ("s", "periodic is"),
    (["t:flip=s", "s:flip=t"], "cannot reverse axes across its own seam too"),
])
def test_bad_periodic_is_refused(periodic, message):
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        extract(KLEIN.formulas, KLEIN.bounds, 8, variables=KLEIN.variables, periodic=periodic)


def test_grid_conditions_are_refused():
    with pytest.raises(InputError, match="axis 't' is reversed across the seam of 's', so its grid is "
                                         "mirror-symmetric and needs an even div, got 9"):
        extract(KLEIN.formulas, KLEIN.bounds, [8, 8, 4, 8, 9], variables=KLEIN.variables, periodic=KLEIN.periodic)
    with pytest.raises(InputError, match="needs at least 3 cubes around it, div is 2"):
        extract(KLEIN.formulas, KLEIN.bounds, [8, 8, 4, 2, 8], variables=KLEIN.variables, periodic=KLEIN.periodic)
    with pytest.raises(InputError, match="periodic axes need F as formulas"):
        extract(np.ones((5, 5, 1)), [[0, 1], [0, 1]], periodic=["x1"])


def test_dict_and_list_forms_agree():
    a = extract(TORUS.formulas, TORUS.bounds, [10, 10, 4, 9, 8], variables=TORUS.variables,
                periodic={"s": True, "t": {"flip": []}, "x": False})
    b = extract(TORUS.formulas, TORUS.bounds, [10, 10, 4, 9, 8], variables=TORUS.variables, periodic=["t", "s"])
    assert a.counts() == b.counts() and np.array_equal(a.vertices, b.vertices)
    assert a.meta["periodic"] == b.meta["periodic"] == ["s", "t"]


def test_cli_periodic(capsys):
    args = ["extract", "--example", "klein-bottle", "--div", "12,12,6,12,12", "-q", "--json"]
    assert main([*args, "--periodic", "s:flip=t", "--periodic", "t"]) == 0
    glued = json.loads(capsys.readouterr().out)
    assert (glued["euler_characteristic"], glued["boundary_facets"]) == (0, 0)
    assert main(["extract", "--example", "klein-bottle-closed", "--div", "12,12,6,12,12", "-q", "--json",
                 "--periodic", "none"]) == 0
    cut = json.loads(capsys.readouterr().out)
    assert cut["euler_characteristic"] == 1 and cut["boundary_facets"] > 0
    assert main([*args, "--periodic", "s:flip=t", "--periodic", "t", "--div", "12,12,6,12,11"]) == 2
    assert "needs an even div, got 11" in capsys.readouterr().err


def test_example_file_periodic_is_checked(tmp_path, monkeypatch):
    text = (KLEIN.path.read_text(encoding="utf-8") if hasattr(KLEIN.path, "read_text") else "")
    monkeypatch.setenv("GCMH_EXAMPLES_DIR", str(tmp_path))
    (tmp_path / "good.toml").write_text(text)
    assert load_example("good").periodic == ["s:flip=t", "t"]
    (tmp_path / "bad.toml").write_text(text.replace('periodic = ["s:flip=t", "t"]', 'periodic = ["s:flip=w"]'))
    with pytest.raises(InputError, match="example 'bad': 'periodic': flip of 's': 'w' is not a variable"):
        load_example("bad")


def test_start_point_projected_across_a_seam():
    """Newton may leave the box through a seam: its point comes back on the other side."""
    ex = load_example("pentagon-linkage")
    a = extract(ex.formulas, ex.bounds, 12, variables=ex.variables, periodic=ex.periodic, method="gcch",
                start=[0, 1, 5, 3])  # (projects to a point with an angle below 0)
    b = extract(ex.formulas, ex.bounds, 12, variables=ex.variables, periodic=ex.periodic)
    assert a.counts() == b.counts() and np.array_equal(a.vertices, b.vertices)
    with pytest.raises(InputError, match="left the domain"):  # (the cut-open box has no way round)
        extract(ex.formulas, ex.bounds, 12, variables=ex.variables, method="gcch", start=[0, 1, 5, 3])


def test_wrap_points_reverses_the_flipped_axis():
    from gcmh_core.identify import IdentifiedGrid

    bounds = np.array(KLEIN.bounds)
    spec = as_periodic(KLEIN.periodic, KLEIN.variables, [4, 4, 2, 4, 4])
    grid = IdentifiedGrid(5, 3, identified_axes(bounds, [4, 4, 2, 4, 4], 0, PERTURBATION, spec), spec=spec,
                          bounds=bounds)
    X = grid.wrap_points([[1.0, 2.0, 0.5, 2 * np.pi + 0.3, 0.7], [1.0, 2.0, 0.5, -0.3, -0.2]])
    assert np.allclose(X, [[1.0, 2.0, 0.5, 0.3, 2 * np.pi - 0.7], [1.0, 2.0, 0.5, 2 * np.pi - 0.3, 0.2]])


@pytest.mark.parametrize("slab", [1 << 22, 16])
def test_curve_on_the_klein_bottle_is_one_circle(slab, monkeypatch):
    """cos t = 1/2 on the Klein bottle: the two arcs t = pi/3 and t = 5pi/3 of the square
    are one circle, since crossing s = 2pi reverses t.  Here the sweep's slabs run along
    s, a glued axis with a reflection (16 vertices a slab: one slab per cube)."""
    import gcmh_core.identify as identify

    monkeypatch.setattr(identify, "_SLAB_VERTICES", slab)
    square = [[0, "2*pi"], [0, "2*pi"]]
    for full, cont in (("gcmh", "gcch"), ("cms", "ccs")):
        a = extract("cos(t) - 0.5", square, [12, 10], variables="s,t", periodic=["s:flip=t", "t"], method=full)
        b = extract("cos(t) - 0.5", square, [12, 10], variables="s,t", periodic=["s:flip=t", "t"], method=cont,
                    start=[0.3, np.pi / 3])
        assert (a.connected_components(), a.euler_characteristic(), len(a.boundary_facets())) == (1, 0, 0)
        assert a.counts() == b.counts() and np.array_equal(a.vertices, b.vertices)
    cut = extract("cos(t) - 0.5", square, [12, 10], variables="s,t")
    assert (cut.connected_components(), len(cut.boundary_facets())) == (2, 4)
    with pytest.raises(InputError, match="F is not 2pi-periodic in s with t reversed"):
        extract("sin(t) - 0.5", square, [12, 10], variables="s,t", periodic=["s:flip=t", "t"])
