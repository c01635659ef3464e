"""QtLinkageInset: the rods of a planar linkage in the configuration picked on its configuration surface.

The pentagon linkage's surface is made of ways to hold the rods: a double-click on it (the view's pick)
shows which one, drawn in a small panel over the 3D view's corner (the fixed rod grey, the four moving
rods in colour, the hinges as dots, the angles written below). The system is recognised from its
equations (:func:`gcmh_studio.angles.linkage_joints`), not from the example's name."""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import QPointF, Qt
from qtpy.QtGui import QColor, QFont, QPainter, QPen
from qtpy.QtWidgets import QWidget

from .angles import circular_mean, linkage_joints, linkage_points, periodic_axes

ROD_COLORS = ("#f0c05a", "#ff7b6b", "#5fd3a3", "#6fa8ff", "#d98cff", "#ffd27f")
FIXED_COLOR = "#9aa3b5"
SIZE = (300, 240)


def picked_angles(cx, coords) -> np.ndarray:
    """The angles (n,) of the configuration at a picked cell: the circular mean of its vertices' coordinates
    along each periodic axis (a cell that crosses the seam is near the seam), the plain mean elsewhere."""
    coords = np.asarray(coords, dtype=float)
    out = coords.mean(axis=0)
    for p, (lo, period) in periodic_axes(cx).items():
        out[p] = circular_mean(coords[:, p], period, lo)
    return out


def closed_configuration(angles, closing=(1.0, 0.0), steps: int = 8) -> np.ndarray:
    """The configuration nearest ``angles`` (radians) whose rods close at ``closing``: Gauss-Newton steps of
    least length on sum cos(a_i) = X, sum sin(a_i) = Y (a picked cell's middle is a chord's point, off M
    by the grid's error: the loop would not close by a visible gap)."""
    a = np.asarray(angles, dtype=float).copy()
    target = np.asarray(closing, dtype=float)
    for _ in range(steps):
        F = np.array([np.cos(a).sum(), np.sin(a).sum()]) - target
        if np.abs(F).max() < 1e-12:
            break
        J = np.stack([-np.sin(a), np.cos(a)])          # (2, m)
        a -= np.linalg.pinv(J) @ F
    return a


class QtLinkageInset(QWidget):
    """The rods at one configuration; ``show_configuration(angles, names)`` shows it, ``hide()`` hides it."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setAttribute(Qt.WA_TransparentForMouseEvents, True)
        self.resize(*SIZE)
        self.angles: np.ndarray | None = None
        self.names: list[str] = []
        self.closing = (1.0, 0.0)
        self.hide()

    def show_configuration(self, angles, names, closing=(1.0, 0.0)) -> None:
        self.closing = (float(closing[0]), float(closing[1]))
        self.angles = closed_configuration(angles, self.closing)
        self.names = list(names)
        self.place()
        self.show()
        self.raise_()
        self.update()

    def place(self) -> None:
        """At the bottom of the view, right of the axes' corner (the colour bar keeps the right side)."""
        p = self.parentWidget()
        if p is not None:
            self.move(int(0.22 * p.width()), max(0, p.height() - self.height() - 12))

    def joints(self) -> np.ndarray:
        """The hinges (m + 1, 2): from (0, 0) along each rod; the last one is where the fixed rod starts."""
        return linkage_points(self.angles if self.angles is not None else [])

    def paintEvent(self, event) -> None:
        if self.angles is None:
            return
        qp = QPainter(self)
        qp.setRenderHint(QPainter.Antialiasing, True)
        qp.fillRect(self.rect(), QColor(20, 24, 34, 215))
        qp.setPen(QPen(QColor("#c8d2e6")))
        font = QFont(self.font())
        font.setPixelSize(14)
        qp.setFont(font)
        qp.drawText(10, 20, "the rods at this point")
        J = self.joints()
        pts = np.vstack([J, [self.closing]])
        lo, hi = pts.min(axis=0) - 0.25, pts.max(axis=0) + 0.25
        top, bottom = 30, self.height() - 34
        scale = min((self.width() - 20) / (hi[0] - lo[0]), (bottom - top) / (hi[1] - lo[1]))
        cx = 10 + 0.5 * ((self.width() - 20) - scale * (hi[0] - lo[0]))
        cy = top + 0.5 * ((bottom - top) - scale * (hi[1] - lo[1]))

        def at(x, y):
            return QPointF(cx + scale * (x - lo[0]), cy + scale * (hi[1] - y))

        pen = QPen(QColor(FIXED_COLOR), 5)
        pen.setStyle(Qt.DashLine)
        qp.setPen(pen)
        qp.drawLine(at(*self.closing), at(0.0, 0.0))
        for i in range(len(J) - 1):
            pen = QPen(QColor(ROD_COLORS[i % len(ROD_COLORS)]), 6)
            pen.setCapStyle(Qt.RoundCap)
            qp.setPen(pen)
            qp.drawLine(at(*J[i]), at(*J[i + 1]))
        qp.setPen(QPen(QColor("#ffffff"), 1))
        qp.setBrush(QColor("#ffffff"))
        for x, y in np.vstack([J, [self.closing]]):
            qp.drawEllipse(at(x, y), 3.5, 3.5)
        qp.setPen(QPen(QColor("#c8d2e6")))
        deg = [f"{nm} {np.degrees(a) % 360:.0f}\u00b0" for nm, a in zip(self.names, self.angles)]
        qp.drawText(10, self.height() - 12, "  ".join(deg))
        qp.end()


def linkage_of(cx) -> tuple[float, float] | None:
    """Where the rods of ``cx``'s system close, if it is a planar linkage of unit rods (else None); cached."""
    cache = getattr(cx, "_cache", None)
    key = ("linkage",)
    if cache is not None and key in cache:
        return cache[key]
    meta = getattr(cx, "meta", None) or {}
    names, formulas = meta.get("variables"), meta.get("formulas")
    out = linkage_joints(names, formulas) if names and formulas and len(names) == int(cx.n) else None
    if cache is not None:
        cache[key] = out
    return out
