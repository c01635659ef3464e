"""Complex mode in the window (issue 17): equations over C^m typed as on the blackboard."""

import json

import numpy as np

from app_helpers import run_and_wait, settle


def _complex(qtbot, p, cvars, equations, real="", names=None, bounds=None, div=10):
    p.complex_check.setChecked(True)
    p.cvars_edit.setText(cvars)
    p.ceq_edit.setPlainText(equations)
    p.creal_edit.setText(real)
    if names:
        p.vars_edit.setText(names)
        p.vars_edit.textEdited.emit(names)
    if bounds is not None:
        for r, (lo, hi) in enumerate(bounds):
            p.table.item(r, 0).setText(str(lo))
            p.table.item(r, 1).setText(str(hi))
    p.div_edit.setText(str(div))
    settle(qtbot, p)


def _same(a, b):
    assert a.counts() == b.counts() and a.euler_characteristic() == b.euler_characteristic()
    np.testing.assert_allclose(a.vertices, b.vertices, atol=1e-12)


def test_complex_cosine_equals_the_hand_split_system(qtbot, window):
    import gcmh_core

    p = window.formula_panel
    _complex(qtbot, p, "w, z", "z = cos(w)", bounds=[("-pi/2", "pi/2")] * 4, div=12)
    assert p.is_valid(), p.errors
    assert (p.n, p.k, p.variables()) == (4, 2, ["u", "v", "x", "y"])   # w = u + iv, z = x + iy
    headers = [p.table.verticalHeaderItem(r).text() for r in range(4)]
    assert headers == ["u = Re w", "v = Im w", "x = Re z", "y = Im z"]
    assert run_and_wait(qtbot, window) == "done", window.last_status
    hand = gcmh_core.extract(["x - cos(u)*cosh(v)", "y + sin(u)*sinh(v)"], bounds=[(-np.pi / 2, np.pi / 2)] * 4,
                             div=12, variables=["u", "v", "x", "y"])
    _same(window.result, hand)
    # the view says what the axes mean, and opens as a graph: the w-plane flat, Re z up, coloured by Im z
    assert window.scene.style.labels == {"u": "Re w", "v": "Im w", "x": "Re z", "y": "Im z"}
    assert window.scene.style.label("x") == "x = Re z"
    assert window.projection_panel.color_by() == "y"
    assert "colour: y = Im z" in window.scene.style.subtitle


def test_z_squared_equals_w_equals_the_hand_split_system(qtbot, window):
    import gcmh_core

    p = window.formula_panel
    _complex(qtbot, p, "z, w", "z^2 = w", names="a, b, c, d", div=8)
    assert p.is_valid(), p.errors
    assert [p.table.item(r, 0).text() for r in range(4)] == ["-2"] * 4   # C^m's default box
    assert "F1 = a**2 - b**2 - c" in p.split_label.text()
    assert run_and_wait(qtbot, window) == "done", window.last_status
    assert window.scene.style.title == "z^2 = w"   # a system typed in is called by its equation
    hand = gcmh_core.extract(["a^2 - b^2 - c", "2*a*b - d"], bounds=[(-2, 2)] * 4, div=8,
                             variables=["a", "b", "c", "d"])
    _same(window.result, hand)


def test_complex_examples_open_as_written_on_the_blackboard(qtbot, window):
    p = window.formula_panel
    for name, eqs, cvars, names, extra in (
            ("complex-cosine", ["z = cos(w)"], ["w", "z"], ["u", "v", "x", "y"], []),
            ("riemann-sqrt", ["z^2 = w"], ["z", "w"], ["a", "b", "c", "d"], []),
            ("trefoil-knot", ["z^2 = w^3"], ["z", "w"], ["a", "b", "c", "d"], ["a**2 + b**2 + c**2 + d**2 - 1"])):
        window.load_example(name, run=False)
        settle(qtbot, p)
        assert p.is_complex() and p.complex_equations() == eqs and p.complex_variables() == cvars, name
        assert p.variables() == names and p.real_equations() == extra and p.is_valid(), (name, p.errors)
        from gcmh_core.examples import load_example

        assert p.formulas() == load_example(name).formulas   # the panel's split is the loader's
    window.load_example("milnor-fibre", div=8)   # complex, with a parameter t
    with qtbot.waitSignal(window.runFinished, timeout=120_000) as b:
        pass
    assert b.args[0] == "done", window.last_status
    assert p.parameters.names() == ["t"] and p.parameters.values() == {"t": 0.1}


def test_the_session_keeps_the_complex_text(qtbot, window, tmp_path):
    p = window.formula_panel
    _complex(qtbot, p, "z, w", "w^3 + z^3 = 1", div=6)
    assert p.is_valid(), p.errors
    assert run_and_wait(qtbot, window) == "done", window.last_status
    path = tmp_path / "c.json"
    window.save_session(path)
    system = json.loads(path.read_text())["system"]
    assert system["complex"] == ["w^3 + z^3 = 1"] and system["complex_variables"] == ["z", "w"]
    assert system["formulas"] == []   # the split is not stored: the text is
    p.complex_check.setChecked(False)   # off: the real system of the split, to read and edit
    settle(qtbot, p)
    assert not p.is_complex() and p.k == 2 and p.formula_edits[0].text() == "u**3 - 3*u*v**2 + x**3 - 3*x*y**2 - 1"
    assert window.controller.open_session(path)
    with qtbot.waitSignal(window.runFinished, timeout=60_000):
        pass
    assert p.is_complex() and p.complex_equations() == ["w^3 + z^3 = 1"]


def test_bad_complex_input_is_refused_next_to_the_field(qtbot, window):
    p = window.formula_panel
    _complex(qtbot, p, "z, w", "abs(z) = w")
    assert not p.is_valid() and "not holomorphic" in p.ceq_error.text()
    p.ceq_edit.setPlainText("z^2 = w\nz + = 1")
    settle(qtbot, p)
    assert not p.is_valid() and p.ceq_error.text().startswith("equation 2")
    p.ceq_edit.setPlainText("z^2 = w")
    p.cvars_edit.setText("z, 1w")
    settle(qtbot, p)
    assert not p.is_valid() and "'1w'" in p.cvars_error.text()
    p.cvars_edit.setText("z, w")
    p.creal_edit.setText("x^2 + y^2 = ")
    settle(qtbot, p)
    assert not p.is_valid() and p.ceq_error.text().startswith("real equation 1")
    p.creal_edit.setText("x^2 + y^2 = 1")
    settle(qtbot, p)
    assert p.is_valid() and p.k == 3
