"""LatestCall: "the newest request wins" for work done off the GUI thread, without Qt.

A panel asks questions faster than a worker answers them (a formula checked at
every keystroke, a run's estimate at every change, a still image of the view at
every turn of a slider). Only the newest question matters: a question waiting
when a newer one comes is dropped, never queued, and a batch under way stops
before its next call. One daemon thread at a time does the work; it ends when
nothing is left to do, so an idle panel holds no thread.

Answers are given by calling ``answer(key, value, error)`` *in the worker
thread*: a Qt user relays them to the GUI thread with a queued signal
(:class:`gcmh_studio.qt_widgets.QtLatestCall`). Every call that ran is answered;
the receiver compares ``key`` with what it still wants.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Hashable, Iterable
from typing import Any

Answer = Callable[[Hashable, Any, "str | None"], None]


class LatestCall:
    """Calls functions in a worker thread, only the newest batch of them.

    ``submit([(key, fn), ...])`` replaces the batch waiting (if any) and calls each ``fn()`` in turn;
    ``ask(key, fn)`` is a batch of one. ``answer(key, value, error)`` follows each call: ``error`` is the
    exception's one-line message (``value`` None) when ``fn`` raised. An ``answer`` that raises
    RuntimeError (its receiver is gone) ends the thread.
    """

    def __init__(self, answer: Answer, name: str = "gcmh-latest-call") -> None:
        self._answer = answer
        self._name = name
        self._lock = threading.Lock()
        self._next: list[tuple[Hashable, Callable[[], Any]]] | None = None
        self._busy = False

    def ask(self, key: Hashable, fn: Callable[[], Any]) -> None:
        """Answer ``fn()`` as ``key``, dropping any question not yet started."""
        self.submit([(key, fn)])

    def submit(self, calls: Iterable[tuple[Hashable, Callable[[], Any]]]) -> None:
        """Replace the batch waiting by ``calls``; the batch under way stops before its next call."""
        with self._lock:
            self._next = list(calls)
            if self._busy:
                return
            self._busy = True
        threading.Thread(target=self._loop, name=self._name, daemon=True).start()

    def busy(self) -> bool:
        """Is a batch waiting or under way?"""
        with self._lock:
            return self._busy

    def _loop(self) -> None:
        while True:
            with self._lock:
                batch, self._next = self._next, None
                if batch is None:
                    self._busy = False
                    return
            for key, fn in batch:
                with self._lock:
                    if self._next is not None:   # a newer batch came: this one is stale
                        break
                value, error = None, None
                try:
                    value = fn()
                except Exception as e:  # noqa: BLE001 - InputError and the like, as a message
                    error = str(e) or type(e).__name__
                try:
                    self._answer(key, value, error)
                except RuntimeError:   # the receiver is gone
                    with self._lock:
                        self._busy, self._next = False, None
                    return
