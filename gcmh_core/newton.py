"""Gauss-Newton onto M with F's exact Jacobian, for many points at once.

One step moves each point x to x - J(x)^+ F(x): J^+ is the Moore-Penrose
pseudo-inverse of the (k, n) Jacobian (sympy's exact derivatives), so the step
is the shortest move that zeroes the linearised F.  Every point is a row of one
array and each step is one vectorised evaluation of F and J over the rows still
moving, so projecting 4,096 start points costs a few evaluations, not 4,096
Python loops.

Used by the continuation's start points (`continuation.start_cubes`, paper
Section 5) and by `analysis.refine_vertices` (Refine onto M in the app).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["NewtonResult", "gauss_newton"]

# singular values below this fraction of the largest are dropped (directions where M is singular)
_RCOND = 1e-10

# why a point stopped, in NewtonResult.status
MOVING, CONVERGED, NOT_FINITE, JACOBIAN_NOT_FINITE, LEFT_DOMAIN = 0, 1, 2, 3, 4


@dataclass
class NewtonResult:
    """Where the points went.

    x : (m, n) float64, the moved points.
    residual : (m,) float64, |F(x)| (Euclidean norm over the k components; inf where not finite).
    step : (m,) float64, the length of each point's last Newton step (inf before the first).
        Where J has full rank k, the step J^+ F does not change when a component of F is
        multiplied by a constant, so tolerances on it are scale-free; |step| is also the
        first-order distance from x to M.
    status : (m,) int8, per point: MOVING (steps ran out), CONVERGED (|F| <= tol or |step| <= step_tol),
        NOT_FINITE (F not finite at x), JACOBIAN_NOT_FINITE, LEFT_DOMAIN (a full step left `bounds`;
        x is where it went).
    """

    x: np.ndarray
    residual: np.ndarray
    step: np.ndarray
    status: np.ndarray


def gauss_newton(
    system,
    X: np.ndarray,
    steps: int,
    *,
    tol: float = 0.0,
    step_tol: float | None = None,
    only_improving: bool = True,
    bounds: np.ndarray | None = None,
    margin: float = 0.0,
) -> NewtonResult:
    """Up to `steps` Gauss-Newton steps x <- x - J(x)^+ F(x) on every row of X (m, n).

    system : formula.System (evaluate_points, jacobian_points).
    tol : a point whose |F| is at most this stops (status CONVERGED).
    step_tol : a point whose full Newton step is at most this long stops after it (CONVERGED):
        a tolerance in the units of x, which does not depend on the scale of F.
    only_improving : take a step only where it lowers |F| (near singular points of M a
        full step may overshoot: refinement keeps the vertex where it was); False takes
        every full step (projection of a start point, which may start far from M).
    bounds : (n, 2) float64 or None; with it, a point whose step leaves the box widened
        by `margin` on each side stops with status LEFT_DOMAIN.
    """
    X = np.array(X, dtype=np.float64, copy=True).reshape(len(X), -1)
    m = len(X)
    status = np.zeros(m, np.int8)
    last_step = np.full(m, np.inf)
    if m == 0:
        return NewtonResult(X, np.zeros(0), last_step, status)
    F = system.evaluate_points(X)  # (m, k)
    res = _norm(F)
    status[~np.isfinite(res)] = NOT_FINITE
    for _ in range(steps):
        status[(status == MOVING) & (res <= tol)] = CONVERGED
        idx = np.flatnonzero((status == MOVING) & (res > 0))
        if len(idx) == 0:
            break
        J = system.jacobian_points(X[idx])  # (m', k, n)
        ok = np.isfinite(J).all(axis=(1, 2))
        status[idx[~ok]] = JACOBIAN_NOT_FINITE
        idx, J = idx[ok], J[ok]
        # each row (component) scaled to a unit gradient first: the same step where J has
        # rank k, but rcond then compares directions, not the components' units
        norms = np.linalg.norm(J, axis=2)  # (m', k)
        norms[norms == 0] = 1.0
        step = np.einsum("mnk,mk->mn", np.linalg.pinv(J / norms[:, :, None], rcond=_RCOND), F[idx] / norms)
        trial = X[idx] - step
        step_length = np.linalg.norm(step, axis=1)
        F_trial = system.evaluate_points(trial)
        res_trial = _norm(F_trial)
        if only_improving:
            take = np.isfinite(res_trial) & (res_trial < res[idx])
        else:
            take = np.ones(len(idx), bool)
            if bounds is not None:
                out = np.any((trial < bounds[:, 0] - margin) | (trial > bounds[:, 1] + margin), axis=1)
                status[idx[out]] = LEFT_DOMAIN
            status[idx[~np.isfinite(res_trial)]] = NOT_FINITE
        moved = idx[take]
        X[moved] = trial[take]
        F[moved] = F_trial[take]
        res[moved] = res_trial[take]
        last_step[moved] = step_length[take]
        if step_tol is not None:
            small = moved[step_length[take] <= step_tol]
            status[small[status[small] == MOVING]] = CONVERGED
    status[(status == MOVING) & (res <= tol)] = CONVERGED
    return NewtonResult(X, res, last_step, status)


def _norm(F: np.ndarray) -> np.ndarray:
    res = np.linalg.norm(F, axis=1)
    res[~np.isfinite(res)] = np.inf
    return res
