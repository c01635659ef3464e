"""QtMethodBox: the Manifold tab's Method box, the method, its start point, where it runs, the seed, and what
the run will cost.

Under the method, the run's estimate (:func:`gcmh_studio.jobs.estimate_job`: peak memory and time, made in a
worker a moment after the last change, the newest request winning) says before Run what the run will cost,
in red when it won't fit. The box checks its own fields (:meth:`QtMethodBox.check`) and says ``edited`` when
one changes; the formula panel reads it.
"""

from __future__ import annotations

from qtpy.QtCore import QTimer, Signal
from qtpy.QtWidgets import QFormLayout, QGroupBox, QLabel, QLineEdit, QSpinBox

from . import inputs
from .jobs import Job, continuation_methods, estimate_job
from .qt_widgets import QtLatestCall, error_label, mark, narrow_combo

METHOD_LABELS = {"gcmh": "GCMH (whole grid)", "gcch": "GCCH (continuation from a start point)",
                 "cms": "CMS (baseline)", "ccs": "CCS (baseline)"}
ESTIMATE_DELAY_MS = 300   # the estimate is asked for this long after the last change


def check_scheduler(text: str) -> tuple[str | None, str | None]:
    """(error message or None, scheduler or None for this process) from the "run on" field."""
    text = text.strip()
    if not text or text.lower() in ("this computer", "here"):
        return None, None
    try:
        from gcmh_core.distributed import check_scheduler as check
        return None, check(text)
    except ImportError:
        return "the cluster support (gcmh_core.distributed) is not installed", None
    except Exception as e:  # noqa: BLE001 - InputError with the reason
        return str(e), None


def work_estimate(n: int, k: int, div: list[int] | None) -> dict | None:
    """The engine's quick count of the work (cubes, bytes) of a grid, or None."""
    if div is None or inputs.check_nk(n, k):
        return None
    try:
        import gcmh_core
        fn = gcmh_core.estimate_work
    except (ImportError, AttributeError):
        return None
    try:
        return dict(fn(n, k, div))
    except Exception:  # noqa: BLE001 - an estimate must never break the panel
        return None


