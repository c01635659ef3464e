"""Exact sections in the view (app/sections.py) and the strip of their chi and pieces (app/qt_section_strip.py)."""

import numpy as np
import pytest
import pyvista as pv

from gcmh_core import extract
from gcmh_studio.projection import View
from gcmh_studio.scene import Style
from gcmh_studio.sections import SECTION_COLOR, SectionScene, section_text

SPHERE3 = ["x**2 + y**2 + z**2 + w**2 - 1"]


@pytest.fixture(scope="module")
def sphere3():
    return extract(SPHERE3, (-1.25, 1.25), 10, variables=list("xyzw"))


@pytest.fixture
def scene(sphere3):
    pl = pv.Plotter(off_screen=True, window_size=(480, 360))
    sc = SectionScene(pl, anti_aliasing=None)
    sc.set_complex(sphere3, list("xyzw"), View(np.eye(4)[:3], "orthographic"), Style(title="3-sphere"))
    yield sc
    pl.close()


def coral_pixels(img) -> int:
    """Pixels of the section's colour, however lit: red well above blue, and bright."""
    a = np.asarray(img, dtype=int)
    r, g, b = a[..., 0], a[..., 1], a[..., 2]
    return int(np.count_nonzero((r > 120) & (r - b > 50) & (r > g)))


def test_slicing_the_three_sphere_draws_its_two_sphere(scene):
    w = np.eye(4)[3]
    drawn = scene.set_slice(w, 0.3, 0.05)
    lay = scene.sections
    assert lay.shown and drawn == lay.mesh.n_cells > 0
    assert scene.mesh is None                                       # no slab under the section
    assert scene.overlay_meshes.ghost is not None                   # the whole result, faint
    assert lay.cells.complex.euler_characteristic() == 2 and lay.cells.pieces == 1
    assert lay.text() == "w = 0.3   section: chi = 2, 1 piece"
    # the section is placed with the whole result's centre and scales: on screen, x y z of its vertices
    pts = np.asarray(lay.mesh.points)
    assert np.array_equal(lay.geometry.projector.center, scene.geometry.projector.center)
    assert np.allclose(pts, lay.geometry.projector.project_view(scene.view))
    assert np.allclose(np.asarray(lay.cells.complex.vertices)[:, 3], 0.3)
    r = np.linalg.norm(np.asarray(lay.cells.complex.vertices)[:, :3], axis=1)
    assert np.allclose(r, np.sqrt(1 - 0.09), atol=0.06)


def test_the_section_grows_and_shrinks_on_screen(scene):
    """A flatlander's 3-sphere: the coral sphere is largest at w = 0 and a dot near w = +-1."""
    w = np.eye(4)[3]
    counts = []
    for c in (-0.9, -0.5, 0.0, 0.5, 0.9):
        scene.set_slice(w, c, 0.05)
        counts.append(coral_pixels(scene.plotter.screenshot(None, return_img=True)))
    assert counts[0] < counts[1] < counts[2] > counts[3] > counts[4] > 0


def test_the_section_follows_the_projection(scene):
    w = np.eye(4)[3]
    scene.set_slice(w, 0.2, 0.05)
    before = np.array(scene.sections.mesh.points)
    t = np.radians(40)
    P = np.eye(4)[:3].copy()
    P[0] = [np.cos(t), 0, 0, np.sin(t)]                             # x turned towards w
    scene.set_projection(View(P, "orthographic"))
    after = np.asarray(scene.sections.mesh.points)
    assert after.shape == before.shape and not np.allclose(after, before)
    want = scene.sections.geometry.projector.project_view(scene.view)
    assert np.allclose(after, want)


def test_a_new_value_rewrites_the_same_actor_and_no_slice_restores_the_result(scene):
    w = np.eye(4)[3]
    scene.set_slice(w, 0.1, 0.05)
    actor = scene.sections.actor
    scene.set_slice(w, -0.6, 0.05)
    assert scene.sections.actor is actor and scene.sections.text().startswith("w = -0.6")
    scene.set_slice(w, 2.0, 0.05)                                    # beyond the 3-sphere: empty
    assert scene.sections.mesh is None and scene.sections.text() == "w = 2   section: empty"
    scene.set_slice(w, 0.2, 0.05)                                    # and back: the words stay in the picture
    assert scene.plotter.renderer.HasViewProp(scene.sections.text_actor)
    assert scene.plotter.renderer.HasViewProp(scene.sections.actor)
    scene.set_slice(None)
    assert not scene.sections.shown and scene.sections.text() == ""
    assert scene.mesh is not None and scene.mesh.n_cells == len(scene.geometry.offsets) - 1


