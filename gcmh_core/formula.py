"""Formulas for F: R^n -> R^k, parsed safely and evaluated with numpy.

The text of each component is parsed with :mod:`ast` (``^`` means power) and
only a whitelist of nodes and names is accepted; the sympy expression is built
by hand from that tree.  User text never reaches ``eval``, ``exec``,
``sympify`` or ``parse_expr``.

Evaluation uses the sympy expressions after common-subexpression elimination
across all k components, compiled to a small tree of numpy calls.  On a grid,
variable ``a`` is an array of shape ``(1, .., len_a, .., 1)``, so numpy
broadcasting evaluates every subexpression on the sub-grid of the variables it
depends on; sums and products combine their terms smallest-support first.

>>> F = parse_system(["x^2 + y^2 + z^2 - 1", "z"], ["x", "y", "z"])
>>> F.evaluate_points([[1.0, 0.0, 0.0]]).tolist()
[[0.0, 0.0]]
>>> F.evaluate_grid([[0.0, 1.0], [0.0], [0.0, 0.5, 1.0]]).shape
(2, 1, 3, 2)
"""

from __future__ import annotations

import ast
import difflib
import functools
import itertools
import keyword
import math
import operator
import re
import reprlib
import unicodedata
import warnings
from collections.abc import Callable, Sequence

import numpy as np
import sympy
from sympy.core.logic import fuzzy_and

from .errors import InputError

__all__ = ["FormulaError", "System", "parse_system", "check_component", "evaluate_constant", "find_parameters"]

MAX_CHARS = 5000  # characters in one component
MAX_NODES = 2000  # expression nodes in one component
MAX_DEPTH = 100  # nesting depth of one component
MAX_EXPONENT = 64  # |constant exponent|
MAX_VARIABLES = 62  # n: a grid has at least 2^n vertices, and its keys are int64
_MAX_BITS = 1024  # exact rational constants larger than this are folded to float


