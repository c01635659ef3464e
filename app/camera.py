"""Framing: where the camera looks from and how far, so the object fills the picture between the title,
the colour bar and the axes (the window, screenshots and thumbnails alike).  No Qt here."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from .labels import SUBTITLE_Y

# Where the object may lie, in halves of the picture from its centre: clear of the title (top), the colour
# bar (right) and the axes (bottom left) -- the picture a window, a screenshot and a thumbnail all share.
MARGIN_X = 0.68
MARGIN_Y = 0.76
TITLE_BOTTOM = 2 * SUBTITLE_Y - 1     # the subtitle's baseline, in the same units (-1..1 up the picture)
VIEW_DIRECTION = (1.0, -1.6, 1.1)


def default_camera(plotter) -> None:
    """An oblique view from above, zoomed so the object fills the picture between title and colour bar."""
    plotter.renderer.view_vector(VIEW_DIRECTION, viewup=(0.0, 0.0, 1.0))
    refit_camera(plotter)


def refit_camera(plotter) -> None:
    """Frame the shown object again from the camera's current direction (the user's view kept):
    the new extent of a projection, mapping or slice, or another picture size."""
    plotter.renderer.reset_camera(render=False)    # focal point on the bounds' centre, direction kept
    fit_camera(plotter, margin_x=MARGIN_X, margin_y=MARGIN_Y)
    plotter.renderer.ResetCameraClippingRange()


def shown_points(plotter, max_points: int = 400_000) -> np.ndarray:
    """(m, 3) points of the visible meshes (every ``step``-th of a very large one), finite only."""
    pts = []
    for actor in plotter.renderer.actors.values():
        try:
            if not actor.IsA("vtkActor") or not actor.GetVisibility():   # 3D only: no text, bars, legends
                continue
            ds = actor.GetMapper().GetInput()
            n = ds.GetNumberOfPoints()
        except AttributeError:
            continue
        if n == 0:
            continue
        P = pv.wrap(ds).points
        step = max(1, n // max_points)
        pts.append(np.asarray(P[::step], dtype=float))
    if not pts:
        return np.zeros((0, 3))
    X = np.concatenate(pts)
    return X[np.all(np.isfinite(X), axis=1)]


def screen_coordinates(plotter, X: np.ndarray, size=None) -> np.ndarray:
    """(m, 2) normalised picture coordinates (-1..1 across the picture) of points ``X`` (m, 3) under the
    plotter's camera, for a picture of ``size`` (w, h) (default: the plotter's)."""
    w, h = size or plotter.window_size
    M = plotter.camera.GetCompositeProjectionTransformMatrix(w / max(h, 1), -1.0, 1.0)
    A = np.array([[M.GetElement(i, j) for j in range(4)] for i in range(4)])
    Y = np.asarray(X, dtype=float) @ A[:, :3].T + A[:, 3]
    wq = Y[:, 3:4]
    wq = np.where(np.abs(wq) < 1e-12, 1e-12, wq)
    return Y[:, :2] / wq


def inside_share(plotter, X: np.ndarray | None = None, size=None, title_band: bool = True) -> float:
    """The share of points ``X`` (default: every shown point) that the picture shows: inside it and, with
    ``title_band``, below the title and subtitle (the top 11.5 %)."""
    X = shown_points(plotter, max_points=10**9) if X is None else np.asarray(X, dtype=float)
    if len(X) == 0:
        return 1.0
    S = screen_coordinates(plotter, X, size)
    top = TITLE_BOTTOM if title_band else 1.0
    ok = (np.abs(S[:, 0]) <= 1.0) & (S[:, 1] >= -1.0) & (S[:, 1] <= top)
    return float(np.mean(ok))


def fit_camera(plotter, margin_x: float = 0.9, margin_y: float = 0.9, max_points: int = 400_000,
               points=None) -> None:
    """Change the view angle so the shown points (or ``points`` (m, 3): an animation's, all frames') just
    fit (perspective camera, direction kept).

    The points fill at most ``margin_x`` of the half-width and ``margin_y`` of the half-height.
    """
    X = shown_points(plotter, max_points) if points is None else np.asarray(points, dtype=float)
    if len(X) == 0:
        return
    cam = plotter.camera
    w, h = plotter.window_size
    aspect = max(1e-6, w / max(h, 1))
    for _ in range(3):  # centre the points on screen, then fit them
        M = np.array([[cam.GetViewTransformMatrix().GetElement(i, j) for j in range(4)] for i in range(4)])
        Y = X @ M[:3, :3].T + M[:3, 3]
        depth = -Y[:, 2]
        if np.any(depth <= 1e-9):   # points behind the eye: back off along the view direction first
            d = np.asarray(cam.direction, dtype=float)
            back = float(np.max(-depth)) + 2.0 * float(np.ptp(Y[:, 2])) + 1.0
            cam.position = tuple(np.asarray(cam.position) - back * d)
            continue
        u = Y[:, 0] / depth
        v = Y[:, 1] / depth
        u0 = 0.5 * (u.min() + u.max())
        v0 = 0.5 * (v.min() + v.max())
        D = cam.distance
        shift = D * (u0 * M[0, :3] + v0 * M[1, :3])   # rows of M: camera right, up, -forward
        cam.focal_point = tuple(np.asarray(cam.focal_point) + shift)
        cam.position = tuple(np.asarray(cam.position) + shift)
    M = np.array([[cam.GetViewTransformMatrix().GetElement(i, j) for j in range(4)] for i in range(4)])
    Y = X @ M[:3, :3].T + M[:3, 3]
    depth = -Y[:, 2]
    if np.any(depth <= 1e-9):
        return
    u = Y[:, 0] / depth
    v = Y[:, 1] / depth
    need = max(np.max(np.abs(v - 0.5 * (v.min() + v.max()))) / margin_y,
               np.max(np.abs(u - 0.5 * (u.min() + u.max()))) / (aspect * margin_x))
    if not np.isfinite(need) or need <= 0:
        return
    cam.view_angle = float(min(max(2 * np.degrees(np.arctan(need)), 1.0), 120.0))


def keep_framing(camera, src_size, dst_size) -> None:
    """Widen ``camera``'s view angle so a picture of ``dst_size`` shows at least what one of ``src_size``
    showed (a taller picture would otherwise crop the sides: the view angle is vertical)."""
    a_src = src_size[0] / max(src_size[1], 1)
    a_dst = dst_size[0] / max(dst_size[1], 1)
    if a_dst >= a_src:
        return
    t = np.tan(np.radians(camera.view_angle) / 2) * a_src / a_dst
    camera.view_angle = float(min(2 * np.degrees(np.arctan(t)), 170.0))


def copy_camera(src, dst) -> None:
    dst.position = tuple(src.position)
    dst.focal_point = tuple(src.focal_point)
    dst.up = tuple(src.up)
    dst.view_angle = float(src.view_angle)
    dst.parallel_projection = bool(src.parallel_projection)
    dst.parallel_scale = float(src.parallel_scale)


def camera_values(camera) -> dict:
    """A pyvista camera as plain values (to copy onto another thread's camera)."""
    return dict(position=tuple(camera.position), focal_point=tuple(camera.focal_point), up=tuple(camera.up),
                view_angle=float(camera.view_angle), parallel_projection=bool(camera.parallel_projection),
                parallel_scale=float(camera.parallel_scale))
