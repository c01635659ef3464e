"""The window's still picture drawn in a process of its own (issue 26, item 8).

A see-through result's still render takes about 0.3 s of software GL, and the GUI cannot tick while VTK draws
on its thread. It was drawn in a thread of the app, which cannot be proven safe: VTK's garbage collector,
object registration and text renderer, Mesa's state and Xlib are shared by every thread that makes, draws or
deletes VTK objects (one ``free(): corrupted unsorted chunks`` in eight runs of the classroom benchmark). So it
is drawn by one long-lived worker process, which has its own VTK, GL context and X connection: a fresh
interpreter (``python -m gcmh_studio.still_process``: a fork of a Qt/X process would share its state; and
multiprocessing's "spawn" runs the parent's main script again in the child, which for a script that opens
a window without a ``__main__`` guard opens a second window). No VTK runs in any thread of the app but
the GUI's: the request is pickled there (:class:`gcmh_studio.offscreen.StillJob`), and two threads of the app
only move bytes (one writes the newest request, one reads the answers). The worker's drawing
(:func:`draw_still`) is here too, importing VTK in the worker only.

The newest request wins: one not yet written when a newer one comes is dropped, and so is one the worker
finds overtaken when it reads it. A worker that dies or hangs fails its requests (the window then draws the
picture itself), is ended, and the next request starts a new one; after ``MAX_FAILURES`` failures in a row
the window draws its still pictures itself for the rest of the session. No Qt here; VTK only in the
worker's functions.
"""

from __future__ import annotations

import os
import pickle
import struct
import subprocess
import sys
import threading
import time
from multiprocessing.connection import Connection
from typing import Any

HANG_S = 20.0        # a request in the worker this long (after its start-up): the worker is ended
START_S = 120.0      # the worker's start-up (importing VTK; the warm-up picture) may take this long
MAX_FAILURES = 3     # failures in a row after which the window draws its still pictures itself
PIPE_BYTES = 1 << 20  # the requests' pipe (Linux's default limit for a pipe's size)
_HEADER = struct.Struct("<q")   # a request: its number, then the pickled job
WORKER_COMMAND = [sys.executable, "-m", "gcmh_studio.still_process"]   # and the two pipes' descriptors


class StillRequest:
    """One picture asked of the worker: ``done()``, then ``image`` ((h, w, 3) uint8) or ``error`` (a line),
    or neither when a newer request overtook it."""

    def __init__(self, number: int, payload: bytes):
        self.number = number
        self.payload = payload
        self.image: Any = None
        self.error: str | None = None
        self.dropped = False
        self.sent_at: float | None = None
        self._finished = threading.Event()

    def done(self) -> bool:
        return self._finished.is_set()

    def wait(self, timeout: float | None = None) -> bool:
        return self._finished.wait(timeout)

    def _finish(self, image=None, error: str | None = None, dropped: bool = False) -> None:
        if self._finished.is_set():
            return
        self.image, self.error, self.dropped = image, error, dropped
        self.payload = b""
        self._finished.set()


