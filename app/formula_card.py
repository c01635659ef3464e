"""The presenter's card: the system typeset (:mod:`gcmh_studio.typeset`) as a VTK 2D actor in the bottom
right corner of a picture, or as plain text when no image can be made.  No Qt here."""

from __future__ import annotations

import numpy as np

from .typeset import typeset_system

FORMULA_LINES_PER_HEIGHT = 27        # the formula's font: the view's height / this, in pixels
FORMULA_MAX = (0.62, 0.3)            # the card's largest share of the view (width, height)
BELOW_BAR = 0.165                    # with a colour bar (from 0.2 of the height up): the card stays under it
MARGIN = 16                          # pixels between the card and the view's edge


def image_actor(rgba: np.ndarray):
    """A VTK 2D actor drawing an (h, w, 4) uint8 RGBA image at a pixel position (alpha-blended)."""
    # (vtkmodules, not ``import vtk``: that loads every VTK module, 1.3 s on the GUI thread)
    from vtkmodules.util import numpy_support
    from vtkmodules.util.vtkConstants import VTK_UNSIGNED_CHAR
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkRenderingCore import vtkActor2D, vtkImageMapper

    h, w = rgba.shape[:2]
    data = vtkImageData()
    data.SetDimensions(w, h, 1)
    flat = np.ascontiguousarray(rgba[::-1].reshape(-1, 4))      # VTK's rows go up
    arr = numpy_support.numpy_to_vtk(flat, deep=True, array_type=VTK_UNSIGNED_CHAR)
    arr.SetNumberOfComponents(4)
    data.GetPointData().SetScalars(arr)
    mapper = vtkImageMapper()
    mapper.SetInputData(data)
    mapper.SetColorWindow(255.0)
    mapper.SetColorLevel(127.5)
    actor = vtkActor2D()
    actor.SetMapper(mapper)
    actor.image_size = (w, h)  # type: ignore[attr-defined]  # (the card's size, for placing it)
    return actor


def text_card(lines, font_size: int):
    """The card as plain text (when no image can be made): a VTK text actor, right-justified."""
    from vtkmodules.vtkRenderingCore import vtkTextActor

    actor = vtkTextActor()
    actor.SetInput("\n".join(lines))
    prop = actor.GetTextProperty()
    prop.SetFontSize(font_size)
    prop.SetJustificationToRight()
    prop.SetVerticalJustificationToBottom()
    prop.SetColor(0.96, 0.97, 0.99)
    prop.SetBackgroundColor(0.05, 0.06, 0.09)
    prop.SetBackgroundOpacity(0.72)
    return actor


def card_actor(key: tuple, size: tuple[int, int], colour_bar: bool = True):
    """The card of ``key`` = (formulas, variables, params, complex equations, complex variables) as a 2D
    actor placed for a picture of ``size`` (w, h): the typeset image, or plain text when the image cannot
    be made; None for an empty key. ``colour_bar``: the picture has one (the card stays under it)."""
    formulas, variables, params, cplx, cvars = key
    vw, vh = size
    share = BELOW_BAR if colour_bar else FORMULA_MAX[1]
    try:
        image, _lines = typeset_system(list(formulas), list(variables), dict(params), cplx, cvars,
                                       font_px=max(14.0, vh / FORMULA_LINES_PER_HEIGHT),
                                       max_size=(int(FORMULA_MAX[0] * vw), int(share * vh) - MARGIN))
        actor = image_actor(image) if image is not None else None
    except Exception:  # noqa: BLE001 - no matplotlib, or no image: the formulas as text
        actor = text_card([f"{f} = 0" for f in formulas] + [f"{p} = {v:g}" for p, v in params],
                          max(12, int(vh / (1.3 * FORMULA_LINES_PER_HEIGHT))))
    if actor is not None:
        place_card(actor, vw)
    return actor


def place_card(actor, view_width: int) -> None:
    """The card in the bottom right corner of a picture ``view_width`` pixels wide."""
    size = getattr(actor, "image_size", None)
    if size is None:   # the plain-text card: right-justified at the corner
        actor.SetPosition(view_width - MARGIN, MARGIN)
    else:
        actor.SetPosition(max(MARGIN, view_width - size[0] - MARGIN), MARGIN)