def test_curves_and_mixed_reversed_directions_keep_the_window(qtbot):
    """A curve is sliced by the window (its section would be points); a glued surface cut along a reversed
    axis mixed with another too (its hyperplanes are no sets of the glued space: the engine refuses)."""
    from gcmh_core.examples import load_example

    pl = pv.Plotter(off_screen=True, window_size=(320, 240))
    sc = SectionScene(pl, anti_aliasing=None)
    try:
        circle = extract(["x**2 + y**2 - 1", "z"], (-1.3, 1.3), 10, variables=list("xyz"))
        sc.set_complex(circle, list("xyz"), np.eye(3), Style())
        assert sc.set_slice(np.eye(3)[0], 0.0, 0.2) > 0 and not sc.sections.shown and sc.mesh is not None
        ex = load_example("moebius-band")
        cx = extract(ex.formulas, ex.bounds, [24, 24, 8, 24, 8], variables=ex.variables, periodic=ex.periodic)
        sc.set_complex(cx, ex.variables, np.eye(5)[:3], Style())
        mixed = np.eye(5)[4] + np.eye(5)[0]                 # t + x: t is reversed across the seam of s
        assert sc.set_slice(mixed, 0.3, 0.2) > 0 and not sc.sections.shown
        assert sc.set_slice(np.eye(5)[4], 0.2, 0.05) > 0 and sc.sections.shown   # t alone: {t = +-0.2}
        assert sc.sections.text() == "t = 0.2   section: chi = 0, 1 piece"
        # the band of cells round both levels the section lies on, t = 0.2 and t = -0.2
        from gcmh_studio.slicing import clip_polygons

        geo = sc.geometry
        bands = [clip_polygons(sc.complex.vertices, geo.offsets, geo.vids, np.eye(5)[4], c, 0.05).n_cells
                 for c in (0.2, -0.2)]
        assert min(bands) > 0 and sc.mesh.n_cells == sum(bands)
    finally:
        pl.close()


def test_a_glued_surface_is_cut_across_its_seam(qtbot):
    """The torus of angles cut along s (a periodic variable): its section, one circle, drawn in coral over
    the band; cut along t, the circle round s, whose edge across the seam of s is drawn whole (not across
    the box) in the picture's copy."""
    from gcmh_core.examples import load_example
    from gcmh_studio.sections import _seam_edges_whole

    ex = load_example("torus-angles")
    cx = extract(ex.formulas, ex.bounds, 12, variables=ex.variables, periodic=ex.periodic)
    pl = pv.Plotter(off_screen=True, window_size=(320, 240))
    sc = SectionScene(pl, anti_aliasing=None)
    try:
        sc.set_complex(cx, ex.variables, np.eye(5)[:3], Style())
        s, t = ex.variables.index("s"), ex.variables.index("t")
        band = sc.set_slice(np.eye(5)[s], 3.0, 0.2)
        assert band == sc.mesh.n_cells > 0 and sc.sections.shown and sc.sections.geometry.kind == "lines"
        assert sc.sections.text() == "s = 3   section: chi = 0, 1 piece"
        pl.render()
        assert coral_pixels(pl.screenshot(None, return_img=True)) > 30
        sc.set_slice(np.eye(5)[t], 1.0, 0.2)
        sec = sc.sections.cells.complex
        E = np.asarray(sec.edges)
        assert np.abs(np.diff(sec.vertices[E][:, :, s], axis=1)).max() > np.pi     # one edge across the seam
        drawn = _seam_edges_whole(sec)
        F = np.asarray(drawn.edges)
        assert drawn.count(1) == sec.count(1)
        assert np.abs(np.diff(drawn.vertices[F][:, :, s], axis=1)).max() < np.pi
        assert sc.sections.geometry.edges.shape[0] == sec.count(1)
    finally:
        pl.close()


