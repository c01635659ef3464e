"""Checking `extract`'s arguments before any work: one specific message per mistake.

Shared by `extract` and `distributed` (block sizes), and by what reads a system from
text -- the command lines (`cli`, the app's) and the example loader (`examples`) --
for the parameters' values (`parse_params`) and the glued axes (`glued_axes`), so
each mistake gets the same message wherever it is made; nothing here computes.
"""

from __future__ import annotations

import re
from numbers import Integral, Real

import numpy as np

from .errors import InputError

__all__ = ["per_axis_ints", "as_div", "as_bounds", "as_periodic", "describe_periodic", "glued_axes", "parse_params",
           "check_n", "infer_n", "prepare", "Float64Slices"]


def per_axis_ints(value, n: int, what: str) -> np.ndarray:
    """(n,) int64 from one positive integer (the same on every axis) or one per axis;
    a clear InputError naming `what` otherwise (bools, fractions, strings, wrong length)."""
    if isinstance(value, (Integral, np.integer)) and not isinstance(value, bool):
        value = [int(value)] * n
    try:
        if isinstance(value, (str, bytes)):
            raise TypeError
        items = list(value)
        if any(isinstance(v, bool) for v in items) or any(float(v) != int(v) for v in items):
            raise ValueError
        arr = [int(v) for v in items]
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} must be a positive integer or one per axis, got {value!r}") from None
    if len(arr) != n:
        raise InputError(f"{what} has {len(arr)} entries but there are n = {n} axes")
    for a, d in enumerate(arr):
        if d < 1:
            raise InputError(f"{what} must be at least 1 cube on every axis (axis {a + 1} has {d})")
    return np.array(arr, np.int64)


def as_div(div, n: int) -> np.ndarray:
    return per_axis_ints(div, n, "div")


# a plain decimal number as Python writes it (no 007): read by float() (the formula module, which
# imports sympy, is for the rest)
_PLAIN_NUMBER = re.compile(r"\s*[+-]?(0+|[1-9][0-9]*|([0-9]+\.[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?"
                           r"|[0-9]+[eE][+-]?[0-9]+)\s*")


def _number(x, what: str) -> float:
    if isinstance(x, str) and _PLAIN_NUMBER.fullmatch(x) and np.isfinite(float(x)):
        x = float(x)
    elif isinstance(x, str):
        from .formula import evaluate_constant  # (numbers like "-pi/2", parsed safely)

        try:
            x = evaluate_constant(x)
        except InputError as err:
            raise InputError(f"{what}: {err}") from None
    if not isinstance(x, (Real, np.floating, np.integer)) or isinstance(x, bool):
        raise InputError(f"{what} must be a number, got {x!r}")
    x = float(x)
    if not np.isfinite(x):
        raise InputError(f"{what} must be finite, got {x}")
    return x


def as_bounds(bounds, n: int) -> np.ndarray:
    if bounds is None:
        raise InputError("bounds are required: one (lo, hi) pair, or one per axis")
    if isinstance(bounds, np.ndarray):
        bounds = bounds.tolist()
    try:
        pairs = list(bounds)
    except TypeError:
        raise InputError(f"bounds must be (lo, hi) pairs, got {bounds!r}") from None
    if len(pairs) == 2 and not any(isinstance(p, (list, tuple, np.ndarray)) for p in pairs):
        pairs = [pairs] * n
    if len(pairs) == 1 and n > 1:
        pairs = pairs * n
    if len(pairs) != n:
        raise InputError(f"bounds has {len(pairs)} intervals but there are n = {n} axes")
    out = np.empty((n, 2))
    for a, pair in enumerate(pairs):
        if not isinstance(pair, (list, tuple, np.ndarray)) or len(pair) != 2:
            raise InputError(f"bounds for axis {a + 1} must be a (lo, hi) pair, got {pair!r}")
        lo = _number(pair[0], f"lower bound of axis {a + 1}")
        hi = _number(pair[1], f"upper bound of axis {a + 1}")
        if not lo < hi:
            raise InputError(f"axis {a + 1}: lower bound {lo:g} is not below upper bound {hi:g}")
        out[a] = lo, hi
    return out


