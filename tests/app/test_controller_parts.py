"""The controller's parts on a model alone, without Qt or a display: the Animate tab's live play
(:class:`gcmh_studio.live_play.LivePlay`) needs no runner and no view. Runs with ``-p no:xvfb``."""

import numpy as np
import pytest

from gcmh_studio.live_play import LivePlay
from gcmh_studio.model import StudioModel


@pytest.fixture
def live():
    model = StudioModel()
    asked = []
    play = LivePlay(model, lambda name, value, final: asked.append((name, value, final)))
    play.asked = asked
    return play


def test_a_plane_of_two_hidden_axes_turns_nothing_on_screen(live):
    """In R^5 seen along x1, x2, x3, turning (x4, x5) moves nothing in an orthographic view; a plane with a
    shown axis, another mode or a nonlinear view does."""
    m = live.model
    m.set_view_variables(["x1", "x2", "x3", "x4", "x5"], keep=False)
    m.animation.mode, m.animation.plane = "rotate", (3, 4)
    assert live.still_plane()
    m.animation.plane = (2, 3)
    assert not live.still_plane()
    m.animation.plane = (3, 4)
    m.projection.angles[m.projection.planes.index((2, 3))] = 30.0   # x4 now shows: the plane turns something
    assert not live.still_plane()
    m.projection.angles[:] = 0.0
    m.projection.mapping = "stereographic"
    assert not live.still_plane()
    m.projection.mapping, m.animation.mode = "orthographic", "tour"
    assert not live.still_plane()


def test_nothing_plays_or_moves_without_a_result(live):
    m = live.model
    before = np.array(m.projection.angles)
    m.animation.mode = "tour"
    assert live.play(True) == (False, "Nothing to animate yet: run first.") and not live.playing
    live.tick(1.0)
    assert np.array_equal(m.projection.angles, before) and live.asked == []
    m.animation.mode, m.animation.sweep = "param", ("a", -1.0, 1.0)
    live.tick(1.0)   # no system with a parameter: no step asked
    assert live.asked == []
