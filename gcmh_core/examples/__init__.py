"""Example manifolds shipped with GCMH Studio.

Each example is one TOML file beside this module, ``gcmh_core/examples/<name>.toml``
(package data, read with :mod:`importlib.resources`, so an installed wheel carries
them)::

    title = "Unit sphere in R^3"
    description = "Two to four sentences for a teacher."
    n = 3
    k = 1
    variables = ["x", "y", "z"]
    formulas = ["x**2 + y**2 + z**2 - 1"]
    bounds = [["-1.5", "1.5"], [-1.5, 1.5], [-1.5, 1.5]]   # numbers or constant expressions
    div = 32                     # or one int per axis
    paper_div = [40, 40, 20, 40, 40]   # optional: the division used in the paper
    start = [1.0, 0.0, 0.0]      # a point on M (continuation seed)

    [view]
    project = ["x", "y", "z"]    # three variables shown as 3D axes
    color = "z"                  # the variable used for the colour map

    [params]                     # optional: the formulas' parameters (one slider each)
    a = { value = 0.5, min = -1, max = 1 }

An example in complex variables gives its equations instead of ``formulas`` (and
may omit ``n`` and ``k``); the loader splits them into the real system
(:func:`gcmh_core.complex_equations.split_complex`)::

    complex = ["z = cos(w)"]              # lhs = rhs over C^m, i the imaginary unit
    complex_variables = ["w", "z"]
    variables = ["u", "v", "x", "y"]      # optional: Re w, Im w, Re z, Im z (default w_re, ...)
    formulas = ["u**2 + v**2 - 1"]        # optional: real equations added after the split ones

Angles are coordinates that wrap around: ``periodic = ["t", "s:flip=t"]`` glues the
domain's faces (t is a circle; crossing s = 2pi reverses t), see :mod:`gcmh_core.identify`.

``labels`` ({variable: "Re w"}) come from ``[view] labels`` or, for a complex
example, from the split.  ``bounds`` may also be a single pair, meaning the same
interval on every axis.
Bound entries written as strings (``"-pi/2"``, ``"2*pi"``) are evaluated by
:func:`evaluate_constant`, a whitelist evaluator built on :mod:`ast`; nothing
is ever passed to ``eval``.  ``$GCMH_EXAMPLES_DIR``, when set, names a folder
read instead of the shipped examples.

>>> ex = load_example("sphere")
>>> ex.n, ex.k, ex.variables
(3, 1, ['x', 'y', 'z'])
"""

from __future__ import annotations

import copy
import functools
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._validate import glued_axes
from ..errors import InputError
from ..formula import check_component, evaluate_constant, find_parameters  # (evaluate_constant re-exported)

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

if TYPE_CHECKING:
    if sys.version_info >= (3, 11):
        from importlib.resources.abc import Traversable
    else:
        from importlib.abc import Traversable

__all__ = [
    "VIEW_MAPPINGS",
    "Example",
    "evaluate_constant",
    "example_names",
    "examples_dir",
    "list_examples",
    "load_example",
]


# How the viewer maps R^n to 3D by default (the app's projection kinds).
VIEW_MAPPINGS = ("orthographic", "perspective", "stereographic")


@dataclass
class Example:
    """One example manifold M = F^-1(0), F: R^n -> R^k.

    bounds: list of n (lo, hi) float pairs; div: int or list of n ints;
    start: a point of M (list of n floats); view: dict(mapping=orthographic|perspective|stereographic,
    project=[3 variable names], color=variable name); path: the file it was read from.
    params: {name: {"value", "min", "max"}} (floats) for each parameter of the formulas
    (``start`` lies on M at the values);
    complex / complex_variables: the equations over C^m the formulas were split from
    (else None); labels: {variable: what it means, e.g. "Re w"}.
    periodic: the identified axes as ``extract(..., periodic=...)`` takes them, e.g.
    ["s:flip=t", "t"] (empty: the domain box is cut open at its faces).
    """

    name: str
    title: str
    description: str
    n: int
    k: int
    variables: list[str]
    formulas: list[str]
    bounds: list[tuple[float, float]]
    div: int | list[int]
    start: list[float]
    view: dict[str, Any] = field(default_factory=dict)
    paper_div: int | list[int] | None = None
    path: Traversable | None = None
    params: dict[str, dict[str, float]] = field(default_factory=dict)
    complex: list[str] | None = None
    complex_variables: list[str] | None = None
    labels: dict[str, str] = field(default_factory=dict)
    periodic: list[str] = field(default_factory=list)

    def param_values(self) -> dict[str, float]:
        """{name: value}: the parameters' default values, for ``extract(..., params=...)``."""
        return {p: spec["value"] for p, spec in self.params.items()}

    @property
    def dim(self) -> int:
        """Dimension n - k of the manifold."""
        return self.n - self.k

    def div_list(self) -> list[int]:
        """``div`` as one int per axis."""
        return [self.div] * self.n if isinstance(self.div, int) else list(self.div)


