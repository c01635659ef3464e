"""Off-screen rendering: pictures and animation frames of a :class:`gcmh_studio.scene.Scene` on off-screen
plotters, and (:class:`StillJob`) the window's still picture drawn in a worker process.  No Qt here."""

from __future__ import annotations

import copy

import numpy as np
import pyvista as pv

from .camera import copy_camera, default_camera, keep_framing, refit_camera
from .scene import Scene
from .sections import SectionScene
from .still_process import still_process


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
        other = SectionScene(pl, anti_aliasing="ssaa")
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
        img = checked_screenshot(other, transparent)
        if path is not None:
            from PIL import Image

            from gcmh_core.safe_io import atomic_write

            atomic_write(path, lambda temp: Image.fromarray(np.asarray(img)).save(temp, format="PNG"), ".png",
                         what=str(path))
    finally:
        pl.close()
    return img


# ------------------------------------------------------------------ pictures that are never black
class RenderError(RuntimeError):
    """The renderer could not draw a picture of this size (its frame buffer could not be made)."""


def gl_limits(plotter) -> dict:
    """{"texture", "renderbuffer", "viewport"}: the largest side the plotter's OpenGL context takes
    (GL_MAX_TEXTURE_SIZE, GL_MAX_RENDERBUFFER_SIZE, the smaller of GL_MAX_VIEWPORT_DIMS); {} before its first
    render or where VTK does not say. (Not the whole truth: Mesa's llvmpipe says 16384 and fails at
    16384 x 8192 super-sampled, a float frame buffer of 2 GB; :func:`checked_screenshot` looks at the result.)"""
    out: dict = {}
    try:
        rw = plotter.ren_win
        rw.MakeCurrent()
        state = rw.GetState()
        for key, enum in (("texture", 0x0D33), ("renderbuffer", 0x84E8), ("viewport", 0x0D3A)):
            v = [0, 0]
            state.vtkglGetIntegerv(enum, v)
            side = min(v) if key == "viewport" else v[0]
            if side > 0:
                out[key] = int(side)
    except Exception:  # noqa: BLE001 - a render window without a GL state: nothing known
        pass
    return out


_FRAMEBUFFER_ERRORS = ("framebuffer", "frame buffer", "glframebuffer", "out of memory")


def _attempt(plotter, transparent: bool):
    """(image, failed): one render and its pixels; failed when VTK reported a frame buffer it could not make
    or the picture came out black where the background should be."""
    import pyvista as pv

    with pv.VtkErrorCatcher(send_to_logging=False) as caught:
        plotter.render()
        img = plotter.screenshot(None, transparent_background=transparent, return_img=True)
    errors = " ".join(str(getattr(e, "message", e)).lower() for e in caught.error_events)
    failed = any(word in errors for word in _FRAMEBUFFER_ERRORS) or _blank(plotter, img, transparent)
    return img, failed


def _blank(plotter, img, transparent: bool) -> bool:
    """The four corners black (and opaque) where the renderer's background is not black: nothing was drawn."""
    img = np.asarray(img)
    if img.ndim != 3 or img.size == 0:
        return True
    ren = plotter.renderer
    backgrounds = [ren.GetBackground()] + ([ren.GetBackground2()] if ren.GetGradientBackground() else [])
    if transparent or all(max(c) < 0.05 for c in backgrounds):
        return not img.any()
    corners = img[[0, 0, -1, -1], [0, -1, 0, -1], :3]
    return not corners.any()


def checked_screenshot(scene: Scene, transparent: bool = False) -> np.ndarray:
    """Render ``scene``'s off-screen plotter and return its (h, w, 3 or 4) picture, never a black one.

    Super-sampling draws four times the pixels into a float frame buffer, which the renderer may not be able to
    make for a large picture (8192 x 4096 under Xvfb: a black picture, exit 0): then the picture is drawn again
    with FXAA at its own size; if that cannot be drawn either, :class:`RenderError` says so with the GL limits."""
    pl = scene.plotter
    img, failed = _attempt(pl, transparent)
    if failed and scene.anti_aliasing == "ssaa":
        scene.set_anti_aliasing("fxaa")
        img, failed = _attempt(pl, transparent)
    if failed:
        w, h = (int(s) for s in pl.window_size)
        limits = gl_limits(pl)
        said = f" (its OpenGL takes at most {min(limits.values())} pixels a side)" if limits else ""
        raise RenderError(f"the renderer could not draw a {w}x{h} picture{said}: use a smaller size")
    return img



# ------------------------------------------------------------------ the still picture in a process of its own
# A see-through result's still render takes about 0.3 s in software GL (every layer of every pixel shaded
# under five lights), and the GUI cannot tick while VTK draws on its thread. A StillJob has that picture drawn
# by the worker process of :mod:`gcmh_studio.still_process` (a thread of the app drawing with VTK while the
# GUI thread does too cannot be proven safe: issue 26, item 8) from a detached copy of the scene, pickled on
# the GUI thread; the window shows the image until it renders again. The newest picture wins.
class StillJob:
    """The still picture of ``scene`` at ``size`` (w, h) under ``camera`` (:func:`camera_values`), drawn by the
    worker process on an off-screen plotter set up as the window's (``anti_aliasing``, no multi-sampling).

    Asked on the GUI thread (the caller has made sure the window draws nothing of its own over the view:
    :func:`draws_over`). Then ``done()``, and ``image`` ((h, w, 3) uint8) or ``error``; or neither, when a
    newer picture was asked for first. ``stale`` is the caller's: set it when the picture is no longer wanted."""

    def __init__(self, scene: Scene, size, camera: dict, anti_aliasing: str | None = "fxaa"):
        self.size = (int(size[0]), int(size[1]))
        self.stale = False
        self.request = still_process().ask(still_payload(scene, self.size, camera, anti_aliasing))

    def done(self) -> bool:
        """Drawn, failed, or dropped for a newer picture (then ``image`` is None); a worker that hangs is ended
        here (the GUI's poll asks)."""
        still_process().check()
        return self.request.done()

    @property
    def image(self) -> np.ndarray | None:
        return self.request.image

    @property
    def error(self) -> str | None:
        return self.request.error


def still_payload(scene: Scene, size, camera: dict, anti_aliasing: str | None) -> bytes:
    """What the worker process needs to draw ``scene``'s still picture (the arguments of
    :func:`gcmh_studio.still_process.draw_still`), pickled: a :meth:`Scene.detached` copy (numpy arrays, and
    meshes pyvista pickles as VTK's own format: no VTK object shared), the size (w, h), the camera's values and
    the anti-aliasing."""
    import pickle

    job = dict(scene=scene.detached(), size=(int(size[0]), int(size[1])), camera=dict(camera),
               anti_aliasing=anti_aliasing)
    return pickle.dumps(job, protocol=pickle.HIGHEST_PROTOCOL)


def draws_over(decorate, plotter) -> bool:
    """``decorate(plotter)`` adds something to ``plotter``'s view (an off-screen plotter kept for the question,
    never rendered; once drawn on, the caller closes it)."""
    before = len(plotter.renderer.actors)
    decorate(plotter)
    return len(plotter.renderer.actors) != before
