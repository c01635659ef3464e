"""Rigorous interval enclosures of F over axis-aligned boxes (the pruned sweep's bound).

`Enclosure(system.exprs, system.symbols).bound(lo, hi)` takes m boxes at once
(corners lo, hi of shape (m, n)) and returns, per box and component, an interval
[L, H] and a flag ok.  ok means: at every point of the box, the value of that
component *as formula.System evaluates it in float64* is finite and lies in
[L, H].  Where ok is False nothing is claimed (a pole, a branch point, a value
that may overflow, or a function this module does not know: the safe fallback).

Why it holds for the computed values, not only for the exact ones: each node's
interval contains the value the evaluator computes for that node (induction over
the tree).  Variables are the exact grid coordinates.  For a node, the exact
result of its operation on any values of its children's intervals lies in the
interval computed from the endpoints (monotonicity, or the critical points
included); the endpoints themselves are computed in float64, and the evaluator's
result at a point differs from the exact operation on its (computed) operands by
its own rounding.  Both errors are relative to the magnitude of the result:
+ - * / and sqrt are correctly rounded (1/2 ulp); numpy's sin, exp, log, pow, ...
are not, but stay within 4 ulp (numpy's accuracy tests; 1 ulp <= 2 u |value|); the
evaluator sums and multiplies in an order of its own (cse and smallest-support-first),
whose error is at most (m-1) u times the sum of the terms' magnitudes (u = 2^-53).
So every bound is widened outward by a multiple of u that covers both errors with a
margin of 2 or more (32 u of the larger end for one function call: 4 ulp at the end
plus 4 ulp at the point are 16 u at most; 4 (m+1) u times the sum of magnitudes for a
sum of m terms), plus
2^-1000 against underflow, whose errors are absolute.  The widening subtraction
rounds too, by at most 1/2 ulp, which the margin covers.
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["Enclosure"]

_U = 2.0**-53  # unit roundoff of float64
_TINY = 2.0**-1000  # absolute pad: subnormal results carry absolute, not relative, errors
_FN = 32.0  # pad of one function call or power, in units of u times the result's magnitude
_PERIODIC_MAX = 1e6  # beyond this |x|, sin/cos bound [-1, 1] and tan gives up
_SLACK = 1e-8  # a critical point this close to the box (in periods) counts as inside
_TWO_PI = 2.0 * math.pi


def _widen(lo, hi, ok, rel):
    """Outward by rel u times the magnitude (+ _TINY); ok only where both bounds are finite."""
    mag = np.maximum(np.abs(lo), np.abs(hi))
    pad = rel * _U * mag + _TINY
    lo = lo - pad
    hi = hi + pad
    ok = ok & np.isfinite(lo) & np.isfinite(hi)
    return np.where(ok, lo, -np.inf), np.where(ok, hi, np.inf), ok


def _const(value):
    v = np.float64(value)
    if np.isfinite(v):
        return v, v, np.True_
    return np.float64(-np.inf), np.float64(np.inf), np.False_


_NOTHING = _const(np.nan)  # what is not bounded: [-inf, inf], not ok


def _hits(lo, hi, c, period):
    """May some c + j period (j integer) lie in [lo, hi]?  Errs towards yes (_SLACK)."""
    return np.ceil((lo - c) / period - _SLACK) <= np.floor((hi - c) / period + _SLACK)


def _mul(a, b):
    """[a] * [b]: extremes among the four endpoint products."""
    (alo, ahi, aok), (blo, bhi, bok) = a, b
    p = (alo * blo, alo * bhi, ahi * blo, ahi * bhi)
    lo = np.minimum(np.minimum(p[0], p[1]), np.minimum(p[2], p[3]))
    hi = np.maximum(np.maximum(p[0], p[1]), np.maximum(p[2], p[3]))
    return _widen(lo, hi, aok & bok, 4.0)


def _reciprocal(a):
    lo, hi, ok = a
    ok = ok & ((lo > 0) | (hi < 0))  # 1/x across 0: a pole
    return _widen(1.0 / hi, 1.0 / lo, ok, 4.0)


def _monotone(fn, a, increasing=True, domain=None):
    """fn over [lo, hi] for a monotone fn; domain(lo, hi) -> bool array where it is defined."""
    lo, hi, ok = a
    if domain is not None:
        ok = ok & domain(lo, hi)
    flo, fhi = fn(lo), fn(hi)
    return _widen(flo, fhi, ok, _FN) if increasing else _widen(fhi, flo, ok, _FN)


def _sin_cos(fn, peak, trough):
    def bound(a):
        lo, hi, ok = a
        flo, fhi = fn(lo), fn(hi)
        far = ~((np.abs(lo) <= _PERIODIC_MAX) & (np.abs(hi) <= _PERIODIC_MAX) & (hi - lo < _TWO_PI))
        top = np.where(far | _hits(lo, hi, peak, _TWO_PI), 1.0, np.maximum(flo, fhi))
        bottom = np.where(far | _hits(lo, hi, trough, _TWO_PI), -1.0, np.minimum(flo, fhi))
        return _widen(bottom, top, ok, _FN)
    return bound


def _tan(a):
    lo, hi, ok = a
    ok = ok & (np.abs(lo) <= _PERIODIC_MAX) & (np.abs(hi) <= _PERIODIC_MAX) & (hi - lo < math.pi)
    ok = ok & ~_hits(lo, hi, math.pi / 2, math.pi)  # a pole pi/2 + j pi in the box
    return _widen(np.tan(lo), np.tan(hi), ok, _FN)


def _cosh(a):
    lo, hi, ok = a
    top = np.maximum(np.cosh(lo), np.cosh(hi))
    bottom = np.where((lo <= 0) & (hi >= 0), 1.0, np.minimum(np.cosh(lo), np.cosh(hi)))
    return _widen(bottom, top, ok, _FN)


def _abs(a):
    lo, hi, ok = a
    top = np.maximum(np.abs(lo), np.abs(hi))
    bottom = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    return bottom, top, ok  # exact: no rounding


def _atan2(y, x):
    """atan2(y, x): continuous off the cut (x <= 0, y = 0), where the angle jumps by 2 pi;
    over a box clear of the cut the extremes are at its corners (the box's angular hull)."""
    (ylo, yhi, yok), (xlo, xhi, xok) = y, x
    c = (np.arctan2(ylo, xlo), np.arctan2(ylo, xhi), np.arctan2(yhi, xlo), np.arctan2(yhi, xhi))
    cut = (ylo <= 0) & (yhi >= 0) & (xlo <= 0)
    lo = np.where(cut, -math.pi, np.minimum(np.minimum(c[0], c[1]), np.minimum(c[2], c[3])))
    hi = np.where(cut, math.pi, np.maximum(np.maximum(c[0], c[1]), np.maximum(c[2], c[3])))
    return _widen(lo, hi, yok & xok, _FN)


def _pairwise(fn):
    def bound(a, b):
        return fn(a[0], b[0]), fn(a[1], b[1]), a[2] & b[2]  # exact
    return bound


def _sign(a):
    return np.sign(a[0]), np.sign(a[1]), a[2]


def _heaviside(a, h0=None):
    """np.heaviside(x, h0) (h0 = 1/2 by default): 0 below 0, h0 at 0, 1 above."""
    lo, hi, ok = a
    h0lo, h0hi, h0ok = (0.5, 0.5, True) if h0 is None else h0
    at0 = (lo <= 0) & (hi >= 0)
    bottom = np.minimum(np.where(lo < 0, 0.0, np.inf), np.where(at0, h0lo, np.inf))
    bottom = np.minimum(bottom, np.where(hi > 0, 1.0, np.inf))
    top = np.maximum(np.where(lo < 0, 0.0, -np.inf), np.where(at0, h0hi, -np.inf))
    top = np.maximum(top, np.where(hi > 0, 1.0, -np.inf))
    return _widen(bottom, top, ok & h0ok, 0.0)


def _power_const(a, c):
    """b^c for a float exponent c, as np.power (or square/sqrt/reciprocal) computes it."""
    lo, hi, ok = a
    if not math.isfinite(c):
        return _NOTHING
    if c == 0:
        return _widen(np.ones_like(lo), np.ones_like(hi), ok, 0.0)
    if c.is_integer():
        even = int(c) % 2 == 0
        if c < 0:  # across 0: a pole
            ok = ok & ((lo > 0) | (hi < 0))
        if even:  # b^c = |b|^c: the extremes at |b|'s ends (0 in the box gives 0, c > 0)
            alo, ahi, _ = _abs((lo, hi, ok))
            plo, phi = np.power(alo, c), np.power(ahi, c)
        else:
            plo, phi = np.power(lo, c), np.power(hi, c)
    else:  # a fractional power of a negative number is nan, of 0 with c < 0 inf
        ok = ok & ((lo >= 0) if c > 0 else (lo > 0))
        plo, phi = np.power(lo, c), np.power(hi, c)
    # monotone on each side of 0: the extremes are among the ends' images
    return _widen(np.minimum(plo, phi), np.maximum(plo, phi), ok, _FN)


def _power(b, q):
    """b^q, q not constant: defined for b > 0, where it is monotone in b and in q
    (so its extremes over a box are at the four corners)."""
    (blo, bhi, bok), (qlo, qhi, qok) = b, q
    c = (np.power(blo, qlo), np.power(blo, qhi), np.power(bhi, qlo), np.power(bhi, qhi))
    lo = np.minimum(np.minimum(c[0], c[1]), np.minimum(c[2], c[3]))
    hi = np.maximum(np.maximum(c[0], c[1]), np.maximum(c[2], c[3]))
    return _widen(lo, hi, bok & qok & (blo > 0), _FN)


@functools.cache
def _tables():
    """(sympy function -> bound, its argument counts), built on first use: sympy is
    imported only when a formula is bounded (`import gcmh_core` loads no sympy)."""
    import sympy

    functions = {
        sympy.sin: _sin_cos(np.sin, math.pi / 2, -math.pi / 2),
        sympy.cos: _sin_cos(np.cos, 0.0, math.pi),
        sympy.tan: _tan,
        sympy.asin: lambda a: _monotone(np.arcsin, a, domain=lambda lo, hi: (lo >= -1) & (hi <= 1)),
        sympy.acos: lambda a: _monotone(np.arccos, a, False, domain=lambda lo, hi: (lo >= -1) & (hi <= 1)),
        sympy.atan: lambda a: _monotone(np.arctan, a),
        sympy.atan2: _atan2,
        sympy.sinh: lambda a: _monotone(np.sinh, a),
        sympy.cosh: _cosh,
        sympy.tanh: lambda a: _monotone(np.tanh, a),
        sympy.exp: lambda a: _monotone(np.exp, a),
        sympy.log: lambda a: _monotone(np.log, a, domain=lambda lo, hi: lo > 0),
        sympy.Abs: _abs,
        sympy.sign: _sign,
        sympy.Heaviside: _heaviside,
        sympy.Max: _pairwise(np.maximum),
        sympy.Min: _pairwise(np.minimum),
    }
    arity = {sympy.atan2: (2,), sympy.Heaviside: (1, 2), sympy.Max: (2,), sympy.Min: (2,)}
    return functions, arity


# formula's own two-argument max/min (kept as written); matched by name so that this
# module depends on System's public attributes only
_BY_NAME = {"_Max2": _pairwise(np.maximum), "_Min2": _pairwise(np.minimum)}


def _sum(*terms):
    """Sum in any order: pad by 4 (m+1) u times the sum of the terms' magnitudes."""
    lo = sum(t[0] for t in terms)
    hi = sum(t[1] for t in terms)
    mag = sum(np.maximum(np.abs(t[0]), np.abs(t[1])) for t in terms)
    ok = functools.reduce(np.logical_and, [t[2] for t in terms])
    pad = 4.0 * (len(terms) + 1) * _U * mag + _TINY
    lo, hi = lo - pad, hi + pad
    ok = ok & np.isfinite(lo) & np.isfinite(hi)
    return np.where(ok, lo, -np.inf), np.where(ok, hi, np.inf), ok


def _product(n_num, *factors):
    """The first n_num factors over the product of the others, in any order."""
    num, den = factors[:n_num], factors[n_num:]
    acc = num[0] if num else _const(1.0)
    for f in num[1:]:
        acc = _mul(acc, f)
    if den:
        d = den[0]
        for f in den[1:]:
            d = _mul(d, f)
        acc = _mul(acc, _reciprocal(d))
    return _widen(acc[0], acc[1], acc[2], 4.0 * len(factors) + 8.0)


class Enclosure:
    """Interval enclosures of the components `exprs` (sympy, over `symbols`) on boxes.

    Built once per system (the tree is walked once, shared subexpressions once);
    `bound` then runs a fixed list of vectorised steps over any number of boxes.
    """

    def __init__(self, exprs, symbols):
        self.n, self.k = len(symbols), len(exprs)
        self._slots: dict = {s: i for i, s in enumerate(symbols)}
        self._steps: list = []  # (function, argument slots), each writes the next slot
        self._outputs = [self._node(e) for e in exprs]

    def _emit(self, fn, args) -> int:
        self._steps.append((fn, tuple(args)))
        return self.n + len(self._steps) - 1

    def _node(self, expr) -> int:
        slot = self._slots.get(expr)
        if slot is not None:
            return slot
        slot = self._emit(*self._rule(expr))
        self._slots[expr] = slot
        return slot

    def _rule(self, expr):
        """(function of the argument triples, argument slots) for one node; mirrors the
        evaluator's reading of the tree (formula._compile) so that the induction holds."""
        import sympy  # (loaded already: expr is a sympy expression)

        if expr.is_Number or expr.is_NumberSymbol or expr in (sympy.I, sympy.zoo):
            try:
                value = float(expr)
            except (TypeError, ValueError):  # I, zoo: nan or inf in the evaluator
                value = math.nan
            c = _const(value)
            return (lambda: c), ()
        if expr.is_Add:
            return _sum, [self._node(a) for a in expr.args]
        if expr.is_Mul:  # a*b**-2 is a / b**2 in the evaluator
            num, den = [], []
            for a in expr.args:
                if a.is_Pow and a.exp.is_Number and a.exp < 0:
                    den.append(a.base ** -a.exp)
                else:
                    num.append(a)
            n_num = len(num)
            return (lambda *f: _product(n_num, *f)), [self._node(a) for a in num + den]
        if expr.is_Pow:
            base, p = expr.base, expr.exp
            if p.is_Number:
                try:
                    c = float(p)
                except (TypeError, ValueError):
                    return (lambda: _NOTHING), ()
                return (lambda b: _power_const(b, c)), [self._node(base)]
            return _power, [self._node(base), self._node(p)]
        functions, arities = _tables()
        fn, arity = functions.get(expr.func), arities.get(expr.func, (1,))
        if fn is None and type(expr).__name__ in _BY_NAME:
            fn, arity = _BY_NAME[type(expr).__name__], (2,)
        if fn is None or len(expr.args) not in arity:
            return (lambda: _NOTHING), ()  # unknown: no claim, the block is evaluated
        return fn, [self._node(a) for a in expr.args]

    def bound(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Enclosures over m boxes lo <= x <= hi (each (m, n) float64).

        Returns L, H (m, k) float64 and ok (m, k) bool: where ok, every value of the
        component that System.evaluate_* computes in the box is finite and in [L, H].
        """
        lo = np.asarray(lo, np.float64)
        hi = np.asarray(hi, np.float64)
        m = lo.shape[0]
        env: list = [(lo[:, a], hi[:, a], np.ones(m, bool)) for a in range(self.n)]
        with np.errstate(all="ignore"):
            for fn, args in self._steps:
                env.append(fn(*[env[i] for i in args]))
        L = np.empty((m, self.k))
        H = np.empty((m, self.k))
        ok = np.empty((m, self.k), bool)
        for j, slot in enumerate(self._outputs):
            L[:, j], H[:, j], ok[:, j] = env[slot]
        return L, H, ok

    def excludes_zero(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """(m,) bool: boxes where every component is surely finite and some component
        has one sign throughout (>= 0 everywhere, or < 0 everywhere: the candidate
        test's two signs), so no cube inside can cross M."""
        L, H, ok = self.bound(lo, hi)
        return np.asarray(ok.all(axis=1) & ((L >= 0) | (H < 0)).any(axis=1))