def _parse_quietly(src: str) -> ast.Expression:
    """ast.parse without its SyntaxWarnings ("1if x" -> invalid decimal literal) on stderr:
    the one-line error is the whole message."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SyntaxWarning)
        warnings.simplefilter("ignore", DeprecationWarning)
        return ast.parse(src, mode="eval")


class FormulaError(InputError):
    """A formula or a variable list is wrong.

    ``component`` is the 0-based component index (None if not about one
    component), ``position`` the 1-based column in that component's text (or
    None), ``detail`` the bare description.
    """

    def __init__(self, detail: str, component: int | None = None, position: int | None = None):
        self.detail, self.component, self.position = detail, component, position
        where = []
        if component is not None:
            where.append(f"component {component + 1} (F{component + 1})")
        if position is not None:
            where.append(f"column {position}")
        super().__init__(f"{', '.join(where)}: {detail}" if where else detail)

    def __reduce__(self):  # keep the fields through pickling (worker processes)
        return (type(self), (self.detail, self.component, self.position))


# --------------------------------------------------------------------------- names

class _Pairwise(sympy.Function):
    """max/min of two arguments, kept as written.

    sympy.Max/Min compare every pair of their arguments, again whenever an
    expression is rebuilt (cse, diff) and flatten nested calls: max() with 400
    arguments took 84 s to parse.  max(a1, ..., am) is a balanced tree of these
    instead: about m nodes and log2(m) levels, built and differentiated in time
    linear in m.  The value is numpy's (np.maximum/np.minimum, nan propagates);
    the derivative is sympy's (Heaviside of the difference, 1/2 at a tie).
    """

    nargs = 2

    @classmethod
    def eval(cls, a, b):
        return None  # never simplified: that is the point

    def _eval_is_real(self):
        return fuzzy_and(a.is_real for a in self.args)

    def fdiff(self, argindex=1):
        a, b = self.args
        if (argindex == 1) == (self.func is _Max2):  # d max/da, d min/db
            return sympy.Heaviside(a - b)
        return sympy.Heaviside(b - a)


class _Max2(_Pairwise):
    pass


class _Min2(_Pairwise):
    pass


def _tree(pair, args):
    """pair(pair(a1, a2), pair(a3, a4))...: a balanced tree over args (in their order)."""
    while len(args) > 1:
        paired = [pair(args[i], args[i + 1]) for i in range(0, len(args) - 1, 2)]
        args = paired + args[len(args) - len(args) % 2:]
    return args[0]


def _max_of(*args):
    return _tree(_Max2, list(args))


def _min_of(*args):
    return _tree(_Min2, list(args))


def _minimum(*a):
    return functools.reduce(np.minimum, a)


def _maximum(*a):
    return functools.reduce(np.maximum, a)


# user name -> (sympy builder, numpy function, min args, max args (None: any))
_FUNCTIONS: dict[str, tuple[Callable, Callable, int, int | None]] = {
    "sin": (sympy.sin, np.sin, 1, 1),
    "cos": (sympy.cos, np.cos, 1, 1),
    "tan": (sympy.tan, np.tan, 1, 1),
    "asin": (sympy.asin, np.arcsin, 1, 1),
    "acos": (sympy.acos, np.arccos, 1, 1),
    "atan": (sympy.atan, np.arctan, 1, 1),
    "atan2": (sympy.atan2, np.arctan2, 2, 2),
    "sinh": (sympy.sinh, np.sinh, 1, 1),
    "cosh": (sympy.cosh, np.cosh, 1, 1),
    "tanh": (sympy.tanh, np.tanh, 1, 1),
    "exp": (sympy.exp, np.exp, 1, 1),
    "log": (sympy.log, np.log, 1, 1),
    "sqrt": (sympy.sqrt, np.sqrt, 1, 1),
    "abs": (sympy.Abs, np.abs, 1, 1),
    "min": (_min_of, _minimum, 2, None),
    "max": (_max_of, _maximum, 2, None),
}
_CONSTANTS = {"pi": sympy.pi, "e": sympy.E}

# sympy function class -> numpy function, for evaluation (Heaviside/sign come from derivatives)
_NUMPY: dict[object, Callable] = {sym: fn for sym, fn, _, _ in _FUNCTIONS.values() if isinstance(sym, type)}
_NUMPY.update({sympy.sign: np.sign, sympy.Heaviside: lambda x, h0=0.5: np.heaviside(x, h0),
               _Max2: np.maximum, _Min2: np.minimum})

_BINOPS = {  # ast op -> (symbol, sympy/python operator, numpy ufunc)
    ast.Add: ("+", operator.add, np.add),
    ast.Sub: ("-", operator.sub, np.subtract),
    ast.Mult: ("*", operator.mul, np.multiply),
    ast.Div: ("/", operator.truediv, np.divide),
    ast.Pow: ("**", operator.pow, np.power),
}
_BAD_OPS = {ast.FloorDiv: "//", ast.Mod: "%", ast.MatMult: "@", ast.LShift: "<<",
            ast.RShift: ">>", ast.BitOr: "|", ast.BitAnd: "&", ast.BitXor: "^",
            ast.Not: "not", ast.Invert: "~"}
_BAD_NODES = {ast.Attribute: "attribute access ('.')", ast.Subscript: "indexing ('[...]')",
              ast.Lambda: "lambda", ast.Compare: "comparisons", ast.BoolOp: "'and'/'or'",
              ast.IfExp: "'if ... else'", ast.ListComp: "comprehensions",
              ast.SetComp: "comprehensions", ast.DictComp: "comprehensions",
              ast.GeneratorExp: "comprehensions", ast.List: "lists", ast.Set: "sets",
              ast.Dict: "dicts", ast.JoinedStr: "strings", ast.NamedExpr: "':='",
              ast.Starred: "'*' unpacking"}


def _check_variables(variables) -> tuple[str, ...]:
    """Validate variable names: identifiers, unique, not function/constant names."""
    if isinstance(variables, str):  # "x, y, z" from a text field
        variables = [v for v in re.split(r"[\s,]+", variables) if v]
    try:
        names = tuple(variables)
    except TypeError:   # (a number where an example file or a session should list names)
        raise FormulaError(f"variables must be a list of names, got {reprlib.repr(variables)}") from None
    if not names:
        raise FormulaError("no variables given")
    if len(names) > MAX_VARIABLES:
        raise FormulaError(f"{len(names):,} variables: at most {MAX_VARIABLES} (a grid in R^n has at least 2^n "
                           "vertices)")
    seen: set[str] = set()   # (names[:i] made this quadratic: --n 100000 spent a minute here)
    for i, v in enumerate(names):
        if not isinstance(v, str) or not v.isidentifier() or keyword.iskeyword(v):
            raise FormulaError(f"variable {i + 1} ({v!r}) is not a valid name "
                               "(use letters, digits and '_', not starting with a digit)")
        if unicodedata.normalize("NFKC", v) != v:  # python would read it as another name
            raise FormulaError(f"variable name {v!r} is not in Unicode normal form "
                               f"(write {unicodedata.normalize('NFKC', v)!r})")
        if v in _FUNCTIONS or v in _CONSTANTS:
            kind = "function" if v in _FUNCTIONS else "constant"
            raise FormulaError(f"variable name {v!r} is the name of a {kind}")
        if v in seen:
            raise FormulaError(f"variable name {v!r} is given twice")
        seen.add(v)
    return names


# ------------------------------------------------------------------------- parsing

def _number(value: float) -> sympy.Expr:
    if math.isnan(value):
        return sympy.nan
    if math.isinf(value):
        return sympy.oo if value > 0 else -sympy.oo
    return sympy.Float(value)


_EXACT = (operator.add, operator.sub, operator.mul, operator.truediv, operator.pow, operator.neg)


def _fold(sym_op, np_op, args):
    """Constant subexpression: exact if small rationals, else float64 as numpy computes it
    (so log(0) is -inf and sqrt(-1) nan, never sympy's zoo or I)."""
    if any(a.has(sympy.I) for a in args):  # complex constants (complex_equations' i): exact
        return sym_op(*args)
    if all(a.is_Rational for a in args) and sym_op in _EXACT:
        a, b = args[0], args[-1]
        ok = not (sym_op is operator.truediv and b == 0)
        if sym_op is operator.pow:  # bound the size of an exact power before computing it
            bits = max(int(a.p).bit_length(), int(a.q).bit_length())
            ok = b.is_Integer and not (a == 0 and b < 0) and bits * abs(int(b)) <= _MAX_BITS
        if ok:
            r = sym_op(*args)
            if max(int(r.p).bit_length(), int(r.q).bit_length()) <= _MAX_BITS:
                return r
    with np.errstate(all="ignore"):
        return _number(float(np_op(*[np.float64(float(a)) for a in args])))


class _Builder:
    """Turns the whitelisted AST of one component into a sympy expression."""

    def __init__(self, text: str, index: int, variables: tuple[str, ...], symbols: dict,
                 params: dict | None = None, found: list | None = None):
        self.text, self.index, self.variables, self.symbols = text, index, variables, symbols
        # params: None (no parameters: an unknown name is an error), or {name: value or a
        # sympy symbol}; found collects (component, column, name) of the parameters met
        self.params, self.found = params, found
        # '^' -> '**' and line breaks -> ' '; cols maps each source char to its column in text
        parts: list[str] = []
        cols: list[int] = []
        for i, ch in enumerate(text):
            parts.append("**" if ch == "^" else " " if ch in "\r\n\t\f\v" else ch)
            cols += [i] * len(parts[-1])
        src = "".join(parts)
        lead = len(src) - len(src.lstrip(" "))  # ast rejects leading spaces
        self.src, self.cols = src[lead:], cols[lead:]
        self.utf8 = self.src.encode("utf-8")

    def error(self, detail, where=None):
        """Raise FormulaError; where is an AST node, or a 0-based index into self.src."""
        if isinstance(where, ast.AST):  # ast columns are utf-8 byte offsets
            where = len(self.utf8[:getattr(where, "col_offset", 0)].decode("utf-8", "ignore"))
        pos = None
        if where is not None:
            pos = self.cols[where] + 1 if where < len(self.cols) else len(self.text) + 1
        raise FormulaError(detail, self.index, pos)

    def parse(self) -> sympy.Expr:
        text = self.text
        if not text.strip():
            self.error("empty formula")
        if len(text) > MAX_CHARS:
            self.error(f"formula too long ({len(text)} characters, at most {MAX_CHARS})")
        if "#" in self.src:
            self.error("'#' is not allowed", self.src.index("#"))
        try:
            tree = _parse_quietly(self.src)
        except SyntaxError as e:
            msg = (e.msg or "invalid syntax").replace("Perhaps you forgot a comma?",
                                                      "Missing operator such as '*'?")
            if msg == "invalid decimal literal":
                msg += " (write 2*x, not 2x)"
            elif msg.startswith("Exceeds the limit"):
                msg = "number with too many digits"
            self.error(f"syntax error: {msg}", e.offset - 1 if e.offset and e.offset > 0 else None)
        except (RecursionError, MemoryError, ValueError):
            self.error("expression too complex (nested too deeply)")
        nodes = sum(isinstance(nd, ast.expr) for nd in ast.walk(tree))
        if nodes > MAX_NODES:
            self.error(f"expression too large ({nodes} nodes, at most {MAX_NODES})")
        try:
            return self.build(tree.body, 1)
        except FormulaError:
            raise
        except (TypeError, ValueError, ArithmeticError, RecursionError) as e:  # sympy surprises
            self.error(f"cannot build expression: {e}")

    def build(self, node, depth) -> sympy.Expr:
        if depth > MAX_DEPTH:
            self.error(f"expression nested too deeply (more than {MAX_DEPTH} levels)", node)
        if isinstance(node, ast.BinOp):
            if type(node.op) not in _BINOPS:
                self.error(f"operator '{_BAD_OPS.get(type(node.op), '?')}' is not supported",
                           self.op_index(node))
            if not isinstance(node.op, ast.Pow):  # a+b-c+... is one level, not a deep tree
                return self.chain(node, depth)
            a, b = self.build(node.left, depth + 1), self.build(node.right, depth + 1)
            _, sym_op, np_op = _BINOPS[type(node.op)]
            if sym_op is operator.pow and b.is_number and abs(float(b)) > MAX_EXPONENT:
                self.error(f"exponent {b} is too large (at most {MAX_EXPONENT} in absolute value)",
                           node.right)
            return _fold(sym_op, np_op, [a, b]) if a.is_number and b.is_number else sym_op(a, b)
        if isinstance(node, ast.UnaryOp):
            if not isinstance(node.op, (ast.USub, ast.UAdd)):
                self.error(f"operator '{_BAD_OPS[type(node.op)]}' is not supported", node)
            a = self.build(node.operand, depth + 1)
            if isinstance(node.op, ast.UAdd):
                return a
            return _fold(operator.neg, np.negative, [a]) if a.is_number else -a
        if isinstance(node, ast.Name):
            return self.name(node)
        if isinstance(node, ast.Call):
            return self.call(node, depth)
        if isinstance(node, ast.Constant):
            v = node.value
            if type(v) is int:
                return sympy.Integer(v)
            if type(v) is float:
                return _number(v)
            what = {complex: "imaginary numbers", str: "strings", bytes: "strings"}.get(
                type(v), f"{v!r}")
            self.error(f"{what} not allowed", node)
        if isinstance(node, ast.Tuple):
            self.error("a comma-separated list is not allowed (one formula per component)", node)
        self.error(f"{_BAD_NODES.get(type(node), type(node).__name__)} not allowed", node)

    def chain(self, node, depth):
        """Left-associated chain of + - (or * /): one level of nesting, and one sympy Add
        (Mul) of all terms, since adding terms one by one costs quadratic time."""
        add = isinstance(node.op, (ast.Add, ast.Sub))
        family = (ast.Add, ast.Sub) if add else (ast.Mult, ast.Div)
        rest = []
        while isinstance(node, ast.BinOp) and isinstance(node.op, family):
            rest.append((node.op, node.right))
            node = node.left
        terms = [self.build(node, depth + 1)]
        for op, right in reversed(rest):
            b = self.build(right, depth + 1)
            if isinstance(op, ast.Sub):
                b = _fold(operator.neg, np.negative, [b]) if b.is_number else -b
            elif isinstance(op, ast.Div):  # constant 1/b as numpy does it: 1/0 = inf
                b = _fold(operator.truediv, np.divide, [sympy.S.One, b]) if b.is_number else 1 / b
            terms.append(b)
        return sympy.Add(*terms) if add else sympy.Mul(*terms)

    def op_index(self, node):
        """0-based index of a binary operator in src (ast gives no position for it)."""
        start = len(self.utf8[:node.left.end_col_offset].decode("utf-8", "ignore"))
        sym = _BAD_OPS.get(type(node.op), "")
        i = self.src.find(sym, start) if sym else -1
        return i if i >= 0 else start

    def suggest(self, name, candidates):
        close = [c for c in candidates if c.lower() == name.lower()]
        close = close or difflib.get_close_matches(name, candidates, n=2, cutoff=0.6)
        return f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""

    def name(self, node):
        name = node.id
        if name in self.symbols:
            return self.symbols[name]
        if name in _CONSTANTS:
            return _CONSTANTS[name]
        if name in _FUNCTIONS:
            self.error(f"'{name}' is a function: write {name}(...)", node)
        m = re.fullmatch(r"([^\W\d]\w*?)(\d+)", name)
        n = len(self.variables)
        if m and self.variables == tuple(f"{m[1]}{i}" for i in range(1, n + 1)):
            self.error(f"{name} is outside {m[1]}1..{m[1]}{n} (n = {n})", node)
        hint = self.suggest(name, [*self.variables, *_CONSTANTS, *_FUNCTIONS])
        if self.params is not None:  # parameters allowed: a free name is one, given a value
            if self.found is not None:
                col = len(self.utf8[:node.col_offset].decode("utf-8", "ignore"))
                self.found.append((self.index, self.cols[col] if col < len(self.cols) else 0, name))
            if name in self.params:
                value = self.params[name]
                return value if isinstance(value, sympy.Symbol) else _number(value)
            self.error(f"parameter {name} has no value: pass params={{'{name}': ...}} "
                       f"or --param {name}=...{hint}", node)
        hint = hint or f" (variables: {', '.join(self.variables)}; a parameter needs a value: " \
            f"params={{'{name}': ...}} or --param {name}=...)"
        self.error(f"unknown name '{name}'{hint}", node)

    def call(self, node, depth):
        if not isinstance(node.func, ast.Name):
            what = _BAD_NODES.get(type(node.func), "calling an expression")
            self.error(f"{what} not allowed; only named functions can be called", node.func)
        name = node.func.id
        if name not in _FUNCTIONS:
            if name in self.symbols:
                self.error(f"'{name}' is a variable, not a function (write {name}*(...) "
                           "for a product)", node)
            if name in _CONSTANTS:
                self.error(f"'{name}' is a constant, not a function", node)
            self.error(f"unknown function '{name}'{self.suggest(name, list(_FUNCTIONS))}", node)
        if node.keywords:
            self.error(f"keyword arguments are not allowed in {name}(...)", node.keywords[0].value)
        sym_f, np_f, lo, hi = _FUNCTIONS[name]
        nargs = len(node.args)
        if nargs < lo or (hi is not None and nargs > hi):
            want = f"at least {lo} arguments" if hi is None else \
                f"{lo} argument{'s' if lo > 1 else ''}"
            self.error(f"{name}() takes {want}, got {nargs}", node)
        args = [self.build(a, depth + 1) for a in node.args]
        if all(a.is_number for a in args):
            return _fold(sym_f, np_f, args)
        if name in ("min", "max") and any(a is sympy.nan for a in args):
            return sympy.nan  # np.minimum/maximum propagate nan; sympy.Min refuses it
        try:
            return sym_f(*args)
        except (TypeError, ValueError):  # e.g. Min of a non-real expression: numpy gives nan
            return sympy.nan


# ---------------------------------------------------------------------- evaluation

def _support(expr, deps) -> frozenset:
    """Axes (variable indices) that expr depends on."""
    return frozenset().union(*(deps[s] for s in expr.free_symbols))


def _constant(expr):
    if expr is sympy.I:  # only from sympy rewriting e.g. sqrt(-x**2); numpy would give nan
        return np.float64(np.nan)
    if expr is sympy.zoo:  # x/0 -> zoo*x; inf*x has numpy's signs for x/0
        return np.float64(np.inf)
    return np.float64(float(expr))


def _reduce(ufunc, items):
    """Combine (support, fn) items with ufunc, merging the pair with the smallest joint
    support first so that terms on small sub-grids meet before being broadcast."""
    groups: dict = {}
    for sup, fn in items:  # same support: same shape, combine freely
        groups.setdefault(sup, []).append(fn)
    items = [(sup, _chain(ufunc, fns)) for sup, fns in groups.items()]
    items.sort(key=lambda it: (len(it[0]), sorted(it[0])))
    while len(items) > 1:
        if len(items) <= 24:
            i, j = min(itertools.combinations(range(len(items)), 2),
                       key=lambda p: len(items[p[0]][0] | items[p[1]][0]))
        else:
            i, j = 0, 1
        (si, fi), (sj, fj) = items[i], items.pop(j)
        items[i] = (si | sj, _chain(ufunc, [fi, fj]))
    return items[0][1]


def _chain(ufunc, fns):
    if len(fns) == 1:
        return fns[0]

    def f(env):
        acc = fns[0](env)
        for g in fns[1:]:
            acc = ufunc(acc, g(env))
        return acc
    return f


def _compile(expr, slots, deps):
    """A closure env -> value of expr (array or np.float64); env[slots[symbol]] holds arrays."""
    if expr in slots:
        i = slots[expr]
        return lambda env: env[i]
    if expr.is_Number or expr.is_NumberSymbol or expr in (sympy.I, sympy.zoo):
        v = _constant(expr)
        return lambda env: v

    def sub(e):
        return _support(e, deps), _compile(e, slots, deps)

    if expr.is_Add:
        return _reduce(np.add, [sub(a) for a in expr.args])
    if expr.is_Mul:  # a*b**-2 -> a/b**2: fewer operations, better rounding
        num, den = [], []
        for a in expr.args:
            if a.is_Pow and a.exp.is_Number and a.exp < 0:
                den.append(a.base ** -a.exp)
            else:
                num.append(a)
        f = _reduce(np.multiply, [sub(a) for a in num]) if num else (lambda env: 1.0)
        if not den:
            return f
        g = _reduce(np.multiply, [sub(a) for a in den])
        return lambda env: np.divide(f(env), g(env))
    if expr.is_Pow:
        b, p = _compile(expr.base, slots, deps), expr.exp
        if p == sympy.S.Half:
            return lambda env: np.sqrt(b(env))
        if p == -sympy.S.Half:
            return lambda env: np.divide(1.0, np.sqrt(b(env)))
        if p == -1:
            return lambda env: np.divide(1.0, b(env))
        if p == 2:
            return lambda env: np.square(b(env))
        if p.is_Number:
            c = _constant(p)
            return lambda env: np.power(b(env), c)
        q = _compile(p, slots, deps)
        return lambda env: np.power(b(env), q(env))
    found = _NUMPY.get(expr.func)
    if found is None:
        raise TypeError(f"cannot evaluate {expr.func.__name__} in {expr}")
    fn: Callable = found
    fs = [_compile(a, slots, deps) for a in expr.args]
    return lambda env: fn(*[g(env) for g in fs])


class _Program:
    """Expressions over `symbols` after cse, compiled to numpy closures.

    run(columns) takes one array per symbol (any mutually broadcastable shapes)
    and returns one array or scalar per expression.
    """

    def __init__(self, exprs, symbols):
        temps, outs = sympy.cse(list(exprs), symbols=(sympy.Dummy() for _ in itertools.count()))
        slots = {s: i for i, s in enumerate(symbols)}
        deps = {s: frozenset([i]) for i, s in enumerate(symbols)}
        self.nslots = len(symbols) + len(temps)
        self.steps: list[tuple[int | None, Callable]] = []
        uses = []
        for t, e in temps:
            self.steps.append((len(slots), _compile(e, slots, deps)))
            deps[t], slots[t] = _support(e, deps), len(slots)
            uses.append(e.free_symbols)
        for e in outs:
            self.steps.append((None, _compile(e, slots, deps)))
            uses.append(e.free_symbols)
        # drop each temporary after its last use (full-grid temporaries are big)
        last = {slots[s]: i for i, used in enumerate(uses) for s in used
                if slots[s] >= len(symbols)}
        self.drops = [[s for s, i in last.items() if i == step] for step in range(len(uses))]

    def run(self, columns) -> list:
        env = list(columns) + [None] * (self.nslots - len(columns))
        out: list = []
        with np.errstate(all="ignore"):
            for (slot, fn), drop in zip(self.steps, self.drops):
                if slot is None:
                    out.append(fn(env))
                else:
                    env[slot] = fn(env)
                for s in drop:
                    env[s] = None
        return out


# -------------------------------------------------------------------------- public

class System:
    """F: R^n -> R^k given by the text of its k components over n named variables.

    Attributes: ``n``, ``k``, ``variables`` (tuple of n names), ``texts`` (tuple
    of k strings), ``exprs`` (tuple of k sympy expressions, parameters replaced by
    their values), ``symbols`` (the n sympy symbols, real), ``parameters`` (the
    free names of the texts, in order of appearance) and ``params`` ({name: value}).
    Pickles as its texts, variables and params; the numpy programs are compiled on
    first use.  Prefer :func:`parse_system`.
    """

    def __init__(self, texts: Sequence[str], variables: Sequence[str], params: dict | None = None):
        self.variables = _check_variables(variables)
        self.texts = tuple(texts)
        self.n, self.k = len(self.variables), len(self.texts)
        self.symbols = tuple(sympy.Symbol(v, real=True) for v in self.variables)
        values = None if params is None else _check_params(params, self.variables)
        names = dict(zip(self.variables, self.symbols))
        for i, t in enumerate(self.texts):
            if not isinstance(t, str):
                raise FormulaError(f"expected a string, got {type(t).__name__}", i)
        found: list = []
        self.exprs = tuple(_Builder(t, i, self.variables, names, values, found).parse()
                           for i, t in enumerate(self.texts))
        self.parameters = _in_order(found)
        unused = [p for p in (values or {}) if p not in self.parameters]
        if unused:
            raise FormulaError(f"parameter {unused[0]} does not appear in the formulas"
                               + (f" (their parameters: {', '.join(self.parameters)})"
                                  if self.parameters else " (they have none)"))
        # the values substituted, in the order of appearance ({} without parameters)
        self.params = {p: values[p] for p in self.parameters} if values else {}

    def __reduce__(self):  # (worker processes parse again, with the same values)
        return (type(self), (self.texts, self.variables, self.params or None))

    def __repr__(self):
        extra = f", params={self.params!r}" if self.params else ""
        return f"System(texts={self.texts!r}, variables={self.variables!r}{extra})"

    @functools.cached_property
    def _program(self) -> _Program:
        return _Program(self.exprs, self.symbols)

    @functools.cached_property
    def _jacobian_program(self) -> _Program:
        return _Program([sympy.diff(e, s) for e in self.exprs for s in self.symbols], self.symbols)

    def _points(self, P) -> np.ndarray:
        P = np.asarray(P, dtype=np.float64)  # float64: integer powers must not overflow
        if P.ndim != 2 or P.shape[1] != self.n:
            raise InputError(f"points must have shape (m, {self.n}), got {P.shape}")
        return P

    def evaluate_points(self, P) -> np.ndarray:
        """F at the rows of P: (m, n) -> (m, k) float64. Never raises on nan/inf."""
        P = self._points(P)
        values = self._program.run(list(np.ascontiguousarray(P.T)))
        out = np.empty((P.shape[0], self.k))
        for j, v in enumerate(values):
            out[:, j] = v  # broadcasts constant components
        return out

    def evaluate_grid(self, axes: Sequence, out: np.ndarray | None = None) -> np.ndarray:
        """F on the grid axes[0] x ... x axes[n-1] (n 1-D arrays of lengths d_a + 1):
        returns (d_0+1, ..., d_{n-1}+1, k) float64, written into `out` when given (a
        reused buffer: first touching a fresh one cost more than evaluating).  Each
        subexpression is evaluated on the sub-grid of the variables it depends on
        (numpy broadcasting)."""
        if len(axes) != self.n:
            raise InputError(f"expected {self.n} grid axes, got {len(axes)}")
        cols = []
        for a, ax in enumerate(axes):
            ax = np.asarray(ax, dtype=np.float64)
            if ax.ndim != 1:
                raise InputError(f"grid axis {a} must be 1-D, got shape {ax.shape}")
            cols.append(ax.reshape([-1 if b == a else 1 for b in range(self.n)]))
        shape = tuple(c.size for c in cols) + (self.k,)
        if out is None:
            out = np.empty(shape)
        elif out.shape != shape or out.dtype != np.float64:
            raise InputError(f"out must be a float64 array of shape {shape}, got {out.dtype} {out.shape}")
        for j, v in enumerate(self._program.run(cols)):
            out[..., j] = v  # broadcast to the full grid
        return out

    def jacobian_points(self, P) -> np.ndarray:
        """Exact Jacobian dF_j/dx_a at the rows of P: (m, n) -> (m, k, n) float64."""
        P = self._points(P)
        values = self._jacobian_program.run(list(np.ascontiguousarray(P.T)))
        out = np.empty((P.shape[0], self.k * self.n))
        for j, v in enumerate(values):
            out[:, j] = v
        return out.reshape(P.shape[0], self.k, self.n)


def parse_system(components: Sequence[str] | str, variables: Sequence[str] | str | None = None,
                 *, n: int | None = None, k: int | None = None, params: dict | None = None) -> System:
    """Parse k formulas over n variables into a :class:`System`.

    ``variables`` defaults to x1..xn (then ``n`` is required); a string
    "x, y, z" is split on commas/spaces.  ``k``, if given, must equal the
    number of components.  Raises :class:`FormulaError`.

    ``params`` ({name: number or constant text such as "pi/4"}) allows parameters:
    a name that is neither a variable nor a constant or function is a parameter,
    replaced by its value exactly as if the value were written in the text as a
    float literal (same expressions, same output).  Every parameter of the text
    needs a value, and every value a parameter.  Without ``params`` an unknown
    name is an error (with a "did you mean" for names close to a variable or a
    function), so a typo never becomes a parameter.

    >>> parse_system(["x^2 + y^2 - a"], "x, y", params={"a": 0.25}).params
    {'a': 0.25}
    """
    comps = [components] if isinstance(components, str) else list(components)
    if not comps:
        raise FormulaError("no formulas given")
    if k is not None and k != len(comps):
        raise FormulaError(f"expected k = {k} formulas (one per component), got {len(comps)}")
    if n is not None:
        try:
            n = operator.index(n)
        except TypeError:
            raise FormulaError(f"n must be an integer, got {n!r}") from None
        if n < 1:
            raise FormulaError(f"n must be at least 1, got {n}")
    if variables is None:
        if n is None:
            raise FormulaError("give the variable names or n (for x1..xn)")
        variables = [f"x{i}" for i in range(1, n + 1)]
    variables = _check_variables(variables)
    if n is not None and n != len(variables):
        raise FormulaError(f"n = {n} but {len(variables)} variables given: {', '.join(variables)}")
    values = None if params is None else _check_params(params, variables)
    if all(isinstance(c, str) for c in comps):
        key = None if values is None else tuple(values.items())
        return _cached_system(tuple(comps), tuple(variables), key)
    return System(comps, variables, values)  # (raises the FormulaError that names the bad component)


@functools.lru_cache(maxsize=64)
def _cached_system(texts: tuple, variables: tuple, params: tuple | None = None) -> System:
    """One System per formula text: parsing and compiling it (sympy's cse) took longer
    than a whole small extraction, which the app and the benchmark repeat with a new div."""
    return System(texts, variables, None if params is None else dict(params))


def _check_params(params, variables: Sequence[str]) -> dict[str, float]:
    """{name: float} from {name: number or constant text}; one clear message per mistake."""
    if not isinstance(params, dict):
        raise FormulaError(f"params must be a dict {{name: value}}, got {params!r}")
    out: dict[str, float] = {}
    for name, value in params.items():
        if not isinstance(name, str) or not name.isidentifier() or keyword.iskeyword(name):
            raise FormulaError(f"parameter name {name!r} is not a valid name")
        if name in _FUNCTIONS or name in _CONSTANTS:
            kind = "function" if name in _FUNCTIONS else "constant"
            raise FormulaError(f"parameter name {name!r} is the name of a {kind}")
        if name in variables:
            raise FormulaError(f"parameter name {name!r} is a variable")
        try:
            out[name] = evaluate_constant(value)
        except InputError as err:
            raise FormulaError(f"value of parameter {name}: {err}") from None
    return out


def _in_order(found: list) -> tuple[str, ...]:
    """Parameter names from (component, column, name) records: each once, first seen first."""
    names: dict[str, None] = {}
    for _, _, name in sorted(found):
        names.setdefault(name, None)
    return tuple(names)


def find_parameters(texts: Sequence[str] | str, variables: Sequence[str] | str) -> list[str]:
    """The parameters of the formulas: names that are neither a variable nor a constant
    or function, each once, in order of appearance (component by component, left to
    right) -- one slider each.  Raises FormulaError for any other mistake in the text.

    >>> find_parameters(["x^2 + y^2 - z^2 - a", "b*x"], "x, y, z")
    ['a', 'b']
    """
    names = _check_variables(variables)
    symbols = {v: sympy.Symbol(v, real=True) for v in names}
    comps = [texts] if isinstance(texts, str) else list(texts)
    found: list = []
    free = _FreeNames()
    for i, t in enumerate(comps):
        if not isinstance(t, str):
            raise FormulaError(f"expected a string, got {type(t).__name__}", i)
        _Builder(t, i, names, symbols, free, found).parse()
    return list(_in_order(found))


class _FreeNames(dict):
    """params for listing them: every free name has a value, its own (real) symbol."""

    def __contains__(self, name) -> bool:
        return True

    def __getitem__(self, name):
        return sympy.Symbol(name, real=True)


def check_component(text: str, variables: Sequence[str] | str, index: int = 0, *,
                    allow_parameters: bool = False) -> None:
    """Raise FormulaError (with component=index) if text is not a valid formula;
    with allow_parameters, free names are parameters (see :func:`find_parameters`)."""
    names = _check_variables(variables)
    symbols = {v: sympy.Symbol(v, real=True) for v in names}
    if not isinstance(text, str):
        raise FormulaError(f"expected a string, got {type(text).__name__}", index)
    _Builder(text, index, names, symbols, _FreeNames() if allow_parameters else None).parse()


# --------------------------------------------------------------------------
# Constant text ("-pi/2", "2*pi", "sqrt(2)/2"): bounds, example files, the app's fields
# --------------------------------------------------------------------------

_CONST_NAMES = {"pi": math.pi, "e": math.e, "tau": math.tau}
_CONST_FUNCS = {
    "sqrt": math.sqrt,
    "sin": math.sin,
    "cos": math.cos,
    "tan": math.tan,
    "exp": math.exp,
    "log": math.log,
    "abs": abs,
}
_CONST_BINOPS = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: lambda a, b: a**b,
    ast.BitXor: lambda a, b: a**b,  # "2^3" written the mathematical way
}
_CONST_MAX_TEXT = 200


