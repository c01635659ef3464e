"""Off-screen rendering: pictures and animation frames of a :class:`gcmh_studio.scene.Scene` on off-screen
plotters, and (:class:`StillJob`) the window's still picture drawn in a thread.  No Qt here."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pyvista as pv

from .background import Picture, draw_in_background, started
from .camera import copy_camera, default_camera, keep_framing, refit_camera
from .scene import Scene


def animation_images(scene: Scene, model, frames, window=None, progress=None):
    """Draw each :class:`gcmh_studio.animation.Frame` on ``scene`` (an off-screen plotter's) and yield its image.

    ``model``: the ProjectionModel whose angles the frames set (changed in place);
    ``window``: an :class:`gcmh_studio.slicing.SliceWindow` to slice with (its centre is
    what a slice frame sets), or None. The camera stays where it is.
    """
    for k, fr in enumerate(frames):
        if fr.angles is not None:
            model.angles[:] = fr.angles
        view = model.view()
        scene.set_projection(view, render=False)
        if window is not None:
            if fr.slice_center is not None:
                window.c = fr.slice_center
            scene.set_slice(window.direction(view.frame), window.c, window.w, render=False)
        scene.plotter.renderer.ResetCameraClippingRange()
        scene.plotter.render()
        img = scene.plotter.screenshot(None, return_img=True)
        if progress is not None:
            progress(k)
        yield img


def render_image(scene: Scene, path=None, size=(1600, 1200), transparent: bool = False, camera=None,
                 fit: bool = True, camera_size=None, decorate=None):
    """Render ``scene`` off screen at ``size`` (w, h), super-sampled, and write a PNG to ``path``.

    The mesh is shared, not rebuilt. ``camera``: a pyvista Camera to copy (the
    window's), else the default oblique view. ``fit``: frame the object for this
    picture's shape from the camera's direction, as the window frames it (a 3840x2160
    picture of a 4:3 window must not crop); else keep the camera and only widen it so
    the picture shows what the window of ``camera_size`` showed. ``decorate(plotter)``: draws what the
    window adds to its view (the presentation's card) on this picture. Returns the (h, w, 3 or 4) image.
    """
    pl = pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
    try:
        other = Scene(pl, anti_aliasing="ssaa")
        other.adopt(scene, copy.copy(scene.style))
        if camera is not None:
            copy_camera(camera, pl.camera)
            if fit:
                refit_camera(pl)
            elif camera_size is not None:
                keep_framing(pl.camera, camera_size, size)
            pl.renderer.ResetCameraClippingRange()
        else:
            default_camera(pl)
        if decorate is not None:
            decorate(pl)
        if transparent:
            pl.renderer.GradientBackgroundOff()   # a gradient would paint every pixel opaque
        pl.render()
        img = pl.screenshot(str(path) if path is not None else None, transparent_background=transparent,
                            return_img=True, window_size=[int(size[0]), int(size[1])])
    finally:
        pl.close()
    return img



# ------------------------------------------------------------------ the still picture off the GUI thread
# A see-through result's still render takes about 0.3 s in software GL (every layer of every pixel shaded
# under five lights), and the GUI cannot tick while VTK draws on its thread. A StillJob draws that picture
# on an off-screen plotter of its own in a thread (VTK lets go of the GIL while it renders) from deep copies
# of the scene's meshes; the window shows the image until it renders again. One such picture at a time, the
# newest wins (one still waiting when the view asks for another is never drawn), and every other render
# waits for it (:mod:`gcmh_studio.background`).
SETTLE_RENDERS = 1          # cheap renders before the picture (see StillJob._run)


class StillJob:
    """The still picture of ``scene`` at ``size`` (w, h) under ``camera`` (:func:`camera_values`), rendered
    in a thread on an off-screen plotter set up as the window's (``anti_aliasing``, no multi-sampling).

    Made on the GUI thread: the copies are taken and the off-screen scene is built there (no GL yet), with
    ``decorate(plotter)`` (what the window draws over its view); when that adds anything the job is
    ``declined`` (the window draws its own picture). Then ``done()``, and ``image`` ((h, w, 3) uint8) or
    ``error``; or no image at all, when a newer picture was asked for before this one began.
    ``stale`` is the caller's: set it when the picture is no longer wanted."""

    def __init__(self, scene: Scene, size, camera: dict, anti_aliasing: str | None = "fxaa", decorate=None):
        self.size = (int(size[0]), int(size[1]))
        self.image: np.ndarray | None = None
        self.error: BaseException | None = None
        self.stale = False
        self.declined = False
        self.seconds = 0.0
        self._plotter: Any = None          # the off-screen plotter and scene, while the thread has them
        self._scene: Any = None
        self.picture: Picture | None = None
        # (made here, not in the thread: ``decorate`` is the window's; a plotter kept for the next job would
        # outlive the X server in a test run, and Xlib ends a process whose display went away)
        pl = pv.Plotter(off_screen=True, window_size=list(self.size))
        try:
            window: Any = pl.ren_win           # (an open plotter has its render window)
            window.SetMultiSamples(0)          # as the window: FXAA, no multi-sampling
            sc = Scene(pl, anti_aliasing=None)
            if anti_aliasing == "fxaa":    # (as pyvista would, without its 20 ms check for EGL: the caller's)
                pl.renderer.SetUseFXAA(True)
                sc.anti_aliasing = "fxaa"
            else:
                sc.set_anti_aliasing(anti_aliasing)
            src = scene.detached()
            sc.adopt(src, src.style)
            for key, value in camera.items():
                setattr(pl.camera, key, value)
            pl.renderer.ResetCameraClippingRange()
            if decorate is not None:
                before = len(pl.renderer.actors)
                decorate(pl)
                self.declined = len(pl.renderer.actors) != before
        except BaseException:
            pl.close()
            raise
        if self.declined:
            pl.close()
            return
        self._plotter, self._scene = pl, sc
        self.picture = draw_in_background(self._run, self._close)

    def done(self) -> bool:
        """Drawn, failed, declined, or dropped for a newer picture (then ``image`` is None)."""
        return self.picture is None or self.picture.done()

    def _run(self) -> None:
        import time

        t0 = time.perf_counter()
        pl = self._plotter
        try:
            # first a cheap render, the complex shrunk to a point (its colours mapped, no pixels): the colour bar
            # lays its labels out from what the frame before drew (in a first frame they sit over the bar)
            actor = self._scene.actor
            if actor is not None:
                actor.SetScale(1e-6, 1e-6, 1e-6)
                for _ in range(SETTLE_RENDERS):
                    pl.ren_win.Render()
                actor.SetScale(1.0, 1.0, 1.0)
            pl.ren_win.Render()                    # (VTK lets go of the GIL while it draws)
            self.image = window_pixels(pl.ren_win)
        except BaseException as e:  # noqa: BLE001 - told to the GUI thread, which draws the picture itself
            self.error = e
        finally:
            self._close()
            self.seconds = time.perf_counter() - t0

    def _close(self) -> None:
        try:
            self._plotter.close()
        except Exception:  # noqa: BLE001
            pass
        self._plotter = self._scene = None


def window_pixels(ren_win) -> np.ndarray:
    """The (h, w, 3) uint8 picture a render window holds now (no new render)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

    f = vtkWindowToImageFilter()
    f.SetInput(ren_win)
    f.SetInputBufferTypeToRGB()
    f.ReadFrontBufferOff()
    f.ShouldRerenderOff()
    f.Update()
    out = f.GetOutput()
    w, h, _ = out.GetDimensions()
    return np.ascontiguousarray(vtk_to_numpy(out.GetPointData().GetScalars()).reshape(h, w, 3)[::-1])


def warm_background() -> None:
    """Draw a small off-screen picture in the background now (the window calls this when it opens): the first
    one of a process loads modules holding the GIL for about a second, which would fall on the first result's
    picture. The window's renders wait for it as for any job."""

    def run() -> None:
        try:
            pl = pv.Plotter(off_screen=True, window_size=[160, 120])
            try:
                m = pv.Plane(i_resolution=2, j_resolution=2)
                m.point_data["t"] = np.arange(m.n_points, dtype=float)
                pl.add_mesh(m, scalars="t", scalar_bar_args=dict(title="t", vertical=True))
                pl.add_text("warm", font_size=10)
                window: Any = pl.ren_win
                window.Render()
            finally:
                pl.close()
        except Exception:  # noqa: BLE001 - the first job will say
            pass

    if not started():
        draw_in_background(run)