class QtMethodBox(QGroupBox):
    """Method, start point, "run on", seed and the run's estimate."""

    edited = Signal()

    def __init__(self, methods, parent=None):
        super().__init__("Method", parent)
        ml = QFormLayout(self)
        self.method_combo = narrow_combo()
        for m in methods:
            self.method_combo.addItem(METHOD_LABELS.get(m, m.upper()), m)
        ml.addRow("method", self.method_combo)
        self.start_edit = QLineEdit("")
        self.start_edit.setPlaceholderText("auto")
        self.start_edit.setToolTip("a point on (or near) the manifold, n numbers separated by commas; "
                                   "empty or 'auto': the engine looks for points of M itself")
        self.start_label = QLabel("start point")
        ml.addRow(self.start_label, self.start_edit)
        self.start_error = error_label()
        ml.addRow(self.start_error)
        self.scheduler_edit = QLineEdit("")
        self.scheduler_edit.setPlaceholderText("this computer")
        self.scheduler_edit.setToolTip("empty: run here; 'local': a Dask cluster of one process per core on this "
                                       "machine; tcp://host:port: a running `dask scheduler` "
                                       "(pip install -e \".[cluster]\")")
        ml.addRow("run on", self.scheduler_edit)
        self.scheduler_error = error_label()
        ml.addRow(self.scheduler_error)
        self.seed_spin = QSpinBox()
        self.seed_spin.setRange(0, 2**31 - 1)
        self.seed_spin.setToolTip("seed of the grid perturbation: same seed, same result")
        ml.addRow("seed", self.seed_spin)
        self.estimate_label = QLabel("")
        self.estimate_label.setWordWrap(True)
        self.estimate_label.setStyleSheet("color: #555;")
        ml.addRow(self.estimate_label)
        # the run's estimate (memory and time), made in a worker
        self.run_estimate = None   # the gcmh_core.budget.Estimate of the job shown, once known
        self._estimate_key: str | None = None
        self._job: Job | None = None
        self._estimator = QtLatestCall(self, "gcmh-estimate")
        self._estimator.answered.connect(self._on_estimate)
        self._estimate_timer = QTimer(self)
        self._estimate_timer.setSingleShot(True)
        self._estimate_timer.setInterval(ESTIMATE_DELAY_MS)
        self._estimate_timer.timeout.connect(self._ask_estimate)
        self.method_combo.currentIndexChanged.connect(self._on_method)
        for signal in (self.start_edit.textChanged, self.scheduler_edit.textChanged, self.seed_spin.valueChanged):
            signal.connect(lambda *_: self.edited.emit())
        self._show_start()

    # ------------------------------------------------------------ the fields
    def method(self) -> str:
        return self.method_combo.currentData() or "gcmh"

    def set_method(self, method: str) -> bool:
        i = self.method_combo.findData(method)
        if i < 0:
            return False
        self.method_combo.setCurrentIndex(i)
        return True

    def continuation(self) -> bool:
        """Does the chosen method start from points (GCCH, CCS)?"""
        return self.method() in continuation_methods()

    def start(self, n: int):
        return inputs.check_start(self.start_edit.text(), n)[1] if self.continuation() else None

    def scheduler(self) -> str | None:
        return check_scheduler(self.scheduler_edit.text())[1]

    def _show_start(self) -> None:
        cont = self.continuation()
        self.start_edit.setVisible(cont)
        self.start_label.setVisible(cont)

    def _on_method(self, *_) -> None:
        self._show_start()
        self.edited.emit()

    def check(self, n: int) -> dict[str, str]:
        """Mark the start point (for continuation) and "run on"; their errors by field."""
        errs = {}
        m = inputs.check_start(self.start_edit.text(), n)[0] if self.continuation() else None
        mark(self.start_edit, self.start_error, m)
        if m:
            errs["start"] = m
        m = check_scheduler(self.scheduler_edit.text())[0]
        mark(self.scheduler_edit, self.scheduler_error, m)
        if m:
            errs["run on"] = m
        return errs

    def state(self) -> dict:
        return {"method": self.method(), "seed": self.seed_spin.value(), "start": self.start_edit.text(),
                "scheduler": self.scheduler_edit.text().strip()}

    def set_state(self, d: dict, format_number) -> None:
        """Fill the fields from a dict like :meth:`state` (a start point may be a list of numbers)."""
        meth = str(d.get("method", "gcmh")).lower()
        i = self.method_combo.findData(meth)
        self.method_combo.setCurrentIndex(i if i >= 0 else 0)
        self.seed_spin.setValue(int(d.get("seed", 0)))
        start = d.get("start")
        if isinstance(start, (list, tuple)):
            start = ", ".join(format_number(v) for v in start)
        self.start_edit.setText(start or "")
        self.scheduler_edit.setText(str(d.get("scheduler") or ""))
        self._show_start()

    # ------------------------------------------------------------ the estimate
    def show_estimate(self, job: Job | None, work: dict | None) -> None:
        """The job the panel would run now (None: it can't yet) and the engine's count of its grid's work:
        said at once, and the run's estimate asked for a moment later."""
        if job is not None:
            key = repr(job)
            if key != self._estimate_key:
                self._estimate_key, self._job, self.run_estimate = key, job, None
                self._estimate_timer.start()
            elif self.run_estimate is not None:
                return   # shown already
        else:
            self._estimate_key, self._job, self.run_estimate = None, None, None
            self._estimate_timer.stop()
        if work is None:
            self.estimate_label.setText("")
            return
        cubes = int(work.get("cubes", 0))
        text = f"work: {cubes:,} cubes, about {inputs.human_bytes(work.get('bytes', 0))} peak memory"
        avail = inputs.available_memory()
        style = "color: #555;"
        if self.continuation():
            text = f"full grid: {cubes:,} cubes; continuation visits only those M passes through"
        elif avail and work.get("bytes", 0) > 0.8 * avail:
            text += f"  \u2014 more than the {inputs.human_bytes(avail)} available!"
            style = "color: #c22; font-weight: bold;"
        self.estimate_label.setStyleSheet(style)
        self.estimate_label.setText(text)

    def _ask_estimate(self) -> None:
        job = self._job
        if self._estimate_key is not None and job is not None:
            self._estimator.ask(self._estimate_key, lambda: estimate_job(job))

    def _on_estimate(self, key, est, error) -> None:
        if key != self._estimate_key:
            return   # stale: the panel changed since
        if error is not None:
            self.estimate_label.setStyleSheet("color: #c22;")
            self.estimate_label.setText(error)
            return
        self.run_estimate = est
        text = (f"this run: about {inputs.human_bytes(est.peak_bytes)} of memory "
                f"(of {inputs.human_bytes(est.available_bytes)} available), about {inputs.human_seconds(est.seconds)}"
                f"; {est.cubes:,} cubes, about {est.candidate_cubes:,} crossed by M")
        if not est.fits:
            text += " \u2014 too large: Run asks first"
        self.estimate_label.setStyleSheet("color: #555;" if est.fits else "color: #c22; font-weight: bold;")
        self.estimate_label.setText(text)
