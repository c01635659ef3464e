"""QtFormulaChecks: the Manifold tab's formulas checked off the GUI thread, a moment after the last keystroke.

A long formula never blocks the window: :func:`check_key` (sympy) runs in a worker
(:class:`gcmh_studio.qt_widgets.QtLatestCall`: only the newest texts are checked). The panel asks for the keys
its fields show now (:meth:`QtFormulaChecks.ask`); until their answers come, :meth:`QtFormulaChecks.checking`
is True, and ``answered`` says when one came.
"""

from __future__ import annotations

from qtpy.QtCore import QObject, QTimer, Signal

from .qt_widgets import QtLatestCall

CHECK_DELAY_MS = 200   # the check starts this long after the last keystroke


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


class QtFormulaChecks(QObject):
    """Answers by key (:func:`check_key`'s keys), and the keys the panel still waits for."""

    answered = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self._answers: dict[tuple, tuple] = {}
        self._waiting: set[tuple] = set()
        self._calls = QtLatestCall(self, "gcmh-formula-check")
        self._calls.answered.connect(self._on_checked)
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(CHECK_DELAY_MS)
        self._timer.timeout.connect(self.check_now)

    def has(self, key: tuple) -> bool:
        return key in self._answers

    def answer(self, key: tuple) -> tuple:
        return self._answers[key]

    def ask(self, wanted: set) -> None:
        """Wait for answers on ``wanted`` (what the fields show now); older questions are dropped."""
        if wanted != self._waiting:
            self._waiting = wanted
            if wanted:
                self._timer.start()   # (restarted by every keystroke: the debounce)
            else:
                self._timer.stop()

    def check_now(self) -> None:
        """Send the keys waiting to the worker now (Run does not wait for the debounce)."""
        self._timer.stop()
        if self._waiting:
            keys = sorted(self._waiting, key=lambda key: key[-1] if key[0] == "real" else -1)
            self._calls.submit([(key, lambda key=key: check_key(key)) for key in keys])

    def checking(self) -> bool:
        return bool(self._waiting)

    def _on_checked(self, key, answer, error) -> None:
        """``answer``: :func:`check_key`'s (message, found); ``error``: what a check that broke said."""
        if key not in self._waiting:
            return   # stale: the field changed since
        if len(self._answers) > 512:
            self._answers.clear()
        self._answers[key] = answer if error is None else (error, () if key[0] == "real" else None)
        self._waiting = self._waiting - {key}
        self.answered.emit()

