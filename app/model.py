"""StudioModel: the state of GCMH Studio, without Qt (napari's ViewerModel, in small).

What the studio knows lives here, apart from the widgets that show it: the
system of the Manifold tab (formulas, variables, n, k, bounds, div, method,
...), the View tab's projection, slice and style, the result on screen with
its names, title and serial number, the picked cell, the last refinement, the
animation clock and the status line. The window writes the panels' state here
when they change and draws what is here; everything below is plain Python and
numpy, so it is tested without a display (tests/app/test_model.py).

Changes are announced through :class:`Event` callbacks (``model.events.result``,
``.status``, ``.system``, ``.view``, ``.picked``), which the window connects to
its widgets.

:class:`History` keeps the states of the system and the view for Undo / Redo
(``model.history``; the window applies what ``model.undo()`` / ``model.redo()``
return to its panels).
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from .animation import Clock, Spec, frames_for
from .slicing import SliceWindow, window_range

EMPTY_RESULT = ("The result is empty: F has no sign change on this grid. Widen the domain, "
                "raise div, or check the formulas.")


class Event:
    """A callback list: ``connect(fn)``, ``disconnect(fn)``, ``emit(*args)`` calls them in order."""

    def __init__(self) -> None:
        self._callbacks: list[Callable[..., Any]] = []

    def connect(self, callback: Callable[..., Any]) -> Callable[..., Any]:
        self._callbacks.append(callback)
        return callback

    def disconnect(self, callback: Callable[..., Any]) -> None:
        """Remove ``callback`` (ValueError if it is not connected)."""
        self._callbacks.remove(callback)

    def emit(self, *args: Any) -> None:
        for callback in list(self._callbacks):   # (a callback may disconnect itself)
            callback(*args)


def changed_paths(a: Any, b: Any, prefix: str = "") -> frozenset[str]:
    """The places (``"system.formulas.0"``) where two nested dicts/lists differ."""
    if isinstance(a, dict) and isinstance(b, dict):
        out: set[str] = set()
        for key in set(a) | set(b):
            out |= changed_paths(a.get(key), b.get(key), f"{prefix}.{key}" if prefix else str(key))
        return frozenset(out)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)) and len(a) == len(b):
        out = set()
        for i, (x, y) in enumerate(zip(a, b)):
            out |= changed_paths(x, y, f"{prefix}.{i}")
        return frozenset(out)
    return frozenset() if a == b else frozenset({prefix})


class History:
    """Undo / Redo over snapshots (plain dicts: ``{"system": ..., "view": ...}``).

    ``record(state)`` pushes a state that differs from the current one.  A change of
    the same places as the previous change, within ``merge_seconds`` of it, replaces
    that entry instead of adding one: typing a formula or dragging a slider is one
    step to undo, not one per keystroke or pixel.  ``undo()`` / ``redo()`` return the
    state to show (a copy) or None at either end; recording after an undo drops the
    states that could be redone.  ``clock``: seconds (replaced by tests).
    """

    def __init__(self, limit: int = 200, merge_seconds: float = 1.5, clock: Callable[[], float] = time.monotonic):
        self.limit = int(limit)
        self.merge_seconds = float(merge_seconds)
        self.clock = clock
        self._states: list[dict] = []
        self._i = -1
        self._last: tuple[frozenset, float] | None = None   # (places, time) of the last change recorded

    @property
    def current(self) -> dict | None:
        return copy.deepcopy(self._states[self._i]) if self._i >= 0 else None

    def can_undo(self) -> bool:
        return self._i > 0

    def can_redo(self) -> bool:
        return 0 <= self._i < len(self._states) - 1

    def record(self, state: dict) -> bool:
        """Note ``state`` as the current one; False when nothing changed."""
        state = copy.deepcopy(state)
        if self._i < 0:
            self._states, self._i = [state], 0
            return True
        top = self._states[self._i]
        places = changed_paths(top, state)
        if not places:
            return False
        now = self.clock()
        merge = (self._last is not None and self._last[0] == places and now - self._last[1] <= self.merge_seconds
                 and self._i == len(self._states) - 1 and self._i > 0)
        del self._states[self._i + 1:]
        if merge and not changed_paths(self._states[self._i - 1], state):
            # the change undid itself (n 4 -> 3 -> 4): no step left to undo
            self._states.pop()
            self._i -= 1
            self._last = None
            return True
        if merge:
            self._states[self._i] = state
        else:
            self._states.append(state)
            if len(self._states) > self.limit:
                del self._states[0]
            self._i = len(self._states) - 1
        self._last = (places, now)
        return True

    def undo(self) -> dict | None:
        if not self.can_undo():
            return None
        self._i -= 1
        self._last = None
        return self.current

    def redo(self) -> dict | None:
        if not self.can_redo():
            return None
        self._i += 1
        self._last = None
        return self.current

    def sync(self, state: dict) -> None:
        """Replace the current entry by ``state`` (the panels' reading of a state just restored), keeping
        what can be undone and redone."""
        if self._i >= 0:
            self._states[self._i] = copy.deepcopy(state)

    def clear(self) -> None:
        self._states, self._i, self._last = [], -1, None


class StudioEvents:
    """The model's events and what they carry."""

    def __init__(self) -> None:
        self.status = Event()    # (text, error)
        self.system = Event()    # (the system dict)
        self.view = Event()      # (the view dict)
        self.result = Event()    # (the CellComplex now on screen)
        self.picked = Event()    # (the picked cell's facts, or None)
        self.history = Event()   # (can_undo, can_redo)


class StudioModel:
    """The studio's state; see the module docstring."""

    def __init__(self) -> None:
        self.events = StudioEvents()
        self.system: dict = {}          # the Manifold tab: n, k, variables, formulas, bounds, div, method, seed, ...
        self.view: dict = {}            # the View tab: projection (kind, axes, angles, mapping), slice, style
        self.result = None              # the CellComplex on screen
        self.names: list[str] = []      # its variable names
        self.title = ""                 # its title (an example's, or "" for a system typed in)
        self.labels: dict = {}          # what its variables mean, {"u": "Re w"} (a system typed in complex mode)
        self.serial = 0                 # counts the results shown: a refinement belongs to one
        self.job = None                 # the gcmh_studio.jobs.Job of the last run started (refinement evaluates its F)
        self.picked: dict | None = None
        self.last_refinement: dict | None = None   # max |F| at the vertices before and after
        self.status = ""
        self.status_error = False
        self.animation = Clock()
        self._expected: tuple | None = None   # (title, (formulas, variables)) of the system an example filled in
        self._pending_view: dict | None = None
        self.history = History()
        self.recording = True           # False while an undo is applied, or while an animation plays

    # ------------------------------------------------------------ state written by the window
    def set_status(self, text: str, error: bool = False) -> None:
        self.status, self.status_error = text, bool(error)
        self.events.status.emit(text, self.status_error)

    def set_system(self, system: dict) -> None:
        self.system = dict(system)
        self._record()
        self.events.system.emit(self.system)

    def set_view(self, view: dict) -> None:
        self.view = dict(view)
        self._record()
        self.events.view.emit(self.view)

    # ------------------------------------------------------------ undo / redo
    def snapshot(self) -> dict:
        """What Undo restores: the system and the view."""
        return {"system": copy.deepcopy(self.system), "view": copy.deepcopy(self.view)}

    def _record(self) -> None:
        if self.recording and self.history.record(self.snapshot()):
            self.events.history.emit(self.history.can_undo(), self.history.can_redo())

    def undo(self) -> dict | None:
        """Step back: the snapshot to show (the model's system and view are set to it), or None."""
        return self._step(self.history.undo())

    def redo(self) -> dict | None:
        """Step forward again after :meth:`undo`: the snapshot to show, or None."""
        return self._step(self.history.redo())

    def _step(self, state: dict | None) -> dict | None:
        if state is not None:
            self.system, self.view = dict(state["system"]), dict(state["view"])
        self.events.history.emit(self.history.can_undo(), self.history.can_redo())
        return state

    # ------------------------------------------------------------ what the next result is called
    def expect(self, title: str, formulas, variables, view: dict | None = None) -> None:
        """The next result of this system (formulas, variables) gets ``title``; the next result gets ``view``
        (an example's suggested projection and colour), once."""
        self._expected = (title, ([str(f).strip() for f in formulas], list(variables)))
        self._pending_view = dict(view) if view is not None else None

    def title_for(self, formulas, variables) -> str:
        """The expected title if this is the system it was given for, else "" (the user typed another)."""
        if self._expected is None:
            return ""
        title, system = self._expected
        return title if system == (list(formulas), list(variables)) else ""

    def suggest_view(self, view: dict) -> None:
        """The next result gets ``view`` unless an example already suggested one."""
        if self._pending_view is None:
            self._pending_view = dict(view)

    def take_view(self) -> dict | None:
        """The suggested view for the result being shown, once."""
        view, self._pending_view = self._pending_view, None
        return view

    # ------------------------------------------------------------ the result
    def set_result(self, cx, names, title: str = "", labels: dict | None = None) -> int:
        """A new result on screen: returns its serial number; the pick is cleared. ``labels``: what the
        variables mean ({"u": "Re w"}), when the system says (complex mode)."""
        self.result = cx
        self.names = list(names)
        self.title = title
        self.labels = dict(labels or {})
        self.serial += 1
        self.set_picked(None)
        self.events.result.emit(cx)
        return self.serial

    def set_picked(self, info: dict | None) -> None:
        self.picked = info
        self.events.picked.emit(info)

    def set_refinement(self, before: float, after: float) -> None:
        self.last_refinement = dict(before=float(before), after=float(after))

    def summary(self) -> str:
        return summarize(self.result) if self.result is not None else "no result yet"

    def pick_text(self) -> str:
        return pick_text(self.picked, self.names, self.result.dim) if self.picked is not None else ""


# ---------------------------------------------------------------- texts
def summarize(cx) -> str:
    """One status line: counts by dimension, Euler characteristic, boundary, time."""
    names = {0: "vertices", 1: "edges", 2: "faces", 3: "3-cells"}
    counts = cx.counts()
    parts = [f"{c:,} {names.get(r, f'{r}-cells')}" for r, c in enumerate(counts)]
    try:
        chi = cx.euler_characteristic()
    except Exception:  # noqa: BLE001
        chi = "?"
    try:
        nb = len(cx.boundary_facets())
    except Exception:  # noqa: BLE001
        nb = "?"
    secs = cx.meta.get("seconds")
    t = f" \u00b7 {secs:.2f} s" if isinstance(secs, (int, float)) else ""
    t += _warnings(cx.meta)
    bword = "boundary vertices" if cx.dim == 1 else "boundary facets"
    return f"{', '.join(parts)} \u00b7 \u03c7 = {chi} \u00b7 {nb:,} {bword}{t}" if isinstance(nb, int) else \
        f"{', '.join(parts)} \u00b7 \u03c7 = {chi}{t}"


def _warnings(meta: dict) -> str:
    """What the engine could not resolve, as the CLI's summary says it (0 on a trustworthy complex)."""
    out = ""
    left = int(meta.get("non_ball_left", meta.get("non_ball_cells", 0)) or 0)
    if left:
        out += f" \u00b7 warning: {left} cells are not balls (try method cms or another div)"
    degenerate = int(meta.get("degenerate", 0) or 0)
    if degenerate:
        out += f" \u00b7 warning: {degenerate} degenerate events (try another seed)"
    return out


def pick_text(info: dict, names, dim: int, rows_shown: int = 12) -> str:
    """A picked cell as text: what it is, its grid cube, and its vertices' coordinates in R^n."""
    rows = [f"{'':>6}" + "".join(f"{nm:>10}" for nm in names)]
    for v, x in zip(info["vertices"][:rows_shown], info["coords"][:rows_shown]):
        rows.append(f"{v:>6}" + "".join(f"{t:>10.4f}" for t in x))
    if len(info["vertices"]) > rows_shown:
        rows.append(f"\u2026 {len(info['vertices']) - rows_shown} more vertices")
    what = "edge" if dim == 1 else "2-cell"
    cube = "" if info["cube"] is None else f" \u00b7 grid cube {tuple(int(i) for i in info['cube'])}"
    return f"{what} {info['cell']} ({len(info['vertices'])} vertices){cube}\n" + "\n".join(rows)


# ---------------------------------------------------------------- views
def telling_plane(P: np.ndarray) -> tuple[int, int]:
    """A plane whose rotation changes the picture of projection ``P`` (3, n): the last shown axis with
    the first hidden one."""
    n = P.shape[1]
    shown = [i for i in range(n) if np.any(np.abs(P[:, i]) > 1e-9)]
    hidden = [i for i in range(n) if i not in shown]
    if not shown or not hidden:
        return (0, 1) if n >= 2 else (0, 0)
    a, b = shown[-1], hidden[0]
    return (min(a, b), max(a, b))


def slice_params(window: SliceWindow | None, vertices, projection, fractions: tuple[float, float]):
    """(window, direction u, lo, hi, centre c, half-width w) of a slice whose centre and half-width are
    ``fractions`` of the range of ``vertices`` along u; None without a window or vertices."""
    if window is None or vertices is None:
        return None
    u = window.direction(projection.frame())
    lo, hi = window_range(vertices, u)
    cf, wf = fractions
    span = max(hi - lo, 1e-12)
    return window, u, lo, hi, lo + cf * span, wf * span


def animation_frames(mode: str, plane, projection, n_frames: int, slice_prm=None):
    """The frames of the Animate tab's animation from ``projection``'s angles, and the slice window to use
    (with its centre and half-width set) or None.  ``slice_prm``: :func:`slice_params`, or None."""
    window = None
    if slice_prm is not None:
        sw, u, lo, hi, c, w = slice_prm
        window = sw
        window.c, window.w = c, w
    if mode == "rotate":
        spec, rng = Spec("rotate", plane=tuple(plane)), (0.0, 1.0)
    elif mode == "tour":
        spec, rng = Spec("tour"), (0.0, 1.0)
    else:
        if slice_prm is None:
            raise ValueError("a slice sweep needs the slice turned on in the View tab")
        spec, rng = Spec("slice", var=0), (lo, hi)
    return frames_for(spec, projection.angles.copy(), int(n_frames), slice_range=rng), window
