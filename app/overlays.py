"""What a :class:`gcmh_studio.scene.Scene` draws beside the complex: line overlays in R^n (boundary facets, grid
cubes, a picked cell) and, behind a slice, the whole result as a faint ghost.  Each is projected with the
scene's view and clipped by its slice.  No Qt here."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from .geometry import Geometry, boundary_lines, grid_cube_lines
from .projection import Projector
from .slicing import clip_polygons, clip_segments

BOUNDARY_COLOR = "#ff4d6d"
GRID_COLOR = "#9fb3d9"
PICK_COLOR = "#40ff90"
GHOST_COLOR = "#c8d2e6"


def projected_cells(scene, X, cells, offsets=None):
    """(Geometry, mesh) of cells on points ``X`` (m, n) in ``scene``'s view and frame: ``cells`` (c, 2) are
    segments, (c, 3) triangles, or with ``offsets`` (c + 1,) the corners of polygons (CSR, as a slice clips
    triangles); the scene projects the points again with every change of view."""
    cells = np.asarray(cells, dtype=np.int64)
    pr = Projector(X, center=scene.geometry.projector.center)
    pr.set_radii(scene.geometry.projector.radii())
    if offsets is not None:
        offsets = np.asarray(offsets, dtype=np.int64)
        sizes = np.diff(offsets)
        packed = np.insert(cells, offsets[:-1], sizes)   # [size, corners..] per polygon
    else:
        packed = np.empty((len(cells), cells.shape[1] + 1), dtype=np.int64)
        packed[:, 0] = cells.shape[1]
        packed[:, 1:] = cells
        packed = packed.ravel()
    pts = pr.project_view(scene.view)
    if offsets is None and cells.shape[1] == 2:
        return Geometry(1, X.shape[1], "lines", packed, pr), pv.PolyData(pts, lines=packed)
    return Geometry(2, X.shape[1], "polygons", packed, pr), pv.PolyData(pts, faces=packed)


class SceneOverlays:
    """The overlays and the slice's ghost of ``scene`` (a Scene: this module is below scene.py).

    ``items``: name -> [Geometry of the lines or triangles, mesh, actor, color, (width, opacity)] as drawn
    (sliced); ``ghost``: (mesh, actor) of the whole result while slicing, else None."""

    def __init__(self, scene):
        self.scene = scene
        self.items: dict = {}
        self._src: dict = {}   # name -> (vertices (m, n), cells (c, 2 or 3), color, width, opacity) before slicing
        self.ghost: tuple | None = None
        # (cx, values (V,), cmap, name): the result coloured by per-vertex values (curvature) until told
        # otherwise, again whenever its mesh is made anew (a slice, a style)
        self.colouring: tuple | None = None

    def clear(self) -> None:
        self.colouring = None
        self.set_ghost(False)
        for name in list(self.items):
            self.remove(name)
        self._src.clear()

    def set(self, name: str, vertices, edges, color: str, width: float = 2.0, opacity: float = 1.0) -> None:
        """Line segments in R^n (vertices (m, n), edges (E, 2)) drawn with the view and clipped by the slice;
        edges (T, 3) are triangles, drawn lit (a surface: the H2 classes of a 3-manifold) and clipped alike."""
        self._src[name] = (np.asarray(vertices, dtype=np.float64), np.asarray(edges, dtype=np.int64),
                           color, float(width), float(opacity))
        self._build(name)

    def names(self) -> list:
        """The overlays asked for (drawn, or clipped away whole by the slice)."""
        return list(self._src)

    def remove(self, name: str) -> None:
        self._src.pop(name, None)
        ov = self.items.pop(name, None)
        if ov is not None and ov[2] is not None:
            self.scene.plotter.remove_actor(ov[2], render=False)

    def rebuild(self) -> None:
        """Clip every overlay again and colour the result's new mesh as asked (the slice changed)."""
        for name in list(self._src):
            self._build(name)
        self.recolour()

    def recolour(self) -> bool:
        """Colour the result's mesh on show by :attr:`colouring` again (its actor was made anew); False when
        there is none to apply."""
        if self.colouring is None or self.scene.mesh is None or self.scene.actor is None:
            return False
        return _apply_colours(self.scene, *self.colouring)

    def project(self) -> None:
        """Write the ghost's and the overlays' points for the scene's view, in place."""
        sc = self.scene
        if self.ghost is not None:
            sc.geometry.projector.project_view(sc.view, out=self.ghost[0].points)
            self.ghost[0].GetPoints().Modified()
            self.ghost[0].Modified()
        for geo, mesh, *_ in self.items.values():
            if mesh is not None:
                geo.projector.project_view(sc.view, out=mesh.points)
                mesh.GetPoints().Modified()
                mesh.Modified()

    def _build(self, name: str) -> None:
        sc = self.scene
        X, E, color, width, opacity = self._src[name]
        old = self.items.pop(name, None)
        if old is not None and old[2] is not None:
            sc.plotter.remove_actor(old[2], render=False)
        if sc.geometry is None or len(E) == 0:
            return
        offsets = None
        if sc.slice is not None:   # as the result is: cut at the slab's two planes
            u, c, w = sc.slice
            if E.shape[1] == 3:
                sl = clip_polygons(X, np.arange(0, E.size + 1, 3), E.ravel(), u, c, w)
                X, E, offsets = sl.vertices, sl.vids, sl.offsets
            else:
                sl = clip_segments(X, E, u, c, w)
                X, E = sl.vertices, sl.edges
            if sl.empty:
                return
        geo, mesh = projected_cells(sc, X, E, offsets)
        self.items[name] = [geo, mesh, None, color, (width, opacity)]
        self.items[name][2] = self._add_actor(name, geo, mesh, color, (width, opacity))

    def _add_actor(self, name, geo, mesh, color, look):
        width, opacity = look
        if geo.kind == "polygons":   # a see-through surface, lit
            return self.scene.plotter.add_mesh(mesh, color=color, opacity=opacity, render=False, reset_camera=False,
                                               name=f"gcmh-overlay-{name}", pickable=False, lighting=True,
                                               show_edges=False)
        return self.scene.plotter.add_mesh(mesh, color=color, line_width=width, opacity=opacity, render=False,
                                           reset_camera=False, name=f"gcmh-overlay-{name}", pickable=False,
                                           render_lines_as_tubes=opacity >= 1.0, lighting=False)

    def set_ghost(self, on: bool) -> None:
        """The whole result, faint and unlit, behind a slice: where the slice sits in the whole."""
        sc = self.scene
        if not on:
            if self.ghost is not None:
                sc.plotter.remove_actor(self.ghost[1], render=False)
                self.ghost = None
            return
        if self.ghost is not None:
            return
        geo = sc.geometry
        mesh = pv.PolyData(geo.projector.project_view(sc.view), faces=geo.cells)
        self.ghost = (mesh, self._add_ghost_actor(mesh))

    def _add_ghost_actor(self, mesh):
        return self.scene.plotter.add_mesh(mesh, color=GHOST_COLOR, opacity=0.07, lighting=False, pickable=False,
                                           render=False, reset_camera=False, name="gcmh-slice-ghost")

    def detached(self, scene) -> SceneOverlays:
        """A copy for ``scene`` (a detached scene): deep copies of the meshes, no actors."""
        other = SceneOverlays(scene)
        other.ghost = None if self.ghost is None else (self.ghost[0].copy(deep=True), None)
        other.items = {name: [geo, None if mesh is None else mesh.copy(deep=True), None, color, look]
                       for name, (geo, mesh, _actor, color, look) in self.items.items()}
        other._src = dict(self._src)
        other.colouring = self.colouring
        return other

    def adopt(self, other: SceneOverlays) -> None:
        """Draw ``other``'s ghost and overlays (their meshes shared, not copied) on this scene's plotter."""
        if other.ghost is not None:
            self.ghost = (other.ghost[0], self._add_ghost_actor(other.ghost[0]))
        for name, (geo, mesh, _actor, color, look) in other.items.items():
            self.items[name] = [geo, mesh, self._add_actor(name, geo, mesh, color, look), color, look]
        self.colouring = other.colouring   # (a screenshot or a still picture: curvature colours too)
        self.recolour()


