"""The parts of presentation mode outside its window: what the card shows and when the axes are framed
(gcmh_studio.presentation: no Qt, no display), and what it draws in a view (gcmh_studio.view_decorations:
VTK on an off-screen plotter, no Qt window; like every test here it needs an X server, e.g. Xvfb).
The whole mode in the window: tests/app/test_presentation.py."""

from types import SimpleNamespace

import pytest

from gcmh_studio.jobs import Job
from gcmh_studio.model import StudioModel
from gcmh_studio.presentation import Reframing, card_key


def _model(formulas, variables, params=None, title="", system=None):
    m = StudioModel()
    m.job = Job(formulas=list(formulas), variables=list(variables), bounds=[(-1, 1)] * len(variables),
                params=params)
    m.result, m.names, m.title = object(), list(variables), title
    m.system = dict(system or {})
    return m


def test_the_card_shows_the_run_system_and_its_parameters_in_order():
    m = _model(["x^2 + y^2 - z^2 - a - b"], ["x", "y", "z"], params={"b": 2.0, "a": 0.5})
    assert card_key(m) == (("x^2 + y^2 - z^2 - a - b",), ("x", "y", "z"), (("a", 0.5), ("b", 2.0)), None, None)
    m.result = None                      # nothing on screen: no card
    assert card_key(m) is None
    m.result, m.job = object(), None     # a result with no run behind it (a file opened): no card either
    assert card_key(m) is None


def test_an_example_over_c_shows_its_complex_equation():
    from gcmh_core.examples import load_example

    ex = load_example("complex-cosine")
    m = _model(ex.formulas, ex.variables, title=ex.title)
    key = card_key(m)
    assert key[:2] == (tuple(ex.formulas), tuple(ex.variables))
    assert key[3:] == (tuple(ex.complex), tuple(ex.complex_variables)) == (("z = cos(w)",), ("w", "z"))
    m.title = ""                         # the same real system typed in by hand: no complex equation
    assert card_key(m)[3:] == (None, None)


def test_a_system_typed_in_complex_mode_shows_its_complex_equations():
    system = {"complex": ["z^2 = w"], "complex_variables": ["z", "w"]}
    m = _model(["x^2 - y^2 - u", "2*x*y - v"], ["x", "y", "u", "v"], system=system)
    assert card_key(m)[3:] == (("z^2 = w",), ("z", "w"))
    m.system = {"complex": ["z^2 = w"]}   # (the variables not given yet: an empty tuple, the card checks the split)
    assert card_key(m)[3:] == (("z^2 = w",), ())
    m.system = {}
    assert card_key(m)[3:] == (None, None)


def test_reframing_a_fit_outlasts_a_later_turn_and_is_taken_once():
    r = Reframing()
    assert r.take() is None
    r.turned()
    assert r.take() == "out" and r.take() is None
    r.fit()
    r.turned()                           # a turn after a new result: still the full fit
    assert r.take() == "fit"
    r.turned()
    r.fit()
    assert r.take() == "fit" and r.how is None


# ---------------------------------------------------------------- drawing in a view (VTK, off screen)


@pytest.fixture
def view():
    """An off-screen plotter with the scene's texts, behind the few things ViewDecorations asks of a viewer."""
    import pyvista as pv

    from gcmh_studio.labels import SceneTexts

    pl = pv.Plotter(off_screen=True, window_size=[640, 400])
    SceneTexts(pl).set_title("A title long enough to leave a small view once its type is half as large again",
                             "its subtitle")
    pl.show(auto_close=False)            # (pyvista renders only once shown)
    viewer = SimpleNamespace(plotter=pl, scene=None, render=pl.render, keep_camera=lambda: False,
                             size=lambda: tuple(pl.window_size))
    yield viewer
    pl.close()


def test_larger_type_stays_in_the_view_and_goes_back_to_the_scene_sizes(view):
    from gcmh_studio.view_decorations import ViewDecorations

    pl = view.plotter
    d = ViewDecorations(view, lambda: None)
    title, sub = pl.actors["gcmh-title"], pl.actors["gcmh-subtitle"]
    base = title.GetTextProperty().GetFontSize(), sub.GetTextProperty().GetFontSize()
    d.large_type = True
    pl.render()
    assert sub.GetTextProperty().GetFontSize() == round(1.5 * base[1])     # larger type
    bb = [0.0] * 4
    title.GetBoundingBox(pl.renderer, bb)
    # the long title as large as fits: larger than it was, but not off the view's right edge
    assert base[0] < title.GetTextProperty().GetFontSize() < round(1.5 * base[0]) and 0.9 * 640 < bb[1] <= 640
    d.large_type = False
    d.restore_fonts()
    assert (title.GetTextProperty().GetFontSize(), sub.GetTextProperty().GetFontSize()) == base
    d.detach()


def test_the_card_is_typeset_again_only_for_a_new_system_or_size(view):
    from gcmh_studio.view_decorations import FORMULA_ACTOR, ViewDecorations

    pl = view.plotter
    resized = []
    d = ViewDecorations(view, lambda: resized.append(tuple(pl.window_size)))
    key = (("x^2 + y^2 - z^2 - a",), ("x", "y", "z"), (("a", 0.5),), None, None)
    d.show_card(key)
    first = d.card()
    assert first is not None and pl.actors[FORMULA_ACTOR] is first
    d.show_card(key)
    assert d.card() is first and resized == []
    pl.window_size = [800, 500]
    pl.render()                                     # the view has grown: the caller is told at its renders
    assert resized and set(resized) == {(800, 500)}
    told = len(resized)
    d.show_card(key)
    assert d.card() is not first
    x, y = d.card().GetPosition()
    assert x > 400 and y < 250                      # in the bottom right corner
    d.detach()
    pl.window_size = [640, 400]
    pl.render()                                     # detached: no more calls from its renders
    assert len(resized) == told
    d.show_card(None)
    assert d.card() is None and FORMULA_ACTOR not in pl.actors


def test_the_caption_comes_and_goes(view):
    from gcmh_studio.view_decorations import CAPTION_ACTOR, ViewDecorations

    d = ViewDecorations(view, lambda: None)
    d.set_caption("3/40 the Klein bottle")
    assert d.caption() == "3/40 the Klein bottle" and CAPTION_ACTOR in view.plotter.actors
    d.set_caption("run failed", error=True)
    assert d.caption() == "run failed"
    assert view.plotter.actors[CAPTION_ACTOR].GetTextProperty().GetColor()[0] == 1.0
    d.set_caption("")
    assert d.caption() == "" and CAPTION_ACTOR not in view.plotter.actors
    d.detach()
