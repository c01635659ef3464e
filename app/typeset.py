"""Formulas typeset for the view: formula text -> LaTeX (sympy) -> an RGBA image (matplotlib's mathtext).

No Qt and no TeX installation: the text is parsed by :mod:`gcmh_core.formula` (an
ast whitelist, never evaluated by Python), printed with ``sympy.latex`` and drawn
with matplotlib's own mathtext engine into a numpy image, which the presentation
mode (:mod:`app.qt_presentation`) puts inside the render window.

Equations are written as on a blackboard: a component ``F_i`` is shown as
``lhs = rhs`` with the terms free of variables moved to the right
(``x^2 + y^2 - z^2 - a`` -> x^2 + y^2 - z^2 = a), a variable that appears once
and alone as a graph (``... - x`` -> x = ...), else the negative terms on the
right; an example written over C shows its complex equations
(``z = cos(w)``) and how the real variables name them (w = u + i v).

Failing soft: a formula that cannot be parsed or typeset becomes a line of plain
text (its own text, ``= 0``), never an exception.

>>> lines = system_lines(["x^2 + y^2 - z^2 - a"], ["x", "y", "z"], {"a": 0.3})
>>> [line.text for line in lines]
['x^{2} + y^{2} - z^{2} = a', 'a = 0.30']
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import sympy
from sympy.printing.latex import LatexPrinter

from gcmh_core.formula import find_parameters, parse_system

__all__ = ["Line", "equation_latex", "complex_equation_latex", "params_latex", "system_lines",
           "render_lines", "typeset_system"]

DPI = 100                     # font sizes are given in pixels; points = pixels * 72 / DPI
TEXT_COLOR = "#f4f6fb"
PANEL_COLOR = (0.05, 0.06, 0.09, 0.72)   # a dark, translucent card behind the text (legible on any surface)
MATH_FONT = "cm"              # Computer Modern: what the blackboard's LaTeX looks like


@dataclass(frozen=True)
class Line:
    """One line of the typeset card: LaTeX (``math``) or plain text."""

    text: str
    math: bool = True


# ---------------------------------------------------------------------------- LaTeX
class _Latex(LatexPrinter):
    """sympy's LaTeX with the terms of a sum in reading order: positive terms first, numbers last
    (sympy's own order starts ``- a + x^{2}``)."""

    def _print_Add(self, expr, order=None):
        terms = sorted(self._as_ordered_terms(expr, order=order),
                       key=lambda t: (bool(t.is_number), bool(t.could_extract_minus_sign())))
        tex = ""
        for i, term in enumerate(terms):
            if i:
                if term.could_extract_minus_sign():
                    tex += " - "
                    term = -term
                else:
                    tex += " + "
            piece = self._print(term)
            if self._needs_add_brackets(term):
                piece = rf"\left({piece}\right)"
            tex += piece
        return tex


_PRINTER = _Latex({"fold_func_brackets": True, "full_prec": False})
# mathtext sets "\\sin t \\cos s" as "sin tcos s" (TeX spaces operators): a thin space after a factor
_OPERATOR_SPACE = re.compile(r"(?<=[\w})])\s+\\(?=(?:a?sin|a?cos|a?tan|sinh|cosh|tanh|log|exp|max|min|operatorname)\b)")


def _latex(expr: sympy.Expr) -> str:
    # the parser's pairwise max/min (kept unevaluated for speed) print as \max and \min
    expr = expr.replace(lambda e: type(e).__name__ in ("_Max2", "_Min2"),
                        lambda e: (sympy.Max if type(e).__name__ == "_Max2" else sympy.Min)(*e.args, evaluate=False))
    return _OPERATOR_SPACE.sub(r"\\,\\", _PRINTER.doprint(expr))


def _sides(expr: sympy.Expr, variables: set) -> tuple[sympy.Expr, sympy.Expr]:
    """``expr = 0`` as (lhs, rhs), the way it is written on a blackboard (see the module docstring)."""
    if not expr.is_Add:
        return expr, sympy.Integer(0)
    terms = list(expr.args)
    # a graph: one variable alone, with coefficient +-1, that appears nowhere else
    for t in terms:
        v = -t if t.could_extract_minus_sign() else t
        if v in variables and not any(v in u.free_symbols for u in terms if u is not t):
            rest = expr - t
            return v, (rest if t.could_extract_minus_sign() else -rest)
    free = [t for t in terms if not (t.free_symbols & variables)]
    bound = [t for t in terms if t.free_symbols & variables]
    if free and bound:                       # the constants (and parameters) on the right
        return sympy.Add(*bound), -sympy.Add(*free)
    neg = [t for t in bound if t.could_extract_minus_sign()]
    if neg and len(neg) < len(bound):        # the negative terms on the right, both sides positive
        return sympy.Add(*[t for t in bound if t not in neg]), -sympy.Add(*neg)
    return expr, sympy.Integer(0)


def equation_latex(text: str, variables: Sequence[str], parameters: Sequence[str] | None = None) -> str:
    """LaTeX of the equation ``text = 0`` over ``variables``; free names are parameters (shown as symbols).

    Raises :class:`gcmh_core.formula.FormulaError` when the text is not a formula.
    """
    variables = list(variables)
    if parameters is None:
        parameters = find_parameters([text], variables)
    system = parse_system([text], variables + [p for p in parameters if p not in variables])
    symbols = {sympy.Symbol(v, real=True) for v in variables}
    lhs, rhs = _sides(system.exprs[0], symbols)
    return f"{_latex(lhs)} = {_latex(rhs)}"


def complex_equation_latex(text: str, complex_variables: Sequence[str], parameters: Sequence[str] | None = None) -> str:
    """LaTeX of an equation over C, ``lhs = rhs`` (or ``expr``, meaning = 0), ``i`` the imaginary unit.

    Each side is read by the same parser as every formula, the complex variables (and ``i``) as symbols.
    Raises :class:`gcmh_core.formula.FormulaError` when the text is not an equation.
    """
    names = list(complex_variables)
    if "i" not in names:
        names.append("i")
    sides = text.split("=")
    if len(sides) > 2 or "==" in text:
        from gcmh_core.formula import FormulaError

        raise FormulaError("an equation has one '=' (lhs = rhs)")
    if parameters is None:
        parameters = find_parameters(sides, names)
    names += [p for p in parameters if p not in names]
    exprs = parse_system(sides, names).exprs
    rhs = exprs[1] if len(exprs) == 2 else sympy.Integer(0)
    return f"{_latex(exprs[0])} = {_latex(rhs)}"


def _number(value: float) -> str:
    """0.30, -1.00, 2.5 \\times 10^{-4}: two decimals, as a slider shows them; tiny and huge in powers of ten."""
    v = float(value)
    if not math.isfinite(v) or v == 0 or 1e-2 <= abs(v) < 1e4:
        return f"{v:.2f}"
    mantissa, exponent = f"{v:.2e}".split("e")
    return rf"{float(mantissa):g} \times 10^{{{int(exponent)}}}"


def params_latex(params: Mapping[str, float]) -> str:
    r"""``a = 0.30,\; b = 0.79``: the parameters' values, names typeset as symbols (``theta`` -> \theta)."""
    parts = []
    for name, value in params.items():
        parts.append(f"{_latex(sympy.Symbol(name))} = {_number(value)}")
    return r",\quad ".join(parts)


def _naming(complex_variables: Sequence[str], real_variables: Sequence[str]) -> str:
    """``w = u + i v,\\; z = x + i y``: which real variables a complex one is made of."""
    parts = []
    for j, w in enumerate(complex_variables):
        re_, im_ = (_latex(sympy.Symbol(s)) for s in real_variables[2 * j: 2 * j + 2])
        parts.append(f"{_latex(sympy.Symbol(w))} = {re_} + i\\,{im_}")
    return r",\quad ".join(parts)


def _split_matches(formulas, variables, complex_equations, complex_variables) -> bool:
    """The formulas begin with the real and imaginary parts of the complex equations (not edited since)."""
    from gcmh_core.complex_equations import split_complex

    try:
        texts, reals, _ = split_complex(list(complex_equations), list(complex_variables),
                                        list(variables)[: 2 * len(complex_variables)], allow_parameters=True)
    except Exception:  # noqa: BLE001 - an equation the split refuses: the real formulas are shown
        return False
    same = [" ".join(str(f).split()) for f in formulas[: len(texts)]] == [" ".join(t.split()) for t in texts]
    return same and list(variables)[: len(reals)] == reals


def system_lines(formulas: Sequence[str], variables: Sequence[str], params: Mapping[str, float] | None = None,
                 complex_equations: Sequence[str] | None = None,
                 complex_variables: Sequence[str] | None = None) -> list[Line]:
    """The lines of the card for a system: one equation per line, then the parameters' values.

    ``complex_equations`` / ``complex_variables``: the equations over C the formulas were split from
    (an example's ``complex``); shown instead of their real and imaginary parts while the formulas
    are still those parts, with a line naming the real variables. A formula that cannot be typeset
    is a plain-text line.
    """
    formulas = [str(f) for f in formulas]
    variables = [str(v) for v in variables]
    params = dict(params or {})
    try:
        parameters = find_parameters(formulas, variables)
    except Exception:  # noqa: BLE001 - each formula says for itself below
        parameters = list(params)
    lines: list[Line] = []
    ceqs = [str(e) for e in complex_equations or ()]
    cvars = [str(v) for v in complex_variables or ()]
    over_c = bool(ceqs and cvars and _split_matches(formulas, variables, ceqs, cvars))
    rest = formulas
    if over_c:
        for eq in ceqs:
            lines.append(_line(lambda eq=eq: complex_equation_latex(eq, cvars, parameters), eq))
        rest = formulas[2 * len(ceqs):]
    for f in rest:
        lines.append(_line(lambda f=f: equation_latex(f, variables, parameters), f"{f} = 0"))
    if over_c:
        lines.append(_line(lambda: _naming(cvars, variables), ""))
    if params:
        lines.append(_line(lambda: params_latex(params),
                           ",  ".join(f"{p} = {v:g}" for p, v in params.items())))
    return [line for line in lines if line.text]


def _line(make, plain: str) -> Line:
    try:
        return Line(make(), True)
    except Exception:  # noqa: BLE001 - shown as written instead
        return Line(" ".join(plain.split()), False)


# ---------------------------------------------------------------------------- images
def _text_artist(fig, line: Line, font_px: float, color):
    if line.math:
        return fig.text(0, 0, f"${line.text}$", fontsize=font_px * 72 / DPI, color=color,
                        math_fontfamily=MATH_FONT, ha="left", va="bottom")
    return fig.text(0, 0, line.text, fontsize=0.85 * font_px * 72 / DPI, color=color, parse_math=False,
                    family="DejaVu Sans Mono", ha="left", va="bottom")


def render_lines(lines: Sequence[Line], font_px: float = 28.0, color=TEXT_COLOR, background=PANEL_COLOR,
                 pad: float | None = None) -> np.ndarray | None:
    """The lines drawn one under the other on a translucent card: an (h, w, 4) uint8 RGBA image (None
    when there is nothing to draw). A math line mathtext cannot draw is drawn as plain text."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    font_px = max(6.0, float(font_px))
    pad = 0.5 * font_px if pad is None else float(pad)
    gap = 0.35 * font_px
    fig = Figure(figsize=(1, 1), dpi=DPI)
    canvas = FigureCanvasAgg(fig)
    renderer = canvas.get_renderer()
    placed = []
    for line in lines:
        if not line.text:
            continue
        artist = _text_artist(fig, line, font_px, color)
        try:
            box = artist.get_window_extent(renderer)
        except Exception:  # noqa: BLE001 - mathtext refused it: the plain text instead
            artist.remove()
            line = Line(line.text, False)
            artist = _text_artist(fig, line, font_px, color)
            try:
                box = artist.get_window_extent(renderer)
            except Exception:  # noqa: BLE001
                artist.remove()
                continue
        placed.append((artist, box.width, box.height))
    if not placed:
        return None
    width = int(math.ceil(max(w for _, w, _ in placed) + 2 * pad))
    height = int(math.ceil(sum(h for _, _, h in placed) + gap * (len(placed) - 1) + 2 * pad))
    fig.set_size_inches(width / DPI, height / DPI)
    fig.patch.set_facecolor(background)
    y = height - pad
    for artist, _w, h in placed:          # top to bottom, in figure fractions
        y -= h
        artist.set_position((pad / width, y / height))
        y -= gap
    canvas.draw()
    return np.array(canvas.buffer_rgba(), dtype=np.uint8)


def typeset_system(formulas: Sequence[str], variables: Sequence[str], params: Mapping[str, float] | None = None,
                   complex_equations: Sequence[str] | None = None, complex_variables: Sequence[str] | None = None,
                   font_px: float = 28.0,
                   max_size: tuple[int, int] | None = None) -> tuple[np.ndarray | None, list[Line]]:
    """The card of a system (:func:`system_lines` drawn by :func:`render_lines`): (RGBA image or None, lines).

    ``max_size`` (w, h) pixels: the font shrinks (down to 10 px) until the card fits.
    """
    lines = system_lines(formulas, variables, params, complex_equations, complex_variables)
    image = render_lines(lines, font_px)
    for _ in range(3):   # the size is nearly proportional to the font: one step, rarely two
        if image is None or max_size is None or font_px <= 10.0:
            break
        h, w = image.shape[:2]
        scale = min(max_size[0] / w, max_size[1] / h)
        if scale >= 1.0:
            break
        font_px = max(10.0, font_px * scale * 0.98)
        image = render_lines(lines, font_px)
    return image, lines