_PERIODIC_FORMS = ('periodic is {"t": True, "s": {"flip": ["t"]}} or a list like ["t", "s:flip=t"] '
                   "(axis names; flip lists the axes reversed across that axis's seam)")


def _periodic_entries(periodic):
    """(name, value) pairs from the dict or list form; value is True, False or a flip list."""
    if isinstance(periodic, dict):
        items = list(periodic.items())
    elif isinstance(periodic, (list, tuple)):
        items = []
        for item in periodic:
            if not isinstance(item, str):
                raise InputError(f"{_PERIODIC_FORMS}; got the entry {item!r}")
            name, _, rest = item.partition(":")
            rest = rest.strip()
            if not rest:
                items.append((name.strip(), True))
                continue
            key, eq, flips = rest.partition("=")
            if key.strip() != "flip" or not eq:
                raise InputError(f"periodic entry {item!r}: write NAME or NAME:flip=A,B")
            flipped = [f.strip() for f in flips.split(",")]
            if not all(flipped):   # ("t:flip=" was read as "t": a seam without the reversal asked for)
                raise InputError(f"periodic entry {item!r}: flip= needs axis names, e.g. {name.strip()}:flip=A,B "
                                 f"(or {name.strip()} alone for a plain seam)")
            items.append((name.strip(), {"flip": flipped}))
    else:
        raise InputError(f"{_PERIODIC_FORMS}; got {periodic!r}")
    out: list[tuple[str, bool | list[str]]] = []
    for name, value in items:
        if value is True or value is False:
            out.append((name, value))
        elif isinstance(value, dict):
            extra = set(value) - {"flip"}
            if extra:
                raise InputError(f"periodic axis {name!r}: unknown option {sorted(extra)[0]!r} (only 'flip')")
            flip = value.get("flip", [])
            if isinstance(flip, str):
                flip = [f.strip() for f in flip.split(",") if f.strip()]
            if not isinstance(flip, (list, tuple)) or not all(isinstance(f, str) for f in flip):
                raise InputError(f"periodic axis {name!r}: flip must be a list of axis names, got {flip!r}")
            out.append((name, list(flip)))
        else:
            raise InputError(f"periodic axis {name!r}: the value must be True, False or {{'flip': [...]}}, "
                             f"got {value!r}")
    return out


def as_periodic(periodic, variables, div) -> tuple[tuple[int, tuple[int, ...]], ...]:
    """The identified axes as ((axis, (flipped axes...)), ...), sorted by axis; () for none.

    Refused with one message each: an unknown name, an axis named twice, an axis flipping
    itself, fewer than 3 cubes on a periodic axis, an odd div on a flipped axis (its grid
    must be mirror-symmetric, see `identify`), and a flipped axis whose own seam flips too."""
    if periodic is None:
        return ()
    names = list(variables)
    index = {v: a for a, v in enumerate(names)}

    def axis_of(name, what):
        if not isinstance(name, str) or name not in index:
            raise InputError(f"{what} {name!r} is not a variable (variables: {', '.join(names)})")
        return index[name]

    spec: dict[int, tuple[int, ...] | None] = {}  # None: named but not periodic (False)
    for name, value in _periodic_entries(periodic):
        p = axis_of(name, "periodic axis")
        if p in spec:
            raise InputError(f"periodic axis {name!r} is given twice")
        if value is False:
            spec[p] = None
            continue
        flips = [] if value is True else [axis_of(f, f"flip of {name!r}:") for f in value]
        if p in flips:
            raise InputError(f"periodic axis {name!r} cannot reverse itself across its own seam")
        if len(set(flips)) != len(flips):
            raise InputError(f"periodic axis {name!r} reverses an axis twice")
        spec[p] = tuple(sorted(flips))
    glued = {p: f for p, f in spec.items() if f is not None}
    for p, flipped in glued.items():
        if int(div[p]) < 3:
            raise InputError(f"periodic axis {names[p]!r} needs at least 3 cubes around it, div is {int(div[p])}")
        for b in flipped:
            if int(div[b]) % 2:
                raise InputError(f"axis {names[b]!r} is reversed across the seam of {names[p]!r}, so its grid is "
                                 f"mirror-symmetric and needs an even div, got {int(div[b])}")
            if glued.get(b):
                raise InputError(f"axis {names[b]!r} is reversed across the seam of {names[p]!r} and cannot "
                                 f"reverse axes across its own seam too")
    return tuple((p, glued[p]) for p in sorted(glued))


