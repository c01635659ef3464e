"""H2 classes of a 3-manifold drawn as translucent surfaces on a scene (VTK, no Qt).

A surface is triangles in R^n (from :func:`gcmh_studio.cycles.generator_surface`), one of
the scene's overlays (:class:`gcmh_studio.overlays.SceneOverlays`, beside the lines), so the
scene projects its points with every change of view, clips it by the slice as it clips the
result (a triangle cut at the slab's planes), drops it with the result, and copies it with
a detached scene.

    draw_homology_surfaces(scene, {"homology-surface-2-0": (X, T, "#ffb000", 0.35)})
"""

from __future__ import annotations

import numpy as np

from .overlays import SURFACE_PREFIX

__all__ = ["SURFACE_OPACITY", "SURFACE_PREFIX", "draw_homology_surfaces"]

SURFACE_OPACITY = 0.6


def draw_homology_surfaces(scene, specs: dict, render: bool = True) -> None:
    """Show exactly the surfaces ``specs`` (name -> (vertices (m, n), triangles (T, 3), colour,
    opacity); names start with ``homology-surface-``): those drawn before and not named go."""
    gone = [n for n in scene.overlay_meshes.names() if n.startswith(SURFACE_PREFIX) and n not in specs]
    for name in gone:
        scene.remove_overlay(name, render=False)
    for name, (X, T, color, opacity) in specs.items():
        T = np.asarray(T, dtype=np.int64).reshape(-1, 3)
        if len(T):
            scene.overlay_meshes.set(name, np.asarray(X, dtype=np.float64), T, color, 1.0, float(opacity))
        else:
            scene.remove_overlay(name, render=False)
    if specs:
        scene.angles.fit_overlays()   # through the circles of "angles as circles" when they are on
    if render and (gone or specs):
        scene.plotter.render()
