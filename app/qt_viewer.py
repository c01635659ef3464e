"""QtViewer: the studio's 3D view (napari's QtViewer, in small).

A ``pyvistaqt.QtInteractor`` drawn by an :class:`gcmh_studio.scene.Scene`, from what
the :class:`gcmh_studio.model.StudioModel` holds (the result, the picked cell) and what
the View tab (:class:`gcmh_studio.qt_projection_panel.QtProjectionPanel`) sets: the
projection in place, the style, the slice and the overlays, picking a cell,
the camera, and pictures of the view. Only the GUI thread touches it; problems
go to the model's status line.

Never frozen: a new result is drawn with one render (pyvista would render after
every actor it adds) in short GUI steps of their own; a see-through result's still
picture (0.3 s of software GL for the three-torus) is drawn in a thread on an
off-screen copy (:class:`gcmh_studio.scene.StillJob`) and shown over the view until the view
renders again. The window anti-aliases with FXAA (super-sampling only for
screenshots), and while a slider or a drag moves the view it is drawn in a cheaper
moving look (:meth:`gcmh_studio.scene.Scene.set_moving`: a very large result at a coarse
level of detail, a see-through one under one headlight), the still look coming
back, the same picture as before, once it rests (``SETTLE_MS``).

Always framed: the camera refits, keeping its direction, when a result arrives and
when the base, the mapping or a slice changes the object's extent, and whenever a
turn carries the object out of the picture; the View tab's "keep camera" holds it.

Steering: Shift-drag turns the screen's x (horizontal drag) and y (vertical drag)
against the hidden direction the View tab names; Ctrl+Shift-drag, or Shift with
the right button, against the next one (:func:`gcmh_studio.projection.turned_angles`).
"""

from __future__ import annotations

import copy

import numpy as np
from qtpy.QtCore import QEvent, QObject, Qt, QTimer
from qtpy.QtGui import QImage, QPixmap
from qtpy.QtWidgets import QLabel

from .background import wait_background
from .camera import (
    MARGIN_X,
    MARGIN_Y,
    TITLE_BOTTOM,
    camera_values,
    copy_camera,
    default_camera,
    refit_camera,
    screen_coordinates,
)
from .inputs import format_value
from .labels import labels_for, view_subtitle, warm_labels
from .model import StudioModel, slice_params
from .offscreen import StillJob, render_image, warm_background
from .overlays import PICK_COLOR, draw_overlays
from .projection import ProjectionModel, turned_angles
from .scene import Scene, Style
from .studio_io import apply_camera, camera_state, valid_camera

SETTLE_MS = 250          # a view at rest this long is drawn in full again
STILL_POLL_MS = 15       # how often the GUI looks whether the still picture drawn in a thread is there
DRAG_DEGREES = 0.4       # per pixel of a Shift-drag


class _DragFilter(QObject):
    """Shift-drag on the 3D view turns hidden planes (the events never reach VTK's trackball)."""

    def __init__(self, viewer: QtViewer):
        super().__init__()
        self.viewer = viewer
        self.last = None
        self.hidden = 0

    def eventFilter(self, obj, ev) -> bool:  # noqa: N802 - Qt's name
        t = ev.type()
        v = self.viewer
        if t == QEvent.Resize:     # another shape: frame again (after the resize settles)
            v._resized.start()
            return False
        if t == QEvent.Hide:       # (a closing window: its picture's thread ends before the display may go)
            v._drop_still()
            wait_background()
            return False
        if t == QEvent.MouseButtonPress and ev.modifiers() & Qt.ShiftModifier and v.can_turn():
            nxt = bool(ev.modifiers() & Qt.ControlModifier) or ev.button() == Qt.RightButton
            self.hidden = v.panel.drag_hidden() + (1 if nxt else 0)
            self.last = (ev.x(), ev.y())
            return True
        if t == QEvent.MouseMove and self.last is not None:
            x, y = ev.x(), ev.y()
            dx, dy = x - self.last[0], y - self.last[1]
            self.last = (x, y)
            v.turn_hidden(dx, -dy, self.hidden)
            return True
        if t == QEvent.MouseButtonRelease and self.last is not None:
            self.last = None
            return True
        return False