class _Link:
    """One worker process and the two threads of the app that talk to it."""

    def __init__(self, command: list[str]):
        requests_out, requests_in = os.pipe()     # (reader end, writer end)
        answers_out, answers_in = os.pipe()
        try:
            self.process = subprocess.Popen([*command, str(requests_out), str(answers_in)],
                                            pass_fds=(requests_out, answers_in), stdin=subprocess.DEVNULL)
        except BaseException:
            for fd in (requests_in, answers_out):
                os.close(fd)
            raise
        finally:   # (the worker's ends: its exit is then an end of file here)
            os.close(requests_out)
            os.close(answers_in)
        try:   # room for a whole request in the pipe (Linux; 64 KB otherwise): the writer seldom waits
            import fcntl

            fcntl.fcntl(requests_in, getattr(fcntl, "F_SETPIPE_SZ", 1031), PIPE_BYTES)
        except (ImportError, OSError):
            pass
        self._requests = Connection(requests_in, readable=False)
        self._answers = Connection(answers_out, writable=False)
        self.started_at = time.monotonic()
        self.ready_at: float | None = None
        self.drew = False      # it answered with a picture
        self.dead = False
        self.why = ""
        self._cond = threading.Condition()
        self._outbox: StillRequest | None = None
        self._writing = False
        self._in_flight: dict[int, StillRequest] = {}
        threading.Thread(target=self._write, name="gcmh-still-write", daemon=True).start()
        threading.Thread(target=self._read, name="gcmh-still-read", daemon=True).start()

    def put(self, request: StillRequest) -> None:
        with self._cond:
            dead, old = self.dead, self._outbox
            if not dead:
                self._outbox = request
                self._cond.notify_all()
        if dead:
            request._finish(error=self.why)
        elif old is not None:
            old._finish(dropped=True)

    def idle(self) -> bool:
        """Every request asked of this link has been written or dropped (the tests wait for it)."""
        with self._cond:
            return self._outbox is None and not self._writing

    def overdue(self, now: float) -> bool:
        """A request has been in the worker longer than ``HANG_S`` (counted from its start-up), or its start-up
        longer than ``START_S``."""
        with self._cond:
            sent = [r.sent_at for r in self._in_flight.values() if r.sent_at is not None]
        if not sent:
            return False
        if self.ready_at is None:
            return now - self.started_at > START_S
        return now - max(min(sent), self.ready_at) > HANG_S

    def _write(self) -> None:
        while True:
            with self._cond:
                while self._outbox is None and not self.dead:
                    self._cond.wait()
                if self.dead:
                    break
                request = self._outbox
                self._outbox = None
                assert request is not None
                request.sent_at = time.monotonic()
                self._in_flight[request.number] = request
                self._writing = True
            try:
                self._requests.send_bytes(_HEADER.pack(request.number) + request.payload)
            except (OSError, ValueError):    # the worker is gone (the reader says why)
                break
            finally:
                with self._cond:
                    self._writing = False
        self._requests.close()

    def _read(self) -> None:
        why = "the still picture's process ended"
        while True:
            try:
                number, status, value = self._answers.recv()
            except (EOFError, OSError):
                break
            except Exception as e:  # noqa: BLE001 - an answer that cannot be read: the worker is not to be trusted
                why = f"the still picture's process answered nonsense ({e})"
                break
            if status == "ready":
                self.ready_at = time.monotonic()
                continue
            with self._cond:
                request = self._in_flight.pop(number, None)
            if request is not None:
                if status == "image":
                    self.drew = True
                    request._finish(image=value)
                elif status == "dropped":
                    request._finish(dropped=True)
                else:
                    request._finish(error=str(value))
        self.end(why)
        self.process.kill()
        self.process.wait()
        self._answers.close()

    def end(self, why: str) -> None:
        """The worker is no longer used: its requests fail (any thread)."""
        with self._cond:
            if self.dead:
                return
            self.dead, self.why = True, why
            failed = list(self._in_flight.values()) + ([self._outbox] if self._outbox is not None else [])
            self._in_flight.clear()
            self._outbox = None
            self._cond.notify_all()
        for request in failed:
            request._finish(error=why)

    def kill(self, why: str) -> None:
        """End a hung worker: its requests fail now; its pipes end with it (the reader reaps it)."""
        self.end(why)
        self.process.kill()


class StillProcess:
    """The app's side of the still picture's worker process (one for the app, started lazily).

    ``command``: how the worker is started (the tests start one that misbehaves).
    ``ask(payload)`` (the GUI thread's) returns a :class:`StillRequest`; ``check()`` (the GUI's poll) ends a
    worker that hangs. ``usable()``: false after ``MAX_FAILURES`` failures in a row."""

    def __init__(self, command: list[str] | None = None):
        self.command = command if command is not None else WORKER_COMMAND
        self._link: _Link | None = None
        self._number = 0
        self.failures = 0        # in a row
        self.starts = 0          # workers started (the tests count restarts)

    def start(self) -> None:
        """Start the worker now if none is running (the window calls this when it opens: a cheap moment), or
        again after it failed (one still starting after ``START_S`` has failed)."""
        link = self._link
        if link is not None and not link.dead and link.ready_at is None \
                and time.monotonic() - link.started_at > START_S:
            link.kill("the still picture's process did not start")
        if link is not None and link.dead:   # (one that drew pictures before it failed starts a new count)
            self.failures = 1 if link.drew else self.failures + 1
            self._link = link = None
        if (link is None or link.dead) and self.usable():
            self._link = _Link(self.command)
            self.starts += 1

    def usable(self) -> bool:
        return self.failures < MAX_FAILURES

    def ask(self, payload: bytes) -> StillRequest:
        """Ask the worker for the picture ``payload`` describes (see :func:`serve`); a newer request drops it."""
        self._number += 1
        request = StillRequest(self._number, payload)
        self.start()
        link = self._link
        if link is None:
            request._finish(error="the still picture's process failed too often")
            return request
        link.put(request)
        return request

    def check(self) -> None:
        """End the worker when a request has hung in it (the GUI's poll calls this)."""
        link = self._link
        if link is not None and not link.dead and link.overdue(time.monotonic()):
            link.kill("the still picture's process hung")

    @property
    def process(self):
        """The worker process now (None before the first); the tests end it."""
        return None if self._link is None else self._link.process

    def ready(self) -> bool:
        link = self._link
        return link is not None and not link.dead and link.ready_at is not None

    def idle(self) -> bool:
        link = self._link
        return link is None or link.dead or link.idle()


_worker: StillProcess | None = None