def describe_periodic(spec, variables) -> list[str]:
    """`as_periodic`'s result as text: ["s:flip=t", "t"] (the list form it accepts)."""
    return [variables[p] + (":flip=" + ",".join(variables[b] for b in flips) if flips else "")
            for p, flips in spec]


def glued_axes(periodic, variables, div) -> list[str]:
    """The glued axes checked against the variables and the grid (`as_periodic`), as the list of
    texts extract's ``periodic=`` takes, e.g. ["s:flip=t", "t"]; [] for None.  ``div``: an int or
    one per axis.  What the example files' ``periodic`` and ``--periodic`` both go through."""
    if periodic is None:
        return []
    n = len(variables)
    return describe_periodic(as_periodic(periodic, variables, per_axis_ints(div, n, "div")), list(variables))


def parse_params(items, option: str = "--param") -> dict[str, float] | None:
    """``NAME=VALUE`` texts (``option``'s values, e.g. ["a=0.3", "c=pi/4"]) -> {name: value}; None for none.

    Values are constant text (`formula.evaluate_constant`); a malformed item, a name given twice or a
    value that is not a number is one InputError naming ``option``.  Whether each name is a parameter
    of the formulas is for `formula.parse_system` to say (it knows them)."""
    if not items:
        return None
    from .formula import evaluate_constant  # (sympy's parser: not for `import gcmh_core`)

    out: dict[str, float] = {}
    for item in items:
        name, eq, value = str(item).partition("=")
        name = name.strip()
        if not eq or not name.isidentifier():
            raise InputError(f"{option}: expected NAME=VALUE, e.g. {option} a=0.3, got {item!r}")
        if name in out:
            raise InputError(f"{option}: {name} is given twice")
        try:
            out[name] = evaluate_constant(value)
        except InputError as err:
            raise InputError(f"{option} {name}: {err}") from None
    return out


def check_n(n) -> None:
    """InputError unless 1 <= n <= formula.MAX_VARIABLES (checked before n of anything is made)."""
    from .formula import MAX_VARIABLES

    if not 1 <= int(n) <= MAX_VARIABLES:
        raise InputError(f"n = {int(n):,}: the number of variables must be between 1 and {MAX_VARIABLES} "
                         "(a grid in R^n has at least 2^n vertices)")


def infer_n(F, variables, bounds, div, n):
    if n is not None:
        return int(n)
    if variables is not None:
        return len(variables)
    if bounds is not None:
        b = bounds.tolist() if isinstance(bounds, np.ndarray) else bounds
        if isinstance(b, (list, tuple)) and b and isinstance(b[0], (list, tuple)) and len(b) > 1:
            return len(b)
    if isinstance(div, (list, tuple, np.ndarray)):
        return len(div)
    texts = [F] if isinstance(F, str) else list(F)
    indices = [int(m) for t in texts for m in re.findall(r"\bx(\d+)\b", str(t))]
    if indices:
        return max(indices)
    raise InputError("cannot tell n: give variables, one bounds pair per axis, or n")


