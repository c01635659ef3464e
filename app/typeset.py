"""Formulas typeset for the view: formula text -> LaTeX (sympy) -> an RGBA image (matplotlib's mathtext).

No Qt and no TeX installation: the text is parsed by :mod:`gcmh_core.formula` (an
ast whitelist, never evaluated by Python), printed with ``sympy.latex`` and drawn
with matplotlib's own mathtext engine into a numpy image, which the presentation
mode (:mod:`gcmh_studio.qt_presentation`) puts inside the render window.

Equations are written as on a blackboard: a component ``F_i`` is shown as
``lhs = rhs`` with the terms free of variables moved to the right
(``x^2 + y^2 - z^2 - a`` -> x^2 + y^2 - z^2 = a), a variable that appears once
and alone as a graph (``... - x`` -> x = ...), else the negative terms on the
right; the terms of a sum in the order the text names their symbols (``z^2 + w^3``,
not sympy's ``w^3 + z^2``); an example written over C shows its complex equations
(``z = cos(w)``) and how the real variables name them (w = u + i v).

Each line is drawn once per font size and kept: while a parameter moves, only its
own line (``a = 0.30``) is drawn again.

Failing soft: a formula that cannot be parsed or typeset becomes a line of plain
text (its own text, ``= 0``), never an exception.

>>> lines = system_lines(["x^2 + y^2 - z^2 - a"], ["x", "y", "z"], {"a": 0.3})
>>> [line.text for line in lines]
['x^{2} + y^{2} - z^{2} = a', 'a = 0.30']
"""

from __future__ import annotations

import functools
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
    """sympy's LaTeX with the terms of a sum in the order the text names their symbols (``z^2 + w^3`` as
    typed, where sympy writes ``w^{3} + z^{2}``), numbers last, and never a leading minus when a term is
    positive (sympy's own order starts ``- a + x^{2}``). ``positions``: {symbol name: where the text
    first names it}."""

    def __init__(self, positions: Mapping[str, int] | None = None):
        super().__init__({"fold_func_brackets": True, "full_prec": False})
        self.positions = dict(positions or {})

    def _first(self, term) -> int:
        return min((self.positions.get(s.name, len(self.positions) + 10**6) for s in term.free_symbols),
                   default=10**9)

    def _print_Add(self, expr, order=None):
        terms = sorted(self._as_ordered_terms(expr, order=order),
                       key=lambda t: (bool(t.is_number), self._first(t)))
        if terms[0].could_extract_minus_sign():
            first = next((t for t in terms if not t.could_extract_minus_sign()), None)
            if first is not None:
                terms.remove(first)
                terms.insert(0, first)
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


def _positions(text: str) -> dict[str, int]:
    """{name: where ``text`` first names it}, for :class:`_Latex`."""
    found: dict[str, int] = {}
    for m in re.finditer(r"[^\W\d]\w*", text):
        found.setdefault(m.group(), m.start())
    return found


# mathtext sets "\\sin t \\cos s" as "sin tcos s" (TeX spaces operators): a thin space after a factor
_OPERATOR_SPACE = re.compile(r"(?<=[\w})])\s+\\(?=(?:a?sin|a?cos|a?tan|sinh|cosh|tanh|log|exp|max|min|operatorname)\b)")


def _latex(expr: sympy.Expr, text: str = "") -> str:
    """LaTeX of ``expr``, its sums in the order ``text`` (the formula it was read from) names the symbols."""
    # the parser's pairwise max/min (kept unevaluated for speed) print as \max and \min
    expr = expr.replace(lambda e: type(e).__name__ in ("_Max2", "_Min2"),
                        lambda e: (sympy.Max if type(e).__name__ == "_Max2" else sympy.Min)(*e.args, evaluate=False))
    return _OPERATOR_SPACE.sub(r"\\,\\", _Latex(_positions(text)).doprint(expr))


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
    return f"{_latex(lhs, text)} = {_latex(rhs, text)}"


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
    return f"{_latex(exprs[0], text)} = {_latex(rhs, text)}"


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
    params = dict(params or {})
    lines = list(_equation_lines(tuple(str(f) for f in formulas), tuple(str(v) for v in variables),
                                 tuple(str(e) for e in complex_equations or ()),
                                 tuple(str(v) for v in complex_variables or ()), tuple(params)))
    if params:
        lines.append(_line(lambda: params_latex(params),
                           ",  ".join(f"{p} = {v:g}" for p, v in params.items())))
    return [line for line in lines if line.text]


