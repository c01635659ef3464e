"""QtDomainBox: the Manifold tab's domain and grid, the bounds of each axis, div (one for all axes or per
axis) and the glued axes.

The box checks its own fields (:meth:`QtDomainBox.check`: a bad cell turns red, a message names the axis) and
says ``edited`` when one changes; the formula panel reads it. Changing n hides rows rather than deleting them:
they come back as they were when n grows again.
"""

from __future__ import annotations

import math
from fractions import Fraction

from qtpy.QtCore import Signal
from qtpy.QtGui import QColor
from qtpy.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
)

from . import inputs
from .qt_widgets import blocked, error_label, mark

BAD_CELL = QColor("#ffc8c8")
GOOD_CELL = QColor("#ffffff")


def format_number(v: float) -> str:
    """Short text for a bound: simple multiples of pi as ``-pi/2``, others as ``%g``."""
    v = float(v)
    if v == 0:
        return "0"
    fr = Fraction(v / math.pi).limit_denominator(12)
    if fr != 0 and abs(float(fr) * math.pi - v) < 1e-12 * max(1.0, abs(v)):
        p, q = fr.numerator, fr.denominator
        sign = "-" if p < 0 else ""
        p = abs(p)
        num = "pi" if p == 1 else f"{p}*pi"
        return f"{sign}{num}" if q == 1 else f"{sign}{num}/{q}"
    return f"{v:.10g}"


