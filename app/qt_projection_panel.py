"""QtProjectionPanel: how the n-dimensional result is turned and projected to 3D.

Edits an :class:`app.projection.ProjectionModel`: the base projection (three
coordinates, a generic orthonormal frame, or the principal axes), one rotation
slider per coordinate plane (i, j) labelled with the variable names, a reset
button; plus the drawing style (colour by a coordinate, opacity, edges).

Signals: ``projectionChanged`` (angles or base changed: update points in
place), ``baseChanged`` (a new base: the viewer may refit the camera),
``styleChanged`` (colour, opacity or edges).
"""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import Qt, Signal
from qtpy.QtWidgets import (
    QCheckBox, QComboBox, QFormLayout, QGridLayout, QGroupBox, QHBoxLayout, QLabel, QPushButton,
    QScrollArea, QSlider, QSpinBox, QVBoxLayout, QWidget,
)

from .projection import KIND_LABELS, KINDS, ProjectionModel, default_axes

SOLID = "(solid colour)"


class QtProjectionPanel(QWidget):
    projectionChanged = Signal()
    baseChanged = Signal()
    styleChanged = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.names: list[str] = ["x1", "x2", "x3"]
        self.model = ProjectionModel(n=3)
        self._updating = False
        self.sliders: list[QSlider] = []
        self.slider_labels: list[QLabel] = []
        self.value_labels: list[QLabel] = []

        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)

        box = QGroupBox("Projection to 3D")
        bl = QVBoxLayout(box)
        form = QFormLayout()
        self.kind_combo = QComboBox()
        for k in KINDS:
            self.kind_combo.addItem(KIND_LABELS[k], k)
        form.addRow("view", self.kind_combo)
        axes_row = QWidget()
        al = QHBoxLayout(axes_row)
        al.setContentsMargins(0, 0, 0, 0)
        self.axis_combos = []
        for lab in ("X", "Y", "Z"):
            c = QComboBox()
            c.setToolTip(f"the coordinate shown along screen {lab}")
            al.addWidget(QLabel(lab))
            al.addWidget(c, 1)
            self.axis_combos.append(c)
        self.axes_row = axes_row
        form.addRow(axes_row)
        self.axes_error = QLabel("")
        self.axes_error.setStyleSheet("color: #c22; font-size: 11px;")
        self.axes_error.setVisible(False)
        form.addRow(self.axes_error)
        self.seed_spin = QSpinBox()
        self.seed_spin.setRange(0, 2**31 - 1)
        self.seed_spin.setToolTip("seed of the generic projection")
        self.seed_label = QLabel("frame seed")
        form.addRow(self.seed_label, self.seed_spin)
        bl.addLayout(form)

        rot_head = QHBoxLayout()
        rot_head.addWidget(QLabel("rotations (degrees) in the planes"))
        rot_head.addStretch(1)
        self.reset_button = QPushButton("Reset")
        self.reset_button.setToolTip("all rotation angles back to 0")
        rot_head.addWidget(self.reset_button)
        bl.addLayout(rot_head)
        self.scroll = QScrollArea()
        self.scroll.setWidgetResizable(True)
        self.scroll.setMinimumHeight(120)
        self.slider_box = QWidget()
        self.slider_grid = QGridLayout(self.slider_box)
        self.slider_grid.setContentsMargins(2, 2, 2, 2)
        self.slider_grid.setVerticalSpacing(1)
        self.scroll.setWidget(self.slider_box)
        bl.addWidget(self.scroll, 1)
        lay.addWidget(box, 1)

        sbox = QGroupBox("Style")
        sf = QFormLayout(sbox)
        self.color_combo = QComboBox()
        self.color_combo.setToolTip("colour the vertices by one of the n coordinates")
        sf.addRow("colour by", self.color_combo)
        self.opacity_slider = QSlider(Qt.Horizontal)
        self.opacity_slider.setRange(5, 100)
        self.opacity_slider.setValue(100)
        sf.addRow("opacity", self.opacity_slider)
        self.edges_check = QCheckBox("show cell edges")
        sf.addRow(self.edges_check)
        lay.addWidget(sbox)

        self.kind_combo.currentIndexChanged.connect(self._on_kind)
        for c in self.axis_combos:
            c.currentIndexChanged.connect(self._on_axes)
        self.seed_spin.valueChanged.connect(self._on_seed)
        self.reset_button.clicked.connect(self.reset)
        self.color_combo.currentIndexChanged.connect(self._on_style)
        self.opacity_slider.valueChanged.connect(self._on_style)
        self.edges_check.toggled.connect(self._on_style)
        self.set_variables(self.names)

    # ------------------------------------------------------------ building
    def set_variables(self, names, keep: bool = True) -> None:
        """Rebuild for a new list of variable names (n = len(names)).

        With ``keep``, the current kind, seed and colour are kept where they still make sense.
        """
        names = list(names)
        n = len(names)
        old = self.model
        color = self.color_by()
        self._updating = True
        try:
            same_n = old.n == n
            self.names = names
            axes = tuple(old.axes) if (keep and same_n) else default_axes(n)
            self.model = ProjectionModel(n=n, kind=old.kind if keep else "coordinates", axes=axes,
                                         seed=old.seed, angles=old.angles if (keep and same_n) else None)
            for c in self.axis_combos:
                c.clear()
                c.addItem("(none)", -1)
                for i, nm in enumerate(names):
                    c.addItem(nm, i)
            for c, a in zip(self.axis_combos, self.model.axes):
                c.setCurrentIndex(c.findData(int(a)))
            self.color_combo.clear()
            self.color_combo.addItem(SOLID, None)
            for nm in names:
                self.color_combo.addItem(nm, nm)
            if color not in names and not keep and names:
                color = names[-1]   # a new system: colour by its last coordinate
            i = self.color_combo.findData(color) if color in names else 0
            self.color_combo.setCurrentIndex(max(i, 0))
            self.kind_combo.setCurrentIndex(self.kind_combo.findData(self.model.kind))
            self._build_sliders()
            self._sync_kind_widgets()
        finally:
            self._updating = False

    def _build_sliders(self) -> None:
        while self.slider_grid.count():
            it = self.slider_grid.takeAt(0)
            w = it.widget()
            if w is not None:
                w.hide()
                w.setParent(None)
                w.deleteLater()
        for r in range(self.slider_grid.rowCount()):
            self.slider_grid.setRowStretch(r, 0)
        self.sliders, self.slider_labels, self.value_labels = [], [], []
        for row, (i, j) in enumerate(self.model.planes):
            lab = QLabel(f"{self.names[i]}\u2013{self.names[j]}")
            lab.setToolTip(f"rotate in the plane of {self.names[i]} and {self.names[j]}")
            s = QSlider(Qt.Horizontal)
            s.setRange(-180, 180)
            s.setValue(int(round(self.model.angles[row])))
            s.setPageStep(15)
            val = QLabel(f"{s.value():+d}\u00b0")
            val.setMinimumWidth(40)
            val.setAlignment(Qt.AlignRight | Qt.AlignVCenter)
            s.valueChanged.connect(lambda v, r=row: self._on_slider(r, v))
            self.slider_grid.addWidget(lab, row, 0)
            self.slider_grid.addWidget(s, row, 1)
            self.slider_grid.addWidget(val, row, 2)
            self.sliders.append(s)
            self.slider_labels.append(lab)
            self.value_labels.append(val)
        self.slider_grid.setColumnStretch(1, 1)
        self.slider_grid.setRowStretch(len(self.sliders), 1)

    def _sync_kind_widgets(self) -> None:
        kind = self.model.kind
        self.axes_row.setVisible(kind == "coordinates")
        self.seed_spin.setVisible(kind == "generic")
        self.seed_label.setVisible(kind == "generic")
        if kind != "coordinates":
            self.axes_error.setVisible(False)

    # ------------------------------------------------------------ handlers
    def _on_kind(self, *_):
        if self._updating:
            return
        self.model.kind = self.kind_combo.currentData()
        self._sync_kind_widgets()
        if self.model.kind == "coordinates":
            self._on_axes()
            return
        self.baseChanged.emit()
        self.projectionChanged.emit()

    def _on_axes(self, *_):
        if self._updating:
            return
        axes = tuple(int(c.currentData()) if c.currentData() is not None else -1 for c in self.axis_combos)
        used = [a for a in axes if a >= 0]
        if len(set(used)) != len(used):
            self.axes_error.setText("each screen axis must show a different coordinate")
            self.axes_error.setVisible(True)
            return
        self.axes_error.setVisible(False)
        self.model.axes = axes
        if self.model.kind == "coordinates":
            self.baseChanged.emit()
            self.projectionChanged.emit()

    def _on_seed(self, v):
        if self._updating:
            return
        self.model.seed = int(v)
        if self.model.kind == "generic":
            self.baseChanged.emit()
            self.projectionChanged.emit()

    def _on_slider(self, row: int, value: int) -> None:
        self.model.angles[row] = float(value)
        self.value_labels[row].setText(f"{value:+d}\u00b0")
        if not self._updating:
            self.projectionChanged.emit()

    def _on_style(self, *_):
        if not self._updating:
            self.styleChanged.emit()

    # ------------------------------------------------------------ API
    def reset(self) -> None:
        """All angles to 0 (one projection update)."""
        self._updating = True
        try:
            self.model.reset_angles()
            for s, v in zip(self.sliders, self.value_labels):
                s.setValue(0)
                v.setText("+0\u00b0")
        finally:
            self._updating = False
        self.projectionChanged.emit()

    def set_angle(self, plane: tuple[int, int], degrees: float) -> None:
        row = self.model.planes.index(tuple(plane))
        self.sliders[row].setValue(int(round(degrees)))

    def set_kind(self, kind: str) -> None:
        self.kind_combo.setCurrentIndex(self.kind_combo.findData(kind))

    def set_axes_by_names(self, axes_names) -> bool:
        """Show the named variables on screen X, Y, Z (coordinate kind). False if a name is unknown."""
        try:
            axes = tuple(self.names.index(a) if a is not None else -1 for a in list(axes_names)[:3])
        except ValueError:
            return False
        self._updating = True
        try:
            for c, a in zip(self.axis_combos, axes):
                c.setCurrentIndex(c.findData(a))
            self.model.axes = axes
            self.model.kind = "coordinates"
            self.kind_combo.setCurrentIndex(self.kind_combo.findData("coordinates"))
            self._sync_kind_widgets()
        finally:
            self._updating = False
        self.baseChanged.emit()
        self.projectionChanged.emit()
        return True

    def apply_view(self, view: dict) -> None:
        """An example's suggested view, silently (the caller redraws): project=[3 names], color=name."""
        self._updating = True
        try:
            names = view.get("project")
            if names:
                try:
                    axes = tuple(self.names.index(a) for a in list(names)[:3])
                except ValueError:
                    axes = None
                if axes is not None:
                    self.model.kind = "coordinates"
                    self.model.axes = axes
                    self.kind_combo.setCurrentIndex(self.kind_combo.findData("coordinates"))
                    for c, a in zip(self.axis_combos, axes):
                        c.setCurrentIndex(c.findData(a))
                    self._sync_kind_widgets()
            if "color" in view:
                self.set_color_by(view.get("color"))
        finally:
            self._updating = False

    def set_style_defaults(self, dim: int) -> None:
        """Opaque surfaces and curves; see-through 2-skeletons with edges above (silently)."""
        self._updating = True
        try:
            self.opacity_slider.setValue(100 if dim <= 2 else 35)
            self.edges_check.setChecked(dim >= 3)
        finally:
            self._updating = False

    def color_by(self) -> str | None:
        return self.color_combo.currentData()

    def set_color_by(self, name: str | None) -> None:
        i = self.color_combo.findData(name) if name else 0
        self.color_combo.setCurrentIndex(max(i, 0))

    def opacity(self) -> float:
        return self.opacity_slider.value() / 100.0

    def show_edges(self) -> bool:
        return self.edges_check.isChecked()

    def matrix(self) -> np.ndarray:
        return self.model.matrix()

    def state(self) -> dict:
        d = self.model.to_dict(self.names)
        d.update(color=self.color_by(), opacity=self.opacity(), show_edges=self.show_edges())
        return d

    def set_state(self, d: dict) -> None:
        """Restore kind, axes, seed, angles and style (the variables must be set first)."""
        n = len(self.names)
        self._updating = True
        try:
            m = ProjectionModel.from_dict(n, d) if len(d.get("angles", [0] * (n * (n - 1) // 2))) == \
                n * (n - 1) // 2 else ProjectionModel(n=n)
            m._principal = self.model._principal
            self.model = m
            self.kind_combo.setCurrentIndex(self.kind_combo.findData(m.kind))
            for c, a in zip(self.axis_combos, m.axes):
                c.setCurrentIndex(c.findData(int(a)))
            self.seed_spin.setValue(m.seed)
            for s, v, a in zip(self.sliders, self.value_labels, m.angles):
                s.setValue(int(round(a)))
                v.setText(f"{int(round(a)):+d}\u00b0")
            self.set_color_by(d.get("color"))
            if "opacity" in d and d["opacity"] is not None:
                self.opacity_slider.setValue(int(round(100 * float(d["opacity"]))))
            self.edges_check.setChecked(bool(d.get("show_edges", False)))
            self._sync_kind_widgets()
        finally:
            self._updating = False
        self.baseChanged.emit()
        self.projectionChanged.emit()
        self.styleChanged.emit()
