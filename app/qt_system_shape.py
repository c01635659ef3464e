"""QtSystemShape: the Manifold tab's n, k and variable names (F: R^n -> R^k over the named variables).

It shows the manifold's dimension (n - k) and marks a wrong n, k or list of names; in complex mode n and k
follow the equations and the names are the real variables (Re and Im of each complex one).
"""

from __future__ import annotations

from qtpy.QtWidgets import QFormLayout, QHBoxLayout, QLabel, QLineEdit, QSpinBox, QVBoxLayout, QWidget

from . import inputs
from .qt_formula_rows import N_MAX
from .qt_widgets import error_label, mark


class QtSystemShape(QWidget):
    """n, k and the variables."""

    def __init__(self, parent=None):
        super().__init__(parent)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        row = QHBoxLayout()
        self.n_spin = QSpinBox()
        self.n_spin.setRange(1, N_MAX)
        self.n_spin.setValue(3)
        self.n_spin.setToolTip("n: the dimension of the ambient space")
        self.k_spin = QSpinBox()
        self.k_spin.setRange(1, N_MAX)
        self.k_spin.setValue(1)
        self.k_spin.setToolTip("k: the number of equations (1 <= k < n); the manifold has dimension n - k")
        row.addWidget(QLabel("n"))
        row.addWidget(self.n_spin)
        row.addSpacing(12)
        row.addWidget(QLabel("k"))
        row.addWidget(self.k_spin)
        self.dim_label = QLabel("")
        self.dim_label.setStyleSheet("color: #666;")
        self.dim_label.setWordWrap(True)   # ("2-dimensional manifold in R^10" beside n and k: two lines if need be)
        row.addSpacing(12)
        row.addWidget(self.dim_label, 1)
        lay.addLayout(row)
        self.nk_error = error_label()
        lay.addWidget(self.nk_error)
        form = QFormLayout()
        form.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        self.vars_edit = QLineEdit()
        self.vars_label = QLabel("variables")
        form.addRow(self.vars_label, self.vars_edit)
        lay.addLayout(form)
        self.vars_error = error_label()
        lay.addWidget(self.vars_error)
        self.show_mode(False)

    def show_mode(self, complex_mode: bool) -> None:
        """In complex mode n and k follow the equations, and the names are the real variables."""
        self.n_spin.setEnabled(not complex_mode)
        self.k_spin.setEnabled(not complex_mode)
        self.vars_label.setText("real variables" if complex_mode else "variables")
        self.vars_edit.setToolTip("the real variables: Re and Im of each complex variable in turn" if complex_mode
                                  else "the variable names, separated by commas")

    def check_nk(self) -> str | None:
        """Mark n and k (and say the manifold's dimension); their error or None."""
        n, k = self.n_spin.value(), self.k_spin.value()
        m = inputs.check_nk(n, k)
        self.nk_error.setText(m or "")
        self.nk_error.setVisible(bool(m))
        self.dim_label.setText("" if m else f"{n - k}-dimensional manifold in R^{n}")
        return m

    def check_variables(self) -> str | None:
        """Mark the names (n of them, distinct, not reserved); their error or None."""
        m = inputs.check_variables(self.vars_edit.text(), self.n_spin.value())
        mark(self.vars_edit, self.vars_error, m)
        return m
