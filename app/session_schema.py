"""What a session file may hold: checked whole before anything is built from it.

A session (``gcmh-session/1``, :mod:`gcmh_studio.studio_io`) is read by the window's panels, which trust
their input: ``"n": 1000000000`` grew past 6 GB of rows, a NaN angle or ``"opacity": "inf"`` ended in a
traceback, ``"n": -1`` or a system with no formulas left ``--session --screenshot`` waiting for a run that
never came. :func:`validate_session` checks every field a panel reads (types, ranges, sizes, finite
numbers, bounded texts and lists, n and k, a system that can run) and raises :class:`SessionError` with
one message naming the first field that is wrong. Fields the format does not know are left alone
(a newer file still opens); what a panel can repair (a camera that cannot be used) is repaired where it
is read. No Qt here.
"""

from __future__ import annotations

import math
import re
from numbers import Integral, Real

# the first field of every session file (studio_io writes it)
SESSION_FORMAT = "gcmh-session/1"

MAX_SESSION_BYTES = 1 << 20   # a session the app writes is a few kB; 100 MB of title took 6 GB
N_MAX = 12                    # the largest n and k (the Manifold tab's, qt_formula_rows.N_MAX)
MAX_TITLE = 500               # characters
MAX_NAME = 64                 # characters of a variable or parameter name
MAX_FORMULA = 5000            # characters of a formula (gcmh_core.formula.MAX_CHARS)
MAX_CONSTANT = 200            # characters of a number written as text ("-pi/2")
MAX_PARAMS = 64
MAX_DIV = 1_000_000           # cubes per axis (the run's budget refuses far less, with its own message)
MAX_SEED = 2**31 - 1
METHODS = ("gcmh", "gcch", "cms", "ccs")
KINDS = ("coordinates", "generic", "principal")
MAPPINGS = ("orthographic", "perspective", "stereographic")
_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class SessionError(ValueError):
    """A session file that cannot be opened; the message is one line naming the field."""


def _fail(where: str, msg: str) -> SessionError:
    return SessionError(f"{where}: {msg}" if where else msg)


def _int(value, where: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (Integral, str)):
        raise _fail(where, f"must be an integer, got {_show(value)}")
    if isinstance(value, str):
        if not re.fullmatch(r"\s*[+-]?\d{1,12}\s*", value):
            raise _fail(where, f"must be an integer, got {_show(value)}")
        value = int(value)
    if not lo <= value <= hi:
        raise _fail(where, f"must be between {lo} and {hi}, got {_show(value)}")
    return int(value)


def _number(value, where: str, lo: float = -math.inf, hi: float = math.inf, text: bool = True) -> float:
    """A finite number in [lo, hi]; with ``text``, also a constant written as text ("-pi/2")."""
    if isinstance(value, str) and text:
        if len(value) > MAX_CONSTANT:
            raise _fail(where, f"a number written as text has at most {MAX_CONSTANT} characters")
        from gcmh_core.errors import InputError
        from gcmh_core.formula import evaluate_constant

        try:
            value = evaluate_constant(value)
        except InputError as e:
            raise _fail(where, str(e)) from None
    if isinstance(value, bool) or not isinstance(value, Real):
        raise _fail(where, f"must be a number, got {_show(value)}")
    x = float(value)
    if not math.isfinite(x):
        raise _fail(where, f"must be a finite number, got {_show(value)}")
    if not lo <= x <= hi:
        raise _fail(where, f"must be between {lo:g} and {hi:g}, got {x:g}")
    return x


def _text(value, where: str, limit: int, empty: bool = True) -> str:
    if not isinstance(value, str):
        raise _fail(where, f"must be a text, got {_show(value)}")
    if len(value) > limit:
        raise _fail(where, f"is {len(value):,} characters long (at most {limit:,})")
    if not empty and not value.strip():
        raise _fail(where, "is empty")
    return value


