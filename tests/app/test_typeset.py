"""gcmh_studio.typeset: formula text -> LaTeX -> RGBA image, written as on a blackboard, failing soft to plain text."""

import numpy as np
import pytest

from gcmh_studio.typeset import Line, complex_equation_latex, equation_latex, render_lines, system_lines, typeset_system


def ink(img):
    """How many pixels of the card carry text (bright), not just the card's dark panel."""
    return int(np.count_nonzero(img[..., :3].min(axis=-1) > 180))


@pytest.mark.parametrize("text, variables, expected", [
    ("x^2 + y^2 + z^2 - 1", "x y z", "x^{2} + y^{2} + z^{2} = 1"),
    ("x^2 + y^2 - z^2 - a", "x y z", "x^{2} + y^{2} - z^{2} = a"),         # a parameter stays a symbol, on the right
    ("cos(t) + 2 - x", "x t", r"x = \cos {t} + 2"),                          # a graph: x = ...
    ("x^2 - y^2*z", "x y z", "x^{2} = y^{2} z"),                             # the negative terms on the right
    ("x1*x2 - 1/2", "x1 x2", r"x_{1} x_{2} = \frac{1}{2}"),
    ("max(x, y) - 1", "x y", r"\max\left(x, y\right) = 1"),                  # the parser's pairwise max prints as \max
])
def test_equations_are_written_as_on_a_blackboard(text, variables, expected):
    assert equation_latex(text, variables.split()) == expected


def test_operators_get_a_thin_space_mathtext_does_not_add():
    tex = equation_latex("cos(s)*(3 + cos(s/2)*sin(t)) - x", ["x", "s", "t"])
    assert tex.startswith("x = ")
    assert r"\sin {t}\,\cos" in tex or r"\cos {\frac{s}{2}}\,\sin" in tex


def test_complex_equations_are_typeset_over_c():
    assert complex_equation_latex("z = cos(w)", ["w", "z"]) == r"z = \cos {w}"
    assert complex_equation_latex("z^2 = w", ["z", "w"]) == "z^{2} = w"


def test_known_formulas_give_an_image():
    img, lines = typeset_system(["x^2 + y^2 + z^2 - 1"], ["x", "y", "z"], font_px=30)
    assert img is not None and img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 4
    assert img.shape[0] >= 30 and img.shape[1] > 4 * 30
    assert lines == [Line("x^{2} + y^{2} + z^{2} = 1", True)]
    assert ink(img) > 100                       # text was drawn
    assert (img[..., 3] > 0).all()              # on a card: every pixel painted, translucent
    assert img[..., 3].min() < 255


def test_parameter_values_appear():
    lines = system_lines(["x^2 + y^2 - z^2 - a"], ["x", "y", "z"], {"a": 0.3})
    assert [line.text for line in lines] == ["x^{2} + y^{2} - z^{2} = a", "a = 0.30"]
    with_value, _ = typeset_system(["x^2 + y^2 - z^2 - a"], ["x", "y", "z"], {"a": 0.3}, font_px=30)
    without, _ = typeset_system(["x^2 + y^2 - z^2 - a"], ["x", "y", "z"], font_px=30)
    assert with_value.shape[0] > without.shape[0] + 20     # one more line
    two = system_lines(["x^2 + y^2 - a*z - b"], ["x", "y", "z"], {"a": -1.0, "b": 0.00025})
    assert two[-1].text == r"a = -1.00,\quad b = 2.5 \times 10^{-4}"


def test_bad_text_falls_back_to_plain_text():
    lines = system_lines(["x^2 + (y", "x - y"], ["x", "y"])
    assert lines[0] == Line("x^2 + (y = 0", False)      # as written, never a traceback
    assert lines[1].math
    img, _ = typeset_system(["x^2 + (y"], ["x", "y"])
    assert img is not None and ink(img) > 50


def test_latex_mathtext_refuses_is_drawn_as_plain_text():
    bad = render_lines([Line(r"\notacommand{x}", True)], 30)
    plain = render_lines([Line(r"\notacommand{x}", False)], 30)
    assert bad is not None and bad.shape == plain.shape and np.array_equal(bad, plain)
    assert render_lines([], 30) is None


def test_dollar_signs_in_plain_text_are_not_math():
    img = render_lines([Line("$x$ costs $5", False)], 30)
    assert img is not None and ink(img) > 50


def test_an_example_over_c_shows_its_complex_equation():
    from gcmh_core.examples import load_example

    ex = load_example("complex-cosine")
    lines = system_lines(ex.formulas, ex.variables, None, ex.complex, ex.complex_variables)
    assert [line.text for line in lines] == [r"z = \cos {w}", r"w = u + i\,v,\quad z = x + i\,y"]
    # edited formulas are no longer the split of the complex equation: the real ones are shown
    edited = ["x - cos(u)*cosh(v) + 0.1", ex.formulas[1]]
    lines = system_lines(edited, ex.variables, None, ex.complex, ex.complex_variables)
    assert len(lines) == 2 and lines[0].text.startswith("x = ")
    # a real equation beside the complex one (the trefoil: the unit sphere of C^2)
    tre = load_example("trefoil-knot")
    lines = system_lines(tre.formulas, tre.variables, None, tre.complex, tre.complex_variables)
    assert [line.text for line in lines][:2] == ["z^{2} = w^{3}", "a^{2} + b^{2} + c^{2} + d^{2} = 1"]


def test_every_example_typesets_as_mathematics():
    from gcmh_core.examples import list_examples

    for ex in list_examples():
        img, lines = typeset_system(ex.formulas, ex.variables, ex.param_values(), ex.complex,
                                    ex.complex_variables, font_px=24)
        assert img is not None, ex.name
        assert all(line.math for line in lines), (ex.name, lines)


def test_a_card_too_large_shrinks_to_fit():
    formulas = ["cos(s)*(3 + cos(s/2)*sin(t) - sin(s/2)*sin(2*t)) - x"] * 3
    big, _ = typeset_system(formulas, ["x", "s", "t"], font_px=40)
    small, _ = typeset_system(formulas, ["x", "s", "t"], font_px=40, max_size=(400, 120))
    assert big.shape[1] > 400
    assert small.shape[1] <= 400 and small.shape[0] <= 120


def test_terms_keep_the_order_they_were_typed_in():
    assert complex_equation_latex("z^2 + w^3 = t", ["z", "w"]) == "z^{2} + w^{3} = t"   # sympy: w^{3} + z^{2}
    assert equation_latex("x^2 + y^2 + z^2 + w^2 - 1", ["x", "y", "z", "w"]) == "x^{2} + y^{2} + z^{2} + w^{2} = 1"
    assert equation_latex("-y^2 + x^2", ["x", "y"]) == "x^{2} = y^{2}"


def test_a_moving_parameter_redraws_only_its_own_line():
    from gcmh_studio.typeset import _line_image

    typeset_system(["x^2 + y^2 - z^2 - a"], ["x", "y", "z"], {"a": 0.3}, font_px=30)
    before = _line_image.cache_info()
    typeset_system(["x^2 + y^2 - z^2 - a"], ["x", "y", "z"], {"a": 0.31}, font_px=30)
    after = _line_image.cache_info()
    assert after.misses - before.misses == 1 and after.hits - before.hits >= 1
