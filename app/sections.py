"""The exact cross-section of a result on a :class:`gcmh_studio.scene.Scene` while it is sliced (no Qt here).

Slicing a result of dimension d >= 2 by ``u . x = c`` draws its section (:mod:`gcmh_core.section`: a complex
of dimension d - 1, cut from the cells themselves) opaque, in its own colour, over the faint ghost of the
whole result, with the slice's value and the section's chi and pieces written in the picture: a surface's
curves over its band of cells (the window of :mod:`gcmh_studio.slicing`), a higher result's section in
place of its slab.  A curve, or a direction the engine refuses (one whose hyperplanes are not sets of the glued space: a
reversed axis mixed with others), keeps the window.  On a glued domain the section is the glued space's:
cut along a periodic variable or one reversed across a seam too (the three-torus of angles cut along an
angle is a 2-torus; the closed Klein bottle cut along t, the circle {t = c} U {t = 2pi - c}).

:class:`SectionLayer` owns the section's mesh and text on a scene; :class:`SectionScene` is the scene
that uses it: :meth:`SectionScene.set_slice` draws the section (over a surface's band, or where
:meth:`Scene.set_slice` drew a higher result's slab), and the projection, the still picture's copy
(:meth:`Scene.detached`) and a new result carry it.
A slider step re-sections (the cells the hyperplane meets only, :class:`gcmh_core.section.Sectioner`)
and writes the new cells into the same mesh: no new actor.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from gcmh_core.errors import InputError
from gcmh_core.section import SectionCells, Sectioner

from .geometry import Geometry, display_complex, seam_spec
from .labels import font_size
from .projection import Projector, axis_label
from .scene import Scene
from .slicing import Slice, clip_polygons_at

SECTION_COLOR = "#ff7b5c"     # coral: apart from the surface's gold, the ghost's grey and viridis
TEXT_COLOR = "#ffd2c4"
TEXT_POSITION = (0.24, 0.035)  # viewport: right of the corner axes, under the object, left of the colour bar
GHOST_OPACITY = 0.025         # the whole result behind a section: a 2-skeleton has many layers, and a
#                               surface's ghost at the slab's 0.07 whitened the section in front of it
# The ghost's back faces are culled: software GL pays for every translucent layer's pixels, and the 3-sphere's
# ghost cost 2/3 of a slice step's render (0.7 of 1.05 s, load 20); culled, half as many layers, as faint.


def section_text(label: str, c: float, cells: SectionCells | None, scale: float = 1.0) -> str:
    """What the picture says of a section: ``w = 0.3   section: chi = 2, 1 piece`` (VTK's font has no Greek).
    ``scale``: the size of the values' range; a value within a billionth of it from 0 is written 0 (a sweep's
    middle frame said "w = -2.22e-16")."""
    if abs(c) <= 1e-9 * abs(scale):
        c = 0.0
    head = f"{label} = {c + 0.0:.3g}"
    if cells is None or cells.complex.count(0) == 0:
        return f"{head}   section: empty"
    pieces = cells.pieces
    return f"{head}   section: chi = {cells.euler_characteristic}, {pieces} piece{'s' if pieces != 1 else ''}"


def _fitting_font(plotter, text: str) -> int:
    """The words' font size: large for a projector, small enough that ``text`` fits between its place and
    the colour bar (a 420-pixel frame of an animation cut it)."""
    try:
        width = int(plotter.window_size[0])
    except Exception:  # noqa: BLE001 - a plotter without a window: the size it is tuned for
        width = 1600
    room = (0.88 - TEXT_POSITION[0]) * width          # pixels up to the colour bar (at 0.9)
    # (pyvista's add_text sizes are half VTK's: a character is about 1.1 of them wide)
    return max(4, min(font_size(plotter, 21), int(room / (1.1 * max(len(text), 1)))))


class SectionLayer:
    """The section of ``scene``'s result, drawn on its plotter.

    ``cells``: the :class:`gcmh_core.section.SectionCells` on show (None when no section is);
    ``geometry``: its drawing arrays (a :class:`gcmh_studio.geometry.Geometry` placed with the whole
    result's centre and scales, so it sits where it is in the ghost)."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.source = None                 # the complex cut: the result as computed (glued axes glued)
        self._cutter: Sectioner | None = None
        self._cutter_key: bytes | None = None
        self.cells: SectionCells | None = None
        self.value: float | None = None
        self.label = ""
        self.geometry: Geometry | None = None
        self.mesh: pv.PolyData | None = None
        self.actor = None
        self.text_actor = None

    # ------------------------------------------------------------------ what is cut
    def set_complex(self, cx) -> None:
        """A new result (``cx`` as the engine made it, before :func:`gcmh_studio.geometry.display_complex`)."""
        self.clear()
        self.source = cx
        self._cutter = None
        self._cutter_key = None

    def cutter(self, direction) -> Sectioner | None:
        """The :class:`Sectioner` of the result along ``direction`` (n,), or None when the result is a curve
        or the engine refuses the direction (its hyperplanes are not sets of the glued space): then the slab
        is drawn."""
        cx = self.source
        if cx is None or cx.dim < 2:
            return None
        u = np.asarray(direction, dtype=np.float64)
        key = u.tobytes()
        if key != self._cutter_key:
            try:
                self._cutter = Sectioner(cx, u)
            except InputError:
                self._cutter = None
            self._cutter_key = key
        return self._cutter

    # ------------------------------------------------------------------ drawing
    def show(self, direction, c: float) -> int:
        """Cut at ``direction . x = c`` and draw the section; the number of cells drawn (0 when empty)."""
        cutter = self.cutter(direction)
        if cutter is None:
            self.clear()
            return 0
        cells = cutter.cells(float(c))
        self.cells, self.value = cells, float(c)
        self.label = axis_label(cutter.direction, self.scene.names or cells.complex.point_names(), terms=3)
        self._draw(cells.complex)
        self._write_text()
        return 0 if self.mesh is None else int(self.mesh.n_cells)

    def _draw(self, sec) -> None:
        sc = self.scene
        if sec.count(0) == 0 or sc.geometry is None or sc.view is None:
            self._remove_mesh()
            return
        shown = display_complex(_seam_edges_whole(sec))    # cells across a glued seam drawn whole
        geo = Geometry.build(shown, lod=False) if sec.dim >= 1 else None
        if geo is None or len(geo.cells) == 0:
            self._remove_mesh()
            return
        V = np.asarray(shown.vertices)
        projector = Projector(V, center=sc.geometry.projector.center)
        projector.set_radii(sc.geometry.projector.radii())
        projector = sc.angles.projector_for(V, projector)     # "angles as circles": the whole's circles
        geo.projector = projector
        if self.mesh is not None and self._kind != geo.kind:
            self._remove_mesh()
        self.geometry = geo
        pts = projector.project_view(sc.view)
        if self.mesh is None:
            self.mesh = pv.PolyData(pts, lines=geo.cells) if geo.kind == "lines" else \
                pv.PolyData(pts, faces=geo.cells)
            self._kind = geo.kind
            self._set_normals()
            self.actor = self._add_actor(self.mesh, geo.kind)
        else:   # the same actor: new points and cells written into its mesh
            self.mesh.points = pts
            if geo.kind == "lines":
                self.mesh.lines = geo.cells
            else:
                self.mesh.faces = geo.cells
            self._set_normals()

    def _set_normals(self) -> None:
        geo, mesh, sc = self.geometry, self.mesh, self.scene
        if geo is None or mesh is None or geo.normals is None:
            return
        normals = np.zeros((mesh.n_points, 3), dtype=np.float32)
        if sc.view is not None and not sc.view.linear:
            mn = geo.mesh_normals()
            if mn is not None:
                mn.write(np.asarray(mesh.points, dtype=np.float32), normals)
        else:
            geo.normals.write(sc.P, normals)
        mesh.point_data["Normals"] = normals
        mesh.point_data.active_normals_name = "Normals"

    _kind = ""

    def _add_actor(self, mesh, kind: str):
        pl = self.scene.plotter
        if kind == "lines":
            actor = pl.add_mesh(mesh, color=SECTION_COLOR, line_width=6.0, render_lines_as_tubes=True,
                                ambient=0.35, render=False, reset_camera=False, name="gcmh-section",
                                pickable=False)
        else:
            actor = pl.add_mesh(mesh, color=SECTION_COLOR, opacity=1.0, show_edges=True, edge_color="#7a3526",
                                line_width=0.5, smooth_shading=False, specular=0.2, specular_power=30.0,
                                diffuse=0.85, ambient=0.2, render=False, reset_camera=False,
                                name="gcmh-section", pickable=False)
            actor.prop.interpolation = "phong"
        return actor

    def _write_text(self) -> None:
        pl = self.scene.plotter
        lo, hi = self._cutter.range() if self._cutter is not None else (0.0, 1.0)
        text = section_text(self.label, self.value if self.value is not None else 0.0, self.cells, hi - lo)
        size = _fitting_font(pl, text)
        if self.text_actor is None:
            # (named apart from "gcmh-section": adding an actor by name removes those named "<name>-...")
            self.text_actor = pl.add_text(text, position=TEXT_POSITION, viewport=True,
                                          font_size=size, color=TEXT_COLOR, name="gcmh-text-section")
        else:
            self.text_actor.SetInput(text)
            self.text_actor.GetTextProperty().SetFontSize(2 * size)   # (as add_text sets it)

    def redraw(self) -> None:
        """Draw the section on show again (the periodic axes drawn another way: as circles or as numbers)."""
        if self.cells is not None:
            self._draw(self.cells.complex)

    def text(self) -> str:
        """The words written in the picture ("" when no section is shown)."""
        return "" if self.text_actor is None else str(self.text_actor.GetInput())

    def project(self) -> None:
        """Write the section's points (and normals) for the scene's view, in place."""
        if self.mesh is None or self.geometry is None or self.scene.view is None:
            return
        self.geometry.projector.project_view(self.scene.view, out=self.mesh.points)
        self.mesh.GetPoints().Modified()
        self._set_normals()
        self.mesh.Modified()

    def _remove_mesh(self) -> None:
        if self.actor is not None and self.scene.plotter is not None:
            self.scene.plotter.remove_actor(self.actor, render=False)
        self.actor = None
        self.mesh = None
        self.geometry = None
        self._kind = ""

    def clear(self) -> None:
        """No section on show (its mesh and text removed)."""
        self._remove_mesh()
        if self.text_actor is not None and self.scene.plotter is not None:
            self.scene.plotter.remove_actor(self.text_actor, render=False)
        self.text_actor = None
        self.cells = None
        self.value = None

    @property
    def shown(self) -> bool:
        return self.cells is not None

    # ------------------------------------------------------------------ copies for another thread
    def detached(self, scene: Scene) -> SectionLayer:
        """A copy for ``scene`` (a detached scene): its mesh a deep copy, no actors."""
        other = SectionLayer(scene)
        other.source, other._cutter, other._cutter_key = self.source, self._cutter, self._cutter_key
        other.cells, other.value, other.label = self.cells, self.value, self.label
        other.geometry, other._kind = self.geometry, self._kind
        other.mesh = None if self.mesh is None else self.mesh.copy(deep=True)
        return other

    def adopt(self, other: SectionLayer) -> None:
        """Draw ``other``'s section (its mesh shared) and text on this layer's plotter."""
        self.source, self._cutter, self._cutter_key = other.source, other._cutter, other._cutter_key
        self.cells, self.value, self.label = other.cells, other.value, other.label
        self.geometry, self._kind, self.mesh = other.geometry, other._kind, other.mesh
        if self.mesh is not None:
            self.actor = self._add_actor(self.mesh, self._kind)
        if self.cells is not None:
            self._write_text()


def _seam_edges_whole(sec):
    """A curve section as it is drawn: each edge across a glued seam drawn whole on the seam's high side (its
    low end moved up a period, and reflected across a reversed seam), not stretched across the box; the
    engine's own copy for a surface (:func:`gcmh_studio.geometry.display_complex`).  For the eye only."""
    spec = seam_spec(sec)
    if sec.dim != 1 or not spec or sec.count(1) == 0:
        return sec
    from gcmh_core import CellComplex

    V = np.asarray(sec.vertices, dtype=np.float64)
    E = np.asarray(sec.edges, dtype=np.int64).reshape(-1, 2)
    ends = V[E]                                            # (E, 2, n)
    for p, period, lo, flips, mirror in spec:
        across = np.abs(ends[:, 0, p] - ends[:, 1, p]) > period / 2
        low = across[:, None] & (ends[:, :, p] < lo + period / 2)
        ends[low, p] += period
        for b, m in zip(flips, mirror):
            ends[low, b] = m - ends[low, b]
    moved = np.flatnonzero(np.any(ends != V[E], axis=2).ravel())
    if moved.size == 0:
        return sec
    flat = E.ravel().copy()
    flat[moved] = V.shape[0] + np.arange(moved.size)      # a moved end: a vertex of its own
    points = np.concatenate([V, ends.reshape(-1, V.shape[1])[moved]])
    meta = {key: value for key, value in sec.meta.items() if key != "periodic"}
    return CellComplex(sec.n, sec.k, points, flat.reshape(-1, 2), {}, meta)


def _no_slab(n: int) -> Slice:
    """An empty window's slice: the slab drawn as nothing while the section stands for it."""
    return Slice(np.empty((0, n)), np.empty(0, np.int64), np.zeros(1, np.int64), np.empty(0, np.int64),
                 np.empty(0, np.int64))


class SectionScene(Scene):
    """A :class:`gcmh_studio.scene.Scene` that shows the exact section of a result of dimension >= 2 while
    sliced (``sections``, a :class:`SectionLayer`), in place of the slab of cells."""

    def __init__(self, plotter, anti_aliasing: str | None = "fxaa"):
        self.sections = SectionLayer(self)
        super().__init__(plotter, anti_aliasing)

    def clear(self) -> None:
        super().clear()
        self.sections.clear()

    def set_complex(self, cx, names, P, style=None, geometry=None) -> None:
        super().set_complex(cx, names, P, style, geometry)
        self.sections.set_complex(cx if self.complex is not None else None)

    def set_slice(self, direction=None, c: float = 0.0, w: float = 0.0, render: bool = True) -> int:
        """As :meth:`Scene.set_slice`, and the section at ``c`` of a result of dimension >= 2: a surface's
        curves drawn over its band of cells within ``w`` (the band is the curves' neighbourhood on the
        surface, one or two layers: it reads); a higher result's section instead of its slab (a pale pile of
        cells). Returns the number of cells drawn (the band's, or the section's)."""
        geo, view = self.geometry, self.view
        if direction is None or geo is None or view is None or self.sections.cutter(direction) is None:
            self.sections.clear()
            return super().set_slice(direction, c, w, render)
        if geo.dim == 2:
            u = np.asarray(direction, dtype=float)
            h = np.asarray(self.complex.vertices) @ u
            levels = self.sections.cutter(u).levels(float(c), float(h.min()) - w, float(h.max()) + w)
            if len(levels) > 1:   # a glued space's section lies on several levels: the band round each
                self.slice = (u, float(c), float(w))
                drawn = self._band(u, levels, float(w))
                self.overlay_meshes.set_ghost(self.style.slice_context)
            else:
                drawn = super().set_slice(direction, c, w, render=False)
            self.sections.show(u, float(c))
            if render:
                self.plotter.render()
            return drawn
        u = np.asarray(direction, dtype=float)
        self.slice = (u, float(c), float(w))
        empty = Geometry.from_slice(_no_slab(geo.n), geo.dim, geo.n, geo.projector.center, geo.projector.radii())
        self._show_geometry(empty, np.empty((0, geo.n)))    # the section stands for the slab
        drawn = self.sections.show(u, float(c))
        self.overlay_meshes.rebuild()
        self.overlay_meshes.set_ghost(self.style.slice_context)
        ghost = self.overlay_meshes.ghost
        if ghost is not None and ghost[1] is not None:
            ghost[1].prop.opacity = GHOST_OPACITY
            ghost[1].prop.culling = "back"
        if render:
            self.plotter.render()
        return drawn

    def _band(self, u, levels, w: float) -> int:
        """Draw the surface's cells within ``w`` of each of ``levels`` (as :meth:`Scene.set_slice` draws the one
        band round ``c``)."""
        geo = self.geometry
        sl = clip_polygons_at(np.asarray(self.complex.vertices), geo.offsets, geo.vids, u, levels, w)
        self._show_geometry(Geometry.from_slice(sl, geo.dim, geo.n, geo.projector.center, geo.projector.radii(),
                                                cell_ids=geo.cell_ids), sl.vertices)
        self.overlay_meshes.rebuild()
        self.angles.fit_overlays()
        return 0 if self.mesh is None else int(self.mesh.n_cells)

    def set_angle_look(self, circles: bool, seam: bool, render: bool = True) -> None:
        super().set_angle_look(circles, seam, render=False)
        self.sections.redraw()
        if render:
            self.plotter.render()

    def set_projection(self, P, render: bool = True, moving: bool = False) -> None:
        super().set_projection(P, render=False, moving=moving)
        self.sections.project()
        if render:
            self.plotter.renderer.ResetCameraClippingRange()
            self.plotter.render()

    def detached(self) -> SectionScene:
        other = super().detached()
        assert isinstance(other, SectionScene)
        other.sections = self.sections.detached(other)
        return other

    def adopt(self, other: Scene, style=None) -> None:
        super().adopt(other, style)
        if isinstance(other, SectionScene):
            self.sections.adopt(other.sections)
