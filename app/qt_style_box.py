"""QtStyleBox: the View tab's drawing style (colour by a coordinate, opacity, edges, two-sided colours, the
boundary and grid overlays). It writes the model's :class:`gcmh_studio.model.ViewStyle` and shows it
(:meth:`show_style`, on the model's ``style`` event: the Topology tab's switches change it too)."""

from __future__ import annotations

from qtpy.QtWidgets import QCheckBox, QComboBox, QFormLayout, QGroupBox

from .angles import angle_look, seam_spec
from .model import StudioModel
from .qt_widgets import blocked, connect_all, slider

SOLID = "(solid colour)"


class QtStyleBox(QGroupBox):
    def __init__(self, model: StudioModel, parent=None):
        super().__init__("Style", parent)
        self.studio = model
        sf = QFormLayout(self)
        self.color_combo = QComboBox()
        self.color_combo.setToolTip("colour the vertices by one of the n coordinates")
        sf.addRow("colour by", self.color_combo)
        self.opacity_slider = slider(5, 100, 100)
        sf.addRow("opacity", self.opacity_slider)
        self.edges_check = QCheckBox("show cell edges")
        sf.addRow(self.edges_check)
        self.two_sided_check = QCheckBox("two-sided colours")
        self.two_sided_check.setToolTip("front gold, back blue: colour the two sides of the coherently oriented "
                                        "surface apart; a non-orientable surface shows where they swap")
        sf.addRow(self.two_sided_check)
        self.boundary_check = QCheckBox("highlight the boundary")
        sf.addRow(self.boundary_check)
        self.grid_check = QCheckBox("grid cubes it passes through")
        sf.addRow(self.grid_check)
        # angles (periodic axes) as the circles they are, and where the gluing is: with view state only
        self.circles_check = QCheckBox("angles as circles")
        self.circles_check.setToolTip("draw each periodic (angle) variable t as the circle (cos t, sin t) before "
                                      "projecting: two angles make a ring torus, and the picture is closed")
        sf.addRow(self.circles_check)
        self.seam_check = QCheckBox("show the glued seam")
        self.seam_check.setToolTip("draw where the two ends of a periodic variable are glued (t = 2pi is t = 0)")
        sf.addRow(self.seam_check)
        self.angles = angle_look(model)
        self.circles_check.toggled.connect(lambda on: self.angles.set(circles=on))
        self.seam_check.toggled.connect(lambda on: self.angles.set(seam=on))
        self.angles.changed.connect(self._show_angles)
        model.events.result.connect(self._on_result)
        self._on_result(model.result)
        connect_all((self.color_combo.currentIndexChanged, self.opacity_slider.valueChanged,
                     self.edges_check.toggled, self.two_sided_check.toggled, self.boundary_check.toggled,
                     self.grid_check.toggled), self._on_edit)

    def _widgets(self):
        return (self.color_combo, self.opacity_slider, self.edges_check, self.two_sided_check,
                self.boundary_check, self.grid_check)

    def set_names(self, names) -> None:
        """The coordinates to colour by."""
        with blocked(self.color_combo):
            self.color_combo.clear()
            self.color_combo.addItem(SOLID, None)
            for nm in names:
                self.color_combo.addItem(nm, nm)
        self.show_style()

    def show_style(self) -> None:
        st = self.studio.style
        with blocked(*self._widgets()):
            i = self.color_combo.findData(st.color_by) if st.color_by else 0
            self.color_combo.setCurrentIndex(max(i, 0))
            self.opacity_slider.setValue(int(round(100 * st.opacity)))
            self.edges_check.setChecked(st.show_edges)
            self.two_sided_check.setChecked(st.two_sided)
            self.boundary_check.setChecked(st.boundary)
            self.grid_check.setChecked(st.grid)

    def _on_result(self, cx) -> None:
        """The angle switches only for a result with periodic axes (they would change nothing else)."""
        has = cx is not None and bool(seam_spec(cx))
        for w in (self.circles_check, self.seam_check):
            w.setEnabled(has)
            w.setVisible(has)

    def _show_angles(self) -> None:
        with blocked(self.circles_check, self.seam_check):
            self.circles_check.setChecked(self.angles.circles)
            self.seam_check.setChecked(self.angles.seam)

    def _on_edit(self, *_) -> None:
        self.studio.set_style(color_by=self.color_combo.currentData(), opacity=self.opacity_slider.value() / 100.0,
                              show_edges=self.edges_check.isChecked(), two_sided=self.two_sided_check.isChecked(),
                              boundary=self.boundary_check.isChecked(), grid=self.grid_check.isChecked())