def draw_overlays(scene, cx, boundary: bool = False, grid: bool = False, picked: dict | None = None) -> str | None:
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


HOMOLOGY_PREFIX = "homology-"
SURFACE_PREFIX = "homology-surface-"   # the H2 classes' surfaces (gcmh_studio.homology_surfaces)


def draw_homology(scene, specs: dict, render: bool = True) -> None:
    """Show exactly the homology overlays ``specs`` (name -> (vertices (m, n), edges (E, 2), colour, width),
    from :class:`gcmh_studio.qt_homology_box.QtHomologyBox`): other lines named ``homology-*`` go (the H2
    surfaces are :func:`gcmh_studio.homology_surfaces.draw_homology_surfaces`' own)."""
    gone = [n for n in scene.overlay_meshes.names()
            if n.startswith(HOMOLOGY_PREFIX) and not n.startswith(SURFACE_PREFIX) and n not in specs]
    for name in gone:
        scene.remove_overlay(name, render=False)
    for name, (X, E, color, width) in specs.items():
        scene.set_overlay(name, X, E, color, width=width, render=False)
    if render and (gone or specs):   # (a new result clears nothing drawn: no render of the old one)
        scene.plotter.render()


CURVATURE_CMAP = "coolwarm"


def _drawn_values(scene, cx, values):
    """``values`` (V,) at the vertices of ``cx``, for the points of the mesh on show: the whole result's take
    their vertex's value; a surface on identified axes is drawn with its seam cells' low vertices moved a
    period up (those take their vertex's value), and a slice's new points on the slab's planes take the
    value of the nearest vertex (they lie on an edge, beside its ends)."""
    mesh = scene.mesh
    V = np.asarray(cx.vertices, dtype=np.float64)
    names = scene.names
    drawn = np.column_stack([np.asarray(mesh.point_data[name], dtype=np.float64) for name in names])
    if len(drawn) >= len(V) and np.array_equal(drawn[:len(V)], V):
        out = np.empty(len(drawn), dtype=np.float64)
        out[:len(V)] = values
        rest = np.arange(len(V), len(drawn))
    else:
        out = np.empty(len(drawn), dtype=np.float64)
        rest = np.arange(len(drawn))
    if rest.size:
        from scipy.spatial import cKDTree

        from .geometry import seam_spec

        pts = drawn[rest].copy()
        for p, period, lo, flips, mirror in seam_spec(cx):   # undo each move up a period
            up = pts[:, p] >= lo + period
            pts[up, p] -= period
            for b, mm in zip(flips, mirror):
                pts[up, b] = mm - pts[up, b]
        ok = np.isfinite(V).all(axis=1)
        index = np.flatnonzero(ok)
        _, nearest = cKDTree(V[ok]).query(np.nan_to_num(pts))
        out[rest] = values[index[nearest]]
    return out


