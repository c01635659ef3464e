"""QtProjectionPanel: how the n-dimensional result is turned and projected to 3D.

Edits an :class:`gcmh_studio.projection.ProjectionModel`: the base projection (three
coordinates, a generic orthonormal frame, or the principal axes), the mapping
(orthographic, perspective with an eye distance, stereographic), one rotation
slider per coordinate plane (i, j) labelled with the variable names, a reset
button; a slice (a window ``[c - w, c + w]`` of a coordinate or of a hidden
direction, sliders for c and w as fractions of the range the window reports);
plus the drawing style (colour by a coordinate, opacity, edges, two-sided
colours, boundary and grid overlays).

Many planes (n = 10 has 45): the planes that bring a hidden axis into view come
first, then the screen's own, then the hidden ones among themselves (marked: they
move nothing alone in an orthographic view); a filter box keeps the rows naming
a variable. Shift-drag on the view turns the screen against the hidden direction
chosen in "Shift-drag turns" (Ctrl+Shift: the next one). "Keep camera" holds the
camera when results, mappings and slices change.

Signals: ``projectionChanged`` (angles, base or mapping changed: update points
in place), ``baseChanged`` (a new base: the viewer may refit the camera),
``styleChanged`` (colour, opacity, edges, overlays), ``sliceChanged``.
"""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import QPointF, Qt, Signal
from qtpy.QtGui import QColor, QPainter, QPen
from qtpy.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QScrollArea,
    QSlider,
    QSpinBox,
    QWidget,
)

from .projection import KIND_LABELS, KINDS, MAPPING_LABELS, MAPPINGS, ProjectionModel, default_axes
from .qt_widgets import clear_layout, connect_all, error_label, group, panel_layout, slider, slider_row
from .slicing import SliceWindow

SOLID = "(solid colour)"


