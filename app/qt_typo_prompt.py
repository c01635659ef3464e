"""QtTypoPrompt: "yy is not a variable: did you mean y?" under the formulas, before a typo becomes a parameter.

A free name in a formula becomes a parameter with a slider. When that name is one edit away from a
variable (:func:`gcmh_studio.formula_names.did_you_mean`) it is more likely a typo: the panel holds it
back (no slider, Run disabled) and this prompt asks. "Use y" writes y in the formulas; "Keep yy as a
parameter" lets it become one (the answer is kept for the name)."""

from __future__ import annotations

from qtpy.QtCore import Signal
from qtpy.QtWidgets import QHBoxLayout, QLabel, QPushButton, QWidget


class QtTypoPrompt(QWidget):
    """Asks about one name at a time: :meth:`ask` (name, suggestion) or :meth:`ask` (None) to hide."""

    replace = Signal(str, str)   # (the name, the variable to write instead)
    keep = Signal(str)           # the name is a parameter after all

    def __init__(self, parent=None):
        super().__init__(parent)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        self.label = QLabel("")
        self.label.setWordWrap(True)
        self.label.setStyleSheet("color: #b35c00;")
        lay.addWidget(self.label, 1)
        self.use_button = QPushButton("")
        self.keep_button = QPushButton("")
        lay.addWidget(self.use_button)
        lay.addWidget(self.keep_button)
        self.name: str | None = None
        self.suggestion: str | None = None
        self.use_button.clicked.connect(lambda: self.name and self.replace.emit(self.name, self.suggestion))
        self.keep_button.clicked.connect(lambda: self.name and self.keep.emit(self.name))
        self.hide()

    def ask(self, name: str | None, suggestion: str | None = None) -> None:
        self.name, self.suggestion = name, suggestion
        if name is None:
            self.hide()
            return
        self.label.setText(f"\u201c{name}\u201d is not a variable: did you mean {suggestion}?")
        self.use_button.setText(f"Use {suggestion}")
        self.use_button.setToolTip(f"write {suggestion} for {name} in the formulas")
        self.keep_button.setText("Keep as parameter")
        self.keep_button.setToolTip(f"{name} is a parameter: give it a slider")
        self.show()

    def message(self) -> str:
        return self.label.text() if self.name is not None else ""
