"""Picking: which cell of a drawn complex is at a pixel, and at which pixel a cell is drawn.  No Qt here.

The drawn mesh carries the complex's cell of each drawn cell as the cell array ``cell_id`` (a slice or a
polygon's triangles draw one cell of the complex as several)."""

from __future__ import annotations

import numpy as np


def cell_at(renderer, actor, mesh, display_xy) -> int | None:
    """The complex's cell drawn by ``actor`` (its ``mesh``) at pixel ``display_xy`` (x, y from bottom left)."""
    from vtkmodules.vtkRenderingCore import vtkCellPicker

    picker = vtkCellPicker()
    picker.SetTolerance(0.002)
    picker.PickFromListOn()
    picker.AddPickList(actor)
    if not picker.Pick(float(display_xy[0]), float(display_xy[1]), 0.0, renderer):
        return None
    cid = picker.GetCellId()
    if cid < 0:
        return None
    return int(mesh.cell_data["cell_id"][cid])


def display_position(renderer, mesh, cell_id: int) -> tuple[float, float] | None:
    """Pixel (x, y from bottom left) of the middle of the complex's cell ``cell_id`` drawn in ``mesh``, or None."""
    rows = np.flatnonzero(mesh.cell_data["cell_id"] == int(cell_id))
    if len(rows) == 0:
        return None
    cell = mesh.get_cell(int(rows[0]))
    p = np.asarray(cell.points, dtype=float).mean(axis=0)
    renderer.SetWorldPoint(p[0], p[1], p[2], 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return float(x), float(y)
