"""The moving look of a :class:`gcmh_studio.scene.Scene`: cheaper while the view moves, exactly as before once
it rests.  No Qt here.

While the view moves (a slider, a drag, a parameter) a scene is drawn cheaper: a very large result by its
coarse copy (:attr:`gcmh_studio.geometry.Geometry.coarse`); a see-through one lit by one headlight instead
of the five lights of pyvista's light kit (software GL shades every layer of every pixel for each light: a
three-torus slider step takes about half the time, its edges and colours as they were); and without FXAA,
a full-screen pass that took 24 of a 38 ms render of a small result under Xvfb.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

MOVING_LIGHT = 0.85          # the moving look's one headlight: as bright as the light kit (the three-torus,
                             # still and moving frames compared: the least mean difference, 0.8 of 255)


class MovingLook:
    """The moving look of ``scene``: its coarse copy, the headlight standing in for its lights, FXAA paused.

    The scene says when it moves (:meth:`set_lights`, :meth:`show_coarse`, :meth:`hide_coarse`) and drops
    the coarse copy when its actor changes (:meth:`drop_coarse`)."""

    def __init__(self, scene):   # (a Scene: this module is below scene.py)
        self.scene = scene
        self._coarse: tuple | None = None          # (geometry, mesh, actor, normals array) of the coarse copy
        self.coarse_on = False
        self._still_lights: list | None = None     # the renderer's lights while one headlight stands in
        self._fxaa_paused = False

    def available(self) -> bool:
        """The result on screen has a moving look cheaper than its still one."""
        return (self.lod_available() or self.see_through() or self.scene.anti_aliasing == "fxaa"
                or self.scene.overlay_meshes.ghost is not None)

    def shown(self) -> bool:
        return self.coarse_on or self._still_lights is not None or self._fxaa_paused or self._ghost_hidden()

    def see_through(self) -> bool:
        """The complex is drawn see-through (a lit surface or 2-skeleton with opacity below 1)."""
        sc = self.scene
        return (sc.actor is not None and sc.dim >= 2 and sc.actor.prop.lighting
                and float(sc.actor.prop.opacity) < 1.0)

    def lod_available(self) -> bool:
        """A coarse copy exists for the whole result on screen (no slice, an actor to stand in for)."""
        sc = self.scene
        g = sc.geometry
        return (g is not None and g.coarse is not None and sc.slice is None and sc.actor is not None
                and not sc.circles_on
                and sc.draw_geo is g)

    def set_lights(self, moving: bool) -> None:
        """The moving look's lights, anti-aliasing and slice ghost (``moving``), or the scene's own."""
        self._still_light(not (moving and self.see_through()))
        self._still_fxaa(not moving)
        self._still_ghost(not moving)

    def _still_ghost(self, still: bool) -> None:
        """The faint whole behind a slice shown (``still``) or hidden while the view moves: its thousands of
        translucent cells took 160 of a 250 ms three-torus section step in the window under software GL."""
        ghost = self.scene.overlay_meshes.ghost
        if ghost is not None and ghost[1] is not None:
            ghost[1].SetVisibility(still)

    def _ghost_hidden(self) -> bool:
        ghost = self.scene.overlay_meshes.ghost
        return ghost is not None and ghost[1] is not None and not ghost[1].GetVisibility()

    def restore_lights(self) -> None:
        """The scene's own lights back (FXAA as it is)."""
        self._still_light(True)

    def _still_fxaa(self, still: bool) -> None:
        """FXAA as the scene was set up (``still``), or off while moving."""
        if self.scene.anti_aliasing != "fxaa" or still != self._fxaa_paused:
            return
        self.scene.plotter.renderer.SetUseFXAA(still)
        self._fxaa_paused = not still

    def _still_light(self, still: bool) -> None:
        """Light the scene with its own lights (``still``) or with one headlight (the same light objects
        come back in the same order, so the still picture is the same, pixel for pixel)."""
        ren = self.scene.plotter.renderer
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
    def show_coarse(self) -> None:
        """The coarse copy at the scene's view in place of the full mesh (made at the first call)."""
        sc = self.scene
        geo = sc.geometry.coarse
        if self._coarse is None:
            pts = geo.projector.project_view(sc.view)
            mesh = (pv.PolyData(pts, lines=geo.cells) if geo.kind == "lines" else pv.PolyData(pts, faces=geo.cells))
            C = geo.projector.XT.T + np.asarray(geo.projector.center, dtype=np.float32)   # back to R^n
            for i, name in enumerate(sc.names):
                mesh.point_data[name] = np.ascontiguousarray(C[:, i], dtype=np.float64)
            normals = None
            if geo.normals is not None:
                mesh.point_data["Normals"] = np.zeros((mesh.n_points, 3), dtype=np.float32)
                mesh.point_data.active_normals_name = "Normals"
                normals = mesh.point_data["Normals"]
            kw = dict(sc.actor_kw)
            kw.update(render=False, reset_camera=False, name="gcmh-complex-coarse", show_scalar_bar=False,
                      pickable=False, show_edges=False)   # (edges are a second pass over every cell)
            actor = sc.plotter.add_mesh(mesh, **kw)
            if normals is not None:
                actor.prop.interpolation = "phong"
            self._coarse = (geo, mesh, actor, normals)
        geo, mesh, actor, normals = self._coarse
        geo.projector.project_view(sc.view, out=mesh.points)
        mesh.GetPoints().Modified()
        if normals is not None:
            if sc.view.linear:
                geo.normals.write(sc.view.P, normals)
            else:
                geo.mesh_normals().write(mesh.points, normals)
            mesh.GetPointData().GetNormals().Modified()
        mesh.Modified()
        actor.SetVisibility(True)
        sc.actor.SetVisibility(False)
        self.coarse_on = True

    def hide_coarse(self) -> None:
        if self.coarse_on and self._coarse is not None:
            self._coarse[2].SetVisibility(False)
            if self.scene.actor is not None:
                self.scene.actor.SetVisibility(True)
        self.coarse_on = False

    def drop_coarse(self) -> None:
        if self._coarse is not None:
            self.scene.plotter.remove_actor(self._coarse[2], render=False)
            self._coarse = None
        if self.coarse_on and self.scene.actor is not None:
            self.scene.actor.SetVisibility(True)
        self.coarse_on = False
