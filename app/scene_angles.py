"""How a :class:`gcmh_studio.scene.Scene` draws periodic (glued) axes: as circles when the style asks
("angles as circles", :class:`gcmh_studio.angles.CircleProjector`), with the glued seam as thick lines
(:func:`gcmh_studio.angles.seam_lines`).  The complex, its overlays and the seam all go through the same
circles, so they stay on each other.  No Qt here."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from .angles import CircleProjector, seam_lines, seam_spec
from .projection import Projector

SEAM_COLOR = "#ff5cf0"       # the glued seam of identified axes


class SceneAngles:
    """The periodic axes of ``scene``'s result (a Scene: this module is below scene.py), drawn as the style
    (``circles``, ``seam``) asks.

    ``seam``: (projector, mesh, actor) of the glued seam on show, else None."""

    def __init__(self, scene):
        self.scene = scene
        self.seam: tuple | None = None

    @property
    def circles_on(self) -> bool:
        """Periodic axes are drawn as circles (the style asks and the result has some)."""
        sc = self.scene
        return bool(sc.style.circles) and sc.source is not None and bool(seam_spec(sc.source))

    def projector_for(self, V: np.ndarray, projector: Projector) -> Projector:
        """``projector`` (of vertices ``V``), or with "angles as circles" one of their circles."""
        if not self.circles_on:
            return projector
        return CircleProjector(V, seam_spec(self.scene.source), center=projector.center)

    def set(self, circles: bool, seam: bool) -> None:
        """Periodic axes as circles or as numbers; the glued seam drawn or not (a new mesh for circles)."""
        sc = self.scene
        st = sc.style
        changed = bool(circles) != bool(st.circles)
        st.circles, st.seam = bool(circles), bool(seam)
        if sc.complex is not None and changed:
            sl = sc.slice
            if sl is None:
                sc.set_slice(None, render=False)
            else:
                sc.set_slice(*sl, render=False)
        self.show_seam()
        self.fit_overlays()

    def fit_overlays(self) -> None:
        """The overlays (a picked cell, the boundary, the grid cubes) drawn as the complex is: through the
        circles of "angles as circles", or plainly again."""
        sc = self.scene
        if sc.geometry is None or sc.view is None:
            return
        center, radii = sc.geometry.projector.center, sc.geometry.projector.radii()
        for geo, mesh, *_ in sc.overlay_meshes.items.values():
            pr = geo.projector
            is_circle = isinstance(pr, CircleProjector)
            if is_circle == self.circles_on:
                continue
            raw = pr.raw if is_circle else np.asarray(pr.XT.T, dtype=np.float64) + pr.center
            new = self.projector_for(raw, Projector(raw, center=center))
            new.set_radii(radii)
            geo.projector = new
            if mesh is not None:
                new.project_view(sc.view, out=mesh.points)
                mesh.GetPoints().Modified()
                mesh.Modified()

    def drop_seam(self) -> None:
        if self.seam is not None and self.seam[2] is not None and self.scene.plotter is not None:
            self.scene.plotter.remove_actor(self.seam[2], render=False)
        self.seam = None

    def show_seam(self) -> None:
        """The glued seam (:func:`gcmh_studio.angles.seam_lines`) as thick lines, when the style asks."""
        self.drop_seam()
        sc = self.scene
        if not sc.style.seam or sc.source is None or sc.geometry is None or sc.view is None:
            return
        X, E = seam_lines(sc.source)
        if len(E) == 0:
            return
        proj = self.projector_for(X, Projector(X, center=sc.geometry.projector.center))
        lines = np.empty((len(E), 3), dtype=np.int64)
        lines[:, 0] = 2
        lines[:, 1:] = E
        mesh = pv.PolyData(proj.project_view(sc.view), lines=lines.ravel())
        actor = sc.plotter.add_mesh(mesh, color=SEAM_COLOR, line_width=4.0, render_lines_as_tubes=True,
                                    render=False, reset_camera=False, name="gcmh-seam", pickable=False)
        self.seam = (proj, mesh, actor)

    def project(self) -> None:
        """Write the seam's points for the scene's view, in place."""
        if self.seam is not None and self.scene.view is not None:
            proj, mesh, _ = self.seam
            proj.project_view(self.scene.view, out=mesh.points)
            mesh.GetPoints().Modified()
            mesh.Modified()
