"""StudioModel: the state of GCMH Studio, without Qt (napari's ViewerModel, in small).

What the studio knows lives here, apart from the widgets that show it: the
system of the Manifold tab (formulas, variables, n, k, bounds, div, method,
seed, parameters, ...) and whether it can run, the View tab's projection,
style, angle switches and slice, the Animate tab's settings, the result on screen with its
names, title and serial number, the picked cell, the last refinement and the
status line. Panels write here what the user changes and redraw when the model
announces a change (whoever made it: the user, Undo, an example, a session);
the 3D view draws what is here. Everything below is plain Python and numpy, so
it is tested without a display (tests/app/test_model.py).

Changes are announced by the psygnal signals of ``model.events``
(:class:`StudioEvents`); each has a listener in the app.

:class:`History` keeps the states of the system and the view for Undo / Redo
(``model.history``; :class:`gcmh_studio.controller.StudioController` steps through it).
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from psygnal import Signal, SignalGroup

from .animation import Clock, Spec, frames_for
from .inputs import default_variables
from .jobs import Job
from .projection import MAPPINGS, ProjectionModel, default_axes, turned_angles, varying_colour
from .slicing import SliceWindow, window_range

EMPTY_RESULT = ("The result is empty: F has no sign change on this grid. Widen the domain, "
                "raise div, or check the formulas.")


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


class StudioEvents(SignalGroup):
    """The model's signals, what they carry and who listens."""

    status = Signal(str, bool)      # (text, error): the window's status line
    system = Signal(dict)           # the Manifold tab's state: the formula panel (shows it), the Animate tab (its
    #                                 parameters)
    checks = Signal()               # whether the system can run changed: the window's Run button, the controller
    check_now = Signal()            # Run waits for the formula checks: the formula panel sends them at once
    notice = Signal(str)            # what a result says of a critical value of its parameters (for each result):
    #                                 the parameter sliders, the Topology tab
    projection = Signal()           # angles, base or mapping: the 3D view, the View tab's sliders
    base = Signal()                 # a new base (kind, axes, seed, or a new projection): the 3D view refits, the
    #                                 View tab orders its rows
    style = Signal()                # colour, opacity, edges, overlays, two sides, keep camera: the 3D view, the View
    #                                 and Topology tabs' switches
    slice = Signal()                # the slice window: the 3D view, the View tab's slice box
    angle_view = Signal()           # angles as circles, the glued seam: the 3D view (a refit), the View tab's switches
    slice_readout = Signal(str)     # what the 3D view says of the slice: the View tab's slice box
    result = Signal(object)         # the CellComplex now on screen: the window's summary
    picked = Signal(object)         # the picked cell's facts, or None: the window's pick line
    history = Signal(bool, bool)    # (can_undo, can_redo): the Edit menu


@dataclass
class ViewStyle:
    """How the result is drawn (the View tab's Style box; the overlays are also in the Topology tab)."""

    color_by: str | None = None   # a variable's name, or None: one colour
    opacity: float = 1.0
    show_edges: bool = False
    two_sided: bool = False       # front and back of an oriented surface in two colours
    boundary: bool = False        # the boundary facets highlighted
    grid: bool = False            # the grid cubes M passes through
    keep_camera: bool = False     # no refitting when results, mappings and slices change the extent


@dataclass
class AngleView:
    """The View tab's angle switches (:mod:`gcmh_studio.angles`): periodic axes drawn as circles, the glued
    seam shown. Apart from :class:`ViewStyle`: a switch changes the extent (a refit), not the colours."""

    circles: bool = False
    seam: bool = False


@dataclass
class SliceState:
    """The slice window: coordinate ``index`` (or, with ``hidden``, the view's hidden direction ``index``),
    centre ``c`` and half-width ``w`` as fractions of the direction's range over the complex."""

    on: bool = False
    index: int = 0
    hidden: bool = False
    c: float = 0.5
    w: float = 0.04

    def window(self) -> SliceWindow | None:
        return SliceWindow(int(self.index), bool(self.hidden)) if self.on else None

    def label(self, names) -> str:
        return SliceWindow(int(self.index), bool(self.hidden)).label(names)


@dataclass
class AnimationSettings:
    """The Animate tab's choice: ``mode`` (rotate, tour, slice, param), the ``plane`` turned, frames and
    frames per second of an export, the parameter sweep (name, from, to), the ``--animate`` text and the
    formulas' parameters."""

    mode: str = "rotate"
    plane: tuple[int, int] | None = None
    frames: int = 72
    fps: float = 20.0
    sweep: tuple[str, float, float] | None = None
    spec: str = "rotate"
    params: tuple[str, ...] = ()