def evaluate_constant(text: str | int | float) -> float:
    """Value of a numeric constant expression such as ``"-pi/2"`` or ``"2*pi"``.

    Allowed: numbers, ``pi``, ``e``, ``tau``, ``+ - * / **`` (and ``^`` for
    power), unary minus/plus, parentheses and the functions sqrt, sin, cos,
    tan, exp, log, abs of one argument (``π`` is ``pi``). The expression is parsed with :mod:`ast`
    and walked against a whitelist; it is never evaluated by Python.

    Raises :class:`InputError` with a one-line message for anything else, or
    when the value is not a finite real number.
    """
    if isinstance(text, bool):
        raise InputError(f"expected a number, got {text!r}")
    if isinstance(text, (int, float)):
        value = float(text)
        if not math.isfinite(value):
            raise InputError(f"number {text!r} is not finite")
        return value
    if not isinstance(text, str):
        raise InputError(f"expected a number or a constant expression, got {text!r}")
    src = text.strip().replace("π", "pi")
    if not src:
        raise InputError("empty number")
    # ``^`` is power, as in formulas: read as Python's XOR it bound looser than unary minus and
    # products (-0.5^2 was +0.25, 2*3^2 was 36); as ``**`` it binds tighter and to the right.
    expr = src.replace("^", "**")
    if len(src) > _CONST_MAX_TEXT:
        raise InputError(f"constant expression longer than {_CONST_MAX_TEXT} characters")
    try:
        tree = _parse_quietly(expr)
    except SyntaxError:
        raise InputError(f"cannot read {src!r} as a number (e.g. 1.5, -pi/2, 2*pi)") from None
    try:
        value = _walk_constant(tree.body, src)
    except (OverflowError, ZeroDivisionError, ValueError) as err:
        if isinstance(err, InputError):
            raise
        raise InputError(f"cannot evaluate {src!r}: {err}") from None
    if not math.isfinite(value):
        raise InputError(f"{src!r} is not a finite number")
    return value


