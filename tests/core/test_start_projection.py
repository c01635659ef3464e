"""A start point on M is projected in one evaluation: Newton judges convergence by its step, and a
start on M (F = 0 exactly: the kernels never move F's values, issue 25) takes no step.  A copy of F
whose exact zeros were shifted took all 50 steps (18 ms of GCCH's 250 on the complex cosine at div 80)."""

import numpy as np

from gcmh_core.continuation import project_onto_M
from gcmh_core.examples import load_example
from gcmh_core.formula import System, parse_system


def test_a_start_on_M_takes_no_step(monkeypatch):
    ex = load_example("complex-cosine")
    bounds = np.array(ex.bounds, np.float64)
    system = parse_system(ex.formulas, ex.variables)
    X0 = np.array([ex.start], np.float64)
    assert np.all(system.evaluate_points(X0) == 0.0)
    calls = []
    evaluate = System.evaluate_points
    monkeypatch.setattr(System, "evaluate_points", lambda self, P: calls.append(len(P)) or evaluate(self, P))
    X, ok, why = project_onto_M(system, X0, bounds)
    assert ok.all() and why == [""]
    assert np.array_equal(X, X0)  # (it was on M: it stays where it was)
    assert calls == [1]
