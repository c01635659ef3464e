"""Tests for gcmh_core.formula: safe parsing, point/grid/Jacobian evaluation, errors."""

import math
import pickle

import numpy as np
import pytest
import sympy

from gcmh_core import formula
from gcmh_core.errors import InputError
from gcmh_core.formula import FormulaError, System, check_component, evaluate_constant, parse_system

KLEIN = [
    "cos(s)*(3+cos(s/2)*sin(t)-sin(s/2)*sin(2*t))-x",
    "sin(s)*(3+cos(s/2)*sin(t)-sin(s/2)*sin(2*t))-y",
    "sin(s/2)*sin(t)+cos(s/2)*sin(2*t)-z",
]
KLEIN_VARS = ["x", "y", "z", "s", "t"]
COMPLEX_COS = ["z1 - cos(w1)*cosh(w2)", "z2 + sin(w1)*sinh(w2)"]
COMPLEX_VARS = ["w1", "w2", "z1", "z2"]


def klein_ref(P):
    x, y, z, s, t = P.T
    r = 3 + np.cos(s / 2) * np.sin(t) - np.sin(s / 2) * np.sin(2 * t)
    return np.stack([np.cos(s) * r - x, np.sin(s) * r - y,
                     np.sin(s / 2) * np.sin(t) + np.cos(s / 2) * np.sin(2 * t) - z], axis=1)


def complex_ref(P):
    w1, w2, z1, z2 = P.T
    return np.stack([z1 - np.cos(w1) * np.cosh(w2), z2 + np.sin(w1) * np.sinh(w2)], axis=1)


def grid_points(axes):
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(axes))


@pytest.fixture
def rng():
    return np.random.default_rng(1)


# ------------------------------------------------------------------ evaluation

