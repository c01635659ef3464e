"""QtPresentationStrip: the slim control strip of presentation mode, in type a room can read.

Beside the view while presenting (:class:`gcmh_studio.qt_presentation.QtPresentation` shows it; H hides it
and brings it back): a slider per parameter of the formulas, the slice (on or off, and where), the turn of
one plane (the Animate tab's), and the animation to play with its Play button (Space).

It reads and writes the model (:class:`gcmh_studio.model.StudioModel`): the slice and the turn directly;
the parameters through ``paramMoved(name, value, final)``, which the presentation hands to the formula
panel's own parameter input (a held slider: coarse steps; let go: the full grid), and the animation
through ``modeRequested(mode)`` / ``playRequested()`` to the Animate tab.  The model's events keep it in
step with the side panels, undo and sessions.
"""

from __future__ import annotations

from qtpy.QtCore import QSignalBlocker, Qt, Signal
from qtpy.QtWidgets import QCheckBox, QComboBox, QFrame, QGridLayout, QLabel, QPushButton, QSlider, QVBoxLayout, QWidget

from .inputs import format_value
from .model import StudioModel
from .qt_parameters import STEPS, step_value

FONT_PX = 20                 # the strip's type, in pixels (the side panels' is about 13)
WIDTH = 320                  # pixels at most: slim beside a 16:9 view (the object stays in the middle 2/3)
WIDTH_SHARE = 0.22           # of the screen at most (a 1024x768 projector keeps 3/4 for the view)
MIN_WIDTH = 180
SLICE_STEPS = 1000
STYLE = f"""
QFrame#gcmh-strip {{ background: #1f2430; }}
QFrame#gcmh-strip QLabel, QFrame#gcmh-strip QCheckBox {{ color: #e8ecf4; font-size: {FONT_PX}px; }}
QFrame#gcmh-strip QLabel#gcmh-strip-head {{ color: #9aa4b8; font-size: {int(FONT_PX * 0.7)}px; }}
QFrame#gcmh-strip QComboBox, QFrame#gcmh-strip QPushButton {{ font-size: {FONT_PX}px; padding: 6px; }}
QFrame#gcmh-strip QSlider {{ min-height: {2 * FONT_PX}px; }}
QFrame#gcmh-strip QSlider::groove:horizontal {{ height: 8px; background: #4a5468; border-radius: 4px; }}
QFrame#gcmh-strip QSlider::handle:horizontal {{ width: {FONT_PX + 4}px; margin: -{FONT_PX // 2}px 0;
    background: #f0c05a; border-radius: {FONT_PX // 2 + 2}px; }}
"""
MODE_LABELS = {"rotate": "rotate", "tour": "tour", "slice": "slice sweep", "param": "parameter sweep"}


def _big_slider(lo: int, hi: int) -> QSlider:
    s = QSlider(Qt.Horizontal)
    s.setRange(lo, hi)
    s.setFocusPolicy(Qt.NoFocus)   # (keys stay the view's: Space plays, H hides, PageDown steps)
    return s


