"""Parameters in the formulas (issue 17): found, listed, substituted as literals, carried
through every path of the engine, and a parameter step continued from the last result."""

import pickle
import re

import numpy as np
import pytest

from gcmh_core import extract
from gcmh_core.cli import main
from gcmh_core.complex import CellComplex
from gcmh_core.errors import InputError
from gcmh_core.examples import load_example
from gcmh_core.formula import FormulaError, check_component, find_parameters, parse_system

HYPERBOLOID = ["x^2 + y^2 - z^2 - a"]
BOX = [(-2, 2)] * 3


def same_complex(a, b) -> bool:
    """Bit for bit: vertices, edges and every cell array."""
    if a.vertices.tobytes() != b.vertices.tobytes() or a.edges.tobytes() != b.edges.tobytes():
        return False
    if sorted(a.cells) != sorted(b.cells):
        return False
    return all(x.tobytes() == y.tobytes() for r in a.cells for x, y in zip(a.cells[r], b.cells[r]))


# ------------------------------------------------------------------ finding them

def test_parameters_found_in_the_text_in_order_of_appearance():
    texts = ["b*x^2 + y^2 - z^2 - a", "x - c + b"]
    assert find_parameters(texts, "x, y, z") == ["b", "a", "c"]
    assert find_parameters(["x^2 + y^2 - 1"], "x, y") == []
    system = parse_system(texts, "x, y, z", params={"a": 1, "c": 2, "b": 3})
    assert system.parameters == ("b", "a", "c")
    assert system.params == {"b": 3.0, "a": 1.0, "c": 2.0}
    assert parse_system(["x^2 + y^2 - 1"], "x, y").parameters == ()
    check_component("x - a*pi", "x, y", allow_parameters=True)  # pi stays a constant


def test_a_value_is_the_literal_in_the_text():
    with_param = parse_system(HYPERBOLOID, "x, y, z", params={"a": "3/10"})
    literal = parse_system(["x^2 + y^2 - z^2 - 0.3"], "x, y, z")
    assert with_param.exprs == literal.exprs
    copy = pickle.loads(pickle.dumps(with_param))  # (how a Dask worker gets it)
    assert copy.params == {"a": 0.3} and copy.exprs == literal.exprs


@pytest.mark.parametrize("texts, kwargs, message", [
    (HYPERBOLOID, {}, "unknown name 'a' (variables: x, y, z; a parameter needs a value: params={'a': ...}"),
    (HYPERBOLOID, {"params": {}}, "parameter a has no value: pass params={'a': ...} or --param a=..."),
    (HYPERBOLOID, {"params": {"a": 1, "b": 2}}, "parameter b does not appear in the formulas (their parameters: a)"),
    (HYPERBOLOID, {"params": {"sin": 1, "a": 1}}, "parameter name 'sin' is the name of a function"),
    (HYPERBOLOID, {"params": {"x": 1, "a": 1}}, "parameter name 'x' is a variable"),
    (HYPERBOLOID, {"params": {"a": "1/0"}}, "value of parameter a: cannot evaluate"),
    (["xx + y^2 - a"], {"params": {"a": 1}}, "parameter xx has no value: pass params={'xx': ...} or --param xx=...; "
                                             "did you mean 'x'?"),
    (["sin + a*x"], {"params": {"a": 1}}, "'sin' is a function: write sin(...)"),
    (["sn(x) + a"], {"params": {"a": 1}}, "unknown function 'sn'; did you mean 'sin' or 'sinh'?"),
])
def test_bad_parameters_get_one_clear_message(texts, kwargs, message):
    with pytest.raises(FormulaError) as info:
        parse_system(texts, "x, y, z", **kwargs)
    assert message in str(info.value)
    assert "\n" not in str(info.value)


