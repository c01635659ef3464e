"""Equations over C^m as the real system the engine takes: ``z^2 = w`` -> two real formulas.

Each complex variable ``w`` becomes two real variables, ``w_re`` and ``w_im`` (shown
as "Re w" and "Im w"), and each equation ``lhs = rhs`` the two real components
Re(lhs - rhs) and Im(lhs - rhs), split exactly by sympy.  The text is read by the
same whitelisted ast walk as every formula (:mod:`gcmh_core.formula`; it is never
evaluated by Python), with the complex variables as complex symbols and ``i`` as
the imaginary unit.  The result is plain formula text over real variables, so the
engine, examples, sessions and the app take it unchanged.

Only holomorphic functions are accepted (sin, cos, tan, sinh, cosh, tanh, exp,
log, sqrt and powers; log and sqrt on their principal branch, so their real parts
jump across the negative real axis): then M is a complex variety and the real
system describes it exactly.  abs, min, max and atan2 are refused with a message:
a real condition such as |z|^2 + |w|^2 = 1 is written as a real formula over the
real variables (an example's ``formulas``, or ``--f`` beside ``--complex``).

>>> texts, variables, labels = split_complex(["z^2 = w"], "z, w")
>>> texts
['z_re**2 - z_im**2 - w_re', '2*z_im*z_re - w_im']
>>> variables, labels["w_im"]
(['z_re', 'z_im', 'w_re', 'w_im'], 'Im w')
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Sequence

import sympy
from sympy.printing.str import StrPrinter

from .formula import FormulaError, _Builder, _check_variables, _FreeNames, _parse_quietly, check_component

__all__ = ["split_complex", "complex_view", "real_names", "DEFAULT_BOUNDS"]

DEFAULT_BOUNDS = (-2.0, 2.0)  # on every real axis, when none are given

# Terms the split of one equation may come to (both parts): sympy's expansion of (z + w + 1)^64 runs for
# minutes, and a formula holds at most MAX_CHARS characters anyway ((z + w + 1)^8, 495 terms, is 6125 of them).
MAX_TERMS = 1000
_TERMS_CAP = 10**12   # (estimates are clipped here: no huge integers)

# not holomorphic (or real-only): the split would be exact, but M would not be a complex variety
_REFUSED = {"abs": "|z|", "min": "min", "max": "max", "atan2": "atan2", "conj": "conj",
            "conjugate": "conj", "re": "Re", "im": "Im", "Re": "Re", "Im": "Im", "arg": "arg"}


def real_names(variables: Sequence[str] | str, names: Sequence[str] | None = None) -> list[str]:
    """The 2m real variable names: given (checked), or ``w_re, w_im`` for each complex ``w``."""
    cvars = _check_variables(variables)
    if names is None:
        names = [f"{v}_{part}" for v in cvars for part in ("re", "im")]
    names = list(_check_variables(names))
    if len(names) != 2 * len(cvars):
        raise FormulaError(f"{len(cvars)} complex variables need {2 * len(cvars)} real names "
                           f"(Re and Im of each), got {len(names)}")
    clash = [v for v in cvars if v in names and names.index(v) // 2 != cvars.index(v)]
    if clash:
        raise FormulaError(f"real name {clash[0]!r} is also a complex variable")
    return names


class _Printer(StrPrinter):
    """Formula text the parser reads back to the same expression (floats in full)."""

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Abs(self, expr):
        return f"abs({self._print(expr.args[0])})"

    def _print_Exp1(self, expr):
        return "e"


def _order_in(equation: str, cvars: tuple, reals: list[str]) -> dict:
    """{real symbol: rank}: the complex variables in the order the equation first names
    them ("z = cos(w)": z, then w), Re before Im."""
    def first(v):
        found = re.search(rf"\b{re.escape(v)}\b", equation)
        return found.start() if found else len(equation)

    ranked = sorted(range(len(cvars)), key=lambda j: first(cvars[j]))
    return {sympy.Symbol(reals[2 * j + p], real=True): 2 * r + p for r, j in enumerate(ranked) for p in (0, 1)}


def _text(expr: sympy.Expr, order: dict) -> str:
    """expr as formula text, its terms in the order of the variables (z_re^2 before w_re),
    higher powers first; the text parses back to the same (canonical) expression."""
    printer = _Printer({"order": None})
    if not expr.is_Add:
        return printer.doprint(expr)

    def key(term):
        first = min((order[s] for s in term.free_symbols if s in order), default=len(order))
        if first == len(order):
            return (first, 0.0)
        power = term.as_coeff_exponent(sorted(order, key=order.__getitem__)[first])[1]
        return (first, -float(power) if power.is_number else 0.0)

    text = ""
    for i, term in enumerate(sorted(expr.args, key=key)):
        piece = printer.doprint(term)
        if i:
            piece = f" - {piece[1:]}" if piece.startswith("-") else f" + {piece}"
        text += piece
    return text


def _side(text: str, index: int, offset: int, cvars: tuple, symbols: dict, allow_parameters: bool) -> sympy.Expr:
    """One side of an equation (starting at column offset + 1) as a sympy expression over
    the complex symbols."""
    try:
        tree = _parse_quietly(text.strip().replace("^", "**"))
    except (SyntaxError, ValueError, RecursionError):
        tree = None  # the builder gives the precise message
    if tree is not None:
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _REFUSED:
                raise FormulaError(
                    f"{node.func.id}() is not holomorphic: complex mode takes holomorphic equations "
                    "(write a real condition such as |z|^2 = 1 as a real formula over the real "
                    "variables, e.g. z_re^2 + z_im^2 - 1)", index)
    try:
        return _Builder(text, index, cvars, symbols, _FreeNames() if allow_parameters else None).parse()
    except FormulaError as err:  # columns in the whole equation
        raise FormulaError(err.detail, index, None if err.position is None else err.position + offset) from None


def expansion_terms(expr: sympy.Expr, complex_symbols) -> int:
    """An upper bound on the terms of ``expr`` expanded over the real and imaginary parts of
    ``complex_symbols`` (each is x + i y: two terms), computed from the tree without expanding: a sum adds
    terms, a product multiplies them, a power p of t terms has C(t + p - 1, p), a function or a power that is
    not an integer counts as two (its real and imaginary parts) and its argument as itself; a polynomial of
    degree d in N real variables has at most C(N + d, d) monomials, whichever is smaller."""
    cplx = set(complex_symbols)
    reals = 2 * len(cplx) + len(expr.free_symbols - cplx)

    inner = [0]   # the largest argument of a function (expanded inside it)

    def clip(x):
        return min(int(x), _TERMS_CAP)

    def walk(e):   # (terms, degree or None if e is not a polynomial)
        if e.is_Symbol:
            return (2 if e in cplx else 1), 1
        if e.is_Number or e.is_NumberSymbol or e is sympy.I or not e.free_symbols:
            return 1, 0
        if e.is_Add or e.is_Mul:
            parts = [walk(a) for a in e.args]
            degs = [d for _, d in parts]
            terms = 0 if e.is_Add else 1
            for t, _ in parts:
                terms = clip(terms + t if e.is_Add else terms * t)
            deg: int | None = None
            if all(d is not None for d in degs):
                deg = max(degs) if e.is_Add else sum(degs)
            return terms, deg
        if e.is_Pow and e.exp.is_Integer:
            t, d = walk(e.base)
            p = abs(int(e.exp))
            terms = clip(math.comb(min(t, 10**6) + p - 1, p))
            if int(e.exp) < 0:   # conj(base)^p / |base|^(2p): the denominator expands too
                terms = clip(terms * math.comb(min(t * t, 10**6) + p - 1, p))
                return terms, None if d is None else 3 * p * d
            return terms, None if d is None else p * d
        for a in e.args:   # (a function's argument is expanded as well)
            t, d = walk(a)
            if d is not None:
                t = min(t, clip(math.comb(reals + min(d, 10**4), reals)))
            inner[0] = max(inner[0], t)
        return 2, None

    terms, degree = walk(expr)
    if degree is not None:
        terms = min(terms, clip(math.comb(reals + min(degree, 10**4), reals)))
    return max(terms, inner[0])


def _check_size(expr: sympy.Expr, csym: dict, index: int) -> None:
    """Refuse, before sympy expands it, an equation whose split would have more than MAX_TERMS terms."""
    terms = expansion_terms(expr, csym.values())
    if terms > MAX_TERMS:
        about = f"about {terms}" if terms < _TERMS_CAP else f"more than {_TERMS_CAP:.0e}"
        raise FormulaError(f"this equation expands to {about} terms over the real and imaginary parts "
                           f"(at most {MAX_TERMS}): expanding it would take minutes and the formula would be "
                           "too long; use a lower power, or write it over the real variables", index)


def split_complex(
    equations: Sequence[str] | str,
    variables: Sequence[str] | str,
    names: Sequence[str] | None = None,
    *,
    allow_parameters: bool = False,
) -> tuple[list[str], list[str], dict[str, str]]:
    """Split equations over the complex ``variables`` into real formula texts.

    ``equations``: texts ``lhs = rhs`` (or ``expr``, meaning expr = 0) in the complex
    variables, ``i`` the imaginary unit (unless it is a variable).  ``names``: the 2m
    real variable names, Re and Im of each complex variable in turn (default
    ``w_re, w_im, ...``).  ``allow_parameters``: other free names are real parameters,
    left in the texts (give their values to `extract`/`parse_system` as ``params``).

    Returns (texts, real variables, labels): two texts per equation, Re(lhs - rhs)
    then Im(lhs - rhs); the 2m names; {real name: "Re w" or "Im w"}.
    Raises FormulaError (component = the equation's index) with one clear message.
    """
    eqs = [equations] if isinstance(equations, str) else list(equations)
    if not eqs:
        raise FormulaError("no equations given")
    cvars = _check_variables(variables)
    reals = real_names(cvars, names)
    csym = {v: sympy.Symbol(v) for v in cvars}  # complex: no assumptions
    symbols = dict(csym)
    if "i" not in symbols:
        symbols["i"] = sympy.I
    parts = {v: sympy.Symbol(reals[2 * j], real=True) + sympy.I * sympy.Symbol(reals[2 * j + 1], real=True)
             for j, v in enumerate(cvars)}
    texts: list[str] = []
    for index, eq in enumerate(eqs):
        if not isinstance(eq, str):
            raise FormulaError(f"expected a string, got {type(eq).__name__}", index)
        if "==" in eq or eq.count("=") > 1:
            raise FormulaError("an equation has one '=' (lhs = rhs)", index)
        sides = eq.split("=")
        if any(not s.strip() for s in sides):
            raise FormulaError("empty side of '='", index)
        expr = _side(sides[0], index, 0, cvars, symbols, allow_parameters)
        if len(sides) == 2:
            expr = expr - _side(sides[1], index, len(sides[0]) + 1, cvars, symbols, allow_parameters)
        _check_size(expr, csym, index)
        expr = sympy.expand_complex(expr.xreplace({csym[v]: parts[v] for v in cvars}))
        # log gives arg(x + iy): atan2(y, x), which the parser knows
        expr = expr.replace(sympy.arg, lambda t: sympy.atan2(*reversed(t.as_real_imag())))
        for j, part in enumerate(expr.as_real_imag()):
            part = sympy.expand(part)
            what = "real" if j == 0 else "imaginary"
            if part.has(sympy.re, sympy.im, sympy.arg, sympy.I) or any(
                isinstance(a, sympy.Float) and not math.isfinite(float(a)) for a in part.atoms(sympy.Float)
            ):
                raise FormulaError(f"cannot split this equation exactly: sympy finds no closed form of "
                                   f"its {what} part ({part})", index)
            if part.is_zero:
                raise FormulaError(f"the {what} part of this equation is identically 0 "
                                   "(a real equation: write it as a real formula)", index)
            text = _text(part, _order_in(eq, cvars, reals))
            check_component(text, reals, len(texts), allow_parameters=allow_parameters)
            texts.append(text)
    labels = {reals[2 * j + p]: f"{'Im' if p else 'Re'} {v}" for j, v in enumerate(cvars) for p in (0, 1)}
    return texts, reals, labels


def complex_view(variables: Sequence[str] | str, names: Sequence[str] | None = None) -> dict:
    """The view of a graph-like complex curve or surface: the first complex variable's
    plane (Re, Im) and the real part of the second as height, coloured by its
    imaginary part.  Returns {"project": [3 real names], "color": real name}."""
    cvars = _check_variables(variables)
    reals = real_names(cvars, names)
    if len(cvars) < 2:
        raise FormulaError("a view of C^m needs at least two complex variables")
    return {"project": [reals[0], reals[1], reals[2]], "color": reals[3]}
