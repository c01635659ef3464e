"""QtDataPanel: the Data tab, the levels of data files opened in the studio as live sliders.

One row per component of F: where its values come from, their range, a slider and a number box for the
level.  Like a parameter's slider (:mod:`gcmh_studio.qt_parameters`): while the slider is held each move
re-extracts on a coarse grid (every few samples, `data_source.DataSource.stride_for`), drawn with the
moving look; letting go runs the full grid.  The newest level wins: a run in flight finishes (a coarse
one) or is cancelled (a full one), and only the latest waiting request starts after it.

Runs happen in a :class:`QtDataRun` thread (the engine and the drawing arrays, no VTK); the window
draws the result on the GUI thread (``window.show_result``).
"""

from __future__ import annotations

import math
import threading

from qtpy.QtCore import QSignalBlocker, Qt, QThread, Signal
from qtpy.QtWidgets import QDoubleSpinBox, QGridLayout, QLabel, QSlider, QVBoxLayout, QWidget

SLIDER_STEPS = 1000


class QtDataRun(QThread):
    """One extraction of a data source at some levels, off the GUI thread: ``done(cx, geometry)`` or
    ``failed(message)``; ``cancel()`` stops it at the engine's next poll (``failed("cancelled")``)."""

    done = Signal(object, object)
    failed = Signal(str)

    def __init__(self, source, levels, coarse: bool, parent=None):
        super().__init__(parent)
        self.source, self.levels, self.coarse = source, list(levels), coarse
        self._cancel = threading.Event()

    def cancel(self) -> None:
        self._cancel.set()

    def run(self) -> None:  # the thread body
        from gcmh_core.errors import Cancelled

        try:
            cx = self.source.extract(self.levels, coarse=self.coarse, cancel=self._cancel.is_set)
            geometry = None
            if cx.count(0):
                from .geometry import Geometry

                geometry = Geometry.build(cx)
        except Cancelled:
            self.failed.emit("cancelled")
            return
        except Exception as e:  # noqa: BLE001 - any error goes to the status line
            self.failed.emit(str(e))
            return
        self.done.emit(cx, geometry)


