"""Slicing by a window of a linear functional (app/slicing.py, pure numpy)."""

import numpy as np
import pytest

from gcmh_studio.slicing import clip_polygons, clip_segments, hidden_directions, window_range


@pytest.fixture(scope="module")
def sphere():
    import gcmh_core

    cx = gcmh_core.extract(["x^2 + y^2 + z^2 - 1"], bounds=[(-1.3, 1.3)] * 3, div=14, variables=["x", "y", "z"])
    off, vids = cx.polygons()
    return cx, np.asarray(off), np.asarray(vids)


def test_sphere_equator_gives_a_ring_inside_the_window(sphere):
    cx, off, vids = sphere
    s = clip_polygons(cx.vertices, off, vids, [0, 0, 1], 0.0, 0.1)
    assert not s.empty
    z = s.vertices[:, 2]
    assert np.all(z >= -0.1 - 1e-12) and np.all(z <= 0.1 + 1e-12)
    # a ring: every angle around the z axis is covered, and the band is near the unit circle
    ang = np.arctan2(s.vertices[:, 1], s.vertices[:, 0])
    hist, _ = np.histogram(ang, bins=24, range=(-np.pi, np.pi))
    assert np.all(hist > 0)
    r = np.linalg.norm(s.vertices, axis=1)
    assert np.all(np.abs(r - 1) < 0.1)
    # one connected band: new vertices are shared between neighbouring polygons
    edges = set()
    for f in range(s.n_cells):
        loop = s.vids[s.offsets[f]:s.offsets[f + 1]]
        for a, b in zip(loop, np.roll(loop, -1)):
            edges.add((min(a, b), max(a, b)))
    parent = list(range(len(s.vertices)))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in edges:
        parent[find(a)] = find(b)
    assert len({find(v) for v in np.unique(s.vids)}) == 1


def test_clipped_vertices_lie_on_the_window_planes(sphere):
    cx, off, vids = sphere
    c, w = 0.23, 0.07
    s = clip_polygons(cx.vertices, off, vids, [0, 0, 1], c, w)
    new = s.source < 0
    assert new.sum() > 10
    z = s.vertices[new, 2]
    on = np.isclose(z, c - w, atol=1e-12) | np.isclose(z, c + w, atol=1e-12)
    assert np.all(on)
    # old ones are the original vertices, unchanged
    old = ~new
    assert np.array_equal(s.vertices[old], cx.vertices[s.source[old]])
    # every clipped cell is a proper polygon
    assert np.all(np.diff(s.offsets) >= 3)


def test_outside_the_sphere_is_empty(sphere):
    cx, off, vids = sphere
    assert clip_polygons(cx.vertices, off, vids, [0, 0, 1], 1.5, 0.1).empty
    assert clip_polygons(cx.vertices, off, vids, [1, 0, 0], -2.0, 0.3).empty


def test_counts_follow_the_window(sphere):
    cx, off, vids = sphere
    n_eq = clip_polygons(cx.vertices, off, vids, [0, 0, 1], 0.0, 0.05).n_cells
    n_cap = clip_polygons(cx.vertices, off, vids, [0, 0, 1], 0.97, 0.05).n_cells
    n_wide = clip_polygons(cx.vertices, off, vids, [0, 0, 1], 0.0, 0.3).n_cells
    assert 0 < n_cap < n_eq < n_wide
    full = clip_polygons(cx.vertices, off, vids, [0, 0, 1], 0.0, 2.0)
    assert full.n_cells == len(off) - 1 and np.all(full.source >= 0)


def test_winding_is_kept():
    # a square in the plane, counter-clockwise; the clipped piece must stay counter-clockwise
    X = np.array([[0., 0.], [2., 0.], [2., 2.], [0., 2.]])
    s = clip_polygons(X, np.array([0, 4]), np.arange(4), np.array([1., 1.]), 2.0, 0.5)
    P = s.vertices[s.vids]
    area = 0.5 * np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1])
    assert area > 0
    assert len(s.vids) == 6  # a hexagon: the square cut by two diagonal lines


