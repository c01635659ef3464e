"""Issue 27 in the window: the pentagon linkage's picked point drawn as rods, the angle switches in the
View tab, panels that fit at 1024 x 768."""

import numpy as np
import pytest

from app_helpers import small_div


def _load(qtbot, window, name, div=None):
    from gcmh_core.examples import load_example

    ex = load_example(name)
    with qtbot.waitSignal(window.runFinished, timeout=180_000) as b:
        assert window.load_example(name, div=div or small_div(ex))
    assert b.args[0] == "done", window.last_status
    return ex


def test_picking_the_linkage_surface_shows_its_rods(qtbot, small_window):
    w = small_window
    _load(qtbot, w, "pentagon-linkage", div=10)
    inset = w.viewer.linkage
    assert not inset.isVisible()
    info = w.viewer.pick_cell(5)
    assert inset.isVisible()
    J = inset.joints()
    assert len(J) == 5
    assert np.allclose(np.linalg.norm(np.diff(J, axis=0), axis=1), 1.0)
    assert np.linalg.norm(J[-1] - [1.0, 0.0]) < 1e-9       # the loop closes on the fixed rod (moved onto M)
    assert np.allclose(np.mod(inset.angles - info["coords"].mean(axis=0) + np.pi, 2 * np.pi) - np.pi, 0,
                       atol=0.7)
    img = inset.grab().toImage()
    assert img.width() > 100
    w.viewer.clear_pick()
    assert not inset.isVisible()


def test_the_angle_switches_follow_the_result(qtbot, small_window):
    w = small_window
    box = w.projection_panel.style_box
    _load(qtbot, w, "sphere")
    assert not box.circles_check.isEnabled()
    _load(qtbot, w, "torus-angles")
    assert box.circles_check.isEnabled()
    before = np.array(w.scene.mesh.points)
    box.circles_check.setChecked(True)
    assert w.scene.circles_on
    box.seam_check.setChecked(True)
    assert w.scene._seam is not None
    assert w.scene.colour_map("t") == "twilight_shifted"
    from gcmh_studio.angles import CircleProjector

    w.viewer.pick_cell(3)                     # the picked cell drawn where the circles put it
    pick = w.scene.overlays["pick"]
    assert isinstance(pick[0].projector, CircleProjector)
    assert np.allclose(np.array(pick[1].points), pick[0].projector.project(w.scene.view.P), atol=1e-5)
    box.circles_check.setChecked(False)
    assert np.allclose(np.array(w.scene.mesh.points), before, atol=1e-5)
    assert not isinstance(w.scene.overlays["pick"][0].projector, CircleProjector)


@pytest.mark.parametrize("n", [3, 10])
def test_the_view_tab_fits_a_third_of_1024_pixels(qtbot, n):
    """The View tab's content is no wider than a side panel of a third of a 1024-pixel window, for 3 and for
    10 variables (45 rotation planes, 7 turn pads); nothing is cut off at its right edge."""
    from gcmh_studio.model import StudioModel
    from gcmh_studio.qt_projection_panel import QtProjectionPanel

    m = StudioModel()
    panel = QtProjectionPanel(m)
    qtbot.addWidget(panel)
    m.set_view_variables([f"x{i + 1}" for i in range(n)])
    assert len(panel.rotation.sliders) == n * (n - 1) // 2
    assert panel.minimumSizeHint().width() <= 1024 // 3, panel.minimumSizeHint().width()


def test_every_side_tab_fits_a_third_of_1024_pixels(qtbot, window):
    """Manifold, View, Animate, Topology (and any later tab): no content wider than a third of a 1024-pixel
    window with 10 variables (long combo labels and "2-dimensional manifold in R^10" made them 360-420)."""
    from qtpy.QtWidgets import QScrollArea, QTabWidget

    window.formula_panel.n_spin.setValue(10)
    window.model.set_view_variables([f"x{i + 1}" for i in range(10)])
    seen = []
    for tabs in window.findChildren(QTabWidget):
        for i in range(tabs.count()):
            page = tabs.widget(i)
            inner = page.widget() if isinstance(page, QScrollArea) else page
            seen.append(tabs.tabText(i))
            assert inner.minimumSizeHint().width() <= 1024 // 3, (tabs.tabText(i), inner.minimumSizeHint().width())
    assert {"Manifold", "View", "Animate", "Topology"} <= set(seen)


def test_the_title_and_story_follow_the_gluing():
    from gcmh_core.examples import load_example
    from gcmh_studio.labels import gluing_title

    kb, closed, torus = load_example("klein-bottle"), load_example("klein-bottle-closed"), load_example("torus-angles")
    # the cut-open Klein bottle glued by hand is the closed one: its title and its story
    title, story = gluing_title(kb.title, kb.formulas, kb.variables, ["t", "s:flip=t"])
    assert title == closed.title and "Euler characteristic 0" in story
    assert gluing_title(kb.title, kb.formulas, kb.variables, None) == (kb.title, None)       # as it is: unchanged
    assert gluing_title(closed.title, closed.formulas, closed.variables, [])[0] == kb.title
    # no example glued so: the title says how, the old story goes
    assert gluing_title(torus.title, torus.formulas, torus.variables, None) == (f"{torus.title}, cut open", "")
    assert gluing_title(torus.title, torus.formulas, torus.variables, ["s"])[0].endswith("glued (s)")
    assert gluing_title("", torus.formulas, torus.variables, ["s"]) == ("", None)          # a system typed in


def test_the_stories_speak_of_the_apps_fields_not_files():
    from gcmh_core.examples import list_examples

    for ex in list_examples():
        text = " ".join(str(ex.description).split())
        assert "from the file" not in text and "the line" not in text, ex.name