def _walk_constant(node: ast.AST, src: str) -> float:
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise InputError(f"cannot read {src!r} as a number: unexpected {node.value!r}")
        return float(node.value)
    if isinstance(node, ast.Name):
        if node.id in _CONST_NAMES:
            return _CONST_NAMES[node.id]
        raise InputError(
            f"cannot read {src!r} as a number: unknown name {node.id!r} "
            f"(allowed: {', '.join(sorted(_CONST_NAMES))})"
        )
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        value = _walk_constant(node.operand, src)
        return -value if isinstance(node.op, ast.USub) else value
    if isinstance(node, ast.BinOp) and type(node.op) in _CONST_BINOPS:
        left = _walk_constant(node.left, src)
        right = _walk_constant(node.right, src)
        if type(node.op) in (ast.Pow, ast.BitXor) and abs(right) > 1e4:
            raise InputError(f"cannot evaluate {src!r}: exponent too large")
        result = _CONST_BINOPS[type(node.op)](left, right)
        if isinstance(result, complex):
            raise InputError(f"cannot evaluate {src!r}: result is not real")
        return float(result)
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id in _CONST_FUNCS
        and len(node.args) == 1
        and not node.keywords
    ):
        function: Callable[[float], float] = _CONST_FUNCS[node.func.id]  # type: ignore[assignment]
        return float(function(_walk_constant(node.args[0], src)))
    col = getattr(node, "col_offset", None)
    where = f" at column {col + 1}" if col is not None else ""
    raise InputError(f"cannot read {src!r} as a number: unsupported syntax{where}")


