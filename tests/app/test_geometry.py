"""Drawing arrays of a complex (pure numpy, no Qt or X): polygons, orientation, normals."""

import numpy as np
import pytest

from gcmh_studio.geometry import Geometry, cross_table, polygon_faces, vertex_bivectors
from gcmh_studio.projection import ProjectionModel, generic_basis


def _edges_directed(offsets, vids):
    out = []
    for f in range(len(offsets) - 1):
        loop = vids[offsets[f]:offsets[f + 1]]
        out += [(int(loop[i]), int(loop[(i + 1) % len(loop)])) for i in range(len(loop))]
    return out


def test_polygon_faces_layout():
    off = np.array([0, 3, 7])
    vids = np.array([0, 1, 2, 2, 3, 4, 5])
    np.testing.assert_array_equal(polygon_faces(off, vids), [3, 0, 1, 2, 4, 2, 3, 4, 5])


def test_sphere_polygons_are_coherently_oriented():
    from gcmh_core import extract
    from gcmh_core.analysis import orient_2cells

    cx = extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 8, variables="x,y,z")
    o = orient_2cells(cx)
    off, oriented = o.offsets, o.vertices
    directed = _edges_directed(off, oriented)
    # a closed oriented surface: every edge is run once in each direction
    assert len(set(directed)) == len(directed)
    assert all((b, a) in set(directed) for a, b in directed)
    # and the vertex normals then point the same way as the position (outward) or all inward
    B = vertex_bivectors(cx.vertices, off, oriented)
    N = B @ cross_table(np.eye(3))
    s = np.sign(np.einsum("ij,ij->i", N, cx.vertices))
    assert abs(s.sum()) == len(s)


@pytest.mark.parametrize("n", [4, 6, 10])
def test_normal_field_matches_the_projected_mesh(n):
    from app_helpers import torus_complex

    cx = torus_complex(30, n)
    geo = Geometry.build(cx)
    assert geo.kind == "polygons" and geo.normals is not None
    P = generic_basis(n, seed=n)
    pts = geo.projector.project(P).astype(np.float64)
    out = np.zeros((len(pts), 3), np.float32)
    geo.normals.write(P, out)
    # reference: area-weighted normals of the projected quads (their two triangles), summed per vertex
    cells = geo.cells.reshape(-1, 5)[:, 1:]
    ref = np.zeros_like(pts)
    for a, b, c in ((0, 1, 2), (0, 2, 3)):
        fn = 0.5 * np.cross(pts[cells[:, b]] - pts[cells[:, a]], pts[cells[:, c]] - pts[cells[:, a]])
        for k in range(4):
            np.add.at(ref, cells[:, k], fn * (k in (a, b, c)))
    norm = np.linalg.norm(ref, axis=1)
    cos = np.einsum("ij,ij->i", ref, out) / norm / np.linalg.norm(out, axis=1)
    seen = norm > 0.05 * np.median(norm)   # where the projected surface is not edge-on
    assert seen.mean() > 0.9
    assert np.all(np.abs(cos[seen]) > 0.99)


def test_cross_table_is_the_bilinear_form():
    rng = np.random.default_rng(0)
    n = 5
    P = ProjectionModel(n=n, kind="generic").matrix()
    a, b = rng.standard_normal(n), rng.standard_normal(n)
    from gcmh_studio.geometry import _wedge
    from gcmh_studio.projection import planes

    w = _wedge(a[None], b[None], planes(n))[0]
    np.testing.assert_allclose(w @ cross_table(P), np.cross(P @ a, P @ b), atol=1e-12)


def test_curves_are_lines():
    from gcmh_core import extract

    cx = extract("x^2 + y^2 - 1", (-1.5, 1.5), 10, variables="x,y")
    geo = Geometry.build(cx)
    assert geo.kind == "lines" and geo.normals is None
    assert len(geo.cells) == 3 * cx.count(1)


def test_mesh_normals_agree_with_bivector_normals_under_a_linear_view():
    """Normals from projected points (nonlinear views) match the exact bivector normals when the view is linear."""
    from gcmh_studio.geometry import Geometry
    from gcmh_studio.projection import ProjectionModel

    from app_helpers import torus_complex

    for n in (4, 5):
        cx = torus_complex(40, n)
        geo = Geometry.build(cx)
        m = ProjectionModel(n=n, kind="generic", seed=2)
        m.angles[:] = 17.0
        P = m.matrix()
        pts = geo.projector.project(P)
        exact = np.zeros_like(pts)
        geo.normals.write(P, exact)
        mine = np.zeros_like(pts)
        geo.mesh_normals().write(pts, mine)
        big = np.linalg.norm(exact, axis=1) > 1e-3 * np.linalg.norm(exact, axis=1).max()
        cos = np.einsum("ij,ij->i", exact, mine)[big] / (
            np.linalg.norm(exact, axis=1)[big] * np.linalg.norm(mine, axis=1)[big])
        assert np.median(cos) > 0.999 and cos.min() > 0.9


