"""LivePlay: the Animate tab's live play, without Qt.

The Animate tab's clock ticks (:meth:`LivePlay.tick`) and each tick moves the model: its angles (a plane
turning, or a tour), its slice (a sweep across the window), or a parameter of the system on show: ``sweep``
is told (parameter, value, final) and the parameter's input sets it, a coarse step while the sweep plays
and the full one when it stops. The frames are not steps to undo: the history records where the play
stopped. :class:`gcmh_studio.controller.StudioController` owns one; an animation exported to a file takes
its frames from :meth:`LivePlay.animation_frames`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from .animation import PARAM_PERIOD
from .model import StudioModel, animation_frames, slice_params


class LivePlay:
    """The live play of ``model``'s animation; ``sweep(parameter, value, final)`` asks for a parameter's step."""

    def __init__(self, model: StudioModel, sweep: Callable[[str, float, bool], Any]):
        self.model = model
        self._ask_step = sweep
        self.playing = False                               # (its frames are not steps to undo)
        self._sweeping: tuple[str, float] | None = None    # a playing parameter sweep's last value

    def play(self, on: bool) -> tuple[bool, str]:
        """The animation starts (``on``) or stops: (may it play, what to say in the Animate tab)."""
        m = self.model
        m.clock.start(m.projection.angles)
        if not on:
            if self.playing:   # its end is a step to undo (not its frames)
                self.playing, m.recording = False, True
                if self._sweeping is not None:   # at rest: the full grid at the value reached
                    name, value = self._sweeping
                    self._sweeping = None
                    self._ask_step(name, value, True)
                m.record()
            return False, ""
        if m.animation.mode == "slice" and not m.slice.on:
            return False, "Turn the slice on in the View tab first."
        if m.result is None:
            return False, "Nothing to animate yet: run first."
        if m.animation.mode == "slice":   # start the sweep where the slider is
            m.clock.start(m.projection.angles, slice_centre=m.slice.c)
        if m.animation.mode == "param":
            sweep = self._sweep()
            if sweep is None:
                return False, "A parameter sweep needs a run of a system with parameters: run first."
            name, lo, hi, value = sweep   # start where the parameter is (within the sweep's range)
            m.clock.start(m.projection.angles, slice_centre=min(max((value - lo) / (hi - lo), 0.0), 1.0))
        self.playing, m.recording = True, False
        return True, ("Both axes of this plane are hidden: turning it moves nothing on screen. "
                      "Pick a plane with a shown axis." if self.still_plane() else "")

    def still_plane(self) -> bool:
        """The plane to rotate shows nothing turning (both its axes hidden in an orthographic view)."""
        m = self.model
        plane = m.animation.plane
        return (m.animation.mode == "rotate" and plane is not None and m.projection.mapping == "orthographic"
                and bool(np.allclose(m.projection.matrix()[:, list(plane)], 0.0)))

    def tick(self, dt: float) -> None:
        """Advance the playing animation by ``dt`` seconds (times the speed), in place."""
        m = self.model
        if m.result is None:
            return
        mode, clock = m.animation.mode, m.clock
        if mode == "rotate":
            plane = m.animation.plane
            if plane is not None:
                row = m.projection.planes.index((plane[0], plane[1]))
                m.set_angles(clock.rotate_step(m.projection.angles, row, dt))
        elif mode == "tour":
            m.set_angles(clock.tour_step(dt))
        elif mode == "slice":
            m.set_slice(c=min(max(clock.sweep_step(dt), 0.0), 1.0))
        elif mode == "param":
            sweep = self._sweep()
            if sweep is not None:   # there and back, eased as the slice sweep; each value a coarse step
                name, lo, hi, _ = sweep
                value = lo + (hi - lo) * min(max(clock.sweep_step(dt, PARAM_PERIOD), 0.0), 1.0)
                self._sweeping = (name, value)
                self._ask_step(name, value, False)

    def _sweep(self) -> tuple[str, float, float, float] | None:
        """(parameter, from, to, its value now) of the Animate tab's sweep, or None: no parameter of the
        system on show to sweep, or an empty range."""
        m = self.model
        sweep = m.animation.sweep
        params = (m.system.get("params") or {}) if m.job is not None else {}
        if sweep is None or sweep[0] not in params or sweep[1] == sweep[2]:
            return None
        name, lo, hi = sweep
        return name, float(lo), float(hi), float(params[name].get("value", lo))

    def animation_frames(self, n_frames: int, projection=None):
        """Frames of the Animate tab's animation (from the current view) and the slice window to use."""
        m = self.model
        projection = projection or m.projection
        vertices = None if m.result is None else m.result.vertices
        prm = slice_params(m.slice.window(), vertices, projection, (m.slice.c, m.slice.w))
        return animation_frames(m.animation.mode, m.animation.plane, projection, n_frames, prm)
