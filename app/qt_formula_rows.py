"""QtFormulaRows: the Manifold tab's formula fields, F1 = ... to Fk = ..., each with its message.

Changing k hides fields rather than deleting them: their formulas come back as they were when k grows again.
Each field is checked off the GUI thread (:class:`gcmh_studio.qt_formula_checks.QtFormulaChecks`): until its
answer comes it keeps its last mark, and the parameters it found last. ``edited`` says a field changed.
"""

from __future__ import annotations

from qtpy.QtCore import Signal
from qtpy.QtWidgets import QHBoxLayout, QLabel, QLineEdit, QVBoxLayout, QWidget

from .formula_names import replace_name
from .qt_widgets import blocked, clear_layout, error_label, mark

N_MAX = 12   # (the largest n and k)


class QtFormulaRows(QWidget):
    """The k formula fields."""

    edited = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.formula_layout = QVBoxLayout(self)
        self.formula_layout.setContentsMargins(0, 0, 0, 0)
        self.formula_layout.setSpacing(2)
        self.formula_edits: list[QLineEdit] = []
        self.formula_errors: list[QLabel] = []
        self.formula_labels: list[QLabel] = []
        self._kept: list[str] = []                  # what a smaller k hid, to bring back
        self._params: dict[int, tuple] = {}         # the parameters last found in each field

    def texts(self, k: int) -> list[str]:
        return [e.text() for e in self.formula_edits[:k]]

    def rebuild(self, k: int, fresh: bool = False, texts=None) -> None:
        """k fields (at least 1, at most N_MAX), keeping what was typed and what a smaller k hid; ``fresh``: a
        new system, whose fields hold ``texts`` only."""
        if fresh:
            self._kept, self._params = list(texts or []), {}
        typed = [] if fresh else [e.text() for e in self.formula_edits]
        texts = self._kept = typed + self._kept[len(typed):]
        clear_layout(self.formula_layout)
        self.formula_edits, self.formula_errors, self.formula_labels = [], [], []
        for i in range(max(1, min(k, N_MAX))):
            row = QWidget()
            rl = QHBoxLayout(row)
            rl.setContentsMargins(0, 0, 0, 0)
            lab = QLabel(f"F{i + 1} =")
            lab.setMinimumWidth(34)
            ed = QLineEdit(texts[i] if i < len(texts) else "")
            ed.setPlaceholderText("e.g. x1^2 + x2^2 - 1")
            ed.setToolTip(f"component {i + 1} of F; the manifold is where all components vanish")
            ed.textChanged.connect(lambda *_: self.edited.emit())
            rl.addWidget(lab)
            rl.addWidget(ed, 1)
            err = error_label()
            self.formula_layout.addWidget(row)
            self.formula_layout.addWidget(err)
            self.formula_edits.append(ed)
            self.formula_errors.append(err)
            self.formula_labels.append(lab)

    def set_texts(self, texts) -> None:
        """Put ``texts`` in the fields (a complex system's split), without a word."""
        for e, t in zip(self.formula_edits, texts):
            if e.text() != t:
                with blocked(e):
                    e.setText(t)

    def replace_name(self, name: str, variable: str, k: int) -> None:
        """Write ``variable`` for the free name ``name`` in the first k fields (whole names only)."""
        for ed in self.formula_edits[:k]:
            new = replace_name(ed.text(), name, variable)
            if new != ed.text():
                ed.setText(new)

    def clear_marks(self) -> None:
        for ed, lab in zip(self.formula_edits, self.formula_errors):
            mark(ed, lab, None)

    def check(self, k: int, names, checks, names_ok: bool) -> tuple[dict, set, list]:
        """Mark the first k fields from the checks' answers: (errors by field, the keys still to check, the
        parameters found)."""
        errs: dict[str, str] = {}
        wanted: set[tuple] = set()
        found: list[str] = []
        for i, (ed, lab) in enumerate(zip(self.formula_edits, self.formula_errors)):
            msg = None
            if i < k and not ed.text().strip():
                msg = "empty formula"
            elif i < k and names_ok:
                key = ("real", ed.text(), tuple(names), i)
                if checks.has(key):
                    msg, self._params[i] = checks.answer(key)
                else:   # not checked yet: keep the field's mark (and its sliders) until the answer comes
                    wanted.add(key)
                    msg = lab.text() if lab.isVisible() else None
                found.extend(self._params.get(i, ()))
            mark(ed, lab, msg)
            if msg:
                errs[f"F{i + 1}"] = msg
        return errs, wanted, found
