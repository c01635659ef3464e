"""Drawing a CellComplex through a projection on any pyvista plotter (no Qt here).

:class:`Scene` owns one pyvista mesh built once per result from an
:class:`gcmh_studio.geometry.Geometry`: lines for curves (dim 1), filled polygons for
surfaces (dim 2), the 2-skeleton for higher dimensions. Moving a projection
slider calls :meth:`Scene.set_projection`, which writes the projected points
(and, for surfaces, the vertex normals of the projected mesh) in place into the
mesh's VTK arrays and re-renders: no new mesh, no new actor, same topology.

A slice (:meth:`Scene.set_slice`) clips the oriented loops of the full result
to a window of a linear functional (:mod:`gcmh_studio.slicing`) and draws that instead:
new topology, so a new mesh, but the same centre and scales, so nothing jumps.
Overlays (boundary facets, the grid cubes, a picked cell) are small line meshes
projected with the same view and clipped by the same slice.

A view is a :class:`gcmh_studio.projection.View` (or a plain (3, n) matrix: linear).
Nonlinear views get their normals from the projected mesh
(:class:`gcmh_studio.geometry.MeshNormals`), linear ones from the bivectors.

The same class renders into the Qt window (a ``pyvistaqt.QtInteractor``) and
into an off-screen ``pyvista.Plotter`` for headless screenshots and animations,
and (:class:`StillJob`) into one in a thread for the window's still picture.
"""

from __future__ import annotations

import copy
import threading
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
import pyvista as pv

from .geometry import Geometry, boundary_lines, display_complex, grid_cube_lines
from .projection import Projector, View
from .slicing import clip_polygons, clip_segments

BACKGROUND = "#1f2430"
BACKGROUND_TOP = "#4a5468"
SURFACE_COLOR = "#d9a441"
LINE_COLOR = "#f0c05a"
BACK_COLOR = "#3f7fd0"       # back faces when two-sided colouring is on
BOUNDARY_COLOR = "#ff4d6d"
GRID_COLOR = "#9fb3d9"
PICK_COLOR = "#40ff90"
CMAP = "viridis"
MOVING_LIGHT = 0.85          # the moving look's one headlight: as bright as the light kit (the three-torus,
                             # still and moving frames compared: the least mean difference, 0.8 of 255)



def colour_range(values) -> list[float]:
    """The colour bar's range for these values: their min and max, widened by 1 when they
    are all equal, and made symmetric when within 1% of it (the complex cosine's
    -1.5701 .. 1.5698 put "-0.00" in the middle of the bar, under a teacher's eyes)."""
    lo, hi = float(np.min(values)), float(np.max(values))
    if hi <= lo:
        return [lo, lo + 1.0]
    if abs(lo + hi) <= 0.01 * (hi - lo):
        m = max(-lo, hi)
        return [-m, m]
    return [lo, hi]


@dataclass
class Style:
    """How the mesh is drawn; everything a user can change without a new run."""

    color_by: str | None = None      # a variable name, or None for a solid colour
    cmap: str = CMAP
    opacity: float | None = None     # None: 1 for curves and surfaces, 0.35 above
    show_edges: bool | None = None   # None: off for surfaces, on above
    line_width: float = 5.0
    title: str = ""
    subtitle: str = ""
    scalar_bar: bool = True
    axes: bool = True
    two_sided: bool = False          # front faces SURFACE_COLOR, back faces BACK_COLOR (no colour map)
    slice_context: bool = True      # while slicing, the whole result as a faint ghost
    labels: dict = field(default_factory=dict)   # variable -> its meaning ("y" -> "Im z"), from the example
    extra: dict = field(default_factory=dict)

    def label(self, name: str) -> str:
        """``name``, with its meaning when the example gives one: "y = Im z"."""
        meaning = self.labels.get(name)
        return f"{name} = {meaning}" if meaning else name

    def resolved_opacity(self, dim: int) -> float:
        if self.opacity is not None:
            return float(self.opacity)
        return 1.0 if dim <= 2 else 0.35

    def resolved_edges(self, dim: int) -> bool:
        if self.show_edges is not None:
            return bool(self.show_edges)
        return dim >= 3