def _source() -> Traversable:
    """Where the TOML files are read from: ``$GCMH_EXAMPLES_DIR`` if set, else this package."""
    env = os.environ.get("GCMH_EXAMPLES_DIR")
    return Path(env) if env else resources.files(__name__)


def examples_dir() -> Path:
    """Folder holding the example TOML files.

    ``$GCMH_EXAMPLES_DIR`` if set, else the folder of this package (``pip install``
    unpacks the package data there).
    """
    return Path(str(_source()))


def example_names() -> list[str]:
    """Sorted names of the available examples."""
    folder = _source()
    if not folder.is_dir():
        return []
    return sorted(f.name[: -len(".toml")] for f in folder.iterdir() if f.name.endswith(".toml") and f.is_file())


def list_examples(on_error: Callable[[str, InputError], None] | None = None) -> list[Example]:
    """All examples that can be read, sorted by name.

    A file that cannot (malformed, too large, an equation too big to split) is left out, so one bad file in
    ``$GCMH_EXAMPLES_DIR`` does not hide the others: ``on_error(name, error)`` is told of each (by default a
    warning names it)."""
    out = []
    for name in example_names():
        try:
            out.append(load_example(name))
        except InputError as err:
            if on_error is None:
                import warnings

                warnings.warn(f"example {name!r} left out: {err}", stacklevel=2)
            else:
                on_error(name, err)
    return out


def load_example(name: str) -> Example:
    """The example called ``name`` (file ``<name>.toml``, see :func:`examples_dir`).

    Raises :class:`InputError` for an unknown name (listing the known ones)
    or a malformed file.
    """
    names = example_names()
    if not isinstance(name, str) or name not in names:
        known = ", ".join(names) if names else f"none found in {_source()}"
        raise InputError(f"unknown example {name!r}; known examples: {known}")
    file = _source() / f"{name}.toml"
    try:
        st = os.stat(str(file))
    except OSError:  # (not a plain file: read it each time)
        return _read_example(name, file)
    # a window lists every example (menus, gallery): parsing and checking 23 systems took 80 ms each time
    return copy.deepcopy(_read_example_cached(name, str(file), st.st_mtime_ns, st.st_size))


@functools.lru_cache(maxsize=256)
def _read_example_cached(name: str, path: str, mtime_ns: int, size: int) -> Example:
    return _read_example(name, Path(path))


MAX_EXAMPLE_BYTES = 1 << 20   # an example file is a few kB


def _read_example(name: str, file: Traversable) -> Example:
    try:
        with file.open("rb") as f:
            raw = f.read(MAX_EXAMPLE_BYTES + 1)
    except OSError as err:
        raise InputError(f"example file {file}: cannot read it: {err.strerror or err}") from None
    if len(raw) > MAX_EXAMPLE_BYTES:
        raise InputError(f"example file {file}: larger than {MAX_EXAMPLE_BYTES >> 20} MB, not an example")
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise InputError(f"example file {file}: {err}") from None
    except RecursionError:
        raise InputError(f"example file {file}: nested too deeply") from None
    return _from_dict(name, data, file)


