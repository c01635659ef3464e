"""H2 classes of a 3-manifold drawn as translucent surfaces on a scene (VTK, no Qt).

A surface is triangles in R^n (from :func:`gcmh_studio.cycles.generator_surface`), kept
among the scene's overlays (``scene.overlay_meshes.items``, the entry a line overlay has:
[Geometry, mesh, actor, colour, (width, opacity)]), so the scene projects its points with
every change of view, drops it with the result, and copies it with a detached scene as it
does the lines.  It is not clipped by a slice: the whole class stays in view.

    draw_homology_surfaces(scene, {"homology-surface-2-0": (X, T, "#ffb000", 0.35)})
"""

from __future__ import annotations

import numpy as np

from .overlays import projected_cells

SURFACE_PREFIX = "homology-surface-"
SURFACE_OPACITY = 0.6


def draw_homology_surfaces(scene, specs: dict, render: bool = True) -> None:
    """Show exactly the surfaces ``specs`` (name -> (vertices (m, n), triangles (T, 3), colour,
    opacity); names start with ``homology-surface-``): those drawn before and not named go."""
    items = scene.overlay_meshes.items
    gone = [n for n in list(items) if n.startswith(SURFACE_PREFIX) and n not in specs]
    for name in gone:
        scene.remove_overlay(name, render=False)
    for name, (X, T, color, opacity) in specs.items():
        _set_surface(scene, name, np.asarray(X, dtype=np.float64), np.asarray(T, dtype=np.int64), color,
                     float(opacity))
    if specs:
        scene.angles.fit_overlays()   # through the circles of "angles as circles" when they are on
    if render and (gone or specs):
        scene.plotter.render()


def _set_surface(scene, name, X, T, color, opacity):
    scene.remove_overlay(name, render=False)
    if scene.geometry is None or len(T) == 0:
        return
    geo, mesh = projected_cells(scene, X, T)
    actor = scene.plotter.add_mesh(mesh, color=color, opacity=opacity, render=False, reset_camera=False,
                                   name=f"gcmh-overlay-{name}", pickable=False, lighting=True,
                                   show_edges=False)
    scene.overlay_meshes.items[name] = [geo, mesh, actor, color, (1.0, opacity)]