def test_with_angles_as_circles_the_section_sits_on_the_circles(qtbot):
    """The torus of angles shown along (s, t, x) with its angles drawn as circles: the section (cut along x)
    is drawn through the same circles as the surface, inside its picture (as numbers, s and t reach 2pi, far
    outside it), and follows when the look is turned back."""
    from gcmh_core.examples import load_example

    ex = load_example("torus-angles")
    cx = extract(ex.formulas, ex.bounds, 12, variables=ex.variables, periodic=ex.periodic)
    names = ex.variables
    pl = pv.Plotter(off_screen=True, window_size=(320, 240))
    sc = SectionScene(pl, anti_aliasing=None)
    try:
        view = View(np.eye(5)[[names.index("s"), names.index("t"), names.index("x")]], "orthographic")
        sc.set_complex(cx, names, view, Style())
        sc.set_angle_look(True, False)
        assert sc.circles_on
        x = np.eye(5)[names.index("x")]

        def section_inside_the_whole():
            sc.set_slice(None)
            whole = np.array(sc.mesh.points)
            sc.set_slice(x, 0.5, 0.1)
            pts = np.array(sc.sections.mesh.points)
            lo, hi = whole.min(axis=0), whole.max(axis=0)
            pad = 0.02 * (hi - lo).max()
            return pts, bool(np.all((pts >= lo - pad) & (pts <= hi + pad)))

        on_circles, inside = section_inside_the_whole()
        assert inside
        sc.set_angle_look(False, False)            # the section on show follows, then a new one is the same
        followed = np.array(sc.sections.mesh.points)
        as_numbers, inside = section_inside_the_whole()
        assert inside and np.allclose(followed, as_numbers) and not np.allclose(on_circles, as_numbers)
    finally:
        pl.close()


def test_the_three_torus_of_angles_cut_along_an_angle_shows_a_two_torus(qtbot):
    """T^3 (a graph over three periodic angles) cut along a = c: a 2-torus, drawn opaque, chi 0, 1 piece."""
    tau = 2 * np.pi
    cx = extract(["w - 0.4*cos(a)*cos(b)*sin(c)"], [(0, tau), (0, tau), (0, tau), (-1, 1)], [8, 8, 8, 6],
                 variables=list("abcw"), periodic=["a", "b", "c"])
    pl = pv.Plotter(off_screen=True, window_size=(320, 240))
    sc = SectionScene(pl, anti_aliasing=None)
    try:
        sc.set_complex(cx, list("abcw"), View(np.eye(4)[[1, 2, 3]], "orthographic"), Style())
        for c in (0.0, 1.3, tau - 0.01):
            assert sc.set_slice(np.eye(4)[0], c, 0.1) > 0
            assert sc.sections.text() == f"a = {c:.3g}   section: chi = 0, 1 piece"
            assert sc.sections.geometry.kind != "lines"
        pl.render()
        assert coral_pixels(pl.screenshot(None, return_img=True)) > 500
    finally:
        pl.close()


def test_a_still_picture_copy_carries_the_section(scene):
    w = np.eye(4)[3]
    scene.set_slice(w, 0.4, 0.05)
    copy = scene.detached()
    assert copy.sections.mesh is not scene.sections.mesh
    pl = pv.Plotter(off_screen=True, window_size=(320, 240))
    try:
        other = SectionScene(pl, anti_aliasing=None)
        other.adopt(copy)
        assert other.sections.actor is not None and other.sections.text() == scene.sections.text()
        pl.render()
        assert coral_pixels(pl.screenshot(None, return_img=True)) > 50
    finally:
        pl.close()


def test_every_frame_of_a_slice_sweep_says_its_value_and_chi(scene):
    """The slice animation's frames (gcmh_studio.offscreen.animation_images on a SectionScene, as the
    headless --animate slice path draws them): each carries the words, with its own value."""
    from gcmh_studio.animation import slice_frames
    from gcmh_studio.offscreen import animation_images
    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.slicing import SliceWindow

    model = ProjectionModel(n=4)
    window = SliceWindow(3, c=0.0, w=0.05)
    said = []
    for img in animation_images(scene, model, slice_frames(-1.02, 1.02, 8), window):
        said.append(scene.sections.text())
        band = np.asarray(img)[-45:, int(0.2 * img.shape[1]):int(0.8 * img.shape[1])]
        assert np.count_nonzero(band.sum(-1) > 500) > 50              # the words are drawn
    assert len(set(said)) == len(said) - 3                           # one value each (the sweep comes back)
    assert said[0] == "w = -1.02   section: empty"
    assert all("chi = 2, 1 piece" in t for t in said if "empty" not in t)
    assert said[2] == "w = 0   section: chi = 2, 1 piece" and said[4] == "w = 1.02   section: empty"


