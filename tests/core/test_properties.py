"""Property-based tests (hypothesis): the formula parser on generated text, save/load
round trips, and the budget's estimate against measured peaks.

Sized to run in seconds; GCMH_HYPOTHESIS_PROFILE=long runs many more examples:

    GCMH_HYPOTHESIS_PROFILE=long .venv/bin/python -m pytest tests/core/test_properties.py -p no:xvfb
"""

import io
import json
import math
import os

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from gcmh_core.complex import CellComplex  # noqa: E402
from gcmh_core.errors import InputError  # noqa: E402
from gcmh_core.formula import FormulaError, System, evaluate_constant  # noqa: E402

LONG = os.environ.get("GCMH_HYPOTHESIS_PROFILE") == "long"


def sized(quick: int, long: int):
    # the quick profile draws the same examples every run (CI's time must not depend on the draw: a random
    # n = 6 CCS case once kept the naive structure check busy for minutes); the long one explores
    return settings(max_examples=long if LONG else quick, deadline=None, derandomize=not LONG,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


# ------------------------------------------------------------------ the parser

VARIABLES = ("x", "y", "z")
SENTINEL = "gcmh_property_sentinel"
TOKENS = [
    *VARIABLES, "x1", "pi", "e", "1", "2.5", "0", "1e308", "1e-9", "10**400", "3j", "'s'",
    "+", "-", "*", "/", "^", "**", "//", "%", "@", "(", ")", ",", " ", ".", "[", "]", "{", "}", ":",
    "sin(", "cos(", "exp(", "log(", "sqrt(", "abs(", "max(", "min(", "atan2(", "tanh(",
    "lambda", "__import__", "os", "system", "open", "eval", "exec", "import", ";", "=", "==", "if", "else",
    f"open('{SENTINEL}','w')", "__class__", "__subclasses__", "#", "\n", "\\", "\u03c0", "\x00",
]


@st.composite
def formula_text(draw):
    if draw(st.booleans()):
        return "".join(draw(st.lists(st.sampled_from(TOKENS), max_size=40)))
    return draw(st.text(max_size=60))


@sized(300, 5000)
@given(formula_text())
def test_parser_never_crashes_and_never_runs_code(tmp_path_factory, text):
    os.chdir(tmp_path_factory.getbasetemp())
    try:
        F = System([text], VARIABLES)
    except FormulaError as err:
        message = str(err)
        assert message and "\n" not in message and "Traceback" not in message
    else:
        values = F.evaluate_points(np.array([[0.5, -1.0, 2.0], [0.0, 0.0, 0.0]]))
        assert values.shape == (2, 1) and values.dtype == np.float64
    assert not os.path.exists(SENTINEL)


@sized(300, 5000)
@given(formula_text())
def test_constant_evaluator_gives_a_number_or_one_line(text):
    try:
        value = evaluate_constant(text)
    except InputError as err:
        assert str(err) and "\n" not in str(err)
    else:
        assert isinstance(value, float) and math.isfinite(value)


# ------------------------------------------------------------------ save / load

@st.composite
def complexes(draw):
    n = draw(st.integers(1, 5))
    k = draw(st.integers(0, n))
    dim = n - k
    nv = draw(st.integers(0, 12))
    floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
    vertices = np.array(draw(st.lists(st.lists(floats, min_size=n, max_size=n), min_size=nv, max_size=nv)),
                        np.float64).reshape(nv, n)
    ne = draw(st.integers(0, 10)) if dim >= 1 and nv else 0
    edges = np.array(draw(st.lists(st.lists(st.integers(0, max(nv - 1, 0)), min_size=2, max_size=2),
                                   min_size=ne, max_size=ne)), np.int64).reshape(ne, 2)
    cells, below = {}, ne
    for r in range(2, dim + 1):
        sizes = draw(st.lists(st.integers(0, 4 if below else 0), max_size=6))
        offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        faces = np.array(draw(st.lists(st.integers(0, max(below - 1, 0)), min_size=int(offsets[-1]),
                                       max_size=int(offsets[-1]))), np.int64)
        cells[r] = (offsets, faces)
        below = len(sizes)
    json_values = st.recursive(
        st.none() | st.booleans() | st.integers(-2**53, 2**53) | st.text(max_size=8)
        | st.floats(allow_nan=False, allow_infinity=False),
        lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner, max_size=3),
        max_leaves=8,
    )
    meta = draw(st.dictionaries(st.text(max_size=8).filter(lambda s: s not in ("seconds", "timings")),
                                json_values, max_size=4))
    return CellComplex(n, k, vertices, edges, cells, meta)


@sized(60, 1000)
@given(complexes(), st.booleans())
def test_save_load_round_trip_same_bytes(tmp_path_factory, cx, compressed):
    path = tmp_path_factory.mktemp("rt") / "c.npz"
    cx.save(path, compressed=compressed)
    back = CellComplex.load(path)
    assert (back.n, back.k) == (cx.n, cx.k)
    assert back.vertices.tobytes() == cx.vertices.tobytes()
    assert back.edges.tobytes() == cx.edges.tobytes()
    for r in cx.cells:
        assert all(np.array_equal(a, b) for a, b in zip(back.cells[r], cx.cells[r]))
    assert json.dumps(back.meta, sort_keys=True) == json.dumps(json.loads(json.dumps(cx.meta)), sort_keys=True)
    again = io.BytesIO()
    back.save(again, compressed=compressed)
    assert again.getvalue() == path.read_bytes()  # the same complex, the same bytes


# ------------------------------------------------------------------ the estimate against the peak
# (runs whose peak is tens of MB at least: below that the allocator's reuse of freed
# memory decides the measured RSS more than the run does)

@pytest.mark.skipif(not hasattr(os, "fork") and not os.path.exists("/proc"), reason="POSIX child processes")
@sized(2, 25)
@given(st.sampled_from([(3, 1, 150), (3, 1, 250), (4, 1, 28), (4, 1, 40), (5, 1, 12), (5, 2, 28),
                        (6, 1, 8), (7, 1, 5), (9, 1, 2)]),
       st.sampled_from(["gcmh", "gcch"]))
def test_estimate_against_the_measured_peak(case, method):
    from test_budget import measure

    n, k, div = case
    m = measure(n, k, div, method)
    assert 0.5 <= m["estimate"] / max(m["measured"], 1) <= 2.0, (case, method, m)
