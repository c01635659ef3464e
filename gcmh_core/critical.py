"""Critical points of F on M: points x of M = F^-1(0) where F's Jacobian J(x) (k, n) has rank
below k, so M is singular there and the parameters are at a critical value (issue 25, item 4).

Whether a grid vertex lands near such a point depends on the grid (the cone x^2 + y^2 - z^2 = 0
at div 13 has its apex in a cube's middle, far from every vertex).  So the point is solved for:
x is a critical point of M when, for some unit u in R^k,

    F(x) = 0,   J(x)^T u = 0,   |u|^2 = 1,

n + k + 1 equations in the n + k unknowns (x, u): one more than unknowns, so a generic M has no
solution and a parameter at its critical value has one.  Gauss-Newton on these equations (F's
exact Jacobian, its derivatives by differences) starts from the vertices of the run where J is closest to
losing rank, the lowest in each block of a few cubes, so every cube M crosses near a critical
point seeds one solve.  A solve that ends with the equations met (to rounding, scale-free: each
F_j is divided by its typical gradient) inside the box is a critical point; away from a critical
value the residual stays at the distance to it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SINGULAR_RATIO", "critical_points", "singular_report", "singular_vertices"]

# a vertex is singular when F's Jacobian there has a smallest singular value below this
# fraction of the median over all vertices (the cone's apex at a grid spacing h: about h)
SINGULAR_RATIO = 0.1
# seeds: the vertex of smallest relative sigma_min in each block of this many cubes per axis, if it
# is below SEED_RATIO of the median; at most MAX_SEEDS of them, smallest first
_BLOCK_CUBES = 3
SEED_RATIO = 0.5
MAX_SEEDS = 12
# Newton's steps: from within a cube of a critical point a solve meets the equations in 5 or 6
# where the point is nondegenerate (a cone's apex); where F vanishes to higher order there (a torus
# pinched to a point, two spheres touching) it converges linearly, halving the distance a step: 40
_STEPS = 40
_FAST_STEPS = 6  # (from then on a solve must shrink its residual to _STALLED of the last one a step)
_STALLED = 0.9
# the equations met: |F_j| / g_j below this fraction of the box's diameter, |J^T u| below _TOL_J
_TOL_F = 1e-9
_TOL_J = 1e-7
# rank of J at a critical point: singular values of J (rows over their typical gradient) above this
_RANK_RCOND = 1e-6

def _jacobian(system, X):
    """F's exact Jacobian at the rows of X, (m, k, n), 0 where not finite."""
    return np.nan_to_num(system.jacobian_points(X), nan=0.0, posinf=0.0, neginf=0.0)


def _typical_gradient(J):
    """(k,) each component's median gradient length over the points (1 where 0): F_j / g_j has
    gradients of length about 1, whatever F_j's scale."""
    g = np.median(np.linalg.norm(J, axis=2), axis=0)
    return np.where(g > 0, g, 1.0)


def _sigma(J):
    """(m,) smallest singular value of each Jacobian J (m, k, n), its rows over their typical
    length (`_typical_gradient`: no component's scale outweighs another's), by the square root of
    the smallest eigenvalue of J J^T (k, k), cheaper than an SVD."""
    J = J / _typical_gradient(J)[None, :, None]
    if J.shape[1] == 1:
        return np.linalg.norm(J[:, 0], axis=1)
    with np.errstate(all="ignore"):
        return np.sqrt(np.maximum(np.linalg.eigvalsh(J @ np.transpose(J, (0, 2, 1)))[:, 0], 0.0))


def singular_vertices(system, X: np.ndarray, sigma=None) -> int:
    """How many of the points X (m, n) have a nearly rank-deficient exact Jacobian (smallest
    singular value below `SINGULAR_RATIO` of the median; sigma (m,): those values, if known)."""
    if len(X) == 0:
        return 0
    sigma = _sigma(_jacobian(system, X)) if sigma is None else sigma
    median = float(np.median(sigma))
    return int(np.count_nonzero(sigma < SINGULAR_RATIO * median)) if median > 0 else 0


