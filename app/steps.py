"""Parameter steps (a slider moved), the part that needs no Qt: which grid a step runs on, what it keeps,
and what a class is told at a critical value.  The window (``qt_main_window``) starts and supersedes them.

While a slider is held, a step runs on a coarse grid, aimed so that its computing (extraction, drawing
arrays, topology; before the render, which the grid hardly changes: ~0.1 s in software GL) takes about
COARSE_COMPUTE_SECONDS; when it is let go, the full grid.
"""

from __future__ import annotations

import math

from .inputs import format_value

COARSE_COMPUTE_SECONDS = 0.05
COARSE_MIN_DIV = 6           # never fewer cubes an axis (nor more than the full div)
COARSE_MAX_CUBES = 300_000   # the first coarse grid's size at most (the Klein bottle: about 50 ms on 2 cores)
COARSE_START = 0.5           # a new system's first coarse grid: half the div
COARSE_FLOOR = 0.25          # coarser than a quarter: a picture too rough to follow


def coarse_div(div, factor: float) -> list[int]:
    """The grid of a step while a slider is held: each axis' div times ``factor`` (even, for glued axes
    that reverse another), at least COARSE_MIN_DIV, at most the full div, and at most COARSE_MAX_CUBES cubes."""
    def scaled(d, f):
        return min(d, max(COARSE_MIN_DIV, 2 * int(round(d * f / 2))))

    full = [int(d) for d in div]
    out = [scaled(d, factor) for d in full]
    while math.prod(out) > COARSE_MAX_CUBES:
        smaller = [scaled(d, 0.85) for d in out]
        if smaller == out:
            break
        out = smaller
    return out


def step_key(job) -> tuple:
    """What a parameter step keeps: the system but for its parameters' values and the grid."""
    return (tuple(job.formulas), tuple(job.variables), tuple(map(tuple, job.bounds)), job.method,
            tuple(job.periodic or ()), int(job.seed))


class CoarseAim:
    """The coarse grid's factor for the system being stepped, learnt from the steps' computing times."""

    def __init__(self) -> None:
        self.key: tuple | None = None
        self.factor = COARSE_START

    def div(self, job, full_div) -> list[int]:
        """The coarse grid for ``job`` (a new system starts again at COARSE_START)."""
        key = step_key(job)
        if key != self.key:
            self.key, self.factor = key, COARSE_START
        return coarse_div(full_div, self.factor)

    def learn(self, job, computed: float) -> None:
        """A coarse step of ``job`` took ``computed`` seconds before its render: aim the next one."""
        if step_key(job) != self.key:
            return
        if computed > COARSE_COMPUTE_SECONDS:
            self.factor = max(COARSE_FLOOR, self.factor * 0.85)
        elif computed < 0.4 * COARSE_COMPUTE_SECONDS:
            self.factor = min(COARSE_START, self.factor * 1.15)


def critical_notice(cx, moved: str | None) -> str:
    """The notice of a result at (or very near) a critical value of its parameters, or "".
    ``moved``: the parameter the user moved last (named first)."""
    k = int(cx.meta.get("singular_vertices") or 0)
    params = cx.meta.get("params") or {}
    if not k or not params:
        return ""
    name = moved if moved in params else next(iter(params))
    try:
        chi = cx.euler_characteristic()
    except Exception:  # noqa: BLE001
        chi = "?"
    return (f"{name} = {format_value(params[name])} is a critical value: F's Jacobian loses rank at {k} "
            f"vertices, so M is singular there (a cone point, a pinch) and \u03c7 = {chi} describes the grid's "
            f"picture of a singular set, not a manifold. Move the slider a little to either side to see the "
            "topology on each side.")
