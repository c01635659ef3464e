"""QtSectionStrip: chi and pieces of the section against the slice value -- a Morse picture beside the slider.

For the result on screen and the slice's direction, the profile (:func:`gcmh_core.section.Sectioner.profile`:
the Euler characteristic and the number of connected pieces of the section at ``SAMPLES`` values across the
direction's range) is computed once, in a worker thread (:class:`gcmh_studio.qt_widgets.QtLatestCall`: a
newer result or direction drops an older question).  The strip draws chi as a step line, pieces as a second
one, a tick where either changes (where the topology of the section changes), and a marker at the slice's
value.  A click or a drag on the strip moves the slice there.  Hidden for curves and while slicing is off.
"""

from __future__ import annotations

import numpy as np
from qtpy.QtCore import QPointF, QRectF, Qt
from qtpy.QtGui import QColor, QFont, QPainter, QPen
from qtpy.QtWidgets import QSizePolicy, QWidget

from gcmh_core.section import Profile, Sectioner

from .model import StudioModel, slice_params
from .qt_widgets import QtLatestCall

SAMPLES = 121                    # values across the range: a profile of the 3-sphere or the three-torus is < 2 s
CHI_COLOR = QColor("#ff7b5c")    # the section's colour in the picture (gcmh_studio.sections.SECTION_COLOR)
PIECES_COLOR = QColor("#6fb6ff")
MARK_COLOR = QColor("#202020")


def profile_values(lo: float, hi: float, samples: int = SAMPLES) -> np.ndarray:
    """``samples`` values strictly inside [lo, hi], evenly spaced (the ends are single points)."""
    return lo + (hi - lo) * (np.arange(samples) + 0.5) / samples


def compute_profile(cx, direction, lo: float, hi: float, samples: int = SAMPLES) -> Profile:
    """The strip's profile of ``cx`` along ``direction`` (n,) over [lo, hi] (runs in the worker thread)."""
    return Sectioner(cx, np.asarray(direction, dtype=np.float64)).profile(profile_values(lo, hi, samples))