def singular_report(system, X: np.ndarray, bounds, div) -> tuple[int, list[dict]]:
    """(singular vertices, critical points) of a run with vertices X (m, n) on a grid of `div`
    (n,) cubes over `bounds` (n, 2): the critical points found (`critical_points`), and how many
    vertices are singular (`singular_vertices`) or lie within one grid cube of a critical point.
    The first is `meta["singular_vertices"]` (> 0: the parameters are at or near a critical value),
    the second `meta["critical_points"]`."""
    X = np.asarray(X, np.float64)
    if len(X) == 0:
        return 0, []
    bounds = np.asarray(bounds, np.float64)
    div = np.asarray(div, np.float64)
    J = _jacobian(system, X)
    sigma = _sigma(J)
    median = float(np.median(sigma))
    near = sigma < SINGULAR_RATIO * median if median > 0 else np.zeros(len(X), bool)
    points = critical_points(system, X, bounds, div, jacobian=J)
    spacing = (bounds[:, 1] - bounds[:, 0]) / div
    for point in points:
        offset = np.abs(X - np.asarray(point["x"]))
        close = (offset <= spacing).all(axis=1)
        if not close.any():  # (a point where M pinches may have no vertex within a cube: its nearest one)
            close[np.argmin((offset / spacing).max(axis=1))] = True
        near |= close
    return int(np.count_nonzero(near)), points


def _hessian_points(system, X, eps):
    """F's second derivatives at the rows of X, (m, k, n, n), by central differences of the exact
    Jacobian (steps eps (n,)): one batch of 2n m points, and no symbolic work per system (a
    parameter sweep makes a new system per frame).  The solve's residuals use the exact F and J,
    so this only sets how fast it converges."""
    m, n = X.shape
    offsets = np.zeros((2 * n, n))
    offsets[np.arange(n), np.arange(n)] = eps
    offsets[n + np.arange(n), np.arange(n)] = -eps
    J = system.jacobian_points((X[:, None, :] + offsets[None]).reshape(-1, n)).reshape(m, 2 * n, system.k, n)
    # H[i, j, a, b] = d2 F_j / dx_a dx_b: column b from the steps along b, symmetrised
    H = np.transpose((J[:, :n] - J[:, n:]) / (2.0 * eps)[None, :, None, None], (0, 2, 3, 1))
    return 0.5 * (H + np.transpose(H, (0, 1, 3, 2)))


def _seeds(X, sigma, bounds, div):
    """The rows of X where a solve starts (see the module doc), smallest relative sigma first."""
    median = float(np.median(sigma))
    if not median > 0:
        return X[:0]
    low = np.flatnonzero(sigma < SEED_RATIO * median)
    lo, hi = bounds[:, 0], bounds[:, 1]
    blocks = np.maximum(np.asarray(div, np.float64) / _BLOCK_CUBES, 1.0)
    multi = np.clip(np.floor((X[low] - lo) / (hi - lo) * blocks), 0, blocks - 1).astype(np.int64)
    block = np.ravel_multi_index(tuple(multi.T), tuple(blocks.astype(np.int64)))
    order = np.lexsort((sigma[low], block))  # by block, then sigma within it
    first = np.ones(len(order), bool)
    first[1:] = block[order][1:] != block[order][:-1]
    best = low[order[first]]
    return X[best[np.argsort(sigma[best], kind="stable")][:MAX_SEEDS]]


