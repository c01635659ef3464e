"""The studio's model, sessions and exports, the animation clock: all without Qt or a display.

This module imports no Qt; it runs with ``-p no:xvfb``.
"""

import json

import numpy as np
import pytest

from gcmh_studio import studio_io
from gcmh_studio.animation import ROTATE_PERIOD, SLICE_PERIOD, Clock, tour_angles
from gcmh_studio.model import (
    EMPTY_RESULT,
    StudioModel,
    animation_frames,
    pick_text,
    slice_params,
    summarize,
    telling_plane,
)
from gcmh_studio.projection import ProjectionModel
from gcmh_studio.slicing import SliceWindow

from app_helpers import torus_complex


@pytest.fixture(scope="module")
def sphere():
    import gcmh_core

    return gcmh_core.extract(["x1^2 + x2^2 + x3^2 - 1"], bounds=[(-1.5, 1.5)] * 3, div=6,
                             variables=["x1", "x2", "x3"])


def test_status_system_and_view_are_announced():
    m = StudioModel()
    said = []
    m.events.status.connect(lambda text, error: said.append((text, error)))
    m.events.system.connect(lambda d: said.append(("system", d["n"])))
    m.events.style.connect(lambda: said.append(("style", m.style.color_by)))
    m.set_status("Cannot run: n", error=True)
    m.set_system({"n": 3, "k": 1})
    m.set_system({"n": 3, "k": 1})        # nothing new: nothing said
    m.set_style(color_by="x3")
    m.set_style(color_by="x3")
    assert said == [("Cannot run: n", True), ("system", 3), ("style", "x3")]
    assert m.status == "Cannot run: n" and m.status_error
    assert m.summary() == "no result yet"


def test_result_serial_title_and_pick(sphere):
    m = StudioModel()
    shown, picks = [], []
    m.events.result.connect(shown.append)
    m.events.picked.connect(picks.append)
    m.expect("Sphere", [" x1^2 + x2^2 + x3^2 - 1 "], ["x1", "x2", "x3"], view={"color": "x3"})
    assert m.title_for(["x1^2 + x2^2 + x3^2 - 1"], ["x1", "x2", "x3"]) == "Sphere"
    assert m.title_for(["x1^2 + x2^2 - 1"], ["x1", "x2", "x3"]) == ""      # the user typed another system
    assert m.take_view() == {"color": "x3"} and m.take_view() is None     # the suggested view is used once
    s1 = m.set_result(sphere, ["x1", "x2", "x3"], "Sphere")
    s2 = m.set_result(sphere, ["x1", "x2", "x3"], "Sphere")
    assert (s1, s2) == (1, 2) and m.serial == 2 and shown == [sphere, sphere]
    assert "\u03c7 = 2" in m.summary() and m.summary() == summarize(sphere)
    from gcmh_studio.geometry import cell_info

    m.set_picked(cell_info(sphere, 0))
    text = m.pick_text()
    assert text.startswith("2-cell 0 (") and "grid cube" in text and "x1" in text.splitlines()[1]
    m.set_result(sphere, ["x1", "x2", "x3"])      # a new result clears the pick
    assert m.picked is None and picks[-1] is None and m.pick_text() == ""
    m.set_refinement(1e-3, 1e-9)
    assert m.last_refinement == {"before": 1e-3, "after": 1e-9}
    assert "empty" in EMPTY_RESULT


def test_pick_text_cuts_long_cells():
    info = dict(cell=7, vertices=list(range(15)), coords=np.zeros((15, 2)), cube=None)
    text = pick_text(info, ["u", "v"], dim=1)
    assert text.startswith("edge 7 (15 vertices)\n") and "grid cube" not in text
    assert text.splitlines()[-1] == "\u2026 3 more vertices" and len(text.splitlines()) == 1 + 1 + 12 + 1


def test_telling_plane_turns_a_hidden_axis_into_view():
    m = ProjectionModel(n=5)          # x, y, z shown; s, t hidden
    assert telling_plane(m.matrix()) == (2, 3)
    assert telling_plane(ProjectionModel(n=3).matrix()) == (0, 1)   # nothing hidden


def test_slice_params_and_animation_frames():
    cx = torus_complex(16, 4)
    proj = ProjectionModel(n=4)
    proj.set_vertices(cx.vertices)
    assert slice_params(None, cx.vertices, proj, (0.5, 0.1)) is None
    sw, u, lo, hi, c, w = slice_params(SliceWindow(3), cx.vertices, proj, (0.25, 0.1))
    assert np.allclose(u, np.eye(4)[3])
    assert lo == pytest.approx(cx.vertices[:, 3].min()) and hi == pytest.approx(cx.vertices[:, 3].max())
    assert c == pytest.approx(lo + 0.25 * (hi - lo)) and w == pytest.approx(0.1 * (hi - lo))

    frames, window = animation_frames("rotate", (2, 3), proj, 6)
    assert len(frames) == 6 and window is None
    row = proj.planes.index((2, 3))
    assert [f.angles[row] for f in frames[:3]] == pytest.approx([0.0, 60.0, 120.0])
    prm = slice_params(SliceWindow(3), cx.vertices, proj, (0.5, 0.05))
    frames, window = animation_frames("slice", None, proj, 4, prm)
    assert window.c == prm[4] and window.w == prm[5]
    assert frames[0].slice_center == pytest.approx(prm[2]) and frames[2].slice_center == pytest.approx(prm[3])
    with pytest.raises(ValueError, match="slice"):
        animation_frames("slice", None, proj, 4, None)


