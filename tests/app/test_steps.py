"""Parameter steps without Qt (gcmh_studio.steps): the coarse grid, what a step keeps, the critical-value notice."""

import math
from types import SimpleNamespace

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gcmh_studio.steps import (
    COARSE_FLOOR,
    COARSE_MAX_CUBES,
    COARSE_MIN_DIV,
    COARSE_START,
    CoarseAim,
    coarse_div,
    critical_notice,
    step_key,
)


def job(**kw):
    d = dict(formulas=["x^2 + y^2 - z^2 - a"], variables=["x", "y", "z"], bounds=[(-2, 2)] * 3, method="gcmh",
             periodic=None, seed=0, div=[64, 64, 64])
    d.update(kw)
    return SimpleNamespace(**d)


@given(st.lists(st.integers(1, 400), min_size=1, max_size=6), st.floats(0.05, 1.0))
def test_a_coarse_grid_is_never_finer_than_the_full_one_and_stays_small(div, factor):
    out = coarse_div(div, factor)
    assert len(out) == len(div)
    for d, c in zip(div, out):
        assert c <= d and (c >= COARSE_MIN_DIV or c == d)
    assert math.prod(out) <= max(COARSE_MAX_CUBES, math.prod(min(d, COARSE_MIN_DIV) for d in div))


def test_a_step_keeps_the_system_but_not_the_values_or_the_grid():
    assert step_key(job()) == step_key(job(div=[8, 8, 8]))
    assert step_key(job()) != step_key(job(method="gcch"))
    assert step_key(job()) != step_key(job(formulas=["x^2 + y^2 + z^2 - a"]))


def test_the_coarse_aim_learns_and_starts_again_for_a_new_system():
    aim = CoarseAim()
    assert aim.div(job(), [64, 64, 64]) == [32, 32, 32]
    for _ in range(20):
        aim.learn(job(), 1.0)            # too slow: coarser, down to the floor
    assert aim.factor == pytest.approx(COARSE_FLOOR)
    aim.learn(job(method="gcch"), 0.0)   # another system's step teaches nothing here
    assert aim.factor == pytest.approx(COARSE_FLOOR)
    for _ in range(20):
        aim.learn(job(), 0.0)            # fast: finer, up to the start
    assert aim.factor == pytest.approx(COARSE_START)
    aim.factor = COARSE_FLOOR
    aim.div(job(method="gcch"), [64, 64, 64])
    assert aim.factor == COARSE_START


class _Cx:
    def __init__(self, singular, params, chi=1):
        self.meta = {"singular_vertices": singular, "params": params}
        self._chi = chi

    def euler_characteristic(self):
        return self._chi


def test_the_critical_notice_names_the_moved_parameter():
    assert critical_notice(_Cx(0, {"a": 0.0}), "a") == ""
    assert critical_notice(_Cx(3, {}), None) == ""
    text = critical_notice(_Cx(86, {"a": 0.0, "b": 1.5}), "b")
    assert text.startswith("b = 1.5 is a critical value") and "86 vertices" in text
    assert critical_notice(_Cx(2, {"a": 0.0}), None).startswith("a = 0 is a critical value")
