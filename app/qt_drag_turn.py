"""QtDragTurn: Shift-drag on the 3D view turns hidden planes (the events never reach VTK's trackball).

Shift-drag turns the screen's x (horizontal drag) and y (vertical drag) against the hidden direction the View
tab names (the model's ``drag_hidden``); Ctrl+Shift-drag, or Shift with the right button, against the next one
(:meth:`gcmh_studio.model.StudioModel.turn`). The filter also tells the view when it was resized or hidden.
"""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import QEvent, QObject, Qt

DRAG_DEGREES = 0.4       # per pixel of a Shift-drag


class QtDragTurn(QObject):
    """The event filter of a :class:`gcmh_studio.qt_viewer.QtViewer`'s widget."""

    def __init__(self, viewer):
        super().__init__()
        self.viewer = viewer
        self.last = None
        self.hidden = 0

    def can_turn(self) -> bool:
        v = self.viewer
        return v.scene.complex is not None and v.model.projection.n >= 4

    def turn_hidden(self, dx: float, dy: float, hidden: int = 0) -> None:
        """Turn the screen's x by ``dx`` and y by ``dy`` (pixels of a drag) against hidden direction ``hidden``."""
        cam = self.viewer.plotter.camera
        right = np.cross(np.asarray(cam.direction, float), np.asarray(cam.up, float))
        right /= max(np.linalg.norm(right), 1e-12)
        up = np.asarray(cam.up, float) - np.dot(cam.up, right) * right
        up /= max(np.linalg.norm(up), 1e-12)
        self.viewer.model.turn(right, up, hidden, DRAG_DEGREES * dx, DRAG_DEGREES * dy)

    def eventFilter(self, obj, ev) -> bool:
        t = ev.type()
        v = self.viewer
        if t == QEvent.Resize:     # another shape: frame again (after the resize settles)
            v._resized.start()
            return False
        if t == QEvent.Hide:       # (a closing window: no picture of the worker's shows on it)
            v.still.drop()
            return False
        if t == QEvent.MouseButtonPress and ev.modifiers() & Qt.ShiftModifier and self.can_turn():
            nxt = bool(ev.modifiers() & Qt.ControlModifier) or ev.button() == Qt.RightButton
            self.hidden = v.model.drag_hidden + (1 if nxt else 0)
            self.last = (ev.x(), ev.y())
            return True
        if t == QEvent.MouseMove and self.last is not None:
            x, y = ev.x(), ev.y()
            dx, dy = x - self.last[0], y - self.last[1]
            self.last = (x, y)
            self.turn_hidden(dx, -dy, self.hidden)
            return True
        if t == QEvent.MouseButtonRelease and self.last is not None:
            self.last = None
            return True
        return False
