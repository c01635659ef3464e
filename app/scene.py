"""Drawing a CellComplex through a projection on any pyvista plotter (no Qt here).

:class:`Scene` owns one pyvista mesh built once per result from an
:class:`gcmh_studio.geometry.Geometry`: lines for curves (dim 1), filled polygons for
surfaces (dim 2), the 2-skeleton for higher dimensions. Moving a projection
slider calls :meth:`Scene.set_projection`, which writes the projected points
(and, for surfaces, the vertex normals of the projected mesh) in place into the
mesh's VTK arrays and re-renders: no new mesh, no new actor, same topology
(the mesh and its writing are :mod:`gcmh_studio.complex_mesh`'s).

A slice (:meth:`Scene.set_slice`) clips the oriented loops of the full result
to a window of a linear functional (:mod:`gcmh_studio.slicing`) and draws that instead:
new topology, so a new mesh, but the same centre and scales, so nothing jumps.
Overlays (boundary facets, the grid cubes, a picked cell) are small line meshes
projected with the same view and clipped by the same slice (:mod:`gcmh_studio.overlays`).
Periodic axes may be drawn as circles, with their glued seam (:mod:`gcmh_studio.scene_angles`).
While the view moves it is drawn in a cheaper look (:mod:`gcmh_studio.moving_look`).

A view is a :class:`gcmh_studio.projection.View` (or a plain (3, n) matrix: linear).

The same class renders into the Qt window (a ``pyvistaqt.QtInteractor``) and
into an off-screen ``pyvista.Plotter`` for headless screenshots and animations,
and (:class:`gcmh_studio.offscreen.StillJob`) into one in a worker process for the window's
still picture. Framing the camera is :mod:`gcmh_studio.camera`'s, the words drawn
over the picture (title, subtitle, colour bar, axis names) :mod:`gcmh_studio.labels`'s.
"""

from __future__ import annotations

import copy
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pyvista as pv

from . import picking
from .angles import cyclic_colour
from .complex_mesh import SHEET_GAP as SHEET_GAP  # (the views' tests read it here)
from .complex_mesh import ComplexMesh
from .geometry import Geometry, display_complex
from .labels import SceneTexts, axes_labels, with_meaning
from .moving_look import MovingLook
from .overlays import SceneOverlays
from .projection import Projector, View
from .scene_angles import SceneAngles
from .slicing import clip_polygons, clip_segments

if TYPE_CHECKING:
    from gcmh_core.complex import CellComplex

BACKGROUND = "#1f2430"
BACKGROUND_TOP = "#4a5468"
SURFACE_COLOR = "#d9a441"
LINE_COLOR = "#f0c05a"
BACK_COLOR = "#3f7fd0"       # back faces when two-sided colouring is on
CMAP = "viridis"


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


def bar_format(limits) -> str:
    """printf format for the colour bar's five labels over ``limits`` (lo, hi): as many decimals as a
    quarter of the range needs, at least two."""
    step = (float(limits[1]) - float(limits[0])) / 4.0
    if not (step > 0 and np.isfinite(step)):
        return "%.2f"
    return f"%.{int(min(8, max(2, 1 - np.floor(np.log10(step)))))}f"


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
    circles: bool = False            # periodic axes drawn as circles (gcmh_studio.angles)
    seam: bool = False               # the glued seam of periodic axes drawn
    labels: dict = field(default_factory=dict)   # variable -> its meaning ("y" -> "Im z"), from the example
    extra: dict = field(default_factory=dict)

    def label(self, name: str) -> str:
        """``name``, with its meaning when the example gives one: "y = Im z"."""
        return with_meaning(name, self.labels)

    def colour_variable(self, names, dim: int) -> str | None:
        """The variable the complex is coloured by: None for the solid colour (none of ``names`` asked for, or
        a surface's two sides painted: a colour map would paint both alike)."""
        if self.color_by not in names or (self.two_sided and dim >= 2):
            return None
        return self.color_by

    def resolved_opacity(self, dim: int) -> float:
        if self.opacity is not None:
            return float(self.opacity)
        return 1.0 if dim <= 2 else 0.35

    def resolved_edges(self, dim: int) -> bool:
        if self.show_edges is not None:
            return bool(self.show_edges)
        return dim >= 3


