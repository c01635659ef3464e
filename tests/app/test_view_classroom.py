"""The view in a classroom (issue 16): never frozen, always framed, steering in any n, pictures for a slide.

Under Xvfb (pytest-xvfb ``--xvfb-backend xvfb``). No timing assertions: the GUI timer must tick during and
after a run, a new result costs one render, the object lies inside the picture after every change
(its shown points projected through the camera), a Shift-drag turns hidden planes, GIFs keep their
frame count and the title's white, PLY and OBJ files carry the colours.
"""

import os

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from gcmh_core.examples import list_examples, load_example

from app_helpers import small_div, torus_complex

EXAMPLES = [ex.name for ex in list_examples()]
SHOTS = os.environ.get("GCMH_TEST_SHOTS")   # a folder: the tests leave their pictures there to look at


def _shot(img, name):
    if SHOTS:
        from PIL import Image

        os.makedirs(SHOTS, exist_ok=True)
        Image.fromarray(np.asarray(img)[..., :3]).save(os.path.join(SHOTS, name))


def _run_example(qtbot, window, name, div=None):
    ex = load_example(name)
    with qtbot.waitSignal(window.runFinished, timeout=180_000) as b:
        assert window.load_example(name, div=div or small_div(ex))
    assert b.args[0] == "done", window.last_status
    qtbot.wait(50)   # the one paint
    return ex


def _inside(window):
    from gcmh_studio.camera import inside_share

    return inside_share(window.plotter)


# --------------------------------------------------------------------------- never frozen
def test_timer_ticks_during_and_after_a_run_and_a_result_costs_one_render(qtbot, window):
    from qtpy.QtCore import QTimer

    ticks = {"run": 0, "after": 0}
    phase = {"now": "run"}
    t = QTimer()
    t.setInterval(10)
    t.timeout.connect(lambda: ticks.__setitem__(phase["now"], ticks[phase["now"]] + 1))
    v = window.viewer
    before = {}
    window.resultChanged.connect(lambda *_: before.setdefault("renders", v.renders))
    t.start()
    try:
        _run_example(qtbot, window, "complex-cosine", div=40)
        phase["now"] = "after"
        qtbot.wait(400)
    finally:
        t.stop()
    assert ticks["run"] > 0, "the GUI timer never ticked while the run went on"
    assert ticks["after"] > 0, "the GUI timer never ticked after the result arrived"
    counts = []
    window.resultChanged.connect(lambda *_: counts.append(v.renders))
    r0 = v.renders
    assert window.run()
    qtbot.waitSignal(window.runFinished, timeout=120_000).wait() if window.is_running() else None
    qtbot.waitUntil(lambda: bool(counts), timeout=120_000)
    assert counts[0] - r0 == 1, f"a new result asked for {counts[0] - r0} renders, not one"


def test_window_anti_aliasing_is_cheap_and_screenshots_super_sample(qtbot, window, tmp_path):
    _run_example(qtbot, window, "sphere", div=12)
    assert window.scene.anti_aliasing == "fxaa"
    img = window.viewer.save_screenshot(tmp_path / "s.png", (320, 240))
    assert img.shape[:2] == (240, 320)


# --------------------------------------------------------------------------- always framed
def test_camera_contains_the_object_after_each_change(qtbot, window, tmp_path):
    _run_example(qtbot, window, "clifford-torus", div=10)
    pp = window.projection_panel
    assert _inside(window) == 1.0, "first open"
    for mapping in ("orthographic", "perspective", "stereographic"):
        pp.set_mapping(mapping)
        assert _inside(window) == 1.0, mapping
    pp.set_angle((0, 3), 90.0)
    assert _inside(window) == 1.0, "a quarter turn of x1-x4"
    pp.set_axes_by_names(["x2", "x3", "x4"])
    assert _inside(window) == 1.0, "another base"
    assert pp.set_slice("x1", 0.3, 0.2)
    assert _inside(window) == 1.0, "a slice"
    cam = window.plotter.camera
    direction = np.asarray(cam.direction)
    pp.set_mapping("perspective")
    assert np.allclose(np.asarray(window.plotter.camera.direction), direction, atol=1e-6), \
        "a refit keeps the user's view direction"
    _shot(window.screenshot_array(), "framed-window.png")


