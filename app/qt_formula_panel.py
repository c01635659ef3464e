"""QtFormulaPanel: the system F: R^n -> R^k, its domain grid, the method and seed.

Everything is checked as the user types: a wrong field gets a red mark and a
one-line message under it (the formula parser's own message for formulas), and
``validityChanged(False)`` keeps Run disabled. No dialog ever opens for a typo.
Formulas are parsed off the GUI thread (:class:`FormulaChecker`), a moment after
the last keystroke: a long formula never blocks the window. Until its answer
comes, a field keeps its last mark and :meth:`QtFormulaPanel.checking` is True;
``checked`` is emitted when no check is left.

Changing n or k hides fields rather than deleting them: formulas, bounds and
names come back as they were when n or k grows again.

Under the method, the run's estimate (:func:`gcmh_studio.jobs.estimate_job`: peak memory
and time, made in a worker a moment after the last change) says before Run what
the run will cost, in red when it won't fit.

Every name in the formulas that is neither a variable nor a constant or function is
a parameter: it gets a row of :class:`gcmh_studio.qt_parameters.QtParameterPanel` (slider,
value, range) under the formulas, found by the same checks; the window re-extracts
as a slider moves.

Complex mode ("complex" switch): equations over C^m as on the blackboard (``z = cos(w)``,
one a line, ``lhs = rhs``), with real equations beside them; the checker splits them
(:func:`gcmh_core.complex_equations.split_complex`) into the real system, shown under
them and run; the real variables (x, y for z; u, v for w, unless typed) name the table's
rows ("u = Re w") and the view's axes.

``state()`` / ``set_state(d)`` give the panel's contents as a plain dict (the
session file stores it; in complex mode the equations as typed, not their split);
``job()`` builds a :class:`gcmh_studio.worker.Job` when valid.
"""

from __future__ import annotations

import math
from fractions import Fraction

from qtpy.QtCore import Qt, QTimer, Signal
from qtpy.QtGui import QColor
from qtpy.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QComboBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPlainTextEdit,
    QSpinBox,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from . import inputs
from .jobs import Job, estimate_job
from .qt_parameters import QtParameterPanel
from .qt_widgets import QtLatestCall, clear_layout, error_label, group, panel_layout

N_MAX = 12
ERROR_STYLE = "QLineEdit { border: 2px solid #d33; background: #fff0f0; }"
BAD_CELL = QColor("#ffc8c8")
GOOD_CELL = QColor("#ffffff")
METHOD_LABELS = {"gcmh": "GCMH (whole grid)", "gcch": "GCCH (continuation from a start point)",
                 "cms": "CMS (baseline)", "ccs": "CCS (baseline)"}


def continuation_methods() -> tuple[str, ...]:
    """The methods that start from points and follow M (they take a start point)."""
    try:
        from gcmh_core import CONTINUATION_METHODS
        return tuple(CONTINUATION_METHODS)
    except ImportError:
        return ("gcch",)


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


# the real variables of a complex one, as on the blackboard: w = u + iv, z = x + iy
_REAL_PAIRS = {"z": ("x", "y"), "w": ("u", "v"), "zeta": ("xi", "eta")}
_REAL_POOL = (("x", "y"), ("u", "v"), ("a", "b"), ("c", "d"), ("p", "q"), ("s", "t"), ("g", "h"), ("m", "n"))


def default_real_names(cvars, equations=()) -> list[str]:
    """Two real names per complex variable: z -> x, y and w -> u, v, then a, b; c, d; ...; never a name the
    equations use (a parameter) or a complex variable; ``z_re, z_im`` when the letters run out."""
    import re

    used = set(cvars) | set(inputs.RESERVED) | {t for e in equations for t in re.findall(r"[A-Za-z_]\w*", e)}
    out: list[str] = []
    for v in cvars:
        pairs = ([_REAL_PAIRS[v]] if v in _REAL_PAIRS else []) + list(_REAL_POOL)
        pair = next((p for p in pairs if not (set(p) & used) and not (set(p) & set(out))), None)
        pair = pair or (f"{v}_re", f"{v}_im")
        out.extend(pair)
        used |= set(pair)
    return out


def real_equation(text: str) -> str:
    """``lhs = rhs`` as the formula lhs - rhs (a real equation in complex mode); other text unchanged."""
    if text.count("=") == 1 and "==" not in text:
        lhs, rhs = text.split("=")
        return f"{lhs.strip()} - ({rhs.strip()})"
    return text.strip()


def check_key(key: tuple):
    """A formula check, made in a worker thread (sympy may take a moment on a long formula).

    ``("real", text, names, index)``: (message or None, the formula's parameters);
    ``("complex", equations, complex variables, real names, real equations)``: (message or None, the split:
    dict(texts (the real formulas: Re and Im of each equation, then the real equations), labels ({real
    name: "Re w"}), params)) or (message, None)."""
    from gcmh_core.formula import FormulaError, check_component, find_parameters

    if key[0] == "real":
        _, text, names, index = key
        try:
            check_component(text, list(names), index, allow_parameters=True)
            return None, tuple(find_parameters(text, list(names)))
        except Exception as e:  # noqa: BLE001 - FormulaError or any InputError, as the field's message
            return str(e), ()
    from gcmh_core.complex_equations import split_complex

    _, equations, cvars, names, extras = key
    try:
        texts, reals, labels = split_complex(list(equations), list(cvars), list(names), allow_parameters=True)
    except FormulaError as e:
        if e.component is None:
            return e.detail, None
        where = f"equation {e.component + 1}" + (f", column {e.position}" if e.position else "")
        return f"{where}: {e.detail}", None
    except Exception as e:  # noqa: BLE001 - any InputError
        return str(e), None
    first = len(texts)
    texts = texts + [real_equation(t) for t in extras]
    for j in range(len(extras)):
        try:
            check_component(texts[first + j], reals, first + j, allow_parameters=True)
        except FormulaError as e:
            return f"real equation {j + 1}: {e.detail}", None
        except Exception as e:  # noqa: BLE001
            return f"real equation {j + 1}: {e}", None
    try:
        params = tuple(find_parameters(texts, reals))
    except Exception as e:  # noqa: BLE001
        return str(e), None
    return None, {"texts": texts, "labels": labels, "params": params}


