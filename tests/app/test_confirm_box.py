"""The Topology tab's "Confirm on a finer grid" (gcmh_core.confirm in a worker)."""

import pytest

import gcmh_core
from gcmh_studio.jobs import Job
from gcmh_studio.model import StudioModel
from gcmh_studio.qt_confirm_box import QtConfirmBox


def _show(model, formulas, div):
    job = Job(list(formulas), ["x", "y", "z"], [(-1.5, 1.5)] * 3, div=div)
    model.job = job
    cx = gcmh_core.extract(list(formulas), [(-1.5, 1.5)] * 3, div, variables=["x", "y", "z"])
    model.set_result(cx, ["x", "y", "z"])
    return cx


@pytest.fixture
def box(qtbot):
    model = StudioModel()
    b = QtConfirmBox(model)
    qtbot.addWidget(b)
    return b


def test_no_result_no_button(box):
    assert not box.button.isEnabled() and not box.start()


def test_a_sphere_is_confirmed(qtbot, box):
    _show(box.studio, ["x^2 + y^2 + z^2 - 1"], 8)
    assert box.button.isEnabled()
    with qtbot.waitSignal(box.confirmed, timeout=120_000) as got:
        box.button.click()
    assert got.args == [True]
    assert box.label.text().startswith("confirmed on a second grid") and box.answer.agree


def test_a_thin_tube_is_below_the_grid(qtbot, box):
    _show(box.studio, ["(sqrt(x^2 + y^2) - 1)^2 + z^2 - 0.0036"], 6)
    with qtbot.waitSignal(box.confirmed, timeout=120_000) as got:
        box.button.click()
    assert got.args == [False]
    assert "finer" in box.label.text()


def test_an_answer_for_an_old_result_is_dropped(qtbot, box):
    _show(box.studio, ["x^2 + y^2 + z^2 - 1"], 8)
    assert box.start()
    with qtbot.assertNotEmitted(box.confirmed):
        _show(box.studio, ["x^2 + y^2 + z^2 - 0.5"], 6)   # a new result while the first is confirmed
        assert box.label.text() == "" and box.answer is None
        qtbot.waitUntil(lambda: not box.worker.busy(), timeout=120_000)
        qtbot.wait(0)   # (the worker's answer, queued to this thread, is delivered and dropped)
    assert box.answer is None and box.button.isEnabled()
