"""A start point on M is projected in one evaluation, also when exact zeros are shifted:
the grid's copy of F (`_zeros`) reads F = 0 as noise of 1e-9 that no Newton step reduces,
and projecting with it took all 50 steps (18 ms of GCCH's 250 on the complex cosine at div 80)."""

import numpy as np

from gcmh_core import _zeros
from gcmh_core.continuation import project_onto_M
from gcmh_core.examples import load_example
from gcmh_core.formula import System, parse_system


def test_a_start_on_M_takes_no_step_with_zeros_shifted(monkeypatch):
    ex = load_example("complex-cosine")
    bounds = np.array(ex.bounds, np.float64)
    system = parse_system(ex.formulas, ex.variables)
    shifted = system.with_zero_shift(_zeros.zero_shift(system, bounds))
    X0 = np.array([ex.start], np.float64)
    assert np.all(system.evaluate_points(X0) == 0.0) and np.all(shifted.evaluate_points(X0) > 0.0)
    calls = []
    evaluate = System.evaluate_points
    monkeypatch.setattr(System, "evaluate_points", lambda self, P: calls.append(len(P)) or evaluate(self, P))
    X, ok, why = project_onto_M(shifted, X0, bounds)
    assert ok.all() and why == [""]
    assert np.array_equal(X, X0)  # (it was on M: it stays where it was)
    assert calls == [1]