@dataclass
class Checks:
    """Whether the system on show can run: ``valid``, the ``errors`` of its fields, ``checking`` (a formula's
    check still under way) and ``job``, the gcmh_studio.jobs.Job it makes (None unless valid and checked)."""

    valid: bool = False
    checking: bool = False
    errors: dict = field(default_factory=dict)
    job: Any = None


class StudioModel:
    """The studio's state; see the module docstring."""

    def __init__(self) -> None:
        self.events = StudioEvents()
        self.system: dict = {}          # the Manifold tab: n, k, variables, formulas, bounds, div, method, seed, ...
        self.checks = Checks()
        self.projection = ProjectionModel(n=3)
        self.view_names: list[str] = default_variables(3)   # the names of the projection's variables
        self.style = ViewStyle()
        self.slice = SliceState()
        self.angle_view = AngleView()
        self.slice_readout = ""
        self.drag_hidden = 0            # the hidden direction a Shift-drag on the view turns against
        self.animation = AnimationSettings()
        self.clock = Clock()            # where a playing animation is
        self.result: Any = None         # the CellComplex on screen
        self.names: list[str] = []      # its variable names
        self.title = ""                 # its title (an example's, or "" for a system typed in)
        self.labels: dict = {}          # what its variables mean, {"u": "Re w"} (a system typed in complex mode)
        self.serial = 0                 # counts the results shown: a refinement belongs to one
        self.job: Job | None = None     # the Job of the last run started (refinement evaluates its F)
        self.picked: dict | None = None
        self.last_refinement: dict | None = None   # max |F| at the vertices before and after
        self.notice = ""
        self.status = ""
        self.status_error = False
        self._expected: tuple | None = None   # (title, (formulas, variables)) of the system an example filled in
        self._pending_view: dict | None = None
        self.history = History()
        self.recording = True           # False while an undo is applied, or while an animation plays

    # ------------------------------------------------------------ the system
    def set_status(self, text: str, error: bool = False) -> None:
        self.status, self.status_error = text, bool(error)
        self.events.status.emit(text, self.status_error)

    def set_system(self, system: dict) -> None:
        """The Manifold tab's state (a step to undo); announced when it changed."""
        system = copy.deepcopy(dict(system))
        changed = system != self.system
        self.system = system
        self.record()
        if changed:
            self.events.system.emit(copy.deepcopy(self.system))

    def set_checks(self, valid: bool, checking: bool, errors: dict, job=None) -> None:
        """Whether the system on show can run (see :class:`Checks`); announced when it changed."""
        new = Checks(bool(valid), bool(checking), dict(errors), job if valid else None)
        old = self.checks
        if (new.valid, new.checking, new.errors, repr(new.job)) != (old.valid, old.checking, old.errors,
                                                                    repr(old.job)):
            self.checks = new
            self.events.checks.emit()

    def set_notice(self, text: str) -> None:
        """What the result on show says of a critical value ("" for none); said for every result."""
        self.notice = text
        self.events.notice.emit(text)

    # ------------------------------------------------------------ the view
    def set_view_variables(self, names, keep: bool = True, vertices=None) -> None:
        """A projection for the variables ``names`` (of a result with ``vertices``, for the principal axes);
        with ``keep``, the kind, seed, angles, mapping, colour and slice stay where they still make sense (a
        new system is coloured by its last coordinate)."""
        names = list(names)
        n, old = len(names), self.projection
        same = keep and old.n == n
        p = ProjectionModel(n=n, kind=old.kind if keep else "coordinates",
                            axes=tuple(old.axes) if same else default_axes(n), seed=old.seed,
                            angles=old.angles if same else None)  # type: ignore[arg-type]  # (None: zeros)
        p.mapping = old.mapping if (keep and n >= 4) else "orthographic"
        p.distance = old.distance
        if vertices is not None:
            p.set_vertices(vertices)
        color = self.style.color_by
        if color not in names and not keep and names:
            # the last coordinate that varies on the result (a torus in R^10 is 0 in its last ones)
            color = varying_colour(names, vertices) if vertices is not None else names[-1]
        self.view_names = names
        recording, self.recording = self.recording, False
        try:
            self.set_style(color_by=color if color in names else None)
            if not same:
                self.set_slice(on=False, index=max(0, n - 1), hidden=False)
            self.set_projection(p)
        finally:
            self.recording = recording
        self.record()

    def set_style_defaults(self, dim: int) -> None:
        """Opaque surfaces and curves; see-through 2-skeletons with edges above."""
        self.set_style(opacity=1.0 if dim <= 2 else 0.35, show_edges=dim >= 3)

    def apply_view(self, view: dict) -> None:
        """An example's suggested view: project=[3 names], color=name, mapping=orthographic|perspective|..."""
        p, names = self.projection, self.view_names
        axes = view.get("project")
        base = False
        if axes and all(a in names for a in list(axes)[:3]):
            p.kind, p.axes, base = "coordinates", tuple(names.index(a) for a in list(axes)[:3]), True
        if "color" in view:
            color = view.get("color")
            self.set_style(color_by=color if color in names else None)
        mapping = view.get("mapping")
        if mapping in MAPPINGS and (mapping == "orthographic" or p.n >= 4):
            p.mapping = mapping
        self.projection_changed(base=base)

    def set_projection(self, projection: ProjectionModel) -> None:
        """Another projection (new variables, a restored view): a new base."""
        self.projection = projection
        self.record()
        self.events.base.emit()
        self.events.projection.emit()

    def projection_changed(self, base: bool = False) -> None:
        """The projection was edited in place (angles, mapping; with ``base``, kind, axes or seed)."""
        self.record()
        if base:
            self.events.base.emit()
        self.events.projection.emit()

    def set_angles(self, degrees) -> None:
        self.projection.angles[:] = np.asarray(degrees, dtype=float)
        self.projection_changed()

    def turn(self, right, up, hidden: int, dx: float, dy: float) -> None:
        """Turn the screen's direction ``right`` by ``dx`` degrees and ``up`` by ``dy`` against hidden direction
        ``hidden`` (modulo the n - 3 there are): one projection update."""
        p = self.projection
        if p.n < 4 or (dx == 0 and dy == 0):
            return
        hidden = hidden % (p.n - 3)
        a = p.angles.copy()
        if dx:
            p.angles[:] = turned_angles(p, np.asarray(right, float), hidden, dx)
        if dy:
            p.angles[:] = turned_angles(p, np.asarray(up, float), hidden, dy)
        new = p.angles.copy()
        p.angles[:] = a
        self.set_angles(new)

    def set_style(self, **changes) -> None:
        """Change the fields of :class:`ViewStyle` named; announced when one changed."""
        self._change("style", changes)

    def set_slice(self, **changes) -> None:
        """Change the fields of :class:`SliceState` named; announced when one changed."""
        self._change("slice", changes)

    def set_angle_view(self, **changes) -> None:
        """Change the fields of :class:`AngleView` named; announced when one changed."""
        self._change("angle_view", changes)

    def _change(self, name: str, changes: dict) -> None:
        new = replace(getattr(self, name), **changes)
        if new != getattr(self, name):
            setattr(self, name, new)
            self.record()
            getattr(self.events, name).emit()

    def set_slice_readout(self, text: str) -> None:
        if text != self.slice_readout:
            self.slice_readout = text
            self.events.slice_readout.emit(text)

    def view_state(self) -> dict:
        """The View tab as a plain dict (what sessions and Undo keep)."""
        d = self.projection.to_dict(self.view_names)
        st = self.style
        d.update(color=st.color_by, opacity=st.opacity, show_edges=st.show_edges, two_sided=st.two_sided,
                 boundary=st.boundary, grid=st.grid, angles_as_circles=self.angle_view.circles,
                 show_seam=self.angle_view.seam)
        if self.slice.on:
            d["slice"] = {"along": self.slice.label(self.view_names), "c": self.slice.c, "w": self.slice.w}
        return d

    def set_view_state(self, d: dict) -> None:
        """Show a dict like :meth:`view_state` (the projection's variables must be set first)."""
        n = self.projection.n
        ok = len(d.get("angles", [0] * (n * (n - 1) // 2))) == n * (n - 1) // 2
        m = ProjectionModel.from_dict(n, d) if ok else ProjectionModel(n=n)
        m.share_principal(self.projection)
        if n < 4:
            m.mapping = "orthographic"
        names = self.view_names
        color = d.get("color")
        opacity = d.get("opacity")
        recording, self.recording = self.recording, False   # (one step, recorded at the end)
        try:
            self.set_style(color_by=color if color in names else None,
                           opacity=self.style.opacity if opacity is None else float(opacity),
                           show_edges=bool(d.get("show_edges", False)), two_sided=bool(d.get("two_sided", False)),
                           boundary=bool(d.get("boundary", False)), grid=bool(d.get("grid", False)))
            # (a session saved before the angle switches were kept has them off)
            self.set_angle_view(circles=bool(d.get("angles_as_circles", False)),
                                seam=bool(d.get("show_seam", False)))
            sl = d.get("slice") or {}
            where = slice_target(sl.get("along", ""), names, n) if sl else None
            if where is None:
                self.set_slice(on=False)
            else:
                self.set_slice(on=True, index=where[0], hidden=where[1], c=float(sl.get("c", 0.5)),
                               w=float(sl.get("w", 0.04)))
            self.set_projection(m)
        finally:
            self.recording = recording
        self.record()

    # ------------------------------------------------------------ undo / redo
    def snapshot(self) -> dict:
        """What Undo restores: the system and the view."""
        return {"system": copy.deepcopy(self.system), "view": self.view_state()}

    def record(self) -> None:
        """Note the state as a step to undo (unless ``recording`` is off)."""
        if self.recording and self.history.record(self.snapshot()):
            self.events.history.emit(self.history.can_undo(), self.history.can_redo())

    def undo(self) -> dict | None:
        """Step back to the last state that changes something on show: that state, or None at the start."""
        return self._step(self.history.undo)

    def redo(self) -> dict | None:
        """Step forward again after :meth:`undo`: the state shown, or None when nothing was undone."""
        return self._step(self.history.redo)

    def _step(self, step) -> dict | None:
        """Step through the history until something on show changes (a view of another result's variables
        changes nothing here, and is passed over)."""
        while True:
            state = step()
            if state is None or self.restore(state):
                self.events.history.emit(self.history.can_undo(), self.history.can_redo())
                return state

    def restore(self, state: dict) -> bool:
        """Show ``state`` (a History entry): its system, and its view if it belongs to the variables on
        show; False if nothing changed. Not a step to undo; the history keeps the panels' reading of it."""
        changed = False
        recording, self.recording = self.recording, False
        try:
            if state.get("system") and state["system"] != self.system:
                self.set_system(state["system"])
                changed = True
            view, current = state.get("view"), self.view_state()
            if view and view != current and view.get("planes") == current.get("planes"):
                self.set_view_state(view)
                changed = True
        finally:
            self.recording = recording
        if changed:
            self.history.sync(self.snapshot())
        return changed

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

    def present(self, cx, names, title: str = "", labels: dict | None = None, view: dict | None = None,
                keep_view: bool = False) -> bool:
        """A new result on screen with the view it gets: kept as it is (``keep_view``: the same system at other
        parameters), else set up for its variables (a new dimension gets its default style, an example its
        suggested ``view``). Returns whether the view was kept."""
        names = list(names)
        keep = keep_view and self.result is not None and names == self.names
        prev_dim, prev_names = (self.result.dim if self.result is not None else None), self.names
        self.set_result(cx, names, title, labels)
        if not keep:
            self.set_view_variables(names, keep=(names == prev_names), vertices=cx.vertices)
            if prev_dim is None or (prev_dim <= 2) != (cx.dim <= 2):
                self.set_style_defaults(cx.dim)
            if view:
                self.apply_view(view)
        return keep

    def set_picked(self, info: dict | None) -> None:
        self.picked = info
        self.events.picked.emit(info)

    def set_refinement(self, before: float, after: float) -> None:
        self.last_refinement = dict(before=float(before), after=float(after))

    def summary(self) -> str:
        return summarize(self.result) if self.result is not None else "no result yet"

    def pick_text(self) -> str:
        if self.picked is None or self.result is None:
            return ""
        return pick_text(self.picked, self.names, self.result.dim)


def slice_target(label: str, names, n: int) -> tuple[int, bool] | None:
    """(index, hidden) of a slice's direction named ``label`` (a variable, or "hidden direction j"), or None."""
    if label in names:
        return list(names).index(label), False
    for j in range(max(0, n - 3)):
        if label == f"hidden direction {j + 1}":
            return j, True
    return None


# ---------------------------------------------------------------- texts
def summarize(cx) -> str:
    """One status line: counts by dimension, Euler characteristic, boundary, time."""
    names = {0: "vertices", 1: "edges", 2: "faces", 3: "3-cells"}
    counts = cx.counts()
    parts = [f"{c:,} {names.get(r, f'{r}-cells')}" for r, c in enumerate(counts)]
    chi: int | str
    nb: int | str
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
    t += _warnings(cx.meta, cx.n)
    bword = "boundary vertices" if cx.dim == 1 else "boundary facets"
    return f"{', '.join(parts)} \u00b7 \u03c7 = {chi} \u00b7 {nb:,} {bword}{t}" if isinstance(nb, int) else \
        f"{', '.join(parts)} \u00b7 \u03c7 = {chi}{t}"


def _warnings(meta: dict, n: int) -> str:
    """What the engine could not resolve, as the CLI's summary says it (0 on a trustworthy complex)."""
    out = ""
    left = int(meta.get("non_ball_left", meta.get("non_ball_cells", 0)) or 0)
    if left:
        # (the simplicial baselines stop at n = 7)
        how = "a finer div" if n > 7 else "method cms or a finer div"
        out += f" \u00b7 warning: {left} {'cell is not a ball' if left == 1 else 'cells are not balls'} (try {how})"
    # (n >= 8: only the cells' boundaries are checked by default; or the check was turned off)
    if meta.get("topology_unchecked"):
        out += f" \u00b7 warning: topology not fully checked ({meta['topology_unchecked']})"
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
