"""The homology of a result in the Topology tab: computed off the GUI thread, generators drawn
as overlays that follow the projection, the w1 loop, curvature colours (gcmh_studio.cycles,
gcmh_studio.qt_homology_box, gcmh_studio.overlays.draw_homology / colour_by_values)."""

import numpy as np
import pytest

from gcmh_core import extract
from gcmh_core.examples import load_example
from gcmh_core.homology import homology
from gcmh_studio.cycles import edge_attribute, edge_cycle_loops, generator_lines, unwrap_segments, w1_lines
from gcmh_studio.model import StudioModel
from gcmh_studio.qt_homology_box import QtHomologyBox


def _example(name, div):
    ex = load_example(name)
    cx = extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic or None,
                 params=ex.param_values() or None)
    return cx


@pytest.fixture(scope="module")
def klein():
    return _example("klein-bottle-closed", [12, 12, 6, 12, 12])


@pytest.fixture
def box(qtbot):
    b = QtHomologyBox(StudioModel())
    qtbot.addWidget(b)
    b.show()
    return b


def _computed(qtbot, box, cx):
    with qtbot.waitSignal(box.computed, timeout=120_000):
        box.set_result(cx)
        # the GUI thread only asked: the answer comes later, from the worker
        assert box.data is None and box.status.text() == "computing…"


def test_box_shows_the_groups(qtbot, box, klein):
    _computed(qtbot, box, klein)
    assert box.status.text() == "H0 = Z, H1 = Z + Z/2, H2 = 0"
    assert [box.groups[q].text() for q in range(3)] == ["H0 = Z", "H1 = Z + Z/2", "H2 = 0"]
    assert [box.betti2[q].text() for q in range(3)] == ["1", "2", "1"]
    assert box.betti[1].text() == "b1 = 1  (+1 torsion)"
    assert not box.groups[3].isVisible()
    assert box.w1_check.isEnabled() and box.curvature_check.isEnabled()
    assert "chi = 0" in box.gauss_bonnet.text()


def test_click_on_a_betti_number_asks_for_its_generators(qtbot, box, klein):
    _computed(qtbot, box, klein)
    with qtbot.waitSignal(box.overlays) as sent:
        box.betti[1].click()
    specs = sent.args[0]
    assert sorted(specs) == ["homology-1-0", "homology-1-1"]
    colours = {spec[2] for spec in specs.values()}
    assert len(colours) == 2   # each generator its own colour
    for X, E, _, width in specs.values():
        assert X.shape[1] == 5 and len(E) and width > 3
    with qtbot.waitSignal(box.w1_check.toggled):
        box.w1_check.click()
    assert {"homology-w1", "homology-w1-arrows"} <= set(box.overlay_specs())
    with qtbot.waitSignal(box.overlays) as sent:
        box.betti[1].click()   # off again
    assert set(sent.args[0]) == {"homology-w1", "homology-w1-arrows"}


def test_a_new_result_replaces_the_old(qtbot, box, klein):
    _computed(qtbot, box, klein)
    box.betti[1].click()
    torus = _example("torus", [12, 12, 6])
    with qtbot.waitSignal(box.overlays) as sent:
        _computed(qtbot, box, torus)
    assert sent.args[0] == {}   # the old result's generators go at once
    assert box.status.text() == "H0 = Z, H1 = Z^2, H2 = Z"
    assert not box.w1_check.isEnabled()


def test_a_refused_complex_says_why(qtbot, box):
    from gcmh_core import CellComplex

    annulus = CellComplex(2, 0, np.zeros((6, 2)), [[0, 1], [1, 2], [2, 0], [3, 4], [4, 5], [5, 3]],
                          {2: ([0, 6], [0, 1, 2, 3, 4, 5])})
    _computed(qtbot, box, annulus)
    assert box.status.text().startswith("not computed: 2-cell 0 is not a ball")


# ---------------------------------------------------------------------------- Qt-free geometry

