"""Angles drawn as angles (gcmh_studio.angles): the circles' map is one map on the glued domain (closed
pictures), two angles make a ring torus, the seam lies on the glued face, angles get a cyclic colour map,
and the pentagon linkage is recognised from its equations."""

from types import SimpleNamespace

import numpy as np
import pytest

from gcmh_core import extract
from gcmh_core.examples import load_example
from gcmh_studio.angles import (
    CYCLIC_CMAP,
    CircleProjector,
    circle_matrix,
    circle_rows,
    circular_mean,
    cyclic_colour,
    linkage_joints,
    linkage_points,
    seam_lines,
    seam_spec,
)

TWO_PI = 2 * np.pi


def _meta(name):
    ex = load_example(name)
    div = ex.div if np.ndim(ex.div) else [ex.div] * len(ex.variables)
    return ex, SimpleNamespace(meta={"periodic": ex.periodic, "variables": list(ex.variables),
                                     "bounds": np.asarray(ex.bounds, float).tolist(), "div": list(div)})


def _run(name, div):
    ex = load_example(name)
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic)


@pytest.mark.parametrize("name", ["torus-angles", "klein-bottle-closed", "moebius-band", "pentagon-linkage"])
def test_the_circles_take_one_value_on_both_sides_of_every_seam(name):
    ex, cx = _meta(name)
    spec = seam_spec(cx)
    assert spec
    rng = np.random.default_rng(1)
    B = np.asarray(ex.bounds, float)
    X = B[:, 0] + rng.random((200, len(ex.variables))) * (B[:, 1] - B[:, 0])
    Y, owners = circle_rows(X, spec)
    assert Y.shape == (len(owners), len(X))
    for p, period, _lo, flips, mirror in spec:
        Z = X.copy()
        Z[:, p] += period                       # across the seam of p ...
        for b, m in zip(flips, mirror):
            Z[:, b] = m - Z[:, b]               # ... with the axes it reverses reflected
        assert np.allclose(circle_rows(Z, spec)[0], Y, atol=1e-12)
    # and a step along a periodic axis that is not a whole period moves the point
    Z = X.copy()
    Z[:, spec[0][0]] += spec[0][1] / 3
    assert not np.allclose(circle_rows(Z, spec)[0], Y)


def test_two_angles_make_a_ring_torus():
    ex, cx = _meta("torus-angles")
    names = list(ex.variables)
    s, t = names.index("s"), names.index("t")
    rng = np.random.default_rng(2)
    X = np.zeros((300, len(names)))
    X[:, s], X[:, t] = rng.random(300) * TWO_PI, rng.random(300) * TWO_PI
    spec = seam_spec(cx)
    P = np.zeros((3, len(names)))
    P[0, s] = P[1, t] = 1.0                     # the two angles on screen x and y, nothing else
    proj = CircleProjector(X, spec, center=np.zeros(len(names)), dtype=np.float64)
    pts = proj.project(P)
    rho = np.hypot(pts[:, 0], pts[:, 1])
    assert np.allclose((rho - 2.0) ** 2 + pts[:, 2] ** 2, 1.0)   # ((2 + cos t) cos s, (2 + cos t) sin s, sin t)
    assert np.allclose(np.arctan2(pts[:, 1], pts[:, 0]) % TWO_PI, X[:, s])
    # an angle off screen adds nothing: the (x, y, z) view is the coordinates' own
    P2 = np.zeros((3, len(names)))
    P2[0, 0] = P2[1, 1] = P2[2, 2] = 1.0
    X[:, :3] = rng.random((300, 3))
    assert np.allclose(CircleProjector(X, spec, center=np.zeros(5), dtype=np.float64).project(P2), X[:, :3])
    assert circle_matrix(P2, proj.owners, spec).shape == (3, len(proj.owners))


