"""QtProjectionPanel: the View tab, how the n-dimensional result is turned and projected to 3D.

It edits the :class:`gcmh_studio.model.StudioModel`'s view: the projection (an
:class:`gcmh_studio.projection.ProjectionModel`: the base (three coordinates, a
generic orthonormal frame, or the principal axes), the mapping (orthographic,
perspective with an eye distance, stereographic) and the plane angles, turned by
:class:`gcmh_studio.qt_rotation_sliders.QtRotationSliders`), the slice
(:class:`gcmh_studio.qt_slice_box.QtSliceBox`) and the drawing style
(:class:`gcmh_studio.qt_style_box.QtStyleBox`). The widgets write the model; the
panel shows what the model holds whenever it announces a change, whoever made
it (the user, Undo, an example, a session, the Animate tab's clock).

Qt signals, relayed from the model's events for the widgets that watch the view
(the presentation mode): ``projectionChanged`` (angles, base or mapping),
``baseChanged`` (a new base), ``styleChanged``, ``sliceChanged``.
"""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import Signal
from qtpy.QtWidgets import QComboBox, QFormLayout, QHBoxLayout, QLabel, QSpinBox, QWidget

from .model import StudioModel, slice_target
from .projection import KIND_LABELS, KINDS, MAPPING_LABELS, MAPPINGS, ProjectionModel
from .qt_rotation_sliders import QtRotationSliders
from .qt_slice_box import QtSliceBox
from .qt_style_box import SOLID, QtStyleBox
from .qt_widgets import blocked, error_label, group, panel_layout, slider_row

__all__ = ["SOLID", "QtProjectionPanel"]


def narrow_combos(widget, chars: int = 8) -> None:
    """Let every combo box in ``widget`` be narrower than its longest entry (the list still opens wide):
    at 1024 x 768 a side panel is a third of the window, and "Stereographic (manifolds on a sphere)" or
    ten variables' plane names made the View tab wider than that, cut off on the right."""
    for c in widget.findChildren(QComboBox):
        c.setSizeAdjustPolicy(QComboBox.AdjustToMinimumContentsLength)
        c.setMinimumContentsLength(chars)


