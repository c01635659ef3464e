"""Pure-numpy tests of the projection model (no Qt, no X needed)."""

import math

import numpy as np
import pytest

from gcmh_studio import projection as pj


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6, 10])
def test_planes_count(n):
    assert len(pj.planes(n)) == n * (n - 1) // 2
    assert all(i < j for i, j in pj.planes(n))


@pytest.mark.parametrize("n", [3, 4, 5, 7, 10])
def test_projection_rows_orthonormal_for_random_angles(n):
    rng = np.random.default_rng(n)
    for kind in pj.KINDS:
        m = pj.ProjectionModel(n=n, kind=kind, seed=3)
        m.set_vertices(rng.standard_normal((200, n)) * np.arange(1, n + 1))
        for _ in range(5):
            m.angles[:] = rng.uniform(-180, 180, len(m.angles))
            P = m.matrix()
            assert P.shape == (3, n)
            np.testing.assert_allclose(P @ P.T, np.eye(3), atol=1e-12)


def test_givens_is_a_plane_rotation():
    G = pj.givens(4, 1, 3, 0.3)
    np.testing.assert_allclose(G @ G.T, np.eye(4), atol=1e-15)
    assert math.isclose(np.linalg.det(G), 1.0)
    e1 = np.eye(4)[1]
    np.testing.assert_allclose(G @ e1, [0, math.cos(0.3), 0, math.sin(0.3)])
    # axes outside the plane stay put
    np.testing.assert_allclose(G @ np.eye(4)[0], np.eye(4)[0])
    np.testing.assert_allclose(G @ np.eye(4)[2], np.eye(4)[2])
    with pytest.raises(ValueError):
        pj.givens(3, 1, 1, 0.1)