@contextmanager
def held_render(plotter, render: bool = True):
    """Draw nothing on ``plotter`` inside the block (pyvista renders after every added actor and camera
    reset: a new result cost seven renders); then one render when ``render``."""
    pl = plotter
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


def mesh_look(style: Style, dim: int, coloured: bool) -> dict:
    """pyvista's ``add_mesh`` keywords for a complex of dimension ``dim`` drawn in ``style``; ``coloured``:
    by a colour map (the caller adds it), else in the solid colour."""
    kw = dict(
        opacity=style.resolved_opacity(dim),
        show_edges=style.resolved_edges(dim) and dim >= 2,
        edge_color="#202020",
        line_width=style.line_width if dim <= 1 else 0.6,
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
    if not coloured:
        kw["color"] = SURFACE_COLOR if dim >= 2 else LINE_COLOR
        kw["show_scalar_bar"] = False
    if style.two_sided and dim >= 2:
        kw["backface_params"] = dict(color=BACK_COLOR)
    return kw


def vertex_colours(style: Style, dim: int, n_points: int, values=None, limits=None, cmap: str | None = None
                   ) -> np.ndarray:
    """(V, 3) uint8: each vertex's colour as the picture shows it: ``values`` (V,), the coloured variable at
    the vertices, through ``style``'s colour map over ``limits`` (lo, hi) (None: 0..1); the solid colour of
    a complex of dimension ``dim`` when ``values`` is None."""
    from matplotlib import colormaps
    from matplotlib.colors import to_rgb

    if values is None:
        rgb = np.array(to_rgb(SURFACE_COLOR if dim >= 2 else LINE_COLOR))
        return np.tile(np.round(255 * rgb).astype(np.uint8), (n_points, 1))
    lo, hi = limits or (0.0, 1.0)
    t = np.clip((np.asarray(values, dtype=float) - lo) / (hi - lo), 0.0, 1.0)
    t = np.where(np.isfinite(t), t, 0.0)
    return np.round(255 * colormaps[cmap or style.cmap](t)[:, :3]).astype(np.uint8)


class Scene:
    """One projected complex on a pyvista plotter.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    """

    def __init__(self, plotter, anti_aliasing: str | None = "fxaa"):
        self.plotter = plotter
        self.complex: CellComplex | None = None
        self.names: list[str] = []
        self.actor: pv.Actor | None = None
        self.style = Style()
        self.P: np.ndarray | None = None         # the view's matrix (3, n)
        self.texts = SceneTexts(plotter)
        self.geometry: Geometry | None = None      # of the whole result
        self.source = None                         # the result as computed (display_complex draws a copy)
        self.view: View | None = None
        self.slice: tuple | None = None            # (direction (n,), c, w) or None
        self.drawn = ComplexMesh(self)             # the complex's mesh, written in place for each view
        self.overlay_meshes = SceneOverlays(self)  # boundary, grid cubes, a picked cell; the slice's ghost
        self.look = MovingLook(self)               # cheaper while the view moves
        self.angles = SceneAngles(self)            # periodic axes as circles, the glued seam
        self.actor_kw: dict = {}                   # how the complex's actor was added (its coarse copy's too)
        plotter.set_background(BACKGROUND, top=BACKGROUND_TOP)
        self.anti_aliasing: str | None = None
        self.set_anti_aliasing(anti_aliasing)

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

    def held_render(self, render: bool = True):
        """Draw nothing inside the block, then one render when ``render`` (:func:`held_render`)."""
        return held_render(self.plotter, render)

    # ------------------------------------------------------------------ build
    @property
    def dim(self) -> int:
        return 0 if self.complex is None else int(self.complex.dim)

    def clear(self) -> None:
        if self.actor is not None:
            self.plotter.remove_actor(self.actor, render=False)
        self.texts.remove_bar()
        self.actor = None
        self.drawn.clear()
        self.complex = None
        self.geometry = None
        self.source = None
        self.angles.drop_seam()
        self.slice = None
        self.look.drop_coarse()
        self.look.restore_lights()
        self.overlay_meshes.clear()

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
            self.texts.set_title(self.style.title, self.style.subtitle)
            return
        geo = geometry if geometry is not None else Geometry.build(cx)
        self.source = cx
        cx = display_complex(cx)  # (seams of identified axes drawn whole: the geometry's own vertices)
        self.complex = cx
        self.names = list(names)
        self.geometry = geo
        self._set_view(P)
        self._show_geometry(geo, np.asarray(cx.vertices))
        self.angles.show_seam()
        self._update_axes_labels()
        self.plotter.renderer.reset_camera(render=False)   # (the plotter's wrapper renders)

    def _set_view(self, P) -> View:
        view = P if isinstance(P, View) else View(np.asarray(P, dtype=float), "orthographic")
        self.view = view
        self.P = np.asarray(view.P, dtype=float)
        return view

    def _show_geometry(self, geo: Geometry, V: np.ndarray) -> None:
        """Make the mesh for ``geo`` (vertices ``V`` (V, n) for the colour data) at the view, and its actor."""
        self.drawn.build(geo, V, self.angles.projector_for(V, geo.projector))
        if self.drawn.mesh is None:   # an empty slice: draw nothing
            if self.actor is not None:
                self.plotter.remove_actor(self.actor, render=False)
            self.texts.remove_bar()
            self.actor = None
            return
        self._add_actor()

    @property
    def mesh(self) -> pv.PolyData | None:
        """The complex's mesh on show (:class:`gcmh_studio.complex_mesh.ComplexMesh`), None when nothing is."""
        return self.drawn.mesh

    @property
    def projector(self) -> Projector | None:
        return self.drawn.projector

    @property
    def draw_geo(self) -> Geometry | None:
        """What is drawn: the slice, or the whole result."""
        return self.drawn.geometry

    @property
    def circles_on(self) -> bool:
        """Periodic axes are drawn as circles (:class:`gcmh_studio.scene_angles.SceneAngles`)."""
        return self.angles.circles_on

    @property
    def _seam(self) -> tuple | None:
        return self.angles.seam

    def set_angle_look(self, circles: bool, seam: bool, render: bool = True) -> None:
        """Periodic axes as circles or as numbers; the glued seam drawn or not (a new mesh for circles)."""
        self.angles.set(circles, seam)
        if render:
            self.plotter.render()

    def detached(self) -> Scene:
        """A copy for another thread to draw with :meth:`adopt`: its meshes deep copies, sharing no VTK object
        with this scene (the GUI thread goes on moving this one's points), and no plotter of its own."""
        other = copy.copy(self)
        other.plotter = other.actor = None
        other.angles = SceneAngles(other)
        other.texts = SceneTexts(None)
        other.look = MovingLook(other)
        other.style = copy.copy(self.style)
        other.P = None if self.P is None else np.array(self.P)
        other.drawn = self.drawn.detached(other)
        other.overlay_meshes = self.overlay_meshes.detached(other)
        return other

    def adopt(self, other: Scene, style: Style | None = None) -> None:
        """Show the mesh of another scene (shared, not copied) with its projection."""
        self.complex = other.complex
        self.source = other.source
        self.names = list(other.names)
        self.drawn = other.drawn.shared(self)
        self.P = other.P
        self.view, self.geometry, self.slice = other.view, other.geometry, other.slice
        self.style = style if style is not None else other.style
        self._add_actor()
        self.overlay_meshes.adopt(other.overlay_meshes)
        self._update_axes_labels()

    def _add_actor(self) -> None:
        if self.mesh is None:
            return
        if self.actor is not None:
            self.plotter.remove_actor(self.actor, render=False)
            self.actor = None
        self.texts.remove_bar()
        st = self.style
        color_by = st.colour_variable(self.names, self.dim)
        kw = mesh_look(st, self.dim, coloured=color_by is not None)
        if color_by is not None:
            clim = self.colour_limits(color_by)
            if clim is not None:
                kw["clim"] = clim
            kw.update(scalars=color_by, cmap=self.colour_map(color_by), show_scalar_bar=st.scalar_bar,
                      scalar_bar_args=self.texts.bar_args(st.label(color_by)))
            if clim is not None:   # the bar's labels with the decimals its range needs ("0.0015", not "0.00")
                kw["scalar_bar_args"]["fmt"] = bar_format(clim)
        self.look.drop_coarse()
        self.actor_kw = {k: v for k, v in kw.items() if k not in ("show_scalar_bar", "scalar_bar_args", "name")}
        self.actor = self.plotter.add_mesh(self.mesh, **kw)
        self.texts.bar_added(st.label(color_by) if color_by is not None and st.scalar_bar else None)
        if self.drawn.normals is not None:
            self.actor.prop.interpolation = "phong"
        self.mesh.set_active_scalars(color_by) if color_by else None
        self.texts.set_title(self.style.title, self.style.subtitle)

    # ----------------------------------------------------------- fast update
    def set_projection(self, P, render: bool = True, moving: bool = False) -> None:
        """Write the points (and normals) for view ``P`` (a View or a (3, n) matrix) in place.

        ``moving``: draw the moving look (:meth:`set_moving`), e.g. while a slider moves; the
        still look comes back, the full mesh's points written, when asked again without it. A
        slice along a direction that depends on the view is the caller's to redo
        (:meth:`set_slice`); overlays follow here.
        """
        self._set_view(P)
        coarse = moving and self.look.lod_available()
        self.look.set_lights(moving)
        if coarse:
            self.look.show_coarse()
        else:
            self.look.hide_coarse()
            self.drawn.project()
        self.overlay_meshes.project()
        self.angles.project()
        self._update_axes_labels()
        if render:
            self.plotter.renderer.ResetCameraClippingRange()
            self.plotter.render()

    # ------------------------------------------------------- the moving look (gcmh_studio.moving_look)
    def set_moving(self, on: bool) -> None:
        """The moving look (``on``) or the still one, for the points as they are (a camera drag)."""
        if self.complex is None:
            return
        if on and self.look.lod_available():
            self.look.show_coarse()
        elif not on and self.look.coarse_on:
            self.set_projection(self.view, render=False)
        self.look.set_lights(on)

    def moving_look_available(self) -> bool:
        """The result on screen has a moving look cheaper than its still one."""
        return self.look.available()

    def moving_shown(self) -> bool:
        return self.look.shown()

    def see_through(self) -> bool:
        """The complex is drawn see-through (a lit surface or 2-skeleton with opacity below 1)."""
        return self.look.see_through()

    def coarse_shown(self) -> bool:
        return self.look.coarse_on

    # ------------------------------------------------------------------ slicing
    def set_slice(self, direction=None, c: float = 0.0, w: float = 0.0, render: bool = True) -> int:
        """Show only the part with ``c - w <= direction . x <= c + w`` (None: everything).

        Cells are clipped at the window's planes (:mod:`gcmh_studio.slicing`). Returns the
        number of cells drawn.
        """
        geo, cx, view = self.geometry, self.complex, self.view
        if geo is None or cx is None or view is None:   # (no result: all three are set together)
            return 0
        V = np.asarray(cx.vertices)
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
        self.overlay_meshes.rebuild()
        self.angles.fit_overlays()
        self.overlay_meshes.set_ghost(self.slice is not None and self.style.slice_context and geo.kind == "polygons")
        if render:
            self.plotter.render()
        return 0 if self.mesh is None else int(self.mesh.n_cells)

    # ------------------------------------------------------------------ overlays (gcmh_studio.overlays)
    @property
    def overlays(self) -> dict:
        """name -> [Geometry, mesh, actor, color, (width, opacity)] of the line overlays drawn."""
        return self.overlay_meshes.items

    @property
    def _ghost(self) -> tuple | None:
        return self.overlay_meshes.ghost

    def set_overlay(self, name: str, vertices, edges, color: str, width: float = 2.0,
                    opacity: float = 1.0, render: bool = True) -> None:
        """Line segments in R^n (vertices (m, n), edges (E, 2)) drawn with the view and clipped by the slice."""
        self.overlay_meshes.set(name, vertices, edges, color, width, opacity)
        self.angles.fit_overlays()
        if render:
            self.plotter.render()

    def remove_overlay(self, name: str, render: bool = True) -> None:
        self.overlay_meshes.remove(name)
        if render:
            self.plotter.render()

    # ------------------------------------------------------------------ picking (gcmh_studio.picking)
    def cell_at(self, display_xy) -> int | None:
        """The complex's cell (2-cell, or edge of a curve) drawn at pixel ``display_xy`` (x, y from bottom left)."""
        if self.mesh is None or self.actor is None:
            return None
        return picking.cell_at(self.plotter.renderer, self.actor, self.mesh, display_xy)

    def display_position(self, cell_id: int) -> tuple[float, float] | None:
        """Pixel (x, y from bottom left) of the middle of a drawn cell of the complex, or None."""
        return None if self.mesh is None else picking.display_position(self.plotter.renderer, self.mesh, cell_id)

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
        self.texts.set_axes(self.P, self.names, self.style)

    def axes_labels(self) -> list[str]:
        return axes_labels(self.P, self.names)

    # ------------------------------------------------------------- exports
    def projected_mesh(self) -> pv.PolyData:
        """A copy of the current projected mesh (3D points, all coordinates as point data, and the colours
        on screen as ``RGB`` (V, 3) uint8 point data for PLY and OBJ files)."""
        if self.mesh is None:
            raise ValueError("nothing to export: no result yet")
        if self.look.coarse_on:   # the full mesh's points, not the ones of a moment ago
            self.set_projection(self.view, render=False)
        m = self.mesh.copy(deep=True)
        m.points = np.asarray(m.points, dtype=np.float64)
        color_by = self.style.colour_variable(self.names, self.dim)
        values = None if color_by is None else self.mesh.point_data[color_by]
        m.point_data["RGB"] = vertex_colours(self.style, self.dim, m.n_points, values,
                                             None if color_by is None else self.colour_limits(color_by),
                                             None if color_by is None else self.colour_map(color_by))
        m.point_data.active_scalars_name = self.style.color_by if self.style.color_by in self.names else None
        return m

    def colour_limits(self, name: str) -> list[float] | None:
        """The colour map's range for variable ``name``: the whole result's (a slice or a sweep keeps its
        colours), None when it has no finite value."""
        if self.complex is None:
            return None
        cyc = cyclic_colour(self.complex, name, self.names)
        if cyc is not None:   # an angle: its whole period, whose two ends are one colour
            return cyc[1]
        col = np.asarray(self.complex.vertices)[:, self.names.index(name)]
        col = col[np.isfinite(col)]
        return colour_range(col) if len(col) else None

    def colour_map(self, name: str) -> str:
        """The colour map for variable ``name``: a cyclic one for an angle (a periodic axis no seam
        reverses), else the style's."""
        cyc = None if self.complex is None else cyclic_colour(self.complex, name, self.names)
        return self.style.cmap if cyc is None else cyc[0]