@pytest.mark.parametrize("texts, variables, ref", [
    (KLEIN, KLEIN_VARS, klein_ref),
    (COMPLEX_COS, COMPLEX_VARS, complex_ref),
])
def test_points_and_grid_match_numpy(texts, variables, ref, rng):
    F = parse_system(texts, variables, k=len(texts))
    assert (F.n, F.k, F.variables, F.texts) == (len(variables), len(texts), tuple(variables),
                                                tuple(texts))
    P = rng.uniform(-3, 3, (200, F.n))
    np.testing.assert_allclose(F.evaluate_points(P), ref(P), rtol=1e-13, atol=1e-13)
    axes = [rng.uniform(-3, 3, 3 + a) for a in range(F.n)]
    G = F.evaluate_grid(axes)
    assert G.shape == tuple(len(a) for a in axes) + (F.k,) and G.dtype == np.float64
    M = grid_points(axes)
    np.testing.assert_allclose(G.reshape(-1, F.k), F.evaluate_points(M), rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(G.reshape(-1, F.k), ref(M), rtol=1e-13, atol=1e-13)


def test_default_variables_and_sphere():
    F = parse_system(["x1^2 + x2^2 + x3^2 - 1"], n=3)
    assert F.variables == ("x1", "x2", "x3")
    assert F.evaluate_points([[1, 0, 0], [0, 0, 2]]).tolist() == [[0.0], [3.0]]


def test_caret_is_power(rng):
    a = parse_system(["x^2*y^-1 + 2^x - x^y^2 + (-x)^3", "e^x"], ["x", "y"])
    b = parse_system(["x**2*y**-1 + 2**x - x**y**2 + (-x)**3", "exp(x)"], ["x", "y"])
    assert a.exprs == b.exprs
    P = rng.uniform(0.5, 2, (50, 2))
    x, y = P.T
    np.testing.assert_allclose(a.evaluate_points(P)[:, 0],
                               x**2 / y + 2**x - x**(y**2) - x**3, rtol=1e-13)


def test_functions_and_constants(rng):
    texts = ["min(x, y, z) + max(x, -y)", "atan2(y, x) - abs(z)", "asin(x/4) + acos(y/4) + atan(z)",
             "tan(x) + tanh(y) + log(abs(z)+1) + sqrt(abs(x)) + 1.5e-1*pi - e", "-+-x + 0.5"]
    F = parse_system(texts, "x y z")
    P = rng.uniform(-3, 3, (100, 3))
    x, y, z = P.T
    ref = np.stack([np.minimum(np.minimum(x, y), z) + np.maximum(x, -y),
                    np.arctan2(y, x) - np.abs(z),
                    np.arcsin(x / 4) + np.arccos(y / 4) + np.arctan(z),
                    np.tan(x) + np.tanh(y) + np.log(np.abs(z) + 1) + np.sqrt(np.abs(x))
                    + 0.15 * np.pi - np.e,
                    x + 0.5], axis=1)
    np.testing.assert_allclose(F.evaluate_points(P), ref, rtol=1e-12, atol=1e-12)
    axes = [rng.uniform(-3, 3, 4), rng.uniform(-3, 3, 5), rng.uniform(-3, 3, 2)]
    np.testing.assert_allclose(F.evaluate_grid(axes).reshape(-1, 5), F.evaluate_points(
        grid_points(axes)), rtol=1e-13, atol=1e-13)


def test_constant_and_partial_components_broadcast_on_grid():
    F = parse_system(["1", "x2", "2*pi - 1", "x1*x3"], n=3)
    axes = [np.arange(2.0), np.arange(3.0), np.arange(4.0)]
    G = F.evaluate_grid(axes)
    assert G.shape == (2, 3, 4, 4)
    assert (G[..., 0] == 1).all() and np.allclose(G[..., 2], 2 * np.pi - 1)
    assert (G[..., 1] == np.arange(3.0)[None, :, None]).all()
    assert (G[..., 3] == np.arange(2.0)[:, None, None] * np.arange(4.0)).all()
    assert F.evaluate_points(np.zeros((5, 3)))[:, 0].tolist() == [1.0] * 5


def test_subexpressions_are_evaluated_on_subgrids(monkeypatch):
    seen = []

    def recording_cos(a):
        seen.append(np.shape(a))
        return np.cos(a)

    monkeypatch.setitem(formula._NUMPY, sympy.cos, recording_cos)
    F = parse_system(["cos(s) - x", "cos(s)*cos(t) + y"], "x y s t")
    axes = [np.linspace(0, 1, 20), np.linspace(0, 1, 30), np.linspace(0, 6, 40), np.linspace(0, 6, 50)]
    G = F.evaluate_grid(axes)
    assert sorted(seen) == [(1, 1, 1, 50), (1, 1, 40, 1)]  # cos(s) computed once (cse), on its axis
    x, y, s, t = np.meshgrid(*axes, indexing="ij", sparse=True)
    np.testing.assert_array_equal(G[..., 0], np.broadcast_to(np.cos(s) - x, G.shape[:-1]))
    np.testing.assert_allclose(G[..., 1], np.broadcast_to(np.cos(s) * np.cos(t) + y, G.shape[:-1]),
                               rtol=1e-15)


def test_integer_input_does_not_overflow():
    F = parse_system(["x^40 - y^3"], "x y")
    out = F.evaluate_points(np.array([[10, 2000000]], dtype=np.int64))
    np.testing.assert_allclose(out, [[1e40 - 8e18]])
    assert F.evaluate_grid([np.array([10]), np.array([3])]).tolist() == [[[1e40 - 27]]]


def test_nan_and_inf_do_not_raise():
    F = parse_system(["log(x)", "sqrt(x)", "1/x", "log(0) + x", "sqrt(-1)", "x/0", "exp(1000*x)"], "x")
    with np.errstate(all="raise"):  # the evaluator must silence numpy itself
        v = F.evaluate_points([[0.0], [-1.0], [np.nan], [np.inf]])
        g = F.evaluate_grid([np.array([0.0, -1.0])])
        J = F.jacobian_points([[0.0], [-1.0]])
    assert v[0, 0] == -np.inf and np.isnan(v[1, 0]) and np.isnan(v[1, 1]) and v[0, 2] == np.inf
    assert (v[:2, 3] == -np.inf).all() and np.isnan(v[:, 4]).all() and v[1, 5] == -np.inf
    assert np.isnan(v[2, [0, 1, 2, 4, 5, 6]]).all() and v[3, 6] == np.inf  # sympy: -oo + x = -oo
    np.testing.assert_array_equal(g.reshape(2, -1), v[:2])
    assert J.shape == (2, 7, 1) and J[0, 0, 0] == np.inf


def test_jacobian_is_exact(rng):
    F = parse_system(KLEIN, KLEIN_VARS)
    P = rng.uniform(-3, 3, (30, 5))
    J = F.jacobian_points(P)
    assert J.shape == (30, 3, 5)
    h = 1e-6
    for a in range(5):
        d = np.zeros(5)
        d[a] = h
        fd = (F.evaluate_points(P + d) - F.evaluate_points(P - d)) / (2 * h)
        np.testing.assert_allclose(J[:, :, a], fd, atol=1e-7)
    G = parse_system(["x*y + min(x, y)", "abs(x) - atan2(y, x)"], "x y")
    np.testing.assert_allclose(G.jacobian_points([[2.0, 1.0]]),
                               [[[1 + 0, 2 + 1], [1 + 1 / 5, -2 / 5]]], rtol=1e-14)


def test_pickle_roundtrip(rng):
    F = parse_system(COMPLEX_COS, COMPLEX_VARS)
    P = rng.uniform(-1, 1, (10, 4))
    F.evaluate_points(P)  # compiled programs must not break pickling
    G = pickle.loads(pickle.dumps(F))
    assert isinstance(G, System) and G.texts == F.texts and G.variables == F.variables
    np.testing.assert_array_equal(G.evaluate_points(P), F.evaluate_points(P))
    e = pickle.loads(pickle.dumps(FormulaError("bad", 1, 3)))
    assert (e.detail, e.component, e.position, str(e)) == ("bad", 1, 3, "component 2 (F2), column 3: bad")


def test_whitespace_and_newlines_are_allowed():
    F = parse_system(["  x +\n  y\t", "(x\n*y)"], "x y")
    assert F.evaluate_points([[2.0, 3.0]]).tolist() == [[5.0, 6.0]]


def test_bad_evaluation_arguments():
    F = parse_system(["x + y"], "x y")
    for call in (lambda: F.evaluate_points(np.zeros((3, 3))), lambda: F.evaluate_points(np.zeros(2)),
                 lambda: F.evaluate_grid([np.zeros(2)]), lambda: F.evaluate_grid([np.zeros((2, 2))] * 2)):
        with pytest.raises(InputError):
            call()


# ------------------------------------------------------------------ errors

VARS5 = ["x1", "x2", "x3", "x4", "x5"]
ANY = object()  # position not checked


@pytest.mark.parametrize("texts, variables, component, position, words", [
    (["x1", "sin(x1"], VARS5, 1, 4, "never closed"),
    (["x1 + * x2"], VARS5, 0, 6, "syntax error"),
    (["2x1"], VARS5, 0, 1, "2*x"),
    (["x1", "x2 + sinn(x1)"], VARS5, 1, 6, "did you mean 'sin'"),
    (["x1 + foo"], VARS5, 0, 6, "unknown name 'foo'"),
    (["x1 + PI"], VARS5, 0, 6, "did you mean 'pi'"),
    (["x1 + x7"], VARS5, 0, 6, "x7 is outside x1..x5"),
    (["x0"], VARS5, 0, 1, "x0 is outside x1..x5"),
    (["cos + x1"], VARS5, 0, 1, "'cos' is a function"),
    (["x1 + x2(3)"], VARS5, 0, 6, "'x2' is a variable, not a function"),
    (["pi(2)"], VARS5, 0, 1, "constant"),
    (["sin(x1, x2)"], VARS5, 0, 1, "sin() takes 1 argument, got 2"),
    (["atan2(x1)"], VARS5, 0, 1, "atan2() takes 2 arguments"),
    (["max(x1)"], VARS5, 0, 1, "at least 2"),
    (["x1", "x2", "   "], VARS5, 2, None, "empty"),
    ([""], VARS5, 0, None, "empty"),
    (["x1^65"], VARS5, 0, 4, "exponent"),
    (["x1 ** (-100)"], VARS5, 0, 8, "exponent"),
    (["2^(8*9)"], VARS5, 0, 4, "exponent"),
    (["x1 + " * 1300 + "1"], VARS5, 0, None, "too long"),
    (["+".join(["1"] * 1500)], VARS5, 0, None, "too large"),
    (["sin(" * 150 + "x1" + ")" * 150], VARS5, 0, 401, "nested too deeply"),
    (["-" * 1000 + "x1"], VARS5, 0, ANY, "nested too deeply"),
    (["x1 % 2"], VARS5, 0, 4, "'%'"),
    (["x1 // 2"], VARS5, 0, 4, "'//'"),
    (["x1 | 2"], VARS5, 0, 4, "'|'"),
    (["~x1"], VARS5, 0, 1, "'~'"),
    (["lambda: 1"], VARS5, 0, 1, "lambda"),
    (["x1.real"], VARS5, 0, 1, "attribute"),
    (["x1[0]"], VARS5, 0, 1, "indexing"),
    (["[x1 for x1 in x2]"], VARS5, 0, 1, "not allowed"),
    (["'a' + x1"], VARS5, 0, 1, "strings"),
    (["1j*x1"], VARS5, 0, 1, "imaginary"),
    (["x1 < x2"], VARS5, 0, 1, "comparisons"),
    (["x1 and x2"], VARS5, 0, 1, "'and'/'or'"),
    (["sin(x=x1)"], VARS5, 0, 7, "keyword"),
    (["sin(*x1)"], VARS5, 0, 5, "unpacking"),
    (["x1, x2"], VARS5, 0, 1, "comma"),
    (["(y := 2)"], VARS5, 0, 2, "':='"),
    (["x1 # comment"], VARS5, 0, 4, "'#'"),
    (["True + x1"], VARS5, 0, 1, "not allowed"),
    (["θ + φ"], ["θ"], 0, 5, "unknown name 'φ'"),
])
def test_errors(texts, variables, component, position, words):
    with pytest.raises(FormulaError) as info:
        parse_system(texts, variables)
    e = info.value
    assert isinstance(e, InputError) and isinstance(e, ValueError)
    assert e.component == component, str(e)
    assert position is ANY or e.position == position, str(e)
    assert words in e.detail and e.detail in str(e)
    assert f"F{component + 1}" in str(e)
    if e.position is not None:
        assert f"column {e.position}" in str(e)
    with pytest.raises(FormulaError) as again:  # the as-you-type check agrees
        check_component(texts[component], variables, index=component)
    assert (again.value.component, again.value.position, again.value.detail) == (
        component, e.position, e.detail)


@pytest.mark.parametrize("call, words", [
    (lambda: parse_system(["x", "y"], "x y", k=3), "k = 3"),
    (lambda: parse_system([], "x"), "no formulas"),
    (lambda: parse_system(["x1"]), "n"),
    (lambda: parse_system(["x1"], n=0), "at least 1"),
    (lambda: parse_system(["x"], ["x", "y"], n=3), "n = 3"),
    (lambda: parse_system(["x"], ["x", "x"]), "twice"),
    (lambda: parse_system(["x"], ["x", "2y"]), "not a valid name"),
    (lambda: parse_system(["x"], ["x", "lambda"]), "not a valid name"),
    (lambda: parse_system(["x"], ["x", "sin"]), "function"),
    (lambda: parse_system(["x"], ["x", "pi"]), "constant"),
    (lambda: parse_system(["x"], ["x", "a b"]), "not a valid name"),
    (lambda: parse_system(["x"], []), "no variables"),
    (lambda: check_component("x", ["x", "x"]), "twice"),
])
def test_system_level_errors(call, words):
    with pytest.raises(FormulaError) as info:
        call()
    assert info.value.component is None and info.value.position is None
    assert words in str(info.value)


def test_variable_string_is_split():
    assert parse_system(["s*t"], "s, t").variables == ("s", "t")
    assert parse_system("x + y", "x y").k == 1


def test_injection_is_rejected_without_running(tmp_path):
    sentinel = tmp_path / "hacked"
    attacks = [
        f"__import__('os').system('touch {sentinel}')",
        f"__import__('os').system('touch {sentinel}') + x1",
        f"open('{sentinel}', 'w')",
        f"(lambda: __import__('os').system('touch {sentinel}'))()",
        "[c for c in ().__class__.__base__.__subclasses__()]",
        f"exec(\"open('{sentinel}', 'w')\")",
        f"eval(\"open('{sentinel}', 'w')\")",
        "__builtins__",
    ]
    for text in attacks:
        with pytest.raises(FormulaError):
            parse_system([text], n=1)
        with pytest.raises(FormulaError):
            check_component(text, ["x1"])
    assert not sentinel.exists()


def test_evaluate_grid_into_a_reused_buffer():
    s = parse_system(["x*y - z", "sin(x) + 0*y*z"], ["x", "y", "z"])
    axes = [np.linspace(-1, 1, 4), np.linspace(0, 2, 5), np.linspace(-2, 0, 3)]
    want = s.evaluate_grid(axes)
    buf = np.full((2, 4, 5, 3, 2), np.nan)
    got = s.evaluate_grid(axes, out=buf[1])
    assert got.base is buf and np.array_equal(buf[1], want) and np.isnan(buf[0]).all()
    with pytest.raises(InputError, match="out must be"):
        s.evaluate_grid(axes, out=np.empty((4, 5, 3, 1)))


# ------------------------------------------------------------ time linear in the text

def _python_calls(fn) -> int:
    """Python function calls made by fn() (an operation count, unlike a time, is the
    same on every machine); sympy's cache is cleared first so nothing is remembered."""
    import sys

    sympy.core.cache.clear_cache()
    count = [0]

    def profile(frame, event, arg):
        if event == "call":
            count[0] += 1

    sys.setprofile(profile)
    try:
        fn()
    finally:
        sys.setprofile(None)
    return count[0]


@pytest.mark.parametrize("make", [
    lambda m: "max(" + ", ".join(f"{i}*x{1 + i % 3}-{i % 7}" for i in range(m)) + ")",
    lambda m: "min(" + ", ".join(f"x{1 + i % 3}^2-{i}" for i in range(m)) + ")",
    lambda m: "min(" + ", ".join(f"max(x1-{i}, x2*{i})" for i in range(m)) + ")",
    lambda m: " + ".join(f"sin(x1*{i})*exp(x2-{i})" for i in range(m)),
    lambda m: "*".join(f"(x{1 + i % 3}+{i})" for i in range(m)),
], ids=["max", "min", "min-of-max", "sum-of-products", "product"])
def test_parsing_and_compiling_grow_linearly_with_the_text(make):
    # max() of 400 arguments took 84 s: sympy.Max compares every pair of arguments.
    # Four times the text must cost at most about four times the operations
    # (a quadratic construct costs 16 times; 6 leaves room for log factors).
    def cost(m):
        text = make(m)
        holder = []
        parse = _python_calls(lambda: holder.append(formula.System([text], ["x1", "x2", "x3"])))
        compile_ = _python_calls(lambda: holder[0].evaluate_points(np.zeros((2, 3))))
        return parse + compile_

    small, large = cost(40), cost(160)
    assert large < 6 * small, (small, large)


def test_max_and_min_of_many_arguments_are_numpys():
    rng = np.random.default_rng(3)
    m = 64   # a tree of pairwise nodes six deep (sympy's Jacobian of it costs ~25 ms an argument)
    F = parse_system(["max(" + ", ".join(f"x1*{i}/7-x2" for i in range(m)) + ")",
                      "min(" + ", ".join(f"x2^2-{i}*x1" for i in range(m)) + ")"], ["x1", "x2"])
    P = rng.uniform(-2, 2, (100, 2))
    x, y = P.T
    i = np.arange(m)[:, None]
    ref = np.stack([np.max(x * (i / 7) - y, axis=0), np.min(y**2 - i * x, axis=0)], axis=1)
    np.testing.assert_array_equal(F.evaluate_points(P), ref)
    # the derivative is the active argument's (Heaviside of the differences)
    J = F.jacobian_points(P)
    top = np.argmax(x * (i / 7) - y, axis=0)
    np.testing.assert_allclose(J[:, 0, 0], top / 7)
    np.testing.assert_allclose(J[:, 0, 1], -1.0)
    assert np.isnan(F.evaluate_points([[np.nan, 0.0]])).all()


def test_syntax_warnings_stay_off_stderr(capsys):
    # "1if x" makes ast.parse warn (invalid decimal literal): one line of error is the message
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for text in ("1if x1 else 2", "2x1", "'\\d'"):
            with pytest.raises(FormulaError):
                check_component(text, ["x1"])
            with pytest.raises(InputError):
                formula.evaluate_constant(text)
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("text, value", [
    ("-0.5^2", -0.25), ("2*3^2", 18.0), ("2^3^2", 512.0), ("(-0.5)^2", 0.25), ("-2^-1", -0.5),
    ("pi^2/4", math.pi ** 2 / 4), ("2**3", 8.0),
])
def test_caret_in_constants_is_power_with_formula_precedence(text, value):
    # the same grammar as formulas: the formula x - (text) vanishes at x = the constant's value
    assert evaluate_constant(text) == pytest.approx(value, rel=1e-15)
    system = parse_system([f"x - ({text})"], ["x"])
    assert system.evaluate_points(np.array([[value]]))[0, 0] == pytest.approx(0.0, abs=1e-12)
