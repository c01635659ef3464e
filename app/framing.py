"""Framing an animation over all of its frames, and checking a picture's framing.  No Qt here.

A rotation or a tour moves the object across the picture: a camera fitted to the first frame cut 42 of the
complex cosine's 60 frames and put 25 over the title.  :func:`animation_extent` is the convex hull of what
every frame draws (the projected points of each frame's view, hull by hull, so it stays small) and
:func:`fit_animation` fits the camera once to it, from the camera's direction, inside the object band:
clear of the title and subtitle above, the caption below and the colour bar on the right.

:func:`framing_faults` measures a picture (an (h, w, 3) frame of a GIF): the object's coloured pixels on
the edges of the object band (cut) and in the text bands (over the title or caption).
"""

from __future__ import annotations

import numpy as np

from .labels import SUBTITLE_Y

# The object band of an animation, in halves of the picture from its centre (camera.MARGIN_X/Y for a still
# picture, less by a few per cent: an animation's hull touches the band's edge in some frame, and FXAA
# spreads an edge by a pixel)
ANIMATION_MARGIN_X = 0.66
ANIMATION_MARGIN_Y = 0.72
HULL_SAMPLE = 100_000      # points of one frame taken into the hull (every m-th of a larger mesh)

# The picture's bands (fractions of the height, up from the bottom; of the width, from the left)
TEXT_TOP = SUBTITLE_Y      # title and subtitle: above the subtitle's baseline
TEXT_BOTTOM = 0.10         # a parameter sweep's caption and critical notice: below this
BAND_RIGHT = 0.86          # the colour bar and its labels: right of this
AXES_CORNER = (0.2, 0.28)  # the orientation widget's viewport (bottom left), not the object's
COLOURED = 30.0            # grey levels off the background-to-white line that make a pixel the object's


def hull_points(X: np.ndarray) -> np.ndarray:
    """The vertices of the convex hull of ``X`` (m, 3) (all of ``X`` when it is flat or tiny): what a
    perspective camera needs to frame ``X`` (a projection's extremes are hull vertices)."""
    X = np.asarray(X, dtype=float)
    if len(X) <= 8:
        return X
    from scipy.spatial import ConvexHull, QhullError

    try:
        return X[ConvexHull(X).vertices]
    except (QhullError, ValueError):   # flat (a planar curve), or fewer independent points than 4
        try:
            return X[ConvexHull(X, qhull_options="QJ").vertices]
        except (QhullError, ValueError):
            return X


def animation_extent(scene, model, frames, sample: int = HULL_SAMPLE) -> np.ndarray:
    """(m, 3) points whose hull holds every frame's projected geometry: the scene's points under each
    frame's view (the angles a frame sets on ``model``, a ProjectionModel; its angles are put back).

    A slice frame draws part of the whole under the same view, so the whole bounds it."""
    whole = getattr(scene, "geometry", None)        # (a slice's own projector holds only the slice)
    proj = whole.projector if whole is not None and whole.projector is not None else scene.projector
    if proj is None or proj.XT.shape[1] == 0:
        return np.zeros((0, 3))
    from .projection import Projector

    step = max(1, proj.XT.shape[1] // sample)
    sub = Projector(proj.X[::step] + proj.center, center=proj.center)
    sub.set_radii(proj.radii())
    saved = model.angles.copy()
    hull = np.zeros((0, 3))
    views = [fr.angles for fr in frames if fr.angles is not None] or [None]
    try:
        for angles in views:
            if angles is not None:
                model.angles[:] = angles
            Y = np.asarray(sub.project_view(model.view()), dtype=float)
            Y = Y[np.all(np.isfinite(Y), axis=1)]
            hull = hull_points(np.concatenate([hull, Y]))
    finally:
        model.angles[:] = saved
    return hull


def fit_animation(plotter, points: np.ndarray) -> None:
    """Fit ``plotter``'s camera, from its direction, so ``points`` (every frame's, :func:`animation_extent`)
    lie in the object band: no frame is cut, none runs over the text."""
    from .camera import fit_camera

    if len(points) == 0:
        return
    cam = plotter.camera
    lo, hi = points.min(0), points.max(0)
    centre = 0.5 * (lo + hi)
    d = np.asarray(cam.direction, dtype=float)
    # from the union's centre, far enough that every point is in front of the eye
    dist = max(float(cam.distance), 2.0 * float(np.linalg.norm(hi - lo)) + 1e-9)
    cam.focal_point = tuple(centre)
    cam.position = tuple(centre - dist * d)
    fit_camera(plotter, margin_x=ANIMATION_MARGIN_X, margin_y=ANIMATION_MARGIN_Y, points=points)
    plotter.renderer.ResetCameraClippingRange()


def object_mask(img, background=None) -> np.ndarray:
    """(h, w) bool: the object's pixels of a picture (h, w, 3): coloured, i.e. more than ``COLOURED`` grey
    levels off every line from the background (``background``: (h, 3), each row's colour; default the
    scene's gradient) to a text's colour: white, on which the texts' whites and greys and their
    anti-aliasing lie, and the section's pale coral caption (`sections.TEXT_COLOR`)."""
    from matplotlib.colors import to_rgb

    from .scene import BACKGROUND, BACKGROUND_TOP
    from .sections import TEXT_COLOR

    f = np.asarray(img, dtype=float)[..., :3]
    h = f.shape[0]
    if background is None:
        up = 1.0 - (np.arange(h) + 0.5) / h
        bot, top = 255 * np.array(to_rgb(BACKGROUND)), 255 * np.array(to_rgb(BACKGROUND_TOP))
        background = bot + up[:, None] * (top - bot)
    b = np.asarray(background, dtype=float)[:, None, :]
    off = np.full(f.shape[:2], np.inf)
    for text in (np.full(3, 255.0), 255 * np.array(to_rgb(TEXT_COLOR))):
        axis = text - b
        t = np.clip(((f - b) * axis).sum(-1, keepdims=True) / (axis * axis).sum(-1, keepdims=True), 0, 1)
        off = np.minimum(off, np.linalg.norm(f - b - t * axis, axis=-1))
    return off > COLOURED


def framing_faults(img) -> dict:
    """The framing of one picture: ``cut``, the object's pixels on the edge rows and columns of the object
    band (the picture without the text bands, the colour bar and the axes corner), and ``over_text``, its
    pixels in the text bands above and below."""
    m = object_mask(img)
    h, w = m.shape
    top = int(np.floor((1 - TEXT_TOP) * h))           # rows 0..top-1: title and subtitle
    bottom = int(np.ceil((1 - TEXT_BOTTOM) * h))      # rows bottom..h-1: the caption
    right = int(BAND_RIGHT * w)
    ax_w, ax_h = int(np.ceil(AXES_CORNER[0] * w)), int(np.floor((1 - AXES_CORNER[1]) * h))
    band = m[top:bottom, :right].copy()
    band[ax_h - top:, :ax_w] = False                  # the orientation widget's corner
    edges = int(band[0].sum() + band[-1].sum() + band[:, 0].sum() + band[:, -1].sum())
    text = m[:top, :right].copy(), m[bottom:, ax_w:right]
    return {"cut": edges, "over_text": int(text[0].sum() + text[1].sum())}
