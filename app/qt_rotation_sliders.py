"""QtRotationSliders: the View tab's turning controls, on the model's projection.

One rotation slider per coordinate plane (i, j), labelled with the variable
names. Many planes (n = 10 has 45): the planes that bring a hidden axis into
view come first, then the screen's own, then the hidden ones among themselves
(marked: they move nothing alone in an orthographic view); a filter box keeps
the rows naming a variable. One small pad per hidden direction turns the
screen's X and Y against it (n - 3 pads instead of n(n-1)/2 sliders); Shift-drag
on the view turns against the hidden direction chosen in "Shift-drag turns".
"Keep camera" holds the camera when results, mappings and slices change.

The widgets write the model (:class:`gcmh_studio.model.StudioModel`: its
projection's angles, its style's ``keep_camera``) and show what it holds
(:meth:`show_angles`, :meth:`place`, :meth:`rebuild`, called by the View tab on
the model's events).
"""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import QSignalBlocker, Qt
from qtpy.QtWidgets import (
    QCheckBox,
    QComboBox,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QScrollArea,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from .model import StudioModel
from .projection import axis_label, hidden_directions
from .qt_turn_pad import QtTurnPad
from .qt_widgets import clear_layout

PADS_PER_ROW = 4


class QtRotationSliders(QWidget):
    """The rotation sliders, turn pads, plane filter, Reset and the Shift-drag and camera switches."""

    def __init__(self, model: StudioModel, parent=None):
        super().__init__(parent)
        self.studio = model
        self.sliders: list[QSlider] = []
        self.slider_labels: list[QLabel] = []
        self.value_labels: list[QLabel] = []
        self.pads: list[QtTurnPad] = []
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)

        cam_row = QHBoxLayout()
        self.keep_camera_check = QCheckBox("keep camera")
        self.keep_camera_check.setToolTip("hold the camera still: no refitting when a result, the mapping or "
                                          "a slice changes the object's extent")
        lay.addWidget(self.keep_camera_check)
        cam_row.addWidget(QLabel("Shift-drag turns"))
        self.drag_combo = QComboBox()
        self.drag_combo.setToolTip("Shift-drag on the view turns the screen's x and y against this hidden "
                                   "direction; Ctrl+Shift-drag (or Shift with the right button) against the next")
        cam_row.addWidget(self.drag_combo, 1)
        lay.addLayout(cam_row)
        self.pad_label = QLabel("turn X, Y into")
        lay.addWidget(self.pad_label)
        self.pad_row = QGridLayout()   # (rows of PADS_PER_ROW: at n = 10 one row was wider than the panel)
        self.pad_row.setSpacing(4)
        lay.addLayout(self.pad_row)
        rot_head = QHBoxLayout()
        rot_head.addWidget(QLabel("rotations (degrees)"))
        self.plane_filter = QLineEdit()
        self.plane_filter.setPlaceholderText("filter planes, e.g. x4")
        self.plane_filter.setClearButtonEnabled(True)
        self.plane_filter.setToolTip("show only the planes whose names contain this text")
        rot_head.addWidget(self.plane_filter, 1)
        self.reset_button = QPushButton("Reset")
        self.reset_button.setToolTip("all rotation angles back to 0")
        rot_head.addWidget(self.reset_button)
        lay.addLayout(rot_head)
        self.scroll = QScrollArea()
        self.scroll.setWidgetResizable(True)
        self.scroll.setMinimumHeight(120)
        self.slider_box = QWidget()
        self.slider_grid = QGridLayout(self.slider_box)
        self.slider_grid.setContentsMargins(2, 2, 2, 2)
        self.slider_grid.setVerticalSpacing(1)
        self.scroll.setWidget(self.slider_box)
        lay.addWidget(self.scroll, 1)

        self.reset_button.clicked.connect(self.reset)
        self.plane_filter.textChanged.connect(self._filter_planes)
        self.keep_camera_check.toggled.connect(lambda on: self.studio.set_style(keep_camera=bool(on)))
        self.drag_combo.currentIndexChanged.connect(lambda i: setattr(self.studio, "drag_hidden", max(0, i)))

    @property
    def names(self) -> list[str]:
        return self.studio.view_names

    # ------------------------------------------------------------ showing the model
    def rebuild(self) -> None:
        """One slider per plane of the model's projection (new variables)."""
        p = self.studio.projection
        clear_layout(self.slider_grid)
        for r in range(self.slider_grid.rowCount()):
            self.slider_grid.setRowStretch(r, 0)
        self.sliders, self.slider_labels, self.value_labels = [], [], []
        names = self.names
        for row, (i, j) in enumerate(p.planes):
            lab = QLabel(f"{names[i]}\u2013{names[j]}")
            lab.setToolTip(f"rotate in the plane of {names[i]} and {names[j]}")
            s = QSlider(Qt.Horizontal)
            s.setRange(-180, 180)
            s.setPageStep(15)
            val = QLabel("")
            val.setMinimumWidth(40)
            val.setAlignment(Qt.AlignRight | Qt.AlignVCenter)
            s.valueChanged.connect(lambda v, r=row: self._on_slider(r, v))
            self.sliders.append(s)
            self.slider_labels.append(lab)
            self.value_labels.append(val)
        self.show_angles()
        self.place()
        self.slider_grid.setColumnStretch(1, 1)
        self.slider_grid.setRowStretch(len(self.sliders), 1)

    def show_angles(self) -> None:
        for s, v, a in zip(self.sliders, self.value_labels, self.studio.projection.angles):
            with QSignalBlocker(s):
                s.setValue(int(round(a)))
            v.setText(f"{int(round(a)):+d}\u00b0")

    def show_keep_camera(self) -> None:
        with QSignalBlocker(self.keep_camera_check):
            self.keep_camera_check.setChecked(self.studio.style.keep_camera)

    def _shown_axes(self) -> set[int]:
        p = self.studio.projection
        return {int(a) for a in p.axes if a >= 0} if p.kind == "coordinates" else {0, 1, 2}

    def plane_order(self) -> list[int]:
        """Rows of the planes in the order shown: a screen axis against a hidden one first (they bring
        the hidden into view), then the screen's own, then hidden against hidden."""
        shown, planes = self._shown_axes(), self.studio.projection.planes

        def rank(row):
            i, j = planes[row]
            return ({1: 0, 2: 1, 0: 2}[(i in shown) + (j in shown)], row)
        return sorted(range(len(planes)), key=rank)

    def place(self) -> None:
        """Put the rows in :meth:`plane_order` (the lists stay in plane order), mark the hidden-only planes, and
        fill the Shift-drag choice and the pads for the base's hidden directions."""
        p, names, shown = self.studio.projection, self.names, self._shown_axes()
        for pos, row in enumerate(self.plane_order()):
            i, j = p.planes[row]
            lab = self.slider_labels[row]
            hidden_only = p.n > 3 and i not in shown and j not in shown
            lab.setStyleSheet("color: #888;" if hidden_only else "")
            lab.setToolTip(f"rotate in the plane of {names[i]} and {names[j]}" + (
                " (both hidden: moves nothing alone in an orthographic view; it acts with the other planes, "
                "or under perspective and stereographic)" if hidden_only else ""))
            for col, w in enumerate((lab, self.sliders[row], self.value_labels[row])):
                self.slider_grid.addWidget(w, pos, col)
        self._filter_planes(self.plane_filter.text())
        self._fill_hidden()

    def _filter_planes(self, text: str = "") -> None:
        words = str(text).replace(",", " ").split()
        names = self.names
        for row, (i, j) in enumerate(self.studio.projection.planes):
            pair = (names[i].lower(), names[j].lower())
            ok = all(any(w.lower() == nm or w.lower() in nm for nm in pair) for w in words)
            for w in (self.slider_labels[row], self.sliders[row], self.value_labels[row]):
                w.setVisible(ok)

    def _fill_hidden(self) -> None:
        p, names = self.studio.projection, self.names
        H = hidden_directions(p.base()) if p.n >= 4 else np.zeros((0, p.n))
        labels = [axis_label(H[r], names) or f"hidden {r + 1}" for r in range(len(H))]
        prev = self.drag_combo.currentIndex()
        with QSignalBlocker(self.drag_combo):
            self.drag_combo.clear()
            for r, text in enumerate(labels):
                self.drag_combo.addItem(text, r)
            self.drag_combo.setCurrentIndex(min(max(prev, 0), self.drag_combo.count() - 1))
        self.studio.drag_hidden = self.drag_hidden()
        self.drag_combo.setEnabled(p.n >= 4)
        clear_layout(self.pad_row)
        self.pads = []
        self.pad_label.setVisible(p.n >= 4)
        if p.n < 4:
            return
        for r, text in enumerate(labels):
            pad = QtTurnPad(text if not text.startswith("hidden ") else f"h{r + 1}", r)
            pad.dragged.connect(self.turn_screen)
            self.pad_row.addWidget(pad, r // PADS_PER_ROW, r % PADS_PER_ROW)
            self.pads.append(pad)

    # ------------------------------------------------------------ turning
    def _on_slider(self, row: int, value: int) -> None:
        self.studio.projection.angles[row] = float(value)
        self.value_labels[row].setText(f"{value:+d}\u00b0")
        self.studio.projection_changed()

    def reset(self) -> None:
        """All angles to 0 (one projection update)."""
        self.studio.projection.reset_angles()
        self.studio.projection_changed()

    def turn_screen(self, hidden: int, dx: float, dy: float) -> None:
        """Turn the projection's X by ``dx`` and Y by ``dy`` degrees against hidden direction ``hidden``
        (one projection update; the sliders follow)."""
        self.studio.turn((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), hidden, dx, dy)

    def drag_hidden(self) -> int:
        """The hidden direction a Shift-drag turns against (0: the first)."""
        return max(0, self.drag_combo.currentIndex())
