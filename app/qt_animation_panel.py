"""QtAnimationPanel: play a rotation, a grand tour or a slice sweep, and export it as GIF / MP4.

The panel owns only the controls and a QTimer on the GUI thread; each tick it
emits ``tick(seconds)`` (the time since the last tick, times the speed) and
the window moves the view by that much, in place. ``exportRequested(format)``
("gif" or "mp4") asks the window to render the animation off screen.

Modes (:data:`MODES`; the periods are in :mod:`gcmh_studio.animation`): ``rotate`` (the chosen plane, one turn per
``ROTATE_PERIOD`` seconds at speed 1), ``tour`` (the path of
:func:`gcmh_studio.animation.tour_angles`, one period per ``TOUR_PERIOD`` seconds) and
``slice`` (the slice window's centre sweeps across and back per
``SLICE_PERIOD`` seconds; needs the slice turned on in the View tab).

``param`` (:data:`PARAM_MODE`): a parameter of the formulas sweeps from one value to another, one
extraction per frame.  Played, it goes there and back (``PARAM_PERIOD``), each value a coarse step and
the full grid where it stops (:meth:`gcmh_studio.controller.StudioController.tick`); exported, it is
``frames`` extractions from one end to the other (``spec_text()`` gives ``param:a=-1:1`` for
:func:`gcmh_studio.headless.export_param_sweep`).  The mode is offered only once the window has
given the formulas' parameters with :meth:`QtAnimationPanel.set_parameters`.
"""

from __future__ import annotations

import time

from qtpy.QtCore import QSignalBlocker, QTimer, Signal
from qtpy.QtWidgets import (
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QWidget,
)

from .model import AnimationSettings, StudioModel, telling_plane
from .qt_widgets import connect_all, error_label, group, labelled_row, narrow_combo, panel_layout, slider_row

MODES = {"rotate": "Rotate in a plane", "tour": "Grand tour (smooth path through projections)",
         "slice": "Sweep the slice window"}
PARAM_MODE = ("param", "Sweep a parameter (one extraction per frame)")
TICK_MS = 33