class Float64Slices:
    """Sampled values of another type than float64 (a float32 volume, int16 scan data) or not C-contiguous,
    read as float64 one slice at a time: F's values as the kernels take them, the same bytes as the
    array converted whole, without the whole float64 copy (twice a float32 volume's size) beside the
    caller's array.  For the runs that only read slices (the full sweep in this process, the budget's
    probe), like `data_files.MappedValues`; continuation and clusters take the array converted."""

    dtype = np.dtype(np.float64)
    reads_slices = True

    def __init__(self, values: np.ndarray):
        self.values = values
        self.shape = values.shape
        self.ndim = values.ndim

    def __getitem__(self, index) -> np.ndarray:
        return np.array(self.values[index], np.float64)

    def __array__(self, dtype=None, copy=None):
        whole = np.ascontiguousarray(self.values, np.float64)
        return whole if dtype is None else whole.astype(dtype)


def prepare(F, variables, n, k, bounds, div, params=None, slices: bool = False):
    """Returns (n, k, bounds, div, system or None, sampled array or None); `params`
    ({name: value}) are the formulas' parameter values (see `formula.parse_system`).  ``slices``: the
    caller reads the sampled values slice by slice only (the full sweep, the estimate): an array that
    is not float64 and C-contiguous is not converted whole but wrapped (`Float64Slices`)."""
    if isinstance(variables, str):
        variables = [v.strip() for v in variables.split(",")]
    if isinstance(F, np.ndarray) or (hasattr(F, "__array__") and not isinstance(F, (str, list, tuple))):
        # values read slice by slice from files (`data_files.MappedValues`): kept so, never whole in memory
        sliced = bool(getattr(F, "reads_slices", False))
        values = F if sliced else np.asarray(F)
        if params is not None:
            raise InputError("params go with formulas: sampled values have no parameters")
        if values.dtype.kind not in "fiu":
            raise InputError(f"sampled values must be numbers, got dtype {values.dtype}")
        if values.ndim < 2:
            raise InputError("sampled values must have shape (d1+1, ..., dn+1, k)")
        n_s = values.ndim - 1
        if n is not None and int(n) == values.ndim:  # (d1+1, ..., dn+1) with k = 1
            values = values[..., None]
            n_s = values.ndim - 1
        n_ = n_s
        k_ = values.shape[-1]
        if k is not None and int(k) != k_:
            raise InputError(f"sampled values have k = {k_} components, not {k}")
        shape_div = np.array(values.shape[:-1], np.int64) - 1
        if np.any(shape_div < 1):
            raise InputError(f"sampled values need at least 2 samples per axis, got shape {values.shape}")
        if div is not None and not np.array_equal(as_div(div, n_), shape_div):
            raise InputError(f"div {div} does not match the sampled array's shape {values.shape}")
        if not 1 <= k_ < n_:
            raise InputError(f"need 1 <= k < n, got n = {n_}, k = {k_}")
        if sliced:
            sampled = values
        elif slices and not (values.dtype == np.float64 and values.flags.c_contiguous):
            sampled = Float64Slices(values)
        else:
            sampled = np.ascontiguousarray(values, np.float64)
        return n_, k_, as_bounds(bounds, n_), shape_div, None, sampled
    from .formula import System, parse_system  # (sympy: not for sampled values)

    if isinstance(F, System):
        system = F if params is None else parse_system(F.texts, F.variables, params={**F.params, **params})
    else:
        if isinstance(F, str):
            F = [F]
        if not isinstance(F, (list, tuple)) or not all(isinstance(t, str) for t in F):
            raise InputError("F must be formula text, a list of formula texts, a System or an array of values")
        n_ = infer_n(F, variables, bounds, div, n)
        check_n(n_)
        system = parse_system(list(F), variables, n=n_, k=k, params=params)
    if n is not None and int(n) != system.n:
        raise InputError(f"n = {n} but the formulas have {system.n} variables")
    if k is not None and int(k) != system.k:
        raise InputError(f"k = {k} but there are {system.k} formulas")
    if not 1 <= system.k < system.n:
        raise InputError(f"need 1 <= k < n, got n = {system.n}, k = {system.k}")
    if div is None:
        div = 10
    return system.n, system.k, as_bounds(bounds, system.n), as_div(div, system.n), system, None