class QtViewer:
    """The view of ``model`` as the View tab ``panel`` asks; ``widget`` goes into the window's layout."""

    def __init__(self, model: StudioModel, panel, parent=None):
        from pyvistaqt import QtInteractor

        self.model = model
        self.panel = panel
        # no multi-sampling: with software GL it doubles every frame; FXAA smooths the edges instead
        self.plotter = QtInteractor(parent, auto_update=False, multi_samples=0)
        self.widget = self.plotter.interactor
        self.scene = Scene(self.plotter, anti_aliasing="fxaa")
        warm_labels()
        self.renders = 0                     # full renders of the window (the benchmark counts them)
        # what else the window draws in the view (the presentation's card and axes): f(plotter) draws it
        # again on the off-screen copies that screenshots and animations render
        self.picture_decorators: list = []
        self._mapping = None                 # the mapping the camera was fitted for
        # timers owned by the view's widget: they die with it instead of firing on a closed window
        self._settle = QTimer(self.widget)
        self._settle.setSingleShot(True)
        self._settle.setInterval(SETTLE_MS)
        self._settle.timeout.connect(self._at_rest)
        self._resized = QTimer(self.widget)
        self._resized.setSingleShot(True)
        self._resized.setInterval(60)
        self._resized.timeout.connect(self._on_resized)
        self._drag = _DragFilter(self)
        self.widget.installEventFilter(self._drag)
        # a see-through result's still picture is drawn in a thread and shown over the view until the
        # view renders again (:class:`gcmh_studio.scene.StillJob`)
        self.still_off_thread = True
        self._still_job: StillJob | None = None
        self.still_image: np.ndarray | None = None    # the last one shown
        self._settling = False
        self._fresh = False        # a new result the window has not drawn yet (its picture drawn in a thread)
        self._still_label = QLabel(self.widget)
        self._still_label.setAttribute(Qt.WA_TransparentForMouseEvents)   # the view under it gets the mouse
        self._still_label.hide()
        self._still_poll = QTimer(self.widget)
        self._still_poll.setInterval(STILL_POLL_MS)
        self._still_poll.timeout.connect(self._still_arrived)
        self._still_steps: list = []
        self._still_step = QTimer(self.widget)
        self._still_step.setSingleShot(True)
        self._still_step.setInterval(0)
        self._still_step.timeout.connect(self._next_still_step)
        self.plotter.ren_win.AddObserver("StartEvent", lambda *a: self._drop_still())
        if self.still_off_thread:
            warm_background()
        try:   # turning the camera with the mouse draws the moving look too, the still one when let go
            style = self.plotter.iren.interactor.GetInteractorStyle()
            style.AddObserver("StartInteractionEvent", lambda *a: self._camera_moving(True))
            style.AddObserver("EndInteractionEvent", lambda *a: self._camera_moving(False))
        except Exception:  # noqa: BLE001 - a convenience
            pass

    # ------------------------------------------------------------ drawing
    def style(self) -> Style:
        """The View tab's style for the result on screen (title and subtitle included)."""
        pp = self.panel
        two = pp.two_sided_check.isChecked()
        mapping = pp.model.mapping if pp.model.n >= 4 else "orthographic"
        # an example's labels are found by its title; a system typed in complex mode brings its own ("u = Re w")
        labels = labels_for(self.model.title, self.model.names) or dict(self.model.labels or {})
        sub = view_subtitle(self.model.result, self.model.names, pp.color_by(), two, mapping, labels)
        params = (self.model.result.meta.get("params") if self.model.result is not None else None) or {}
        if params:   # the picture says at which values it was made (a class watching a slider reads them)
            sub = "  ".join(f"{p} = {format_value(v)}" for p, v in params.items()) + " \u00b7 " + sub
        return Style(color_by=pp.color_by(), opacity=pp.opacity(), show_edges=pp.show_edges(),
                     title=self.model.title, subtitle=sub, two_sided=two, labels=labels)

    def render(self) -> None:
        """Ask for one render of the window: Qt paints it once, however many changes came before
        (``plotter.render()`` renders now and then once more in the paint it schedules)."""
        self.renders += 1
        self._drop_still()
        if self._fresh:
            self._settle_window()
        self.widget.update()

    # ------------------------------------------------------------ the still picture off the GUI thread
    def _still_in_thread(self) -> bool:
        """Draw the still picture in a thread: a see-through result (0.3 s of software GL for the three-torus)
        in a view on screen with nothing of the window's own drawn over it (the presentation's card)."""
        aa = self.scene.anti_aliasing   # (FXAA as asked: an EGL build falls back to super-sampling)
        return (self.still_off_thread and self.scene.see_through() and self.widget.isVisible()
                and min(self.size()) > 0 and (aa != "fxaa" or bool(self.plotter.renderer.GetUseFXAA())))

    def _render_still(self) -> None:
        """The still look of the scene as it is, drawn in a thread, shown when it arrives (else the window
        renders it); the render was counted when it was asked for."""
        self._drop_still()
        if not self._still_in_thread():
            self.widget.update()
            return
        try:
            job = StillJob(self.scene, self.plotter.ren_win.GetSize(), camera_values(self.plotter.camera),
                           anti_aliasing=self.scene.anti_aliasing, decorate=self._decorate)
        except Exception:  # noqa: BLE001 - the window draws it itself
            job = None
        if job is None or job.declined:   # (the presentation draws over the view: the window's own render)
            self.widget.update()
            return
        self._still_job = job
        self._still_poll.start()

    def _next_still_step(self) -> None:
        if self._still_steps:
            self._still_steps.pop(0)()
        if self._still_steps:     # (started after the step: a timer due meanwhile, the GUI's, goes first)
            self._still_step.start()

    def _drop_still(self) -> None:
        """The view renders itself (or changed): a still picture on its way or on screen is no longer it."""
        if self._settling:
            return
        self._still_steps = []
        self._still_step.stop()
        if self._still_job is not None:
            self._still_job.stale = True
            self._still_job = None
        if self._still_label.isVisible():
            self._still_label.hide()
            self._still_label.clear()

    def _still_arrived(self) -> None:
        job = self._still_job
        if job is None:
            self._still_poll.stop()
            return
        if not job.done():
            return
        self._still_poll.stop()
        self._still_job = None
        w, h = self.plotter.ren_win.GetSize()
        img = job.image
        if job.stale or img is None or img.shape[:2] != (h, w):   # failed, or the view changed size
            if not job.stale:
                self.render()
            return
        self.still_image = img
        qimg = QImage(img.data, w, h, 3 * w, QImage.Format_RGB888)
        pix = QPixmap.fromImage(qimg)    # (a copy: the array may go)
        pix.setDevicePixelRatio(w / max(self.widget.width(), 1))
        self._still_label.setGeometry(self.widget.rect())
        self._still_label.setPixmap(pix)
        self._still_label.show()
        self._still_label.raise_()

    def _settle_window(self) -> None:
        """One cheap render of a new result, not shown, with the complex shrunk to a point: the colour bar lays
        its labels out from the frame before, and the window's first frame of a new result put them over the
        bar (the picture a result opened with, until the next render)."""
        self._fresh = False
        actor = self.scene.actor
        if actor is None or not self.widget.isVisible():
            return
        rw = self.plotter.ren_win
        ren = self.plotter.renderer
        fxaa = bool(ren.GetUseFXAA())
        self._settling = True
        try:
            actor.SetScale(1e-6, 1e-6, 1e-6)
            ren.SetUseFXAA(False)   # (nothing of it is seen)
            rw.SwapBuffersOff()     # (a frame not to be shown: the widget schedules no paint for it)
            rw.Render()
        except Exception:  # noqa: BLE001 - only the labels' first frame is at stake
            pass
        finally:
            rw.SwapBuffersOn()
            ren.SetUseFXAA(fxaa)
            actor.SetScale(1.0, 1.0, 1.0)
            self._settling = False

    def still_shown(self) -> bool:
        """The view shows a still picture drawn in a thread (tests and the benchmark ask)."""
        return self._still_label.isVisible()

    def still_pending(self) -> bool:
        """A new result's picture is on its way (its steps, or its thread)."""
        return bool(self._still_steps) or self._still_job is not None

    def keep_camera(self) -> bool:
        return bool(self.panel.keep_camera_check.isChecked())

    def show(self, geometry=None, moving: bool = False) -> None:
        """Draw the model's result (its drawing arrays ``geometry`` if made beforehand), frame it, render once.

        The first result gets the default oblique view; later ones keep the camera's direction
        (and, with "keep camera", the whole camera). ``moving``: one of a stream of results (a parameter
        slider held): drawn with the moving look, the still one coming back when the stream rests."""
        first = self.scene.mesh is None and self._mapping is None
        held = None if first or not self.keep_camera() else camera_state(self.plotter.camera)
        with self.scene.held_render(render=False):
            self.scene.set_complex(self.model.result, self.model.names, self.panel.model.view(), self.style(),
                                   geometry=geometry)
            if held is not None:    # (set_complex resets the camera to the new bounds)
                apply_camera(self.plotter.camera, held)
            self.clear_pick()
            self.apply_overlays(self.scene)
            self.apply_slice(render=False)
            if first:
                default_camera(self.plotter)
            elif not self.keep_camera():
                refit_camera(self.plotter)
            self.plotter.renderer.ResetCameraClippingRange()
            self.scene.set_moving(moving)
        self._mapping = self.panel.model.view().mapping
        if moving:
            self.render()
            self._settle.start()
        else:   # in short steps of their own (one render asked): the picture drawn in a thread, or the
            # window's unshown render and then its own
            self._drop_still()
            self.renders += 1
            self._fresh = self._still_in_thread()   # (the unshown render comes before the window's first)
            self._still_steps = [self._render_still] if self._fresh else [self._settle_window, self._render_still]
            self._still_step.start()

    def on_projection(self) -> None:
        """The angles, base or mapping changed: move the points in place (and re-slice a turning direction)."""
        if self.scene.complex is None:
            return
        pp = self.panel
        view = pp.model.view()
        moving = self.scene.moving_look_available()
        with self.scene.held_render(render=False):
            self.scene.set_projection(view, render=False, moving=moving)
            sw = pp.slice_window()
            if sw is not None and sw.hidden:    # the hidden directions turn with the view
                self.apply_slice(render=False)
            if self.scene.style.subtitle != self.style().subtitle:
                self.scene.set_style(self.style(), render=False)
            if view.mapping != self._mapping:   # another mapping: another extent
                self._mapping = view.mapping
                self.refit()
            else:
                self.keep_in_view()
            self.plotter.renderer.ResetCameraClippingRange()
        self.render()
        if moving:
            self._settle.start()

    def _camera_moving(self, on: bool) -> None:
        if not self.scene.moving_look_available():
            return
        if on:
            self._settle.stop()
            if self._fresh:
                self._settle_window()
            self.scene.set_moving(True)
        else:
            self._settle.start()

    def _at_rest(self) -> None:
        """The view stopped moving: the still look again (the full mesh, the scene's own lights)."""
        if self.scene.complex is None or not self.scene.moving_shown():
            return
        with self.scene.held_render(render=False):
            self.scene.set_moving(False)
            self.plotter.renderer.ResetCameraClippingRange()
        self.render()

    def _on_resized(self) -> None:
        if self.scene.complex is not None and not self.keep_camera():
            self.keep_in_view()
            self.render()

    def on_base(self) -> None:
        if self.scene.complex is None:
            return
        self.on_projection()
        self.refit(render=True)

    def refit(self, render: bool = False) -> None:
        """Frame the object again from the current direction (nothing with "keep camera")."""
        if self.keep_camera() or self.scene.complex is None:
            return
        refit_camera(self.plotter)
        if render:
            self.render()

    def keep_in_view(self) -> None:
        """Refit when the object left the picture (or ran under the title), or shrank to under half of
        what the picture could show; a turn that stays inside keeps the camera still."""
        if self.keep_camera() or self.scene.complex is None:
            return
        b = np.array(self.plotter.renderer.ComputeVisiblePropBounds(), dtype=float)
        if not np.all(np.isfinite(b)) or b[1] < b[0]:
            return
        corners = np.array([[x, y, z] for x in b[0:2] for y in b[2:4] for z in b[4:6]])
        S = screen_coordinates(self.plotter, corners)
        u = S[:, 0] - 0.5 * (S[:, 0].min() + S[:, 0].max())
        v = S[:, 1] - 0.5 * (S[:, 1].min() + S[:, 1].max())
        out = (np.abs(S[:, 0]).max() > 1.0 or S[:, 1].min() < -1.0 or S[:, 1].max() > TITLE_BOTTOM)
        small = max(np.abs(u).max() / MARGIN_X, np.abs(v).max() / MARGIN_Y) < 0.5
        if out or small:
            refit_camera(self.plotter)

    # ------------------------------------------------------------ steering hidden planes
    def can_turn(self) -> bool:
        return self.scene.complex is not None and self.panel.model.n >= 4

    def turn_hidden(self, dx: float, dy: float, hidden: int = 0) -> None:
        """Turn the screen's x by ``dx`` and y by ``dy`` (pixels of a drag) against hidden direction ``hidden``."""
        pm = self.panel.model
        if pm.n < 4 or (dx == 0 and dy == 0):
            return
        cam = self.plotter.camera
        right = np.cross(np.asarray(cam.direction, float), np.asarray(cam.up, float))
        right /= max(np.linalg.norm(right), 1e-12)
        up = np.asarray(cam.up, float) - np.dot(cam.up, right) * right
        up /= max(np.linalg.norm(up), 1e-12)
        hidden = hidden % (pm.n - 3)
        a = pm.angles.copy()
        if dx:
            pm.angles[:] = turned_angles(pm, right, hidden, DRAG_DEGREES * dx)
        if dy:
            pm.angles[:] = turned_angles(pm, up, hidden, DRAG_DEGREES * dy)
        new = pm.angles.copy()
        pm.angles[:] = a
        self.panel.set_angles(new)   # the sliders follow; projectionChanged redraws

    def on_style(self) -> None:
        if self.scene.complex is None:
            return
        st = self.style()
        old = self.scene.style
        if (st.color_by, st.title, st.subtitle, st.two_sided) == (old.color_by, old.title, old.subtitle,
                                                                    old.two_sided):
            self.scene.style = st
            self.scene.set_opacity(st.opacity, render=False)
            self.scene.set_show_edges(st.show_edges, render=False)
        else:
            self.scene.set_style(st, render=False)
        with self.scene.held_render(render=False):
            self.apply_overlays(self.scene)
        self.render()

    def on_slice(self) -> None:
        if self.scene.complex is not None:
            with self.scene.held_render(render=False):
                self.apply_slice(render=False)
                self.keep_in_view()
            self.render()

    def apply_overlays(self, scene: Scene) -> None:
        """Boundary facets, grid cubes and the picked cell on ``scene`` (this view's, or an off-screen copy)."""
        pp = self.panel
        if self.model.result is None or scene.complex is None:
            return
        problem = draw_overlays(scene, self.model.result, pp.boundary_check.isChecked(), pp.grid_check.isChecked(),
                                self.model.picked)
        if problem:
            self.model.set_status(problem, error=True)

    # ------------------------------------------------------------ slicing
    def slice_params(self, projection: ProjectionModel | None = None):
        """(window, u, lo, hi, c, w) of the View tab's slice for the result on screen, or None."""
        pp = self.panel
        return slice_params(pp.slice_window(), None if self.model.result is None else self.model.result.vertices,
                            projection or pp.model, pp.slice_fractions())

    def apply_slice(self, render: bool = True) -> None:
        pp = self.panel
        prm = self.slice_params()
        if prm is None:
            if self.scene.slice is not None:
                self.scene.set_slice(None, render=False)
            pp.set_slice_readout("")
        else:
            sw, u, lo, hi, c, w = prm
            k = self.scene.set_slice(u, c, w, render=False)
            what = sw.label(self.model.names)
            pp.set_slice_readout(f"{what} in [{c - w:.3g}, {c + w:.3g}] of [{lo:.3g}, {hi:.3g}] \u00b7 "
                                 f"{k:,} cells" + ("" if k else " (nothing here)"))
        if render:
            self.render()

    # ------------------------------------------------------------ picking
    def pick_cell(self, cell_id: int) -> dict:
        """Select cell ``cell_id`` (a 2-cell, or an edge of a curve) in the model and draw it."""
        from .geometry import cell_info

        cx = self.model.result
        if cx is None:
            raise ValueError("nothing to pick: no result yet")
        info = cell_info(cx, int(cell_id))
        self.model.set_picked(info)
        X, E = info["lines"]
        self.scene.set_overlay("pick", X, E, PICK_COLOR, width=5.0, render=False)
        self.render()
        return info

    def clear_pick(self) -> None:
        self.model.set_picked(None)
        self.scene.remove_overlay("pick", render=False)

    def pick_at(self, display_xy):
        """Pick the cell drawn at pixel (x, y) (from the bottom left); None if nothing is there."""
        cid = self.scene.cell_at(display_xy)
        if cid is None:
            self.clear_pick()
            self.render()
            return None
        return self.pick_cell(cid)

    # ------------------------------------------------------------ camera and pictures
    def camera_session(self) -> dict:
        """The camera and the "keep camera" toggle, for a session file (:func:`gcmh_studio.studio_io.session_dict`)."""
        return {"camera": camera_state(self.plotter.camera), "keep_camera": self.keep_camera()}

    def restore_camera(self, camera: dict | None, keep: bool) -> None:
        """A session's camera (:func:`gcmh_studio.studio_io.session_camera`) as it was saved, and the "keep camera"
        toggle as the user left it (held, later results and changes of mapping leave the camera alone)."""
        self.panel.keep_camera_check.setChecked(bool(keep))
        camera = valid_camera(camera)
        if camera is not None and self.scene.complex is not None:
            apply_camera(self.plotter.camera, camera)
            self.plotter.renderer.ResetCameraClippingRange()
        self.render()

    def reset_camera(self) -> None:
        """The default oblique view, framed."""
        default_camera(self.plotter)
        self.render()

    def size(self) -> tuple[int, int]:
        return self.widget.width(), self.widget.height()

    def screenshot_array(self) -> np.ndarray:
        """The current view as an (h, w, 3) uint8 array."""
        if self._still_steps or self._fresh:   # a new result not drawn yet: its unshown render first
            self._settle_window()
        self._at_rest()
        self.plotter.render()
        return self.plotter.screenshot(return_img=True)

    def save_screenshot(self, path, size=None, transparent: bool = False) -> np.ndarray:
        """Write a PNG of the current view at ``size`` (w, h) pixels, re-rendered off screen."""
        size = tuple(int(s) for s in (size or self.size()))
        self._at_rest()
        return render_image(self.scene, path, size=size, transparent=transparent, camera=self.plotter.camera,
                            fit=not self.keep_camera(), camera_size=self.size(), decorate=self._decorate)

    def _decorate(self, plotter) -> None:
        for draw in self.picture_decorators:
            draw(plotter)

    def write_animation(self, path, frames, window, projection: ProjectionModel, size, fps: float,
                        progress=None, cancel=None) -> int:
        """Render ``frames`` of this view off screen (the camera copied, the window untouched) to ``path``."""
        from .headless import offscreen_scene, write_frames

        with offscreen_scene(size) as sc:
            sc.set_complex(self.model.result, self.model.names, projection.view(), copy.copy(self.scene.style),
                           geometry=self.scene.geometry)
            self.apply_overlays(sc)
            copy_camera(self.plotter.camera, sc.plotter.camera)
            if not self.keep_camera():   # the window's direction, framed for this picture's shape
                refit_camera(sc.plotter)
            self._decorate(sc.plotter)
            return write_frames(sc, projection, frames, window, [path], fps, progress=progress, cancel=cancel)