class Scene:
    """One projected complex on a pyvista plotter.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    """

    def __init__(self, plotter, anti_aliasing: str | None = "fxaa"):
        self.plotter = plotter
        self.complex = None
        self.names: list[str] = []
        self.mesh: pv.PolyData | None = None
        self.actor = None
        self.style = Style()
        self.projector: Projector | None = None
        self._pts = None
        self._normals = None
        self._normal_field = None
        self._P = None
        self._axes_actor = None
        self._title_actor = None
        self._subtitle_actor = None
        self._legend_actor = None
        self._bar_title = None
        self.geometry: Geometry | None = None      # of the whole result
        self.draw_geo: Geometry | None = None      # what is drawn (the slice, or the whole)
        self.view: View | None = None
        self.slice: tuple | None = None            # (direction (n,), c, w) or None
        self._mesh_normals = None
        # name -> [Geometry-like (projector, cells, kind), mesh, actor, color]
        self.overlays: dict = {}
        self._overlay_src: dict = {}               # name -> (vertices (m, n), edges (E, 2)) before slicing
        self._ghost = None                         # (mesh, actor): the whole result, faint, while slicing
        self._coarse = None                        # (geometry, mesh, actor, normals array): drawn while moving
        self._coarse_on = False
        self._still_lights = None                  # the renderer's lights while one headlight stands in for them
        self._fxaa_paused = False                  # FXAA off while the view moves
        self._actor_kw: dict = {}
        plotter.set_background(BACKGROUND, top=BACKGROUND_TOP)
        self.anti_aliasing = None
        self.set_anti_aliasing(anti_aliasing)
        try:   # a render here waits for a still picture drawing in the background (:class:`StillJob`)
            plotter.ren_win.AddObserver("StartEvent", lambda *a: wait_background())
        except AttributeError:  # (a plotter without a render window)
            pass

    def set_anti_aliasing(self, kind: str | None) -> None:
        """"fxaa" (cheap: the window), "ssaa" (four times the pixels: screenshots) or None.

        Super-sampling multiplies a software render's cost by four to eight (three-torus:
        0.3 s -> 4 s a frame), so only pictures that are kept pay for it."""
        if kind == self.anti_aliasing:
            return
        import warnings

        try:
            self.plotter.disable_anti_aliasing()
            if kind:
                with warnings.catch_warnings():   # EGL builds warn that FXAA falls back to SSAA
                    warnings.simplefilter("ignore")
                    self.plotter.enable_anti_aliasing(kind)
        except Exception:  # noqa: BLE001 - not every render window supports it
            pass
        self.anti_aliasing = kind

    @contextmanager
    def held_render(self, render: bool = True):
        """Draw nothing inside the block (pyvista renders after every added actor and camera
        reset: a new result cost seven renders); then one render when ``render``."""
        pl = self.plotter
        if getattr(pl, "_gcmh_held", False):   # already held: the outer block renders
            yield
            return
        saved = vars(pl).get("render")          # an instance's own render (a test's counter) comes back
        pl.render = lambda *a, **k: None
        pl._gcmh_held = True
        try:
            yield
        finally:
            pl._gcmh_held = False
            if saved is None:
                del pl.render
            else:
                pl.render = saved
        if render:
            pl.render()

    # ------------------------------------------------------------------ build
    @property
    def dim(self) -> int:
        return 0 if self.complex is None else int(self.complex.dim)

    def clear(self) -> None:
        if self.actor is not None:
            self.plotter.remove_actor(self.actor, render=False)
        self._remove_bar()
        self.actor = None
        self.mesh = None
        self.complex = None
        self.projector = None
        self._pts = self._normals = self._normal_field = None
        self.geometry = self.draw_geo = None
        self.slice = None
        self._mesh_normals = None
        self._drop_coarse()
        self._still_light(True)
        self._set_ghost(False)
        for name in list(self.overlays):
            self.remove_overlay(name, render=False)
        self._overlay_src.clear()

    def set_complex(self, cx, names, P, style: Style | None = None,
                    geometry: Geometry | None = None) -> None:
        """Build the mesh of ``cx`` (a CellComplex) under view ``P`` (a View or a (3, n) matrix) and show it.

        ``geometry``: :meth:`Geometry.build` of ``cx`` if already made (the worker makes it
        off the GUI thread); otherwise it is built here.
        """
        self.clear()
        if style is not None:
            self.style = style
        if cx.count(0) == 0:   # nothing to draw (pyvista refuses empty meshes)
            self._set_title()
            return
        geo = geometry if geometry is not None else Geometry.build(cx)
        cx = display_complex(cx)  # (seams of identified axes drawn whole: the geometry's own vertices)
        self.complex = cx
        self.names = list(names)
        self.geometry = geo
        self._set_view(P)
        self._show_geometry(geo, np.asarray(cx.vertices))
        self._update_axes_labels()
        self.plotter.renderer.reset_camera(render=False)   # (the plotter's wrapper renders)

    def _set_view(self, P) -> None:
        if isinstance(P, View):
            self.view = P
        else:
            P = np.asarray(P, dtype=float)
            self.view = View(np.asarray(P, dtype=float), "orthographic")
        self._P = np.asarray(self.view.P, dtype=float)

    def _show_geometry(self, geo: Geometry, V: np.ndarray) -> None:
        """Make the mesh for ``geo`` (vertices ``V`` (V, n) for the colour data) and its actor."""
        self.draw_geo = geo
        self.projector = geo.projector
        self._mesh_normals = None
        if geo.projector.XT.shape[1] == 0 or len(geo.cells) == 0:   # an empty slice: draw nothing
            if self.actor is not None:
                self.plotter.remove_actor(self.actor, render=False)
            self._remove_bar()
            self.actor = None
            self.mesh = None
            self._pts = self._normals = self._normal_field = None
            return
        pts = self.projector.project_view(self.view)
        if geo.kind == "lines":
            mesh = pv.PolyData(pts, lines=geo.cells)
        else:
            mesh = pv.PolyData(pts, faces=geo.cells)
        self._normal_field = geo.normals
        if self._normal_field is not None:
            mesh.point_data["Normals"] = np.zeros((len(V), 3), dtype=np.float32)
            mesh.point_data.active_normals_name = "Normals"
        for i, name in enumerate(self.names):
            mesh.point_data[name] = np.ascontiguousarray(V[:, i])
        mesh.cell_data["cell_id"] = np.asarray(geo.cell_ids if geo.cell_ids is not None
                                                else np.arange(mesh.n_cells), dtype=np.int64)
        self.mesh = mesh
        self._pts = mesh.points  # a view of the VTK buffer: written in place
        self._normals = mesh.point_data["Normals"] if self._normal_field is not None else None
        self._write_normals()
        self._add_actor()

    def detached(self) -> Scene:
        """A copy for another thread to draw with :meth:`adopt`: its meshes deep copies, sharing no VTK object
        with this scene (the GUI thread goes on moving this one's points), and no plotter of its own."""
        other = copy.copy(self)
        other.plotter = other.actor = None
        other._axes_actor = other._title_actor = other._subtitle_actor = other._legend_actor = None
        other._bar_title = None
        other._coarse, other._coarse_on, other._still_lights, other._fxaa_paused = None, False, None, False
        other.style = copy.copy(self.style)
        other._P = None if self._P is None else np.array(self._P)
        if self.mesh is not None:
            other.mesh = self.mesh.copy(deep=True)
            other._pts = other.mesh.points
            other._normals = other.mesh.point_data["Normals"] if self._normals is not None else None
        other._ghost = None if self._ghost is None else (self._ghost[0].copy(deep=True), None)
        other.overlays = {name: [geo, None if mesh is None else mesh.copy(deep=True), None, color, width]
                          for name, (geo, mesh, _actor, color, width) in self.overlays.items()}
        other._overlay_src = dict(self._overlay_src)
        return other

    def adopt(self, other: Scene, style: Style | None = None) -> None:
        """Show the mesh of another scene (shared, not copied) with its projection."""
        self.complex = other.complex
        self.names = list(other.names)
        self.mesh = other.mesh
        self.projector = other.projector
        self._pts, self._normals, self._normal_field = other._pts, other._normals, other._normal_field
        self._P = other._P
        self.view, self.geometry, self.draw_geo, self.slice = other.view, other.geometry, other.draw_geo, other.slice
        self.style = style if style is not None else other.style
        self._add_actor()
        if other._ghost is not None:
            m = other._ghost[0]
            self._ghost = (m, self.plotter.add_mesh(m, color="#c8d2e6", opacity=0.07, lighting=False, pickable=False,
                                                    render=False, reset_camera=False, name="gcmh-slice-ghost"))
        for name, (geo, mesh, _actor, color, width) in other.overlays.items():
            self.overlays[name] = [geo, mesh, self._add_overlay_actor(name, mesh, color, width), color, width]
        self._update_axes_labels()

    def _add_actor(self) -> None:
        if self.mesh is None:
            return
        if self.actor is not None:
            self.plotter.remove_actor(self.actor, render=False)
            self.actor = None
        self._remove_bar()
        st = self.style
        dim = self.dim
        color_by = st.color_by if st.color_by in self.names else None
        two_sided = st.two_sided and dim >= 2
        if two_sided:
            color_by = None   # a colour map would paint both sides alike
        kw = dict(
            opacity=st.resolved_opacity(dim),
            show_edges=st.resolved_edges(dim) and dim >= 2,
            edge_color="#202020",
            line_width=st.line_width if dim <= 1 else 0.6,
            smooth_shading=False,
            render=False,
            reset_camera=False,
            name="gcmh-complex",
            specular=0.12,
            specular_power=40.0,
            diffuse=0.85,
            ambient=0.18,
        )
        if dim <= 1:
            kw["render_lines_as_tubes"] = True
            kw["ambient"] = 0.35
        if color_by is not None:
            # the whole result's range: a slice or a sweep keeps its colours
            col = np.asarray(self.complex.vertices)[:, self.names.index(color_by)]
            col = col[np.isfinite(col)]
            if len(col):
                kw["clim"] = colour_range(col)
            kw.update(scalars=color_by, cmap=st.cmap, show_scalar_bar=st.scalar_bar,
                      scalar_bar_args=dict(title=st.label(color_by), vertical=True, title_font_size=self._font(36),
                                           label_font_size=self._font(26), n_labels=5, fmt="%.2f",
                                           position_x=0.9, position_y=0.2, width=0.045,
                                           height=0.6, color="white", bold=False,
                                           unconstrained_font_size=True))
            self._bar_title = st.label(color_by) if st.scalar_bar else None
        else:
            kw["color"] = SURFACE_COLOR if dim >= 2 else LINE_COLOR
            kw["show_scalar_bar"] = False
        if two_sided:
            kw["backface_params"] = dict(color=BACK_COLOR)
        self._drop_coarse()
        self._actor_kw = {k: v for k, v in kw.items() if k not in ("show_scalar_bar", "scalar_bar_args", "name")}
        self.actor = self.plotter.add_mesh(self.mesh, **kw)
        if self._bar_title is not None:
            try:
                bar = self.plotter.scalar_bars[self._bar_title]
            except (KeyError, AttributeError):
                bar = None
            if bar is not None:
                bar.SetTextPosition(0)          # labels and title below the bar, never over it
                bar.SetTitleRatio(1.0)
        if self._normals is not None:
            self.actor.prop.interpolation = "phong"
        self.mesh.set_active_scalars(color_by) if color_by else None
        self._set_title()

    def _remove_bar(self) -> None:
        if self._bar_title is not None:
            try:
                self.plotter.remove_scalar_bar(self._bar_title, render=False)
            except Exception:  # noqa: BLE001 - already gone
                pass
            self._bar_title = None

    def _set_title(self) -> None:
        for a in (self._title_actor, self._subtitle_actor):
            if a is not None:
                self.plotter.remove_actor(a, render=False)
        self._title_actor = self._subtitle_actor = None
        if self.style.title:
            self._title_actor = self.plotter.add_text(self.style.title, position=(0.02, 0.925), viewport=True,
                                                      font_size=self._font(18), color="white", name="gcmh-title")
        if self.style.subtitle:
            self._subtitle_actor = self.plotter.add_text(self.style.subtitle, position=(0.02, 0.885), viewport=True,
                                                         font_size=self._font(11), color="#c8cfdc",
                                                         name="gcmh-subtitle")

    # ----------------------------------------------------------- fast update
    def set_projection(self, P, render: bool = True, moving: bool = False) -> None:
        """Write the points (and normals) for view ``P`` (a View or a (3, n) matrix) in place.

        ``moving``: draw the moving look (:meth:`set_moving`), e.g. while a slider moves; the
        still look comes back, the full mesh's points written, when asked again without it. A
        slice along a direction that depends on the view is the caller's to redo
        (:meth:`set_slice`); overlays follow here.
        """
        self._set_view(P)
        coarse = moving and self.lod_available()
        self._still_light(not (moving and self.see_through()))
        self._still_fxaa(not moving)
        if coarse:
            self._show_coarse()
        else:
            self._hide_coarse()
            if self.mesh is not None:
                self.projector.project_view(self.view, out=self._pts)
                self.mesh.GetPoints().Modified()
                self._write_normals()
                self.mesh.Modified()
        if self._ghost is not None:
            self.geometry.projector.project_view(self.view, out=self._ghost[0].points)
            self._ghost[0].GetPoints().Modified()
            self._ghost[0].Modified()
        for geo, mesh, *_ in self.overlays.values():
            if mesh is not None:
                geo.projector.project_view(self.view, out=mesh.points)
                mesh.GetPoints().Modified()
                mesh.Modified()
        self._update_axes_labels()
        if render:
            self.plotter.renderer.ResetCameraClippingRange()
            self.plotter.render()

    # ------------------------------------------------------- the moving look
    # While the view moves (a slider, a drag, a parameter) it is drawn cheaper, and exactly as before once
    # it rests: a very large result by its coarse copy; a see-through one lit by one headlight instead of
    # the five lights of pyvista's light kit (software GL shades every layer of every pixel for each light:
    # a three-torus slider step takes about half the time, its edges and colours as they were); and
    # without FXAA, a full-screen pass that took 24 of a 38 ms render of a small result under Xvfb.
    def set_moving(self, on: bool) -> None:
        """The moving look (``on``) or the still one, for the points as they are (a camera drag)."""
        if self.complex is None:
            return
        if on and self.lod_available():
            self._show_coarse()
        elif not on and self._coarse_on:
            self.set_projection(self.view, render=False)
        self._still_light(not (on and self.see_through()))
        self._still_fxaa(not on)

    def moving_look_available(self) -> bool:
        """The result on screen has a moving look cheaper than its still one."""
        return self.lod_available() or self.see_through() or self.anti_aliasing == "fxaa"

    def moving_shown(self) -> bool:
        return self._coarse_on or self._still_lights is not None or self._fxaa_paused

    def _still_fxaa(self, still: bool) -> None:
        """FXAA as the scene was set up (``still``), or off while moving."""
        if self.anti_aliasing != "fxaa" or still != self._fxaa_paused:
            return
        self.plotter.renderer.SetUseFXAA(still)
        self._fxaa_paused = not still

    def see_through(self) -> bool:
        """The complex is drawn see-through (a lit surface or 2-skeleton with opacity below 1)."""
        return (self.actor is not None and self.dim >= 2 and self.actor.prop.lighting
                and float(self.actor.prop.opacity) < 1.0)

    def _still_light(self, still: bool) -> None:
        """Light the scene with its own lights (``still``) or with one headlight (the same light objects
        come back in the same order, so the still picture is the same, pixel for pixel)."""
        ren = self.plotter.renderer
        if still:
            if self._still_lights is not None:
                ren.RemoveAllLights()
                for light in self._still_lights:
                    ren.AddLight(light)
                self._still_lights = None
            return
        if self._still_lights is None:
            from vtkmodules.vtkRenderingCore import vtkLight  # (not ``import vtk``: that loads every module, 1.3 s)

            lights = ren.GetLights()
            self._still_lights = [lights.GetItemAsObject(i) for i in range(lights.GetNumberOfItems())]
            head = vtkLight()
            head.SetLightTypeToHeadlight()
            head.SetIntensity(MOVING_LIGHT)
            ren.RemoveAllLights()
            ren.AddLight(head)

    # ------------------------------------------------------- level of detail
    def lod_available(self) -> bool:
        """A coarse copy exists for the whole result on screen (no slice, an actor to stand in for)."""
        g = self.geometry
        return (g is not None and g.coarse is not None and self.slice is None and self.actor is not None
                and self.draw_geo is g)

    def coarse_shown(self) -> bool:
        return self._coarse_on

    def _show_coarse(self) -> None:
        geo = self.geometry.coarse
        if self._coarse is None:
            pts = geo.projector.project_view(self.view)
            mesh = (pv.PolyData(pts, lines=geo.cells) if geo.kind == "lines" else pv.PolyData(pts, faces=geo.cells))
            C = geo.projector.XT.T + np.asarray(geo.projector.center, dtype=np.float32)   # back to R^n
            for i, name in enumerate(self.names):
                mesh.point_data[name] = np.ascontiguousarray(C[:, i], dtype=np.float64)
            normals = None
            if geo.normals is not None:
                mesh.point_data["Normals"] = np.zeros((mesh.n_points, 3), dtype=np.float32)
                mesh.point_data.active_normals_name = "Normals"
                normals = mesh.point_data["Normals"]
            kw = dict(self._actor_kw)
            kw.update(render=False, reset_camera=False, name="gcmh-complex-coarse", show_scalar_bar=False,
                      pickable=False, show_edges=False)   # (edges are a second pass over every cell)
            actor = self.plotter.add_mesh(mesh, **kw)
            if normals is not None:
                actor.prop.interpolation = "phong"
            self._coarse = (geo, mesh, actor, normals)
        geo, mesh, actor, normals = self._coarse
        geo.projector.project_view(self.view, out=mesh.points)
        mesh.GetPoints().Modified()
        if normals is not None:
            if self.view.linear:
                geo.normals.write(self._P, normals)
            else:
                geo.mesh_normals().write(mesh.points, normals)
            mesh.GetPointData().GetNormals().Modified()
        mesh.Modified()
        actor.SetVisibility(True)
        self.actor.SetVisibility(False)
        self._coarse_on = True

    def _hide_coarse(self) -> None:
        if self._coarse_on:
            self._coarse[2].SetVisibility(False)
            if self.actor is not None:
                self.actor.SetVisibility(True)
            self._coarse_on = False

    def _drop_coarse(self) -> None:
        if self._coarse is not None:
            self.plotter.remove_actor(self._coarse[2], render=False)
            self._coarse = None
        if self._coarse_on and self.actor is not None:
            self.actor.SetVisibility(True)
        self._coarse_on = False

    def _write_normals(self) -> None:
        if self._normals is None or self._normal_field is None:
            return
        if self.view is not None and not self.view.linear:
            # the bivector identity needs a linear map: take the normals of the projected mesh
            if self._mesh_normals is None:
                self._mesh_normals = self.draw_geo.mesh_normals()
            self._mesh_normals.write(self._pts, self._normals)
        else:
            self._normal_field.write(self._P, self._normals)
        self.mesh.GetPointData().GetNormals().Modified()

    # ------------------------------------------------------------------ slicing
    def set_slice(self, direction=None, c: float = 0.0, w: float = 0.0, render: bool = True) -> int:
        """Show only the part with ``c - w <= direction . x <= c + w`` (None: everything).

        Cells are clipped at the window's planes (:mod:`gcmh_studio.slicing`). Returns the
        number of cells drawn.
        """
        geo = self.geometry
        if geo is None:
            return 0
        V = np.asarray(self.complex.vertices)
        if direction is None:
            self.slice = None
            self._show_geometry(geo, V)
        else:
            u = np.asarray(direction, dtype=float)
            self.slice = (u, float(c), float(w))
            if geo.kind == "lines":
                sl = clip_segments(V, geo.edges, u, c, w)
            else:
                sl = clip_polygons(V, geo.offsets, geo.vids, u, c, w)
            sgeo = Geometry.from_slice(sl, geo.dim, geo.n, geo.projector.center, geo.projector.radii(),
                                       cell_ids=geo.cell_ids)
            self._show_geometry(sgeo, sl.vertices)
        for name in list(self._overlay_src):
            self._build_overlay(name)
        self._set_ghost(self.slice is not None and self.style.slice_context and geo.kind == "polygons")
        if render:
            self.plotter.render()
        return 0 if self.mesh is None else int(self.mesh.n_cells)

    def _set_ghost(self, on: bool) -> None:
        """The whole result, faint and unlit, behind a slice: where the slice sits in the whole."""
        if not on:
            if self._ghost is not None:
                self.plotter.remove_actor(self._ghost[1], render=False)
                self._ghost = None
            return
        if self._ghost is not None:
            return
        geo = self.geometry
        mesh = pv.PolyData(geo.projector.project_view(self.view), faces=geo.cells)
        actor = self.plotter.add_mesh(mesh, color="#c8d2e6", opacity=0.07, lighting=False, pickable=False,
                                      render=False, reset_camera=False, name="gcmh-slice-ghost")
        self._ghost = (mesh, actor)

    # ------------------------------------------------------------------ overlays
    def set_overlay(self, name: str, vertices, edges, color: str, width: float = 2.0,
                    opacity: float = 1.0, render: bool = True) -> None:
        """Line segments in R^n (vertices (m, n), edges (E, 2)) drawn with the view and clipped by the slice."""
        self._overlay_src[name] = (np.asarray(vertices, dtype=np.float64), np.asarray(edges, dtype=np.int64),
                                   color, float(width), float(opacity))
        self._build_overlay(name)
        if render:
            self.plotter.render()

    def remove_overlay(self, name: str, render: bool = True) -> None:
        self._overlay_src.pop(name, None)
        ov = self.overlays.pop(name, None)
        if ov is not None and ov[2] is not None:
            self.plotter.remove_actor(ov[2], render=False)
        if render:
            self.plotter.render()

    def _build_overlay(self, name: str) -> None:
        X, E, color, width, opacity = self._overlay_src[name]
        old = self.overlays.pop(name, None)
        if old is not None and old[2] is not None:
            self.plotter.remove_actor(old[2], render=False)
        if self.geometry is None or len(E) == 0:
            return
        if self.slice is not None:
            u, c, w = self.slice
            sl = clip_segments(X, E, u, c, w)
            X, E = sl.vertices, sl.edges
            if len(E) == 0:
                return
        pr = Projector(X, center=self.geometry.projector.center)
        pr.set_radii(self.geometry.projector.radii())
        lines = np.empty((len(E), 3), dtype=np.int64)
        lines[:, 0] = 2
        lines[:, 1:] = E
        mesh = pv.PolyData(pr.project_view(self.view), lines=lines.ravel())
        geo = Geometry(1, X.shape[1], "lines", lines.ravel(), pr)
        self.overlays[name] = [geo, mesh, None, color, (width, opacity)]
        self.overlays[name][2] = self._add_overlay_actor(name, mesh, color, (width, opacity))

    def _add_overlay_actor(self, name, mesh, color, width):
        width, opacity = width
        return self.plotter.add_mesh(mesh, color=color, line_width=width, opacity=opacity, render=False,
                                     reset_camera=False, name=f"gcmh-overlay-{name}", pickable=False,
                                     render_lines_as_tubes=opacity >= 1.0, lighting=False)

    # ------------------------------------------------------------------ picking
    def cell_at(self, display_xy) -> int | None:
        """The complex's cell (2-cell, or edge of a curve) drawn at pixel ``display_xy`` (x, y from bottom left)."""
        if self.mesh is None or self.actor is None:
            return None
        from vtkmodules.vtkRenderingCore import vtkCellPicker

        picker = vtkCellPicker()
        picker.SetTolerance(0.002)
        picker.PickFromListOn()
        picker.AddPickList(self.actor)
        if not picker.Pick(float(display_xy[0]), float(display_xy[1]), 0.0, self.plotter.renderer):
            return None
        cid = picker.GetCellId()
        if cid < 0:
            return None
        return int(self.mesh.cell_data["cell_id"][cid])

    def display_position(self, cell_id: int) -> tuple[float, float] | None:
        """Pixel (x, y from bottom left) of the middle of a drawn cell of the complex, or None."""
        if self.mesh is None:
            return None
        rows = np.flatnonzero(self.mesh.cell_data["cell_id"] == int(cell_id))
        if len(rows) == 0:
            return None
        cell = self.mesh.get_cell(int(rows[0]))
        p = np.asarray(cell.points, dtype=float).mean(axis=0)
        ren = self.plotter.renderer
        ren.SetWorldPoint(p[0], p[1], p[2], 1.0)
        ren.WorldToDisplay()
        x, y, _ = ren.GetDisplayPoint()
        return float(x), float(y)

    # ---------------------------------------------------------------- style
    def set_style(self, style: Style, render: bool = True) -> None:
        self.style = style
        self._add_actor()
        self._update_axes_labels()
        if render:
            self.plotter.render()

    def set_opacity(self, opacity: float, render: bool = True) -> None:
        self.style.opacity = float(opacity)
        if self.actor is not None:
            self.actor.prop.opacity = float(opacity)
        if render:
            self.plotter.render()

    def set_show_edges(self, on: bool, render: bool = True) -> None:
        self.style.show_edges = bool(on)
        if self.actor is not None:
            self.actor.prop.show_edges = bool(on) and self.dim >= 2
        if render:
            self.plotter.render()

    def _update_axes_labels(self) -> None:
        """Axis names on the orientation widget; a legend of the screen axes when they mix variables."""
        if not self.style.axes or self._P is None or not self.names:
            return
        from .projection import axis_label
        full = [axis_label(self._P[r], self.names, terms=3) for r in range(3)]
        short = []
        for r in range(3):
            row = self._P[r]
            if not np.any(np.abs(row) > 1e-6):
                short.append("-")
                continue
            i = int(np.argmax(np.abs(row)))
            pure = abs(abs(row[i]) - 1.0) < 1e-6
            # ~x: "mostly x" (the legend has the mix)
            short.append(self.style.label(full[r]) if pure else "~" + self.names[i])
        mixed = any(lab.startswith("~") for lab in short)
        legend = "\n".join(f"{'XYZ'[r]} = {full[r]}" for r in range(3) if full[r]) if mixed else ""
        if self._axes_actor is None:
            try:
                self._axes_actor = self.plotter.add_axes(
                    xlabel=short[0], ylabel=short[1], zlabel=short[2],
                    line_width=3, color="white", labels_off=False,
                    viewport=(0.0, 0.0, 0.2, 0.28))
            except Exception:  # noqa: BLE001 - a plotter without an orientation widget
                self._axes_actor = None
        a = self._axes_actor
        if a is not None:
            a.SetXAxisLabelText(short[0])
            a.SetYAxisLabelText(short[1])
            a.SetZAxisLabelText(short[2])
        if self._legend_actor is None:
            self._legend_actor = self.plotter.add_text(legend, position=(0.02, 0.80), viewport=True,
                                                       font_size=self._font(11), color="#dfe4ee",
                                                       name="gcmh-legend")
        else:
            self._legend_actor.SetInput(legend)

    def _font(self, size: float) -> int:
        """A font size scaled to the picture (sizes are tuned for 1600x1200; a narrow picture counts by its
        width, so a title fits across a portrait screenshot)."""
        try:
            w, h = (int(x) for x in self.plotter.window_size)
        except Exception:  # noqa: BLE001
            w, h = 1600, 1200
        ref = min(h, 0.75 * w)
        return max(6, int(round(size * min(1.5, max(0.55, ref / 1200)))))

    def axes_labels(self) -> list[str]:
        from .projection import axis_label
        if self._P is None:
            return ["", "", ""]
        return [axis_label(self._P[r], self.names) for r in range(3)]

    # ------------------------------------------------------------- exports
    def projected_mesh(self) -> pv.PolyData:
        """A copy of the current projected mesh (3D points, all coordinates as point data, and the colours
        on screen as ``RGB`` (V, 3) uint8 point data for PLY and OBJ files)."""
        if self.mesh is None:
            raise ValueError("nothing to export: no result yet")
        if self._coarse_on:   # the full mesh's points, not the ones of a moment ago
            self.set_projection(self.view, render=False)
        m = self.mesh.copy(deep=True)
        m.points = np.asarray(m.points, dtype=np.float64)
        m.point_data["RGB"] = self.vertex_colours()
        m.point_data.active_scalars_name = self.style.color_by if self.style.color_by in self.names else None
        return m

    def vertex_colours(self) -> np.ndarray:
        """(V, 3) uint8: each drawn vertex's colour as the picture shows it (the colour map over the whole
        result's range, or the solid colour)."""
        from matplotlib import colormaps
        from matplotlib.colors import to_rgb

        st = self.style
        V = self.mesh.n_points
        color_by = st.color_by if st.color_by in self.names and not (st.two_sided and self.dim >= 2) else None
        if color_by is None:
            rgb = np.array(to_rgb(SURFACE_COLOR if self.dim >= 2 else LINE_COLOR))
            return np.tile(np.round(255 * rgb).astype(np.uint8), (V, 1))
        col = np.asarray(self.complex.vertices)[:, self.names.index(color_by)]
        fin = col[np.isfinite(col)]
        lo, hi = colour_range(fin) if len(fin) else (0.0, 1.0)
        t = np.clip((np.asarray(self.mesh.point_data[color_by], dtype=float) - lo) / (hi - lo), 0.0, 1.0)
        t = np.where(np.isfinite(t), t, 0.0)
        return np.round(255 * colormaps[st.cmap](t)[:, :3]).astype(np.uint8)


