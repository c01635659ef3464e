"""QtComplexBox: the Manifold tab's complex mode, equations over C^m as on the blackboard.

A switch ("complex") and, while it is on, the complex variables, the equations (``z = cos(w)``, one a line,
``lhs = rhs``), real equations beside them and the real system they split into
(:func:`gcmh_core.complex_equations.split_complex`, made by the panel's checks). The real variables (x, y for
z; u, v for w, unless typed: :func:`default_real_names`) name the rows ("u = Re w") and the view's axes.
``toggled(on)`` and ``edited`` tell the formula panel.
"""

from __future__ import annotations

from qtpy.QtCore import Qt, Signal
from qtpy.QtWidgets import QCheckBox, QFormLayout, QLabel, QLineEdit, QPlainTextEdit, QVBoxLayout, QWidget

from . import inputs
from .qt_widgets import ERROR_STYLE, blocked, error_label, mark

# the real variables of a complex one, as on the blackboard: w = u + iv, z = x + iy
_REAL_PAIRS = {"z": ("x", "y"), "w": ("u", "v"), "zeta": ("xi", "eta")}
_REAL_POOL = (("x", "y"), ("u", "v"), ("a", "b"), ("c", "d"), ("p", "q"), ("s", "t"), ("g", "h"), ("m", "n"))


def default_real_names(cvars, equations=()) -> list[str]:
    """Two real names per complex variable: z -> x, y and w -> u, v, then a, b; c, d; ...; never a name the
    equations use (a parameter) or a complex variable; ``z_re, z_im`` when the letters run out."""
    import re

    used = set(cvars) | set(inputs.RESERVED) | {t for e in equations for t in re.findall(r"[A-Za-z_]\w*", e)}
    out: list[str] = []
    for v in cvars:
        pairs = ([_REAL_PAIRS[v]] if v in _REAL_PAIRS else []) + list(_REAL_POOL)
        pair = next((p for p in pairs if not (set(p) & used) and not (set(p) & set(out))), None)
        pair = pair or (f"{v}_re", f"{v}_im")
        out.extend(pair)
        used |= set(pair)
    return out


