"""QtHomologyBox: the homology of the result on show, its generators on the picture, the w1
loop and curvature (the Topology tab's lower half).

The homology is computed off the GUI thread (a :class:`gcmh_studio.qt_widgets.QtLatestCall`:
the newest result wins, the window never waits).  One button per dimension shows
``H1 = Z + Z/2`` with its Betti numbers over Q and Z/2; pressing it asks for its
generators to be drawn, each a thick loop in its own colour (an H2 class of a 3-manifold:
a see-through surface).  The box never touches the
scene: it emits what should be drawn, and the window hands it to
:func:`gcmh_studio.overlays.draw_homology` and :func:`gcmh_studio.overlays.colour_by_values`.

    box = QtHomologyBox(model)
    box.overlays.connect(lambda specs: draw_homology(window.scene, specs))
    box.surfaces.connect(lambda specs: draw_homology_surfaces(window.scene, specs))
    box.curvature.connect(lambda values: colour_by_values(window.scene, values))
"""

from __future__ import annotations

from qtpy.QtCore import QSignalBlocker, Qt, QTimer, Signal
from qtpy.QtWidgets import QCheckBox, QGridLayout, QGroupBox, QLabel, QPushButton, QVBoxLayout

from .cycles import curvature_values, cycle_color, generator_lines, generator_surface, unwrap_segments, w1_lines
from .homology_surfaces import SURFACE_OPACITY, SURFACE_PREFIX
from .model import StudioModel
from .qt_widgets import QtLatestCall

GENERATOR_WIDTH = 7.0
W1_WIDTH = 6.0
ARROW_WIDTH = 2.5
MAX_DIMS = 8


def compute(cx) -> dict:
    """Everything the box shows of ``cx``, computed in the worker thread (no Qt here)."""
    from gcmh_core.homology import homology

    h = homology(cx)
    lines, surfaces = [], {}
    for q, cycles in enumerate(h.generators):
        row = []
        for i, c in enumerate(cycles):
            if q == 2 and cx.dim >= 3:   # an H2 class of a 3-manifold: a surface, drawn see-through
                X, T = generator_surface(cx, c)
                surfaces.setdefault(q, []).append((X, T, cycle_color(i), c.order))
                row.append((X[:0], T[:0, :2], cycle_color(i), c.order))
            else:
                X, E = unwrap_segments(cx, *generator_lines(cx, c))
                row.append((X, E, cycle_color(i), c.order))
        lines.append(row)
    out = {"homology": h, "lines": lines, "surfaces": surfaces, "w1": None, "curvature": None,
           "gauss_bonnet": None}
    if h.orientation_cycle is not None:
        (XL, EL), (XA, EA) = w1_lines(cx, h.orientation_cycle, h.orientation)
        out["w1"] = (unwrap_segments(cx, XL, EL), unwrap_segments(cx, XA, EA))
    if cx.dim == 2 and cx.count(2):
        values, text = curvature_values(cx)
        out["curvature"], out["gauss_bonnet"] = values, text
    return out