def test_keep_camera_holds_it(qtbot, window):
    _run_example(qtbot, window, "clifford-torus", div=10)
    pp = window.projection_panel
    pp.keep_camera_check.setChecked(True)
    cam = window.plotter.camera
    before = (tuple(cam.position), tuple(cam.focal_point), cam.view_angle)
    pp.set_mapping("stereographic")
    pp.set_angle((0, 3), 60.0)
    cam = window.plotter.camera
    assert (tuple(cam.position), tuple(cam.focal_point), cam.view_angle) == before


@pytest.mark.parametrize("size", [(3840, 2160), (600, 1400)])
def test_screenshots_of_any_size_frame_the_object(qtbot, window, tmp_path, size):
    _run_example(qtbot, window, "three-torus")
    img = window.viewer.save_screenshot(tmp_path / "big.png", size, transparent=True)
    assert img.shape[:2] == (size[1], size[0])
    a = img[..., 3]
    # nothing drawn on the picture's edges: the object is inside (text and bar sit within the margins)
    assert a[:, :2].max() == 0 and a[:, -2:].max() == 0 and a[-2:, :].max() == 0 and a[:2, :].max() == 0
    _shot(img[::4, ::4], f"screenshot-{size[0]}x{size[1]}.png")


@pytest.mark.parametrize("name", EXAMPLES)
def test_every_example_opens_framed(name):
    """First open, as the headless screenshot and the gallery draw it: every vertex inside the picture,
    below the title."""
    from gcmh_studio.camera import default_camera, inside_share
    from gcmh_studio.headless import offscreen_scene
    from gcmh_studio.jobs import Job, run_job
    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Style

    ex = load_example(name)
    cx = run_job(Job(list(ex.formulas), list(ex.variables), [tuple(b) for b in ex.bounds], small_div(ex),
                     extra={"params": ex.param_values()} if ex.params else {}))
    view = ex.view
    m = ProjectionModel(n=ex.n, axes=tuple(ex.variables.index(a) for a in view["project"]),
                        mapping=view.get("mapping", "orthographic"))
    with offscreen_scene((800, 600)) as sc:
        sc.set_complex(cx, ex.variables, m.view(), Style(color_by=view.get("color"), title=ex.title, subtitle="s"))
        default_camera(sc.plotter)
        share = inside_share(sc.plotter)
    assert share == 1.0, f"{name}: {100 * share:.1f}% of the vertices in view"


def test_clifford_torus_opens_without_coincident_sheets():
    """In (x1, x2, x3) orthographic the two sheets of the Clifford torus coincide (z-fighting)."""
    ex = load_example("clifford-torus")
    assert ex.view["mapping"] != "orthographic" or ex.view["project"] != ["x1", "x2", "x3"]


