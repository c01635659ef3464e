"""One off-screen picture drawn in a thread at a time, and every other render waits for it.

VTK's text rendering is one unguarded singleton, so a picture drawn in a thread
(:class:`gcmh_studio.offscreen.StillJob`, the warm-up) must not overlap any other
render: each runs after the one before it, and every :class:`gcmh_studio.scene.Scene`
waits for the one under way before it renders (a ``StartEvent`` observer calling
:func:`wait_background`). No Qt, no VTK here.
"""

from __future__ import annotations

import atexit
import threading
from collections.abc import Callable

_tls = threading.local()
_current: threading.Thread | None = None     # the last picture thread started


def wait_background() -> None:
    """Block until the picture drawing in the background (if any) is done (a no-op on such a thread)."""
    thread = _current
    if thread is not None and not getattr(_tls, "worker", False):
        thread.join()


def started() -> bool:
    """A picture has been drawn (or is drawing) in the background in this process."""
    return _current is not None


def draw_in_background(target: Callable[[], None], name: str) -> threading.Thread:
    """Run ``target()`` in a daemon thread once the picture before it (if any) is done; returns the thread."""
    global _current
    previous = _current

    def run() -> None:
        _tls.worker = True
        if previous is not None:
            previous.join()
        target()

    if previous is None:   # a picture still drawing when Python exits would draw into a finalised VTK
        atexit.register(wait_background)
    thread = threading.Thread(target=run, name=name, daemon=True)
    _current = thread
    thread.start()
    return thread