class QtAnimationPanel(QWidget):
    tick = Signal(float)              # elapsed seconds times the speed factor
    playingChanged = Signal(bool)
    exportRequested = Signal(str)     # "gif" or "mp4"
    modeChanged = Signal(str)

    def __init__(self, model: StudioModel | None = None, parent=None):
        super().__init__(parent)
        self.studio = model if model is not None else StudioModel()
        self.names: list[str] = []
        self.planes: list[tuple[int, int]] = []
        lay = panel_layout(self)

        _, pf = group(lay, "Play", QFormLayout)
        self.mode_combo = narrow_combo()
        for k, label in MODES.items():
            self.mode_combo.addItem(label, k)
        pf.addRow("animation", self.mode_combo)
        self.plane_combo = narrow_combo()
        self.plane_combo.setToolTip("the plane of the rotation")
        self.plane_label = labelled_row(pf, "plane", self.plane_combo)
        self.param_combo = narrow_combo()
        self.param_combo.setToolTip("the parameter of the formulas that the animation sweeps (coarse while "
                                    "playing, the full grid where it stops)")
        self.param_label = labelled_row(pf, "parameter", self.param_combo)
        self.from_spin, self.to_spin = QDoubleSpinBox(), QDoubleSpinBox()
        for sp, tip in ((self.from_spin, "its value in the first frame"),
                        (self.to_spin, "its value in the last frame")):
            sp.setDecimals(3)
            sp.setRange(-1e6, 1e6)
            sp.setSingleStep(0.1)
            sp.setToolTip(tip)
        self.from_label = labelled_row(pf, "from", self.from_spin)
        self.to_label = labelled_row(pf, "to", self.to_spin)
        self.params: dict[str, dict] = {}
        self.speed_slider, self.speed_label = slider_row(pf, "speed 1\u00d7", 1, 100, 20,
                                                         "speed: 1 = a twentieth of the normal speed, 100 = five times")
        self.play_button = QPushButton("Play")
        self.play_button.setCheckable(True)
        self.play_button.setToolTip("start or pause the animation (Space)")
        pf.addRow(self.play_button)
        self.message = error_label()
        pf.addRow(self.message)

        _, ef = group(lay, "Export", QFormLayout)
        self.frames_spin = QSpinBox()
        self.frames_spin.setRange(2, 2000)
        self.frames_spin.setValue(72)
        self.frames_spin.setToolTip("frames in the exported animation (one whole turn, tour or sweep)")
        ef.addRow("frames", self.frames_spin)
        self.fps_spin = QSpinBox()
        self.fps_spin.setRange(1, 60)
        self.fps_spin.setValue(20)
        ef.addRow("frames per second", self.fps_spin)
        row = QHBoxLayout()
        self.gif_button = QPushButton("Export GIF\u2026")
        self.mp4_button = QPushButton("Export MP4\u2026")
        self.gif_button.setToolTip("plays in every slide program; one 256-colour palette made for this "
                                   "animation, text kept in its own colour")
        self.mp4_button.setToolTip("recommended: full colour, smooth shading, and several times smaller than the GIF")
        row.addWidget(self.mp4_button)
        row.addWidget(self.gif_button)
        ef.addRow(row)
        hint = QLabel("MP4 is smaller and smoother; GIF plays everywhere.")
        hint.setStyleSheet("color: #666; font-size: 11px;")
        ef.addRow(hint)
        lay.addStretch(1)

        self.timer = QTimer(self)
        self.timer.setInterval(TICK_MS)
        self.timer.timeout.connect(self._on_timer)
        self._last = None
        self.mode_combo.currentIndexChanged.connect(self._on_mode)
        self.param_combo.currentIndexChanged.connect(self._on_param)
        self.speed_slider.valueChanged.connect(self._on_speed)
        self.play_button.toggled.connect(self.set_playing)
        self.gif_button.clicked.connect(lambda: self.exportRequested.emit("gif"))
        self.mp4_button.clicked.connect(lambda: self.exportRequested.emit("mp4"))
        connect_all((self.mode_combo.currentIndexChanged, self.plane_combo.currentIndexChanged,
                     self.param_combo.currentIndexChanged, self.from_spin.valueChanged, self.to_spin.valueChanged,
                     self.frames_spin.valueChanged, self.fps_spin.valueChanged), self._write_model)
        self.studio.events.system.connect(lambda d: self.set_parameters(d.get("params") or {}))
        self.studio.events.base.connect(self._on_base)
        self._on_mode()
        self._write_model()

    def _on_base(self) -> None:
        """A projection for other variables (a new result): their planes, the one that turns a hidden axis in."""
        names = self.studio.view_names
        if names != self.names:
            self.set_variables(names)
            self.set_plane(telling_plane(self.studio.projection.matrix()))

    def _write_model(self, *_) -> None:
        """The panel's choice as the model's animation settings (the window plays and exports from them)."""
        self.studio.animation = AnimationSettings(
            mode=self.mode(), plane=self.plane(), frames=self.frames_spin.value(), fps=float(self.fps_spin.value()),
            sweep=self.param_sweep(), spec=self.spec_text(), params=tuple(self.params))

    # ------------------------------------------------------------ state
    def set_variables(self, names) -> None:
        from .projection import planes

        self.names = list(names)
        self.planes = planes(len(self.names))
        prev = self.plane_combo.currentText()
        with QSignalBlocker(self.plane_combo):
            self.plane_combo.clear()
            for r, p in enumerate(self.planes):   # data: the row in planes() (a tuple would not survive QVariant)
                self.plane_combo.addItem(f"{self.names[p[0]]}\u2013{self.names[p[1]]}", r)
            i = self.plane_combo.findText(prev) if prev else -1
            self.plane_combo.setCurrentIndex(i if i >= 0 else max(0, len(self.planes) - 1))
        self._write_model()

    def set_parameters(self, params: dict) -> None:
        """The formulas' parameters, {name: {"value", "min", "max"}} (an example's ``params``, or the sliders'
        ranges): the ``param`` mode is offered while there is one, sweeping from each one's min to its max
        unless the user set other ends (kept while the name stays)."""
        old = dict(self.params)
        self.params = {str(k): dict(v) for k, v in (params or {}).items()}
        prev = self.param_combo.currentText()
        with QSignalBlocker(self.param_combo):
            self.param_combo.clear()
            for name in self.params:
                self.param_combo.addItem(name)
            i = self.param_combo.findText(prev) if prev else -1
            self.param_combo.setCurrentIndex(i if i >= 0 else 0)
        name = self.param_combo.currentText()
        if name and (name not in old or old[name] != self.params[name]):
            self._on_param()
        has = self.mode_combo.findData(PARAM_MODE[0]) >= 0
        if self.params and not has:
            self.mode_combo.addItem(PARAM_MODE[1], PARAM_MODE[0])
        elif not self.params and has:
            if self.mode() == PARAM_MODE[0]:
                self.set_mode("rotate")
            self.mode_combo.removeItem(self.mode_combo.findData(PARAM_MODE[0]))
        self._on_mode()
        self._write_model()

    def param_sweep(self) -> tuple[str, float, float] | None:
        """(name, from, to) of the parameter sweep, or None when no parameter is offered."""
        name = self.param_combo.currentText()
        if not name:
            return None
        return name, self.from_spin.value(), self.to_spin.value()

    def set_param_sweep(self, name: str, lo: float, hi: float) -> None:
        self.param_combo.setCurrentIndex(self.param_combo.findText(name))
        self.from_spin.setValue(float(lo))
        self.to_spin.setValue(float(hi))

    def _on_param(self, *_) -> None:
        spec = self.params.get(self.param_combo.currentText())
        if spec is not None:
            self.from_spin.setValue(float(spec.get("min", -1.0)))
            self.to_spin.setValue(float(spec.get("max", 1.0)))

    def mode(self) -> str:
        return self.mode_combo.currentData()

    def set_mode(self, mode: str) -> None:
        self.mode_combo.setCurrentIndex(self.mode_combo.findData(mode))

    def plane(self) -> tuple[int, int] | None:
        r = self.plane_combo.currentData()
        return None if r is None else self.planes[int(r)]

    def set_plane(self, plane) -> None:
        self.plane_combo.setCurrentIndex(self.plane_combo.findData(self.planes.index(tuple(plane))))

    def speed(self) -> float:
        """Speed factor: slider 20 is 1x; 1 is 0.05x; 100 is 5x."""
        return self.speed_slider.value() / 20.0

    def spec_text(self) -> str:
        """The animation in ``--animate`` syntax (for messages and file names)."""
        m = self.mode()
        if m == PARAM_MODE[0] and self.param_sweep() is not None:
            name, lo, hi = self.param_sweep()
            return f"param:{name}={lo:g}:{hi:g}"
        if m == "rotate" and self.plane() is not None:
            i, j = self.plane()
            return f"rotate:{self.names[i]}-{self.names[j]}"
        return m

    def show_message(self, text: str) -> None:
        self.message.setText(text)
        self.message.setVisible(bool(text))

    # ------------------------------------------------------------ playing
    def is_playing(self) -> bool:
        return self.timer.isActive()

    def toggle_play(self) -> None:
        self.set_playing(not self.is_playing())

    def set_playing(self, on: bool) -> None:
        on = bool(on)
        if self.play_button.isChecked() != on:
            with QSignalBlocker(self.play_button):
                self.play_button.setChecked(on)
        self.play_button.setText("Pause" if on else "Play")
        if on and not self.timer.isActive():
            self._last = time.perf_counter()
            self.timer.start()
        elif not on:
            self.timer.stop()
        self.playingChanged.emit(on)

    def _on_timer(self) -> None:
        now = time.perf_counter()
        dt = min(now - (self._last or now), 0.25)   # after a stall, don't jump
        self._last = now
        self.tick.emit(dt * self.speed())

    def _on_mode(self, *_):
        rot = self.mode() == "rotate"
        self.plane_combo.setVisible(rot)
        self.plane_label.setVisible(rot)
        par = self.mode() == PARAM_MODE[0]
        for w in (self.param_combo, self.param_label, self.from_spin, self.from_label, self.to_spin, self.to_label):
            w.setVisible(par)
        self.show_message("")
        self.modeChanged.emit(self.mode())

    def _on_speed(self, *_):
        self.speed_label.setText(f"speed {self.speed():.2g}\u00d7")
