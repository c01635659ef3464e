"""Parameter sweeps (issue 17): ``gcmh-app --animate param:a=-1:1``.

One extraction per frame, one camera for all frames, a caption with the value and the topology;
bad specs are one line and exit status 2, checked before any work.
"""

import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image, ImageSequence

from gcmh_studio.animation import critical_note, param_caption, param_frames, parse_spec

from app_helpers import app_in_process

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NAMES = ["x", "y", "z"]


# ---------------------------------------------------------------- the spec, the values, the caption


def test_param_spec_and_its_frames():
    s = parse_spec("param:a=-1:1", NAMES, params=["a"])
    assert (s.kind, s.param, s.lo, s.hi) == ("param", "a", -1.0, 1.0)
    assert s.describe(NAMES) == "param:a=-1:1"
    assert parse_spec("param: a = -pi/2 : pi/2", NAMES, params=["a"]).hi == pytest.approx(np.pi / 2)
    assert parse_spec("param:a=1:-1", NAMES, params=["a"]).lo == 1.0   # a sweep may run downwards
    values = [f.param_value for f in param_frames(-1.0, 1.0, 5)]
    assert values == [-1.0, -0.5, 0.0, 0.5, 1.0]   # both ends, evenly
    assert [f.param_value for f in param_frames(0.2, 0.7, 1)] == [0.2]


@pytest.mark.parametrize("text, params, message", [
    ("param:b=-1:1", ["a"], "unknown parameter 'b' in 'param:b=-1:1'; the formulas' parameters are a"),
    ("param:a=1:1", ["a"], "param a: the range 1:1 is empty"),
    ("param:a=-1", ["a"], "param needs a range FROM:TO, e.g. param:a=-1:1"),
    ("param:a=-1:1:2", ["a"], "param needs a range FROM:TO"),
    ("param:a", ["a"], "param needs NAME=FROM:TO"),
    ("param:=0:1", ["a"], "param needs NAME=FROM:TO"),
    ("param:a=x:1", ["a"], "param a: cannot read 'x' as a number"),
    ("param:a=0:1", [], "these formulas have no parameter to sweep"),
])
def test_bad_param_specs_say_what_is_wrong(text, params, message):
    with pytest.raises(ValueError) as info:
        parse_spec(text, NAMES, params=params)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_caption_shows_value_topology_and_the_critical_value():
    assert param_caption("a", -0.5, 2 / 23, 2, 2) == "a = -0.50   chi = 2   2 components"
    assert param_caption("a", -1e-9, 0.5, 0, 1) == "a = 0.00   chi = 0   1 component"   # never "-0.00"
    assert param_caption("c", 0.1234, 0.001, 0, 1).startswith("c = 0.123 ")   # decimals follow the step
    assert param_caption("r", 0.0, 0.5, 0, 0) == "r = 0.00   empty (M misses the grid)"
    assert critical_note("a", 0) == ""
    assert "critical value of a" in critical_note("a", 86) and "86 vertices" in critical_note("a", 86)


# ---------------------------------------------------------------- the sweep itself


def _hyperboloid_job(method="gcmh", div=20):
    from gcmh_core.examples import load_example
    from gcmh_studio.jobs import Job

    ex = load_example("hyperboloid")
    return Job(formulas=list(ex.formulas), variables=list(ex.variables), bounds=[tuple(b) for b in ex.bounds],
               div=div, method=method, params=ex.param_values(),
               start=list(ex.start) if method == "gcch" else None)


