"""The interval enclosure (gcmh_core.interval) holds every value F's evaluator computes.

Random boxes, from wide to a few ulp across, many of them across poles and branch
points; the samples are the boxes' corners and random points inside, evaluated by
System.evaluate_points (the very code the sweep uses), so rounding is included.
"""

import math
import zlib

import numpy as np
import pytest
import sympy

from gcmh_core.formula import parse_system
from gcmh_core.interval import Enclosure

# every function and power form the parser accepts, alone and inside sums and products
FORMULAS = [
    "sin(x)", "cos(x)", "tan(x)", "asin(x)", "acos(x)", "atan(x)", "atan2(y, x)",
    "sinh(x)", "cosh(x)", "tanh(x)", "exp(x)", "log(x)", "sqrt(x)", "abs(x)",
    "min(x, y)", "max(x, y, x*y)", "min(x, y, 1, -y)",
    "x^2", "x^3", "x^4", "x^-1", "x^-2", "x^-3", "1/x", "x/y", "y/(x^2 - 1)",
    "x^(1/3)", "x^(2/3)", "x^(-1/2)", "x^2.5", "x^-2.5", "x^y", "2^x", "(1/2)^y",
    "e^x", "pi*x - 1", "x*y - y^2/3 + 1", "(x + y)^2 - x^2 - 2*x*y - y^2",
    "sin(x)*exp(y) - log(1 + x^2) + sqrt(abs(y))*cos(x*y)",
    "tan(x*y) + 1/sin(x)", "log(x*y) - asin(y/4)", "sqrt(x - y) * acos(x/5)", "cosh(x)/sinh(y)",
    "x^64 - y^64", "exp(x^3)", "sin(1e6*x)", "cos(x + 1e7)", "tanh(1/x)", "atan2(sin(x), cos(y))",
]


def _boxes(rng, m, center_scale=4.0):
    """m boxes in R^2: centres spread wide, widths from a few ulp to several units, and
    corners put exactly on 0, pi/2 multiples and 1 now and then."""
    c = rng.uniform(-center_scale, center_scale, (m, 2))
    w = 10.0 ** rng.uniform(-15, 0.7, (m, 2))
    lo, hi = c - w * rng.uniform(0, 1, (m, 2)), c + w * rng.uniform(0, 1, (m, 2))
    special = np.array([0.0, -0.0, 1.0, -1.0, math.pi / 2, -math.pi / 2, math.pi])
    pick = rng.uniform(size=(m, 2)) < 0.15
    lo = np.where(pick, special[rng.integers(0, len(special), (m, 2))], lo)
    hi = np.maximum(hi, lo)
    return lo, hi


def _samples(rng, lo, hi, per_box):
    """The 4 corners and per_box random points of each box: (m, 4 + per_box, 2)."""
    m = len(lo)
    corners = np.stack([np.stack([np.where(c >> a & 1, hi[:, a], lo[:, a]) for a in range(2)], 1)
                        for c in range(4)], 1)
    inside = lo[:, None] + (hi - lo)[:, None] * rng.uniform(0, 1, (m, per_box, 2))
    return np.concatenate([corners, inside], axis=1)


def _check(enclosure, evaluate, lo, hi, pts):
    L, H, ok = enclosure.bound(lo, hi)
    m, s, n = pts.shape
    V = evaluate(pts.reshape(-1, n)).reshape(m, s, -1)
    for j in range(V.shape[-1]):
        v, good = V[:, :, j], ok[:, j]
        assert np.isfinite(v[good]).all(), "ok claims finite values but the evaluator gave nan/inf"
        inside = (L[good, j, None] <= v[good]) & (v[good] <= H[good, j, None])
        assert inside.all(), f"component {j}: a value escapes its enclosure"
    return ok


@pytest.mark.parametrize("text", FORMULAS)
def test_enclosure_holds_every_sampled_value(text):
    system = parse_system([text], ["x", "y"])
    enclosure = Enclosure(system.exprs, system.symbols)
    rng = np.random.default_rng(zlib.crc32(text.encode()))
    lo, hi = _boxes(rng, 3000)
    ok = _check(enclosure, system.evaluate_points, lo, hi, _samples(rng, lo, hi, 12))
    assert ok.any(), "no box was bounded at all (the test would prove nothing)"


