"""QtViewer: the studio's 3D view (napari's QtViewer, in small).

A ``pyvistaqt.QtInteractor`` drawn by an :class:`app.scene.Scene`, from what
the :class:`app.model.StudioModel` holds (the result, the picked cell) and what
the View tab (:class:`app.qt_projection_panel.QtProjectionPanel`) sets: the
projection in place, the style, the slice and the overlays, picking a cell,
the camera, and pictures of the view. Only the GUI thread touches it; problems
go to the model's status line.
"""

from __future__ import annotations

import copy

import numpy as np

from .model import StudioModel, slice_params
from .projection import ProjectionModel
from .scene import PICK_COLOR, Scene, Style, copy_camera, default_camera, draw_overlays, render_image, view_subtitle


class QtViewer:
    """The view of ``model`` as the View tab ``panel`` asks; ``widget`` goes into the window's layout."""

    def __init__(self, model: StudioModel, panel, parent=None):
        from pyvistaqt import QtInteractor

        self.model = model
        self.panel = panel
        self.plotter = QtInteractor(parent, auto_update=False)
        self.widget = self.plotter.interactor
        self.scene = Scene(self.plotter)

    # ------------------------------------------------------------ drawing
    def style(self) -> Style:
        """The View tab's style for the result on screen (title and subtitle included)."""
        pp = self.panel
        two = pp.two_sided_check.isChecked()
        mapping = pp.model.mapping if pp.model.n >= 4 else "orthographic"
        sub = view_subtitle(self.model.result, self.model.names, pp.color_by(), two, mapping)
        return Style(color_by=pp.color_by(), opacity=pp.opacity(), show_edges=pp.show_edges(),
                     title=self.model.title, subtitle=sub, two_sided=two)

    def show(self, geometry=None) -> None:
        """Draw the model's result (its drawing arrays ``geometry`` if made beforehand) and fit the camera."""
        self.scene.set_complex(self.model.result, self.model.names, self.panel.model.view(), self.style(),
                               geometry=geometry)
        self.clear_pick()
        self.apply_overlays(self.scene)
        self.apply_slice(render=False)
        self.reset_camera()

    def on_projection(self) -> None:
        """The angles, base or mapping changed: move the points in place (and re-slice a turning direction)."""
        if self.scene.complex is None:
            return
        pp = self.panel
        self.scene.set_projection(pp.model.view(), render=False)
        sw = pp.slice_window()
        if sw is not None and sw.hidden:    # the hidden directions turn with the view
            self.apply_slice(render=False)
        if self.scene.style.subtitle != self.style().subtitle:
            self.scene.set_style(self.style(), render=False)
        self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.render()

    def on_base(self) -> None:
        if self.scene.complex is None:
            return
        self.on_projection()
        self.reset_camera()

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
        self.apply_overlays(self.scene)
        self.plotter.render()

    def on_slice(self) -> None:
        if self.scene.complex is not None:
            self.apply_slice()

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
            self.plotter.render()

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
        self.plotter.render()
        return info

    def clear_pick(self) -> None:
        self.model.set_picked(None)
        self.scene.remove_overlay("pick", render=False)

    def pick_at(self, display_xy):
        """Pick the cell drawn at pixel (x, y) (from the bottom left); None if nothing is there."""
        cid = self.scene.cell_at(display_xy)
        if cid is None:
            self.clear_pick()
            self.plotter.render()
            return None
        return self.pick_cell(cid)

    # ------------------------------------------------------------ camera and pictures
    def reset_camera(self) -> None:
        default_camera(self.plotter)
        self.plotter.render()

    def size(self) -> tuple[int, int]:
        return self.widget.width(), self.widget.height()

    def screenshot_array(self) -> np.ndarray:
        """The current view as an (h, w, 3) uint8 array."""
        self.plotter.render()
        return self.plotter.screenshot(return_img=True)

    def save_screenshot(self, path, size=None, transparent: bool = False) -> np.ndarray:
        """Write a PNG of the current view at ``size`` (w, h) pixels, re-rendered off screen."""
        size = tuple(int(s) for s in (size or self.size()))
        return render_image(self.scene, path, size=size, transparent=transparent, camera=self.plotter.camera)

    def write_animation(self, path, frames, window, projection: ProjectionModel, size, fps: float,
                        progress=None, cancel=None) -> int:
        """Render ``frames`` of this view off screen (the camera copied, the window untouched) to ``path``."""
        from .headless import offscreen_scene, write_frames

        with offscreen_scene(size) as sc:
            sc.set_complex(self.model.result, self.model.names, projection.view(), copy.copy(self.scene.style),
                           geometry=self.scene.geometry)
            self.apply_overlays(sc)
            copy_camera(self.plotter.camera, sc.plotter.camera)
            return write_frames(sc, projection, frames, window, [path], fps, progress=progress, cancel=cancel)
