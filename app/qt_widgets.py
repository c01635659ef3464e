"""Small builders shared by the side panels (one place for the layout boilerplate)."""

from __future__ import annotations

from contextlib import ExitStack, contextmanager

from qtpy.QtCore import QObject, QSignalBlocker, Qt, Signal
from qtpy.QtWidgets import QComboBox, QGroupBox, QLabel, QScrollArea, QSlider, QVBoxLayout

from .latest import LatestCall

ERROR_LABEL_STYLE = "color: #c22; font-size: 11px;"
ERROR_STYLE = "QLineEdit { border: 2px solid #d33; background: #fff0f0; }"


def panel_layout(widget) -> QVBoxLayout:
    """The panel's own vertical layout, flush with its edges."""
    lay = QVBoxLayout(widget)
    lay.setContentsMargins(0, 0, 0, 0)
    return lay


def group(parent_layout, title: str, layout_cls=QVBoxLayout, stretch: int = 0):
    """A titled group box added to ``parent_layout``; returns (box, the box's layout)."""
    box = QGroupBox(title)
    inner = layout_cls(box)
    parent_layout.addWidget(box, stretch)
    return box, inner


def error_label() -> QLabel:
    """A hidden red one-line message to show next to a field."""
    lab = QLabel("")
    lab.setStyleSheet(ERROR_LABEL_STYLE)
    lab.setWordWrap(True)
    lab.setVisible(False)
    return lab


def mark(edit, label: QLabel, message: str | None) -> None:
    """A field in red with ``message`` under it (and as its tip), or back to normal with None."""
    edit.setStyleSheet(ERROR_STYLE if message else "")
    edit.setToolTip(message or "")
    label.setText(message or "")
    label.setVisible(bool(message))


def slider(lo: int, hi: int, value: int, tip: str = "") -> QSlider:
    s = QSlider(Qt.Horizontal)
    s.setRange(lo, hi)
    s.setValue(value)
    s.setToolTip(tip)
    return s


def narrow_combo(chars: int = 18) -> QComboBox:
    """A combo box as wide as ``chars`` characters when closed (its list shows the whole labels): long
    labels ("GCCH (continuation from a start point)") widened every side panel past a third of 1024 px."""
    combo = QComboBox()
    combo.setSizeAdjustPolicy(QComboBox.AdjustToMinimumContentsLengthWithIcon)
    combo.setMinimumContentsLength(chars)
    return combo


def labelled_row(form, text: str, field):
    """Add ``field`` to a QFormLayout under a label the caller can change or hide; returns the label."""
    lab = QLabel(text)
    form.addRow(lab, field)
    return lab


def slider_row(form, text: str, lo: int, hi: int, value: int, tip: str = ""):
    """A labelled horizontal slider row in a QFormLayout: (slider, label)."""
    s = slider(lo, hi, value, tip)
    return s, labelled_row(form, text, s)


@contextmanager
def blocked(*objects):
    """No signals from ``objects`` inside the block (one QSignalBlocker each: showing the model's state in
    widgets must not write it back)."""
    with ExitStack() as stack:
        for obj in objects:
            stack.enter_context(QSignalBlocker(obj))
        yield


def scrolled(widget) -> QScrollArea:
    """``widget`` in a vertical scroll area (a side panel's tab)."""
    sc = QScrollArea()
    sc.setWidgetResizable(True)
    sc.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
    sc.setWidget(widget)
    return sc


def connect_all(signals, slot) -> None:
    """Connect every signal in ``signals`` to ``slot``."""
    for sig in signals:
        sig.connect(slot)


def clear_layout(layout) -> None:
    """Remove and delete every widget of ``layout`` (hidden first, so nothing flashes as a top-level window)."""
    while layout.count():
        w = layout.takeAt(0).widget()
        if w is not None:
            w.hide()
            w.setParent(None)
            w.deleteLater()


class QtLatestCall(QObject):
    """A :class:`gcmh_studio.latest.LatestCall` whose answers come on the GUI thread:
    ``answered(key, value, error)``, queued from the worker (the newest request wins)."""

    answered = Signal(object, object, object)

    def __init__(self, parent=None, name: str = "gcmh-latest-call"):
        super().__init__(parent)
        self.calls = LatestCall(self._relay, name)
        self.ask, self.submit, self.busy = self.calls.ask, self.calls.submit, self.calls.busy

    def _relay(self, key, value, error) -> None:
        # (the signal is looked up at each answer: once this object is deleted that raises RuntimeError, which
        # ends the thread; a bound signal kept from before would emit on freed memory)
        self.answered.emit(key, value, error)
