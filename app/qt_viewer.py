"""QtViewer: the studio's 3D view (napari's QtViewer, in small).

A ``pyvistaqt.QtInteractor`` drawn by an :class:`gcmh_studio.scene.Scene`, from what
the :class:`gcmh_studio.model.StudioModel` holds (the result, the picked cell, the
projection, the style, the slice and the overlays), redrawn on the model's events:
the projection in place, picking a cell, the camera, and pictures of the view.
Only the GUI thread touches it; problems go to the model's status line.

Never frozen: a new result is drawn with one render (pyvista would render after
every actor it adds) in short GUI steps of their own; a see-through result's still
picture (0.3 s of software GL for the three-torus) is drawn in a worker process from an
off-screen copy (:class:`gcmh_studio.qt_still_picture.QtStillPicture`) and shown over the view until the view
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
the right button, against the next one (:class:`gcmh_studio.qt_drag_turn.QtDragTurn`).
"""

from __future__ import annotations

import copy

import numpy as np
from qtpy.QtCore import QTimer

from .angles import angle_look
from .camera import (
    MARGIN_X,
    MARGIN_Y,
    TITLE_BOTTOM,
    copy_camera,
    default_camera,
    refit_camera,
    screen_coordinates,
)
from .inputs import format_value
from .labels import labels_for, view_subtitle, warm_labels
from .model import StudioModel, slice_params
from .offscreen import render_image
from .overlays import PICK_COLOR, draw_overlays
from .projection import ProjectionModel
from .qt_drag_turn import QtDragTurn
from .qt_linkage_inset import QtLinkageInset, linkage_of, picked_angles
from .qt_still_picture import QtStillPicture
from .qt_waiting_picture import QtWaitingPicture
from .scene import Scene, Style
from .sections import SectionScene
from .studio_io import apply_camera, camera_state, valid_camera

SETTLE_MS = 250          # a view at rest this long is drawn in full again


