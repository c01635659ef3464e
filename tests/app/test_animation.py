"""Animations: frame sequences (pure), GIF/MP4 export, and the headless --animate command."""

import os
import subprocess
import sys

import numpy as np
import pytest

from gcmh_studio.animation import (
    frames_for,
    parse_spec,
    rotation_frames,
    slice_frames,
    tour_angles,
    tour_frames,
    write_animation,
)

from app_helpers import app_in_process

NAMES = ["x", "y", "z", "s", "t"]
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_parse_spec_accepts_the_three_kinds():
    r = parse_spec("rotate:s-t", NAMES)
    assert r.kind == "rotate" and r.plane == (3, 4) and r.sign == 1.0
    assert parse_spec("rotate:t-s", NAMES).sign == -1.0
    assert parse_spec("tour", NAMES).kind == "tour"
    s = parse_spec("slice:s", NAMES)
    assert s.kind == "slice" and s.var == 3
    assert s.describe(NAMES) == "slice:s" and r.describe(NAMES) == "rotate:s-t"


@pytest.mark.parametrize("bad, msg", [("spin:s-t", "unknown animation"), ("rotate:s", "two variables"),
                                      ("rotate:s-s", "different"), ("rotate:q-t", "unknown variable"),
                                      ("slice:q", "slice needs"), ("tour:x", "no argument"), ("", "unknown")])
def test_parse_spec_rejects_bad_text(bad, msg):
    with pytest.raises(ValueError, match=msg):
        parse_spec(bad, NAMES)


def test_rotation_goes_once_around_in_its_plane_only():
    a0 = np.zeros(10)
    a0[2] = 30.0
    fr = rotation_frames(a0, 9, 12)
    assert len(fr) == 12
    A = np.array([f.angles for f in fr])
    assert np.allclose(A[:, :9], a0[:9])
    steps = np.diff(np.unwrap(np.radians(A[:, 9])))
    assert np.allclose(np.degrees(steps), 30.0)


def test_tour_is_smooth_starts_here_and_closes():
    a0 = np.linspace(-40, 40, 10)
    assert np.allclose(tour_angles(a0, 0.0), a0)
    assert np.allclose(tour_angles(a0, 1.0), a0)
    T = np.linspace(0, 1, 401)
    A = np.unwrap(np.radians(tour_angles(a0, T)), axis=0)
    step = np.degrees(np.abs(np.diff(A, axis=0))).max()
    assert step < 3.0                                # about 2 pi * 2 * 75 / 400 = 2.4 degrees at most
    fr = tour_frames(a0, 30, seed=3)
    assert len(fr) == 30 and not np.allclose(fr[10].angles, a0)
    assert not np.allclose(tour_angles(a0, 0.3, seed=1), tour_angles(a0, 0.3, seed=2))


def test_slice_sweep_goes_there_and_back():
    c = np.array([f.slice_center for f in slice_frames(-1.0, 3.0, 20)])
    assert c[0] == pytest.approx(-1.0) and c.max() == pytest.approx(3.0) and np.all(c >= -1.0)
    assert len(frames_for(parse_spec("slice:s", NAMES), np.zeros(10), 7, (0, 1))) == 7
    assert len(frames_for(parse_spec("rotate:x-t", NAMES), np.zeros(10), 5)) == 5


@pytest.mark.parametrize("ext", [".gif", ".mp4"])
def test_export_writes_the_requested_frames(tmp_path, ext):
    import imageio.v3 as iio

    imgs = [np.full((48, 64, 3), 10 * k, np.uint8) for k in range(9)]
    p = tmp_path / f"a{ext}"
    seen = []
    assert write_animation(p, imgs, fps=10, progress=seen.append) == 9
    assert seen == list(range(1, 10))
    frames = iio.imread(p, index=None, mode="RGB") if ext == ".gif" else _ffmpeg_frames(p)
    assert len(frames) == 9
    assert frames.shape[1:3] == (48, 64)


def _ffmpeg_frames(p):
    import imageio.v2 as imageio

    r = imageio.get_reader(str(p), format="ffmpeg")
    try:
        return np.stack([f for f in r])
    finally:
        r.close()


def test_export_cancel_removes_the_file(tmp_path):
    p = tmp_path / "c.gif"
    imgs = (np.zeros((16, 16, 3), np.uint8) for _ in range(10))
    k = write_animation(p, imgs, cancel=lambda: True)
    assert k == 0 and not p.exists()
    with pytest.raises(ValueError, match="format"):
        write_animation(tmp_path / "x.avi", [])