class QtPresentationStrip(QFrame):
    """The strip (see the module docstring) over ``model``."""

    paramMoved = Signal(str, float, bool)   # (parameter, value, final): held -> coarse steps, let go -> full
    modeRequested = Signal(str)             # an animation mode chosen here
    playRequested = Signal()                # Play / Pause pressed here

    def __init__(self, model: StudioModel, parent=None):
        super().__init__(parent)
        self.setObjectName("gcmh-strip")
        self.setStyleSheet(STYLE)
        self.setFixedWidth(WIDTH)
        self.model = model
        self.param_rows: dict[str, tuple[QLabel, QSlider]] = {}
        self._specs: dict[str, dict] = {}
        lay = QVBoxLayout(self)
        lay.setContentsMargins(16, 16, 16, 16)
        lay.setSpacing(10)
        head = QLabel("H hides this strip \u00b7 Space plays \u00b7 Esc leaves")
        head.setObjectName("gcmh-strip-head")
        head.setWordWrap(True)
        lay.addWidget(head)

        self.params_box = QWidget()
        self.params_grid = QGridLayout(self.params_box)
        self.params_grid.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.params_box)

        self.slice_check = QCheckBox("slice")
        self.slice_check.setFocusPolicy(Qt.NoFocus)
        self.slice_slider = _big_slider(0, SLICE_STEPS)
        lay.addWidget(self.slice_check)
        lay.addWidget(self.slice_slider)

        self.turn_label = QLabel("turn")
        self.turn_slider = _big_slider(-180, 180)
        lay.addWidget(self.turn_label)
        lay.addWidget(self.turn_slider)

        self.mode_combo = QComboBox()
        self.mode_combo.setFocusPolicy(Qt.NoFocus)
        self.play_button = QPushButton("\u25b6 Play")
        self.play_button.setFocusPolicy(Qt.NoFocus)
        lay.addWidget(self.mode_combo)
        lay.addWidget(self.play_button)
        lay.addStretch(1)

        self.slice_check.toggled.connect(lambda on: self.model.set_slice(on=bool(on)))
        self.slice_slider.valueChanged.connect(lambda i: self.model.set_slice(c=i / SLICE_STEPS))
        self.turn_slider.valueChanged.connect(self._on_turn)
        self.mode_combo.activated.connect(lambda _i: self.modeRequested.emit(self.mode_combo.currentData()))
        self.play_button.clicked.connect(self.playRequested.emit)
        ev = model.events
        self._connections = [(ev.system, self._on_system), (ev.slice, self.show_slice),
                             (ev.projection, self.show_turn), (ev.base, self.show_turn)]
        for signal, slot in self._connections:
            signal.connect(slot)
        self.refresh()

    def fit_width(self, screen_width: int) -> None:
        """Slim on any screen: at most ``WIDTH`` pixels and ``WIDTH_SHARE`` of ``screen_width``."""
        self.setFixedWidth(int(max(MIN_WIDTH, min(WIDTH, WIDTH_SHARE * screen_width))))

    def disconnect_model(self) -> None:
        for signal, slot in self._connections:
            signal.disconnect(slot)

    def refresh(self) -> None:
        """Everything as the model has it now (entering presentation mode)."""
        self._on_system(self.model.system)
        self.show_slice()
        self.show_turn()

    # ------------------------------------------------------------ the parameters
    def _on_system(self, system: dict) -> None:
        params = {str(k): dict(v) for k, v in ((system or {}).get("params") or {}).items()}
        if list(params) != list(self._specs):
            self._rebuild_params(list(params))
        self._specs = params
        for name, spec in params.items():
            self._show_param(name, spec)

    def _rebuild_params(self, names) -> None:
        for label, sl in self.param_rows.values():
            label.deleteLater()
            sl.deleteLater()
        self.param_rows = {}
        for r, name in enumerate(names):
            label = QLabel(name)
            sl = _big_slider(0, STEPS)
            self.params_grid.addWidget(label, 2 * r, 0)
            self.params_grid.addWidget(sl, 2 * r + 1, 0)
            sl.valueChanged.connect(lambda i, n=name, s=sl: self._on_param(n, i, final=not s.isSliderDown()))
            sl.sliderReleased.connect(lambda n=name, s=sl: self._on_param(n, s.value(), final=True))
            self.param_rows[name] = (label, sl)
        self.params_box.setVisible(bool(names))

    def _show_param(self, name: str, spec: dict) -> None:
        label, sl = self.param_rows[name]
        lo, hi, v = float(spec.get("min", -1)), float(spec.get("max", 1)), float(spec.get("value", 0))
        label.setText(f"{name} = {format_value(v)}")
        with QSignalBlocker(sl):
            sl.setValue(int(round((v - lo) / (hi - lo) * STEPS)) if hi > lo else 0)

    def _on_param(self, name: str, i: int, final: bool) -> None:
        spec = self._specs.get(name)
        if spec is None:
            return
        value = step_value(float(spec.get("min", -1)), float(spec.get("max", 1)), int(i))
        self.param_rows[name][0].setText(f"{name} = {format_value(value)}")
        self.paramMoved.emit(name, value, final)

    def set_param_position(self, name: str, i: int, final: bool = True) -> None:
        """Move parameter ``name``'s slider to position ``i`` (0..STEPS), as a hand on it would."""
        sl = self.param_rows[name][1]
        with QSignalBlocker(sl):
            sl.setValue(int(i))
        self._on_param(name, sl.value(), final)

    # ------------------------------------------------------------ the slice and the turn
    def show_slice(self) -> None:
        s = self.model.slice
        with QSignalBlocker(self.slice_check):
            self.slice_check.setChecked(bool(s.on))
        names = self.model.view_names
        self.slice_check.setText(f"slice {s.label(names)}" if names else "slice")
        self.slice_slider.setEnabled(bool(s.on))
        with QSignalBlocker(self.slice_slider):
            self.slice_slider.setValue(int(round(s.c * SLICE_STEPS)))

    def _plane_row(self) -> int | None:
        plane = self.model.animation.plane
        planes = self.model.projection.planes
        if plane is None or tuple(plane) not in planes:
            return None
        return planes.index(tuple(plane))

    def show_turn(self) -> None:
        row = self._plane_row()
        self.turn_slider.setEnabled(row is not None)
        if row is None:
            self.turn_label.setText("turn")
            return
        names = self.model.view_names
        i, j = self.model.animation.plane
        angle = float(self.model.projection.angles[row])
        if len(names) > max(i, j):
            self.turn_label.setText(f"turn {names[i]}\u2013{names[j]}  {angle:.0f}\u00b0")
        with QSignalBlocker(self.turn_slider):
            self.turn_slider.setValue(int(round(angle)))

    def _on_turn(self, degrees: int) -> None:
        row = self._plane_row()
        if row is None:
            return
        angles = self.model.projection.angles.copy()
        angles[row] = float(degrees)
        self.model.set_angles(angles)

    # ------------------------------------------------------------ the animation
    def set_modes(self, modes, current: str) -> None:
        """The animations on offer (the Animate tab's modes) and the one chosen."""
        with QSignalBlocker(self.mode_combo):
            self.mode_combo.clear()
            for m in modes:
                self.mode_combo.addItem(MODE_LABELS.get(m, m), m)
            self.mode_combo.setCurrentIndex(max(0, self.mode_combo.findData(current)))
        self.show_turn()

    def set_playing(self, on: bool) -> None:
        self.play_button.setText("\u25a0 Pause" if on else "\u25b6 Play")
