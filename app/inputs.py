"""Checking what the user types into the side panel (pure Python, no Qt).

Each ``check_*`` function returns ``None`` when the text is fine and a short
message otherwise; the panel shows the message under the field and keeps Run
disabled. Numbers may be written as constant expressions (``-pi/2``,
``2*pi``, ``1e-3``), read by :func:`gcmh_core.formula.evaluate_constant`, never eval.
"""

from __future__ import annotations

import re

from gcmh_core._memory import available_memory as available_memory  # used by the formula panel
from gcmh_core._memory import format_bytes, format_seconds
from gcmh_core.errors import InputError
from gcmh_core.formula import evaluate_constant

# names a variable may not take: they mean something in formulas
RESERVED = {
    "pi", "e", "tau", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh",
    "acosh", "atanh", "exp", "log", "ln", "sqrt", "abs", "sign", "min", "max", "floor", "ceil", "re", "im",
    "I", "j", "inf", "nan", "E", "hypot", "cbrt", "mod", "arg",
}
_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")

# the engine's words for what Python's math raised, said the way a field's message says them
_PLAIN = {"division by zero": "division by zero", "math domain error": "argument out of range",
          "Numerical result out of range": "out of range", "math range error": "out of range"}


class NumberError(ValueError):
    pass


def parse_number(text: str) -> float:
    """A finite float from a constant expression such as ``-pi/2`` or ``3.5``.

    A thin wrapper over :func:`gcmh_core.formula.evaluate_constant` (the one
    evaluator of constant text): its message, without the text the field already
    shows, is raised as :class:`NumberError`.
    """
    try:
        return evaluate_constant(str(text))
    except InputError as e:
        raise NumberError(_short_message(str(e), str(text).strip().replace("\u03c0", "pi"))) from None


def _short_message(message: str, src: str) -> str:
    for prefix in (f"cannot read {src!r} as a number: ", f"cannot evaluate {src!r}: "):
        if message.startswith(prefix):
            rest = message[len(prefix):]
            for words, plain in _PLAIN.items():
                if words in rest:
                    return plain
            return rest
    return message


def default_variables(n: int) -> list[str]:
    return [f"x{i + 1}" for i in range(n)]


def split_names(text: str) -> list[str]:
    return [t for t in re.split(r"[,\s]+", text.strip()) if t]


def check_variables(text: str, n: int) -> str | None:
    names = split_names(text)
    if len(names) != n:
        return f"{n} names needed (separated by commas), got {len(names)}"
    for nm in names:
        if not _IDENT.match(nm):
            return f"{nm!r} is not a name (letters, digits, _; not starting with a digit)"
        if nm in RESERVED:
            return f"{nm!r} is reserved (a function or constant)"
    seen = set()
    for nm in names:
        if nm in seen:
            return f"{nm!r} appears twice"
        seen.add(nm)
    return None


def check_formula(text: str, names, index: int, params=()) -> str | None:
    """None when ``text`` parses as component ``index`` of F in ``names`` (with the parameters named in
    ``params``), else the parser's message. (The panel calls this in a worker thread: a long formula
    never blocks the window.)"""
    from gcmh_core.formula import check_component, find_parameters

    try:
        if not params:
            check_component(text, list(names), index)
            return None
        check_component(text, list(names), index, allow_parameters=True)
        unknown = [p for p in find_parameters(text, list(names)) if p not in params]
    except Exception as e:  # noqa: BLE001 - FormulaError or any InputError
        return str(e)
    if unknown:
        return (f"component {index + 1} (F{index + 1}): unknown name {unknown[0]!r} (variables: {', '.join(names)}; "
                f"parameters: {', '.join(params)})")
    return None


def check_params(text: str, names) -> tuple[str | None, dict[str, float]]:
    """The parameters field, ``a = 0.5, b = pi/4``: (a message or None, {name: value})."""
    out: dict[str, float] = {}
    for part in [p for p in re.split(r"[,;]", text) if p.strip()]:
        name, eq, value = part.partition("=")
        name = name.strip()
        if not eq:
            return f"parameters: write NAME = VALUE, got {part.strip()!r}", {}
        if not _IDENT.match(name) or name in RESERVED:
            return f"parameters: {name!r} cannot be a parameter's name", {}
        if name in names:
            return f"parameters: {name!r} is a variable", {}
        if name in out:
            return f"parameters: {name!r} appears twice", {}
        try:
            out[name] = parse_number(value)
        except NumberError as e:
            return f"parameters: {name}: {e}", {}
    return None, out


def check_periodic(text: str, names, div) -> tuple[str | None, list[str]]:
    """The glued-axes field, ``t  s:flip=t`` (entries separated by spaces, commas or
    semicolons, as ``gcmh extract --periodic`` takes them): (a message or None, the entries)."""
    entries = [e for e in re.split(r"[\s;]+", text.replace(", ", " ").strip()) if e]
    entries = [e.strip(",") for e in entries if e.strip(",")]
    if not entries:
        return None, []
    if div is None:
        return None, entries  # checked again once the division is valid
    from gcmh_core._validate import as_periodic  # the engine's own check: the same messages as the CLI

    try:
        as_periodic(entries, list(names), list(div))
    except InputError as e:
        return f"glued axes: {e}", []
    return None, entries


def check_nk(n: int, k: int) -> str | None:
    if n < 1:
        return "n must be at least 1"
    if not 1 <= k < n:
        return f"k must satisfy 1 <= k < n (got n = {n}, k = {k})"
    return None


def check_bounds(lo_text: str, hi_text: str) -> tuple[str | None, str | None, tuple[float, float] | None]:
    """Messages for the lower and upper cell, and the parsed pair when both are fine."""
    lo = hi = None
    elo = ehi = None
    try:
        lo = parse_number(lo_text)
    except NumberError as e:
        elo = f"lower: {e}"
    try:
        hi = parse_number(hi_text)
    except NumberError as e:
        ehi = f"upper: {e}"
    if elo or ehi or lo is None or hi is None:
        return elo, ehi, None
    if not lo < hi:
        return None, f"empty interval: lower {lo:g} is not below upper {hi:g}", None
    return None, None, (lo, hi)


def check_div(text: str) -> tuple[str | None, int | None]:
    try:
        v = parse_number(text)
    except NumberError as e:
        return f"div: {e}", None
    if v != int(v):
        return f"div must be a whole number, got {v:g}", None
    v = int(v)
    if v < 1:
        return f"div must be at least 1, got {v}", None
    if v > 100000:
        return "div is unreasonably large", None
    return None, v


def check_start(text: str, n: int):
    """A start point for continuation: empty or "auto" (the engine finds one), or n numbers."""
    if not text.strip() or text.strip().lower() == "auto":
        return None, "auto"
    parts = [p for p in re.split(r"[,;\s]+", text.strip()) if p]
    if len(parts) != n:
        return f"the start point needs {n} coordinates, got {len(parts)}", None
    out = []
    for p in parts:
        try:
            out.append(parse_number(p))
        except NumberError as e:
            return f"start point: {e}", None
    return None, out


def format_value(v: float) -> str:
    """A parameter's value as the user reads it (six significant digits)."""
    return f"{float(v):.6g}"


# Sizes, durations and free memory are said the same way by the engine's budget and the app.
human_bytes = format_bytes
human_seconds = format_seconds
