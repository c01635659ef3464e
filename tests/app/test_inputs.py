"""The panel's input checks, without Qt."""

import math

import pytest

from gcmh_studio import inputs


@pytest.mark.parametrize("text,value", [("1", 1.0), ("-pi/2", -math.pi / 2), ("2*pi", 2 * math.pi),
                                        ("1e-3", 1e-3), ("2^3", 8.0), ("sqrt(2)", math.sqrt(2))])
def test_parse_number(text, value):
    assert inputs.parse_number(text) == pytest.approx(value)


@pytest.mark.parametrize("text", ["", "pi pi", "__import__('os')", "x", "1/0", "abc(1)", "[1]", "9**9**9"])
def test_parse_number_refuses(text):
    with pytest.raises(inputs.NumberError):
        inputs.parse_number(text)


def test_checks():
    assert inputs.check_variables("x, y, z", 3) is None
    assert "3 names" in inputs.check_variables("x, y", 3)
    assert "twice" in inputs.check_variables("x, y, x", 3)
    assert "reserved" in inputs.check_variables("x, sin, z", 3)
    assert "not a name" in inputs.check_variables("x, 2y, z", 3)
    assert inputs.check_nk(3, 1) is None
    assert inputs.check_nk(3, 3) is not None
    assert inputs.check_bounds("-pi", "pi")[2] == pytest.approx((-math.pi, math.pi))
    assert "empty interval" in inputs.check_bounds("2", "1")[1]
    assert inputs.check_div("0")[0] is not None
    assert inputs.check_div("2.5")[0] is not None
    assert inputs.check_div("12") == (None, 12)
    assert inputs.check_start("1, 2, 3", 3) == (None, [1.0, 2.0, 3.0])
    assert inputs.check_start("1, 2", 3)[0] is not None


@pytest.mark.parametrize("text,words", [("1/0", "division by zero"), ("x", "'x'"), ("sqrt(-1)", "out of range"),
                                        ("", "empty")])
def test_parse_number_says_why_in_a_few_words(text, words):
    with pytest.raises(inputs.NumberError) as err:
        inputs.parse_number(text)
    assert words in str(err.value) and "cannot read" not in str(err.value)


def test_parse_number_is_the_engines_evaluator():
    from gcmh_core.formula import evaluate_constant

    for text in ("-pi/2", "2^3", "\u03c0/4", "abs(-2)*tau", "exp(1) - e"):
        assert inputs.parse_number(text) == evaluate_constant(text)


def test_check_formula_gives_the_parsers_message_or_none():
    names = ["x1", "x2", "x3"]
    assert inputs.check_formula("x1^2 + x2^2 + x3^2 - 1", names, 0) is None
    msg = inputs.check_formula("x1 + (x2", names, 1)
    assert msg and "F2" in msg and "\n" not in msg
    assert "y" in inputs.check_formula("x1 + y", names, 0)


def test_check_formula_refuses_pathological_text_with_a_limit():
    names = ["x1", "x2", "x3"]
    too_long = "x1" + " + x2" * 1500
    assert "at most" in inputs.check_formula(too_long, names, 0)
    many = "max(" + ", ".join(f"x1*{i} + x2" for i in range(400)) + ")"
    assert "at most" in inputs.check_formula(many, names, 0)


@pytest.mark.parametrize("seconds,text", [(0.3, "0.3 s"), (4.2, "4 s"), (42, "42 s"), (600, "10 min"),
                                          (9000, "2.5 h"), (86400 * 5, "5 days")])
def test_human_seconds(seconds, text):
    assert inputs.human_seconds(seconds) == text


def test_check_params_reads_name_value_pairs():
    assert inputs.check_params("", ["x"]) == (None, {})
    err, values = inputs.check_params("a = 0.5, b = pi/4", ["x", "y"])
    assert err is None and values == pytest.approx({"a": 0.5, "b": math.pi / 4})
    for bad, words in [("a 0.5", "NAME = VALUE"), ("x = 1", "is a variable"), ("a = 1, a = 2", "twice"),
                       ("sin = 1", "cannot be"), ("a = 1/0", "a:")]:
        err, values = inputs.check_params(bad, ["x", "y"])
        assert err and words in err and values == {}


def test_check_formula_with_parameters():
    names = ["x", "y", "z"]
    assert inputs.check_formula("x^2 + y^2 - z^2 - a", names, 0, ("a",)) is None
    assert "'b'" in inputs.check_formula("x^2 + y^2 - z^2 - a*b", names, 0, ("a",))
    assert "'a'" in inputs.check_formula("x^2 + y^2 - z^2 - a", names, 0)   # no parameters given


def test_glued_axes_field():
    names, div = ["x", "y", "z", "s", "t"], [8, 8, 4, 8, 8]
    assert inputs.check_periodic("", names, div) == (None, [])
    assert inputs.check_periodic("t  s:flip=t", names, div) == (None, ["t", "s:flip=t"])
    assert inputs.check_periodic("t; s:flip=t", names, div)[1] == ["t", "s:flip=t"]
    m, entries = inputs.check_periodic("q", names, div)
    assert entries == [] and "glued axes" in m and "'q' is not a variable" in m
    m, _ = inputs.check_periodic("s:flip=t", names, [8, 8, 4, 8, 7])
    assert "even div" in m
