"""Bounds axes with ticks around the drawn object, titled with the projection's axes ("y = Im z", or a
mixture such as "0.71 x + 0.71 w"), their ticks in the projected coordinates; and framing the camera on
their box.  No Qt here."""

from __future__ import annotations

import numpy as np

from .camera import screen_coordinates

AXES_FONT = 13                       # the bounds axes' labels (points; times the presentation's font scale)
# where the axes' box may lie (-1..1 across the picture, as gcmh_studio.camera.screen_coordinates): clear of the
# colour bar (right), the title (top) and the card (bottom right), with room for the tick labels outside it
AXES_X, AXES_TOP, AXES_BOTTOM = 0.70, 0.66, 0.56


def axis_titles(scene) -> list[str]:
    """The screen axes' titles: the projection's label of each ("s", "0.71 x + 0.71 w") with what a
    plain variable means ("y = Im z"), and the mapping when it is not orthographic."""
    titles = []
    for label in scene.axes_labels():
        titles.append(scene.style.label(label) if label in scene.names else label)
    mapping = getattr(scene.view, "mapping", "orthographic")
    if mapping != "orthographic":
        titles = [f"{t} ({mapping})" if t else t for t in titles]
    return titles


def add_axes(plotter, key: tuple):
    """pyvista's bounds axes on ``plotter`` for ``key`` = (bounds, titles, shown ranges, font size, label
    counts), remembered on the actor as ``_gcmh_key``."""
    bounds, titles, ranges, font, counts = key
    actor = plotter.show_bounds(bounds=bounds, axes_ranges=ranges, xtitle=titles[0], ytitle=titles[1],
                                ztitle=titles[2], location="outer", ticks="outside", font_size=font,
                                color="#e6e9f0", bold=False, n_xlabels=counts[0], n_ylabels=counts[1],
                                n_zlabels=counts[2], fmt="{0:.2g}", use_3d_text=False, render=False)
    actor._gcmh_key = key
    return actor


def axis_offsets(scene) -> np.ndarray:
    """(3,): what each screen axis adds back to the drawn coordinates, which are centred on the
    object's middle (``P (x - c)``, :mod:`gcmh_studio.projection`): the ticks show ``P x``."""
    try:
        return np.asarray(scene.view.P, dtype=float) @ np.asarray(scene.projector.center, dtype=float)
    except Exception:  # noqa: BLE001 - no projection yet
        return np.zeros(3)


def update_axes(plotter, scene, font_scale: float = 1.0) -> None:
    """The bounds axes of ``scene``'s mesh on ``plotter``: drawn, or their bounds, ranges and titles changed
    in place when only those changed."""
    pl = plotter
    mesh = scene.mesh
    if mesh is None:
        return
    bounds = tuple(float(b) for b in mesh.bounds)
    titles = tuple(axis_titles(scene))
    shown = np.reshape(bounds, (3, 2)) + axis_offsets(scene)[:, None]
    # the ends to a thousandth of the side: float32 noise makes no "-8.2e-06" tick where 0 is meant
    q = 10.0 ** (np.floor(np.log10(np.maximum(np.ptp(shown, axis=1, keepdims=True), 1e-300))) - 3)
    shown = np.round(shown / q) * q + 0.0
    ranges = tuple(float(r) for r in shown.ravel())
    font = int(round(AXES_FONT * font_scale))
    # a short side gets three labels (five would overlap there)
    sides = np.diff(np.reshape(bounds, (3, 2)), axis=1).ravel()
    counts = tuple(5 if r >= 0.5 * sides.max() else 3 for r in sides)
    actor = getattr(pl.renderer, "cube_axes_actor", None)
    key = getattr(actor, "_gcmh_key", None)
    if actor is not None and key is not None and key[3:] == (font, counts):
        if key[:3] != (bounds, titles, ranges):
            actor.bounds = bounds
            actor.x_axis_range, actor.y_axis_range, actor.z_axis_range = ranges[0:2], ranges[2:4], ranges[4:6]
            actor.SetXTitle(titles[0])
            actor.SetYTitle(titles[1])
            actor.SetZTitle(titles[2])
            actor._gcmh_key = (bounds, titles, ranges, font, counts)
        return
    add_axes(pl, (bounds, titles, ranges, font, counts))


def frame_axes(plotter, how: str, size: tuple[int, int]) -> None:
    """Frame the axes' box on ``plotter`` (a picture of ``size`` (w, h)), not only the object (the camera
    frames the object's points; the box's corners reach further): ``"fit"`` centres the box and zooms it to
    the picture's free part; ``"out"`` only zooms out when the box has left it (a turn of the projection),
    so the camera does not breathe while a projection turns."""
    pl = plotter
    actor = getattr(pl.renderer, "cube_axes_actor", None)
    if actor is None:
        return
    b = actor.GetBounds()
    corners = np.array([[x, y, z] for x in b[0:2] for y in b[2:4] for z in b[4:6]], dtype=float)
    if how == "fit":
        pl.renderer.ResetCamera(b)          # centred on the box, the direction kept
    for _ in range(3 if how == "fit" else 1):   # pan and zoom (under perspective, again to settle)
        S = screen_coordinates(pl, corners)
        if not np.all(np.isfinite(S)):
            break
        lo, hi = S.min(axis=0), S.max(axis=0)
        if how == "fit":
            f = max((hi[0] - lo[0]) / (2 * AXES_X), (hi[1] - lo[1]) / (AXES_TOP + AXES_BOTTOM))
            pan(pl.camera, 0.5 * (lo + hi) - np.array([0.0, 0.5 * (AXES_TOP - AXES_BOTTOM)]), size)
        else:
            f = max(np.abs(S[:, 0]).max() / AXES_X, hi[1] / AXES_TOP, -lo[1] / AXES_BOTTOM)
            if f <= 1.001:
                break
        if f > 1e-9:
            pl.camera.zoom(1.0 / f)
    pl.renderer.ResetCameraClippingRange()


def pan(cam, d, size: tuple[int, int]) -> None:
    """Move camera ``cam`` across a picture of ``size`` (w, h) by ``d`` (x, y) in -1..1 picture units (the
    view shifts by -d)."""
    fp, pos = np.array(cam.focal_point, float), np.array(cam.position, float)
    ahead = fp - pos
    dist = float(np.linalg.norm(ahead))
    if dist <= 0:
        return
    ahead /= dist
    up = np.array(cam.up, float)
    up -= np.dot(up, ahead) * ahead
    up /= max(float(np.linalg.norm(up)), 1e-12)
    right = np.cross(ahead, up)
    half = cam.parallel_scale if cam.parallel_projection else dist * np.tan(np.radians(cam.view_angle) / 2)
    w, h = size
    shift = right * d[0] * half * (w / h) + up * d[1] * half
    cam.focal_point = tuple(fp + shift)
    cam.position = tuple(pos + shift)