def test_rotation_composes_givens_in_plane_order():
    n = 5
    rng = np.random.default_rng(1)
    thetas = rng.uniform(-3, 3, n * (n - 1) // 2)
    R = pj.rotation(n, thetas)
    expected = np.eye(n)
    for (i, j), t in zip(pj.planes(n), thetas):
        expected = expected @ pj.givens(n, i, j, t)
    np.testing.assert_allclose(R, expected, atol=1e-12)
    # dict form, missing planes are zero
    np.testing.assert_allclose(pj.rotation(n, {(1, 4): 0.7}), pj.givens(n, 1, 4, 0.7))
    np.testing.assert_allclose(pj.rotation(n, np.zeros(10)), np.eye(n))
    with pytest.raises(ValueError):
        pj.rotation(n, [0.1, 0.2])


def test_coordinate_choice_picks_columns():
    rng = np.random.default_rng(2)
    X = rng.standard_normal((50, 6))
    B = pj.coordinate_basis(6, (4, 0, 2))
    Y = pj.project(X, B)
    np.testing.assert_array_equal(Y, X[:, [4, 0, 2]])
    with pytest.raises(ValueError):
        pj.coordinate_basis(6, (1, 1, 2))
    with pytest.raises(ValueError):
        pj.coordinate_basis(3, (0, 1, 5))


def test_quarter_turn_swaps_coordinates_into_view():
    # rotating the plane (z, w) of R^4 by 90 degrees shows -w... and +w along screen Z
    m = pj.ProjectionModel(n=4, axes=(0, 1, 2))
    m.angles[m.planes.index((2, 3))] = 90.0
    P = m.matrix()
    np.testing.assert_allclose(np.abs(P[2]), [0, 0, 0, 1], atol=1e-12)
    assert m.labels(["x", "y", "z", "w"])[:2] == ["x", "y"]
    assert m.labels(["x", "y", "z", "w"])[2].lstrip("-") == "w"


def test_generic_is_seeded_and_principal_finds_the_spread():
    a = pj.generic_basis(7, seed=5)
    np.testing.assert_array_equal(a, pj.generic_basis(7, seed=5))
    assert not np.allclose(a, pj.generic_basis(7, seed=6))
    rng = np.random.default_rng(0)
    X = rng.standard_normal((2000, 5)) * np.array([0.01, 5.0, 0.02, 3.0, 1.0])
    B = pj.principal_basis(X)
    # largest spreads are axes 1, 3, 4 in that order
    assert [int(np.argmax(np.abs(r))) for r in B] == [1, 3, 4]
    np.testing.assert_allclose(B @ B.T, np.eye(3), atol=1e-12)


def test_small_n_pads_with_zero_rows():
    m = pj.ProjectionModel(n=2)
    P = m.matrix()
    assert P.shape == (3, 2)
    np.testing.assert_allclose(P[:2], np.eye(2))
    np.testing.assert_allclose(P[2], 0)


def test_projector_matches_plain_matmul_and_writes_in_place():
    rng = np.random.default_rng(3)
    X = rng.standard_normal((1000, 6)) + 5.0
    pr = pj.Projector(X)
    P = pj.ProjectionModel(n=6, kind="generic").matrix()
    out = pr.empty()
    r = pr.project(P, out=out)
    assert r is out
    expected = (X - pj.bbox_center(X)) @ P.T
    np.testing.assert_allclose(out, expected, rtol=1e-5, atol=1e-4)


def test_axis_label():
    names = ["x", "y", "z", "w"]
    assert pj.axis_label([0, 0, 1, 0], names) == "z"
    assert pj.axis_label([0, 0, -1, 0], names) == "-z"
    lab = pj.axis_label([0.6, 0, 0, 0.8], names)
    assert "w" in lab and "x" in lab


def test_model_dict_roundtrip():
    m = pj.ProjectionModel(n=5, kind="generic", seed=9)
    m.angles[3] = 42.0
    d = m.to_dict(["a", "b", "c", "d", "e"])
    m2 = pj.ProjectionModel.from_dict(5, d)
    np.testing.assert_allclose(m2.matrix(), m.matrix())


# --------------------------------------------------------------------------- nonlinear kinds
def test_perspective_maps_known_points():
    from gcmh_studio.projection import perspective

    d = 4.0
    # n = 4: one hidden axis; h = 2 is halfway to the eye -> factor d / (d - h) = 2
    Y = np.array([[1.0, 1.0, 1.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [2.0, 0.0, -4.0]])
    out = perspective(Y, d)
    assert np.allclose(out[:, 0], [2.0, 4.0, 0.0])
    assert np.allclose(out[:, 1], [1.0, 0.0, 3.0])       # h = 0: unchanged
    assert np.allclose(out[:, 2], [0.5, 0.0, 0.0])       # h = -4: factor 4 / 8
    # n = 5, recursively: first y4 = 2 -> factor 2 (y3 becomes 2), then y3 = 2 -> factor 2: total 4
    Y5 = np.array([[1.0], [0.0], [0.0], [1.0], [2.0]])
    assert np.allclose(perspective(Y5, d)[:, 0], [4.0, 0.0, 0.0])
    # no hidden axis (n = 3): the identity
    assert np.allclose(perspective(Y[:3], d), Y[:3])


def test_stereographic_maps_known_points():
    from gcmh_studio.projection import stereographic

    r = 2.0
    Y = np.array([[2.0, 0.0, 0.0, 0.0],      # on the equator: fixed
                  [0.0, 0.0, 0.0, -2.0]])    # the south pole: the origin
    Y = np.concatenate([Y, [[np.sqrt(2.0), 0.0, 0.0, np.sqrt(2.0)]]]).T
    out = stereographic(Y, r)
    assert np.allclose(out[:, 0], [2, 0, 0])
    assert np.allclose(out[:, 1], [0, 0, 0])
    # 45 degrees above the equator: r * x / (r - h) = 2 * 1.414 / (2 - 1.414) = 2 (1 + sqrt 2)
    assert np.allclose(out[:, 2], [2 * (1 + np.sqrt(2)), 0, 0])
    # circles on the sphere go to circles: the Clifford torus' circle x1^2 + x2^2 = 1/2 at fixed x3, x4
    t = np.linspace(0, 2 * np.pi, 9)
    a = np.sqrt(0.5)
    C = np.stack([a * np.cos(t), a * np.sin(t), 0 * t + a * np.cos(1.0), 0 * t + a * np.sin(1.0)])
    img = stereographic(C, 1.0)
    rad = np.hypot(img[0], img[1])
    assert np.allclose(rad, rad[0]) and np.allclose(img[2], img[2][0])
    with pytest.raises(ValueError, match="n >= 4"):
        stereographic(Y[:3], r)


def test_view_frame_and_projector_kinds():
    from gcmh_studio.projection import ProjectionModel, Projector

    m = ProjectionModel(n=4)
    F = m.frame()
    assert np.allclose(F @ F.T, np.eye(4)) and np.allclose(F[:3], m.matrix())
    assert np.allclose(F[3], [0, 0, 0, 1])
    X = np.array([[1.0, 0.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, -1.0],
                  [0.5, 0.0, 0.0, 0.5]])
    pr = Projector(X, center=np.zeros(4), dtype=np.float64)
    assert pr.radii() == (1.0, 1.0)
    lin = pr.project_view(m.view())
    assert np.allclose(lin, X[:, :3])
    m.mapping = "stereographic"
    st = pr.project_view(m.view())
    assert np.allclose(st[0], [1, 0, 0]) and np.allclose(st[4], [1.0, 0, 0])   # 0.5 / (1 - 0.5)
    m.mapping = "perspective"
    m.distance = 2.0
    pe = pr.project_view(m.view())
    assert np.allclose(pe[4], [0.5 * 2 / 1.5, 0, 0])
    # the rotation is kept when switching kinds, and the angle turns the hidden axis into view
    m.angles[m.planes.index((0, 3))] = 90.0
    m.mapping = "orthographic"
    assert np.allclose(np.abs(pr.project_view(m.view())[2]), [1, 0, 0], atol=1e-12)
    # the state round-trips
    m2 = ProjectionModel.from_dict(4, m.to_dict())
    assert m2.mapping == "orthographic" and m2.distance == 2.0 and np.allclose(m2.angles, m.angles)
    with pytest.raises(ValueError, match="mapping"):
        ProjectionModel(n=4, mapping="fisheye")


def test_colour_range_is_symmetric_when_nearly_so():
    from gcmh_studio.scene import colour_range

    assert colour_range(np.array([-1.5701, 0.2, 1.5698])) == [-1.5701, 1.5701]
    assert colour_range(np.array([-1.0, 1.1])) == [-1.0, 1.1]  # 5% off: left as it is
    assert colour_range(np.array([0.0, 2.0])) == [0.0, 2.0]
    assert colour_range(np.array([3.0, 3.0])) == [3.0, 4.0]