def describe(cx, names, color_by=None, labels: dict | None = None) -> str:
    """A one-line subtitle: what the picture shows."""
    dim, n, k = cx.dim, cx.n, cx.k
    what = {1: "curve", 2: "surface"}.get(dim, f"{dim}-manifold, 2-skeleton")
    text = f"{what} in R^{n} (n = {n}, k = {k}) · {cx.count(0):,} vertices"
    if color_by:
        text += f" · colour: {Style(labels=labels or {}).label(color_by)}"
    return text


def example_labels(ex) -> dict:
    """What an example's variables mean ({"y": "Im z"}): its file's ``[view] labels``, or those of its
    complex equations (the loader's ``Example.labels``); {} when it says nothing."""
    raw = getattr(ex, "labels", None) or {}
    return {k: " ".join(str(v).split())[:24] for k, v in raw.items() if k in ex.variables and str(v).strip()}


_LABELS_CACHE: dict = {}
_TITLES: dict | None = None      # example title -> names of the example files with it


def _example_titles() -> dict:
    """{title: [example names]} from the files' ``title`` keys only (loading every example, as before,
    parsed all their formulas: 0.27 s on the GUI thread when the three-torus arrived)."""
    global _TITLES
    if _TITLES is None:
        import tomllib

        from gcmh_core.examples import example_names, examples_dir

        found: dict = {}
        folder = examples_dir()
        for name in example_names():
            try:
                title = tomllib.loads((folder / f"{name}.toml").read_text(encoding="utf-8")).get("title")
            except (OSError, ValueError):
                continue
            if isinstance(title, str):
                found.setdefault(title.strip(), []).append(name)
        _TITLES = found
    return _TITLES


