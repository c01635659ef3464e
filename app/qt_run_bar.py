"""QtRunBar: what stays in view under the side panel's tabs.

The example's description (kept while its result is on screen), Run and Cancel,
the progress bar (with the seconds a run has taken, ticking while it runs), the
result's summary, the picked cell and the status line (errors in red), from the
model (:class:`gcmh_studio.model.StudioModel`) and what the window passes on from the
controller (progress, the example's description, whether Run can run).
"""

from __future__ import annotations

from qtpy.QtCore import QObject, Qt, QTimer
from qtpy.QtWidgets import QGroupBox, QHBoxLayout, QLabel, QProgressBar, QPushButton, QVBoxLayout

RUN_TIP = "extract the manifold (Ctrl+R)"


class QtWarmUpLabel(QLabel):
    """The status bar's word on the kernels' warm-up (:class:`gcmh_studio.jobs.WarmUp` or None): while they
    compile; a second after a cached load, nothing is said."""

    def __init__(self, warm_up, parent=None):
        super().__init__("", parent)
        self.warm_up = warm_up
        self._timer = QTimer(self)
        self._timer.setInterval(250)
        self._timer.timeout.connect(self._show)
        if warm_up is not None and warm_up.running():
            self._timer.start()

    def stop(self) -> None:
        self._timer.stop()

    def _show(self) -> None:
        warm = self.warm_up
        if warm.running():
            self.setText(warm.notice())   # (only while numba really compiles: a cache load says nothing)
            return
        self._timer.stop()
        if warm.error:
            self.setText(f"Kernel warm-up failed ({warm.error}); the first run compiles them.")
        elif warm.compiling and warm.seconds is not None:
            self.setText(f"Kernels compiled in {warm.seconds:.0f} s; they are kept for later runs.")
            clear = QTimer(self)   # (owned by the label: it dies with the window instead of firing on it)
            clear.setSingleShot(True)
            clear.timeout.connect(self.clear)
            clear.start(15_000)
        else:
            self.setText("")


def _label(style: str = "") -> QLabel:
    lab = QLabel("")
    lab.setWordWrap(True)
    lab.setTextInteractionFlags(Qt.TextSelectableByMouse)
    lab.setStyleSheet(style)
    return lab


class QtRunBar(QObject):
    """Run / Cancel, progress, summary, pick and status, added to the side panel's layout ``lay`` (in it, not
    in a box of their own: a result's longer summary then takes its room from the tabs above, as a layout of
    its own would move every widget in it and repaint the 3D view beside, dropping its still picture);
    ``elapsed()`` gives the running run's seconds."""

    def __init__(self, model, elapsed, lay, parent=None):
        super().__init__(parent)
        self.elapsed = elapsed
        self.about_box = QGroupBox("")
        self.about_label = _label("font-size: 11px;")
        QVBoxLayout(self.about_box).addWidget(self.about_label)
        self.about_box.setVisible(False)
        lay.addWidget(self.about_box)
        self.run_button = QPushButton("Run")
        self.run_button.setToolTip(RUN_TIP)
        self.run_button.setDefault(True)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setToolTip("stop the running extraction (Esc)")
        self.cancel_button.setEnabled(False)
        row = QHBoxLayout()
        row.addWidget(self.run_button, 1)
        row.addWidget(self.cancel_button)
        lay.addLayout(row)
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setValue(0)
        self.progress.setFormat("idle")
        self.progress.setTextVisible(True)
        lay.addWidget(self.progress)
        self.result_label = _label("font-weight: bold;")
        self.pick_label = _label("font-family: monospace; font-size: 11px;")
        self.pick_label.setVisible(False)
        self.status_label = _label()
        self.status_label.setMinimumHeight(36)
        for w in (self.result_label, self.pick_label, self.status_label):
            lay.addWidget(w)
        self._timer = QTimer(self)
        self._timer.setInterval(100)
        self._timer.timeout.connect(self._tick)
        self.result_label.setText(model.summary())
        model.events.status.connect(self.show_status)
        model.events.picked.connect(lambda info: self.show_pick(model.pick_text()))
        model.events.result.connect(lambda cx: self.result_label.setText(model.summary()))

    def show_description(self, title: str, text: str) -> None:
        """The example's title and description above Run (hidden for a system typed in)."""
        self.about_box.setTitle(title)
        self.about_label.setText(text)
        self.about_box.setVisible(bool(title or text))

    def show_status(self, text: str, error: bool) -> None:
        self.status_label.setStyleSheet("color: #c22;" if error else "")
        self.status_label.setText(text)

    def show_pick(self, text: str) -> None:
        self.pick_label.setText(text)
        self.pick_label.setVisible(bool(text))

    def show_progress(self, fraction, text: str) -> None:
        """``fraction`` in [0, 1] (None: as it is) and the bar's text."""
        if fraction is not None:
            self.progress.setValue(int(round(1000 * fraction)))
        self.progress.setFormat(text)

    def set_running(self, running: bool, can_run: bool, errors: dict) -> None:
        """Run and Cancel for a run under way (``running``) or a system that can (or can't) run."""
        self.run_button.setEnabled(can_run and not running)
        self.cancel_button.setEnabled(running)
        first = next(iter(errors.items()), None)
        self.run_button.setToolTip(f"fix first: {first[1]}" if first and not running and not can_run else RUN_TIP)

    def set_ticking(self, on: bool) -> None:
        """The progress bar counts the seconds of the run under way."""
        (self._timer.start if on else self._timer.stop)()

    def _tick(self) -> None:
        fmt = self.progress.format()
        phase = fmt.split(" \u00b7 ")[0] if fmt else "running"
        self.progress.setFormat(f"{phase} \u00b7 {self.elapsed():.1f} s")