# --------------------------------------------------------------------------- steering in any n
def test_shift_drag_turns_hidden_planes(qtbot, window):
    from qtpy.QtCore import QPoint, Qt
    from qtpy.QtTest import QTest

    _run_example(qtbot, window, "clifford-torus", div=10)
    pp = window.projection_panel
    pp.set_mapping("orthographic")
    pp.reset()
    w = window.viewer.widget
    c = QPoint(w.width() // 2, w.height() // 2)
    cam_before = tuple(window.plotter.camera.position)
    QTest.mousePress(w, Qt.LeftButton, Qt.ShiftModifier, c)
    QTest.mouseMove(w, c + QPoint(60, 0))
    QTest.mouseRelease(w, Qt.LeftButton, Qt.ShiftModifier, c + QPoint(60, 0))
    assert np.any(np.abs(pp.model.angles) > 1.0), "a Shift-drag turned no plane"
    P = pp.model.matrix()
    assert np.abs(P[:, 3]).max() > 0.1, "x4 (hidden) did not come into view"
    # the turn is in R^4: the camera itself did not move (VTK's trackball never saw the drag)
    assert np.allclose(window.plotter.camera.position, cam_before) or _inside(window) == 1.0
    # Ctrl+Shift picks the next hidden direction; with one hidden direction (n = 4) it is the same one
    a = pp.model.angles.copy()
    QTest.mousePress(w, Qt.LeftButton, Qt.ShiftModifier | Qt.ControlModifier, c)
    QTest.mouseMove(w, c + QPoint(0, 40))
    QTest.mouseRelease(w, Qt.LeftButton, Qt.ShiftModifier | Qt.ControlModifier, c + QPoint(0, 40))
    assert not np.allclose(pp.model.angles, a)


def test_turned_angles_rotate_the_screen_against_the_hidden_axis():
    from gcmh_studio.projection import ProjectionModel, givens_angles, rotation, turned_angles

    for n in (4, 6, 10):
        R = rotation(n, np.random.default_rng(n).uniform(-np.pi, np.pi, n * (n - 1) // 2))
        assert np.allclose(rotation(n, givens_angles(R)), R)
    m = ProjectionModel(n=6)
    m.angles[:] = turned_angles(m, np.array([1.0, 0.0, 0.0]), 1, 30.0)
    P = m.matrix()
    hidden = 4   # the second hidden axis of (x1, x2, x3 | x4, x5, x6) is x5
    assert np.isclose(abs(P[0, hidden]), np.sin(np.radians(30.0)))
    assert np.allclose(P[1:], np.eye(6)[1:3])


def test_plane_list_scales_to_ten_dimensions(qtbot):
    from gcmh_studio.qt_projection_panel import QtProjectionPanel

    pp = QtProjectionPanel()
    qtbot.addWidget(pp)
    names = [f"x{i + 1}" for i in range(10)]
    pp.set_variables(names, keep=False)
    assert len(pp.sliders) == 45
    order = pp.plane_order()
    first = [pp.model.planes[r] for r in order[:21]]
    assert all((i < 3) != (j < 3) for i, j in first), "the planes that bring a hidden axis into view come first"
    pp.plane_filter.setText("x10")
    shown = [r for r, s in enumerate(pp.sliders) if not s.isHidden()]
    assert len(shown) == 9 and all("x10" in pp.slider_labels[r].text() for r in shown)
    assert pp.drag_combo.count() == 7


# --------------------------------------------------------------------------- level of detail
def test_large_results_move_at_a_coarse_level_of_detail(qtbot):
    import pyvista as pv

    from gcmh_studio.geometry import Geometry
    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Scene, Style

    cx = torus_complex(420, 4)            # 176,400 vertices: above the threshold
    geo = Geometry.build(cx)
    assert geo.coarse is not None and len(geo.coarse.projector.XT.T) < cx.count(0) // 3
    pl = pv.Plotter(off_screen=True, window_size=[320, 240])
    try:
        sc = Scene(pl)
        m = ProjectionModel(n=4)
        sc.set_complex(cx, cx.point_names(), m.view(), Style(color_by="x4"), geometry=geo)
        m.angles[2] = 30.0
        sc.set_projection(m.view(), render=False, moving=True)
        assert sc.coarse_shown() and not sc.actor.GetVisibility()
        sc.set_projection(m.view(), render=False)
        assert not sc.coarse_shown() and sc.actor.GetVisibility()
        # (the full mesh's points, each held SHEET_GAP of the radius off its coincident sheets)
        from gcmh_studio.scene import SHEET_GAP

        gap = SHEET_GAP * sc.projector.radii()[0]
        assert np.allclose(sc.mesh.points, sc.projector.project_view(m.view()), atol=1e-5 + 1.01 * gap)
    finally:
        pl.close()


def _lights(plotter):
    c = plotter.renderer.GetLights()
    return [c.GetItemAsObject(i) for i in range(c.GetNumberOfItems())]


def test_a_see_through_view_moves_under_one_headlight_and_rests_as_the_same_picture():
    """The moving look of a see-through surface: one headlight instead of the light kit (a cheaper frame
    that still shows the colours and the edges); at rest the same light objects come back and the picture
    is the still one, pixel for pixel."""
    import pyvista as pv

    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Scene, Style

    cx = torus_complex(40, 4)
    pl = pv.Plotter(off_screen=True, window_size=[320, 240])
    try:
        sc = Scene(pl)
        m = ProjectionModel(n=4)
        m.angles[2] = 25.0
        sc.set_complex(cx, cx.point_names(), m.view(), Style(color_by="x4", opacity=0.4, show_edges=True))
        pl.screenshot(return_img=True)   # (an off-screen plotter's first picture differs from every later one)
        sc.set_projection(m.view(), render=True)
        kit = _lights(pl)
        assert len(kit) > 1 and sc.moving_look_available() and sc.see_through()
        still = pl.screenshot(return_img=True)
        m.angles[2] = 40.0
        sc.set_projection(m.view(), render=True, moving=True)
        assert sc.moving_shown() and len(_lights(pl)) == 1
        m.angles[2] = 25.0
        sc.set_projection(m.view(), render=True, moving=True)
        moving = pl.screenshot(return_img=True)
        _shot(moving, "see_through_moving.png")
        sc.set_moving(False)
        pl.render()
        assert not sc.moving_shown() and _lights(pl) == kit
        again = pl.screenshot(return_img=True)
        _shot(again, "see_through_still.png")
        assert np.array_equal(again, still), "the still picture changed after moving"
        # the moving frame is the same object in the same place, only lit differently
        assert np.any(moving != still)
        assert np.abs(moving.astype(int) - still.astype(int)).mean() < 12
    finally:
        pl.close()


def test_an_opaque_surface_moves_with_its_own_lights_and_only_fxaa_paused():
    """An opaque surface keeps its lights and its full mesh while moving; only the FXAA pass pauses, and the
    still picture comes back pixel for pixel."""
    import pyvista as pv

    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Scene, Style

    cx = torus_complex(30, 4)
    pl = pv.Plotter(off_screen=True, window_size=[200, 150])
    try:
        sc = Scene(pl, anti_aliasing="fxaa")
        m = ProjectionModel(n=4)
        sc.set_complex(cx, cx.point_names(), m.view(), Style(color_by="x4"))
        pl.screenshot(return_img=True)   # (an off-screen plotter's first picture differs from every later one)
        sc.set_projection(m.view(), render=True)
        still = pl.screenshot(return_img=True)
        kit = _lights(pl)
        assert sc.moving_look_available() and pl.renderer.GetUseFXAA()
        sc.set_projection(m.view(), render=False, moving=True)
        assert sc.moving_shown() and _lights(pl) == kit and not sc.coarse_shown()
        assert not pl.renderer.GetUseFXAA()
        sc.set_moving(False)
        assert not sc.moving_shown() and pl.renderer.GetUseFXAA()
        pl.render()
        assert np.array_equal(pl.screenshot(return_img=True), still)
        plain = Scene(pv.Plotter(off_screen=True, window_size=[200, 150]), anti_aliasing=None)
        plain.set_complex(cx, cx.point_names(), m.view(), Style(color_by="x4"))
        assert not plain.moving_look_available()   # (no FXAA to pause, opaque, small: nothing cheaper)
        plain.plotter.close()
    finally:
        pl.close()


def test_the_three_torus_rests_as_the_picture_it_opened_with(qtbot, window):
    """In the window: a slider step draws the moving look, and once the view rests (the settle timer) the
    slider set back gives the very picture the result opened with (the camera held, so that nothing
    refits it)."""
    from gcmh_studio.qt_viewer import SETTLE_MS

    _run_example(qtbot, window, "three-torus")
    v = window.viewer
    window.projection_panel.keep_camera_check.setChecked(True)
    assert v.scene.see_through() and v.scene.geometry.coarse is None
    qtbot.wait(SETTLE_MS + 100)
    first = v.screenshot_array()
    _shot(first, "three_torus_still.png")
    pp = window.projection_panel
    row = next(r for r, (i, j) in enumerate(pp.model.planes) if j >= 3)
    value = pp.sliders[row].value()
    pp.sliders[row].setValue(value + 20)
    assert v.scene.moving_shown()
    qtbot.wait(50)
    _shot(v.plotter.screenshot(return_img=True), "three_torus_moving.png")
    pp.sliders[row].setValue(value)
    qtbot.waitUntil(lambda: not v.scene.moving_shown(), timeout=5000)
    assert np.array_equal(v.screenshot_array(), first), "the still picture changed after moving"


# --------------------------------------------------------------------------- pictures for a slide
def test_gif_counts_frames_exactly_and_keeps_the_titles_white(tmp_path):
    from PIL import Image

    from gcmh_studio.animation import write_animation

    h, w = 60, 80
    y = np.linspace(0, 1, h)[:, None, None]
    base = (np.array([31, 36, 48]) * (1 - y) + np.array([74, 84, 104]) * y).astype(np.uint8)
    frames = []
    for k in range(12):
        f = np.broadcast_to(base, (h, w, 3)).copy()
        f[10:50, 20:60] = (np.array([255, 0, 0]) * (k / 11) + np.array([0, 0, 255]) * (1 - k / 11)).astype(np.uint8)
        f[2:5, 2:30] = 255            # the title
        frames.append(f)
    frames += [frames[-1]] * 3        # still frames at the end must stay frames
    p = tmp_path / "a.gif"
    assert write_animation(p, frames, fps=10) == 15
    im = Image.open(p)
    assert im.n_frames == 15
    for k in (0, 7, 14):
        im.seek(k)
        rgb = np.asarray(im.convert("RGB"))
        assert np.all(rgb[2:5, 2:30] == 255), "the title is not white any more"
        assert np.abs(rgb.astype(int) - frames[k].astype(int)).mean() < 4


def test_ply_and_obj_exports_carry_the_colours(qtbot, window, tmp_path):
    import pyvista as pv

    _run_example(qtbot, window, "sphere", div=12)
    ply = tmp_path / "m.ply"
    window.export_mesh(ply)
    m = pv.read(ply)
    rgb = np.asarray(m.point_data["RGB"])
    assert rgb.shape == (m.n_points, 3) and len(np.unique(rgb, axis=0)) > 20, "no colour map in the PLY"
    obj = tmp_path / "m.obj"
    window.export_mesh(obj)
    v = [ln.split() for ln in obj.read_text().splitlines() if ln.startswith("v ")]
    assert len(v) > 0 and all(len(r) == 7 for r in v[:50]), "OBJ vertices without r g b"


def test_colour_bar_and_axes_say_what_the_variables_mean(qtbot, window):
    """The complex cosine's file says y is Im z: the colour bar, the subtitle and the axes say so too;
    a system typed in (no example) keeps the bare names."""
    from gcmh_studio.labels import example_labels

    ex = _run_example(qtbot, window, "complex-cosine", div=12)
    assert example_labels(ex)["y"] == "Im z"
    sc = window.scene
    assert sc.texts.bar_title == "y = Im z"
    assert "colour: y = Im z" in sc.style.subtitle
    a = sc.texts.axes_actor
    assert a is not None and a.GetZAxisLabelText() == "x = Re z"
    assert example_labels(load_example("sphere")) == {}


def test_a_turn_pad_per_hidden_direction(qtbot):
    from qtpy.QtCore import QPoint, Qt
    from qtpy.QtTest import QTest

    from gcmh_studio.qt_projection_panel import QtProjectionPanel

    pp = QtProjectionPanel()
    qtbot.addWidget(pp)
    pp.set_variables([f"x{i + 1}" for i in range(10)], keep=False)
    assert len(pp.pads) == 7
    pp.show()
    qtbot.waitExposed(pp)
    pad = pp.pads[6]                                   # x10
    with qtbot.waitSignal(pp.projectionChanged, timeout=2000):
        QTest.mousePress(pad, Qt.LeftButton, Qt.NoModifier, QPoint(22, 22))
        QTest.mouseMove(pad, QPoint(42, 22))
        QTest.mouseRelease(pad, Qt.LeftButton, Qt.NoModifier, QPoint(42, 22))
    P = pp.model.matrix()
    assert abs(P[0, 9]) > 0.1 and np.allclose(P[:, 3:9], 0.0, atol=1e-9), "only x10 came into X"