def warm_labels() -> None:
    """Read the examples' titles in a daemon thread now (the window calls this when it opens), so the first
    result does not wait for them on the GUI thread."""
    import threading

    if _TITLES is None:
        threading.Thread(target=_example_titles, name="gcmh-example-titles", daemon=True).start()


def labels_for(title: str, names) -> dict:
    """The labels of the example with this title and these variables (a run of an example in the
    window), else {} (a system the user typed)."""
    key = (title, tuple(names))
    if not title:
        return {}
    if key not in _LABELS_CACHE:
        found = {}
        try:
            from gcmh_core.examples import load_example

            for name in _example_titles().get(title.strip(), []):
                ex = load_example(name)
                if ex.title == title and list(ex.variables) == list(names):
                    found = example_labels(ex)
                    break
        except Exception:  # noqa: BLE001
            found = {}
        _LABELS_CACHE[key] = found
    return _LABELS_CACHE[key]


def view_subtitle(cx, names, color_by=None, two_sided: bool = False, mapping: str = "orthographic",
                  labels: dict | None = None) -> str:
    """The subtitle of a view (window and headless alike): :func:`describe`, then the two sides and the mapping."""
    sub = describe(cx, names, None if two_sided else color_by, labels) if cx is not None else ""
    if two_sided and cx is not None:
        sub += " \u00b7 two sides: gold front, blue back"
    if mapping != "orthographic":
        sub += f" \u00b7 {mapping}"
    return sub


