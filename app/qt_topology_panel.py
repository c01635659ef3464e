"""QtTopologyPanel: what the extracted complex is, in numbers, and a few view toggles.

The panel shows :func:`gcmh_core.analysis.topology_report` of the current
result (cells by dimension, Euler characteristic, components, boundary,
orientation of a surface, max |F| at a vertex, the time of each phase), its
homology (:class:`gcmh_studio.qt_homology_box.QtHomologyBox`, computed in a worker:
Betti numbers over Q and Z/2, torsion, generators to highlight, the w1 loop,
curvature and the Gauss-Bonnet sum), a "Refine onto M" button and three switches
of the view (the boundary, the processed cubes, two-sided colours), which are the
model's: it never touches the scene.

    panel = QtTopologyPanel(model)
    panel.set_result(cx, system)              # or panel.set_report(report) from a worker
    panel.refineRequested.connect(...)        # run refine_vertices, then:
    panel.show_refinement(before, after)
"""

from __future__ import annotations

from qtpy.QtCore import QSignalBlocker, Qt, Signal
from qtpy.QtWidgets import (
    QCheckBox,
    QFormLayout,
    QGroupBox,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from .model import StudioModel
from .qt_confirm_box import QtConfirmBox
from .qt_homology_box import QtHomologyBox

DIM_NAMES = {0: "points", 1: "curve", 2: "surface"}
CELL_LETTERS = ("V", "E", "F")
BAD_STYLE = "color: #c22;"
GOOD_STYLE = "color: #1a7f37;"


def _seconds(t) -> str:
    if t is None:
        return "—"
    return f"{t * 1000:.0f} ms" if t < 1 else f"{t:.2f} s"


def _describe_dim(rep) -> str:
    dim = rep["dim"]
    what = DIM_NAMES.get(dim, f"{dim}-manifold")
    return f"{what} in R^{rep['n']}, k = {rep['k']}"


def _describe_counts(rep) -> str:
    parts = []
    for r, c in enumerate(rep["counts"]):
        letter = CELL_LETTERS[r] if r < len(CELL_LETTERS) and rep["dim"] <= 2 else f"{r}-cells"
        parts.append(f"{letter} {c:,}")
    return " · ".join(parts)


def _describe_boundary(rep) -> str:
    if rep["boundary_facets"] == 0:
        return "none (closed)" if rep["counts"][0] else "—"
    comps = rep["boundary_components"]
    return (f"{comps} component{'s' if comps != 1 else ''}\n"
            f"({rep['boundary_facets']:,} facets)")


def _describe_orientation(rep, w1_edges=None) -> tuple[str, bool | None]:
    """The orientation row.  A surface that is not orientable says across how many edges its
    normals flip once the homology has its w1 loop (`w1_edges`: the loop the w1 switch draws,
    shortened; the breadth-first orientation of the report conflicts on a longer set of
    edges in the same class, whose size depends on the search order, so it is not shown)."""
    o = rep.get("orientation")
    if o is None:
        return ("— (only for surfaces)", None)
    if o["consistent"]:
        return (f"consistent (orientable)\n{o['n_flipped']:,} loops reversed", True)
    bad = o["n_components"] - o["orientable_components"]
    text = "not orientable"
    if w1_edges is not None:
        text += f"\nw1 loop: {w1_edges:,} edges"   # (short: the column is narrow)
    if o["n_components"] > 1:
        text += f" ({bad} of {o['n_components']} pieces)"
    if o["nonmanifold_edges"]:
        text += f"\n{o['nonmanifold_edges']:,} edges on 3+ polygons"
    return text, False


class QtTopologyPanel(QWidget):
    """Side panel with the topology report of the current result.

    Signals
    -------
    refineRequested()
        The user pressed "Refine onto M" (only enabled when F is known).

    The three view switches are the model's (:class:`gcmh_studio.model.ViewStyle`: ``boundary``, ``grid``,
    ``two_sided``), the same as the View tab's: they write it and show it. A result at a critical value of its
    parameters (the model's ``notice``) is marked at its Euler characteristic.
    """

    refineRequested = Signal()

    ROWS = (
        ("shape", "Object"),
        ("counts", "Cells"),
        ("euler", "Euler characteristic"),
        ("components", "Connected components"),
        ("boundary", "Boundary"),
        ("orientation", "Orientation"),
        ("residual", "Max |F| at a vertex"),
        ("timings", "Phases"),
        ("seconds", "Total time"),
    )

    def __init__(self, model: StudioModel | None = None, parent=None):
        super().__init__(parent)
        self.studio = model if model is not None else StudioModel()
        self._report = None
        self._has_system = False
        layout = QVBoxLayout(self)

        box = QGroupBox("Topology")
        self.form = QFormLayout(box)
        self.form.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        self.values: dict[str, QLabel] = {}
        for key, label in self.ROWS:
            value = QLabel("—")
            # explicit line breaks, no word wrap: wrapped labels in a form get clipped
            value.setTextInteractionFlags(Qt.TextSelectableByMouse)
            value.setObjectName(f"topology_{key}")
            self.values[key] = value
            self.form.addRow(label + ":", value)
        layout.addWidget(box)
        self.homology_box = QtHomologyBox(self.studio)
        self.homology_box.computed.connect(self._show_orientation)   # the w1 loop's length
        layout.addWidget(self.homology_box)

        refine_box = QGroupBox("Refine and confirm")
        rl = QVBoxLayout(refine_box)
        self.refine_button = QPushButton("Refine onto M")
        self.refine_button.setToolTip(
            "Move every vertex onto M by a few Gauss-Newton steps with the exact Jacobian; the cells stay the same")
        self.refine_button.setEnabled(False)
        self.refine_button.clicked.connect(self.refineRequested)
        self.refine_label = QLabel("")
        self.refine_label.setWordWrap(True)
        self.refine_label.setObjectName("topology_refinement")
        rl.addWidget(self.refine_button)
        rl.addWidget(self.refine_label)
        self.confirm_box = QtConfirmBox(self.studio)   # how sure the topology is: a second grid
        rl.addWidget(self.confirm_box)
        layout.addWidget(refine_box)

        view_box = QGroupBox("Show")
        vl = QVBoxLayout(view_box)
        self.boundary_check = QCheckBox("Highlight the boundary")
        self.path_check = QCheckBox("Processed cubes (the algorithm's path)")
        self.two_sided_check = QCheckBox("Two sides in two colours")
        self.two_sided_check.setToolTip("Colour the front and the back of an oriented surface differently")
        self._switches = {"boundary": self.boundary_check, "grid": self.path_check, "two_sided": self.two_sided_check}
        for field, check in self._switches.items():
            check.toggled.connect(lambda on, field=field: self.studio.set_style(**{field: bool(on)}))
            vl.addWidget(check)
        self.studio.events.style.connect(self._show_style)
        self.studio.events.notice.connect(self._show_notice)
        layout.addWidget(view_box)
        layout.addStretch(1)
        self._update_enabled()

    # ------------------------------------------------------------------ the model
    def _show_style(self) -> None:
        for field, check in self._switches.items():
            with QSignalBlocker(check):
                check.setChecked(bool(getattr(self.studio.style, field)))

    def _show_notice(self, text: str) -> None:
        """A result at a critical value: its Euler characteristic says so (the report of the result came first)."""
        euler = self.values["euler"]
        if text and self._report is not None and "(critical value)" not in euler.text():
            euler.setText(f"{euler.text()}  (critical value)")
            euler.setStyleSheet("color: #a04000; font-weight: bold;")

    # ------------------------------------------------------------------ content

    def report(self) -> dict | None:
        """The report on show (a dict from topology_report), or None."""
        return self._report

    def set_result(self, cx, system=None) -> dict:
        """Compute and show the report of `cx` (F given as a System gives max |F|
        and enables refinement). Returns the report."""
        from gcmh_core.analysis import topology_report

        report = topology_report(cx, system)
        self.set_report(report, has_system=system is not None)
        if self.studio.result is not cx:   # (a result on show has its homology under way already)
            self.homology_box.set_result(cx)
        return report

    def set_report(self, report: dict, has_system: bool | None = None) -> None:
        """Show a report computed elsewhere (e.g. in the worker thread).

        `has_system` enables "Refine onto M"; by default it is on when the
        report has a max |F|.
        """
        self._report = report
        self._has_system = report.get("max_abs_F") is not None if has_system is None else bool(has_system)
        v = self.values
        v["shape"].setText(_describe_dim(report))
        v["counts"].setText(_describe_counts(report))
        v["euler"].setText(str(report["euler_characteristic"]))
        v["components"].setText(str(report["connected_components"]))
        v["boundary"].setText(_describe_boundary(report))
        self._show_orientation()
        residual = report.get("max_abs_F")
        v["residual"].setText("—" if residual is None else f"{residual:.3g}")
        timings = report.get("timings") or {}
        v["timings"].setText("\n".join(f"{k} {_seconds(t)}" for k, t in timings.items()) or "—")
        v["seconds"].setText(_seconds(report.get("seconds")))
        self.refine_label.setText("")
        self._update_enabled()

    def _w1_edges(self) -> int | None:
        """The number of edges of the w1 loop the homology box has for the result reported, or None."""
        data = self.homology_box.data
        if data is None or self._report is None or self._report["dim"] != 2:
            return None
        h = data["homology"]
        if h.orientation_cycle is None or h.orientation is None or h.orientation.size != self._report["counts"][2]:
            return None
        return int(h.orientation_cycle.size)

    def _show_orientation(self) -> None:
        if self._report is None:
            return
        text, ok = _describe_orientation(self._report, self._w1_edges())
        label = self.values["orientation"]
        label.setText(text)
        label.setToolTip("The w1 loop: the edges across which the surface's normals flip, as the switch "
                         "'Where the orientation reverses (w1)' draws it" if ok is False else "")
        label.setStyleSheet("" if ok is None else (GOOD_STYLE if ok else BAD_STYLE))

    def clear(self) -> None:
        """No result: every value back to a dash, refinement off."""
        self._report = None
        self._has_system = False
        for label in self.values.values():
            label.setText("—")
            label.setStyleSheet("")
        self.refine_label.setText("")
        self.homology_box.set_result(None)
        self._update_enabled()

    def show_refinement(self, before: float, after: float) -> None:
        """Show max |F| at the vertices before and after a refinement."""
        factor = ""
        if after > 0 and before > 0:
            factor = f" ({before / after:.1e} times smaller)" if after < before else " (no better)"
        elif after == 0 < before:
            factor = " (exactly on M)"
        self.refine_label.setText(f"max |F|: {before:.3g} → {after:.3g}\n{factor.strip(' ()')}")
        if self._report is not None:
            self._report = dict(self._report, max_abs_F=float(after))
            self.values["residual"].setText(f"{after:.3g}")

    def set_refine_enabled(self, enabled: bool) -> None:
        """Let the window disable the button while a refinement runs."""
        self.refine_button.setEnabled(bool(enabled) and self._can_refine())

    def _can_refine(self) -> bool:
        return self._report is not None and self._has_system and self._report["counts"][0] > 0

    def _update_enabled(self) -> None:
        self.refine_button.setEnabled(self._can_refine())
        has = self._report is not None
        surface = has and self._report["dim"] == 2
        self.boundary_check.setEnabled(has and self._report["boundary_facets"] > 0)
        self.two_sided_check.setEnabled(surface)
        self.path_check.setEnabled(has)