def test_a_typo_is_never_silently_a_parameter():
    # without params nothing is a parameter; with them, a name still needs its own value
    with pytest.raises(FormulaError, match="unknown name 'xx'; did you mean 'x'"):
        parse_system(["xx + y - 1"], "x, y")
    with pytest.raises(FormulaError, match="parameter xx has no value"):
        extract(["xx + y^2 + z^2 - a"], BOX, 4, variables="x, y, z", params={"a": 1})


# ------------------------------------------------------------ through the engine

@pytest.mark.parametrize("method", ["gcmh", "gcch", "cms"])
def test_params_give_the_bytes_of_the_literal(method):
    a = extract(HYPERBOLOID, BOX, 16, variables="x,y,z", params={"a": 0.3}, method=method)
    b = extract(["x^2 + y^2 - z^2 - 0.3"], BOX, 16, variables="x,y,z", method=method)
    assert same_complex(a, b)
    assert a.meta["params"] == {"a": 0.3} and b.meta["params"] == {}
    # a System with values, and a System given new ones
    system = parse_system(HYPERBOLOID, "x,y,z", params={"a": -1})
    assert same_complex(extract(system, BOX, 16, params={"a": 0.3}, method=method), b)


def test_params_through_the_pruned_sweep_and_the_budget(monkeypatch):
    from gcmh_core import sweep
    from gcmh_core.budget import estimate

    kw = dict(variables="x,y,z", params={"a": -0.3})
    monkeypatch.setattr(sweep, "_LEAF_CUBES", 8)
    monkeypatch.setattr(sweep, "_GIVE_UP_SHARE", np.inf)
    monkeypatch.setattr(sweep, "PRUNE", True)
    pruned = extract(HYPERBOLOID, BOX, 24, **kw)
    monkeypatch.setattr(sweep, "PRUNE", False)
    plain = extract(HYPERBOLOID, BOX, 24, **kw)
    assert pruned.meta["pruned_cubes"] > 0 and same_complex(pruned, plain)
    assert pruned.euler_characteristic() == 2
    with pytest.raises(InputError, match="parameter a has no value|unknown name 'a'"):
        estimate(HYPERBOLOID, BOX, 24, variables="x,y,z")
    cost = estimate(parse_system(HYPERBOLOID, "x,y,z", params={"a": -0.3}), BOX, 24)
    assert cost.cubes == 24 ** 3


def test_params_on_a_dask_cluster(cluster):
    kw = dict(variables="x,y,z", params={"a": 0.3})
    single = {m: extract(HYPERBOLOID, BOX, 12, method=m, **kw) for m in ("gcmh", "gcch")}
    for method, cx in single.items():  # (the worker processes parse the texts with the values)
        on_dask = extract(HYPERBOLOID, BOX, 12, method=method, scheduler=cluster[0].scheduler_address,
                          block=None if method == "gcch" else 4, **kw)
        assert same_complex(on_dask, cx) and on_dask.meta["params"] == {"a": 0.3}


def test_the_hyperboloid_changes_topology_at_its_critical_value():
    ex = load_example("hyperboloid")
    found = {}
    for a in (-0.3, 0.0, 0.3):
        cx = extract(ex.formulas, ex.bounds, 32, variables=ex.variables, params={"a": a})
        found[a] = (cx.euler_characteristic(), cx.meta["singular_vertices"])
    assert found[-0.3] == (2, 0)  # two sheets
    assert found[0.3] == (0, 0)  # one sheet
    assert found[0.0][1] > 0  # the cone: a notice that a = 0 is critical
    assert "a = 0 is a critical value" in ex.description


# ------------------------------------------------------- continuing from a result

@pytest.mark.parametrize("name, before, after, div", [
    ("hyperboloid", {"a": 0.25}, {"a": 0.3}, 24),
    ("shrinking-tori", {"r": 1.0}, {"r": 0.9}, 16),
])
def test_a_parameter_step_continues_from_the_previous_result(name, before, after, div):
    ex = load_example(name)
    kw = dict(variables=ex.variables, method="gcch")
    previous = extract(ex.formulas, ex.bounds, div, params=before, **kw)
    step = extract(ex.formulas, ex.bounds, div, params=after, start=previous, **kw)
    fresh = extract(ex.formulas, ex.bounds, div, params=after, **kw)
    assert same_complex(step, fresh)
    assert not same_complex(step, previous)