class QtViewer:
    """The view of ``model``; ``widget`` goes into the window's layout."""

    def __init__(self, model: StudioModel, parent=None):
        from pyvistaqt import QtInteractor

        self.model = model
        # no multi-sampling: with software GL it doubles every frame; FXAA smooths the edges instead
        self.plotter = QtInteractor(parent, auto_update=False, multi_samples=0)
        self.widget = self.plotter.interactor
        self.scene: Scene = SectionScene(self.plotter, anti_aliasing="fxaa")   # a sliced solid shows its section
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
        self.linkage = QtLinkageInset(self.widget)   # the rods at a picked point of a linkage's surface
        # the example's picture (and the wait's word) until its first result is drawn: never a blank view
        self.waiting = QtWaitingPicture(self)
        model.events.system.connect(self.waiting.on_system)
        self._wait_note = QTimer(self.widget)
        self._wait_note.setInterval(500)
        self._wait_note.timeout.connect(self._show_wait_note)
        self._wait_note.start()
        self._drag = QtDragTurn(self)
        self.widget.installEventFilter(self._drag)
        # a see-through result's still picture is drawn in a worker process and shown over the view until
        # the view renders again
        self.still = QtStillPicture(self)
        self.still.cover = self.waiting     # (it goes when the first result's picture is on screen)
        self.angles = angle_look(model)
        self.angles.changed.connect(self.on_angles)
        ev = model.events   # (the view's own listeners come before the presentation's relays)
        for signal, slot in ((ev.projection, self.on_projection), (ev.base, self.on_base), (ev.style, self.on_style),
                             (ev.slice, self.on_slice)):
            signal.connect(slot, priority=1)
        try:   # turning the camera with the mouse draws the moving look too, the still one when let go
            style = self.plotter.iren.interactor.GetInteractorStyle()
            style.AddObserver("StartInteractionEvent", lambda *a: self._camera_moving(True))
            style.AddObserver("EndInteractionEvent", lambda *a: self._camera_moving(False))
        except Exception:  # noqa: BLE001 - a convenience
            pass

    # ------------------------------------------------------------ drawing
    def style(self) -> Style:
        """The View tab's style for the result on screen (title and subtitle included)."""
        st, p = self.model.style, self.model.projection
        two = st.two_sided
        mapping = p.mapping if p.n >= 4 else "orthographic"
        # an example's labels are found by its title; a system typed in complex mode brings its own ("u = Re w")
        labels = labels_for(self.model.title, self.model.names) or dict(self.model.labels or {})
        sub = view_subtitle(self.model.result, self.model.names, st.color_by, two, mapping, labels)
        params = (self.model.result.meta.get("params") if self.model.result is not None else None) or {}
        if params:   # the picture says at which values it was made (a class watching a slider reads them)
            sub = "  ".join(f"{p} = {format_value(v)}" for p, v in params.items()) + " \u00b7 " + sub
        return Style(color_by=st.color_by, opacity=st.opacity, show_edges=st.show_edges,
                     title=self.model.title, subtitle=sub, two_sided=two, labels=labels,
                     circles=self.angles.circles, seam=self.angles.seam)

    def render(self) -> None:
        """Ask for one render of the window: Qt paints it once, however many changes came before
        (``plotter.render()`` renders now and then once more in the paint it schedules)."""
        self.renders += 1
        self.still.drop()
        if self.still.fresh:
            self.still.settle()
        self.widget.update()

    # the still picture, as the tests and the benchmark ask
    def still_shown(self) -> bool:
        return self.still.shown()

    def still_pending(self) -> bool:
        return self.still.pending()

    @property
    def still_image(self) -> np.ndarray | None:
        return self.still.image

    @property
    def still_off_thread(self) -> bool:
        return self.still.off_thread

    @still_off_thread.setter
    def still_off_thread(self, on: bool) -> None:
        self.still.off_thread = bool(on)

    @property
    def _still_job(self):
        return self.still.job

    def keep_camera(self) -> bool:
        return bool(self.model.style.keep_camera)

    def drawn(self) -> bool:
        """The model's result is the one drawn (a new one is drawn by :meth:`show`, not by the events that
        set up its view)."""
        # (the scene draws a copy of a result with identified axes: its source is the model's)
        return self.scene.complex is not None and self.scene.source is self.model.result

    def show(self, geometry=None, moving: bool = False) -> None:
        """Draw the model's result (its drawing arrays ``geometry`` if made beforehand), frame it, render once.

        The first result gets the default oblique view; later ones keep the camera's direction
        (and, with "keep camera", the whole camera). ``moving``: one of a stream of results (a parameter
        slider held): drawn with the moving look, the still one coming back when the stream rests."""
        first = self.scene.mesh is None and self._mapping is None
        held = None if first or not self.keep_camera() else camera_state(self.plotter.camera)
        with self.scene.held_render(render=False):
            self.scene.set_complex(self.model.result, self.model.names, self.model.projection.view(), self.style(),
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
        self._mapping = self.model.projection.view().mapping
        if moving:
            self.waiting.hide()
            self.render()
            self._settle.start()
        else:   # in short steps of their own (one render asked): the picture drawn in a thread, or the
            # window's unshown render and then its own
            self.renders += 1
            self.still.start()

    def on_projection(self) -> None:
        """The angles, base or mapping changed: move the points in place (and re-slice a turning direction)."""
        if not self.drawn():
            return
        view = self.model.projection.view()
        moving = self.scene.moving_look_available()
        with self.scene.held_render(render=False):
            self.scene.set_projection(view, render=False, moving=moving)
            sw = self.model.slice.window()
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
            if self.still.fresh:
                self.still.settle()
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

    def _show_wait_note(self) -> None:
        """The warm-up's notice under the waiting picture (nothing once the kernels are ready)."""
        from .jobs import current_warm_up

        warm = current_warm_up()
        self.waiting.set_note(warm.notice() if warm is not None else "")
        if warm is None or not warm.running():
            self._wait_note.stop()

    def _on_resized(self) -> None:
        self.linkage.place()
        if self.waiting.shown():
            self.waiting.show()
        if self.scene.complex is not None and not self.keep_camera():
            self.keep_in_view()
            self.render()

    def on_base(self) -> None:
        if not self.drawn():
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

    def on_style(self) -> None:
        if not self.drawn():
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

    def on_angles(self) -> None:
        """Angles as circles or as numbers, the seam shown or not: another extent, so a refit."""
        if not self.drawn():
            return
        with self.scene.held_render(render=False):
            self.scene.set_angle_look(self.angles.circles, self.angles.seam, render=False)
            self.apply_slice(render=False)
            self.refit()
            self.plotter.renderer.ResetCameraClippingRange()
        self.render()

    def on_slice(self) -> None:
        """The slice moved: re-cut, drawn with the moving look until the slider rests (a step's cost halved)."""
        if not self.drawn():
            return
        moving = self.scene.moving_look_available()
        with self.scene.held_render(render=False):
            self.apply_slice(render=False)
            self.keep_in_view()
            if moving:
                self.scene.set_moving(True)
        self.render()
        if moving:
            self._settle.start()   # (restarted: the still look comes back once the slider rests)

    def apply_overlays(self, scene: Scene) -> None:
        """Boundary facets, grid cubes and the picked cell on ``scene`` (this view's, or an off-screen copy)."""
        st = self.model.style
        if self.model.result is None or scene.complex is None:
            return
        problem = draw_overlays(scene, self.model.result, st.boundary, st.grid, self.model.picked)
        if problem:
            self.model.set_status(problem, error=True)

    # ------------------------------------------------------------ slicing
    def slice_params(self, projection: ProjectionModel | None = None):
        """(window, u, lo, hi, c, w) of the View tab's slice for the result on screen, or None."""
        m = self.model
        return slice_params(m.slice.window(), None if m.result is None else m.result.vertices,
                            projection or m.projection, (m.slice.c, m.slice.w))

    def apply_slice(self, render: bool = True) -> None:
        prm = self.slice_params()
        if prm is None:
            if self.scene.slice is not None:
                self.scene.set_slice(None, render=False)
            self.model.set_slice_readout("")
        else:
            sw, u, lo, hi, c, w = prm
            k = self.scene.set_slice(u, c, w, render=False)
            what = sw.label(self.model.names)
            self.model.set_slice_readout(f"{what} in [{c - w:.3g}, {c + w:.3g}] of [{lo:.3g}, {hi:.3g}] \u00b7 "
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
        closing = linkage_of(cx)
        if closing is not None:   # a linkage's surface: the rods as they are held at this point
            self.linkage.show_configuration(picked_angles(cx, info["coords"]), self.model.names, closing)
        X, E = info["lines"]
        self.scene.set_overlay("pick", X, E, PICK_COLOR, width=5.0, render=False)
        self.render()
        return info

    def clear_pick(self) -> None:
        self.model.set_picked(None)
        self.linkage.hide()
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
    def restore_camera(self, camera: dict | None, keep: bool) -> None:
        """A session's camera (:func:`gcmh_studio.studio_io.session_camera`) as it was saved, and the "keep camera"
        toggle as the user left it (held, later results and changes of mapping leave the camera alone)."""
        self.model.set_style(keep_camera=bool(keep))
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
        if self.still.steps or self.still.fresh:   # a new result not drawn yet: its unshown render first
            self.still.settle()
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
