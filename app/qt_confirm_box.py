"""QtConfirmBox: the Topology tab's "Confirm on a finer grid" (gcmh_core.confirm).

The run on show is repeated on a second grid (the next seed, 1.5 times the div) in a worker, and
the box says whether chi, pieces and boundary agree, or that the result is below the grid's
resolution with a finer div to try.  Sampled data exists on its own grid only: no button then.
"""

from __future__ import annotations

from qtpy.QtCore import Qt, Signal
from qtpy.QtWidgets import QLabel, QPushButton, QVBoxLayout, QWidget

from .model import StudioModel
from .qt_widgets import QtLatestCall


def confirm_job(job, cx):
    """The confirmation of ``cx``, the result of ``job`` (run in the worker thread: no Qt here)."""
    from gcmh_core.confirm import confirm

    kw = {key: value for key, value in job.kwargs().items() if key not in ("bounds", "div", "seed")}
    return confirm(list(job.formulas), result=cx, **kw)


class QtConfirmBox(QWidget):
    """A button and the answer; ``confirmed(agree)`` when an answer is on show (agree None: it failed)."""

    confirmed = Signal(object)

    def __init__(self, model: StudioModel, parent=None):
        super().__init__(parent)
        self.studio = model
        self._serial = 0
        self._job = None   # the job of the result on show (the model's job moves on when a new run starts)
        self.answer = None   # the last gcmh_core.confirm.Confirmation on show
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.button = QPushButton("Confirm on a finer grid")
        self.button.setObjectName("confirm_button")
        self.button.setToolTip("Run again on a second grid (another seed, 1.5 times the divisions) and say "
                               "whether the Euler characteristic, the pieces and the boundary agree")
        self.button.clicked.connect(self.start)
        self.label = QLabel("")
        self.label.setObjectName("confirm_answer")
        self.label.setWordWrap(True)
        self.label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        layout.addWidget(self.button)
        layout.addWidget(self.label)
        self.worker = QtLatestCall(self, name="gcmh-confirm")
        self.worker.answered.connect(self._answered)
        model.events.result.connect(self._new_result)
        self._new_result(model.result)

    def _can_confirm(self) -> bool:
        job, cx = self._job, self.studio.result
        return (job is not None and cx is not None and cx.count(0) > 0 and bool(job.formulas)
                and all(isinstance(f, str) for f in job.formulas))

    def _new_result(self, cx) -> None:
        self._serial += 1   # (an answer still on its way is for a result no longer on show)
        self._job = self.studio.job if cx is not None else None
        self.answer = None
        self.label.setText("")
        self.button.setEnabled(self._can_confirm())

    def start(self) -> bool:
        """Ask for the confirmation of the result on show; False when there is none to confirm."""
        if not self._can_confirm():
            return False
        self.button.setEnabled(False)
        self.label.setText("Running again on a finer grid\u2026")
        job, cx = self._job, self.studio.result
        self.worker.ask(self._serial, lambda: confirm_job(job, cx))
        return True

    def _answered(self, key, value, error) -> None:
        if key != self._serial:
            return
        self.button.setEnabled(self._can_confirm())
        if error is not None:
            self.label.setText(f"Could not confirm: {error}")
            self.confirmed.emit(None)
            return
        self.answer = value
        self.label.setText(value.message)
        self.confirmed.emit(bool(value.agree))