def _run_app(*args, timeout=300):
    env = dict(os.environ, PYTHONPATH=REPO, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
    return subprocess.run([sys.executable, "-m", "gcmh_studio", *args], capture_output=True, text=True, env=env,
                          timeout=timeout, cwd=REPO)


def test_headless_animate_tour_writes_gif_and_mp4(tmp_path):
    gif, mp4 = tmp_path / "t.gif", tmp_path / "t.mp4"
    r = _run_app("--example", "clifford-torus", "--div", "10", "--animate", "tour", "--frames", "6",
                 "--mapping", "stereographic", "--gif", str(gif), "--mp4", str(mp4), "--size", "160x120")
    assert r.returncode == 0, r.stderr
    import imageio.v3 as iio

    g = iio.imread(gif, index=None, mode="RGB")   # (frames after the first: what changed, over it)
    assert g.shape[0] == 6 and g.shape[1:3] == (120, 160)
    assert len(_ffmpeg_frames(mp4)) == 6
    # the frames differ: the view moves
    assert np.abs(g[0].astype(int) - g[3].astype(int)).mean() > 0.5


def test_headless_animate_slice_sweep(tmp_path):
    gif = tmp_path / "s.gif"
    r = _run_app("--example", "klein-bottle", "--div", "10,10,6,12,12", "--animate", "slice:s", "--frames", "4",
                 "--gif", str(gif), "--size", "160x120")
    assert r.returncode == 0, r.stderr
    import imageio.v3 as iio

    g = iio.imread(gif, index=None, mode="RGB")   # (frames after the first: what changed, over it)
    assert g.shape[0] == 4
    assert np.abs(g[0].astype(int) - g[2].astype(int)).mean() > 0.2


def test_headless_slice_sweep_spans_the_variable_over_the_result(tmp_path, monkeypatch):
    """``--animate slice:VAR`` sweeps VAR's range over the result, not 0..1 (the range went through an
    attribute set on the window, and a clean-up that saw no reader of it dropped it)."""
    from gcmh_studio import headless

    seen = {}

    def frames_only(scene, projection, frames, window, paths, fps, progress=None, cancel=None):
        seen["centres"] = [f.slice_center for f in frames]
        seen["x"] = np.asarray(scene.complex.vertices)[:, scene.names.index("x")]
        return len(frames)

    monkeypatch.setattr(headless, "write_frames", frames_only)
    code = headless.render(headless.Options(example="complex-cosine", div=8, animate="slice:x", frames=4,
                                            gif=str(tmp_path / "s.gif"), size=(160, 120)))
    assert code == 0
    x = seen["x"][np.isfinite(seen["x"])]
    assert min(seen["centres"]) == pytest.approx(x.min()) and max(seen["centres"]) == pytest.approx(x.max())
    assert x.max() - x.min() > 1.5                # (a range unlike 0..1)


@pytest.mark.parametrize("args", [["--animate", "spin:s-t", "--gif", "x.gif"],
                                  ["--animate", "rotate:s-q", "--gif", "x.gif"],
                                  ["--animate", "tour"],
                                  ["--gif", "x.gif"]])
def test_headless_animate_bad_spec_exits_2_with_one_line(args, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = app_in_process(capsys, monkeypatch, "--example", "klein-bottle", *args)
    assert code == 2
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("gcmh-app:"), err
    assert list(tmp_path.iterdir()) == []


def test_headless_screenshot_with_slice_mapping_and_two_sides(tmp_path, capsys, monkeypatch):
    import imageio.v3 as iio

    full, cut = tmp_path / "full.png", tmp_path / "cut.png"
    common = ["--example", "klein-bottle", "--div", "10,10,6,12,12", "--size", "200x150", "--two-sided"]
    assert _run_app(*common, "--screenshot", str(full)).returncode == 0
    r = _run_app(*common, "--slice", "s=3", "--slice-width", "0.3", "--mapping", "perspective",
                 "--screenshot", str(cut))
    assert r.returncode == 0, r.stderr
    a, b = iio.imread(full)[..., :3].astype(int), iio.imread(cut)[..., :3].astype(int)
    assert np.abs(a - b).mean() > 1.0
    blue = lambda img: np.sum(img[..., 2] > img[..., 0] + 60)  # noqa: E731
    assert blue(a) > 100                      # the back side shows
    code, _, err = app_in_process(capsys, monkeypatch, "--example", "sphere", "--mapping", "stereographic",
                                   "--screenshot", str(tmp_path / "x.png"))
    assert code == 2 and "n >= 4" in err
    code, _, err = app_in_process(capsys, monkeypatch, "--example", "klein-bottle", "--slice", "q=1",
                                   "--screenshot", str(tmp_path / "x.png"))
    assert code == 2 and "--slice" in err
    assert not (tmp_path / "x.png").exists()


def test_gif_dithers_gradients_and_keeps_text_exact(tmp_path):
    """Issue 16: one 256-colour palette bands a shaded surface.  The GIF's frames are dithered where the
    palette lacks a colour: blurred (as the eye sees it) the picture is closer to the original than the
    nearest palette colour alone would make it; pixels in the text's colours stay exactly as they were."""
    from PIL import Image, ImageSequence

    from gcmh_studio.animation import RESERVED_COLOURS

    y, x = np.mgrid[0:240, 0:320] / np.array([239.0, 319.0])[:, None, None]
    frames = []
    for k in range(3):   # a smooth two-way gradient (far more colours than a palette holds), and text
        img = np.stack([40 + 150 * x, 60 + 120 * y + 10 * k, 90 + 60 * (1 - x) * y], -1).round().astype(np.uint8)
        img[10:20, 10:120] = RESERVED_COLOURS[0]
        img[25:30, 10:90] = RESERVED_COLOURS[1]
        frames.append(img)
    path = tmp_path / "g.gif"
    assert write_animation(path, frames) == 3
    gif = Image.open(path)
    pal = np.asarray(gif.getpalette()[:768], float).reshape(-1, 3)   # (one palette for every frame)
    got = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(gif)]

    def blurred(a, s=8):
        h, w = a.shape[0] // s * s, a.shape[1] // s * s
        return a[:h, :w].astype(float).reshape(h // s, s, w // s, s, 3).mean((1, 3))

    for src, out in zip(frames, got):
        # the nearest palette colour of each pixel: the least |a - p|^2 - |a|^2 = |p|^2 - 2 a.p, one matrix
        # product (integers, exact in float64; the (pixels, 256, 3) difference array took seconds per frame)
        a1 = np.c_[src.reshape(-1, 3).astype(float), np.ones(src.shape[0] * src.shape[1])]
        nearest = pal[np.argmin(a1 @ np.r_[-2.0 * pal.T, [(pal * pal).sum(1)]], 1)].reshape(src.shape)
        assert np.abs(blurred(out) - blurred(src)).mean() < 0.8 * np.abs(blurred(nearest) - blurred(src)).mean()
        assert np.array_equal(out[10:20, 10:120], src[10:20, 10:120])
        assert np.array_equal(out[25:30, 10:90], src[25:30, 10:90])


def test_gif_frames_after_the_first_hold_only_what_changed(tmp_path):
    """Each frame after the first codes only the pixels that changed (the rest transparent over the frame
    before): squares moving over a still, dithered gradient decode frame by frame as drawn, repeated
    frames are kept (not merged), and ten frames take less room than two whole ones (each frame after the
    first carries its own copy of the palette, 768 bytes)."""
    from PIL import Image, ImageSequence

    y, x = np.mgrid[0:240, 0:320] / np.array([239.0, 319.0])[:, None, None]
    still = np.stack([30 + 60 * x, 40 + 50 * y, 60 + 40 * x * y], -1).round().astype(np.uint8)
    frames = []
    for k in range(10):
        f = still.copy()
        c = 10 + 8 * min(k, 6)                      # two squares in opposite corners move 8 px a frame, then
        f[10:40, c:c + 30] = (220, 170, 60)         # rest for three frames (what changed spans the picture)
        f[200:230, 280 - c:310 - c] = (220, 170, 60)
        frames.append(f)
    path = tmp_path / "d.gif"
    assert write_animation(path, frames) == 10
    got = [np.asarray(f.convert("RGB")).astype(int) for f in ImageSequence.Iterator(Image.open(path))]
    assert len(got) == 10
    for k in range(1, 10):   # the still part decodes the same in every frame (the dither does not crawl)
        same = np.all(frames[k] == frames[k - 1], axis=-1)
        assert np.array_equal(got[k][same], got[k - 1][same])
    for src, out in zip(frames, got):   # each frame as drawn: the square where it is, the gradient dithered
        assert np.abs(out - src).mean() < 4.0
        sq = np.all(src == (220, 170, 60), axis=-1)
        assert np.abs(out[sq] - src[sq]).max() < 24 and np.abs(out[~sq] - src[~sq]).max() < 24
    one = tmp_path / "one.gif"
    write_animation(one, frames[:1])
    assert path.stat().st_size < 2.0 * one.stat().st_size