def test_generator_lines_and_loops(klein):
    h = homology(klein)
    for c in h.generators[1]:
        X, E = generator_lines(klein, c)
        assert len(E) == len(c) and X.shape[1] == 5
        loops = edge_cycle_loops(klein, c)
        assert all(loop[0] == loop[-1] for loop in loops)
        assert sum(len(loop) - 1 for loop in loops) == int(np.abs(c.coefficients).sum())
    attr = edge_attribute(klein, h.generators[1])
    assert set(np.unique(attr)) <= {0, 1, 2} and (attr > 0).sum() >= max(len(c) for c in h.generators[1])
    X, E = generator_lines(klein, h.generators[0][0])   # H0: the component's edges
    assert len(E) == klein.count(1)


def test_seam_segments_are_drawn_short(klein):
    """A generator goes round the identified axes: unwrapped, no segment spans the box."""
    h = homology(klein)
    c = h.generators[1][0]
    X, E = generator_lines(klein, c)
    span = np.array(klein.meta["bounds"])[:, 1] - np.array(klein.meta["bounds"])[:, 0]
    before = np.abs(X[E[:, 0]] - X[E[:, 1]]).max(axis=0) / span
    X2, E2 = unwrap_segments(klein, X, E)
    after = np.abs(X2[E2[:, 0]] - X2[E2[:, 1]]).max(axis=0) / span
    assert before.max() > 0.5 and after.max() < 0.5
    assert len(E2) == len(E)


def test_w1_lines_beside_the_loop(klein):
    h = homology(klein)
    (XL, EL), (XA, EA) = w1_lines(klein, h.orientation_cycle, h.orientation)
    assert len(EL) == h.orientation_cycle.size
    assert len(EA) > 2 * len(EL)   # an oriented loop with an arrowhead in each polygon beside it


# ---------------------------------------------------------------------------- in the window

def test_generators_follow_the_view(qtbot, small_window, klein):
    w = small_window
    box = w.topology_panel.homology_box   # (the window connects it to its scene)
    with qtbot.waitSignal(box.computed, timeout=120_000):
        w.show_result(klein, klein.point_names(), title="Klein bottle")
    box.betti[1].click()
    box.w1_check.click()
    drawn = w.scene.overlays
    assert {"homology-1-0", "homology-1-1", "homology-w1", "homology-w1-arrows"} <= set(drawn)
    before = np.array(drawn["homology-1-0"][1].points)
    P = np.array(w.scene.P)
    P2 = np.roll(P, 1, axis=1)   # another projection of R^5
    w.scene.set_projection(P2)
    after = np.array(w.scene.overlays["homology-1-0"][1].points)
    assert not np.allclose(before, after)
    box.curvature_check.click()
    assert "curvature" in w.scene.mesh.point_data
    assert w.scene.actor.mapper.array_name == "curvature"
    assert "K" in w.scene.plotter.scalar_bars.keys()
    box.curvature_check.click()   # back to the style's colours
    assert w.scene.actor.mapper.array_name != "curvature"
    box.betti[1].click()
    assert "homology-1-0" not in w.scene.overlays and "homology-w1" in w.scene.overlays


