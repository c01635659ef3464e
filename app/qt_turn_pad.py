"""QtTurnPad: a small disc to drag in, turning the screen's X and Y against one hidden direction."""

from __future__ import annotations

from qtpy.QtCore import QPointF, Qt, Signal
from qtpy.QtGui import QColor, QPainter, QPen
from qtpy.QtWidgets import QWidget


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

    def paintEvent(self, ev) -> None:
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

    def mousePressEvent(self, ev) -> None:
        self._last = (ev.x(), ev.y())
        self.update()

    def mouseMoveEvent(self, ev) -> None:
        if self._last is None:
            return
        dx, dy = ev.x() - self._last[0], ev.y() - self._last[1]
        self._last = (ev.x(), ev.y())
        if dx or dy:
            self.dragged.emit(self.hidden, 0.5 * dx, -0.5 * dy)

    def mouseReleaseEvent(self, ev) -> None:
        self._last = None
        self.update()