def _apply_colours(scene, cx, values, cmap, name) -> bool:
    drawn = _drawn_values(scene, cx, values)
    scene.mesh.point_data[name] = drawn
    top = float(np.abs(drawn).max()) if drawn.size else 1.0
    top = top or 1.0
    mapper = scene.actor.mapper
    mapper.lookup_table = pv.LookupTable(cmap=cmap)
    mapper.array_name = name
    mapper.scalar_map_mode = "point"
    mapper.scalar_range = (-top, top)
    mapper.scalar_visibility = True
    scene.mesh.set_active_scalars(name)
    # the colour bar names what the colours now mean (the scene's own bar goes; its _add_actor brings it back)
    scene.texts.remove_bar()
    title = "K"   # (a short title: the bar sits at the right edge)
    args = scene.texts.bar_args(title)
    args.pop("title", None)
    scene.plotter.add_scalar_bar(title, mapper=mapper, **args)
    scene.texts.bar_added(title)
    return True


def colour_by_values(scene, cx, values, cmap: str = CURVATURE_CMAP, name: str = "curvature") -> bool:
    """Colour the result on ``scene`` by per-vertex ``values`` (V,) of ``cx`` (a symmetric range: the sign of
    the curvature is the colour), or back to the style's colours when ``values`` is None.  The colouring
    stays asked for: a slice colours its cells (and the points it adds on its planes) the same way, and
    :meth:`SceneOverlays.recolour` applies it again to an actor made anew.  False when nothing is drawn."""
    scene.overlay_meshes.colouring = None if values is None else \
        (cx, np.asarray(values, dtype=np.float64), cmap, name)
    if scene.mesh is None or scene.actor is None:
        return False
    if values is None:
        scene._add_actor()   # the style's colours again
    else:
        _apply_colours(scene, *scene.overlay_meshes.colouring)
    scene.plotter.render()
    return True


def homology_lines_mesh(scene):
    """The homology overlays on show (lines, and the H2 surfaces as polygons, as sliced) as one projected
    mesh, for an export beside the result's mesh: cell data ``cycle`` (1, 2, ... in the order of their names;
    the w1 loop and its marks 0) and point data ``RGB`` (V, 3) uint8 (their colours on screen).  None when
    no homology overlay is drawn.  :func:`export_cycles` writes it with the cycle of each cell."""
    names = sorted(n for n, item in scene.overlays.items() if n.startswith(HOMOLOGY_PREFIX) and item[1] is not None)
    if not names:
        return None
    meshes = []
    number = 0
    for name in names:
        _geo, mesh, _actor, color, _look = scene.overlays[name]
        m = mesh.copy(deep=True)
        is_cycle = not name.startswith(HOMOLOGY_PREFIX + "w1")
        number += is_cycle
        m.cell_data["cycle"] = np.full(m.n_cells, number if is_cycle else 0, dtype=np.int32)
        m.point_data["RGB"] = np.tile(np.array(pv.Color(color).int_rgb, dtype=np.uint8), (m.n_points, 1))
        meshes.append(m)
    out = meshes[0].merge(meshes[1:], merge_points=False) if len(meshes) > 1 else meshes[0]
    return out.extract_surface() if not isinstance(out, pv.PolyData) else out


def export_cycles(scene, mesh_path) -> str | None:
    """Write the homology overlays on show beside an exported mesh ``mesh_path`` (``name.ply`` ->
    ``name-cycles.ply``; .obj alike; .stl, which has no lines, -> .vtp), each cell with its cycle
    (:func:`gcmh_studio.cycles.write_cycles`).  Returns the path written, or None when none is drawn."""
    import os

    from .cycles import write_cycles

    mesh = homology_lines_mesh(scene)
    if mesh is None:
        return None
    stem, ext = os.path.splitext(str(mesh_path))
    return write_cycles(mesh, f"{stem}-cycles{ext if ext.lower() in ('.ply', '.obj', '.vtp') else '.vtp'}")
