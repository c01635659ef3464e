"""Small builders shared by the side panels (one place for the layout boilerplate)."""

from __future__ import annotations

from qtpy.QtCore import Qt
from qtpy.QtWidgets import QGroupBox, QLabel, QSlider, QVBoxLayout

ERROR_LABEL_STYLE = "color: #c22; font-size: 11px;"


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


def slider(lo: int, hi: int, value: int, tip: str = "") -> QSlider:
    s = QSlider(Qt.Horizontal)
    s.setRange(lo, hi)
    s.setValue(value)
    s.setToolTip(tip)
    return s