def test_generators_export_as_lines(qtbot, small_window, tmp_path):
    from gcmh_studio import studio_io
    from gcmh_studio.overlays import homology_lines_mesh

    w = small_window
    torus = _example("torus", [12, 12, 6])
    box = w.topology_panel.homology_box
    with qtbot.waitSignal(box.computed, timeout=120_000):
        w.show_result(torus, torus.point_names(), title="torus")
    assert homology_lines_mesh(w.scene) is None
    box.betti[1].click()
    mesh = homology_lines_mesh(w.scene)
    assert sorted(set(mesh.cell_data["cycle"].tolist())) == [1, 2]
    assert mesh.n_lines == sum(len(spec[1]) for spec in box.overlay_specs().values())
    path = studio_io.export_mesh(mesh, tmp_path / "cycles.obj", 1)
    text = open(path).read()
    assert text.count("\nl ") == mesh.n_lines and "\nv " in text
    # the window's Export mesh writes the generators beside the result's mesh
    w.export_mesh(str(tmp_path / "torus.ply"))
    assert (tmp_path / "torus.ply").exists() and (tmp_path / "torus-cycles.ply").exists()
    assert "property int cycle" in (tmp_path / "torus-cycles.ply").read_text().splitlines()   # (not points alone)
    # PLY and OBJ keep each edge's cycle (a PLY edge element with a cycle property; OBJ groups)
    from gcmh_studio.overlays import export_cycles

    path = export_cycles(w.scene, tmp_path / "mine.ply")
    assert path.endswith("mine-cycles.ply")
    lines = open(path).read().splitlines()
    n_v = int(next(t for t in lines if t.startswith("element vertex")).split()[-1])
    n_e = int(next(t for t in lines if t.startswith("element edge")).split()[-1])
    assert "property int cycle" in lines and n_e == mesh.n_lines
    body = lines[lines.index("end_header") + 1:]
    verts = [t.split() for t in body[:n_v]]
    edges = [[int(v) for v in t.split()] for t in body[n_v:n_v + n_e]]
    colours = {k: box.generator_colours(1)[k - 1] for k in (1, 2)}
    import pyvista as pv

    for a, b, k in edges:   # both ends in the colour of the cycle named
        assert k in (1, 2)
        for end in (a, b):
            assert tuple(int(c) for c in verts[end][3:]) == tuple(pv.Color(colours[k]).int_rgb)
    assert sorted({k for *_, k in edges}) == [1, 2]
    text = open(export_cycles(w.scene, tmp_path / "mine.obj")).read()
    assert "\ng cycle-1\n" in text and "\ng cycle-2\n" in text and text.count("\nl ") == mesh.n_lines


def test_curvature_values_of_a_sphere():
    from gcmh_studio.cycles import curvature_values

    cx = extract("x^2 + y^2 + z^2 - 4", bounds=(-2.5, 2.5), div=12, variables="x, y, z")
    k, text = curvature_values(cx)
    assert k.shape == (cx.count(0),)
    assert np.median(k) == pytest.approx(0.25, rel=0.1) and k.min() > 0   # 1 / r^2 everywhere
    assert text == "Gauss-Bonnet: K / 2pi = 2.000, chi = 2"


def test_h2_classes_of_a_three_manifold_as_surfaces(qtbot, small_window, tmp_path):
    """b2 of the three-torus: three see-through surfaces (the 2-cells of each generator, fanned into
    triangles), which turn with the view and go with a second click."""
    from gcmh_studio.homology_surfaces import SURFACE_OPACITY

    w = small_window
    cx = _example("three-torus", 5)
    box = w.topology_panel.homology_box   # (the window draws what its surfaces signal asks: its own hook)
    with qtbot.waitSignal(box.computed, timeout=120_000):
        w.show_result(cx, cx.point_names(), title="three-torus")
    assert box.status.text() == "H0 = Z, H1 = Z^3, H2 = Z^3, H3 = Z"
    with qtbot.waitSignal(box.surfaces) as sent:
        box.betti[2].click()
    specs = sent.args[0]
    assert sorted(specs) == [f"homology-surface-2-{i}" for i in range(3)]
    h = box.data["homology"]
    offs = np.asarray(cx.polygons()[0])
    for i, c in enumerate(h.generators[2]):
        X, T, colour, opacity = specs[f"homology-surface-2-{i}"]
        assert len(T) == int((np.diff(offs)[c.cells] - 2).sum())   # each polygon fanned
        assert opacity == SURFACE_OPACITY < 1 and colour == box.generator_colours(2)[i]
        # unwrapped across the glued axes: no triangle spans half the box
        span = np.ptp(np.asarray(cx.meta["bounds"], dtype=float), axis=1)
        assert (np.ptp(X[T], axis=1) < span / 2).all()
    # no line overlays for them: the surfaces show them
    assert not [n for n in box.overlay_specs() if n.startswith("homology-2-")]
    drawn = w.scene.overlays
    assert set(specs) <= set(drawn)
    mesh = drawn["homology-surface-2-0"][1]
    assert mesh.n_cells == len(specs["homology-surface-2-0"][1])
    assert drawn["homology-surface-2-0"][2].prop.opacity == pytest.approx(SURFACE_OPACITY)
    before = np.array(mesh.points)
    w.scene.set_projection(np.roll(np.array(w.scene.P), 1, axis=1))
    assert not np.allclose(before, np.array(w.scene.overlays["homology-surface-2-0"][1].points))
    # exported with a cycle per face
    from gcmh_studio.overlays import export_cycles

    lines = open(export_cycles(w.scene, tmp_path / "t3.ply")).read().splitlines()
    n_v = int(next(t for t in lines if t.startswith("element vertex")).split()[-1])
    n_f = int(next(t for t in lines if t.startswith("element face")).split()[-1])
    body = lines[lines.index("end_header") + 1:]
    faces = [[int(v) for v in t.split()] for t in body[n_v:n_v + n_f]]
    assert n_f == sum(w.scene.overlays[n][1].n_cells for n in specs)
    assert sorted({f[-1] for f in faces}) == [1, 2, 3] and all(f[0] == len(f) - 2 for f in faces)
    with qtbot.waitSignal(box.surfaces) as sent:
        box.betti[2].click()
    assert sent.args[0] == {} and not [n for n in w.scene.overlays if n.startswith("homology-surface-")]