def test_segments_are_clipped_too():
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    X = np.stack([np.cos(t), np.sin(t), 0 * t, t / 10], 1)      # a circle, any n works (n = 4 here)
    E = np.stack([np.arange(40), (np.arange(40) + 1) % 40], 1)
    s = clip_segments(X, E, [1, 0, 0, 0], 0.0, 0.2)
    assert s.edges.shape[1] == 2 and len(s.edges) > 0
    assert np.all(np.abs(s.vertices[:, 0]) <= 0.2 + 1e-12)
    assert np.sum(np.isclose(np.abs(s.vertices[s.source < 0, 0]), 0.2)) == 4  # two arcs, four cut ends
    assert clip_segments(X, E, [1, 0, 0, 0], 3.0, 0.2).empty


def test_hidden_directions_complete_the_projection():
    P = np.eye(5)[[0, 1, 2]]
    H = hidden_directions(P)
    assert np.allclose(H, np.eye(5)[[3, 4]])
    rng = np.random.default_rng(1)
    Q, _ = np.linalg.qr(rng.standard_normal((6, 6)))
    H = hidden_directions(Q[:3])
    assert H.shape == (3, 6)
    assert np.allclose(H @ Q[:3].T, 0, atol=1e-12) and np.allclose(H @ H.T, np.eye(3), atol=1e-12)


def test_window_range_and_bad_input():
    X = np.array([[0., 1.], [2., -1.]])
    assert window_range(X, [1, 0]) == (0.0, 2.0)
    with pytest.raises(ValueError, match="components"):
        clip_polygons(X, np.array([0]), np.array([], int), [1, 0, 0], 0, 1)
    with pytest.raises(ValueError, match="half-width"):
        clip_polygons(X, np.array([0]), np.array([], int), [1, 0], 0, -1)


def test_any_n_along_a_hidden_direction():
    """A flat torus in R^10, sliced along a direction a generic view hides."""
    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.slicing import SliceWindow

    from app_helpers import torus_complex

    cx = torus_complex(30, 10)
    off, vids = cx.polygons()
    m = ProjectionModel(n=10, kind="generic", seed=5)
    m.angles[:] = 11.0
    sw = SliceWindow(6, hidden=True)
    u = sw.direction(m.frame())
    assert np.isclose(np.linalg.norm(u), 1) and np.allclose(m.matrix() @ u, 0, atol=1e-12)
    lo, hi = window_range(cx.vertices, u)
    c, w = 0.5 * (lo + hi), 0.05 * (hi - lo)
    s = clip_polygons(cx.vertices, off, vids, u, c, w)
    h = s.vertices @ u
    assert s.n_cells > 0 and np.all(h >= c - w - 1e-9) and np.all(h <= c + w + 1e-9)
    assert np.all(np.isclose(h[s.source < 0], c - w) | np.isclose(h[s.source < 0], c + w))
    with pytest.raises(ValueError, match="hidden direction 8"):
        SliceWindow(7, hidden=True).direction(m.frame())


def test_bands_round_several_levels_are_one_slice():
    """clip_polygons_at: the bands round each level in one Slice, each band as clip_polygons makes it."""
    from gcmh_studio.slicing import clip_polygons, clip_polygons_at

    g = np.linspace(0.0, 4.0, 9)
    X = np.array([[x, y] for y in g for x in g])
    quads = [[j * 9 + i, j * 9 + i + 1, (j + 1) * 9 + i + 1, (j + 1) * 9 + i] for j in range(8) for i in range(8)]
    offsets = np.arange(0, 4 * len(quads) + 1, 4)
    vids = np.asarray(quads).ravel()
    u = np.array([1.0, 0.0])
    one, two = (clip_polygons(X, offsets, vids, u, c, 0.2) for c in (1.1, 3.1))
    both = clip_polygons_at(X, offsets, vids, u, [1.1, 3.1], 0.2)
    assert both.n_cells == one.n_cells + two.n_cells > 0
    assert len(both.vertices) == len(one.vertices) + len(two.vertices)
    loops = [both.vertices[both.vids[both.offsets[i]:both.offsets[i + 1]], 0] for i in range(both.n_cells)]
    assert sum(np.all(np.abs(x - 1.1) <= 0.2 + 1e-12) for x in loops) == one.n_cells
    assert sum(np.all(np.abs(x - 3.1) <= 0.2 + 1e-12) for x in loops) == two.n_cells
    assert clip_polygons_at(X, offsets, vids, u, [1.1], 0.2).n_cells == one.n_cells