class QtSectionStrip(QWidget):
    """chi and pieces of the section against the slice value; ``profile`` is the one drawn (None while it is
    computed), ``key`` what it was asked for: (the result's serial, the direction's bytes, lo, hi)."""

    def __init__(self, model: StudioModel, parent=None):
        super().__init__(parent)
        self.studio = model
        self.profile: Profile | None = None
        self.key: tuple | None = None
        self.error: str | None = None
        self.range = (0.0, 1.0)
        self.setMinimumHeight(70)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Fixed)
        self.setToolTip("chi (coral) and pieces (blue) of the section against the slice's value: where they "
                        "change, the topology of the section changes. Click or drag to move the slice.")
        self.worker = QtLatestCall(self, "gcmh-section-profile")
        self.worker.answered.connect(self._on_answer)
        model.events.result.connect(lambda *_: self.refresh())
        model.events.slice.connect(self.refresh)
        model.events.projection.connect(self._on_projection)
        self.refresh()

    # ------------------------------------------------------------------ what to show
    def wanted(self):
        """(key, direction, lo, hi) of the profile the model's slice asks for, or None (no result, a curve,
        slicing off)."""
        m = self.studio
        cx = m.result
        if cx is None or getattr(cx, "dim", 0) < 2 or not m.slice.on:
            return None
        prm = slice_params(m.slice.window(), cx.vertices, m.projection, (m.slice.c, m.slice.w))
        if prm is None:
            return None
        _, u, lo, hi, _, _ = prm
        return (m.serial, np.asarray(u, dtype=np.float64).round(12).tobytes(), lo, hi), u, lo, hi

    def refresh(self) -> None:
        """Ask for the profile when the result or the direction changed; show or hide; redraw the marker."""
        want = self.wanted()
        self.setVisible(want is not None)
        if want is None:
            return
        key, u, lo, hi = want
        if key != self.key:
            self.key, self.profile, self.error, self.range = key, None, None, (lo, hi)
            cx = self.studio.result
            self.worker.ask(key, lambda: compute_profile(cx, u, lo, hi))
        self.update()

    def _on_projection(self) -> None:
        if self.studio.slice.on and self.studio.slice.hidden:   # a hidden direction turns with the view
            self.refresh()

    def _on_answer(self, key, value, error) -> None:
        if key != self.key:
            return
        self.profile, self.error = value, error
        self.update()

    def busy(self) -> bool:
        return self.key is not None and self.profile is None and self.error is None

    # ------------------------------------------------------------------ drawing
    def _plot_rect(self) -> QRectF:
        return QRectF(34, 6, max(10, self.width() - 42), max(10, self.height() - 22))

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        r = self._plot_rect()
        p.fillRect(r, QColor("#f4f5f8"))
        small = QFont(self.font())
        small.setPointSizeF(max(7.0, small.pointSizeF() * 0.85))
        p.setFont(small)
        lo, hi = self.range
        if self.profile is None:
            p.setPen(QColor("#666"))
            p.drawText(r, Qt.AlignCenter, "section profile: " + (self.error or "computing ..."))
        else:
            self._draw_profile(p, r)
        # the slice's value
        c = lo + self.studio.slice.c * (hi - lo)
        x = self._x(c, r)
        p.setPen(QPen(MARK_COLOR, 2))
        p.drawLine(QPointF(x, r.top()), QPointF(x, r.bottom()))
        p.setPen(QColor("#444"))
        p.drawText(QRectF(r.left(), r.bottom() + 1, r.width(), 14), Qt.AlignLeft, f"{lo:.3g}")
        p.drawText(QRectF(r.left(), r.bottom() + 1, r.width(), 14), Qt.AlignRight, f"{hi:.3g}")
        p.end()

    def _x(self, value: float, r: QRectF) -> float:
        lo, hi = self.range
        t = 0.5 if hi <= lo else (value - lo) / (hi - lo)
        return r.left() + min(max(t, 0.0), 1.0) * r.width()

    def _draw_profile(self, p: QPainter, r: QRectF) -> None:
        prof = self.profile
        assert prof is not None
        ys = np.concatenate([prof.chi, prof.pieces, [0]])
        top, bottom = int(ys.max()), int(ys.min())
        span = max(top - bottom, 1)

        def y(v: float) -> float:
            return r.bottom() - 4 - (v - bottom) / span * (r.height() - 8)

        p.setPen(QPen(QColor("#c9ccd4"), 1, Qt.DashLine))
        p.drawLine(QPointF(r.left(), y(0)), QPointF(r.right(), y(0)))
        for k in prof.changes():     # the topology of the section changes between these two values
            x = self._x(0.5 * (prof.values[k - 1] + prof.values[k]), r)
            p.setPen(QPen(QColor("#9aa0ad"), 1, Qt.DotLine))
            p.drawLine(QPointF(x, r.top()), QPointF(x, r.bottom()))
        edges = np.concatenate([[self.range[0]], 0.5 * (prof.values[1:] + prof.values[:-1]), [self.range[1]]])
        for series, color in ((prof.pieces, PIECES_COLOR), (prof.chi, CHI_COLOR)):
            p.setPen(QPen(color, 2.2))
            pts = []
            for i, v in enumerate(series.tolist()):
                pts += [QPointF(self._x(edges[i], r), y(v)), QPointF(self._x(edges[i + 1], r), y(v))]
            for a, b in zip(pts[:-1], pts[1:]):
                p.drawLine(a, b)
        p.setPen(QColor("#444"))
        p.drawText(QRectF(0, y(top) - 7, 30, 14), Qt.AlignRight | Qt.AlignVCenter, str(top))
        if bottom != top:
            p.drawText(QRectF(0, y(bottom) - 7, 30, 14), Qt.AlignRight | Qt.AlignVCenter, str(bottom))
        # the legend under the plot, between the range's ends (inside, it sat on a line at the top)
        below = QRectF(r.left(), r.bottom() + 1, r.width(), 14)
        p.setPen(CHI_COLOR)
        p.drawText(below.adjusted(-40, 0, 0, 0), Qt.AlignHCenter, "chi")
        p.setPen(PIECES_COLOR)
        p.drawText(below.adjusted(0, 0, 40, 0), Qt.AlignHCenter, "pieces")

    def value_at(self, fraction: float) -> tuple[int, int] | None:
        """(chi, pieces) of the profile at ``fraction`` of the range (the nearest value computed), or None."""
        if self.profile is None or self.profile.values.size == 0:
            return None
        lo, hi = self.range
        i = int(np.argmin(np.abs(self.profile.values - (lo + fraction * (hi - lo)))))
        return int(self.profile.chi[i]), int(self.profile.pieces[i])

    # ------------------------------------------------------------------ moving the slice from the strip
    def _move_to(self, x: float) -> None:
        r = self._plot_rect()
        t = min(max((x - r.left()) / max(r.width(), 1.0), 0.0), 1.0)
        self.studio.set_slice(c=round(t, 3))

    def mousePressEvent(self, event) -> None:
        if event.button() == Qt.LeftButton:
            self._move_to(event.pos().x())

    def mouseMoveEvent(self, event) -> None:
        if event.buttons() & Qt.LeftButton:
            self._move_to(event.pos().x())