def still_process() -> StillProcess:
    """The app's worker for still pictures (one for every window)."""
    global _worker
    if _worker is None:
        _worker = StillProcess()
    return _worker


# ------------------------------------------------------------------ the worker process
def serve(requests, answers) -> None:
    """The worker's main loop (its only thread that runs VTK): read requests, draw the newest, answer each
    (``(number, "image", (h, w, 3) uint8)``, ``"dropped"`` or ``"error"``); end when the app's end of the pipe
    closes. The first message is ``(0, "ready", None)``, after a warm-up picture (the first of a process loads
    modules for about a second)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)   # (Ctrl-C is the app's: it ends, and this process with it)
    try:
        warm_up()
    except Exception:  # noqa: BLE001 - the first picture will say
        pass
    try:
        answers.send((0, "ready", None))
        while True:
            _serve_one(requests, answers)
    except (EOFError, OSError):   # the app is gone
        return


def _serve_one(requests, answers) -> None:
    """Read what the app has written (waiting for it), draw the newest, answer each."""
    pending = [requests.recv_bytes()]
    while requests.poll():          # everything already written: only the newest is drawn
        pending.append(requests.recv_bytes())
    for message in pending[:-1]:
        answers.send((_HEADER.unpack_from(message)[0], "dropped", None))
    message = pending[-1]
    number = _HEADER.unpack_from(message)[0]
    try:
        image = draw_still(**pickle.loads(memoryview(message)[_HEADER.size:]))
    except Exception as e:  # noqa: BLE001 - told to the app, which draws the picture itself
        answers.send((number, "error", f"{type(e).__name__}: {e}"))
        return
    answers.send((number, "image", image))


SETTLE_RENDERS = 1          # cheap renders before the picture (see draw_still)


def draw_still(scene, size, camera: dict, anti_aliasing: str | None):
    """The worker's side of a :class:`gcmh_studio.offscreen.StillJob`: the (h, w, 3) uint8 still picture of
    ``scene`` (a :meth:`gcmh_studio.scene.Scene.detached` copy) drawn as the window draws it."""
    import pyvista as pv

    from .sections import SectionScene

    pl = pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
    try:
        window: Any = pl.ren_win           # (an open plotter has its render window)
        window.SetMultiSamples(0)          # as the window: FXAA, no multi-sampling
        sc = SectionScene(pl, anti_aliasing=None)
        if anti_aliasing == "fxaa":    # (as pyvista would, without its 20 ms check for EGL: the window's)
            pl.renderer.SetUseFXAA(True)
            sc.anti_aliasing = "fxaa"
        else:
            sc.set_anti_aliasing(anti_aliasing)
        sc.adopt(scene, scene.style)
        for key, value in camera.items():
            setattr(pl.camera, key, value)
        pl.renderer.ResetCameraClippingRange()
        # first a cheap render, the complex shrunk to a point (its colours mapped, no pixels): the colour bar
        # lays its labels out from what the frame before drew (in a first frame they sit over the bar)
        actor = sc.actor
        if actor is not None:
            actor.SetScale(1e-6, 1e-6, 1e-6)
            for _ in range(SETTLE_RENDERS):
                window.Render()
            actor.SetScale(1.0, 1.0, 1.0)
        window.Render()
        return window_pixels(window)
    finally:
        pl.close()


def window_pixels(ren_win):
    """The (h, w, 3) uint8 picture a render window holds now (no new render)."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

    f = vtkWindowToImageFilter()
    f.SetInput(ren_win)
    f.SetInputBufferTypeToRGB()
    f.ReadFrontBufferOff()
    f.ShouldRerenderOff()
    f.Update()
    out = f.GetOutput()
    w, h, _ = out.GetDimensions()
    return np.ascontiguousarray(vtk_to_numpy(out.GetPointData().GetScalars()).reshape(h, w, 3)[::-1])


def warm_up() -> None:
    """Draw a small off-screen picture (the worker does when it starts): the first one of a process loads
    modules for about a second, which would fall on the first result's picture."""
    import numpy as np
    import pyvista as pv

    from . import sections  # noqa: F401 - (what the first picture needs, loaded now)

    pl = pv.Plotter(off_screen=True, window_size=[160, 120])
    try:
        m = pv.Plane(i_resolution=2, j_resolution=2)
        m.point_data["t"] = np.arange(m.n_points, dtype=float)
        pl.add_mesh(m, scalars="t", scalar_bar_args=dict(title="t", vertical=True))
        pl.add_text("warm", font_size=10)
        window: Any = pl.ren_win
        window.Render()
    finally:
        pl.close()


if __name__ == "__main__":   # python -m gcmh_studio.still_process REQUESTS_FD ANSWERS_FD
    import faulthandler

    faulthandler.enable()    # (a native crash here says where, on the app's stderr)
    serve(Connection(int(sys.argv[1]), writable=False), Connection(int(sys.argv[2]), readable=False))
