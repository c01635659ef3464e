"""QtTopologyPanel on its own: the report it shows, the refine button, the toggles."""

import numpy as np
import pytest

from gcmh_core import CellComplex, extract
from gcmh_core.analysis import refine_vertices
from gcmh_core.examples import load_example
from gcmh_core.formula import parse_system
from gcmh_studio.qt_topology_panel import QtTopologyPanel


def _example(name):
    ex = load_example(name)
    cx = extract(ex.formulas, ex.bounds, ex.div, variables=ex.variables)
    return cx, parse_system(ex.formulas, ex.variables)


@pytest.fixture
def panel(qtbot):
    p = QtTopologyPanel()
    qtbot.addWidget(p)
    p.show()
    return p


def test_empty_panel(panel):
    assert panel.report() is None
    assert not panel.refine_button.isEnabled()
    assert all(label.text() == "—" for label in panel.values.values())


def test_klein_bottle_report(panel):
    cx, system = _example("klein-bottle")
    rep = panel.set_result(cx, system)
    assert panel.report() is rep
    v = {k: label.text() for k, label in panel.values.items()}
    assert v["euler"] == "1"
    assert v["components"] == "1"
    assert "surface" in v["shape"] and "R^5" in v["shape"] and "k = 3" in v["shape"]
    assert f"V {cx.count(0):,}" in v["counts"] and f"F {cx.count(2):,}" in v["counts"]
    assert v["boundary"].startswith("1 component")
    assert v["orientation"].startswith("consistent")
    assert float(v["residual"]) == pytest.approx(rep["max_abs_F"], rel=1e-2)
    assert "kernel" in v["timings"] and v["seconds"] != "—"
    assert panel.refine_button.isEnabled()
    assert panel.two_sided_check.isEnabled() and panel.boundary_check.isEnabled()


def test_sphere_closed_and_no_system(panel):
    cx, _ = _example("sphere")
    panel.set_result(cx)
    assert panel.values["euler"].text() == "2"
    assert panel.values["boundary"].text() == "none (closed)"
    assert panel.values["residual"].text() == "—"
    assert not panel.refine_button.isEnabled()  # no F: nothing to refine onto
    assert not panel.boundary_check.isEnabled()


def test_three_manifold_has_no_orientation_row(panel):
    cx, system = _example("three-sphere-slices")
    panel.set_result(cx, system)
    assert panel.values["euler"].text() == "0"
    assert "only for surfaces" in panel.values["orientation"].text()
    assert not panel.two_sided_check.isEnabled()
    assert "3-cells" in panel.values["counts"].text()


def test_non_orientable_shown_in_red(panel):
    s = 6
    quads = [[i, i + 1, s + i + 1, s + i] for i in range(s - 1)] + [[s - 1, s, 0, 2 * s - 1]]
    edges, faces, offsets, ids = [], [], [0], {}
    for q in quads:
        for a, b in zip(q, q[1:] + q[:1]):
            key = (min(a, b), max(a, b))
            if key not in ids:
                ids[key] = len(edges)
                edges.append(key)
            faces.append(ids[key])
        offsets.append(len(faces))
    mob = CellComplex(3, 1, np.random.default_rng(0).normal(size=(2 * s, 3)), edges, {2: (offsets, faces)})
    panel.set_result(mob)
    assert panel.values["orientation"].text().startswith("not orientable")
    assert "#c22" in panel.values["orientation"].styleSheet()
    assert panel.values["euler"].text() == "0"


def test_refine_button_and_result(panel, qtbot):
    cx, system = _example("complex-cosine")
    panel.set_result(cx, system)
    with qtbot.waitSignal(panel.refineRequested, timeout=1000):
        qtbot.mouseClick(panel.refine_button, 1)  # Qt.LeftButton
    _, before, after = refine_vertices(cx, system)
    panel.show_refinement(before, after)
    text = panel.refine_label.text()
    assert f"{before:.3g}" in text and f"{after:.3g}" in text and "times smaller" in text
    assert panel.report()["max_abs_F"] == after
    panel.set_refine_enabled(False)
    assert not panel.refine_button.isEnabled()
    panel.set_refine_enabled(True)
    assert panel.refine_button.isEnabled()
    panel.clear()
    assert panel.report() is None and panel.refine_label.text() == "" and not panel.refine_button.isEnabled()


@pytest.mark.parametrize("check, field", [("boundary_check", "boundary"), ("path_check", "grid"),
                                          ("two_sided_check", "two_sided")])
def test_toggles_write_and_show_the_model(panel, check, field):
    cx, system = _example("complex-cosine")
    panel.set_result(cx, system)
    box = getattr(panel, check)
    seen = []
    panel.studio.events.style.connect(lambda: seen.append(getattr(panel.studio.style, field)))
    for state in (True, False):
        box.setChecked(state)
        assert getattr(panel.studio.style, field) is state
    assert seen == [True, False]
    panel.studio.set_style(**{field: True})   # the View tab's switch, say: this one follows
    assert box.isChecked()


def test_w1_count_is_the_loop_drawn(panel, qtbot):
    """The closed Klein bottle: the orientation row counts the edges of the w1 loop the box draws
    (not the breadth-first search's conflicts, a longer set whose size depends on the search)."""
    ex = load_example("klein-bottle-closed")
    cx = extract(ex.formulas, ex.bounds, [12, 12, 6, 12, 12], variables=ex.variables, periodic=ex.periodic)
    box = panel.homology_box
    with qtbot.waitSignal(box.computed, timeout=60000):
        panel.set_result(cx)
    h = box.data["homology"]
    text = panel.values["orientation"].text()
    assert text.startswith("not orientable")
    assert f"w1 loop: {h.orientation_cycle.size:,} edges" in text
    assert "conflict" not in text
    box.w1_check.setChecked(True)
    from gcmh_studio.cycles import w1_lines

    (_, EL), _ = w1_lines(cx, h.orientation_cycle, h.orientation)
    assert len(EL) == h.orientation_cycle.size
    # another result: the row no longer counts the old loop
    sphere, _ = _example("sphere")
    panel.set_result(sphere)
    assert "w1" not in panel.values["orientation"].text()