def _slab_heights(scene, name):
    """The heights direction . x of the points of overlay ``name`` as drawn (in R^n), and the slab."""
    geo = scene.overlays[name][0]
    pr = geo.projector
    X = np.asarray(pr.XT.T, dtype=np.float64) + pr.center
    u, c, w = scene.slice
    return X @ u, c, w


def test_generators_follow_the_slice(qtbot, small_window, klein):
    """A slice clips the H1 generators and the w1 loop as it clips the result: every point drawn lies in
    the slab, fewer segments than the whole loop; the slice off, the whole loops again."""
    w = small_window
    box = w.topology_panel.homology_box
    with qtbot.waitSignal(box.computed, timeout=120_000):
        w.show_result(klein, klein.point_names(), title="Klein bottle")
    box.betti[1].click()
    box.w1_check.click()
    names = ["homology-1-0", "homology-1-1", "homology-w1"]
    whole = {n: w.scene.overlays[n][1].n_cells for n in names}
    u = np.zeros(5)
    u[0] = 1.0
    x = np.asarray(klein.vertices)[:, 0]
    w.scene.set_slice(u, x.min() + 0.5 * np.ptp(x), 0.15 * np.ptp(x))
    shown = [n for n in names if n in w.scene.overlays]   # (a loop may miss the slab altogether)
    assert shown
    for n in shown:
        h, c, width = _slab_heights(w.scene, n)
        assert (h >= c - width - 1e-9).all() and (h <= c + width + 1e-9).all()
    assert sum(w.scene.overlays[n][1].n_cells for n in shown) < sum(whole.values())
    w.scene.set_slice(None)
    assert {n: w.scene.overlays[n][1].n_cells for n in names} == whole