def test_section_text_words():
    assert section_text("w", 0.123456, None) == "w = 0.123   section: empty"
    assert section_text("w", -2.2e-16, None, 2.0) == section_text("w", -0.0, None) == "w = 0   section: empty"
    assert SECTION_COLOR.startswith("#")


# ------------------------------------------------------------------------------------- the strip
@pytest.fixture
def studio(qtbot, sphere3):
    from gcmh_studio.model import StudioModel

    m = StudioModel()
    m.set_view_variables(list("xyzw"), False)
    m.set_result(sphere3, list("xyzw"), "3-sphere")
    return m


def test_the_strip_plots_chi_and_pieces_of_the_three_sphere(qtbot, studio):
    from gcmh_studio.qt_section_strip import QtSectionStrip

    strip = QtSectionStrip(studio)
    qtbot.addWidget(strip)
    strip.resize(300, 80)
    assert strip.isHidden()                                          # slicing is off
    studio.set_slice(on=True, index=3, hidden=False, c=0.5)
    assert not strip.isHidden()
    qtbot.waitUntil(lambda: strip.profile is not None or strip.error is not None, timeout=60_000)
    assert strip.error is None
    prof = strip.profile
    assert prof.values.size > 50 and np.all(prof.chi == 2) and np.all(prof.pieces == 1)
    assert strip.value_at(0.5) == (2, 1)
    img = strip.grab().toImage()
    assert not img.isNull()
    key = strip.key
    studio.set_slice(c=0.8)                                          # the same direction: no new profile
    assert strip.key == key and strip.profile is prof
    # a click moves the slice
    from qtpy.QtCore import QPoint, Qt

    r = strip._plot_rect()
    qtbot.mouseClick(strip, Qt.LeftButton, pos=QPoint(int(r.left() + 0.25 * r.width()), int(r.center().y())))
    assert studio.slice.c == pytest.approx(0.25, abs=0.01)


def test_the_strip_sees_the_torus_change(qtbot):
    from gcmh_studio.model import StudioModel
    from gcmh_studio.qt_section_strip import QtSectionStrip

    torus = extract(["(x**2 + y**2 + z**2 + 0.84)**2 - 4*(x**2 + y**2)"], [(-1.6, 1.6), (-1.6, 1.6), (-0.6, 0.6)],
                    [24, 24, 10], variables=list("xyz"))
    m = StudioModel()
    m.set_view_variables(list("xyz"), False)
    m.set_result(torus, list("xyz"), "torus")
    strip = QtSectionStrip(m)
    qtbot.addWidget(strip)
    m.set_slice(on=True, index=0, hidden=False, c=0.5)
    qtbot.waitUntil(lambda: strip.profile is not None, timeout=60_000)
    prof = strip.profile
    assert set(prof.pieces.tolist()) == {1, 2} and np.all(prof.chi == 0)
    # one circle, two, one: the circle splits near x = -0.6 and joins near 0.6 (the ends, x = +-1.4, are
    # the range's own ends)
    jumps = prof.values[prof.changes()]
    assert len(jumps) == 2 and np.allclose(jumps, [-0.6, 0.6], atol=0.1)


def test_the_strip_plots_a_glued_band_cut_along_its_reversed_axis(qtbot):
    """The glued Moebius band along t (reversed across the seam of s): every section one circle but at the
    band's edges t = +-0.5 (the range's own ends), where the strip's values do not reach."""
    from gcmh_core.examples import load_example
    from gcmh_studio.model import StudioModel
    from gcmh_studio.qt_section_strip import QtSectionStrip

    ex = load_example("moebius-band")
    band = extract(ex.formulas, ex.bounds, [24, 24, 8, 24, 8], variables=ex.variables, periodic=ex.periodic)
    m = StudioModel()
    m.set_view_variables(ex.variables, False)
    m.set_result(band, ex.variables, "band")
    strip = QtSectionStrip(m)
    qtbot.addWidget(strip)
    m.set_slice(on=True, index=ex.variables.index("t"), hidden=False, c=0.1)
    qtbot.waitUntil(lambda: strip.profile is not None, timeout=60_000)
    prof = strip.profile
    assert np.all(prof.chi == 0) and np.all(prof.pieces == 1) and prof.values.size > 10


