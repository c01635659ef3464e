"""QtParameterPanel: one slider per parameter of the formulas (SURFER's a and b, Mathematica's Manipulate).

A parameter is a name in the formulas that is neither a variable nor a constant or
function (:func:`gcmh_core.formula.find_parameters`). Each gets a row: its name, a
slider over [min, max], its value (editable: a constant expression such as ``pi/4``;
a value outside the range widens the range) and the range's ends (editable).

Rows follow the formulas: :meth:`QtParameterPanel.set_names` shows one row per name,
in order; a name that goes away (a formula being retyped) keeps its value and range,
which come back with it.

Signals: ``dragging(name, value)`` while the slider is held (the window re-extracts on a
coarse grid), ``committed(name, value)`` when a value settles (the slider let go, a value
typed, a key or a click on the groove: the full grid), ``changed()`` on every change of a
value or a range (the formula panel's state: sessions and undo).
"""

from __future__ import annotations

import math

from qtpy.QtCore import QSignalBlocker, Qt, Signal
from qtpy.QtWidgets import QGridLayout, QLabel, QLineEdit, QSlider, QVBoxLayout, QWidget

from . import inputs
from .inputs import format_value

STEPS = 200            # slider positions over [min, max]: values are multiples of (max - min) / STEPS
DEFAULT_VALUE = 1.0    # a new parameter's value (0 often makes a formula degenerate: a*x^2)
ERROR_STYLE = "QLineEdit { border: 2px solid #d33; background: #fff0f0; }"


def default_range(value: float) -> tuple[float, float]:
    """A symmetric range around 0 that holds ``value`` with room on both sides: [-s, s], s = 1, 2 or 5 x 10^j."""
    need = max(1.0, 2.0 * abs(float(value)))
    j = math.floor(math.log10(need))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10.0 ** j >= need - 1e-12:
            s = m * 10.0 ** j
            return -s, s
    return -need, need


def step_value(lo: float, hi: float, i: int) -> float:
    """The value at slider position ``i``, rounded to the slider's step (so 0 is 0, not 1e-17)."""
    step = (hi - lo) / STEPS
    v = lo + i * step
    if step > 0:
        v = round(v, max(0, math.ceil(-math.log10(step))) + 1)
    return 0.0 if v == 0 else v


def _number(v) -> float:
    return inputs.parse_number(v) if isinstance(v, str) else float(v)


def spec(value: float, lo: float | None = None, hi: float | None = None) -> dict:
    """A parameter's state {"value", "min", "max"}; a missing or too narrow range is made around the value."""
    value = float(value)
    if lo is None or hi is None or not lo < hi:
        lo, hi = default_range(value)
    return {"value": value, "min": float(min(lo, value)), "max": float(max(hi, value))}