class QtHomologyBox(QGroupBox):
    """Homology of the result on show, computed in a worker; a click on a Betti number
    highlights its generators.

    Signals
    -------
    overlays(dict)
        name -> (vertices (m, n), edges (E, 2), colour, width): every homology overlay that
        should be on the picture now (names start with ``homology-``; others are removed).
    surfaces(dict)
        name -> (vertices (m, n), triangles (T, 3), colour, opacity): the H2 classes of a
        3-manifold asked for, as see-through surfaces (names start with ``homology-surface-``;
        for :func:`gcmh_studio.homology_surfaces.draw_homology_surfaces`).
    curvature(object)
        (V,) float64 curvature densities to colour the result by, or None for its usual colours (again
        after a change of style, which draws the result anew).
    computed()
        A result's homology is on show (or failed: see :attr:`status`).
    """

    overlays = Signal(object)
    surfaces = Signal(object)
    curvature = Signal(object)
    computed = Signal()

    def __init__(self, model: StudioModel | None = None, parent=None):
        super().__init__("Homology", parent)
        self.studio = model if model is not None else StudioModel()
        self.data: dict | None = None
        self._cx = None
        self._serial = 0
        layout = QVBoxLayout(self)
        self.status = QLabel("—")
        self.status.setObjectName("homology_status")
        self.status.setTextInteractionFlags(Qt.TextSelectableByMouse)
        layout.addWidget(self.status)
        grid = QGridLayout()
        grid.addWidget(QLabel("<i>group</i>"), 0, 0)
        grid.addWidget(QLabel("<i>Betti over Q</i>"), 0, 1)
        grid.addWidget(QLabel("<i>over Z/2</i>"), 0, 2)
        self.groups, self.betti, self.betti2 = [], [], []
        for q in range(MAX_DIMS):
            group = QLabel("")
            b = QPushButton("")
            b.setCheckable(True)
            b.setObjectName(f"homology_betti_{q}")
            b.setToolTip("Show this group's generators on the picture")
            b.toggled.connect(self._emit_overlays)
            b2 = QLabel("")
            for col, w in enumerate((group, b, b2)):
                grid.addWidget(w, q + 1, col)
                w.setVisible(False)
            self.groups.append(group)
            self.betti.append(b)
            self.betti2.append(b2)
        layout.addLayout(grid)
        self.w1_check = QCheckBox("Where the orientation reverses (w1)")
        self.w1_check.setObjectName("homology_w1")
        self.w1_check.setToolTip("The loop across which the surface's normals flip, with small oriented loops "
                                 "beside it: they turn the same way on both sides of it")
        self.w1_check.toggled.connect(self._emit_overlays)
        layout.addWidget(self.w1_check)
        self.curvature_check = QCheckBox("Colour by Gaussian curvature")
        self.curvature_check.setObjectName("homology_curvature")
        self.curvature_check.toggled.connect(self._emit_curvature)
        layout.addWidget(self.curvature_check)
        self.gauss_bonnet = QLabel("")
        self.gauss_bonnet.setObjectName("homology_gauss_bonnet")
        self.gauss_bonnet.setTextInteractionFlags(Qt.TextSelectableByMouse)
        layout.addWidget(self.gauss_bonnet)
        self.worker = QtLatestCall(self, name="gcmh-homology")
        self.worker.answered.connect(self._answered)
        self.studio.events.result.connect(self.set_result)
        self.studio.events.style.connect(self._style_changed)
        self._style_seen = self._colouring_style()
        self._enable()

    # ------------------------------------------------------------------ results
    def set_result(self, cx) -> None:
        """Compute the homology of ``cx`` in the worker (None clears the box)."""
        self._serial += 1
        self._cx = cx
        self.data = None
        self._show_rows(None)
        self.gauss_bonnet.setText("")
        had_curvature = self.curvature_check.isChecked()
        for check in (self.w1_check, self.curvature_check):
            with QSignalBlocker(check):
                check.setChecked(False)
        self.overlays.emit({})
        self.surfaces.emit({})
        if had_curvature:
            self.curvature.emit(None)
        if cx is None:
            self.status.setText("—")
            self._enable()
            return
        self.status.setText("computing…")
        self._enable()
        self.worker.ask(self._serial, lambda cx=cx: compute(cx))

    def busy(self) -> bool:
        return self.worker.busy()

    def _answered(self, key, value, error) -> None:
        if key != self._serial:
            return   # a result no longer on show
        if error is not None:
            self.status.setText(f"not computed: {error}")
            self.status.setStyleSheet("color: #c22;")
        else:
            self.status.setStyleSheet("")
            self.data = value
            h = value["homology"]
            self.status.setText(h.describe())
            self._show_rows(h)
            if value["gauss_bonnet"]:
                self.gauss_bonnet.setText(value["gauss_bonnet"])
        self._enable()
        self.computed.emit()

    def _show_rows(self, h) -> None:
        for q in range(MAX_DIMS):
            on = h is not None and q < len(h.betti)
            for w in (self.groups[q], self.betti[q], self.betti2[q]):
                w.setVisible(on)
            b = self.betti[q]
            with QSignalBlocker(b):
                b.setChecked(False)
            if on:
                self.groups[q].setText(f"H{q} = {h.group(q)}")
                b.setText(f"b{q} = {h.betti[q]}" + (f"  (+{len(h.torsion[q])} torsion)" if h.torsion[q] else ""))
                b.setEnabled(bool(h.generators[q]))
                self.betti2[q].setText(str(h.betti_mod2[q]))

    def _enable(self) -> None:
        d = self.data
        self.w1_check.setEnabled(d is not None and d["w1"] is not None)
        self.curvature_check.setEnabled(d is not None and d["curvature"] is not None)

    # ------------------------------------------------------------------ what to draw
    def overlay_specs(self) -> dict:
        """name -> (X, E, colour, width) of the generators and the w1 loop asked for."""
        specs: dict = {}
        if self.data is None:
            return specs
        for q, rows in enumerate(self.data["lines"]):
            if q < MAX_DIMS and self.betti[q].isChecked():
                for i, (X, E, color, _order) in enumerate(rows):
                    if len(E):
                        specs[f"homology-{q}-{i}"] = (X, E, color, GENERATOR_WIDTH if q == 1 else 3.0)
        if self.w1_check.isChecked() and self.data["w1"] is not None:
            (XL, EL), (XA, EA) = self.data["w1"]
            specs["homology-w1"] = (XL, EL, "#ff2d2d", W1_WIDTH)
            if len(EA):
                specs["homology-w1-arrows"] = (XA, EA, "#ffffff", ARROW_WIDTH)
        return specs

    def surface_specs(self) -> dict:
        """name -> (X, T, colour, opacity) of the H2 classes of a 3-manifold asked for."""
        specs: dict = {}
        if self.data is None:
            return specs
        for q, rows in self.data["surfaces"].items():
            if q < MAX_DIMS and self.betti[q].isChecked():
                for i, (X, T, color, _order) in enumerate(rows):
                    if len(T):
                        specs[f"{SURFACE_PREFIX}{q}-{i}"] = (X, T, color, SURFACE_OPACITY)
        return specs

    def generator_colours(self, q: int) -> list[str]:
        """The colours the generators of H_q are drawn in (for a legend or a test)."""
        if self.data is None or q >= len(self.data["lines"]):
            return []
        return [row[2] for row in self.data["lines"][q]]

    def _emit_overlays(self, *_args) -> None:
        self.overlays.emit(self.overlay_specs())
        self.surfaces.emit(self.surface_specs())

    def _colouring_style(self) -> tuple:
        st = self.studio.style
        return st.color_by, st.two_sided

    def _style_changed(self) -> None:
        """A new style draws the result anew in its colours: the curvature's are asked for again (once the
        window has drawn it: queued), unless the style now colours it otherwise (colour by a variable, two
        sides), which wins: the switch goes off."""
        seen, self._style_seen = self._style_seen, self._colouring_style()
        if not self.curvature_check.isChecked():
            return
        color_by, two_sided = self._style_seen
        if color_by != seen[0] or (two_sided and not seen[1]):
            self.curvature_check.setChecked(False)
        else:
            QTimer.singleShot(0, lambda: self._emit_curvature(self.curvature_check.isChecked()))

    def _emit_curvature(self, on: bool) -> None:
        self.curvature.emit(self.data["curvature"] if on and self.data is not None else None)
