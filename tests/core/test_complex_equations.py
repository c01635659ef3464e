"""Equations over C^m (issue 17): split exactly into the real system the engine takes."""

import json

import numpy as np
import pytest
from test_parameters import same_complex  # (rootdir-style import, as test_properties does)

from gcmh_core import extract
from gcmh_core.cli import main
from gcmh_core.complex_equations import DEFAULT_BOUNDS, complex_view, split_complex
from gcmh_core.examples import load_example
from gcmh_core.formula import FormulaError, parse_system

COSINE_BY_HAND = ["x - cos(u)*cosh(v)", "y + sin(u)*sinh(v)"]  # the paper's Section 6.1
SQRT_BY_HAND = ["a**2 - b**2 - c", "2*a*b - d"]


def test_the_split_is_the_hand_split():
    texts, variables, labels = split_complex(["z = cos(w)"], "w, z", ["u", "v", "x", "y"])
    assert texts == COSINE_BY_HAND and variables == ["u", "v", "x", "y"]
    assert labels == {"u": "Re w", "v": "Im w", "x": "Re z", "y": "Im z"}
    texts, variables, _ = split_complex(["z^2 = w"], "z, w", ["a", "b", "c", "d"])
    hand = parse_system(SQRT_BY_HAND, "a, b, c, d")
    assert parse_system(texts, variables).exprs == hand.exprs
    texts, variables, labels = split_complex("w^3 + z^3 = 1", ["w", "z"])
    assert variables == ["w_re", "w_im", "z_re", "z_im"] and labels["z_im"] == "Im z"
    assert texts == ["w_re**3 - 3*w_im**2*w_re + z_re**3 - 3*z_im**2*z_re - 1",
                     "3*w_im*w_re**2 - w_im**3 + 3*z_im*z_re**2 - z_im**3"]
    assert split_complex(["z = i*w + 2"], "w, z")[0] == ["z_re + w_im - 2", "z_im - w_re"]


@pytest.mark.parametrize("equation", ["z = cos(w)", "z^2 = w", "z = exp(w)/(1 + w^2)", "w^3 + z^3 = 1",
                                      "z = sqrt(w) + log(w)"])
def test_the_real_jacobian_is_the_complex_derivative(equation):
    # Cauchy-Riemann: d(Re f, Im f)/d(Re w, Im w) = [[Re f', -Im f'], [Im f', Re f']] with f' = df/dw
    texts, variables, _ = split_complex([equation], "w, z")
    system = parse_system(texts, variables)
    rng = np.random.default_rng(1)
    P = rng.uniform(0.2, 1.0, (20, 4))  # (off the branch cut of sqrt and log)
    J = system.jacobian_points(P)
    w, z = P[:, 0] + 1j * P[:, 1], P[:, 2] + 1j * P[:, 3]
    h = 1e-6
    F = {"z = cos(w)": lambda w, z: z - np.cos(w), "z^2 = w": lambda w, z: z**2 - w,
         "z = exp(w)/(1 + w^2)": lambda w, z: z - np.exp(w) / (1 + w**2),
         "w^3 + z^3 = 1": lambda w, z: w**3 + z**3 - 1,
         "z = sqrt(w) + log(w)": lambda w, z: z - np.sqrt(w) - np.log(w)}[equation]
    for col, var in ((0, "w"), (2, "z")):
        d = (F(w + h, z) - F(w - h, z)) / (2 * h) if var == "w" else (F(w, z + h) - F(w, z - h)) / (2 * h)
        assert np.allclose(J[:, 0, col], d.real, atol=1e-6) and np.allclose(J[:, 0, col + 1], -d.imag, atol=1e-6)
        assert np.allclose(J[:, 1, col], d.imag, atol=1e-6) and np.allclose(J[:, 1, col + 1], d.real, atol=1e-6)
    assert np.allclose(system.evaluate_points(P), np.stack([F(w, z).real, F(w, z).imag], 1))


