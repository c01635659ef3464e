"""The mesh a :class:`gcmh_studio.scene.Scene` draws of its complex, written in place for each view.  No Qt here.

The mesh is made once per drawn :class:`gcmh_studio.geometry.Geometry` (the whole result, or a slice): lines
for curves, filled polygons for surfaces, the 2-skeleton above.  A new view writes the projected points, and
a surface's vertex normals, into the mesh's VTK arrays: no new mesh, no new actor, same topology.  Nonlinear
views (and "angles as circles") get their normals from the projected mesh
(:class:`gcmh_studio.geometry.MeshNormals`), linear ones from the bivectors; sheets a linear view lays onto
each other are held a little apart (:meth:`ComplexMesh.separate_sheets`).
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from .geometry import Geometry, NormalField
from .projection import Projector

SHEET_GAP = 2e-3             # coincident sheets held apart by this much of the object's radius (no z-fighting)


class ComplexMesh:
    """The complex's mesh on ``scene`` (a Scene: this module is below scene.py), which gives the view, the
    variables' names and whether angles are drawn as circles.

    ``mesh``: the pyvista mesh (None: nothing drawn); ``projector``: its vertices' projector; ``pts`` and
    ``normals``: views of its VTK points and, for surfaces, normals (written in place)."""

    def __init__(self, scene):
        self.scene = scene
        self.geometry: Geometry | None = None      # what the mesh draws (the slice, or the whole)
        self.mesh: pv.PolyData | None = None
        self.projector: Projector | None = None
        self.pts: np.ndarray | None = None
        self.normals: np.ndarray | None = None
        self.normal_field: NormalField | None = None

    def clear(self) -> None:
        self.geometry = self.mesh = self.projector = None
        self.pts = self.normals = self.normal_field = None

    def build(self, geo: Geometry, V: np.ndarray, projector: Projector) -> None:
        """The mesh of ``geo`` (vertices ``V`` (V, n) for the colour data) through ``projector`` at the scene's
        view; None when ``geo`` draws nothing (an empty slice)."""
        self.clear()
        self.geometry, self.projector = geo, projector
        if geo.projector.XT.shape[1] == 0 or len(geo.cells) == 0:
            return
        pts = projector.project_view(self.scene.view)
        if geo.kind == "lines":
            mesh = pv.PolyData(pts, lines=geo.cells)
        else:
            mesh = pv.PolyData(pts, faces=geo.cells)
        self.normal_field = geo.normals
        if self.normal_field is not None:
            mesh.point_data["Normals"] = np.zeros((len(V), 3), dtype=np.float32)
            mesh.point_data.active_normals_name = "Normals"
        for i, name in enumerate(self.scene.names):
            mesh.point_data[name] = np.ascontiguousarray(V[:, i])
        mesh.cell_data["cell_id"] = np.asarray(geo.cell_ids if geo.cell_ids is not None
                                                else np.arange(mesh.n_cells), dtype=np.int64)
        self.mesh = mesh
        self.pts = mesh.points  # a view of the VTK buffer: written in place
        self.normals = mesh.point_data["Normals"] if self.normal_field is not None else None
        self.write_normals()
        self.separate_sheets()

    def project(self) -> None:
        """Write the points (and normals) for the scene's view, in place."""
        if self.mesh is None or self.projector is None:
            return
        self.projector.project_view(self.scene.view, out=self.pts)
        self.mesh.GetPoints().Modified()
        self.write_normals()
        self.separate_sheets()
        self.mesh.Modified()

    def write_normals(self) -> None:
        """A surface's vertex normals for the scene's view, in place."""
        mesh, pts, normals, normal_field, geo = self.mesh, self.pts, self.normals, self.normal_field, self.geometry
        view, P = self.scene.view, self.scene.P
        if mesh is None or pts is None or normals is None or normal_field is None or geo is None or P is None:
            return
        if view is not None and (not view.linear or self.scene.circles_on):
            # the bivector identity needs a linear map: take the normals of the projected mesh
            mesh_normals = geo.mesh_normals()   # (made once, kept by the geometry)
            assert mesh_normals is not None     # (normals are a surface's: its polygons have them)
            mesh_normals.write(pts, normals)
        else:
            normal_field.write(P, normals)
        mesh.GetPointData().GetNormals().Modified()

    def separate_sheets(self) -> None:
        """Hold apart sheets that a linear view lays onto each other (the Clifford torus in Orthographic is a
        cylinder covered twice): each point moves ``SHEET_GAP`` of the object's radius along its normal, turned
        away from the centre, outwards where the first hidden coordinate is positive and inwards where it is
        negative. The depth test then draws one sheet in front everywhere instead of a speckle of both
        (z-fighting); the move is far below a pixel."""
        view, pts, normals, proj = self.scene.view, self.pts, self.normals, self.projector
        if (view is None or pts is None or normals is None or proj is None or not view.linear
                or view.frame.shape[0] < 4 or self.scene.circles_on):
            return
        h = np.asarray(view.frame[3], dtype=proj.XT.dtype) @ proj.XT          # (V,) the first hidden coordinate
        side = np.where(h >= 0, 1.0, -1.0).astype(pts.dtype)
        out = np.einsum("ij,ij->i", normals, pts)
        side *= np.where(out >= 0, 1.0, -1.0).astype(pts.dtype)
        length = np.sqrt(np.einsum("ij,ij->i", normals, normals))               # (the normals' lengths vary)
        side /= np.where(length > 0, length, np.inf).astype(pts.dtype)
        gap = SHEET_GAP * proj.radii()[0]
        pts += (gap * side)[:, None] * normals

    def detached(self, scene) -> ComplexMesh:
        """A copy for ``scene`` (a detached scene): the mesh a deep copy, sharing no VTK object with this one."""
        other = self.shared(scene)
        if self.mesh is not None:
            other.mesh = self.mesh.copy(deep=True)
            other.pts = other.mesh.points
            other.normals = other.mesh.point_data["Normals"] if self.normals is not None else None
        return other

    def shared(self, scene) -> ComplexMesh:
        """This mesh (not a copy) drawn on ``scene``."""
        other = ComplexMesh(scene)
        other.geometry, other.mesh, other.projector = self.geometry, self.mesh, self.projector
        other.pts, other.normals, other.normal_field = self.pts, self.normals, self.normal_field
        return other