class QtDataPanel(QWidget):
    """The levels of ``window``'s data source (see the module docstring).

    Signals: ``shown(step)`` after a result is drawn ("coarse" or "full"), ``failed(message)``."""

    shown = Signal(str)
    failed = Signal(str)

    def __init__(self, window, parent=None):
        super().__init__(parent)
        self.window = window
        self.source = None
        self.sliders: list[QSlider] = []
        self.boxes: list[QDoubleSpinBox] = []
        self._run: QtDataRun | None = None
        self._waiting: tuple[list[float], bool] | None = None
        self._first = True
        lay = QVBoxLayout(self)
        self.title = QLabel("Open a data file: File \u2192 Open data\u2026, or drop it on the window.")
        self.title.setWordWrap(True)
        lay.addWidget(self.title)
        self.grid = QGridLayout()
        lay.addLayout(self.grid)
        self.notes = QLabel("")
        self.notes.setWordWrap(True)
        lay.addWidget(self.notes)
        lay.addStretch(1)

    # ------------------------------------------------------------------ the source
    def set_source(self, source) -> None:
        """Show ``source``'s components and run it at its levels."""
        self.stop()
        self.source = source
        self._first = True
        while self.grid.count():
            item = self.grid.takeAt(0)
            if item.widget() is not None:
                item.widget().deleteLater()
        self.sliders, self.boxes = [], []
        shape = "\u00d7".join(map(str, source.shape))
        self.title.setText(f"<b>{source.title}</b><br>{shape} samples, "
                           f"{', '.join(source.names)}: M is where each component equals its level")
        for j, r in enumerate(source.ranges):
            label = QLabel(f"{r.source}\nrange [{r.lo:.6g}, {r.hi:.6g}]")
            label.setWordWrap(True)
            slider = QSlider(Qt.Horizontal)
            slider.setRange(0, SLIDER_STEPS)
            slider.setValue(self._to_slider(j, source.levels[j]))
            box = QDoubleSpinBox()
            # (one decimal at least: a level between two integers of integer data)
            decimals = max(1, 4 - int(math.floor(math.log10(max(abs(r.hi - r.lo), 1e-300)))))
            box.setDecimals(min(decimals, 10))
            box.setRange(r.lo, r.hi)
            box.setSingleStep((r.hi - r.lo) / 100 or 1.0)
            box.setValue(source.levels[j])
            slider.sliderMoved.connect(lambda v, j=j: self._slid(j, v, coarse=True))
            slider.sliderReleased.connect(lambda j=j: self._slid(j, self.sliders[j].value(), coarse=False))
            slider.actionTriggered.connect(lambda action, j=j: self._stepped(j))
            box.editingFinished.connect(lambda j=j: self.set_level(j, self.boxes[j].value()))
            self.grid.addWidget(label, 2 * j, 0, 1, 2)
            self.grid.addWidget(slider, 2 * j + 1, 0)
            self.grid.addWidget(box, 2 * j + 1, 1)
            self.sliders.append(slider)
            self.boxes.append(box)
        self.notes.setText("\n".join(source.notes))
        self.request(coarse=False)

    def _to_slider(self, j: int, level: float) -> int:
        r = self.source.ranges[j]
        return 0 if r.hi == r.lo else round(SLIDER_STEPS * (level - r.lo) / (r.hi - r.lo))

    def _from_slider(self, j: int, value: int) -> float:
        r = self.source.ranges[j]
        return r.lo + (r.hi - r.lo) * value / SLIDER_STEPS

    def _slid(self, j: int, value: int, coarse: bool) -> None:
        self.source.levels[j] = self._from_slider(j, value)
        with QSignalBlocker(self.boxes[j]):
            self.boxes[j].setValue(self.source.levels[j])
        self.request(coarse=coarse)

    def _stepped(self, j: int) -> None:
        """A click on the groove or a key: one step, run on the full grid once the slider has moved."""
        slider = self.sliders[j]
        if slider.isSliderDown():
            return   # (dragging: sliderMoved runs the coarse steps)
        from qtpy.QtCore import QTimer

        QTimer.singleShot(0, lambda: self._slid(j, slider.value(), coarse=False))

    def set_level(self, j: int, level: float, coarse: bool = False) -> None:
        """Component j's level (clamped to its data range), and a run at it."""
        level = self.source.ranges[j].clamp(level)
        self.source.levels[j] = level
        for w, v in ((self.sliders[j], self._to_slider(j, level)), (self.boxes[j], level)):
            with QSignalBlocker(w):
                w.setValue(v)
        self.request(coarse=coarse)

    # ------------------------------------------------------------------ runs
    def request(self, coarse: bool) -> None:
        """Extract at the levels on show: now, or after the run in flight (the newest request wins; a full
        run in flight is cancelled for it)."""
        if self.source is None:
            return
        self._waiting = (list(self.source.levels), coarse)
        if self._run is not None:
            if not self._run.coarse:
                self._run.cancel()
            return
        self._start_waiting()

    def _start_waiting(self) -> None:
        if self._waiting is None or self.source is None:
            return
        levels, coarse = self._waiting
        self._waiting = None
        run = self._run = QtDataRun(self.source, levels, coarse, self)
        run.done.connect(lambda cx, geometry, run=run: self._done(run, cx, geometry))
        run.failed.connect(lambda message, run=run: self._failed(run, message))
        what = "coarse grid" if coarse else "full grid"
        self.window.set_status(f"Extracting at level {', '.join(f'{v:.6g}' for v in levels)} ({what})\u2026")
        run.start()

    def _ended(self, run) -> bool:
        """The run's thread is over; whether it was the panel's current run (not one stopped for a new source)."""
        run.wait()
        current = self._run is run
        if current:
            self._run = None
        run.deleteLater()
        return current

    def _done(self, run, cx, geometry) -> None:
        if not self._ended(run):
            return
        src = self.source
        if src is not None and (self._waiting is None or run.coarse):   # (a full one a newer level replaced: not drawn)
            keep = not self._first
            self._first = False
            self.window.show_result(cx, src.names, title=src.title, geometry=geometry, keep_view=keep,
                                    moving=run.coarse)
            where = ", ".join(f"{v:.6g}" for v in run.levels)
            grid = f" (every {cx.meta['data']['stride']}th sample)" if run.coarse else ""
            self.window.set_status(f"Level {where}{grid}: {cx.count(0):,} vertices"
                                   + (" \u2014 M is empty at this level" if cx.count(0) == 0 else ""))
            self.shown.emit("coarse" if run.coarse else "full")
        self._start_waiting()

    def _failed(self, run, message: str) -> None:
        if not self._ended(run):
            return
        if message != "cancelled":
            self.window.set_status(f"Data: {message}", error=True)
            self.failed.emit(message)
        self._start_waiting()

    def busy(self) -> bool:
        return self._run is not None or self._waiting is not None

    def stop(self) -> None:
        """Cancel the run in flight and drop the waiting one (a new source, the window closing)."""
        self._waiting = None
        run = self._run
        if run is not None:
            run.cancel()
            run.wait()
            self._run = None