@pytest.mark.parametrize("method", ["gcmh", "gcch"])
def test_chi_goes_from_2_to_0_across_the_critical_value(method):
    """The hyperboloid: two sheets (chi 2) for a < 0, one (chi 0) for a > 0; continuation from each
    previous frame finds what the whole grid finds, and a = 0 itself is reported singular."""
    from gcmh_studio.headless import param_sweep

    spec = parse_spec("param:a=-1:1", NAMES, params=["a"])
    cxs = param_sweep(_hyperboloid_job(method), spec, 5)
    assert [cx.meta["params"]["a"] for cx in cxs] == [-1.0, -0.5, 0.0, 0.5, 1.0]
    chis = [cx.euler_characteristic() for cx in cxs]
    assert chis[:2] == [2, 2] and chis[3:] == [0, 0]
    assert [cx.connected_components() for cx in cxs[:2] + cxs[3:]] == [2, 2, 1, 1]
    assert cxs[2].meta["singular_vertices"] > 0
    assert all(not cx.meta["singular_vertices"] for cx in cxs[:2] + cxs[3:])


def test_budget_of_all_frames_is_checked_first(monkeypatch):
    from gcmh_core.budget import TooLargeError
    from gcmh_studio.headless import check_param_sweep

    spec = parse_spec("param:a=-1:1", NAMES, params=["a"])
    job = _hyperboloid_job(div=64)
    check_param_sweep(job, spec, 24, (320, 240))   # fits
    monkeypatch.setenv("GCMH_TIME_LIMIT", "0.001")
    with pytest.raises(TooLargeError, match="24 extractions would take about"):
        check_param_sweep(job, spec, 24, (320, 240))


def test_one_camera_for_all_frames_and_every_frame_inside_it():
    """The framing is fitted once to all frames together: the camera never moves, every frame is in the
    picture (below the title), and the colour scale is the same for all."""
    from gcmh_studio.camera import inside_share
    from gcmh_studio.headless import offscreen_scene, param_sweep, sweep_images
    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Style

    spec = parse_spec("param:a=-1:1", NAMES, params=["a"])
    cxs = param_sweep(_hyperboloid_job(), spec, 4)
    model = ProjectionModel(n=3)
    cams, shares, ranges = [], [], []
    with offscreen_scene((320, 240)) as scene:
        for img in sweep_images(scene, NAMES, model.view(), cxs, spec, Style(color_by="z", title="t")):
            assert img.shape[:2] == (240, 320)
            cams.append((tuple(scene.plotter.camera.position), scene.plotter.camera.view_angle))
            shares.append(inside_share(scene.plotter, size=(320, 240)))
            ranges.append(tuple(scene.actor.mapper.scalar_range))
    assert len(set(cams)) == 1
    assert min(shares) == 1.0
    assert len(set(ranges)) == 1 and ranges[0] == pytest.approx((-2.0, 2.0), abs=0.1)


# ---------------------------------------------------------------- the command line


def _app(*args, timeout=600):
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-m", "gcmh_studio", *args], cwd=REPO, env=env, capture_output=True,
                          text=True, timeout=timeout)


def test_a_sweep_gif_has_the_frames_asked_for_and_they_differ(tmp_path):
    gif = tmp_path / "sweep.gif"
    r = _app("--example", "hyperboloid", "--div", "20", "--animate", "param:a=-1:1", "--frames", "6",
             "--gif", str(gif), "--size", "320x240")
    assert r.returncode == 0, r.stderr
    assert "6 frames" in r.stdout and "chi 2 -> 0 at a = 0.2" in r.stdout
    frames = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(Image.open(gif))]
    assert len(frames) == 6
    assert all(not np.array_equal(a, b) for a, b in zip(frames, frames[1:]))
    # the caption (bottom left, below the axes) changes with every frame; the title never does
    captions = [f[-24:, :200] for f in frames]
    assert all(not np.array_equal(a, b) for a, b in zip(captions, captions[1:]))
    assert all(np.array_equal(frames[0][:10], f[:10]) for f in frames)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sweep.gif"]   # no temporary left


