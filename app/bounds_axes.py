"""Bounds axes with ticks around the drawn object, titled with the projection's axes ("y = Im z", or a
mixture such as "0.71 x + 0.71 w"), their ticks in the projected coordinates; and framing the camera on
their box.  No Qt here."""

from __future__ import annotations

import numpy as np

from .camera import screen_coordinates

AXES_FONT = 14                       # the bounds axes' labels (pixels; times the presentation's font scale)
TICKS = 4                            # about this many steps along a long side (round steps: 1, 2, 2.5, 5 x 10^k)
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


def nice_range(lo: float, hi: float, steps: int = TICKS) -> tuple[float, float, int]:
    """(lo', hi', labels): ``[lo, hi]`` widened to multiples of a round step (1, 2, 2.5 or 5 times a power of
    ten) cut into ``steps - 1`` to ``steps + 2`` parts, the one that widens it least; and the number of ticks."""
    span = hi - lo
    if not (span > 0 and np.isfinite(span)):
        return float(np.floor(lo)), float(np.floor(lo)) + 1.0, 2
    decade = 10.0 ** np.floor(np.log10(span / steps))
    best = None
    for step in (m * decade * f for f in (0.1, 1.0, 10.0) for m in (1.0, 2.0, 2.5, 5.0)):
        # (an end a fiftieth of a step past a round value stays at it: -1.0015 is drawn from -1)
        a, b = np.floor(lo / step + 0.02) * step, np.ceil(hi / step - 0.02) * step
        parts = int(round((b - a) / step))
        key = (round((b - a) / span, 2), abs(parts - steps))   # the least widening, then the nearest count
        if max(1, steps - 1) <= parts <= steps + 2 and (best is None or key < best[0]):
            best = (key, float(a), float(b), parts + 1)
    return best[1:] if best is not None else (float(lo), float(hi), 2)


class TickFormat(str):
    """A tick label format that writes a round value with the decimals its step needs, never "-0" or
    "-0.0" (pyvista formats every tick with ``fmt.format(value)``; the float noise of a linspace went
    through as "-0.0" and "5.6e-17")."""

    def __new__(cls, step: float):
        obj = super().__new__(cls, "{0}")
        power = int(np.floor(np.log10(step) + 1e-9))
        quarter = round(step / 10.0 ** power, 6) == 2.5      # (2.5, 0.25: one decimal more)
        obj.decimals = max(0, -power + (1 if quarter else 0))
        return obj

    def format(self, *args, **kwargs) -> str:
        text = f"{float(args[0]):.{self.decimals}f}"
        return "0" if float(text) == 0.0 else text


def add_axes(plotter, key: tuple):
    """pyvista's bounds axes on ``plotter`` for ``key`` = (bounds, titles, shown ranges, font size, label
    counts), remembered on the actor as ``_gcmh_key``."""
    bounds, titles, ranges, font, counts = key
    actor = plotter.show_bounds(bounds=bounds, axes_ranges=ranges, xtitle=titles[0], ytitle=titles[1],
                                ztitle=titles[2], location="outer", ticks="outside", font_size=font,
                                color="#e6e9f0", bold=False, n_xlabels=counts[0], n_ylabels=counts[1],
                                n_zlabels=counts[2], fmt="{0:.2g}", use_3d_text=False, render=False)
    set_tick_formats(actor, ranges, counts)
    actor._gcmh_key = key
    return actor


def set_tick_formats(actor, ranges, counts) -> None:
    """Each axis' ticks written with the decimals of its step (:class:`TickFormat`)."""
    for a, name in enumerate("xyz"):
        lo, hi = ranges[2 * a], ranges[2 * a + 1]
        step = (hi - lo) / max(counts[a] - 1, 1) if hi > lo else 1.0
        setattr(actor, f"{name}_label_format", TickFormat(step))


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
    drawn = np.reshape([float(b) for b in mesh.bounds], (3, 2))
    titles = tuple(axis_titles(scene))
    offsets = axis_offsets(scene)
    shown = drawn + offsets[:, None]
    # the box widened to round values, ticked at a round step (a short side: about two steps, five
    # labels would overlap there)
    sides = np.diff(drawn, axis=1).ravel()
    nice = [nice_range(lo, hi, TICKS if side >= 0.5 * sides.max() else 2)
            for (lo, hi), side in zip(shown, sides)]
    ranges = tuple(float(v) for a, b, _ in nice for v in (a, b))
    counts = tuple(c for _, _, c in nice)
    bounds = tuple(float(v) for (a, b, _), off in zip(nice, offsets) for v in (a - off, b - off))
    font = int(round(AXES_FONT * font_scale))
    actor = getattr(pl.renderer, "cube_axes_actor", None)
    key = getattr(actor, "_gcmh_key", None)
    if actor is not None and key is not None and key[3:] == (font, counts):
        if key[:3] != (bounds, titles, ranges):
            actor.bounds = bounds
            actor.x_axis_range, actor.y_axis_range, actor.z_axis_range = ranges[0:2], ranges[2:4], ranges[4:6]
            actor.SetXTitle(titles[0])
            actor.SetYTitle(titles[1])
            actor.SetZTitle(titles[2])
            set_tick_formats(actor, ranges, counts)
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
