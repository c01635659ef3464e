"""Generated hostile input (issue 26): example files and ``gcmh extract`` command lines, valid and broken.

Whatever is generated, the example loader gives an Example or one InputError, and the command line exits 0, 1 or
2 with at most a line or two on stderr and no traceback; neither allocates past a bound (tracemalloc) nor runs
past hypothesis' deadline. A few dozen examples each (derandomized: the same ones every run).
"""

import math
import tracemalloc

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from gcmh_core.cli import main  # noqa: E402
from gcmh_core.errors import InputError  # noqa: E402
from gcmh_core.examples import Example, load_example  # noqa: E402

SUITE = settings(max_examples=30, deadline=20_000, derandomize=True,
                 suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
MEMORY_BOUND = 300 << 20   # bytes Python allocates at the peak of one load or one command


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f'"{k}" = {_toml_value(x)}' for k, x in v.items()) + "}"
    raise TypeError(v)


def toml(d: dict) -> str:
    return "".join(f"{k} = {_toml_value(v)}\n" for k, v in d.items())


# pieces of formulas and equations: powers up to the exponent limit, sums that expand, functions, junk
atoms = st.sampled_from(["x", "y", "z", "w", "1", "0.5", "pi", "a", "2", "e", "i", "t", "q"])
ops = st.sampled_from(["+", "-", "*", "/", "^"])
funcs = st.sampled_from(["sin", "cos", "exp", "log", "sqrt", "abs", "tanh", "atan2", "__import__", "min"])


@st.composite
def expressions(draw, depth=3):
    if depth == 0 or draw(st.booleans()):
        return draw(atoms)
    kind = draw(st.integers(0, 3))
    a = draw(expressions(depth=depth - 1))
    if kind == 0:
        return f"({a}){draw(st.sampled_from(['^', '**']))}{draw(st.sampled_from(['2', '8', '64', '65', '-3', '0.5']))}"
    if kind == 1:
        return f"{draw(funcs)}({a})"
    b = draw(expressions(depth=depth - 1))
    return f"{a} {draw(ops)} {b}"


numbers = st.one_of(st.integers(-10**20, 10**20), st.floats(allow_nan=True, allow_infinity=True),
                    st.sampled_from(["-pi", "2*3^2", "1e999", "nan", "-0.5^2", "x"]))
junk = st.one_of(numbers, st.text(max_size=30), st.booleans(), st.lists(st.integers(-5, 5), max_size=5),
                 st.just("x" * 20_000), st.just([[[[[[1]]]]]]), st.dictionaries(st.text(max_size=5), st.integers(),
                                                                                  max_size=3))


@st.composite
def example_files(draw):
    d = {"title": "T", "description": "D", "variables": ["x", "y", "z"], "formulas": ["x^2 + y^2 + z^2 - 1"],
         "bounds": [-1.5, 1.5], "div": 8, "start": [1.0, 0.0, 0.0]}
    if draw(st.booleans()):   # complex mode
        d.pop("formulas")
        d.pop("variables")
        d["start"] = [0.0, 0.0, 0.0, 0.0]
        d["complex"] = [f"{draw(expressions())} = {draw(expressions())}"]
        d["complex_variables"] = ["z", "w"]
    else:
        d["formulas"] = [draw(expressions())]
    for _ in range(draw(st.integers(0, 3))):   # broken fields
        key = draw(st.sampled_from(["title", "description", "variables", "formulas", "bounds", "div", "start", "n",
                                    "k", "params", "periodic", "view", "complex_variables", "paper_div"]))
        d[key] = draw(junk)
    return d


@SUITE
@given(example_files())
def test_an_example_file_loads_or_is_refused_in_one_line(tmp_path_factory, monkeypatch, data):
    folder = tmp_path_factory.mktemp("examples")
    (folder / "generated.toml").write_text(toml(data), encoding="utf-8")
    monkeypatch.setenv("GCMH_EXAMPLES_DIR", str(folder))
    tracemalloc.start()
    try:
        ex = load_example("generated")
        assert isinstance(ex, Example) and 1 <= ex.k < ex.n and len(ex.formulas) == ex.k
    except InputError as e:
        assert "\n" not in str(e).strip() and len(str(e)) < 2000, str(e)
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert peak < MEMORY_BOUND, peak


@st.composite
def command_lines(draw):
    argv = ["extract", "-q"]
    if draw(st.booleans()):
        argv += ["--complex", "--f", f"{draw(expressions())} = {draw(expressions())}", "--vars", "z,w"]
    else:
        argv += ["--f", draw(expressions()), "--vars", draw(st.sampled_from(["x,y,z", "x,y", "x,x,z", "x y z", ""]))]
    argv += ["--bounds", draw(st.sampled_from(["-1.5:1.5", "-pi:pi", "1:-1", "nan:1", "-1e308:1e308", "0:0", "-2:2"]))]
    argv += ["--div", draw(st.sampled_from(["4", "6", "0", "-1", "4,4,4", "1e9", "x", "99999999999999999999"]))]
    if draw(st.booleans()):
        argv += ["--param", draw(st.sampled_from(["a=0.5", "a=-0.5^2", "a=nan", "a=", "=1", "a=1e999", "q=1"]))]
    if draw(st.booleans()):
        argv += ["--periodic", draw(st.sampled_from(["x", "x:flip=", "x:flip=y", "q", "x:flop=y", "x:flip=x"]))]
    if draw(st.booleans()):
        argv += ["--n", draw(st.sampled_from(["3", "0", "-1", "100000", "63"]))]
    return argv


@pytest.fixture(scope="module")
def warm(tmp_path_factory):
    """The kernels compiled (or loaded from numba's cache) before the deadline and tracemalloc count."""
    main(["extract", "-q", "--f", "x^2 + y^2 + z^2 - 1", "--vars", "x,y,z", "--bounds", "-1.5:1.5", "--div", "4",
          "-o", str(tmp_path_factory.mktemp("warm") / "w.npz")])


@SUITE
@given(command_lines())
def test_the_command_line_exits_with_one_line_never_a_traceback(warm, tmp_path_factory, capsys, argv):
    out = tmp_path_factory.mktemp("out") / "a.npz"
    tracemalloc.start()
    try:
        code = main([*argv, "-o", str(out)])
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    _, err = capsys.readouterr()
    assert code in (0, 1, 2), (argv, code, err)
    assert "Traceback" not in err and len(err.strip().splitlines()) <= 2, (argv, err)
    if code == 2:
        assert err.startswith("gcmh: error:"), (argv, err)
    assert out.exists() == (code == 0), (argv, code, err)
    assert peak < MEMORY_BOUND, (argv, peak)