def draw_overlays(scene: Scene, cx, boundary: bool = False, grid: bool = False,
                  picked: dict | None = None) -> str | None:
    """Boundary facets (red), grid cubes (faint) and a picked cell (green) as line overlays on ``scene``.

    Returns a message when the grid cubes cannot be drawn (sampled data has no grid), else None.
    """
    problem = None
    if boundary:
        X, E = boundary_lines(cx)
        scene.set_overlay("boundary", X, E, BOUNDARY_COLOR, width=4.0, render=False)
    else:
        scene.remove_overlay("boundary", render=False)
    if grid:
        try:
            X, E = grid_cube_lines(cx)
        except ValueError as e:
            problem = f"Grid cubes: {e}"
            scene.remove_overlay("grid", render=False)
        else:
            scene.set_overlay("grid", X, E, GRID_COLOR, width=1.0, opacity=0.18, render=False)
    else:
        scene.remove_overlay("grid", render=False)
    if picked is not None:
        X, E = picked["lines"]
        scene.set_overlay("pick", X, E, PICK_COLOR, width=5.0, render=False)
    return problem


# Where the object may lie, in halves of the picture from its centre: clear of the title (top), the colour
# bar (right) and the axes (bottom left) -- the picture a window, a screenshot and a thumbnail all share.
MARGIN_X = 0.68
MARGIN_Y = 0.76
TITLE_BOTTOM = 2 * 0.885 - 1     # the subtitle's baseline, in the same units (-1..1 up the picture)
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