def _list(value, where: str, lo: int, hi: int) -> list:
    if not isinstance(value, list):
        raise _fail(where, f"must be a list, got {_show(value)}")
    if not lo <= len(value) <= hi:
        raise _fail(where, f"must have {lo} to {hi} entries, it has {len(value):,}" if lo != hi
                    else f"must have {lo} entries, it has {len(value):,}")
    return value


def _name(value, where: str) -> str:
    _text(value, where, MAX_NAME, empty=False)
    if not _IDENT.match(value.strip()):
        raise _fail(where, f"{value!r} is not a name (letters, digits, _)")
    return value


def _mapping(value, where: str) -> dict:
    if not isinstance(value, dict):
        raise _fail(where, f"must be a mapping ({{...}}), got {_show(value)}")
    return value


def _show(value) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


# ---------------------------------------------------------------- the parts
def _system(s, blank: bool = False) -> tuple[int, int]:
    """Check the Manifold tab's part; returns (n, k) of the system it describes.  ``blank``: its formulas
    may all be empty (a session of data files: the tab's system is not what is shown)."""
    _mapping(s, "system")
    cplx = s.get("complex")
    if cplx:   # equations over C^m: the panel splits them (n = 2m, k = 2 per equation + the real formulas)
        eqs = _list(cplx, "system.complex", 1, N_MAX // 2)
        for i, e in enumerate(eqs):
            _text(e, f"system.complex[{i}]", MAX_FORMULA, empty=False)
        cvars = _list(s.get("complex_variables"), "system.complex_variables", 1, N_MAX // 2)
        for i, v in enumerate(cvars):
            _name(v, f"system.complex_variables[{i}]")
        extra = _list(s.get("formulas") or [], "system.formulas", 0, N_MAX)
        for i, f in enumerate(extra):
            _text(f, f"system.formulas[{i}]", MAX_FORMULA, empty=False)
        n, k = 2 * len(cvars), 2 * len(eqs) + len(extra)
        if k > N_MAX:
            raise _fail("system", f"the equations give k = {k} components (at most {N_MAX})")
    else:
        if "formulas" not in s:
            raise _fail("system", "has no formulas (a list of F's components)")
        formulas = _list(s["formulas"], "system.formulas", 1, N_MAX)
        for i, f in enumerate(formulas):   # (a row left blank is the panel's to point out, as when typed)
            _text(f, f"system.formulas[{i}]", MAX_FORMULA)
        if not blank and not any(f.strip() for f in formulas):
            raise _fail("system.formulas", "are all empty")
        n = _int(s["n"], "system.n", 1, N_MAX) if "n" in s else len(s.get("variables") or [])
        if not n:
            raise _fail("system", "gives neither n nor the variables")
        k = _int(s["k"], "system.k", 1, N_MAX) if "k" in s else len(formulas)
        if k != len(formulas):
            raise _fail("system", f"k = {k} but there are {len(formulas)} formulas")
    for key in ("n", "k"):   # (complex mode: the panel computes them; a file's own must still be sane)
        if key in s and cplx:
            _int(s[key], f"system.{key}", 1, N_MAX)
    if k > n:
        raise _fail("system", f"k = {k} is more than n = {n} (F: R^n -> R^k needs k <= n)")
    variables = s.get("variables")
    if variables is not None and variables != []:
        _list(variables, "system.variables", n, n)
        for i, v in enumerate(variables):
            _name(v, f"system.variables[{i}]")
        if len(set(variables)) != n:
            raise _fail("system.variables", "names a variable twice")
    if s.get("bounds") is not None:
        bounds = _list(s["bounds"], "system.bounds", 1, max(n, 2))
        if len(bounds) == 2 and not isinstance(bounds[0], list):
            bounds = [bounds]
        elif len(bounds) not in (1, n):
            raise _fail("system.bounds", f"must have one (lo, hi) pair or {n}, it has {len(bounds)}")
        for a, pair in enumerate(bounds):
            _list(pair, f"system.bounds[{a}]", 2, 2)
            lo = _number(pair[0], f"system.bounds[{a}][0]")
            hi = _number(pair[1], f"system.bounds[{a}][1]")
            if not lo < hi:
                raise _fail(f"system.bounds[{a}]", f"lower bound {lo:g} is not below upper bound {hi:g}")
    if "div" in s:
        div = s["div"]
        if isinstance(div, list):
            _list(div, "system.div", n, n)
            for a, d in enumerate(div):
                _int(d, f"system.div[{a}]", 1, MAX_DIV)
        else:
            _int(div, "system.div", 1, MAX_DIV)
    if s.get("method") is not None:
        method = _text(s["method"], "system.method", 20).lower()
        if method not in METHODS:
            raise _fail("system.method", f"must be one of {', '.join(METHODS)}, got {_show(s['method'])}")
    if "seed" in s:
        _int(s["seed"], "system.seed", 0, MAX_SEED)
    start = s.get("start")
    if isinstance(start, list):
        _list(start, "system.start", n, n)
        for a, x in enumerate(start):
            _number(x, f"system.start[{a}]")
    elif start is not None:
        _text(start, "system.start", MAX_CONSTANT * N_MAX)
    params = s.get("params")
    if isinstance(params, str):
        _text(params, "system.params", MAX_CONSTANT * MAX_PARAMS)
    elif params is not None:
        _mapping(params, "system.params")
        if len(params) > MAX_PARAMS:
            raise _fail("system.params", f"has {len(params):,} parameters (at most {MAX_PARAMS})")
        for name, spec in params.items():
            _name(name, "system.params")
            if isinstance(spec, dict):
                for key in ("value", "min", "max"):
                    if spec.get(key) is not None:
                        _number(spec[key], f"system.params.{name}.{key}")
                low, high = spec.get("min"), spec.get("max")
                if low is not None and high is not None and not _number(low, "") < _number(high, ""):
                    raise _fail(f"system.params.{name}", "min is not below max")
            else:
                _number(spec, f"system.params.{name}")
    periodic = s.get("periodic")
    if isinstance(periodic, list):
        for i, p in enumerate(_list(periodic, "system.periodic", 0, N_MAX)):
            _text(p, f"system.periodic[{i}]", MAX_CONSTANT)
    elif periodic is not None:
        _text(periodic, "system.periodic", MAX_CONSTANT * N_MAX)
    if s.get("scheduler") is not None:
        _text(s["scheduler"], "system.scheduler", MAX_CONSTANT)
    return n, k


def _view(v) -> None:
    """Check the View tab's part."""
    _mapping(v, "view")
    if "kind" in v and v["kind"] not in KINDS:
        raise _fail("view.kind", f"must be one of {', '.join(KINDS)}, got {_show(v['kind'])}")
    # (the view is the result's on screen, which may have other variables than the system in the panel: a
    # view that does not fit the result is replaced when it is shown, so only its size is bounded here)
    if "axes" in v:
        for i, a in enumerate(_list(v["axes"], "view.axes", 3, 3)):
            _int(a, f"view.axes[{i}]", -1, N_MAX - 1)
    if "seed" in v:
        _int(v["seed"], "view.seed", 0, MAX_SEED)
    if "angles" in v and v["angles"] is not None:
        for i, a in enumerate(_list(v["angles"], "view.angles", 0, N_MAX * (N_MAX - 1) // 2)):
            _number(a, f"view.angles[{i}]", text=False)
    if v.get("mapping") is not None and v["mapping"] not in MAPPINGS:
        raise _fail("view.mapping", f"must be one of {', '.join(MAPPINGS)}, got {_show(v['mapping'])}")
    if "distance" in v:
        _number(v["distance"], "view.distance", 1.0, 1e6, text=False)
    if v.get("color") is not None:
        _text(v["color"], "view.color", MAX_NAME)
    if v.get("opacity") is not None:
        _number(v["opacity"], "view.opacity", 0.0, 1.0, text=False)
    for key in ("show_edges", "two_sided", "boundary", "grid", "angles_as_circles", "show_seam"):
        if key in v and not isinstance(v[key], bool):
            raise _fail(f"view.{key}", f"must be true or false, got {_show(v[key])}")
    for key in ("axes_names", "planes"):   # (what the file says for a reader: not read back)
        if v.get(key) is not None:
            for i, t in enumerate(_list(v[key], f"view.{key}", 0, N_MAX * N_MAX)):
                if t is not None:
                    _text(t, f"view.{key}[{i}]", 2 * MAX_NAME + 1)
    sl = v.get("slice")
    if sl is not None:
        _mapping(sl, "view.slice")
        if "along" in sl:
            _text(sl["along"], "view.slice.along", MAX_NAME + 20)
        if "c" in sl:
            _number(sl["c"], "view.slice.c", text=False)
        if "w" in sl:
            w = _number(sl["w"], "view.slice.w", text=False)
            if not w > 0:
                raise _fail("view.slice.w", f"must be > 0, got {w:g}")


MAX_PATH = 4096               # characters of a data file's path (PATH_MAX)


def data_entry(e) -> dict:
    """Check a data source's entry (:meth:`gcmh_studio.data_source.DataSource.session_entry`, a session's
    ``"data"`` and the gallery's remembered sources): its files by path, levels, box, component flag and
    what was seen of each file (size, modification time)."""
    _mapping(e, "data")
    files = _list(e.get("files"), "data.files", 1, N_MAX)
    for i, f in enumerate(files):
        _text(f, f"data.files[{i}]", MAX_PATH, empty=False)
    if e.get("levels") is not None:
        for i, v in enumerate(_list(e["levels"], "data.levels", 1, N_MAX)):
            _number(v, f"data.levels[{i}]", text=False)
    if e.get("bounds") is not None:
        box = _list(e["bounds"], "data.bounds", 2, N_MAX)
        pairs = box if isinstance(box[0], list) else [box]
        for i, pair in enumerate(pairs):
            for j, v in enumerate(_list(pair, f"data.bounds[{i}]", 2, 2)):
                _number(v, f"data.bounds[{i}][{j}]", text=False)
    if e.get("components") is not None and not isinstance(e["components"], bool):
        raise _fail("data.components", f"must be true, false or null, got {_show(e['components'])}")
    for i, stamp in enumerate(_list(e.get("seen") or [], "data.seen", 0, len(files))):
        if stamp is not None:
            for j, v in enumerate(_list(stamp, f"data.seen[{i}]", 2, 2)):
                _int(v, f"data.seen[{i}][{j}]", 0, 2**63 - 1)
    return e


def validate_session(d) -> dict:
    """``d`` (a parsed session file) if every field the app reads is usable, else :class:`SessionError`.

    The format, the title (at most MAX_TITLE characters), the system (n and k in 1..N_MAX with k <= n,
    its formulas or complex equations, variables, bounds, div, method, seed, start, parameters and glued
    axes, each bounded and finite), the view (projection kind, axes, n(n-1)/2 finite angles, mapping,
    distance, colour, opacity in [0, 1], toggles (the angle switches too), a slice that is a mapping), and
    a data source's entry (:func:`data_entry`)."""
    if not isinstance(d, dict) or d.get("format") != SESSION_FORMAT:
        raise SessionError(f"not a GCMH session file (format {SESSION_FORMAT!r} expected)")
    if d.get("title") is not None:
        _text(d["title"], "title", MAX_TITLE)
    if "system" not in d:
        raise SessionError("the session has no system")
    if d.get("data") is not None:
        data_entry(d["data"])
    _system(d["system"], blank=d.get("data") is not None)
    if d.get("view") is not None:
        _view(d["view"])
    return d   # (the camera and "keep camera": a hand-edited one that cannot be used is dropped, not refused)