def critical_points(system, X: np.ndarray, bounds, div, jacobian=None) -> list[dict]:
    """Critical points of F on M near the points X (m, n) (a run's vertices; the module doc says
    how): a list of {"x": [n floats], "rank": rank of J there}, one per point found, in the box
    `bounds` (n, 2) of a grid of `div` (n,) cubes; points closer than a hundredth of a cube are one.
    jacobian (m, k, n): F's Jacobian at X, if known."""
    bounds = np.asarray(bounds, np.float64)
    X = np.asarray(X, np.float64)
    if len(X) == 0 or system is None:
        return []
    n, k = system.n, system.k
    J_all = _jacobian(system, X) if jacobian is None else jacobian
    x = _seeds(X, _sigma(J_all), bounds, div)
    if len(x) == 0:
        return []
    # each F_j over its typical gradient (scale-free: no component's numbers meet another's)
    g = _typical_gradient(J_all)
    J0 = system.jacobian_points(x) / g[None, :, None]
    with np.errstate(all="ignore"):
        u = np.linalg.svd(np.nan_to_num(J0))[0][:, :, -1]  # the left singular vector of sigma_min
    z = np.concatenate([x, u], axis=1)
    diameter = float(np.linalg.norm(bounds[:, 1] - bounds[:, 0]))
    eps = 1e-4 * (bounds[:, 1] - bounds[:, 0]) / np.asarray(div, np.float64)
    with np.errstate(all="ignore"):
        moving = np.ones(len(z), bool)
        last = np.full(len(z), np.inf)  # each solve's residual at its previous step
        for step_no in range(_STEPS):
            if not moving.any():
                break
            zi = z[moving]
            x, u = zi[:, :n], zi[:, n:]
            F = system.evaluate_points(x) / g
            J = system.jacobian_points(x) / g[None, :, None]
            r = np.concatenate([F, np.einsum("mkn,mk->mn", J, u), (u * u).sum(axis=1, keepdims=True) - 1.0], axis=1)
            size = np.linalg.norm(r, axis=1)
            if step_no >= _FAST_STEPS:
                # a solve whose residual no longer shrinks by a fixed factor has stalled at the residual's
                # minimum away from M's critical points (the linear convergence to a degenerate one halves
                # it or better): it stops there
                stalled = ~(size <= _STALLED * last[moving])
                if stalled.any():
                    idx = np.flatnonzero(moving)
                    moving[idx[stalled]] = False
                    keep = ~stalled
                    zi, x, u, F, J, r, size = zi[keep], x[keep], u[keep], F[keep], J[keep], r[keep], size[keep]
                    if len(zi) == 0:
                        break
            last[moving] = size
            H = _hessian_points(system, x, eps) / g[None, :, None, None]
            D = np.zeros((len(zi), n + k + 1, n + k))
            D[:, :k, :n] = J
            D[:, k : k + n, :n] = np.einsum("mk,mkab->mab", u, H)
            D[:, k : k + n, n:] = np.transpose(J, (0, 2, 1))
            D[:, -1, n:] = 2.0 * u
            good = np.isfinite(r).all(axis=1) & np.isfinite(D).all(axis=(1, 2))
            step = np.zeros_like(zi)
            if good.any():
                Dg = D[good]
                Dt = np.transpose(Dg, (0, 2, 1))
                normal = Dt @ Dg
                normal += 1e-14 * np.trace(normal, axis1=1, axis2=2)[:, None, None] * np.eye(n + k)
                step[good] = np.linalg.solve(normal, (Dt @ r[good][:, :, None]))[:, :, 0]
            z[moving] = zi - step
            idx = np.flatnonzero(moving)
            # a solve stops where its step is below 1e-10 of the box (met to rounding, or stalled at
            # the residual's minimum away from M's critical points), or where F is not finite
            moving[idx[~good | (np.abs(step[:, :n]).max(axis=1) <= 1e-10 * diameter)]] = False
        x, u = z[:, :n], z[:, n:]
        F = system.evaluate_points(x) / g
        J = system.jacobian_points(x) / g[None, :, None]
        met = (np.abs(F).max(axis=1) <= _TOL_F * diameter) & \
            (np.linalg.norm(np.einsum("mkn,mk->mn", J, u), axis=1) <= _TOL_J * np.linalg.norm(u, axis=1))
        inside = ((x >= bounds[:, 0]) & (x <= bounds[:, 1])).all(axis=1)
    found: list = []
    merge = 0.01 * (bounds[:, 1] - bounds[:, 0]) / np.asarray(div, np.float64)
    for i in np.flatnonzero(met & inside):
        if any((np.abs(x[i] - p) <= merge).all() for p, _ in found):
            continue
        s = np.linalg.svd(J[i], compute_uv=False)  # (rows over their typical gradient: ~1 where regular)
        found.append((x[i], int(np.count_nonzero(s > _RANK_RCOND))))
    return [{"x": [float(v) for v in p], "rank": rank} for p, rank in found]