@functools.lru_cache(maxsize=128)
def _equation_lines(formulas: tuple, variables: tuple, ceqs: tuple, cvars: tuple, given: tuple) -> tuple:
    """The equations' lines of :func:`system_lines` (cached: a moving parameter changes only its own line)."""
    try:
        parameters = find_parameters(formulas, variables)
    except Exception:  # noqa: BLE001 - each formula says for itself below
        parameters = list(given)
    lines: list[Line] = []
    over_c = bool(ceqs and cvars and _split_matches(formulas, variables, ceqs, cvars))
    rest = formulas
    if over_c:
        for eq in ceqs:
            lines.append(_line(lambda eq=eq: complex_equation_latex(eq, cvars, parameters), eq))
        rest = formulas[2 * len(ceqs):]
    for f in rest:
        lines.append(_line(lambda f=f: equation_latex(f, list(variables), parameters), f"{f} = 0"))
    if over_c:
        lines.append(_line(lambda: _naming(cvars, variables), ""))
    return tuple(lines)


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


@functools.lru_cache(maxsize=512)
def _line_image(text: str, math_line: bool, font_px: float, color) -> np.ndarray:
    """One line drawn tight on a transparent background, (h, w, 4) uint8 RGBA (cached: while a parameter
    moves, only its own line is drawn again). Raises when mathtext cannot draw it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(1, 1), dpi=DPI)
    canvas = FigureCanvasAgg(fig)
    artist = _text_artist(fig, Line(text, math_line), font_px, color)
    box = artist.get_window_extent(canvas.get_renderer())
    w, h = int(math.ceil(box.width)) + 2, int(math.ceil(box.height)) + 2
    fig.set_size_inches(w / DPI, h / DPI)
    fig.patch.set_alpha(0.0)
    artist.set_position((1.0 / w, 1.0 / h))
    canvas.draw()
    image = np.array(canvas.buffer_rgba(), dtype=np.uint8)
    image.setflags(write=False)
    return image


def render_lines(lines: Sequence[Line], font_px: float = 28.0, color=TEXT_COLOR, background=PANEL_COLOR,
                 pad: float | None = None) -> np.ndarray | None:
    """The lines drawn one under the other on a translucent card: an (h, w, 4) uint8 RGBA image (None
    when there is nothing to draw). A math line mathtext cannot draw is drawn as plain text."""
    from matplotlib.colors import to_rgba

    font_px = max(6.0, float(font_px))
    pad = int(round(0.5 * font_px if pad is None else float(pad)))
    gap = int(round(0.35 * font_px))
    color = to_rgba(color)
    images = []
    for line in lines:
        if not line.text:
            continue
        for math_line in ((True, False) if line.math else (False,)):
            try:
                images.append(_line_image(line.text, math_line, font_px, color))
                break
            except Exception:  # noqa: BLE001 - mathtext refused it: the plain text instead
                continue
    if not images:
        return None
    width = max(im.shape[1] for im in images) + 2 * pad
    height = sum(im.shape[0] for im in images) + gap * (len(images) - 1) + 2 * pad
    card = np.empty((height, width, 4), dtype=float)
    card[:] = to_rgba(background)
    y = pad
    for im in images:        # "over" compositing of straight-alpha images, top to bottom
        h, w = im.shape[:2]
        src = im.astype(float) / 255.0
        dst = card[y:y + h, pad:pad + w]
        a = src[..., 3:4]
        out_a = a + dst[..., 3:4] * (1.0 - a)
        rgb = (src[..., :3] * a + dst[..., :3] * dst[..., 3:4] * (1.0 - a)) / np.maximum(out_a, 1e-12)
        dst[..., :3], dst[..., 3:4] = rgb, out_a
        y += h + gap
    return np.round(255.0 * card).astype(np.uint8)


def typeset_system(formulas: Sequence[str], variables: Sequence[str], params: Mapping[str, float] | None = None,
                   complex_equations: Sequence[str] | None = None, complex_variables: Sequence[str] | None = None,
                   font_px: float = 28.0,
                   max_size: tuple[int, int] | None = None) -> tuple[np.ndarray | None, list[Line]]:
    """The card of a system (:func:`system_lines` drawn by :func:`render_lines`): (RGBA image or None, lines).

    ``max_size`` (w, h) pixels: the font shrinks (down to 10 px) until the card fits.
    """
    lines = system_lines(formulas, variables, params, complex_equations, complex_variables)
    font_px = float(round(font_px))
    image = render_lines(lines, font_px)
    for _ in range(3):   # the size is nearly proportional to the font: one step, rarely two
        if image is None or max_size is None or font_px <= 10.0:
            break
        h, w = image.shape[:2]
        scale = min(max_size[0] / w, max_size[1] / h)
        if scale >= 1.0:
            break
        font_px = max(10.0, float(math.floor(font_px * scale * 0.98)))
        image = render_lines(lines, font_px)
    return image, lines