def test_the_strip_hides_for_curves_and_the_box_shows_the_width_for_them(qtbot, studio):
    from gcmh_studio.qt_slice_box import QtSliceBox

    box = QtSliceBox(studio)
    qtbot.addWidget(box)
    box.set_names(list("xyzw"))
    box.show()
    studio.set_slice(on=True, index=3, hidden=False, c=0.5)
    assert box.strip.isVisible() and not box.slice_w.isVisible() and box.slice_c_label.text() == "value"
    sphere = extract(["x**2 + y**2 + z**2 - 1"], (-1.3, 1.3), 8, variables=list("xyz"))
    studio.set_view_variables(list("xyz"), False)
    studio.set_result(sphere, list("xyz"), "sphere")                  # a surface: its band keeps a width
    studio.set_slice(on=True, index=2, hidden=False, c=0.5)           # (new variables turned the slice off)
    assert box.strip.isVisible() and box.slice_w.isVisible() and box.slice_c_label.text() == "value"
    circle = extract(["x**2 + y**2 - 1", "z"], (-1.3, 1.3), 10, variables=list("xyz"))
    studio.set_result(circle, list("xyz"), "circle")
    assert not box.strip.isVisible() and box.slice_w.isVisible() and box.slice_c_label.text() == "centre"


def test_a_moving_slice_hides_the_ghost_and_rest_brings_it_back(qtbot, small_window):
    """A slider step draws the section with the moving look (no FXAA, no faint whole behind it: 250 -> 90 ms
    a three-torus step under software GL); at rest the whole comes back."""
    from gcmh_core.examples import load_example

    from app_helpers import small_div

    w = small_window
    ex = load_example("three-sphere")
    with qtbot.waitSignal(w.runFinished, timeout=180_000):
        assert w.load_example("three-sphere", div=small_div(ex))
    sc = w.viewer.scene
    w.model.set_slice(on=True, index=3, hidden=False, c=0.1)
    qtbot.waitUntil(lambda: not sc.moving_shown(), timeout=30_000)
    ghost = sc.overlay_meshes.ghost
    assert ghost is not None and ghost[1].GetVisibility() and sc.sections.shown
    w.model.set_slice(c=0.2)
    assert sc.moving_shown() and not ghost[1].GetVisibility() and sc.sections.shown
    qtbot.waitUntil(lambda: not sc.moving_shown(), timeout=30_000)
    assert sc.overlay_meshes.ghost[1].GetVisibility()
    assert bool(w.plotter.renderer.GetUseFXAA()) == (sc.anti_aliasing == "fxaa")


def test_the_window_slices_the_closed_klein_bottle_along_its_glued_angles(qtbot, small_window):
    """In the window, the slice box's slider on the closed Klein bottle: along s (periodic) and along t
    (reversed across the seam of s), the glued space's section, a circle, with its words."""
    from gcmh_core.examples import load_example

    w = small_window
    ex = load_example("klein-bottle-closed")
    with qtbot.waitSignal(w.runFinished, timeout=180_000):
        assert w.load_example("klein-bottle-closed", div=[20, 20, 10, 20, 20])
    sc = w.viewer.scene
    sb = w.projection_panel.slice_box
    for var in ("s", "t"):
        sb.slice_combo.setCurrentIndex(ex.variables.index(var))
        sb.setChecked(True)
        for step in (300, 700):
            before = sc.sections.text()
            sb.slice_c.setValue(step)
            qtbot.waitUntil(lambda v=var, b=before: sc.sections.shown and sc.sections.text() != b
                            and sc.sections.text().startswith(v + " = "), timeout=30_000)
            assert sc.sections.text().endswith("section: chi = 0, 1 piece")
            assert sc.sections.cells.complex.boundary_facets().size == 0
        qtbot.waitUntil(lambda v=var: sb.strip.profile is not None and sb.strip.profile.along.endswith(v),
                        timeout=120_000)
        assert np.all(sb.strip.profile.pieces == 1)