def test_h2_surfaces_follow_the_slice(qtbot, small_window):
    """The three-torus' H2 surfaces are cut by the slab as the result is (triangles clipped at its planes),
    stay see-through, and come back whole with the slice off."""
    from gcmh_studio.homology_surfaces import SURFACE_OPACITY

    w = small_window
    cx = _example("three-torus", 5)
    box = w.topology_panel.homology_box
    with qtbot.waitSignal(box.computed, timeout=120_000):
        w.show_result(cx, cx.point_names(), title="three-torus")
    box.betti[2].click()
    names = [f"homology-surface-2-{i}" for i in range(3)]
    whole = {n: w.scene.overlays[n][1].n_cells for n in names}
    V = np.asarray(cx.vertices)
    u = np.zeros(V.shape[1])
    u[0] = 1.0
    c, width = V[:, 0].min() + 0.5 * np.ptp(V[:, 0]), 0.1 * np.ptp(V[:, 0])
    w.scene.set_slice(u, c, width)
    shown = [n for n in names if n in w.scene.overlays]
    assert shown
    for n in shown:
        geo, mesh, actor, _colour, _look = w.scene.overlays[n]
        assert geo.kind == "polygons" and actor.prop.opacity == pytest.approx(SURFACE_OPACITY)
        h, c0, w0 = _slab_heights(w.scene, n)
        assert (h >= c0 - w0 - 1e-9).all() and (h <= c0 + w0 + 1e-9).all()
    assert sum(w.scene.overlays[n][1].n_cells for n in shown) < sum(whole.values())
    w.scene.set_slice(None)
    assert {n: w.scene.overlays[n][1].n_cells for n in names} == whole
    with qtbot.waitSignal(box.surfaces):
        box.betti[2].click()
    assert not [n for n in w.scene.overlay_meshes.names() if n.startswith("homology-surface-")]


def test_curvature_survives_style_and_slice(qtbot, small_window):
    """Curvature colours stay through a change of style that draws the result anew (the boundary
    highlighted), through a slice (its cells, and the points it adds, coloured by the curvature) and back;
    colouring by a variable instead turns the switch off."""
    from gcmh_studio.cycles import curvature_values

    w = small_window
    cx = _example("genus-two", [26, 16, 10])
    box = w.topology_panel.homology_box
    with qtbot.waitSignal(box.computed, timeout=120_000):
        w.show_result(cx, cx.point_names(), title="genus two")
    box.curvature_check.click()
    assert w.scene.actor.mapper.array_name == "curvature"
    with qtbot.waitSignal(box.curvature):
        w.model.set_style(boundary=True)
    assert w.scene.actor.mapper.array_name == "curvature" and w.scene.actor.mapper.scalar_visibility
    k, _ = curvature_values(cx)
    u = np.array([1.0, 0.0, 0.0])
    x = np.asarray(cx.vertices)[:, 0]
    w.scene.set_slice(u, x.min() + 0.5 * np.ptp(x), 0.1 * np.ptp(x))
    mesh = w.scene.mesh
    assert w.scene.actor.mapper.array_name == "curvature" and mesh.n_points < cx.count(0)
    drawn = np.asarray(mesh.point_data["curvature"])
    pts = np.column_stack([np.asarray(mesh.point_data[n]) for n in w.scene.names])
    V = np.asarray(cx.vertices)
    same = {tuple(v): i for i, v in enumerate(V)}
    kept = [(j, same[tuple(p)]) for j, p in enumerate(pts) if tuple(p) in same]
    assert kept and np.allclose(drawn[[j for j, _ in kept]], k[[i for _, i in kept]])
    assert set(np.unique(drawn)) <= set(np.unique(k))   # a new point: its nearest vertex's value
    w.scene.set_slice(None)
    assert w.scene.actor.mapper.array_name == "curvature"
    assert np.allclose(np.asarray(w.scene.mesh.point_data["curvature"])[:len(V)], k)
    # a picture drawn off the window (a screenshot, the still picture's worker) from a detached copy
    import pyvista as pv

    from gcmh_studio.sections import SectionScene

    pl = pv.Plotter(off_screen=True, window_size=[200, 150])
    try:
        other = SectionScene(pl, anti_aliasing=None)
        other.adopt(w.scene.detached(), w.scene.style)
        assert other.actor.mapper.array_name == "curvature"
        assert np.allclose(np.asarray(other.mesh.point_data["curvature"])[:len(V)], k)
    finally:
        pl.close()
    w.model.set_style(color_by=w.scene.names[0])   # another colouring wins
    assert not box.curvature_check.isChecked()
    assert w.scene.actor.mapper.array_name != "curvature"
