"""Waits explained truthfully (issue 27, item 5): the notice only while numba really compiles (simulated with
the compile_notice hook), with a measured estimate and the family of kernels; the example's picture, not a
blank view, until the first result."""

import threading
from types import SimpleNamespace

import pytest

import gcmh_core
from gcmh_studio import jobs


@pytest.fixture
def fake_notice():
    """``fire(module)``: numba's "numba:compile" event for a kernel of ``module`` (what numba broadcasts when a
    kernel misses its on-disk cache and compiles), heard by the real gcmh_core.compile_notice."""
    from numba.core import event

    def fire(module):
        def kernel():
            pass

        kernel.__module__ = module
        with event.trigger_event("numba:compile", data={"dispatcher": SimpleNamespace(py_func=kernel)}):
            pass

    return fire


def _warm_up(monkeypatch, body):
    """A WarmUp whose kernels' warm-up is ``body()`` (run in its thread)."""
    monkeypatch.setattr(jobs, "warm_up_kernels", lambda methods, cancel=None, ready=None: body())
    return jobs.WarmUp(("gcmh",)).start()


def test_a_warm_up_that_only_loads_the_cache_says_nothing(monkeypatch, fake_notice):
    go = threading.Event()
    warm = _warm_up(monkeypatch, lambda: go.wait(30))
    try:
        assert warm.running() and warm.notice() == ""          # loading: no word of compiling
        assert warm.phase() == jobs.LOADING
    finally:
        go.set()
    assert warm.wait(30) and warm.notice() == ""


def test_a_warm_up_that_compiles_says_so_with_an_estimate(monkeypatch, fake_notice):
    fired, go = threading.Event(), threading.Event()

    def body():
        fake_notice("gcmh_core._hashtable")     # (a small part: the estimate is still the quiet one times the load)
        fired.set()
        go.wait(30)

    monkeypatch.setattr(jobs, "busy_factor", lambda: 2.0)
    warm = _warm_up(monkeypatch, body)
    try:
        assert fired.wait(30)
        text = warm.notice()
        assert warm.phase() == jobs.COMPILING
        assert text.startswith("Compiling the numerical kernels") and "left" in text
        assert 0 < warm.seconds_left() <= 2.0 * jobs.WARM_UP_SECONDS
        assert warm.modules == ["gcmh_core._hashtable"]
        assert set(warm.compiled) == {"gcmh_core._hashtable"}    # (its compile's start and end were heard)
        # once a tenth has compiled, what it took here is scaled to the whole
        monkeypatch.setattr(warm, "elapsed", lambda: 30.0)
        warm.compiled = {"gcmh_core.kernels.gcmh": 30.0}
        share = jobs.KERNEL_FAMILIES["gcmh_core.kernels.gcmh"][1] / jobs.WARM_UP_SECONDS
        assert warm.seconds_left() == pytest.approx(30.0 / share - 30.0)
    finally:
        go.set()
    assert warm.wait(30) and warm.notice() == ""                # done: nothing more to say


@pytest.mark.parametrize("module, words", [("gcmh_core.kernels.lazy", "n >= 8"),
                                           ("gcmh_core.kernels.cell_check", "cell check")])
def test_a_run_announces_each_family_of_kernels_it_compiles(monkeypatch, fake_notice, module, words):
    phases = []
    real = gcmh_core.extract

    def extract(formulas, progress=None, cancel=None, **kw):
        fake_notice(module)
        fake_notice(module)          # (a second kernel of the family: announced once)
        return real(formulas, **kw)

    monkeypatch.setattr(gcmh_core, "extract", extract)
    job = jobs.Job(["x^2 + y^2 + z^2 - 1"], ["x", "y", "z"], [(-1.5, 1.5)] * 3, div=4)
    jobs.run_job(job, progress=lambda phase, fraction: phases.append(phase))
    announced = [p for p in phases if p.startswith(jobs.COMPILING)]
    assert len(announced) == 1 and words in announced[0] and "about" in announced[0]
    assert announced[0].startswith(jobs.WAITING_PHASES)          # shown as a wait, without a percentage


def test_a_run_that_compiles_nothing_announces_nothing(monkeypatch, fake_notice):
    phases = []
    job = jobs.Job(["x^2 + y^2 + z^2 - 1"], ["x", "y", "z"], [(-1.5, 1.5)] * 3, div=4)
    jobs.run_job(job, progress=lambda phase, fraction: phases.append(phase))
    assert not any(p.startswith(jobs.COMPILING) for p in phases)


def test_the_estimate_grows_with_the_load(monkeypatch):
    monkeypatch.setattr(jobs.os, "getloadavg", lambda: (8.0, 8.0, 8.0))
    monkeypatch.setattr(jobs.os, "cpu_count", lambda: 2)
    assert jobs.busy_factor() == 4.0
    name, seconds = jobs.kernel_family("gcmh_core.kernels.lazy")
    assert name == "the kernels for n >= 8" and seconds == 4.0 * jobs.KERNEL_FAMILIES["gcmh_core.kernels.lazy"][1]
    assert jobs.about_seconds(11) == "15 s" and jobs.about_seconds(61) == "2 min"


def test_the_view_shows_the_examples_picture_until_its_first_result(qtbot, small_window):
    from gcmh_core.examples import load_example

    from app_helpers import small_div

    w = small_window
    waiting = w.viewer.waiting
    assert not waiting.shown()
    ex = load_example("torus-angles")
    with qtbot.waitSignal(w.runFinished, timeout=180_000) as b:
        assert w.load_example("torus-angles", div=small_div(ex))
        assert waiting.shown() and waiting.example.name == "torus-angles"   # (before the result comes)
    assert b.args[0] == "done"
    # it stays until the result's first picture is on screen (hiding it earlier repainted the view on the GUI
    # thread, and the see-through result's picture drawn in a thread was dropped)
    qtbot.waitUntil(lambda: not waiting.shown(), timeout=60_000)
    assert not w.viewer.still_pending()
    img = w.viewer.waiting.card(400, 300).toImage()
    assert img.width() == 400


def test_the_estimate_of_a_glued_run_is_told_of_its_glued_axes(monkeypatch):
    import gcmh_core.budget

    seen = {}

    def estimate(F, bounds=None, div=None, *, variables=None, method="gcmh", scheduler=None, periodic=None):
        seen["periodic"] = periodic
        return "estimate"

    monkeypatch.setattr(gcmh_core.budget, "estimate", estimate)
    job = jobs.Job(["x^2 + y^2 + z^2 - 1"], ["x", "y", "z"], [(-1.5, 1.5)] * 3, div=4, periodic=["x"])
    assert jobs.estimate_job(job) == "estimate" and seen["periodic"] == ["x"]
    job.periodic = None
    jobs.estimate_job(job)
    assert seen["periodic"] is None


def test_the_waiting_picture_is_the_glued_examples_when_the_system_is_glued():
    from gcmh_core.examples import load_example
    from gcmh_studio.qt_waiting_picture import example_of_system

    kb = load_example("klein-bottle")
    system = {"formulas": list(kb.formulas), "variables": list(kb.variables)}
    assert example_of_system(system).name == "klein-bottle"
    assert example_of_system({**system, "periodic": ["s:flip=t", "t"]}).name == "klein-bottle-closed"
    assert example_of_system({**system, "periodic": "t  s:flip=t"}).name == "klein-bottle-closed"   # the field's text
    assert example_of_system({**system, "formulas": ["x - y", "y", "z"]}) is None