def test_the_seam_lies_on_the_glued_face_of_m():
    cx = _run("torus-angles", 12)
    X, E = seam_lines(cx)
    names = cx.meta["variables"]
    s, t = names.index("s"), names.index("t")
    assert len(E) > 10
    on_s = np.isclose(X[:, s], TWO_PI, atol=1e-3)     # (the grid's last line is moved a little: its seam too)
    on_t = np.isclose(X[:, t], TWO_PI, atol=1e-3)
    assert (on_s | on_t).all() and on_s.any() and on_t.any()
    # the points are on the torus (the equations hold up to the grid's linear interpolation)
    def off_torus(P):
        return np.abs((np.hypot(P[:, 0], P[:, 1]) - 2) ** 2 + P[:, 2] ** 2 - 1)

    assert off_torus(X).max() <= off_torus(np.asarray(cx.vertices)).max() + 1e-9   # (a div-12 grid's chords)
    # each seam is a closed curve: every point ends two segments
    assert (np.bincount(E.ravel(), minlength=len(X)) == 2).all()


def test_without_identified_axes_there_is_no_seam_and_no_cyclic_map():
    cx = extract(["x^2 + y^2 + z^2 - 1"], [(-1.5, 1.5)] * 3, 6, variables="x,y,z")
    assert len(seam_lines(cx)[1]) == 0
    assert cyclic_colour(cx, "z", ["x", "y", "z"]) is None


def test_angles_get_a_cyclic_colour_map_over_their_period():
    ex, cx = _meta("klein-bottle-closed")
    names = list(ex.variables)
    cmap, lim = cyclic_colour(cx, "s", names)
    assert cmap == CYCLIC_CMAP and np.allclose(lim, [0, TWO_PI])
    from matplotlib import colormaps

    ends = colormaps[cmap]([0.0, 1.0])
    assert np.allclose(ends[0], ends[1], atol=0.02)          # 0 and 2pi: one colour
    assert cyclic_colour(cx, "x", names) is None             # not an angle
    assert cyclic_colour(cx, "t", names) is None             # reversed across s's seam: t and 2pi - t meet there


def test_the_pentagon_linkage_is_read_from_its_equations():
    ex = load_example("pentagon-linkage")
    assert linkage_joints(ex.variables, ex.formulas) == (1.0, 0.0)
    assert linkage_joints(["x", "y", "z"], ["x^2 + y^2 - 1", "z"]) is None
    start = [0, np.pi / 3, 5 * np.pi / 3, np.pi]
    J = linkage_points(start)
    assert np.allclose(J[-1], [1.0, 0.0])                      # the loop closes on the fixed rod
    assert np.allclose(np.linalg.norm(np.diff(J, axis=0), axis=1), 1.0)
    assert np.isclose(circular_mean([TWO_PI - 0.1, 0.1], TWO_PI, 0.0) % TWO_PI, 0.0, atol=1e-12)


def test_the_scene_draws_angles_as_circles_with_their_seam_and_a_cyclic_map():
    import pyvista as pv

    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Scene, Style

    cx = _run("torus-angles", 10)
    names = cx.meta["variables"]
    pl = pv.Plotter(off_screen=True, window_size=(300, 240))
    try:
        sc = Scene(pl, anti_aliasing=None)
        view = ProjectionModel(n=5, axes=(3, 4, 2)).view()       # s, t and z on screen
        sc.set_complex(cx, names, view, Style(color_by="t"))
        flat = np.array(sc.mesh.points)
        assert np.ptp(flat[:, 0]) <= TWO_PI + 1.0                # s drawn as a number: the box's width
        lut = sc.actor.mapper.lookup_table
        assert np.allclose(lut.GetRange(), (0.0, TWO_PI))         # the whole period ...
        assert sc.colour_map("t") == CYCLIC_CMAP                  # ... in a cyclic map
        assert sc.colour_map("x") != CYCLIC_CMAP
        sc.set_angle_look(circles=True, seam=True, render=False)
        ring = np.array(sc.mesh.points)
        r = np.hypot(ring[:, 0], ring[:, 1])
        assert r.min() > 0.5 and r.max() < 3.5                   # a ring about the screen's z axis
        assert sc._seam is not None and sc._seam[1].n_cells > 10
        sc.set_projection(ProjectionModel(n=5, axes=(3, 4, 2), angles=np.r_[np.zeros(9), 30.0]).view(),
                          render=False)
        assert not np.allclose(np.array(sc._seam[1].points), np.array(sc._seam[0].project(view.P)))
        sc.set_angle_look(circles=False, seam=False, render=False)
        sc.set_projection(view, render=False)
        assert sc._seam is None and np.ptp(np.array(sc.mesh.points)[:, 0]) <= TWO_PI + 1.0
    finally:
        pl.close()