class QtComplexBox(QWidget):
    """The complex switch and the fields it shows."""

    toggled = Signal(bool)
    edited = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        self.complex_check = QCheckBox("complex: equations over C^m")
        self.complex_check.setToolTip("type equations in complex variables (z^2 = w, z = cos(w)); they are split "
                                      "exactly into real and imaginary parts over Re and Im of each variable")
        lay.addWidget(self.complex_check)
        self.complex_box = QWidget()
        cform = QFormLayout(self.complex_box)
        cform.setContentsMargins(0, 0, 0, 0)
        cform.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        self.cvars_edit = QLineEdit()
        self.cvars_edit.setPlaceholderText("e.g. w, z")
        self.cvars_edit.setToolTip("the complex variables, separated by commas; each is two real ones (Re, Im)")
        cform.addRow("complex variables", self.cvars_edit)
        self.cvars_error = error_label()
        cform.addRow(self.cvars_error)
        self.ceq_edit = QPlainTextEdit()
        self.ceq_edit.setPlaceholderText("one equation a line, e.g.\nz = cos(w)")
        self.ceq_edit.setToolTip("equations lhs = rhs over C^m, one a line (i is the imaginary unit); "
                                 "holomorphic functions only: sin, cos, exp, log, sqrt, powers ...")
        self.ceq_edit.setTabChangesFocus(True)
        self.ceq_edit.setFixedHeight(self.ceq_edit.fontMetrics().lineSpacing() * 3 + 12)
        cform.addRow("equations", self.ceq_edit)
        self.ceq_error = error_label()
        cform.addRow(self.ceq_error)
        self.creal_edit = QLineEdit()
        self.creal_edit.setPlaceholderText("none (e.g. x^2 + y^2 + u^2 + v^2 = 1)")
        self.creal_edit.setToolTip("real equations over the real variables, separated by ';' (a real condition such "
                                   "as |z|^2 + |w|^2 = 1 is not holomorphic: write it here)")
        cform.addRow("real equations", self.creal_edit)
        self.split_label = QLabel("")
        self.split_label.setWordWrap(True)
        self.split_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.split_label.setStyleSheet("color: #555; font-size: 11px;")
        self.split_label.setToolTip("the real system the equations give (split exactly by sympy)")
        cform.addRow(self.split_label)
        lay.addWidget(self.complex_box)
        self.complex_box.setVisible(False)
        self.complex_check.toggled.connect(self.toggled)
        for signal in (self.cvars_edit.textChanged, self.ceq_edit.textChanged, self.creal_edit.textChanged):
            signal.connect(lambda *_: self.edited.emit())

    def is_complex(self) -> bool:
        return self.complex_check.isChecked()

    def complex_variables(self) -> list[str]:
        return inputs.split_names(self.cvars_edit.text())

    def complex_equations(self) -> list[str]:
        return [" ".join(t.split()) for t in self.ceq_edit.toPlainText().splitlines() if t.strip()]

    def real_equations(self) -> list[str]:
        return [" ".join(t.split()) for t in self.creal_edit.text().split(";") if t.strip()]

    def labels(self, names) -> dict[str, str]:
        """{real variable: "Re w"} in complex mode ({} otherwise)."""
        cv = self.complex_variables()
        if not self.is_complex() or len(names) != 2 * len(cv):
            return {}
        return {names[2 * j + p]: f"{'Im' if p else 'Re'} {v}" for j, v in enumerate(cv) for p in (0, 1)}

    def check_variables(self) -> str | None:
        """Mark the complex variables; their error or None."""
        cv = self.complex_variables()
        msg = inputs.check_variables(self.cvars_edit.text(), len(cv)) if cv else "name the complex variables"
        mark(self.cvars_edit, self.cvars_error, msg)
        return msg

    def check(self, names, names_ok: bool, checks, shown_params) -> tuple[dict, set, list, dict | None]:
        """Mark the equations from the checks' answer on their split over the real ``names``: (errors, the key
        still to check, the parameters found, the split or None). Until the answer comes, the equations keep
        their mark and the sliders on show (``shown_params``) stay."""
        eqs = self.complex_equations()
        msg, wanted, found, split = None, set(), [], None
        if not eqs:
            msg = "type an equation, e.g. z^2 = w"
        elif names_ok:
            key = ("complex", tuple(eqs), tuple(self.complex_variables()), tuple(names), tuple(self.real_equations()))
            if checks.has(key):
                msg, split = checks.answer(key)
                found = list(split["params"]) if split is not None else []
            else:
                wanted.add(key)
                msg = self.ceq_error.text() if self.ceq_error.isVisible() else None
                found = list(shown_params)
        self.ceq_edit.setStyleSheet(ERROR_STYLE.replace("QLineEdit", "QPlainTextEdit") if msg else "")
        self.ceq_error.setText(msg or "")
        self.ceq_error.setVisible(bool(msg))
        if msg:
            self.split_label.setText("")
        return ({"equations": msg} if msg else {}), wanted, found, split

    def set_equations(self, cvars, equations, extras) -> None:
        """The fields (without a word to the panel: it checks them when it is ready)."""
        with blocked(self.cvars_edit, self.ceq_edit, self.creal_edit):
            self.cvars_edit.setText(", ".join(cvars))
            self.ceq_edit.setPlainText("\n".join(str(e) for e in equations))
            self.creal_edit.setText("; ".join(extras))

    def show_split(self, texts) -> None:
        """The real system the equations split into ("" to clear)."""
        lines = [f"F{i + 1} = {t}" for i, t in enumerate(texts)]
        self.split_label.setText("real system:\n" + "\n".join(lines) if lines else "")
