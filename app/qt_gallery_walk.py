"""QtGalleryWalk: the gallery's examples one after another, as a presenter's remote steps through them.

Each example is opened and run by the window's own ``load_example``, as the gallery opens them; a run under
way is cancelled first and the example opened once it has stopped (the window's ``runFinished``).
"""

from __future__ import annotations

import functools

from qtpy.QtCore import QObject, QTimer

from .labels import example_for


@functools.lru_cache(maxsize=1)
def _examples():
    from gcmh_core.examples import list_examples

    return tuple(list_examples())


def example_names() -> list[str]:
    """The examples in the gallery's order (the gallery shows :func:`gcmh_core.examples.list_examples`)."""
    try:
        return [ex.name for ex in _examples()]
    except Exception:  # noqa: BLE001 - a broken examples folder: nothing to walk through
        return []


class QtGalleryWalk(QObject):
    """Steps through the gallery in ``window``; ``caption(text, error=False)`` says what is happening
    (called with "" when there is nothing to say)."""

    def __init__(self, window, caption, parent=None):
        super().__init__(parent)
        self.window = window
        self.caption = caption
        self.current: str | None = None      # the example last opened by stepping
        self._pending: str | None = None     # the example to open when the cancelled run has ended

    def pending(self) -> bool:
        return self._pending is not None

    def current_index(self) -> int | None:
        """The position in the gallery of the example on screen (or being opened), else None."""
        names = example_names()
        for name in (self._pending, self.current):
            if name in names:
                return names.index(name)
        ex = example_for(self.window.model.title, self.window.result_names)
        return names.index(ex.name) if ex is not None and ex.name in names else None

    def step(self, step: int, say: bool = True) -> str | None:
        """Open and run the example ``step`` places on in the gallery (round the ends); returns its name.
        ``say``: caption it ("3/12 · Hyperboloid: computing…")."""
        names = example_names()
        if not names:
            return None
        i = self.current_index()
        i = (0 if step > 0 else len(names) - 1) if i is None else (i + step) % len(names)
        name = names[i]
        self._pending = name
        title = next((ex.title for ex in _examples() if ex.name == name), name)
        self.caption(f"{i + 1}/{len(names)} \u00b7 {title}: computing\u2026" if say else "")
        if self.window.is_running():
            self.window.cancel()              # its runFinished opens the pending example
            if self.window.is_running():
                return name
        self.open_pending()
        return name

    def open_pending(self) -> None:
        name, self._pending = self._pending, None
        if name is None:
            return
        self.current = name
        if not self.window.load_example(name):
            self.caption(self.window.last_status or f"cannot open {name}", error=True)

    def run_finished(self) -> bool:
        """A run has ended: the example waiting for it opens next (True), else nothing to do here (False)."""
        if self._pending is None:
            return False
        QTimer.singleShot(0, self.open_pending)
        return True
