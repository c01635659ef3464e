"""The parts a Scene owns: the complex's mesh written in place for each view (gcmh_studio.complex_mesh) and the
periodic axes drawn as circles (gcmh_studio.scene_angles)."""

import numpy as np
import pyvista as pv

from gcmh_core import extract
from gcmh_core.examples import load_example
from gcmh_studio.angles import CircleProjector
from gcmh_studio.projection import ProjectionModel
from gcmh_studio.scene import Scene, Style

from app_helpers import torus_complex


def test_a_detached_copy_keeps_its_points_while_the_scene_moves_and_an_adopting_scene_writes_them():
    cx = torus_complex(16, 4)
    pl, pl2 = pv.Plotter(off_screen=True, window_size=(160, 120)), pv.Plotter(off_screen=True, window_size=(160, 120))
    try:
        sc = Scene(pl, anti_aliasing=None)
        m = ProjectionModel(n=4)
        m.angles[2] = 20.0
        sc.set_complex(cx, cx.point_names(), m.view(), Style(color_by="x4"))
        copy = sc.detached()
        assert copy.mesh is not sc.mesh and not np.shares_memory(copy.drawn.pts, sc.drawn.pts)
        assert not np.shares_memory(copy.drawn.normals, sc.drawn.normals)
        points, normals = np.array(copy.mesh.points), np.array(copy.drawn.normals)
        m.angles[2] = 50.0
        sc.set_projection(m.view(), render=False)            # the GUI thread moves on ...
        assert not np.allclose(sc.mesh.points, points)
        assert np.array_equal(copy.mesh.points, points) and np.array_equal(copy.drawn.normals, normals)
        other = Scene(pl2, anti_aliasing=None)               # ... the copy is drawn elsewhere, shared
        other.adopt(copy)
        assert other.mesh is copy.mesh and other.draw_geo is sc.draw_geo
        other.set_projection(m.view(), render=False)         # and written in place for a view as the scene's
        assert np.array_equal(copy.mesh.points, sc.mesh.points)
        assert np.array_equal(copy.drawn.normals, sc.drawn.normals)
    finally:
        pl.close()
        pl2.close()


def test_an_overlay_follows_the_complex_onto_its_circles_and_back():
    ex = load_example("torus-angles")
    cx = extract(ex.formulas, ex.bounds, 8, variables=ex.variables, periodic=ex.periodic)
    pl = pv.Plotter(off_screen=True, window_size=(160, 120))
    try:
        sc = Scene(pl, anti_aliasing=None)
        view = ProjectionModel(n=5, axes=(3, 4, 2)).view()       # s, t and z on screen
        sc.set_complex(cx, cx.meta["variables"], view, Style())
        X = np.asarray(sc.complex.vertices)[:12]
        sc.set_overlay("path", X, np.c_[np.arange(11), np.arange(1, 12)], "#ffffff", render=False)
        geo, mesh, *_ = sc.overlays["path"]
        plain = np.array(mesh.points)
        sc.set_angle_look(circles=True, seam=False, render=False)
        geo, mesh, *_ = sc.overlays["path"]
        assert isinstance(geo.projector, CircleProjector)
        np.testing.assert_allclose(mesh.points, np.asarray(sc.mesh.points)[:12], atol=1e-5)   # on the ring
        assert not np.allclose(mesh.points, plain)
        sc.set_angle_look(circles=False, seam=False, render=False)
        geo, mesh, *_ = sc.overlays["path"]
        assert not isinstance(geo.projector, CircleProjector)
        np.testing.assert_allclose(mesh.points, plain, atol=1e-6)
    finally:
        pl.close()