def fit_camera(plotter, margin_x: float = 0.9, margin_y: float = 0.9, max_points: int = 400_000) -> None:
    """Change the view angle so the shown points just fit (perspective camera, direction kept).

    The points fill at most ``margin_x`` of the half-width and ``margin_y`` of the half-height.
    """
    X = shown_points(plotter, max_points)
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
# of the scene's meshes; the window shows the image until it renders again. VTK's text rendering is one
# unguarded singleton, so there is only ever one job at a time and every other render of a Scene's plotter
# waits for it (the StartEvent observer every Scene installs).
_tls = threading.local()
_background: StillJob | None = None
SETTLE_RENDERS = 1          # cheap renders before the picture (see StillJob._run)


def wait_background() -> None:
    """Block until the still picture drawing in the background (if any) is done (a no-op on its thread)."""
    job = _background
    if job is not None and not getattr(_tls, "worker", False):
        job.thread.join()


def camera_values(camera) -> dict:
    """A pyvista camera as plain values (to copy onto another thread's camera)."""
    return dict(position=tuple(camera.position), focal_point=tuple(camera.focal_point), up=tuple(camera.up),
                view_angle=float(camera.view_angle), parallel_projection=bool(camera.parallel_projection),
                parallel_scale=float(camera.parallel_scale))