class QtProjectionPanel(QWidget):
    projectionChanged = Signal()
    baseChanged = Signal()
    styleChanged = Signal()
    sliceChanged = Signal()

    def __init__(self, model: StudioModel | None = None, parent=None):
        super().__init__(parent)
        self.studio = model if model is not None else StudioModel()
        self._shape: tuple | None = None   # (names, n) the widgets were built for
        lay = panel_layout(self)

        box, bl = group(lay, "Projection to 3D", stretch=1)
        form = QFormLayout()
        self.kind_combo = QComboBox()
        for k in KINDS:
            self.kind_combo.addItem(KIND_LABELS[k], k)
        form.addRow("view", self.kind_combo)
        self.axes_row = QWidget()
        al = QHBoxLayout(self.axes_row)
        al.setContentsMargins(0, 0, 0, 0)
        self.axis_combos = []
        for lab in ("X", "Y", "Z"):
            c = QComboBox()
            c.setToolTip(f"the coordinate shown along screen {lab}")
            al.addWidget(QLabel(lab))
            al.addWidget(c, 1)
            self.axis_combos.append(c)
        form.addRow(self.axes_row)
        self.axes_error = error_label()
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
        self.rotation = QtRotationSliders(self.studio)
        bl.addWidget(self.rotation, 1)
        self.slice_box = QtSliceBox(self.studio)
        lay.addWidget(self.slice_box)
        self.style_box = QtStyleBox(self.studio)
        lay.addWidget(self.style_box)
        # the sub-widgets' controls, as the tests and the window's shortcuts know them
        r, sb, st = self.rotation, self.slice_box, self.style_box
        self.keep_camera_check, self.drag_combo, self.plane_filter = r.keep_camera_check, r.drag_combo, r.plane_filter
        self.reset_button, self.plane_order, self.turn_screen, self.drag_hidden = (
            r.reset_button, r.plane_order, r.turn_screen, r.drag_hidden)
        self.slice_combo, self.slice_c, self.slice_w, self.slice_info = (
            sb.slice_combo, sb.slice_c, sb.slice_w, sb.slice_info)
        self.color_combo, self.opacity_slider, self.edges_check = st.color_combo, st.opacity_slider, st.edges_check
        self.two_sided_check, self.boundary_check, self.grid_check = (
            st.two_sided_check, st.boundary_check, st.grid_check)

        narrow_combos(self)
        for c in self.axis_combos:   # (three in a row: a variable's name each)
            c.setMinimumContentsLength(3)
        self.kind_combo.currentIndexChanged.connect(self._on_kind)
        for c in self.axis_combos:
            c.currentIndexChanged.connect(self._on_axes)
        self.seed_spin.valueChanged.connect(self._on_seed)
        self.mapping_combo.currentIndexChanged.connect(self._on_mapping)
        self.distance_slider.valueChanged.connect(self._on_distance)
        ev = self.studio.events
        ev.base.connect(self._show_base)
        ev.projection.connect(self._show_projection)
        ev.style.connect(self._show_style)
        ev.slice.connect(self._show_slice)
        self._show_base()

    # ------------------------------------------------------------ the model's state
    @property
    def model(self) -> ProjectionModel:
        """The projection on show (the studio model's)."""
        return self.studio.projection

    @property
    def names(self) -> list[str]:
        return self.studio.view_names

    @property
    def sliders(self):
        return self.rotation.sliders

    @property
    def slider_labels(self):
        return self.rotation.slider_labels

    @property
    def pads(self):
        return self.rotation.pads

    def _show_base(self) -> None:
        """A new base or projection: the axis choices, the rows of the sliders, the hidden directions."""
        p, names = self.model, self.names
        with blocked(self.kind_combo, self.seed_spin, *self.axis_combos):
            if self._shape != (tuple(names), p.n):
                self._shape = (tuple(names), p.n)
                for c in self.axis_combos:
                    c.clear()
                    c.addItem("(none)", -1)
                    for i, nm in enumerate(names):
                        c.addItem(nm, i)
                self.rotation.rebuild()
                self.style_box.set_names(names)
                self.slice_box.set_names(names)
            else:
                self.rotation.place()
            for c, a in zip(self.axis_combos, p.axes):
                c.setCurrentIndex(c.findData(int(a)))
            self.kind_combo.setCurrentIndex(self.kind_combo.findData(p.kind))
            self.seed_spin.setValue(int(p.seed))
        self.axes_error.setVisible(False)
        self._show_projection(relay=False)
        self.baseChanged.emit()

    def _show_projection(self, relay: bool = True) -> None:
        p = self.model
        self.rotation.show_angles()
        with blocked(self.mapping_combo, self.distance_slider):
            self.mapping_combo.setCurrentIndex(self.mapping_combo.findData(p.mapping))
            self.distance_slider.setValue(int(round(10 * p.distance)))
        self.distance_label.setText(f"eye distance {p.distance:.1f}")
        self._sync_kind_widgets()
        if relay:
            self.projectionChanged.emit()

    def _show_style(self) -> None:
        self.style_box.show_style()
        self.rotation.show_keep_camera()
        self.styleChanged.emit()

    def _show_slice(self) -> None:
        self.slice_box.show_slice()
        self.sliceChanged.emit()

    def _sync_kind_widgets(self) -> None:
        kind = self.model.kind
        self.axes_row.setVisible(kind == "coordinates")
        self.seed_spin.setVisible(kind == "generic")
        self.seed_label.setVisible(kind == "generic")
        persp = self.model.mapping == "perspective"
        self.distance_slider.setVisible(persp)
        self.distance_label.setVisible(persp)

    # ------------------------------------------------------------ the user's edits
    def _on_kind(self, *_):
        self.model.kind = self.kind_combo.currentData()
        if self.model.kind == "coordinates":
            self._on_axes()
            return
        self.studio.projection_changed(base=True)

    def _on_axes(self, *_):
        axes = tuple(int(c.currentData()) if c.currentData() is not None else -1 for c in self.axis_combos)
        used = [a for a in axes if a >= 0]
        if len(set(used)) != len(used):
            self.axes_error.setText("each screen axis must show a different coordinate")
            self.axes_error.setVisible(True)
            return
        self.axes_error.setVisible(False)
        self.model.axes = axes
        if self.model.kind == "coordinates":
            self.studio.projection_changed(base=True)

    def _on_seed(self, v):
        self.model.seed = int(v)
        if self.model.kind == "generic":
            self.studio.projection_changed(base=True)

    def _on_mapping(self, *_):
        m = self.mapping_combo.currentData()
        if m != "orthographic" and self.model.n < 4:
            self.mapping_error.setText(f"{MAPPING_LABELS[m].split(' ')[0]} needs n >= 4: "
                                       f"nothing is hidden in R^{self.model.n}")
            self.mapping_error.setVisible(True)
            m = "orthographic"
        else:
            self.mapping_error.setVisible(False)
        self.model.mapping = m
        self.studio.projection_changed()

    def _on_distance(self, v):
        self.model.distance = v / 10.0
        self.studio.projection_changed()

    # ------------------------------------------------------------ API (each goes through the model)
    def set_variables(self, names, keep: bool = True) -> None:
        """Rebuild for a new list of variable names (n = len(names)); with ``keep``, the current kind, seed and
        colour are kept where they still make sense."""
        self.studio.set_view_variables(names, keep)

    def reset(self) -> None:
        """All angles to 0 (one projection update)."""
        self.rotation.reset()

    def set_angles(self, degrees) -> None:
        """All plane angles at once (floats kept: an animation moves smoothly); one projection update."""
        self.studio.set_angles(degrees)

    def set_angle(self, plane: tuple[int, int], degrees: float) -> None:
        row = self.model.planes.index(tuple(plane))
        self.sliders[row].setValue(int(round(degrees)))

    def set_kind(self, kind: str) -> None:
        self.kind_combo.setCurrentIndex(self.kind_combo.findData(kind))

    def set_mapping(self, mapping: str) -> None:
        self.mapping_combo.setCurrentIndex(self.mapping_combo.findData(mapping))

    def set_axes_by_names(self, axes_names) -> bool:
        """Show the named variables on screen X, Y, Z (coordinate kind). False if a name is unknown."""
        try:
            axes = tuple(self.names.index(a) if a is not None else -1 for a in list(axes_names)[:3])
        except ValueError:
            return False
        self.model.axes, self.model.kind = axes, "coordinates"
        self.studio.projection_changed(base=True)
        return True

    def set_slice(self, label: str | None, c_frac: float = 0.5, w_frac: float = 0.04) -> bool:
        """Turn the slice on along ``label`` (a variable or "hidden direction j"), or off with None."""
        if label is None:
            self.studio.set_slice(on=False)
            return True
        where = slice_target(label, self.names, self.model.n)
        if where is None:
            return False
        self.studio.set_slice(on=True, index=where[0], hidden=where[1], c=float(c_frac), w=max(0.001, float(w_frac)))
        return True

    def color_by(self) -> str | None:
        return self.studio.style.color_by

    def set_color_by(self, name: str | None) -> None:
        self.studio.set_style(color_by=name if name in self.names else None)

    def matrix(self) -> np.ndarray:
        return self.model.matrix()

    def state(self) -> dict:
        return self.studio.view_state()

    def set_state(self, d: dict) -> None:
        """Restore kind, axes, seed, angles, slice and style (the variables must be set first)."""
        self.studio.set_view_state(d)