@pytest.mark.parametrize("text", ["sin(x)*y", "abs(x) - y", "max(x, y^2)", "min(x*y, sqrt(x))", "x^3 - tan(y)"])
def test_enclosure_of_derivatives(text):
    """sign and Heaviside only appear in derivatives (of abs, max, min): bound the Jacobian."""
    system = parse_system([text], ["x", "y"])
    exprs = [sympy.diff(e, s) for e in system.exprs for s in system.symbols]
    enclosure = Enclosure(exprs, system.symbols)
    rng = np.random.default_rng(7)
    lo, hi = _boxes(rng, 2000)
    ok = _check(enclosure, lambda P: system.jacobian_points(P).reshape(len(P), -1), lo, hi, _samples(rng, lo, hi, 8))
    assert ok.any()


def test_periodic_functions_far_out():
    for text in ["sin(x)", "cos(x)", "tan(x)", "sin(x)*cos(y)"]:
        system = parse_system([text], ["x", "y"])
        enclosure = Enclosure(system.exprs, system.symbols)
        rng = np.random.default_rng(3)
        lo, hi = _boxes(rng, 2000, center_scale=1e7)
        _check(enclosure, system.evaluate_points, lo, hi, _samples(rng, lo, hi, 8))


def _one(text, lo, hi):
    system = parse_system([text], ["x"])
    L, H, ok = Enclosure(system.exprs, system.symbols).bound(np.array([[lo]]), np.array([[hi]]))
    return float(L[0, 0]), float(H[0, 0]), bool(ok[0, 0])


def test_poles_and_branch_points_give_no_claim():
    assert not _one("log(x)", 0.0, 1.0)[2]
    assert not _one("log(x)", -1.0, -0.5)[2]
    assert _one("log(x)", 1e-300, 1.0)[2]
    assert not _one("sqrt(x)", -1e-300, 1.0)[2]
    assert _one("sqrt(x)", 0.0, 1.0)[2] and _one("sqrt(x)", -0.0, 1.0)[2]
    assert not _one("1/x", -1.0, 1.0)[2] and not _one("1/x", 0.0, 1.0)[2]
    assert not _one("x^-2", -1e-3, 1e-3)[2]
    assert not _one("tan(x)", 1.5, 1.6)[2]
    assert not _one("tan(x)", 1.5 + 3 * math.pi, 1.6 + 3 * math.pi)[2]
    assert _one("tan(x)", -1.5, 1.5)[2]
    assert not _one("asin(x)", 0.5, 1.0000001)[2] and _one("acos(x)", -1.0, 1.0)[2]
    assert not _one("x^(1/3)", -1.0, 1.0)[2] and _one("x^3", -1.0, 1.0)[2]
    assert not _one("exp(x)", 700.0, 710.0)[2]  # overflows
    assert not _one("x^64", 1e5, 1e6)[2]
    assert not _one("(-2)^x", 0.0, 1.0)[2]  # nan but at integer x


def test_enclosures_are_tight_where_nothing_happens():
    for text, lo, hi, want in [("sin(x)", 0.1, 0.2, (math.sin(0.1), math.sin(0.2))),
                               ("sin(x)", 1.0, 2.0, (math.sin(1.0), 1.0)),
                               ("cos(x)", 3.0, 3.5, (-1.0, math.cos(3.5))),
                               ("x^2 - 1", -0.5, 0.25, (-1.0, -0.75)),
                               ("atan2(x, 1)", -1.0, 1.0, (-math.pi / 4, math.pi / 4)),
                               ("cosh(x)", -1.0, 0.5, (1.0, math.cosh(1.0)))]:
        L, H, ok = _one(text, lo, hi)
        assert ok and L <= want[0] and H >= want[1]
        assert want[0] - L < 1e-12 and H - want[1] < 1e-12


def test_unknown_functions_fall_back_to_no_claim():
    x = sympy.Symbol("x", real=True)
    L, H, ok = Enclosure([sympy.gamma(x), sympy.floor(x) + 1], (x,)).bound(np.array([[0.5]]), np.array([[0.6]]))
    assert not ok.any() and np.all(L == -np.inf) and np.all(H == np.inf)