class QtProjectionPanel(QWidget):
    projectionChanged = Signal()
    baseChanged = Signal()
    styleChanged = Signal()
    sliceChanged = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.names: list[str] = ["x1", "x2", "x3"]
        self.model = ProjectionModel(n=3)
        self._updating = False
        self.sliders: list[QSlider] = []
        self.slider_labels: list[QLabel] = []
        self.value_labels: list[QLabel] = []

        lay = panel_layout(self)

        box, bl = group(lay, "Projection to 3D", stretch=1)
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
        self.mapping_combo = QComboBox()
        for k in MAPPINGS:
            self.mapping_combo.addItem(MAPPING_LABELS[k], k)
        self.mapping_combo.setToolTip("how R^n goes to 3D; perspective and stereographic need n >= 4")
        form.addRow("mapping", self.mapping_combo)
        self.distance_slider, self.distance_label = slider_row(
            form, "eye distance 3.0", 11, 100, 30, "perspective: the eye's distance, in radii of the object")
        self.mapping_error = error_label()
        form.addRow(self.mapping_error)
        bl.addLayout(form)

        cam_row = QHBoxLayout()
        self.keep_camera_check = QCheckBox("keep camera")
        self.keep_camera_check.setToolTip("hold the camera still: no refitting when a result, the mapping or "
                                          "a slice changes the object's extent")
        cam_row.addWidget(self.keep_camera_check)
        cam_row.addStretch(1)
        cam_row.addWidget(QLabel("Shift-drag turns"))
        self.drag_combo = QComboBox()
        self.drag_combo.setToolTip("Shift-drag on the view turns the screen's x and y against this hidden "
                                   "direction; Ctrl+Shift-drag (or Shift with the right button) against the next")
        cam_row.addWidget(self.drag_combo)
        bl.addLayout(cam_row)
        # one small pad per hidden direction: dragging in it turns the screen's X (sideways) and Y (up and
        # down) against that direction -- n - 3 pads instead of n(n-1)/2 sliders
        self.pad_row = QHBoxLayout()
        self.pad_row.setSpacing(4)
        self.pads: list[QtTurnPad] = []
        bl.addLayout(self.pad_row)
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

        self.slice_box, slf = group(lay, "Slice", QFormLayout)
        self.slice_box.setCheckable(True)
        self.slice_box.setChecked(False)
        self.slice_box.setToolTip("show only the part of the complex inside a window of one direction")
        self.slice_combo = QComboBox()
        self.slice_combo.setToolTip("a coordinate, or a direction the current projection hides")
        slf.addRow("along", self.slice_combo)
        self.slice_c, self.slice_c_label = slider_row(slf, "centre", 0, 1000, 500,
                                                      "centre of the window (across the whole range)")
        self.slice_w, self.slice_w_label = slider_row(slf, "width", 1, 500, 40,
                                                      "half-width of the window (thousandths of the range)")
        self.slice_info = QLabel("")
        self.slice_info.setStyleSheet("color: #666; font-size: 11px;")
        slf.addRow(self.slice_info)

        sbox, sf = group(lay, "Style", QFormLayout)
        self.color_combo = QComboBox()
        self.color_combo.setToolTip("colour the vertices by one of the n coordinates")
        sf.addRow("colour by", self.color_combo)
        self.opacity_slider = slider(5, 100, 100)
        sf.addRow("opacity", self.opacity_slider)
        self.edges_check = QCheckBox("show cell edges")
        sf.addRow(self.edges_check)
        self.two_sided_check = QCheckBox("two-sided colours (front gold, back blue)")
        self.two_sided_check.setToolTip("colour the two sides of the coherently oriented surface apart; "
                                        "a non-orientable surface shows where they swap")
        sf.addRow(self.two_sided_check)
        self.boundary_check = QCheckBox("highlight the boundary")
        sf.addRow(self.boundary_check)
        self.grid_check = QCheckBox("show the grid cubes it passes through")
        sf.addRow(self.grid_check)

        self.kind_combo.currentIndexChanged.connect(self._on_kind)
        for c in self.axis_combos:
            c.currentIndexChanged.connect(self._on_axes)
        self.seed_spin.valueChanged.connect(self._on_seed)
        self.reset_button.clicked.connect(self.reset)
        self.plane_filter.textChanged.connect(self._filter_planes)
        self.baseChanged.connect(self._rows_for_base)
        connect_all((self.color_combo.currentIndexChanged, self.opacity_slider.valueChanged,
                     self.edges_check.toggled, self.two_sided_check.toggled, self.boundary_check.toggled,
                     self.grid_check.toggled), self._on_style)
        self.mapping_combo.currentIndexChanged.connect(self._on_mapping)
        self.distance_slider.valueChanged.connect(self._on_distance)
        connect_all((self.slice_box.toggled, self.slice_combo.currentIndexChanged, self.slice_c.valueChanged,
                     self.slice_w.valueChanged), self._on_slice)
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
            self.model.mapping = old.mapping if (keep and n >= 4) else "orthographic"
            self.model.distance = old.distance
            self.mapping_combo.setCurrentIndex(self.mapping_combo.findData(self.model.mapping))
            prev = self.slice_combo.currentData()
            self.slice_combo.clear()
            for i, nm in enumerate(names):
                self.slice_combo.addItem(nm, (i, False))
            for j in range(max(0, n - 3)):
                self.slice_combo.addItem(f"hidden direction {j + 1}", (j, True))
            i = self.slice_combo.findData(prev) if (keep and same_n and prev is not None) else -1
            self.slice_combo.setCurrentIndex(i if i >= 0 else max(0, n - 1))
            if not (keep and same_n):
                self.slice_box.setChecked(False)
            self._build_sliders()
            self._sync_kind_widgets()
        finally:
            self._updating = False

    def plane_order(self) -> list[int]:
        """Rows of the planes in the order shown: a screen axis against a hidden one first (they bring
        the hidden into view), then the screen's own, then hidden against hidden."""
        shown = {int(a) for a in self.model.axes if a >= 0} if self.model.kind == "coordinates" else {0, 1, 2}
        def rank(row):
            i, j = self.model.planes[row]
            k = (i in shown) + (j in shown)
            return ({1: 0, 2: 1, 0: 2}[k], row)
        return sorted(range(len(self.model.planes)), key=rank)

    def _build_sliders(self) -> None:
        clear_layout(self.slider_grid)
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
            self.sliders.append(s)
            self.slider_labels.append(lab)
            self.value_labels.append(val)
        self._place_sliders()
        self.slider_grid.setColumnStretch(1, 1)
        self.slider_grid.setRowStretch(len(self.sliders), 1)
        self._fill_drag_combo()

    def _place_sliders(self) -> None:
        """Put the rows in :meth:`plane_order` (the lists stay in plane order) and mark the hidden-only planes."""
        order = self.plane_order()
        shown = {int(a) for a in self.model.axes if a >= 0} if self.model.kind == "coordinates" else {0, 1, 2}
        for pos, row in enumerate(order):
            i, j = self.model.planes[row]
            lab = self.slider_labels[row]
            hidden_only = self.model.n > 3 and i not in shown and j not in shown
            lab.setStyleSheet("color: #888;" if hidden_only else "")
            if hidden_only:
                lab.setToolTip(f"rotate in the plane of {self.names[i]} and {self.names[j]} (both hidden: "
                               "moves nothing alone in an orthographic view; it acts with the other planes, "
                               "or under perspective and stereographic)")
            for col, w in enumerate((lab, self.sliders[row], self.value_labels[row])):
                self.slider_grid.addWidget(w, pos, col)
        self._filter_planes(self.plane_filter.text())

    def _filter_planes(self, text: str = "") -> None:
        words = str(text).replace(",", " ").split()
        for row, (i, j) in enumerate(self.model.planes):
            names = (self.names[i].lower(), self.names[j].lower())
            ok = all(any(w.lower() == nm or w.lower() in nm for nm in names) for w in words)
            for w in (self.slider_labels[row], self.sliders[row], self.value_labels[row]):
                w.setVisible(ok)

    def _fill_drag_combo(self) -> None:
        from .projection import axis_label, hidden_directions

        prev = self.drag_combo.currentIndex()
        self.drag_combo.blockSignals(True)
        self.drag_combo.clear()
        if self.model.n >= 4:
            H = hidden_directions(self.model.base())
            for r in range(len(H)):
                self.drag_combo.addItem(axis_label(H[r], self.names) or f"hidden {r + 1}", r)
        self.drag_combo.setCurrentIndex(min(max(prev, 0), self.drag_combo.count() - 1))
        self.drag_combo.setEnabled(self.model.n >= 4)
        self.drag_combo.blockSignals(False)
        self._fill_pads()

    def _rows_for_base(self) -> None:
        """A new base: other planes bring hidden axes into view, other directions are hidden."""
        if self.sliders:
            self._place_sliders()
            self._fill_drag_combo()

    def _fill_pads(self) -> None:
        from .projection import axis_label, hidden_directions

        clear_layout(self.pad_row)
        self.pads = []
        if self.model.n < 4:
            return
        H = hidden_directions(self.model.base())
        self.pad_row.addWidget(QLabel("turn X, Y into"))
        for r in range(len(H)):
            pad = QtTurnPad(axis_label(H[r], self.names) or f"h{r + 1}", r)
            pad.dragged.connect(self.turn_screen)
            self.pad_row.addWidget(pad)
            self.pads.append(pad)
        self.pad_row.addStretch(1)

    def turn_screen(self, hidden: int, dx: float, dy: float) -> None:
        """Turn the projection's X by ``dx`` and Y by ``dy`` degrees against hidden direction ``hidden``
        (one projection update; the sliders follow)."""
        from .projection import turned_angles

        a = self.model.angles.copy()
        if dx:
            self.model.angles[:] = turned_angles(self.model, np.array([1.0, 0.0, 0.0]), hidden, dx)
        if dy:
            self.model.angles[:] = turned_angles(self.model, np.array([0.0, 1.0, 0.0]), hidden, dy)
        new = self.model.angles.copy()
        self.model.angles[:] = a
        self.set_angles(new)

    def drag_hidden(self) -> int:
        """The hidden direction a Shift-drag turns against (0: the first)."""
        return max(0, self.drag_combo.currentIndex())

    def _sync_kind_widgets(self) -> None:
        kind = self.model.kind
        self.axes_row.setVisible(kind == "coordinates")
        self.seed_spin.setVisible(kind == "generic")
        self.seed_label.setVisible(kind == "generic")
        if kind != "coordinates":
            self.axes_error.setVisible(False)
        persp = self.model.mapping == "perspective"
        self.distance_slider.setVisible(persp)
        self.distance_label.setVisible(persp)

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

    def _on_mapping(self, *_):
        if self._updating:
            return
        m = self.mapping_combo.currentData()
        if m != "orthographic" and self.model.n < 4:
            self.mapping_error.setText(f"{MAPPING_LABELS[m].split(' ')[0]} needs n >= 4: "
                                       f"nothing is hidden in R^{self.model.n}")
            self.mapping_error.setVisible(True)
            m = "orthographic"
        else:
            self.mapping_error.setVisible(False)
        self.model.mapping = m
        self._sync_kind_widgets()
        self.projectionChanged.emit()

    def _on_distance(self, v):
        self.model.distance = v / 10.0
        self.distance_label.setText(f"eye distance {self.model.distance:.1f}")
        if not self._updating and self.model.mapping == "perspective":
            self.projectionChanged.emit()

    def _on_slice(self, *_):
        if not self._updating:
            self.sliceChanged.emit()

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

    def set_angles(self, degrees) -> None:
        """All plane angles at once (floats kept: an animation moves smoothly); one projection update."""
        self._updating = True
        try:
            self.model.angles[:] = np.asarray(degrees, dtype=float)
            for s, v, a in zip(self.sliders, self.value_labels, self.model.angles):
                s.setValue(int(round(a)))
                v.setText(f"{int(round(a)):+d}\u00b0")
            self.model.angles[:] = np.asarray(degrees, dtype=float)   # the sliders rounded them
        finally:
            self._updating = False
        self.projectionChanged.emit()

    def set_slice_center(self, fraction: float) -> None:
        """The slice window's centre as a fraction of the range (emits sliceChanged)."""
        self.slice_c.setValue(int(round(1000 * min(max(fraction, 0.0), 1.0))))

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
        """An example's suggested view, silently (the caller redraws): project=[3 names], color=name,
        mapping=orthographic|perspective|stereographic."""
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
            mapping = view.get("mapping")
            if mapping in MAPPING_LABELS and (mapping == "orthographic" or self.model.n >= 4):
                self.model.mapping = mapping
                self.mapping_combo.setCurrentIndex(self.mapping_combo.findData(mapping))
                self.mapping_error.setVisible(False)
                self._sync_kind_widgets()
            self._rows_for_base()
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

    def set_mapping(self, mapping: str) -> None:
        self.mapping_combo.setCurrentIndex(self.mapping_combo.findData(mapping))

    def slice_window(self) -> SliceWindow | None:
        """The slice the user set up (c and w as fractions of the range, see :meth:`slice_fractions`), or None."""
        if not self.slice_box.isChecked() or self.slice_combo.currentData() is None:
            return None
        index, hidden = self.slice_combo.currentData()
        return SliceWindow(int(index), bool(hidden))

    def slice_fractions(self) -> tuple[float, float]:
        """(centre, half-width) as fractions of the direction's range over the complex."""
        return self.slice_c.value() / 1000.0, self.slice_w.value() / 1000.0

    def set_slice(self, label: str | None, c_frac: float = 0.5, w_frac: float = 0.04) -> bool:
        """Turn the slice on along ``label`` (a variable or "hidden direction j"), or off with None."""
        self._updating = True
        try:
            if label is None:
                self.slice_box.setChecked(False)
            else:
                i = self.slice_combo.findText(label)
                if i < 0:
                    return False
                self.slice_combo.setCurrentIndex(i)
                self.slice_c.setValue(int(round(1000 * c_frac)))
                self.slice_w.setValue(max(1, int(round(1000 * w_frac))))
                self.slice_box.setChecked(True)
        finally:
            self._updating = False
        self.sliceChanged.emit()
        return True

    def set_slice_readout(self, text: str) -> None:
        self.slice_info.setText(text)

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
        d.update(color=self.color_by(), opacity=self.opacity(), show_edges=self.show_edges(),
                 two_sided=self.two_sided_check.isChecked(), boundary=self.boundary_check.isChecked(),
                 grid=self.grid_check.isChecked())
        sw = self.slice_window()
        if sw is not None:
            c, w = self.slice_fractions()
            d["slice"] = {"along": self.slice_combo.currentText(), "c": c, "w": w}
        return d

    def set_state(self, d: dict) -> None:
        """Restore kind, axes, seed, angles and style (the variables must be set first)."""
        n = len(self.names)
        self._updating = True
        try:
            m = ProjectionModel.from_dict(n, d) if len(d.get("angles", [0] * (n * (n - 1) // 2))) == \
                n * (n - 1) // 2 else ProjectionModel(n=n)
            m.share_principal(self.model)
            if n < 4:
                m.mapping = "orthographic"
            self.model = m
            self.mapping_combo.setCurrentIndex(self.mapping_combo.findData(m.mapping))
            self.distance_slider.setValue(int(round(10 * m.distance)))
            self.two_sided_check.setChecked(bool(d.get("two_sided", False)))
            self.boundary_check.setChecked(bool(d.get("boundary", False)))
            self.grid_check.setChecked(bool(d.get("grid", False)))
            sl = d.get("slice")
            if sl and self.slice_combo.findText(sl.get("along", "")) >= 0:
                self.slice_combo.setCurrentIndex(self.slice_combo.findText(sl["along"]))
                self.slice_c.setValue(int(round(1000 * float(sl.get("c", 0.5)))))
                self.slice_w.setValue(max(1, int(round(1000 * float(sl.get("w", 0.04))))))
                self.slice_box.setChecked(True)
            else:
                self.slice_box.setChecked(False)
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
        self.sliceChanged.emit()


class QtTurnPad(QWidget):
    """A small square to drag in: ``dragged(hidden, dx, dy)`` in degrees (half a degree a pixel)."""

    dragged = Signal(int, float, float)

    def __init__(self, label: str, hidden: int, parent=None):
        super().__init__(parent)
        self.label = label
        self.hidden = hidden
        self._last = None
        self.setFixedSize(44, 44)
        self.setCursor(Qt.SizeAllCursor)
        self.setMouseTracking(True)   # (moves count only between press and release)
        self.setToolTip(f"drag: turn the screen's X (sideways) and Y (up, down) against {label}")

    def paintEvent(self, ev) -> None:  # noqa: N802 - Qt's name
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        p.setPen(QPen(QColor("#7a869a"), 1))
        p.setBrush(QColor("#e8ecf3" if self._last is None else "#cfd9ea"))
        p.drawEllipse(QPointF(22, 22), 20, 20)
        p.setPen(QColor("#333"))
        f = p.font()
        f.setPointSizeF(7.5)
        p.setFont(f)
        p.drawText(self.rect(), Qt.AlignCenter, self.label if len(self.label) <= 6 else self.label[:5] + "\u2026")
        p.end()

    def mousePressEvent(self, ev) -> None:  # noqa: N802
        self._last = (ev.x(), ev.y())
        self.update()

    def mouseMoveEvent(self, ev) -> None:  # noqa: N802
        if self._last is None:
            return
        dx, dy = ev.x() - self._last[0], ev.y() - self._last[1]
        self._last = (ev.x(), ev.y())
        if dx or dy:
            self.dragged.emit(self.hidden, 0.5 * dx, -0.5 * dy)

    def mouseReleaseEvent(self, ev) -> None:  # noqa: N802
        self._last = None
        self.update()