@pytest.mark.parametrize("method", ["gcmh", "gcch"])
@pytest.mark.parametrize("name, equation, cvars", [
    ("complex-cosine", "z = cos(w)", "w, z"),
    ("riemann-sqrt", "z^2 = w", "z, w"),
])
def test_complex_mode_gives_the_hand_split_complex(name, equation, cvars, method):
    ex = load_example(name)
    hand = {"complex-cosine": COSINE_BY_HAND, "riemann-sqrt": SQRT_BY_HAND}[name]
    div = 12
    by_hand = extract(hand, ex.bounds, div, variables=ex.variables, method=method)
    # the example is written over C now: same texts, same bytes
    assert same_complex(extract(ex.formulas, ex.bounds, div, variables=ex.variables, method=method), by_hand)
    # typed afresh with the default real names (w_re, ...): the same complex, up to rounding
    texts, variables, _ = split_complex([equation], cvars)
    typed = extract(texts, ex.bounds, div, variables=variables, method=method)
    assert typed.counts() == by_hand.counts()
    assert typed.euler_characteristic() == by_hand.euler_characteristic()
    assert np.array_equal(typed.edges, by_hand.edges)
    assert np.max(np.abs(typed.vertices - by_hand.vertices)) <= 1e-12


def test_parameters_in_complex_equations():
    texts, variables, _ = split_complex(["z^2 + w^3 = t"], "z, w", allow_parameters=True)
    assert texts[0].endswith("- t") and "t" not in texts[1]
    with pytest.raises(FormulaError, match="unknown name 't'"):
        split_complex(["z^2 + w^3 = t"], "z, w")
    ex = load_example("milnor-fibre")
    assert ex.complex == ["z^2 + w^3 = t"] and ex.params["t"]["value"] == 0.1


@pytest.mark.parametrize("equation, message", [
    ("z = abs(w)", "abs() is not holomorphic: complex mode takes holomorphic equations"),
    ("z = conj(w)", "conj() is not holomorphic"),
    ("z = max(w, 1)", "max() is not holomorphic"),
    ("z = atan2(w, 1)", "atan2() is not holomorphic"),
    ("z = asin(w)", "cannot split this equation exactly: sympy finds no closed form"),
    ("z - z = 0*w", "the real part of this equation is identically 0"),
    ("z == w", "an equation has one '=' (lhs = rhs)"),
    ("z = ", "empty side of '='"),
    ("z = 2w", "column 5: syntax error: invalid decimal literal (write 2*x, not 2x)"),
    ("z = sn(w)", "column 5: unknown function 'sn'; did you mean 'sin' or 'sinh'?"),
    ("z = w.real", "attribute access ('.') not allowed"),
    ("__import__('os').system('true') = w", "not allowed"),
])
def test_bad_complex_input_gets_one_clear_message(equation, message):
    with pytest.raises(FormulaError) as info:
        split_complex([equation], "w, z")
    assert message in str(info.value) and "\n" not in str(info.value)


def test_real_names_are_checked():
    with pytest.raises(FormulaError, match="2 complex variables need 4 real names"):
        split_complex(["z = w"], "w, z", ["a", "b", "c"])
    with pytest.raises(FormulaError, match="real name 'z' is also a complex variable"):
        split_complex(["z = w"], "w, z", ["z", "b", "c", "d"])


def test_the_view_and_the_bounds():
    assert complex_view("w, z") == {"project": ["w_re", "w_im", "z_re"], "color": "z_im"}
    assert complex_view("w, z", ["u", "v", "x", "y"]) == {"project": ["u", "v", "x"], "color": "y"}
    assert DEFAULT_BOUNDS == (-2.0, 2.0)


def test_cli_complex_mode_is_the_hand_split(capsys):
    common = ["--div", "8", "--bounds", "-1.2:1.2", "--json", "-q"]
    assert main(["extract", "--complex", "--f", "z^2 = w", "--vars", "z,w", *common]) == 0
    typed = json.loads(capsys.readouterr().out)
    assert main(["extract", *sum((["--f", f] for f in SQRT_BY_HAND), []), "--vars", "a,b,c,d", *common]) == 0
    hand = json.loads(capsys.readouterr().out)
    assert typed["cells"] == hand["cells"] and typed["euler_characteristic"] == hand["euler_characteristic"] == 1
    assert main(["extract", "--complex", "--f", "z = abs(w)", "--vars", "w,z", "-q"]) == 2
    assert "not holomorphic" in capsys.readouterr().err
    assert main(["extract", "--complex", "--f", "z = w", "-q"]) == 2
    assert "--complex needs --vars" in capsys.readouterr().err