def test_start_from_a_result_is_checked():
    sphere = extract("x^2 + y^2 - 1", (-2, 2), 8, variables="x,y")
    with pytest.raises(InputError, match="the previous result lies in R\\^2, not in R\\^3"):
        extract(HYPERBOLOID, BOX, 8, variables="x,y,z", params={"a": 1}, method="gcch", start=sphere)
    far = extract("x^2 + y^2 + z^2 - 1", BOX, 8, variables="x,y,z", method="gcch")
    with pytest.raises(InputError, match="no vertex of the previous result projects onto the new M"):
        extract(["x^2 + y^2 + z^2 + a"], BOX, 8, variables="x,y,z", params={"a": 1}, method="gcch", start=far)


# ------------------------------------------------------------- the command line

def _arrays(path):
    with np.load(path, allow_pickle=False) as data:
        return {key: data[key].tobytes() for key in data.files if key != "meta_json"}


def test_cli_param_gives_the_bytes_of_the_literal(tmp_path, capsys):
    common = ["extract", "--vars", "x,y,z", "--bounds", "-2:2", "--div", "12", "--json", "-q"]
    assert main([*common, "--f", "x^2 + y^2 - z^2 - a", "--param", "a=3/10", "-o", str(tmp_path / "p.npz")]) == 0
    with_param = capsys.readouterr().out
    assert main([*common, "--f", "x^2 + y^2 - z^2 - 0.3", "-o", str(tmp_path / "l.npz")]) == 0
    literal = capsys.readouterr().out
    assert _arrays(tmp_path / "p.npz") == _arrays(tmp_path / "l.npz")
    assert CellComplex.load(tmp_path / "p.npz").meta["params"] == {"a": 0.3}  # saved with the complex
    a, b = (__import__("json").loads(out) for out in (with_param, literal))
    assert a["params"] == {"a": 0.3} and b["params"] == {}
    assert a["cells"] == b["cells"] and a["euler_characteristic"] == 0


@pytest.mark.parametrize("argv, message", [
    (["--example", "hyperboloid", "--param", "a"], "--param: expected NAME=VALUE"),
    (["--example", "hyperboloid", "--param", "b=1"], "parameter b does not appear in the formulas"),
    (["--example", "hyperboloid", "--param", "a=1", "--param", "a=2"], "--param: a is given twice"),
    (["--example", "hyperboloid", "--param", "a=x"], "--param a: cannot read 'x' as a number"),
    (["--f", "x^2 - a", "--vars", "x,y", "--bounds", "-1:1"], "a parameter needs a value"),
])
def test_cli_bad_params_get_one_line(capsys, argv, message):
    assert main(["extract", *argv, "-q"]) == 2
    out, err = capsys.readouterr()
    assert len(err.splitlines()) == 1 and message in err and out == ""


def test_cli_example_parameters_default_and_override(capsys):
    assert main(["extract", "--example", "hyperboloid", "--div", "24", "--param", "a=-0.3", "-q"]) == 0
    out = capsys.readouterr().out
    assert "hyperboloid at a = -0.3" in out and "Euler characteristic 2" in out
    assert main(["extract", "--example", "hyperboloid", "--div", "24", "--param", "a=0", "-q"]) == 0
    assert re.search(r"notice: F's Jacobian nearly loses rank at \d+ vertices", capsys.readouterr().out)
    # continuation from the example's start point, which lies on M only at a = 0.5: "auto" otherwise
    assert main(["extract", "--example", "hyperboloid", "--div", "24", "--param", "a=-0.3", "--method", "gcch",
                 "-q"]) == 0
    assert "Euler characteristic 2" in capsys.readouterr().out
    assert main(["examples"]) == 0
    assert "a = 0.5 in [-1, 1]" in capsys.readouterr().out
