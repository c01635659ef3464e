"""Pictures drawn off the GUI thread: one at a time, the newest wins, and every other render waits for it.

VTK's text rendering is one unguarded singleton, so a picture drawn in a thread
(:class:`gcmh_studio.offscreen.StillJob`, the warm-up) must not overlap any other
render: they are drawn one after another by one :class:`gcmh_studio.latest.LatestCall`
(a picture still waiting when a newer one is asked for is dropped, never drawn: the view
has moved on), and every :class:`gcmh_studio.scene.Scene` waits for the newest before it
renders (a ``StartEvent`` observer calling :func:`wait_background`). No Qt, no VTK here.
"""

from __future__ import annotations

import atexit
import threading
from collections.abc import Callable

from .latest import LatestCall

_tls = threading.local()
_lock = threading.Lock()
_waiting: list[Picture] = []      # asked for and not begun, oldest first: all but the newest will be dropped
_newest: Picture | None = None
_latest: LatestCall | None = None


class Picture:
    """A picture asked of the background: ``draw()`` runs in its thread, or ``drop()`` there when a newer
    picture was asked for before this one began; ``finished`` is set after either."""

    def __init__(self, draw: Callable[[], None], drop: Callable[[], None] | None = None):
        self._draw, self._drop = draw, drop
        self.finished = threading.Event()

    def done(self) -> bool:
        return self.finished.is_set()

    def _run(self) -> None:
        _tls.worker = True
        with _lock:   # the pictures asked for before this one that never began were dropped
            i = _waiting.index(self)
            dropped, _waiting[: i + 1] = _waiting[:i], []
        for p in dropped:
            p._end(p._drop)
        self._end(self._draw)

    def _end(self, what: Callable[[], None] | None) -> None:
        try:
            if what is not None:
                what()
        finally:
            self.finished.set()


def wait_background() -> None:
    """Block until the newest picture asked of the background is drawn (a no-op on its thread)."""
    picture = _newest
    if picture is not None and not getattr(_tls, "worker", False):
        picture.finished.wait()


def started() -> bool:
    """A picture has been asked of the background in this process."""
    return _newest is not None


def draw_in_background(draw: Callable[[], None], drop: Callable[[], None] | None = None) -> Picture:
    """Draw a picture in the background thread (``draw()``) once the one under way is done, unless a newer
    one is asked for first (then ``drop()`` runs there instead). Call it from one thread (the GUI's)."""
    global _newest, _latest
    if _latest is None:   # a picture still drawing when Python exits would draw into a finalised VTK
        _latest = LatestCall(lambda key, value, error: None, name="gcmh-background-picture")
        atexit.register(wait_background)
    picture = Picture(draw, drop)
    with _lock:
        _waiting.append(picture)
    _newest = picture
    _latest.ask(id(picture), picture._run)
    return picture
