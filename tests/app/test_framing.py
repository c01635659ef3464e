"""Animations framed over all their frames: every frame of a rotation, a tour, a slice sweep and a parameter
sweep shows the whole object inside the object band (no coloured pixel on the band's edges) and nothing of
it in the text bands (title above, caption below).  Measured on the GIFs' pixels."""

import numpy as np
import pytest
from PIL import Image, ImageSequence

from gcmh_studio.framing import framing_faults, hull_points, object_mask
from gcmh_studio.headless import Options, render

CASES = [   # (example, animation, extra options): the two worst, a parameter sweep, a slice
    ("complex-cosine", "rotate:x-y", {"div": 16}),
    ("clifford-torus", "tour", {"mapping": "stereographic", "div": 12}),
    ("hyperboloid", "param:a=-1:1", {"div": 12}),
    ("klein-bottle", "slice:s", {"div": 16, "slice_width": 0.3}),
]


def gif_frames(path):
    return [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(Image.open(path))]


@pytest.mark.parametrize("example, spec, extra", CASES, ids=[c[1].split(":")[0] for c in CASES])
def test_every_frame_inside_the_picture_and_clear_of_the_text(tmp_path, example, spec, extra):
    out = tmp_path / "a.gif"
    assert render(Options(example=example, animate=spec, frames=8, size=(240, 180), gif=str(out), **extra)) == 0
    frames = gif_frames(out)
    assert len(frames) == 8
    faults = [framing_faults(f) for f in frames]
    assert all(f == {"cut": 0, "over_text": 0} for f in faults), faults
    assert all(object_mask(f).sum() > 200 for f in frames)   # (something is drawn in every frame)


def test_the_measure_sees_a_cut_and_a_title_overrun():
    from gcmh_studio.scene import BACKGROUND, BACKGROUND_TOP

    h, w = 180, 240
    bot, top = (np.array([int(c[i:i + 2], 16) for i in (1, 3, 5)], float) for c in (BACKGROUND, BACKGROUND_TOP))
    up = np.linspace(1, 0, h)[:, None, None]
    img = np.round(bot + up * (top - bot) + np.zeros((h, w, 3))).astype(np.uint8)   # the scene's gradient
    assert framing_faults(img) == {"cut": 0, "over_text": 0}
    img[40:120, 100:150] = (250, 200, 40)          # a gold patch in the middle: inside
    assert framing_faults(img) == {"cut": 0, "over_text": 0}
    img[5:60, 60:80] = (40, 180, 120)              # up into the title
    f = framing_faults(img)
    assert f["over_text"] > 0 and f["cut"] > 0     # (it crosses the band's top row)
    img[5:60, 60:80] = 255                        # white text is not the object
    assert framing_faults(img)["over_text"] == 0


def test_hull_keeps_the_extremes_of_flat_and_solid_sets():
    rng = np.random.default_rng(1)
    X = rng.normal(size=(500, 3))
    H = hull_points(X)
    assert len(H) < len(X) and np.allclose(H.max(0), X.max(0)) and np.allclose(H.min(0), X.min(0))
    F = X.copy()
    F[:, 2] = 0.0                                  # flat: no 3-D hull
    H = hull_points(F)
    assert np.allclose(H.max(0), F.max(0)) and np.allclose(H.min(0), F.min(0))


def test_the_windows_export_is_framed_over_all_its_frames(qtbot, window, tmp_path):
    """The window's Export GIF (its camera's direction, the Animate tab's rotation) frames every frame."""
    pytest.importorskip("pytestqt")
    from gcmh_core.examples import load_example

    from app_helpers import small_div

    with qtbot.waitSignal(window.runFinished, timeout=180_000) as b:
        assert window.load_example("complex-cosine", div=small_div(load_example("complex-cosine")))
    assert b.args[0] == "done", window.last_status
    ap = window.animation_panel
    ap.set_mode("rotate")
    names = window.model.view_names
    ap.set_plane((names.index("x"), names.index("y")))
    out = tmp_path / "w.gif"
    assert window.export_animation(out, frames=8, size=(240, 180), show_progress=False) == 8
    faults = [framing_faults(f) for f in gif_frames(out)]
    assert all(f == {"cut": 0, "over_text": 0} for f in faults), faults