def engine_methods() -> tuple[str, ...]:
    """The extraction methods the installed engine supports."""
    try:
        import gcmh_core
        m = getattr(gcmh_core, "METHODS", None)
        if m:
            return tuple(str(x).lower() for x in m)
    except ImportError:
        pass
    return ("gcmh",)


def format_number(v: float) -> str:
    """Short text for a bound: simple multiples of pi as ``-pi/2``, others as ``%g``."""
    v = float(v)
    if v == 0:
        return "0"
    fr = Fraction(v / math.pi).limit_denominator(12)
    if fr != 0 and abs(float(fr) * math.pi - v) < 1e-12 * max(1.0, abs(v)):
        p, q = fr.numerator, fr.denominator
        sign = "-" if p < 0 else ""
        p = abs(p)
        num = "pi" if p == 1 else f"{p}*pi"
        return f"{sign}{num}" if q == 1 else f"{sign}{num}/{q}"
    return f"{v:.10g}"


_error_label = error_label


def _mark(edit: QLineEdit, label: QLabel, message: str | None) -> None:
    edit.setStyleSheet(ERROR_STYLE if message else "")
    edit.setToolTip(message or "")
    label.setText(message or "")
    label.setVisible(bool(message))


class QtFormulaPanel(QWidget):
    """Side panel: n, k, variable names, k formulas, domain table, div, method, seed."""

    validityChanged = Signal(bool)
    changed = Signal()
    estimateChanged = Signal(object)   # dict(cubes, bytes) or None
    checked = Signal()                 # every formula on show has its check's answer

    CHECK_DELAY_MS = 200   # the check starts this long after the last keystroke

    def __init__(self, parent=None):
        super().__init__(parent)
        self._building = False
        self._valid = False
        self.errors: dict[str, str] = {}
        self._auto_names = True
        self.methods = engine_methods()
        # what n or k hid, to bring back: formulas, domain rows (lower, upper, div), names
        self._kept_formulas: list[str] = []
        self._kept_rows: list[tuple[str, str, str]] = []
        self._kept_names: list[str] = []
        # formula checks: answers by (text, names, index), and the keys still waiting for one
        self._answers: dict[tuple, tuple] = {}
        self._waiting: set[tuple] = set()
        self.checker = QtLatestCall(self, "gcmh-formula-check")   # (sympy may take a moment on a long formula)
        self.checker.answered.connect(self._on_checked)
        self._check_timer = QTimer(self)
        self._check_timer.setSingleShot(True)
        self._check_timer.setInterval(self.CHECK_DELAY_MS)
        self._check_timer.timeout.connect(self.check_now)
        # the run's estimate (memory and time), made in a worker
        self.run_estimate = None   # the gcmh_core.budget.Estimate of the panel's job, once known
        self._estimate_key = None
        self._estimator = QtLatestCall(self, "gcmh-estimate")
        self._estimator.answered.connect(self._on_estimate)
        self._estimate_timer = QTimer(self)
        self._estimate_timer.setSingleShot(True)
        self._estimate_timer.setInterval(300)
        self._estimate_timer.timeout.connect(self._ask_estimate)

        lay = panel_layout(self)

        # --- system -------------------------------------------------------
        sys_box, sl = group(lay, "System  F(x) = 0,  F: R^n \u2192 R^k")
        self.complex_check = QCheckBox("complex: equations over C^m")
        self.complex_check.setToolTip("type equations in complex variables (z^2 = w, z = cos(w)); they are split "
                                      "exactly into real and imaginary parts over Re and Im of each variable")
        sl.addWidget(self.complex_check)
        self.complex_box = QWidget()
        cform = QFormLayout(self.complex_box)
        cform.setContentsMargins(0, 0, 0, 0)
        cform.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        self.cvars_edit = QLineEdit()
        self.cvars_edit.setPlaceholderText("e.g. w, z")
        self.cvars_edit.setToolTip("the complex variables, separated by commas; each is two real ones (Re, Im)")
        cform.addRow("complex variables", self.cvars_edit)
        self.cvars_error = _error_label()
        cform.addRow(self.cvars_error)
        self.ceq_edit = QPlainTextEdit()
        self.ceq_edit.setPlaceholderText("one equation a line, e.g.\nz = cos(w)")
        self.ceq_edit.setToolTip("equations lhs = rhs over C^m, one a line (i is the imaginary unit); "
                                 "holomorphic functions only: sin, cos, exp, log, sqrt, powers ...")
        self.ceq_edit.setTabChangesFocus(True)
        self.ceq_edit.setFixedHeight(self.ceq_edit.fontMetrics().lineSpacing() * 3 + 12)
        cform.addRow("equations", self.ceq_edit)
        self.ceq_error = _error_label()
        cform.addRow(self.ceq_error)
        self.creal_edit = QLineEdit()
        self.creal_edit.setPlaceholderText("none (e.g. x^2 + y^2 + u^2 + v^2 = 1)")
        self.creal_edit.setToolTip("real equations over the real variables, separated by ';' (a real condition such "
                                   "as |z|^2 + |w|^2 = 1 is not holomorphic: write it here)")
        cform.addRow("real equations", self.creal_edit)
        self.split_label = QLabel("")
        self.split_label.setWordWrap(True)
        self.split_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        self.split_label.setStyleSheet("color: #555; font-size: 11px;")
        self.split_label.setToolTip("the real system the equations give (split exactly by sympy)")
        cform.addRow(self.split_label)
        sl.addWidget(self.complex_box)
        self.complex_box.setVisible(False)
        self._split: dict | None = None   # the complex check's answer for the equations on show
        self._auto_complex_names = ""      # the real names complex mode made (replaced while not edited)

        row = QHBoxLayout()
        self.n_spin = QSpinBox()
        self.n_spin.setRange(1, N_MAX)
        self.n_spin.setValue(3)
        self.n_spin.setToolTip("n: the dimension of the ambient space")
        self.k_spin = QSpinBox()
        self.k_spin.setRange(1, N_MAX)
        self.k_spin.setValue(1)
        self.k_spin.setToolTip("k: the number of equations (1 <= k < n); the manifold has dimension n - k")
        row.addWidget(QLabel("n"))
        row.addWidget(self.n_spin)
        row.addSpacing(12)
        row.addWidget(QLabel("k"))
        row.addWidget(self.k_spin)
        self.dim_label = QLabel("")
        self.dim_label.setStyleSheet("color: #666;")
        row.addSpacing(12)
        row.addWidget(self.dim_label, 1)
        sl.addLayout(row)
        self.nk_error = _error_label()
        sl.addWidget(self.nk_error)

        form = QFormLayout()
        form.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        self.vars_edit = QLineEdit()
        self.vars_edit.setToolTip("the variable names, separated by commas")
        self.vars_label = QLabel("variables")
        form.addRow(self.vars_label, self.vars_edit)
        sl.addLayout(form)
        self.vars_error = _error_label()
        sl.addWidget(self.vars_error)

        self.formula_box = QWidget()
        self.formula_layout = QVBoxLayout(self.formula_box)
        self.formula_layout.setContentsMargins(0, 0, 0, 0)
        self.formula_layout.setSpacing(2)
        sl.addWidget(self.formula_box)
        self.formula_edits: list[QLineEdit] = []
        self.formula_errors: list[QLabel] = []
        self.formula_labels: list[QLabel] = []
        self._field_params: dict[int, tuple] = {}   # the parameters last found in each formula field
        self.parameters = QtParameterPanel()
        sl.addWidget(self.parameters)

        # --- domain -------------------------------------------------------
        dom_box, dl = group(lay, "Domain and grid")
        self.table = QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels(["lower", "upper", "div"])
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.Stretch)
        self.table.verticalHeader().setDefaultSectionSize(22)
        self.table.setEditTriggers(QAbstractItemView.AllEditTriggers)
        self.table.setToolTip("bounds per axis; constant expressions such as -pi/2 are fine")
        dl.addWidget(self.table)
        self.domain_error = _error_label()
        dl.addWidget(self.domain_error)
        drow = QHBoxLayout()
        drow.addWidget(QLabel("div"))
        self.div_edit = QLineEdit("10")
        self.div_edit.setMaximumWidth(70)
        self.div_edit.setToolTip("grid divisions per axis (one number for all axes)")
        drow.addWidget(self.div_edit)
        self.per_axis = QCheckBox("per axis")
        self.per_axis.setToolTip("set a different div for each axis in the table")
        drow.addWidget(self.per_axis)
        drow.addStretch(1)
        dl.addLayout(drow)
        gform = QFormLayout()
        gform.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        self.periodic_edit = QLineEdit()
        self.periodic_edit.setPlaceholderText("none (e.g. t  s:flip=t)")
        self.periodic_edit.setToolTip(
            "axes whose ends are the same point (angles): 't' glues t's lower and upper bound; "
            "'s:flip=t' glues s's and reverses t across that seam (the Klein bottle, the Moebius band). "
            "F must be invariant under the gluing; a reversed axis needs an even div")
        gform.addRow("glued axes", self.periodic_edit)
        dl.addLayout(gform)
        self.periodic_error = _error_label()
        dl.addWidget(self.periodic_error)
        self.div_error = _error_label()
        dl.addWidget(self.div_error)

        # --- method -------------------------------------------------------
        m_box = QGroupBox("Method")
        ml = QFormLayout(m_box)
        self.method_combo = QComboBox()
        for m in self.methods:
            self.method_combo.addItem(METHOD_LABELS.get(m, m.upper()), m)
        ml.addRow("method", self.method_combo)
        self.start_edit = QLineEdit("")
        self.start_edit.setPlaceholderText("auto")
        self.start_edit.setToolTip("a point on (or near) the manifold, n numbers separated by commas; "
                                   "empty or 'auto': the engine looks for points of M itself")
        self.start_label = QLabel("start point")
        ml.addRow(self.start_label, self.start_edit)
        self.start_error = _error_label()
        ml.addRow(self.start_error)
        self.scheduler_edit = QLineEdit("")
        self.scheduler_edit.setPlaceholderText("this computer")
        self.scheduler_edit.setToolTip("empty: run here; 'local': a Dask cluster of one process per core on this "
                                       "machine; tcp://host:port: a running `dask scheduler` "
                                       "(pip install -e \".[cluster]\")")
        ml.addRow("run on", self.scheduler_edit)
        self.scheduler_error = _error_label()
        ml.addRow(self.scheduler_error)
        self.seed_spin = QSpinBox()
        self.seed_spin.setRange(0, 2**31 - 1)
        self.seed_spin.setToolTip("seed of the grid perturbation: same seed, same result")
        ml.addRow("seed", self.seed_spin)
        self.estimate_label = QLabel("")
        self.estimate_label.setWordWrap(True)
        self.estimate_label.setStyleSheet("color: #555;")
        ml.addRow(self.estimate_label)
        lay.addWidget(m_box)
        lay.addStretch(1)

        # signals
        self.n_spin.valueChanged.connect(self._on_nk)
        self.k_spin.valueChanged.connect(self._on_nk)
        self.vars_edit.textEdited.connect(self._on_vars_edited)
        self.vars_edit.textChanged.connect(self._validate)
        self.table.itemChanged.connect(lambda *_: self._validate())
        self.div_edit.textChanged.connect(self._validate)
        self.periodic_edit.textChanged.connect(self._validate)
        self.per_axis.toggled.connect(self._on_per_axis)
        self.method_combo.currentIndexChanged.connect(self._on_method)
        self.start_edit.textChanged.connect(self._validate)
        self.parameters.changed.connect(self._on_parameters)
        self.complex_check.toggled.connect(self._on_complex)
        self.cvars_edit.textChanged.connect(self._validate)
        self.ceq_edit.textChanged.connect(self._validate)
        self.creal_edit.textChanged.connect(self._validate)
        self.scheduler_edit.textChanged.connect(self._validate)
        self.seed_spin.valueChanged.connect(lambda *_: self.changed.emit())

        self._rebuild(3, 1)
        self._on_method()
        self._on_per_axis(False)
        self._validate()

    # ------------------------------------------------------------ structure
    @property
    def n(self) -> int:
        return self.n_spin.value()

    @property
    def k(self) -> int:
        return self.k_spin.value()

    def variables(self) -> list[str]:
        return inputs.split_names(self.vars_edit.text())

    def _on_vars_edited(self, *_):
        self._auto_names = False

    # ------------------------------------------------------------ complex mode
    def is_complex(self) -> bool:
        return self.complex_check.isChecked()

    def complex_variables(self) -> list[str]:
        return inputs.split_names(self.cvars_edit.text())

    def complex_equations(self) -> list[str]:
        return [" ".join(t.split()) for t in self.ceq_edit.toPlainText().splitlines() if t.strip()]

    def real_equations(self) -> list[str]:
        return [" ".join(t.split()) for t in self.creal_edit.text().split(";") if t.strip()]

    def labels(self) -> dict[str, str]:
        """{real variable: "Re w"} in complex mode ({} otherwise)."""
        if not self.is_complex():
            return {}
        cv, names = self.complex_variables(), self.variables()
        if len(names) != 2 * len(cv):
            return {}
        return {names[2 * j + p]: f"{'Im' if p else 'Re'} {v}" for j, v in enumerate(cv) for p in (0, 1)}

    def _on_complex(self, on: bool) -> None:
        """The user turned complex mode on (a first equation to start from, bounds for C^m) or off (the real
        system of the split stays, to read and edit)."""
        if self._building:
            return
        if on and not self.complex_equations():
            self._building = True
            try:
                self.cvars_edit.setText("z, w")
                self.ceq_edit.setPlainText("z^2 = w")
                self.creal_edit.setText("")
            finally:
                self._building = False
        if on:
            self._auto_complex_names = self.vars_edit.text()   # (the real mode's names give way)
        self._show_mode()
        if on:
            self._sync_complex_shape()
            self._building = True
            try:
                from gcmh_core.complex_equations import DEFAULT_BOUNDS

                for r in range(self.table.rowCount()):
                    self.table.item(r, 0).setText(format_number(DEFAULT_BOUNDS[0]))
                    self.table.item(r, 1).setText(format_number(DEFAULT_BOUNDS[1]))
            finally:
                self._building = False
        self._validate()

    def _show_mode(self) -> None:
        on = self.is_complex()
        self.complex_box.setVisible(on)
        self.formula_box.setVisible(not on)
        self.n_spin.setEnabled(not on)
        self.k_spin.setEnabled(not on)
        self.vars_label.setText("real variables" if on else "variables")
        self.vars_edit.setToolTip("the real variables: Re and Im of each complex variable in turn" if on
                                  else "the variable names, separated by commas")

    def _sync_complex_shape(self) -> None:
        """n = 2m, k = 2 (equations) + (real equations), and default real names (x, y for z; u, v for w) until
        the user types their own."""
        cv = self.complex_variables()
        if not cv:
            return
        n = 2 * len(cv)
        k = max(1, 2 * len(self.complex_equations()) + len(self.real_equations()))
        auto = self.vars_edit.text() in (self._auto_complex_names, "")
        self._building = True
        try:
            if (n, k) != (self.n, self.k) and n <= N_MAX and k <= N_MAX:
                self.n_spin.setValue(n)
                self.k_spin.setValue(k)
                self._building = False
                self._rebuild(n, k)   # (which may rename the variables: named again below)
                self._building = True
            # (textChanged comes before textEdited: whether the names are the user's is read off the text)
            if auto:
                names = ", ".join(default_real_names(cv, self.complex_equations()))
                if names != self.vars_edit.text():
                    self.vars_edit.setText(names)
                self._auto_complex_names = names
        finally:
            self._building = False

    def _apply_split(self, split: dict) -> None:
        """The complex check's answer: its real formulas go into the (hidden) formula fields."""
        self._building = True
        try:
            for e, t in zip(self.formula_edits, split["texts"]):
                if e.text() != t:
                    e.setText(t)
        finally:
            self._building = False
        lines = [f"F{i + 1} = {t}" for i, t in enumerate(split["texts"])]
        self.split_label.setText("real system:\n" + "\n".join(lines))

    def _on_parameters(self) -> None:
        """A value or range changed: the panel's state (sessions, undo) and the run's estimate."""
        if not self._building:
            self.changed.emit()

    def _on_nk(self, *_):
        if self._building:
            return
        self._rebuild(self.n, self.k)
        self._validate()

    def _rebuild(self, n: int, k: int, fresh: bool = False) -> None:
        """Resize the variable list, the formula fields and the table, keeping what was typed (and what an
        earlier n or k hid). ``fresh``: the fields' contents belong to the old system: take only the kept ones."""
        self._building = True
        try:
            names = self.variables()
            if self._auto_names or not names:
                names = inputs.default_variables(n)
            else:
                self._kept_names = names + self._kept_names[len(names):]
                names = (self._kept_names + [f"x{i + 1}" for i in range(len(self._kept_names), n)])[:n]
                # fill in defaults that would clash
                for i in range(len(names)):
                    if names[i] in names[:i]:
                        names[i] = f"x{i + 1}"
            self.vars_edit.setText(", ".join(names))
            # formulas: k fields (k may be invalid, show at least 1 and at most n_max)
            kk = max(1, min(k, N_MAX))
            texts = [] if fresh else [e.text() for e in self.formula_edits]
            texts = self._kept_formulas = texts + self._kept_formulas[len(texts):]
            clear_layout(self.formula_layout)
            self.formula_edits, self.formula_errors, self.formula_labels = [], [], []
            for i in range(kk):
                roww = QWidget()
                rl = QHBoxLayout(roww)
                rl.setContentsMargins(0, 0, 0, 0)
                lab = QLabel(f"F{i + 1} =")
                lab.setMinimumWidth(34)
                ed = QLineEdit(texts[i] if i < len(texts) else "")
                ed.setPlaceholderText("e.g. x1^2 + x2^2 - 1")
                ed.setToolTip(f"component {i + 1} of F; the manifold is where all components vanish")
                ed.textChanged.connect(self._validate)
                rl.addWidget(lab)
                rl.addWidget(ed, 1)
                err = _error_label()
                self.formula_layout.addWidget(roww)
                self.formula_layout.addWidget(err)
                self.formula_edits.append(ed)
                self.formula_errors.append(err)
                self.formula_labels.append(lab)
            # domain table
            old = [] if fresh else [(self._cell(r, 0), self._cell(r, 1), self._cell(r, 2))
                                    for r in range(self.table.rowCount())]
            old = self._kept_rows = old + self._kept_rows[len(old):]
            self.table.setRowCount(n)
            for r in range(n):
                blank = ("-2", "2") if self.is_complex() else ("-1", "1")   # (C^m: complex_equations.DEFAULT_BOUNDS)
                lo, hi, dv = old[r] if r < len(old) else (*blank, self.div_edit.text() or "10")
                for c, t in enumerate((lo, hi, dv)):
                    self.table.setItem(r, c, QTableWidgetItem(t))
            self._update_table_headers()
            h = self.table.verticalHeader().defaultSectionSize() * min(n, 6) + \
                self.table.horizontalHeader().height() + 6
            self.table.setFixedHeight(h)
        finally:
            self._building = False

    def _cell(self, r: int, c: int) -> str:
        it = self.table.item(r, c)
        return it.text() if it is not None else ""

    def _update_table_headers(self) -> None:
        names = self.variables()
        meaning = self.labels()
        labels = [names[r] if r < len(names) else f"x{r + 1}" for r in range(self.table.rowCount())]
        self.table.setVerticalHeaderLabels([f"{nm} = {meaning[nm]}" if nm in meaning else nm for nm in labels])

    def _on_per_axis(self, on: bool) -> None:
        self.table.setColumnHidden(2, not on)
        self.div_edit.setEnabled(not on)
        if on and not self._building:
            err, v = inputs.check_div(self.div_edit.text())
            if v is not None:
                self._building = True
                for r in range(self.table.rowCount()):
                    self.table.item(r, 2).setText(str(v))
                self._building = False
        self._validate()

    def _on_method(self, *_):
        cont = self.continuation()
        self.start_edit.setVisible(cont)
        self.start_label.setVisible(cont)
        self._validate()

    def continuation(self) -> bool:
        """Does the chosen method start from points (GCCH, CCS)?"""
        return self.method() in continuation_methods()

    def method(self) -> str:
        return self.method_combo.currentData() or "gcmh"

    def set_method(self, method: str) -> bool:
        i = self.method_combo.findData(method)
        if i < 0:
            return False
        self.method_combo.setCurrentIndex(i)
        return True

    # ------------------------------------------------------------ validation
    def _validate(self, *_) -> bool:
        if self._building:
            return self._valid
        errs: dict[str, str] = {}
        n, k = self.n, self.k
        m = inputs.check_nk(n, k)
        if m:
            errs["nk"] = m
        self.nk_error.setText(m or "")
        self.nk_error.setVisible(bool(m))
        self.dim_label.setText("" if m else f"{n - k}-dimensional manifold in R^{n}")

        cmsg = None
        if self.is_complex():
            cv = self.complex_variables()
            cmsg = inputs.check_variables(self.cvars_edit.text(), len(cv)) if cv else "name the complex variables"
            _mark(self.cvars_edit, self.cvars_error, cmsg)
            if cmsg:
                errs["complex variables"] = cmsg
            else:
                self._sync_complex_shape()
                n, k = self.n, self.k

        m = inputs.check_variables(self.vars_edit.text(), n)
        _mark(self.vars_edit, self.vars_error, m)
        if m:
            errs["variables"] = m
        else:
            self._update_table_headers()
        names = self.variables()

        wanted: set[tuple] = set()
        found: list[str] = []
        if self.is_complex():
            eqs = self.complex_equations()
            msg = None
            if not eqs:
                msg = "type an equation, e.g. z^2 = w"
            elif not cmsg and "variables" not in errs:
                key = ("complex", tuple(eqs), tuple(self.complex_variables()), tuple(names),
                       tuple(self.real_equations()))
                if key in self._answers:
                    msg, split = self._answers[key]
                    if split is not None:
                        self._split = split
                        self._apply_split(split)
                        found = list(split["params"])
                else:   # not checked yet: keep the mark (and the sliders) until the answer comes
                    wanted.add(key)
                    msg = self.ceq_error.text() if self.ceq_error.isVisible() else None
                    found = self.parameters.names()
            self.ceq_edit.setStyleSheet(ERROR_STYLE.replace("QLineEdit", "QPlainTextEdit") if msg else "")
            self.ceq_error.setText(msg or "")
            self.ceq_error.setVisible(bool(msg))
            if msg:
                errs["equations"] = msg
                self.split_label.setText("")
            for ed, lab in zip(self.formula_edits, self.formula_errors):
                _mark(ed, lab, None)
        else:
            for i, (ed, lab) in enumerate(zip(self.formula_edits, self.formula_errors)):
                msg = None
                if i >= k:
                    msg = None
                elif not ed.text().strip():
                    msg = "empty formula"
                elif "variables" in errs:
                    msg = None
                else:
                    key = ("real", ed.text(), tuple(names), i)
                    if key in self._answers:
                        msg, params = self._answers[key]
                        self._field_params[i] = params
                    else:   # not checked yet: keep the field's mark (and its sliders) until the answer comes
                        wanted.add(key)
                        msg = lab.text() if lab.isVisible() else None
                    if i < k:
                        found.extend(self._field_params.get(i, ()))
                _mark(ed, lab, msg)
                if msg:
                    errs[f"F{i + 1}"] = msg
        self._ask(wanted)
        self._building = True   # (new rows bring their values: one change, emitted below)
        try:
            self.parameters.set_names(found)
        finally:
            self._building = False

        # domain
        dom_msgs = []
        self._building = True
        try:
            for r in range(self.table.rowCount()):
                elo, ehi, _ = inputs.check_bounds(self._cell(r, 0), self._cell(r, 1))
                name = names[r] if r < len(names) else f"x{r + 1}"
                for c, e in ((0, elo), (1, ehi)):
                    it = self.table.item(r, c)
                    if it is not None:
                        it.setBackground(BAD_CELL if e else GOOD_CELL)
                        it.setToolTip(e or "")
                if elo or ehi:
                    if ehi and not elo and "empty interval" in ehi:
                        self.table.item(r, 0).setBackground(BAD_CELL)
                    dom_msgs.append(f"{name}: {elo or ehi}")
                if self.per_axis.isChecked():
                    ed, _v = inputs.check_div(self._cell(r, 2))
                    it = self.table.item(r, 2)
                    if it is not None:
                        it.setBackground(BAD_CELL if ed else GOOD_CELL)
                        it.setToolTip(ed or "")
                    if ed:
                        dom_msgs.append(f"{name}: {ed}")
        finally:
            self._building = False
        msg = "; ".join(dom_msgs[:3]) + (" ..." if len(dom_msgs) > 3 else "")
        self.domain_error.setText(msg)
        self.domain_error.setVisible(bool(msg))
        if msg:
            errs["domain"] = msg

        if not self.per_axis.isChecked():
            m, _ = inputs.check_div(self.div_edit.text())
            _mark(self.div_edit, self.div_error, m)
            if m:
                errs["div"] = m
        else:
            _mark(self.div_edit, self.div_error, None)

        m, _ = inputs.check_periodic(self.periodic_edit.text(), names, self.div_list())
        _mark(self.periodic_edit, self.periodic_error, m)
        if m:
            errs["glued axes"] = m

        if self.continuation():
            m, _ = inputs.check_start(self.start_edit.text(), n)
            _mark(self.start_edit, self.start_error, m)
            if m:
                errs["start"] = m
        else:
            _mark(self.start_edit, self.start_error, None)

        m, _ = check_scheduler(self.scheduler_edit.text())
        _mark(self.scheduler_edit, self.scheduler_error, m)
        if m:
            errs["run on"] = m

        self.errors = errs
        valid = not errs
        self._update_estimate(valid)
        if valid != self._valid:
            self._valid = valid
            self.validityChanged.emit(valid)
        self.changed.emit()
        return valid

    # ------------------------------------------------------------ formula checks, off the GUI thread
    def _ask(self, wanted: set) -> None:
        """Wait for answers on ``wanted`` (what the fields show now); older questions are dropped."""
        if wanted != self._waiting:
            self._waiting = wanted
            if wanted:
                self._check_timer.start()   # (restarted by every keystroke: the debounce)
            else:
                self._check_timer.stop()

    def check_now(self) -> None:
        """Send the formulas waiting for a check to the worker now (Run does not wait for the debounce)."""
        self._check_timer.stop()
        if self._waiting:
            keys = sorted(self._waiting, key=lambda key: key[-1] if key[0] == "real" else -1)
            self.checker.submit([(key, lambda key=key: check_key(key)) for key in keys])

    def checking(self) -> bool:
        """Is a formula on show still waiting for its check?"""
        return bool(self._waiting)

    def _on_checked(self, key, answer, error) -> None:
        """``answer``: :func:`check_key`'s (message, found); ``error``: what a check that broke said."""
        if key not in self._waiting:
            return   # stale: the field changed since
        if len(self._answers) > 512:
            self._answers.clear()
        self._answers[key] = answer if error is None else (error, () if key[0] == "real" else None)
        self._waiting = self._waiting - {key}
        self._validate()
        if not self._waiting:
            self.checked.emit()

    def is_valid(self) -> bool:
        return self._valid

    # ------------------------------------------------------------- values
    def bounds(self) -> list[tuple[float, float]]:
        out = []
        for r in range(self.table.rowCount()):
            _, _, pair = inputs.check_bounds(self._cell(r, 0), self._cell(r, 1))
            if pair is None:
                raise ValueError(f"bad bounds in row {r + 1}")
            out.append(pair)
        return out

    def div(self):
        """An int, or a list of n ints when 'per axis' is on."""
        if self.per_axis.isChecked():
            return [inputs.check_div(self._cell(r, 2))[1] for r in range(self.table.rowCount())]
        return inputs.check_div(self.div_edit.text())[1]

    def div_list(self) -> list[int] | None:
        d = self.div()
        if d is None or (isinstance(d, list) and None in d):
            return None
        return list(d) if isinstance(d, list) else [d] * self.n

    def start(self):
        if not self.continuation():
            return None
        return inputs.check_start(self.start_edit.text(), self.n)[1]

    def formulas(self) -> list[str]:
        return [e.text().strip() for e in self.formula_edits[: self.k]]

    def job(self) -> Job:
        if not self._validate():
            raise ValueError("; ".join(self.errors.values()))
        return self.job_unchecked()

    def estimate(self) -> dict | None:
        d = self.div_list()
        if d is None or inputs.check_nk(self.n, self.k):
            return None
        try:
            import gcmh_core
            fn = gcmh_core.estimate_work
        except (ImportError, AttributeError):
            return None
        try:
            return dict(fn(self.n, self.k, d))
        except Exception:  # noqa: BLE001 - an estimate must never break the panel
            return None

    def _update_estimate(self, valid: bool) -> None:
        if valid and not self.checking():
            job = self.job_unchecked()
            key = repr(job)
            if key != self._estimate_key:
                self._estimate_key, self.run_estimate = key, None
                self._estimate_timer.start()
            elif self.run_estimate is not None:
                return   # shown already
        else:
            self._estimate_key, self.run_estimate = None, None
            self._estimate_timer.stop()
        est = self.estimate()
        if est is None:
            self.estimate_label.setText("")
        else:
            cubes = int(est.get("cubes", 0))
            text = f"work: {cubes:,} cubes, about {inputs.human_bytes(est.get('bytes', 0))} peak memory"
            avail = inputs.available_memory()
            if self.continuation():
                text = f"full grid: {cubes:,} cubes; continuation visits only those M passes through"
                self.estimate_label.setStyleSheet("color: #555;")
            elif avail and est.get("bytes", 0) > 0.8 * avail:
                text += f"  \u2014 more than the {inputs.human_bytes(avail)} available!"
                self.estimate_label.setStyleSheet("color: #c22; font-weight: bold;")
            else:
                self.estimate_label.setStyleSheet("color: #555;")
            self.estimate_label.setText(text)
        self.estimateChanged.emit(est)

    def job_unchecked(self) -> Job:
        """The job of the panel's contents as they stand (call when valid)."""
        return Job(formulas=self.formulas(), variables=self.variables(), bounds=self.bounds(),
                   div=self.div(), method=self.method(), seed=self.seed_spin.value(), start=self.start(),
                   scheduler=check_scheduler(self.scheduler_edit.text())[1], params=self.params() or None,
                   periodic=self.periodic() or None, labels=self.labels() or None,
                   title=", ".join(self.complex_equations()) if self.is_complex() else "")

    def periodic(self) -> list[str]:
        """The glued axes as extract's periodic= list ([] when none or the field is wrong)."""
        return inputs.check_periodic(self.periodic_edit.text(), self.variables(), self.div_list())[1]

    def params(self) -> dict[str, float]:
        """The parameters' values, {name: value} ({} when the formulas have none)."""
        return self.parameters.values()

    def _ask_estimate(self) -> None:
        if self._estimate_key is None or not self._valid:
            return
        job = self.job_unchecked()
        self._estimator.ask(repr(job), lambda: estimate_job(job))

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

    # ------------------------------------------------------------- state
    def state(self) -> dict:
        """The panel as a plain dict: in complex mode, the equations as typed ("complex", "complex_variables";
        "formulas" are the real equations beside them), not their split; "params": {name: {value, min, max}}."""
        d = self._state()
        if self.is_complex():
            d.update(complex=self.complex_equations(), complex_variables=self.complex_variables(),
                     formulas=self.real_equations())
        return d

    def _state(self) -> dict:
        return {
            "n": self.n, "k": self.k, "variables": self.variables(),
            "formulas": [e.text() for e in self.formula_edits[: self.k]],
            "bounds": [[self._cell(r, 0), self._cell(r, 1)] for r in range(self.table.rowCount())],
            "div": ([self._cell(r, 2) for r in range(self.table.rowCount())]
                    if self.per_axis.isChecked() else self.div_edit.text()),
            "method": self.method(), "seed": self.seed_spin.value(),
            "start": self.start_edit.text(),
            "scheduler": self.scheduler_edit.text().strip(),
            "params": self.parameters.state(),
            "periodic": self.periodic_edit.text(),
        }

    def set_state(self, d: dict) -> None:
        """Fill the panel from a dict like :meth:`state` (numbers or texts accepted); with "complex" (equations
        over C^m, as in an example's file), in complex mode."""
        cx_eqs = d.get("complex")
        on = bool(cx_eqs)
        if on:
            cvars = list(d.get("complex_variables") or [])
            extras = [str(t) for t in d.get("formulas") or []]
            n, k = 2 * len(cvars), 2 * len(cx_eqs) + len(extras)
        else:
            n = int(d.get("n", self.n))
            k = int(d.get("k", self.k))
        self._building = True
        try:
            self.complex_check.setChecked(on)
            if on:
                self.cvars_edit.setText(", ".join(cvars))
                self.ceq_edit.setPlainText("\n".join(str(e) for e in cx_eqs))
                self.creal_edit.setText("; ".join(extras))
            self.n_spin.setValue(n)
            self.k_spin.setValue(k)
        finally:
            self._building = False
        self._show_mode()
        defaults = default_real_names(cvars, self.complex_equations()) if on else inputs.default_variables(n)
        variables = d.get("variables") or defaults
        self._auto_names = not on and list(variables) == defaults
        self._auto_complex_names = ", ".join(defaults) if on else ""
        self._building = True   # (no check, no history entry, for the half-filled panel)
        try:
            self.vars_edit.setText(", ".join(variables))
        finally:
            self._building = False
        # a new system: what an earlier one hid does not come back in it
        formulas = [] if on else [str(t) for t in d.get("formulas", [])]   # (complex: the split fills them)
        self._kept_formulas, self._kept_names = list(formulas), list(variables)
        self._kept_rows = []
        self._field_params = {}
        self.split_label.setText("")
        self._rebuild(n, k, fresh=True)
        self._building = True
        try:
            for e, t in zip(self.formula_edits, formulas):
                e.setText(t)
            bounds = d.get("bounds")
            if bounds is not None:
                if len(bounds) == 2 and not isinstance(bounds[0], (list, tuple)):
                    bounds = [bounds] * n
                for r, (lo, hi) in enumerate(list(bounds)[:n]):
                    self.table.item(r, 0).setText(lo if isinstance(lo, str) else format_number(lo))
                    self.table.item(r, 1).setText(hi if isinstance(hi, str) else format_number(hi))
            div = d.get("div", 10)
            if isinstance(div, (list, tuple)):
                vals = [str(v) for v in div]
                if len(set(vals)) == 1:
                    self.per_axis.setChecked(False)
                    self.div_edit.setText(vals[0])
                else:
                    self.per_axis.setChecked(True)
                    for r, v in enumerate(vals[:n]):
                        self.table.item(r, 2).setText(v)
            else:
                self.per_axis.setChecked(False)
                self.div_edit.setText(str(div))
            meth = str(d.get("method", "gcmh")).lower()
            i = self.method_combo.findData(meth)
            self.method_combo.setCurrentIndex(i if i >= 0 else 0)
            self.seed_spin.setValue(int(d.get("seed", 0)))
            start = d.get("start")
            if isinstance(start, (list, tuple)):
                start = ", ".join(format_number(v) for v in start)
            self.start_edit.setText(start or "")
            self.scheduler_edit.setText(str(d.get("scheduler") or ""))
            params = d.get("params") or {}
            if isinstance(params, str):   # (sessions of before the sliders: "a = 0.5, b = pi/4")
                params = inputs.check_params(params, variables)[1]
            self.parameters.set_state(dict(params))
            periodic = d.get("periodic") or ""
            if isinstance(periodic, (list, tuple)):
                periodic = "  ".join(str(p) for p in periodic)
            self.periodic_edit.setText(str(periodic))
        finally:
            self._building = False
        self.table.setColumnHidden(2, not self.per_axis.isChecked())
        self.div_edit.setEnabled(not self.per_axis.isChecked())
        self._on_method()
        self._validate()