@pytest.mark.parametrize("args, message", [
    (["--animate", "param:b=-1:1"], "unknown parameter 'b'"),
    (["--animate", "param:a=0.5:0.5"], "is empty"),
    (["--animate", "param:a=-1:1x"], "cannot read"),
    (["--animate", "param:a"], "param needs NAME=FROM:TO"),
    (["--animate", "param:a=0:1", "--param", "b=1"], "parameter b does not appear in the formulas"),
    (["--animate", "param:a=0:1", "--param", "a"], "--param: expected NAME=VALUE"),
    (["--animate", "param:a=0:1", "--frames", "3000"], "above the limit"),
])
def test_bad_sweeps_are_one_line_and_exit_2(tmp_path, args, message, capsys, monkeypatch):
    gif = tmp_path / "x.gif"
    code, _, err = app_in_process(capsys, monkeypatch, "--example", "hyperboloid", "--gif", str(gif), *args)
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert message in lines[0]
    assert not gif.exists()


# ---------------------------------------------------------------- the Animate tab


def test_the_animate_tab_offers_a_parameter_sweep_and_exports_it(qtbot, tmp_path):
    """The panel's "param" mode (offered once the formulas' parameters are given) says the sweep in
    --animate syntax, plays (the window's live sweep: tests/app/test_presentation.py) and its spec drives
    the headless export."""
    from gcmh_core.examples import load_example
    from gcmh_studio.animation import parse_spec
    from gcmh_studio.headless import export_param_sweep
    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.qt_animation_panel import PARAM_MODE, QtAnimationPanel
    from gcmh_studio.scene import Style

    panel = QtAnimationPanel()
    qtbot.addWidget(panel)
    panel.set_variables(NAMES)
    assert panel.mode_combo.findData(PARAM_MODE[0]) < 0          # no parameters: no such mode
    ex = load_example("hyperboloid")
    panel.set_parameters(ex.params)
    panel.set_mode(PARAM_MODE[0])
    assert panel.spec_text() == "param:a=-1:1"                     # the example's range by default
    assert panel.play_button.isEnabled()
    with qtbot.waitSignal(panel.tick):                            # (Space): it plays, ticking
        panel.set_playing(True)
    assert panel.is_playing() and panel.play_button.text() == "Pause"
    panel.set_playing(False)
    assert not panel.is_playing()
    panel.set_param_sweep("a", 0.5, -0.5)
    assert panel.spec_text() == "param:a=0.5:-0.5"
    panel.set_parameters(ex.params)                               # the same parameters again: the ends stay
    assert panel.spec_text() == "param:a=0.5:-0.5"

    spec = parse_spec(panel.spec_text(), NAMES, params=list(ex.params))
    seen = []
    n, cxs = export_param_sweep([tmp_path / "p.gif"], _hyperboloid_job(), spec, 3, NAMES, ProjectionModel(n=3),
                                Style(color_by="z", title=ex.title), (240, 180), 10,
                                progress=lambda phase, k: seen.append((phase, k)))
    assert n == 3 and cxs[0].euler_characteristic() == 0 and cxs[2].euler_characteristic() == 2
    assert seen == [("extract", 1), ("extract", 2), ("extract", 3), ("draw", 1), ("draw", 2), ("draw", 3)]
    assert len(list(ImageSequence.Iterator(Image.open(tmp_path / "p.gif")))) == 3

    panel.set_parameters({})                                      # a system without parameters
    assert panel.mode_combo.findData(PARAM_MODE[0]) < 0 and panel.mode() == "rotate"


def test_param_sets_a_screenshot_parameter_and_needs_a_headless_mode(tmp_path, capsys, monkeypatch):
    png = tmp_path / "two-sheets.png"
    r = _app("--example", "hyperboloid", "--div", "20", "--param", "a=-0.3", "--screenshot", str(png),
             "--size", "160x120")
    assert r.returncode == 0, r.stderr
    assert "chi = 2" in r.stdout and Image.open(png).size == (160, 120)
    # no headless mode: the window would take the value from its slider
    code, _, err = app_in_process(capsys, monkeypatch, "--example", "hyperboloid", "--param", "a=-0.3")
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2 and len(lines) == 1 and "--param goes with --screenshot or --animate" in lines[0]
