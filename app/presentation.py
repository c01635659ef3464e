"""What presentation mode shows, decided without Qt or VTK: the system on the presenter's card
(:func:`card_key`, read from the :class:`gcmh_studio.model.StudioModel`) and when the bounds axes'
box is framed again (:class:`Reframing`).  The window side is :mod:`gcmh_studio.qt_presentation`,
the drawing in the view :mod:`gcmh_studio.view_decorations`."""

from __future__ import annotations

from .labels import example_for


def card_key(model) -> tuple | None:
    """What the card shows for the result on screen: (formulas, variables, params, complex equations,
    complex variables), the last two None for a system over R; None before a result."""
    job = model.job
    if model.result is None or job is None:
        return None
    ex = example_for(model.title, model.names)
    cplx: tuple = (None, None)
    if ex is not None and ex.complex and ex.complex_variables:
        cplx = (tuple(ex.complex), tuple(ex.complex_variables))
    elif ex is None and model.system.get("complex"):   # typed in complex mode (the card checks the split)
        cplx = (tuple(model.system["complex"]), tuple(model.system.get("complex_variables") or ()))
    params = tuple(sorted((job.params or {}).items()))
    return (tuple(job.formulas), tuple(job.variables), params) + cplx


class Reframing:
    """How the axes' box is framed at the next render (:func:`gcmh_studio.bounds_axes.frame_axes`):
    ``"fit"`` after a new result, base or view size, or the axes just turned on; ``"out"`` after a turn
    of the projection or a move of the slice (it only zooms out when the box has left the picture, so the
    camera does not breathe).  A fit asked for before the render is not weakened by a turn after it."""

    def __init__(self) -> None:
        self.how: str | None = None

    def fit(self) -> None:
        self.how = "fit"

    def turned(self) -> None:
        self.how = self.how or "out"

    def take(self) -> str | None:
        """The framing asked for since the last render, and none until the next ask."""
        how, self.how = self.how, None
        return how
