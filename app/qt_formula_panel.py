"""QtFormulaPanel: the system F: R^n -> R^k, its domain grid, the method and seed.

The panel writes what it shows into the :class:`gcmh_studio.model.StudioModel`
(its ``system``, and its ``checks``: whether it can run, the errors, the job) and
shows the model's system when someone else changes it (an example, Undo, a session).

Everything is checked as the user types: a wrong field gets a red mark and a
one-line message under it (the formula parser's own message for formulas), and
the model's checks keep Run disabled. No dialog ever opens for a typo.
Formulas are parsed off the GUI thread (:class:`gcmh_studio.qt_widgets.QtLatestCall`), a
moment after the last keystroke: a long formula never blocks the window. Until its
answer comes, a field keeps its last mark and :meth:`QtFormulaPanel.checking` is True.

Changing n or k hides fields rather than deleting them: formulas, bounds and
names come back as they were when n or k grows again.

Under the method, the run's estimate (:func:`gcmh_studio.jobs.estimate_job`: peak memory
and time, made in a worker a moment after the last change) says before Run what
the run will cost, in red when it won't fit.

Every name in the formulas that is neither a variable nor a constant or function is
a parameter: it gets a row of :class:`gcmh_studio.qt_parameters.QtParameterPanel` (slider,
value, range) under the formulas, found by the same checks; ``stepRequested`` asks to
re-extract as a slider moves.

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

from contextlib import contextmanager

from qtpy.QtCore import Signal
from qtpy.QtWidgets import (
    QWidget,
)

from . import inputs
from .formula_names import VariableNames, hold_typos
from .jobs import Job, engine_methods
from .model import StudioModel
from .qt_complex_box import QtComplexBox, default_real_names
from .qt_domain_box import QtDomainBox, format_number
from .qt_formula_checks import QtFormulaChecks
from .qt_formula_rows import N_MAX, QtFormulaRows
from .qt_method_box import QtMethodBox, work_estimate
from .qt_parameters import QtParameterPanel
from .qt_system_shape import QtSystemShape
from .qt_typo_prompt import QtTypoPrompt
from .qt_widgets import group, panel_layout


class QtFormulaPanel(QWidget):
    """Side panel: n, k, variable names, k formulas, domain table, div, method, seed."""

    changed = Signal()                 # the panel's contents changed (written to the model)
    stepRequested = Signal(bool, str)  # a parameter's slider moved: (held, so a coarse step; the parameter)

    def __init__(self, model: StudioModel | None = None, parent=None):
        super().__init__(parent)
        self.studio = model if model is not None else StudioModel()
        self._building = False
        self._valid = False
        self.errors: dict[str, str] = {}
        self.methods = engine_methods()
        self.variable_names = VariableNames()   # (the defaults until the user types their own)
        self.checks = QtFormulaChecks(self)   # (off the GUI thread: sympy may take a moment on a long formula)
        self.checks.answered.connect(self._validate)

        lay = panel_layout(self)

        # --- system -------------------------------------------------------
        sys_box, sl = group(lay, "System  F(x) = 0,  F: R^n \u2192 R^k")
        self.complex_mode = QtComplexBox()
        sl.addWidget(self.complex_mode)
        cm = self.complex_mode   # (its fields, as the tests know them)
        self.complex_check, self.complex_box, self.split_label = cm.complex_check, cm.complex_box, cm.split_label
        self.cvars_edit, self.ceq_edit, self.creal_edit = cm.cvars_edit, cm.ceq_edit, cm.creal_edit
        self.cvars_error, self.ceq_error = cm.cvars_error, cm.ceq_error
        self._split: dict | None = None   # the complex check's answer for the equations on show

        self.shape = QtSystemShape()
        sl.addWidget(self.shape)
        sh = self.shape   # (its fields, as the tests know them)
        self.n_spin, self.k_spin, self.dim_label, self.nk_error = sh.n_spin, sh.k_spin, sh.dim_label, sh.nk_error
        self.vars_edit, self.vars_label, self.vars_error = sh.vars_edit, sh.vars_label, sh.vars_error
        self.formula_box = QtFormulaRows()
        sl.addWidget(self.formula_box)
        self.typo_prompt = QtTypoPrompt()   # "did you mean y?" before a near-variable name gets a slider
        sl.addWidget(self.typo_prompt)
        self._kept_params: set[str] = set()  # names the user said are parameters (not typos)
        self.parameters = QtParameterPanel()
        sl.addWidget(self.parameters)

        self.domain = QtDomainBox()
        lay.addWidget(self.domain)
        self.method_box = QtMethodBox(self.methods)
        lay.addWidget(self.method_box)
        lay.addStretch(1)
        # the boxes' fields, as the tests know them
        d, mb = self.domain, self.method_box
        self.table, self.domain_error, self.div_edit, self.div_error = d.table, d.domain_error, d.div_edit, d.div_error
        self.per_axis, self.periodic_edit, self.periodic_error = d.per_axis, d.periodic_edit, d.periodic_error
        self.method_combo, self.seed_spin, self.estimate_label = mb.method_combo, mb.seed_spin, mb.estimate_label
        self.start_edit, self.start_label, self.start_error = mb.start_edit, mb.start_label, mb.start_error
        self.scheduler_edit, self.scheduler_error = mb.scheduler_edit, mb.scheduler_error

        # signals
        self.n_spin.valueChanged.connect(self._on_nk)
        self.k_spin.valueChanged.connect(self._on_nk)
        self.vars_edit.textEdited.connect(self.variable_names.typed)
        self.vars_edit.textChanged.connect(self._validate)
        self.domain.edited.connect(self._validate)
        self.method_box.edited.connect(self._validate)
        self.parameters.changed.connect(self._on_parameters)
        self.typo_prompt.replace.connect(lambda name, variable: self.formula_box.replace_name(name, variable, self.k))
        self.typo_prompt.keep.connect(self.keep_parameter)
        self.complex_mode.toggled.connect(self._on_complex)
        self.complex_mode.edited.connect(self._validate)
        self.formula_box.edited.connect(self._validate)
        self.parameters.dragging.connect(lambda name, _v: self.stepRequested.emit(True, name))
        self.parameters.committed.connect(lambda name, _v: self.stepRequested.emit(False, name))
        self.changed.connect(self._write_model)
        ev = self.studio.events
        ev.system.connect(self._show_system)
        ev.check_now.connect(self.check_now)
        ev.notice.connect(self.parameters.set_notice)

        self._rebuild(3, 1)
        self._validate()

    @contextmanager
    def _filling(self):
        """The panel fills its own fields: no check, no history entry, for the half-filled panel (nested: the
        outer filling goes on)."""
        before, self._building = self._building, True
        try:
            yield
        finally:
            self._building = before

    # ------------------------------------------------------------ the model
    def _write_model(self) -> None:
        """The panel's contents as the model's system, and whether (and what) it can run."""
        ready = self._valid and not self.checking()
        self.studio.set_checks(self._valid, self.checking(), self.errors, self.job_unchecked() if ready else None)
        self.studio.set_system(self.state())

    def _show_system(self, d: dict) -> None:
        """The model's system changed (an example, Undo, a session): show it, unless it is what is shown."""
        if d != self.state():
            self.set_state(d)

    # ------------------------------------------------------------ structure
    @property
    def n(self) -> int:
        return self.n_spin.value()

    @property
    def k(self) -> int:
        return self.k_spin.value()

    def variables(self) -> list[str]:
        return inputs.split_names(self.vars_edit.text())

    @property
    def formula_edits(self):
        return self.formula_box.formula_edits

    @property
    def formula_errors(self):
        return self.formula_box.formula_errors

    # ------------------------------------------------------------ complex mode
    def is_complex(self) -> bool:
        return self.complex_mode.is_complex()

    def complex_variables(self) -> list[str]:
        return self.complex_mode.complex_variables()

    def complex_equations(self) -> list[str]:
        return self.complex_mode.complex_equations()

    def real_equations(self) -> list[str]:
        return self.complex_mode.real_equations()

    def labels(self) -> dict[str, str]:
        """{real variable: "Re w"} in complex mode ({} otherwise)."""
        return self.complex_mode.labels(self.variables())

    def _on_complex(self, on: bool) -> None:
        """The user turned complex mode on (a first equation to start from, bounds for C^m) or off (the real
        system of the split stays, to read and edit)."""
        if self._building:
            return
        if on and not self.complex_equations():
            self.complex_mode.set_equations(["z", "w"], ["z^2 = w"], [])
        if on:
            self.variable_names.auto_complex = self.vars_edit.text()   # (the real mode's names give way)
        self._show_mode()
        if on:
            self._sync_complex_shape()
            from gcmh_core.complex_equations import DEFAULT_BOUNDS

            self.domain.set_all_bounds(*DEFAULT_BOUNDS)
        self._validate()

    def _show_mode(self) -> None:
        on = self.is_complex()
        self.complex_box.setVisible(on)
        self.formula_box.setVisible(not on)
        self.shape.show_mode(on)

    def _sync_complex_shape(self) -> None:
        """n = 2m, k = 2 (equations) + (real equations), and default real names (x, y for z; u, v for w) until
        the user types their own."""
        cv = self.complex_variables()
        if not cv:
            return
        n = 2 * len(cv)
        k = max(1, 2 * len(self.complex_equations()) + len(self.real_equations()))
        auto = self.variable_names.complex_own(self.vars_edit.text())
        with self._filling():
            if (n, k) != (self.n, self.k) and n <= N_MAX and k <= N_MAX:
                self.n_spin.setValue(n)
                self.k_spin.setValue(k)
                self._rebuild(n, k)   # (which may rename the variables: named again below)
            # (textChanged comes before textEdited: whether the names are the user's is read off the text)
            if auto:
                names = ", ".join(default_real_names(cv, self.complex_equations()))
                if names != self.vars_edit.text():
                    self.vars_edit.setText(names)
                self.variable_names.auto_complex = names

    def _apply_split(self, split: dict) -> None:
        """The complex check's answer: its real formulas go into the (hidden) formula fields."""
        self.formula_box.set_texts(split["texts"])
        self.complex_mode.show_split(split["texts"])

    def _on_parameters(self) -> None:
        """A value or range changed: the panel's state (sessions, undo) and the run's estimate."""
        if not self._building:
            self.changed.emit()

    def _on_nk(self, *_):
        if self._building:
            return
        self._rebuild(self.n, self.k)
        self._validate()

    def _rebuild(self, n: int, k: int, fresh: bool = False, texts=None) -> None:
        """Resize the variable list, the formula fields and the table, keeping what was typed (and what an
        earlier n or k hid). ``fresh``: a new system: its formulas are ``texts``."""
        with self._filling():
            self.vars_edit.setText(", ".join(self.variable_names.resized(self.variables(), n)))
            self.formula_box.rebuild(k, fresh, texts)
            self.domain.resize_rows(n, fresh, self.is_complex())
            self._update_table_headers()

    def _update_table_headers(self) -> None:
        self.domain.set_headers(self.variables(), self.labels())

    def method(self) -> str:
        return self.method_box.method()

    def set_method(self, method: str) -> bool:
        return self.method_box.set_method(method)

    # ------------------------------------------------------------ validation
    def _validate(self, *_) -> bool:
        if self._building:
            return self._valid
        errs: dict[str, str] = {}
        n, k = self.n, self.k
        m = self.shape.check_nk()
        if m:
            errs["nk"] = m

        cmsg = None
        if self.is_complex():
            cmsg = self.complex_mode.check_variables()
            if cmsg:
                errs["complex variables"] = cmsg
            else:
                self._sync_complex_shape()
                n, k = self.n, self.k

        m = self.shape.check_variables()
        if m:
            errs["variables"] = m
        else:
            self._update_table_headers()
        names = self.variables()

        if self.is_complex():
            more, wanted, found, split = self.complex_mode.check(names, not cmsg and "variables" not in errs,
                                                                 self.checks, self.parameters.names())
            errs.update(more)
            if split is not None:
                self._split = split
                self._apply_split(split)
            self.formula_box.clear_marks()
        else:
            more, wanted, found = self.formula_box.check(k, names, self.checks, "variables" not in errs)
            errs.update(more)
            typo, found = hold_typos(found, names, self._kept_params)   # (Run waits for the prompt's answer)
            self.typo_prompt.ask(*(typo or (None,)))
            if typo:
                errs["typo"] = self.typo_prompt.message()
        self.checks.ask(wanted)
        with self._filling():   # (new rows bring their values: one change, emitted below)
            self.parameters.set_names(found)

        errs.update(self.domain.check(names, n))
        errs.update(self.method_box.check(n))

        self.errors = errs
        valid = not errs
        self._update_estimate(valid)
        self._valid = valid
        self.changed.emit()
        return valid

    def keep_parameter(self, name: str) -> None:
        """``name`` is a parameter, not a typo: it gets its slider."""
        self._kept_params.add(name)
        self._validate()

    # ------------------------------------------------------------ formula checks, off the GUI thread
    def check_now(self) -> None:
        """Send the formulas waiting for a check to the worker now (Run does not wait for the debounce)."""
        self.checks.check_now()

    def checking(self) -> bool:
        """Is a formula on show still waiting for its check?"""
        return self.checks.checking()

    def is_valid(self) -> bool:
        return self._valid

    # ------------------------------------------------------------- values
    def bounds(self) -> list[tuple[float, float]]:
        return self.domain.bounds()

    def div(self):
        """An int, or a list of n ints when 'per axis' is on."""
        return self.domain.div()

    def div_list(self) -> list[int] | None:
        return self.domain.div_list(self.n)

    def formulas(self) -> list[str]:
        return [t.strip() for t in self.formula_box.texts(self.k)]

    def job(self) -> Job:
        if not self._validate():
            raise ValueError("; ".join(self.errors.values()))
        return self.job_unchecked()

    @property
    def run_estimate(self):
        """The gcmh_core.budget.Estimate of the panel's job, once known."""
        return self.method_box.run_estimate

    def _update_estimate(self, valid: bool) -> None:
        self.method_box.show_estimate(self.job_unchecked() if valid and not self.checking() else None,
                                      work_estimate(self.n, self.k, self.div_list()))

    def job_unchecked(self) -> Job:
        """The job of the panel's contents as they stand (call when valid)."""
        mb = self.method_box
        return Job(formulas=self.formulas(), variables=self.variables(), bounds=self.bounds(),
                   div=self.div(), method=self.method(), seed=self.seed_spin.value(), start=mb.start(self.n),
                   scheduler=mb.scheduler(), params=self.params() or None,
                   periodic=self.periodic() or None, labels=self.labels() or None,
                   title=", ".join(self.complex_equations()) if self.is_complex() else "")

    def periodic(self) -> list[str]:
        """The glued axes as extract's periodic= list ([] when none or the field is wrong)."""
        return self.domain.periodic(self.variables(), self.n)

    def params(self) -> dict[str, float]:
        """The parameters' values, {name: value} ({} when the formulas have none)."""
        return self.parameters.values()

    # ------------------------------------------------------------- state
    def state(self) -> dict:
        """The panel as a plain dict: in complex mode, the equations as typed ("complex", "complex_variables";
        "formulas" are the real equations beside them), not their split; "params": {name: {value, min, max}}."""
        d = {"n": self.n, "k": self.k, "variables": self.variables(), "formulas": self.formula_box.texts(self.k),
             **self.domain.state(), **self.method_box.state(), "params": self.parameters.state()}
        if self.is_complex():
            d.update(complex=self.complex_equations(), complex_variables=self.complex_variables(),
                     formulas=self.real_equations())
        return d

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
        with self._filling():
            self.complex_check.setChecked(on)
            if on:
                self.complex_mode.set_equations(cvars, cx_eqs, extras)
            self.n_spin.setValue(n)
            self.k_spin.setValue(k)
        self._show_mode()
        defaults = default_real_names(cvars, self.complex_equations()) if on else inputs.default_variables(n)
        variables = d.get("variables") or defaults
        self.variable_names.reset(variables, defaults, on)   # (a new system: what an earlier one hid stays hidden)
        with self._filling():
            self.vars_edit.setText(", ".join(variables))
        formulas = [] if on else [str(t) for t in d.get("formulas", [])]   # (complex: the split fills them)
        self.complex_mode.show_split([])
        self._rebuild(n, k, fresh=True, texts=formulas)
        with self._filling():
            self.domain.set_state(d, n)
            self.method_box.set_state(d, format_number)
            params = d.get("params") or {}
            if isinstance(params, str):   # (sessions of before the sliders: "a = 0.5, b = pi/4")
                params = inputs.check_params(params, variables)[1]
            self._kept_params.update(params)   # (a file's or a session's parameters are no typos)
            self.parameters.set_state(dict(params))
        self._validate()
