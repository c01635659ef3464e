"""The one batched Gauss-Newton (newton.gauss_newton) against a one-point-at-a-time twin."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gcmh_core.continuation import project_onto_M
from gcmh_core.formula import parse_system
from gcmh_core.newton import CONVERGED, LEFT_DOMAIN, MOVING, NOT_FINITE, gauss_newton

SPHERE_LINE = parse_system(["x^2 + y^2 + z^2 - 1", "x - y*z"], "x,y,z")


def one_point(system, x, steps, tol, only_improving):
    """Obviously correct: one point, lstsq for the step (the minimum-norm least-squares step)."""
    x = np.array(x, float)
    F = system.evaluate_points(x[None])[0]
    for _ in range(steps):
        if np.linalg.norm(F) <= tol:
            break
        J = system.jacobian_points(x[None])[0]
        trial = x - np.linalg.lstsq(J, F, rcond=1e-10)[0]
        F_trial = system.evaluate_points(trial[None])[0]
        if only_improving and not np.linalg.norm(F_trial) < np.linalg.norm(F):
            continue
        x, F = trial, F_trial
    return x, np.linalg.norm(F)


@pytest.mark.parametrize("only_improving", [True, False])
def test_batch_equals_one_point_at_a_time(only_improving):
    rng = np.random.default_rng(7)
    X0 = rng.uniform(-1.2, 1.2, (60, 3))
    out = gauss_newton(SPHERE_LINE, X0, 8, tol=1e-13, only_improving=only_improving)
    for i, x0 in enumerate(X0):
        x, res = one_point(SPHERE_LINE, x0, 8, 1e-13, only_improving)
        assert_allclose(out.x[i], x, rtol=0, atol=1e-9)
        assert out.residual[i] == pytest.approx(res, abs=1e-9)
    assert not np.shares_memory(out.x, X0)


def test_status_says_why_a_point_stopped():
    f = parse_system(["log(x) + y^2 + z^2 - 1"], "x,y,z")
    X0 = np.array([[1.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [1.0, 0.5, 0.2]])
    out = gauss_newton(f, X0, 30, tol=1e-12, only_improving=False)
    assert out.status[0] == CONVERGED and out.residual[0] == 0.0  # on M already
    assert out.status[1] == NOT_FINITE  # log of a negative number
    assert out.status[2] == CONVERGED and out.residual[2] <= 1e-12
    boxed = gauss_newton(SPHERE_LINE, [[0.9, 0.9, 0.9]], 30, tol=1e-12, only_improving=False,
                         bounds=np.array([[0.8, 1.0]] * 3))
    assert boxed.status[0] == LEFT_DOMAIN
    few = gauss_newton(SPHERE_LINE, [[3.0, 2.0, 1.0]], 1, tol=1e-12)
    assert few.status[0] == MOVING


def test_refine_never_raises_the_residual():
    rng = np.random.default_rng(3)
    X0 = rng.uniform(-2, 2, (200, 3))
    before = np.linalg.norm(SPHERE_LINE.evaluate_points(X0), axis=1)
    out = gauss_newton(SPHERE_LINE, X0, 3)
    assert np.all(out.residual <= before)


def test_projected_start_points_land_on_M():
    bounds = np.array([[-1.5, 1.5]] * 3)
    lattice = np.stack(np.meshgrid(*[np.linspace(-1.2, 1.2, 6)] * 3, indexing="ij"), -1).reshape(-1, 3)
    X, ok, why = project_onto_M(SPHERE_LINE, lattice, bounds)
    assert ok.sum() > len(lattice) // 2
    assert np.abs(SPHERE_LINE.evaluate_points(X[ok])).max() <= 1e-8
    assert all(w == "" for w, good in zip(why, ok) if good) and all(w for w, good in zip(why, ok) if not good)


@pytest.mark.parametrize("factors", [(1e10, 1e10), (1e-12, 1e-12), (1e-12, 1e12), (1e8, 1.0)])
def test_start_point_projection_does_not_depend_on_the_scale_of_F(factors):
    bounds = np.array([[-1.5, 1.5]] * 3)
    texts = ["x^2 + y^2 + z^2 - 1", "x - y*z"]
    scaled = parse_system([f"{c:.0e}*({t})" for c, t in zip(factors, texts)], "x,y,z")
    X0 = np.array([[0.9, 0.3, 0.2], [0.1, -0.8, 0.5], [0.5, 0.5, 0.5]])
    plain_X, plain_ok, _ = project_onto_M(SPHERE_LINE, X0, bounds)
    X, ok, why = project_onto_M(scaled, X0, bounds)
    assert ok.all() and plain_ok.all(), why
    assert_allclose(X, plain_X, rtol=0, atol=1e-9)
    assert np.abs(SPHERE_LINE.evaluate_points(X)).max() <= 1e-9