def test_mesh_normals_of_a_stereographic_sphere_point_outward():
    """A unit 2-sphere in R^4 (x4 = 0) seen stereographically is the same sphere: normals radial."""
    import gcmh_core
    from gcmh_studio.geometry import Geometry
    from gcmh_studio.projection import ProjectionModel

    cx = gcmh_core.extract(["x1^2 + x2^2 + x3^2 + x4^2 - 1", "x4 - 0.01"], bounds=[(-1.2, 1.2)] * 4, div=10,
                           variables=["x1", "x2", "x3", "x4"])
    geo = Geometry.build(cx)
    view = ProjectionModel(n=4, mapping="stereographic").view()
    pts = geo.projector.project_view(view)
    N = np.zeros_like(pts)
    geo.mesh_normals().write(pts, N)
    c = pts - pts.mean(0)
    cos = np.einsum("ij,ij->i", c, N) / (np.linalg.norm(c, axis=1) * np.linalg.norm(N, axis=1))
    assert np.all(np.abs(cos) > 0.9)
    assert abs(np.mean(np.sign(cos))) == 1.0      # one side everywhere: oriented loops


def test_klein_seam_swaps_the_sides():
    """Oriented loops (gcmh_core.analysis.orient_2cells when present) of the Klein sheet: where its s = 0 and
    s = 2 pi edges meet in (x, y, z), the faces on the two sides have opposite normals -- the swap of colours
    that two-sided colouring shows."""
    from gcmh_core.examples import load_example
    from gcmh_studio.geometry import Geometry
    from gcmh_studio.jobs import Job, run_job

    ex = load_example("klein-bottle")
    cx = run_job(Job(formulas=list(ex.formulas), variables=list(ex.variables),
                     bounds=[tuple(b) for b in ex.bounds], div=[16, 16, 8, 20, 20]))
    geo = Geometry.build(cx)
    X = cx.vertices
    off, vids = geo.offsets, geo.vids
    cent = np.add.reduceat(X[vids], off[:-1], axis=0) / np.diff(off)[:, None]
    # Newell normals of the loops in (x, y, z)
    P = X[:, :3]
    nxt = np.arange(1, len(vids) + 1)
    nxt[off[1:] - 1] = off[:-1]
    N = np.add.reduceat(np.cross(P[vids], P[vids[nxt]]), off[:-1], axis=0)
    N /= np.linalg.norm(N, axis=1)[:, None]
    two_pi = 2 * np.pi
    lo = np.flatnonzero(cent[:, 3] < 0.25)
    hi = np.flatnonzero(cent[:, 3] > two_pi - 0.25)
    assert len(lo) > 10 and len(hi) > 10
    d = np.linalg.norm(cent[lo, None, :3] - cent[None, hi, :3], axis=2)
    match = hi[np.argmin(d, axis=1)]
    close = d.min(axis=1) < 0.6
    dots = np.einsum("ij,ij->i", N[lo[close]], N[match[close]])
    assert close.sum() > 10
    assert np.mean(dots < 0) > 0.9, dots
    # away from the seam, neighbours agree (the loops are coherently oriented)
    mid = np.flatnonzero(np.abs(cent[:, 3] - np.pi) < 0.3)
    dm = np.linalg.norm(cent[mid, None, :3] - cent[None, mid, :3], axis=2) + np.eye(len(mid)) * 9
    nb = np.argmin(dm, axis=1)
    assert np.mean(np.einsum("ij,ij->i", N[mid], N[mid[nb]]) > 0) > 0.9


@pytest.mark.parametrize("shape,spread", [((1000, 3), 5), ((5000, 10), 3000), ((300, 1), 7), ((1, 6), 4),
                                          ((2000, 5), 2**40)])
def test_row_ids_number_rows_as_numpy_unique_does(shape, spread):
    """The coarse copy's clusters: the same ids as np.unique over rows (which held the GIL), negative keys,
    ten columns and keys too wide to combine in one int64 included."""
    from gcmh_studio.geometry import row_ids

    key = np.random.default_rng(shape[0]).integers(-spread, spread, size=shape)
    key[::7] = key[0]                                 # repeated rows
    expected = np.unique(key, axis=0, return_inverse=True)[1].ravel()
    assert np.array_equal(row_ids(key), expected)