class QtDomainBox(QGroupBox):
    """Bounds per axis, div, "per axis" and the glued axes."""

    edited = Signal()

    def __init__(self, parent=None):
        super().__init__("Domain and grid", parent)
        dl = QVBoxLayout(self)
        self._kept_rows: list[tuple[str, str, str]] = []   # what a smaller n hid, to bring back
        self.table = QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels(["lower", "upper", "div"])
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.Stretch)
        self.table.verticalHeader().setDefaultSectionSize(22)
        self.table.setEditTriggers(QAbstractItemView.AllEditTriggers)
        self.table.setToolTip("bounds per axis; constant expressions such as -pi/2 are fine")
        dl.addWidget(self.table)
        self.domain_error = error_label()
        dl.addWidget(self.domain_error)
        drow = QHBoxLayout()
        drow.addWidget(QLabel("div"))
        self.div_edit = QLineEdit("10")
        self.div_edit.setMaximumWidth(70)
        self.div_edit.setToolTip("grid divisions per axis (one number for all axes)")
        drow.addWidget(self.div_edit)
        self.per_axis = QCheckBox("per axis")
        self.per_axis.setToolTip("set a different div for each axis in the table")
        drow.addWidget(self.per_axis)
        drow.addStretch(1)
        dl.addLayout(drow)
        gform = QFormLayout()
        gform.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        self.periodic_edit = QLineEdit()
        self.periodic_edit.setPlaceholderText("none (e.g. t  s:flip=t)")
        self.periodic_edit.setToolTip(
            "axes whose ends are the same point (angles): 't' glues t's lower and upper bound; "
            "'s:flip=t' glues s's and reverses t across that seam (the Klein bottle, the Moebius band). "
            "F must be invariant under the gluing; a reversed axis needs an even div")
        gform.addRow("glued axes", self.periodic_edit)
        dl.addLayout(gform)
        self.periodic_error = error_label()
        dl.addWidget(self.periodic_error)
        self.div_error = error_label()
        dl.addWidget(self.div_error)
        self.table.itemChanged.connect(lambda *_: self.edited.emit())
        self.div_edit.textChanged.connect(lambda *_: self.edited.emit())
        self.periodic_edit.textChanged.connect(lambda *_: self.edited.emit())
        self.per_axis.toggled.connect(self._on_per_axis)
        self._show_per_axis()

    # ------------------------------------------------------------ rows
    def cell(self, r: int, c: int) -> str:
        it = self.table.item(r, c)
        return it.text() if it is not None else ""

    def resize_rows(self, n: int, fresh: bool, complex_mode: bool) -> None:
        """n rows, keeping what was typed (and what an earlier n hid); ``fresh``: a new system, whose rows
        take nothing from the old one."""
        old = [] if fresh else [(self.cell(r, 0), self.cell(r, 1), self.cell(r, 2))
                                for r in range(self.table.rowCount())]
        old = self._kept_rows = old + ([] if fresh else self._kept_rows[len(old):])
        with blocked(self.table):
            self.table.setRowCount(n)
            for r in range(n):
                blank = ("-2", "2") if complex_mode else ("-1", "1")   # (C^m: complex_equations.DEFAULT_BOUNDS)
                lo, hi, dv = old[r] if r < len(old) else (*blank, self.div_edit.text() or "10")
                for c, t in enumerate((lo, hi, dv)):
                    self.table.setItem(r, c, QTableWidgetItem(t))
        h = self.table.verticalHeader().defaultSectionSize() * min(n, 6) + self.table.horizontalHeader().height() + 6
        self.table.setFixedHeight(h)

    def set_headers(self, names, meaning: dict) -> None:
        """The rows named by the variables ("u = Re w" in complex mode)."""
        labels = [names[r] if r < len(names) else f"x{r + 1}" for r in range(self.table.rowCount())]
        self.table.setVerticalHeaderLabels([f"{nm} = {meaning[nm]}" if nm in meaning else nm for nm in labels])

    def set_all_bounds(self, lo: float, hi: float) -> None:
        with blocked(self.table):
            for r in range(self.table.rowCount()):
                self.table.item(r, 0).setText(format_number(lo))
                self.table.item(r, 1).setText(format_number(hi))

    def _show_per_axis(self) -> None:
        self.table.setColumnHidden(2, not self.per_axis.isChecked())
        self.div_edit.setEnabled(not self.per_axis.isChecked())

    def _on_per_axis(self, on: bool) -> None:
        self._show_per_axis()
        v = inputs.check_div(self.div_edit.text())[1]
        if on and v is not None:   # every axis starts from the common div
            with blocked(self.table):
                for r in range(self.table.rowCount()):
                    self.table.item(r, 2).setText(str(v))
        self.edited.emit()

    # ------------------------------------------------------------ checks and values
    def check(self, names, n: int) -> dict[str, str]:
        """Mark the cells and fields; their errors by field ("domain", "div", "glued axes")."""
        errs, msgs = {}, []
        with blocked(self.table):
            for r in range(self.table.rowCount()):
                elo, ehi, _ = inputs.check_bounds(self.cell(r, 0), self.cell(r, 1))
                name = names[r] if r < len(names) else f"x{r + 1}"
                for c, e in ((0, elo), (1, ehi)):
                    it = self.table.item(r, c)
                    if it is not None:
                        it.setBackground(BAD_CELL if e else GOOD_CELL)
                        it.setToolTip(e or "")
                if elo or ehi:
                    if ehi and not elo and "empty interval" in ehi:
                        self.table.item(r, 0).setBackground(BAD_CELL)
                    msgs.append(f"{name}: {elo or ehi}")
                if self.per_axis.isChecked():
                    ed = inputs.check_div(self.cell(r, 2))[0]
                    it = self.table.item(r, 2)
                    if it is not None:
                        it.setBackground(BAD_CELL if ed else GOOD_CELL)
                        it.setToolTip(ed or "")
                    if ed:
                        msgs.append(f"{name}: {ed}")
        msg = "; ".join(msgs[:3]) + (" ..." if len(msgs) > 3 else "")
        self.domain_error.setText(msg)
        self.domain_error.setVisible(bool(msg))
        if msg:
            errs["domain"] = msg
        m = None if self.per_axis.isChecked() else inputs.check_div(self.div_edit.text())[0]
        mark(self.div_edit, self.div_error, m)
        if m:
            errs["div"] = m
        m = inputs.check_periodic(self.periodic_edit.text(), names, self.div_list(n))[0]
        mark(self.periodic_edit, self.periodic_error, m)
        if m:
            errs["glued axes"] = m
        return errs

    def bounds(self) -> list[tuple[float, float]]:
        out = []
        for r in range(self.table.rowCount()):
            _, _, pair = inputs.check_bounds(self.cell(r, 0), self.cell(r, 1))
            if pair is None:
                raise ValueError(f"bad bounds in row {r + 1}")
            out.append(pair)
        return out

    def div(self):
        """An int, or a list of n ints when 'per axis' is on."""
        if self.per_axis.isChecked():
            return [inputs.check_div(self.cell(r, 2))[1] for r in range(self.table.rowCount())]
        return inputs.check_div(self.div_edit.text())[1]

    def div_list(self, n: int) -> list[int] | None:
        d = self.div()
        if d is None or (isinstance(d, list) and None in d):
            return None
        return list(d) if isinstance(d, list) else [d] * n

    def periodic(self, names, n: int) -> list[str]:
        """The glued axes as extract's periodic= list ([] when none or the field is wrong)."""
        return inputs.check_periodic(self.periodic_edit.text(), names, self.div_list(n))[1]

    # ------------------------------------------------------------ state
    def state(self) -> dict:
        rows = range(self.table.rowCount())
        return {"bounds": [[self.cell(r, 0), self.cell(r, 1)] for r in rows],
                "div": [self.cell(r, 2) for r in rows] if self.per_axis.isChecked() else self.div_edit.text(),
                "periodic": self.periodic_edit.text()}

    def set_state(self, d: dict, n: int) -> None:
        """Fill the rows and fields from a dict like :meth:`state` (numbers or texts)."""
        bounds = d.get("bounds")
        with blocked(self.table, self.per_axis, self.div_edit, self.periodic_edit):
            if bounds is not None:
                if len(bounds) == 2 and not isinstance(bounds[0], (list, tuple)):
                    bounds = [bounds] * n
                for r, (lo, hi) in enumerate(list(bounds)[:n]):
                    self.table.item(r, 0).setText(lo if isinstance(lo, str) else format_number(lo))
                    self.table.item(r, 1).setText(hi if isinstance(hi, str) else format_number(hi))
            div = d.get("div", 10)
            vals = [str(v) for v in div] if isinstance(div, (list, tuple)) else [str(div)]
            per_axis = len(set(vals)) > 1
            self.per_axis.setChecked(per_axis)
            if per_axis:
                for r, v in enumerate(vals[:n]):
                    self.table.item(r, 2).setText(v)
            else:
                self.div_edit.setText(vals[0])
            periodic = d.get("periodic") or ""
            if isinstance(periodic, (list, tuple)):
                periodic = "  ".join(str(p) for p in periodic)
            self.periodic_edit.setText(str(periodic))
        self._show_per_axis()