def _from_dict(name: str, data: dict[str, Any], path: Traversable | None = None) -> Example:
    where = f"example {name!r}"

    def fail(msg: str) -> InputError:
        return InputError(f"{where}: {msg}")

    def need(key: str, types: type | tuple[type, ...], what: str) -> Any:
        if key not in data:
            raise fail(f"missing key {key!r}")
        value = data[key]
        if not isinstance(value, types) or isinstance(value, bool):
            raise fail(f"{key!r} must be {what}")
        return value

    title = need("title", str, "a string").strip()
    description = " ".join(need("description", str, "a string").split())
    params = _read_params(data.get("params"), fail)

    complex_eqs = complex_vars = None
    labels: dict[str, str] = {}
    if "complex" in data:
        complex_eqs = need("complex", list, "a list of equations")
        complex_vars = need("complex_variables", list, "a list of names")
        if not complex_eqs or not all(isinstance(e, str) and e.strip() for e in complex_eqs):
            raise fail("'complex' must be a list of equations (strings)")
        complex_eqs = [" ".join(e.split()) for e in complex_eqs]
        extra = data.get("formulas", [])
        if not isinstance(extra, list) or not all(isinstance(f, str) and f.strip() for f in extra):
            raise fail("'formulas' must be a list of non-empty strings")
        from ..complex_equations import split_complex

        try:
            texts, variables, labels = split_complex(complex_eqs, complex_vars, data.get("variables"),
                                                     allow_parameters=bool(params))
        except InputError as err:
            raise fail(f"'complex': {err}") from None
        formulas = texts + [" ".join(f.split()) for f in extra]
        n, k = len(variables), len(formulas)
        for key, value in (("n", n), ("k", k)):
            if key in data and data[key] != value:
                raise fail(f"{key!r} is {data[key]} but the complex equations give {key} = {value}")
        if not 1 <= k < n:
            raise fail(f"need fewer real equations than real variables, got n={n}, k={k}")
    else:
        n = need("n", int, "an integer")
        k = need("k", int, "an integer")
        if not 1 <= k < n:
            raise fail(f"need 1 <= k < n, got n={n}, k={k}")

        variables = need("variables", list, "a list of names")
        if len(variables) != n or not all(isinstance(v, str) and v.isidentifier() for v in variables):
            raise fail(f"'variables' must be {n} names")
        if len(set(variables)) != n:
            raise fail("'variables' has a repeated name")

        formulas = need("formulas", list, "a list of strings")
        if len(formulas) != k or not all(isinstance(f, str) and f.strip() for f in formulas):
            raise fail(f"'formulas' must be {k} non-empty strings (k = {k})")
        formulas = [" ".join(f.split()) for f in formulas]
    _check_formulas(formulas, variables, fail, bool(params))
    _check_params(formulas, variables, params, fail)

    raw_bounds = need("bounds", list, "a list of [lo, hi] pairs")
    if len(raw_bounds) == 1 and n > 1:
        raw_bounds = raw_bounds * n
    if len(raw_bounds) != n:
        raise fail(f"'bounds' needs {n} [lo, hi] pairs (or one for every axis), got {len(raw_bounds)}")
    bounds: list[tuple[float, float]] = []
    for axis, pair in enumerate(raw_bounds):
        if not isinstance(pair, list) or len(pair) != 2:
            raise fail(f"bounds of {variables[axis]} must be a pair [lo, hi]")
        try:
            lo, hi = (evaluate_constant(v) for v in pair)
        except InputError as err:
            raise fail(f"bounds of {variables[axis]}: {err}") from None
        if not lo < hi:
            raise fail(f"bounds of {variables[axis]}: lower {lo:g} must be below upper {hi:g}")
        bounds.append((lo, hi))

    div = _read_div(data.get("div"), n, "div", fail)
    if div is None:
        raise fail("missing key 'div'")
    paper_div = _read_div(data.get("paper_div"), n, "paper_div", fail)
    try:
        periodic = glued_axes(data.get("periodic"), variables, div)
    except InputError as err:
        raise fail(f"'periodic': {err}") from None

    start = need("start", list, f"a list of {n} numbers")
    if len(start) != n:
        raise fail(f"'start' must have {n} coordinates, got {len(start)}")
    try:
        start = [evaluate_constant(v) for v in start]
    except InputError as err:
        raise fail(f"'start': {err}") from None

    view = data.get("view", {})
    if not isinstance(view, dict):
        raise fail("[view] must be a table")
    m = min(3, n)
    project = view.get("project", list(variables[:m]))
    if (
        not isinstance(project, list)
        or len(project) != m
        or len(set(project)) != m
        or not all(p in variables for p in project)
    ):
        raise fail(f"view.project must be {m} different variables out of {variables}")
    color = view.get("color", variables[-1])
    if color not in variables:
        raise fail(f"view.color must be one of {variables}")
    mapping = view.get("mapping", "orthographic")
    if mapping not in VIEW_MAPPINGS:
        raise fail(f"view.mapping must be one of {', '.join(VIEW_MAPPINGS)}, got {mapping!r}")
    if mapping != "orthographic" and n < 4:
        raise fail(f"view.mapping {mapping!r} needs n >= 4: nothing is hidden in R^{n}")
    view = {"project": list(project), "color": color, "mapping": mapping}
    raw_labels = data.get("view", {}).get("labels", labels)
    if not isinstance(raw_labels, dict) or not all(
        v in variables and isinstance(text, str) for v, text in raw_labels.items()
    ):
        raise fail(f"view.labels must be a table {{variable: text}} over {variables}")

    return Example(
        name=name,
        title=title,
        description=description,
        n=n,
        k=k,
        variables=list(variables),
        formulas=formulas,
        bounds=bounds,
        div=div,
        start=start,
        view=view,
        paper_div=paper_div,
        path=path,
        params=params,
        complex=complex_eqs,
        complex_variables=list(complex_vars) if complex_vars is not None else None,
        labels=dict(raw_labels),
        periodic=periodic,
    )