class StillJob:
    """The still picture of ``scene`` at ``size`` (w, h) under ``camera`` (:func:`camera_values`), rendered
    in a thread on an off-screen plotter set up as the window's (``anti_aliasing``, no multi-sampling).

    Made on the GUI thread: the copies are taken and the off-screen scene is built there (no GL yet), with
    ``decorate(plotter)`` (what the window draws over its view); when that adds anything the job is
    ``declined`` (the window draws its own picture). Then ``done()``, and ``image`` ((h, w, 3) uint8) or
    ``error``. ``stale`` is the caller's: set it when the picture is no longer wanted."""

    def __init__(self, scene: Scene, size, camera: dict, anti_aliasing: str | None = "fxaa", decorate=None):
        global _background
        self.size = (int(size[0]), int(size[1]))
        self.image: np.ndarray | None = None
        self.error: BaseException | None = None
        self.stale = False
        self.declined = False
        self.seconds = 0.0
        # (made here, not in the thread: ``decorate`` is the window's; a plotter kept for the next job would
        # outlive the X server in a test run, and Xlib ends a process whose display went away)
        pl = pv.Plotter(off_screen=True, window_size=list(self.size))
        try:
            pl.ren_win.SetMultiSamples(0)      # as the window: FXAA, no multi-sampling
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
            self.thread = None
            return
        self._plotter, self._scene = pl, sc
        self._previous = _background
        if _background is None:   # a job still drawing when Python exits would draw into a finalised VTK
            import atexit

            atexit.register(wait_background)
        self.thread = threading.Thread(target=self._run, name="gcmh-still-picture", daemon=True)
        _background = self
        self.thread.start()

    def done(self) -> bool:
        return self.thread is None or not self.thread.is_alive()

    def _run(self) -> None:
        import time

        _tls.worker = True
        t0 = time.perf_counter()
        pl = self._plotter
        try:
            if self._previous is not None:   # one job at a time
                self._previous.thread.join()
            self._previous = None
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
            try:
                pl.close()
            except Exception:  # noqa: BLE001
                pass
            self._plotter = self._scene = None
            self.seconds = time.perf_counter() - t0


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
    global _background

    class _Warm:
        def run(self):
            _tls.worker = True
            try:
                pl = pv.Plotter(off_screen=True, window_size=[160, 120])
                try:
                    m = pv.Plane(i_resolution=2, j_resolution=2)
                    m.point_data["t"] = np.arange(m.n_points, dtype=float)
                    pl.add_mesh(m, scalars="t", scalar_bar_args=dict(title="t", vertical=True))
                    pl.add_text("warm", font_size=10)
                    pl.ren_win.Render()
                finally:
                    pl.close()
            except Exception:  # noqa: BLE001 - the first job will say
                pass

    if _background is not None:
        return
    job = _Warm()
    job.thread = threading.Thread(target=job.run, name="gcmh-still-warm-up", daemon=True)
    import atexit

    atexit.register(wait_background)
    _background = job
    job.thread.start()