def test_animation_clock():
    a = np.array([170.0, 0.0, 10.0])
    turned = Clock.rotate_step(a, 0, ROTATE_PERIOD / 36)     # 1/36 of a period: 10 degrees, 180 wraps to -180
    assert turned == pytest.approx([-180.0, 0.0, 10.0]) and a[0] == 170.0
    clock = Clock()
    clock.start(a)
    assert clock.t == 0.0
    assert clock.tour_step(3.0) == pytest.approx(tour_angles(a, 3.0 / 60.0))
    clock.start(a, slice_centre=0.25)                       # the sweep starts where the slider is
    assert clock.sweep_step(0.0) == pytest.approx(0.25)
    assert clock.sweep_step(SLICE_PERIOD) == pytest.approx(0.25)   # one whole period later: the same place


def test_session_round_trip(tmp_path, sphere):
    m = StudioModel()
    m.set_system({"n": 3, "k": 1, "formulas": ["x1^2 + x2^2 + x3^2 - 1"]})
    m.projection.kind = "generic"
    m.projection_changed(base=True)
    m.set_style(color_by="x2")
    m.set_result(sphere, ["x1", "x2", "x3"], "Sphere")

    class Camera:
        position, focal_point, up = (1.0, 2.0, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)
        parallel_scale, view_angle = 1.5, 30.0

    d = studio_io.session_dict(m, studio_io.camera_state(Camera()))
    path = studio_io.write_session(tmp_path / "s.json", d)
    back = studio_io.read_session(path)
    assert back == json.loads(json.dumps(d)) and back["format"] == studio_io.SESSION_FORMAT
    assert back["title"] == "Sphere" and back["view"]["color"] == "x2"
    cam = Camera()
    studio_io.apply_camera(cam, {"position": [4, 5, 6], "focal_point": [0, 0, 1], "up": [0, 1, 0]})
    assert cam.position == [4, 5, 6] and cam.view_angle == 30.0    # absent keys keep the camera's own


@pytest.mark.parametrize("text,words", [("{not json", "Expecting"), ('{"format": "other"}', "not a GCMH session"),
                                        ('{"format": "gcmh-session/1"}', "no system")])
def test_bad_sessions_are_refused_in_one_line(tmp_path, text, words):
    p = tmp_path / "bad.json"
    p.write_text(text)
    with pytest.raises(ValueError, match=words):
        studio_io.read_session(p)


def test_exports(tmp_path, sphere):
    from gcmh_core.complex import CellComplex

    assert studio_io.export_complex(sphere, tmp_path / "c").endswith("c.npz")
    assert CellComplex.load(tmp_path / "c.npz").counts() == sphere.counts()
    with pytest.raises(ValueError, match="no result"):
        studio_io.export_complex(None, tmp_path / "d.npz")
    with pytest.raises(ValueError, match="unknown mesh format"):
        studio_io.export_mesh(None, tmp_path / "m.xyz", 2)


def test_a_parameter_step_that_loses_the_start_point_continues_from_auto():
    # the hyperboloid's start point lies on M for a > 0 only: at a = -0.3 Newton leaves the box
    from gcmh_core.examples import load_example
    from gcmh_studio.jobs import Job, run_job

    ex = load_example("hyperboloid")
    job = Job(formulas=ex.formulas, variables=ex.variables, bounds=ex.bounds, div=16, method="gcch",
              start=list(ex.start), params={"a": -0.3})
    cx = run_job(job)
    assert cx.euler_characteristic() == 2 and "started from 'auto'" in cx.meta["start_note"]
    job.params = {"a": 0.3}
    cx = run_job(job)
    assert cx.euler_characteristic() == 0 and "start_note" not in cx.meta


def test_the_status_says_when_the_topology_is_unchecked():
    from gcmh_studio.model import _warnings

    assert _warnings({}, 10) == ""
    said = _warnings({"topology_unchecked": "no cell check exists in R^10 with k = 8"}, 10)
    assert "topology not fully checked (no cell check exists in R^10 with k = 8)" in said


def test_cells_left_not_balls_are_told_with_what_can_help():
    from gcmh_studio.model import _warnings

    # (the simplicial baselines stop at n = 7: beyond it only a finer grid helps)
    assert "2 cells are not balls (try a finer div)" in _warnings({"non_ball_left": 2}, 8)
    assert "1 cell is not a ball (try method cms or a finer div)" in _warnings({"non_ball_left": 1}, 5)
