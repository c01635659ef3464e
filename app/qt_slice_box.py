"""QtSliceBox: the View tab's slice along a coordinate or a hidden direction, at ``c`` (a window ``[c - w, c + w]``
for curves).

The sliders set c and w as fractions of the range the 3D view reports (its readout is shown under them). The
box writes the model's :class:`gcmh_studio.model.SliceState` and shows it (:meth:`show_slice`, on the model's
``slice`` event).  A result of dimension >= 2 is drawn with its exact section at c (:mod:`gcmh_studio.sections`)
and :class:`gcmh_studio.qt_section_strip.QtSectionStrip` plots the section's chi and pieces against c under
the slider; the width is hidden for dimension >= 3 (the section stands for the slab; a surface keeps its band).
"""

from __future__ import annotations

from qtpy.QtCore import QSignalBlocker
from qtpy.QtWidgets import QComboBox, QFormLayout, QGroupBox, QLabel

from .model import StudioModel
from .qt_section_strip import QtSectionStrip
from .qt_widgets import blocked, connect_all, slider_row


class QtSliceBox(QGroupBox):
    def __init__(self, model: StudioModel, parent=None):
        super().__init__("Slice", parent)
        self.studio = model
        slf = QFormLayout(self)
        self.setCheckable(True)
        self.setChecked(False)
        self.setToolTip("cut the result by a hyperplane (a variable = c): a surface or a higher manifold shows its "
                        "exact section, a curve the part inside a window")
        self.slice_combo = QComboBox()
        self.slice_combo.setToolTip("a coordinate, or a direction the current projection hides")
        slf.addRow("along", self.slice_combo)
        self.slice_c, self.slice_c_label = slider_row(slf, "centre", 0, 1000, 500,
                                                      "where the hyperplane cuts (across the whole range)")
        self.strip = QtSectionStrip(model)
        slf.addRow(self.strip)
        self.slice_w, self.slice_w_label = slider_row(slf, "width", 1, 500, 40,
                                                      "half-width of the window (thousandths of the range)")
        self.slice_info = QLabel("")
        self.slice_info.setStyleSheet("color: #666; font-size: 11px;")
        slf.addRow(self.slice_info)
        connect_all((self.toggled, self.slice_combo.currentIndexChanged, self.slice_c.valueChanged,
                     self.slice_w.valueChanged), self._on_edit)
        model.events.slice_readout.connect(lambda text: self.slice_info.setText(text))
        model.events.result.connect(lambda *_: self.show_kind())
        self.show_kind()

    def show_kind(self) -> None:
        """A section at a value (dimension >= 2, with the strip; a surface's band of cells keeps its width)
        or a window (a curve)."""
        dim = getattr(self.studio.result, "dim", 3)
        self.slice_w.setVisible(dim <= 2)
        self.slice_w_label.setVisible(dim <= 2)
        self.slice_c_label.setText("value" if dim >= 2 else "centre")

    def set_names(self, names) -> None:
        """The directions to slice along: the variables, then the hidden directions."""
        n = len(names)
        with QSignalBlocker(self.slice_combo):
            self.slice_combo.clear()
            for i, nm in enumerate(names):
                self.slice_combo.addItem(nm, (i, False))
            for j in range(max(0, n - 3)):
                self.slice_combo.addItem(f"hidden direction {j + 1}", (j, True))
        self.show_slice()

    def show_slice(self) -> None:
        s = self.studio.slice
        with blocked(self, self.slice_combo, self.slice_c, self.slice_w):
            self.setChecked(s.on)
            want = (int(s.index), bool(s.hidden))   # (findData does not compare tuples)
            i = next((i for i in range(self.slice_combo.count()) if self.slice_combo.itemData(i) == want), 0)
            self.slice_combo.setCurrentIndex(i)
            self.slice_c.setValue(int(round(1000 * s.c)))
            self.slice_w.setValue(max(1, int(round(1000 * s.w))))

    def _on_edit(self, *_) -> None:
        data = self.slice_combo.currentData()
        index, hidden = data if data is not None else (0, False)
        self.studio.set_slice(on=self.isChecked() and data is not None, index=int(index), hidden=bool(hidden),
                              c=self.slice_c.value() / 1000.0, w=self.slice_w.value() / 1000.0)