class _Row:
    """The widgets of one parameter."""

    def __init__(self, panel: QtParameterPanel, name: str, state: dict):
        self.name = name
        self.state = dict(state)
        self.label = QLabel(name)
        self.label.setStyleSheet("font-weight: bold;")
        self.label.setToolTip(f"the parameter {name} of the formulas")
        self.slider = QSlider(Qt.Horizontal)
        self.slider.setRange(0, STEPS)
        self.slider.setPageStep(STEPS // 10)
        self.slider.setMinimumWidth(120)
        self.slider.setToolTip(f"drag to change {name}: a coarse grid follows the slider, the full one when "
                               "you let go")
        self.value_edit = QLineEdit()
        self.value_edit.setMaximumWidth(64)
        self.value_edit.setToolTip(f"the value of {name} (a constant expression such as pi/4)")
        self.min_edit = QLineEdit()
        self.max_edit = QLineEdit()
        for e, what in ((self.min_edit, "lower"), (self.max_edit, "upper")):
            e.setMaximumWidth(46)
            e.setToolTip(f"the slider's {what} end")
        self.slider.valueChanged.connect(lambda i: panel._on_slider(self, i))
        self.slider.sliderReleased.connect(lambda: panel._on_released(self))
        self.value_edit.editingFinished.connect(lambda: panel._on_value_typed(self))
        self.min_edit.editingFinished.connect(lambda: panel._on_range_typed(self))
        self.max_edit.editingFinished.connect(lambda: panel._on_range_typed(self))
        self.show_state()

    def widgets(self):
        return (self.label, self.slider, self.value_edit, self.min_edit, self.max_edit)

    def position(self) -> int:
        lo, hi, v = self.state["min"], self.state["max"], self.state["value"]
        return int(round((v - lo) / (hi - lo) * STEPS)) if hi > lo else 0

    def show_state(self) -> None:
        """Put the state into the widgets (without signals)."""
        with QSignalBlocker(self.slider):
            self.slider.setValue(self.position())
        self.value_edit.setText(format_value(self.state["value"]))
        self.min_edit.setText(format_value(self.state["min"]))
        self.max_edit.setText(format_value(self.state["max"]))
        for e in (self.value_edit, self.min_edit, self.max_edit):
            e.setStyleSheet("")


class QtParameterPanel(QWidget):
    """The parameters' sliders; see the module docstring."""

    dragging = Signal(str, float)
    committed = Signal(str, float)
    changed = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.rows: dict[str, _Row] = {}
        self._kept: dict[str, dict] = {}   # the state of names not on show, for when they come back
        self.last_moved: str | None = None
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(2)
        self.title = QLabel("parameters")
        self.title.setStyleSheet("color: #555;")
        lay.addWidget(self.title)
        self.grid_box = QWidget()
        self.grid = QGridLayout(self.grid_box)
        self.grid.setContentsMargins(0, 0, 0, 0)
        self.grid.setHorizontalSpacing(4)
        self.grid.setVerticalSpacing(2)
        lay.addWidget(self.grid_box)
        self.error = QLabel("")
        self.error.setStyleSheet("color: #c22;")
        self.error.setWordWrap(True)
        self.error.setVisible(False)
        lay.addWidget(self.error)
        self.notice = QLabel("")
        self.notice.setWordWrap(True)
        self.notice.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.notice.setStyleSheet("color: #a04000; font-weight: bold;")
        self.notice.setVisible(False)
        lay.addWidget(self.notice)
        self.setVisible(False)

    # ------------------------------------------------------------ rows
    def names(self) -> list[str]:
        return list(self.rows)

    def set_names(self, names) -> bool:
        """One row per name, in this order (a name seen before gets its value and range back);
        False when the rows were these already."""
        names = list(dict.fromkeys(names))
        if names == list(self.rows):
            return False
        for name in list(self.rows):
            row = self.rows.pop(name)
            self._kept[name] = dict(row.state)
            for w in row.widgets():
                self.grid.removeWidget(w)
                w.deleteLater()
        for r, name in enumerate(names):
            row = _Row(self, name, self._kept.get(name) or spec(DEFAULT_VALUE))
            self.rows[name] = row
            for c, w in enumerate(row.widgets()):
                self.grid.addWidget(w, r, c)
        self.grid.setColumnStretch(1, 1)
        self.title.setText("parameters: drag a slider, the manifold follows" if names else "")
        self.setVisible(bool(names))
        if not names:
            self.set_notice("")
        return True

    def values(self) -> dict[str, float]:
        """{name: value} of the rows on show."""
        return {name: row.state["value"] for name, row in self.rows.items()}

    def state(self) -> dict[str, dict]:
        """{name: {"value", "min", "max"}} of the rows on show."""
        return {name: dict(row.state) for name, row in self.rows.items()}

    def set_state(self, d: dict) -> None:
        """Values and ranges, {name: {"value", "min", "max"}} or {name: value}; rows follow :meth:`set_names`
        (a name without a row keeps its state for when its row comes)."""
        for name, s in (d or {}).items():
            s = s if isinstance(s, dict) else {"value": s}
            try:   # (numbers, or constant texts from a hand-written session)
                v, lo, hi = (None if s.get(key) is None else _number(s.get(key)) for key in ("value", "min", "max"))
            except (inputs.NumberError, TypeError, ValueError):
                continue   # a value that is no number: the row keeps its own
            s = spec(DEFAULT_VALUE if v is None else v, lo, hi)
            self._kept[name] = s
            if name in self.rows:
                self.rows[name].state = dict(s)
                self.rows[name].show_state()

    def set_value(self, name: str, value: float, commit: bool = True) -> None:
        """Set ``name``'s value as if typed (the range widens to hold it); ``commit``: say ``committed``."""
        row = self.rows[name]
        row.state = spec(value, row.state["min"], row.state["max"])
        row.show_state()
        self.last_moved = name
        self.changed.emit()
        if commit:
            self.committed.emit(name, row.state["value"])

    # ------------------------------------------------------------ the notice of a critical value
    def set_notice(self, text: str) -> None:
        self.notice.setText(text)
        self.notice.setVisible(bool(text))

    # ------------------------------------------------------------ user input
    def _on_slider(self, row: _Row, i: int) -> None:
        row.state["value"] = step_value(row.state["min"], row.state["max"], i)
        row.value_edit.setText(format_value(row.state["value"]))
        row.value_edit.setStyleSheet("")
        self.last_moved = row.name
        self.changed.emit()
        if row.slider.isSliderDown():
            self.dragging.emit(row.name, row.state["value"])
        else:   # a key, the wheel or a click on the groove: the value is where it stays
            self.committed.emit(row.name, row.state["value"])

    def _on_released(self, row: _Row) -> None:
        self.committed.emit(row.name, row.state["value"])

    def _read(self, edit: QLineEdit) -> float | None:
        try:
            v = inputs.parse_number(edit.text())
        except inputs.NumberError as e:
            self._mark(edit, f"{edit.text().strip() or 'empty'}: {e}")
            return None
        self._mark(edit, None)
        return v

    def _mark(self, edit: QLineEdit, message: str | None) -> None:
        edit.setStyleSheet(ERROR_STYLE if message else "")
        edit.setToolTip(message or "")
        self.error.setText(message or "")
        self.error.setVisible(bool(message))

    def _on_value_typed(self, row: _Row) -> None:
        v = self._read(row.value_edit)
        if v is None or v == row.state["value"]:
            return
        self.set_value(row.name, v)

    def _on_range_typed(self, row: _Row) -> None:
        lo, hi = self._read(row.min_edit), self._read(row.max_edit)
        if lo is None or hi is None:
            return
        if not lo < hi:
            self._mark(row.max_edit, f"{row.name}: the range needs min < max")
            return
        if (lo, hi) == (row.state["min"], row.state["max"]):
            return
        v = min(max(row.state["value"], lo), hi)
        moved = v != row.state["value"]
        row.state = {"value": v, "min": lo, "max": hi}
        row.show_state()
        self.changed.emit()
        if moved:   # the value had to come inside the new range
            self.last_moved = row.name
            self.committed.emit(row.name, v)