def _read_div(value: object, n: int, key: str, fail: Callable[[str], InputError]) -> int | list[int] | None:
    """``value`` as a division (an int, or one int per axis); None when the key is absent."""
    if value is None:
        return None
    if isinstance(value, int) and not isinstance(value, bool):
        if value < 1:
            raise fail(f"{key!r} must be at least 1")
        return value
    if (
        isinstance(value, list)
        and len(value) == n
        and all(isinstance(d, int) and not isinstance(d, bool) and d >= 1 for d in value)
    ):
        return list(value)
    raise fail(f"{key!r} must be a positive integer or a list of {n} of them")


def _check_formulas(formulas: list[str], variables: list[str], fail: Callable[[str], InputError],
                    allow_parameters: bool = False) -> None:
    """Validate the formula texts with the safe parser."""
    for i, text in enumerate(formulas):
        try:
            check_component(text, variables, i, allow_parameters=allow_parameters)
        except InputError as err:
            raise fail(str(err)) from None


def _read_params(value: object, fail: Callable[[str], InputError]) -> dict[str, dict[str, float]]:
    """The [params] table: {name: {value, min, max}}, numbers or constant text, min <= value <= max."""
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise fail("[params] must be a table of { value = ..., min = ..., max = ... }")
    out: dict[str, dict[str, float]] = {}
    for name, spec in value.items():
        if not isinstance(spec, dict) or set(spec) != {"value", "min", "max"}:
            raise fail(f"params.{name} must be {{ value = ..., min = ..., max = ... }}")
        try:
            got = {key: evaluate_constant(spec[key]) for key in ("value", "min", "max")}
        except InputError as err:
            raise fail(f"params.{name}: {err}") from None
        if not got["min"] < got["max"] or not got["min"] <= got["value"] <= got["max"]:
            raise fail(f"params.{name}: need min < max and min <= value <= max, got {got}")
        out[name] = got
    return out


def _check_params(formulas: list[str], variables: list[str], params: dict, fail: Callable[[str], InputError]) -> None:
    """Every parameter of the formulas has a [params] entry, and every entry is used."""
    if not params:
        return
    try:
        found = find_parameters(formulas, variables)
    except InputError as err:
        raise fail(str(err)) from None
    for name in found:
        if name not in params:
            raise fail(f"parameter {name} has no entry in [params]")
    for name in params:
        if name not in found:
            raise fail(f"params.{name} does not appear in the formulas")
