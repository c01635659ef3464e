"""gcmh_core.analysis: orientation of surfaces, the topology report, refinement onto M."""

from collections import Counter

import numpy as np
import pytest

from gcmh_core import CellComplex, InputError, extract
from gcmh_core.analysis import (
    Orientation,
    boundary_components,
    graph_components,
    orient_2cells,
    refine_vertices,
    topology_report,
)
from gcmh_core.examples import load_example
from gcmh_core.formula import parse_system


def _example(name):
    ex = load_example(name)
    cx = extract(ex.formulas, ex.bounds, ex.div, variables=ex.variables)
    return cx, parse_system(ex.formulas, ex.variables)


def _complex_from_polygons(n_vertices, polygons, n=3):
    """A 2-complex in R^n from vertex loops (edges shared by vertex pair)."""
    edge_id, edges, faces, offsets = {}, [], [], [0]
    for loop in polygons:
        for a, b in zip(loop, loop[1:] + loop[:1]):
            key = (min(a, b), max(a, b))
            if key not in edge_id:
                edge_id[key] = len(edges)
                edges.append(key)
            faces.append(edge_id[key])
        offsets.append(len(faces))
    rng = np.random.default_rng(0)
    return CellComplex(n, n - 2, rng.normal(size=(n_vertices, n)), edges, {2: (offsets, faces)})


def _directed_steps_balanced(cx, loops):
    """Slow check: for every vertex pair whose edges all have exactly two polygons,
    the oriented loops run it as often u -> v as v -> u."""
    cof = cx.facet_cofaces()
    pair_edges = {}
    for e, (u, v) in enumerate(cx.edges.tolist()):
        pair_edges.setdefault((min(u, v), max(u, v)), []).append(e)
    steps = Counter()
    for loop in loops:
        loop = loop.tolist()
        for a, b in zip(loop, loop[1:] + loop[:1]):
            steps[(a, b)] += 1
    checked = 0
    for (u, v), es in pair_edges.items():
        if all(cof[e] == 2 for e in es):
            checked += 1
            if steps[(u, v)] != steps[(v, u)]:
                return False, checked
    return True, checked


# --------------------------------------------------------------------- orientation

@pytest.mark.parametrize("name", ["sphere", "torus", "clifford-torus", "complex-cosine", "klein-bottle"])
def test_level_sets_orient_consistently(name):
    cx, _ = _example(name)
    o = orient_2cells(cx)
    assert isinstance(o, Orientation)
    assert o.consistent
    assert o.conflict_edges.size == 0 and o.nonmanifold_edges.size == 0
    assert o.n_components == 1 and o.component_consistent.tolist() == [True]
    ok, checked = _directed_steps_balanced(cx, o.loops())
    assert ok and checked > 100
    # the loops as cx.polygons() gives them are not coherent: the search did the work
    off, ids = cx.polygons()
    raw_ok, _ = _directed_steps_balanced(cx, np.split(np.asarray(ids), np.asarray(off)[1:-1]))
    assert not raw_ok and o.n_flipped > 0


def test_flip_mask_says_which_loops_were_reversed():
    cx, _ = _example("complex-cosine")
    o = orient_2cells(cx)
    off, ids = cx.polygons()
    raw = np.split(np.asarray(ids), np.asarray(off)[1:-1])
    mask = o.flip_mask()
    assert mask.shape == (cx.count(2),) and mask.dtype == bool and mask.sum() == o.n_flipped
    assert np.array_equal(o.offsets, off)
    for loop, new, flipped in zip(raw, o.loops(), mask):
        assert np.array_equal(new, loop[::-1] if flipped else loop)
    mask[:] = False  # a copy: the orientation itself is unchanged
    assert o.flip_mask().sum() == o.n_flipped


def test_orientation_does_not_depend_on_the_face_order():
    cx, _ = _example("sphere")
    off, fac = cx.cells[2]
    rng = np.random.default_rng(1)
    shuffled = np.concatenate([rng.permutation(fac[off[i]:off[i + 1]]) for i in range(cx.count(2))])
    cy = CellComplex(cx.n, cx.k, cx.vertices, cx.edges[:, ::-1], {2: (off, shuffled)})
    o = orient_2cells(cy)
    assert o.consistent
    assert _directed_steps_balanced(cy, o.loops())[0]


def _moebius(segments=6):
    # top row 0..s-1, bottom row s..2s-1; the last quad glues the ends with a half twist
    s = segments
    quads = [[i, i + 1, s + i + 1, s + i] for i in range(s - 1)]
    quads.append([s - 1, s, 0, 2 * s - 1])
    return _complex_from_polygons(2 * s, quads)


def test_moebius_strip_is_not_orientable():
    cx = _moebius()
    assert cx.euler_characteristic() == 0 and boundary_components(cx) == 1
    o = orient_2cells(cx)
    assert not o.consistent
    assert o.conflict_edges.size >= 1 and o.component_consistent.tolist() == [False]
    assert not _directed_steps_balanced(cx, o.loops())[0]


def test_cylinder_is_orientable_whatever_the_input_windings():
    s = 6
    quads = [[i, (i + 1) % s, s + (i + 1) % s, s + i] for i in range(s)]
    quads = [q[::-1] if i % 2 else q for i, q in enumerate(quads)]  # alternate windings
    cx = _complex_from_polygons(2 * s, quads)
    o = orient_2cells(cx)
    assert o.consistent and _directed_steps_balanced(cx, o.loops()) == (True, s)
    assert boundary_components(cx) == 2


def test_projective_plane_is_not_orientable():
    # the 6-vertex triangulation of RP^2 (half an icosahedron)
    tris = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5], [0, 5, 1],
            [1, 2, 4], [2, 3, 5], [3, 4, 1], [4, 5, 2], [5, 1, 3]]
    cx = _complex_from_polygons(6, tris, n=4)
    assert cx.euler_characteristic() == 1 and cx.boundary_facets().size == 0
    o = orient_2cells(cx)
    assert not o.consistent and o.n_components == 1


def test_two_components_are_oriented_separately():
    s = 5
    moebius = [[i, i + 1, s + i + 1, s + i] for i in range(s - 1)] + [[s - 1, s, 0, 2 * s - 1]]
    tet = [[10, 11, 12], [10, 13, 11], [11, 13, 12], [12, 13, 10]]
    cx = _complex_from_polygons(14, moebius + tet)
    o = orient_2cells(cx)
    assert not o.consistent and o.n_components == 2
    assert o.component_consistent.tolist() == [False, True]
    assert np.array_equal(o.component, [0] * s + [1] * 4)


def test_orient_rejects_other_dimensions():
    with pytest.raises(InputError, match="dimension 1"):
        orient_2cells(extract("x^2 + y^2 - 1", bounds=(-2, 2), div=8, variables="x, y"))
    with pytest.raises(InputError, match="dimension 3"):
        orient_2cells(extract("x^2 + y^2 + z^2 + w^2 - 1", bounds=(-2, 2), div=6, variables="x, y, z, w"))
    with pytest.raises(InputError, match="CellComplex"):
        orient_2cells("sphere")


def test_empty_surface():
    cx = CellComplex(3, 1, np.zeros((0, 3)), np.zeros((0, 2), dtype=np.int64))
    o = orient_2cells(cx)
    assert o.consistent and o.n_flipped == 0 and o.offsets.tolist() == [0]


def test_graph_components():
    labels, n = graph_components(7, [0, 2, 3, 6], [1, 3, 4, 5])
    assert n == 3 and labels.tolist() == [0, 0, 1, 1, 1, 2, 2]
    # a long path needs many hooking rounds
    m = 1000
    labels, n = graph_components(m, np.arange(m - 1)[::-1], np.arange(1, m)[::-1])
    assert n == 1 and not labels.any()
    with pytest.raises(InputError):
        graph_components(3, [0], [3])


# ----------------------------------------------------------------------- report

def test_report_klein_bottle_sheet():
    cx, system = _example("klein-bottle")
    rep = topology_report(cx, system)
    assert rep["euler_characteristic"] == 1
    assert (rep["n"], rep["k"], rep["dim"]) == (5, 3, 2)
    assert rep["counts"] == cx.counts()
    assert rep["connected_components"] == 1
    assert rep["boundary_components"] == 1 and not rep["closed"]
    assert rep["orientation"]["consistent"] and rep["orientation"]["orientable_components"] == 1
    assert 0 < rep["max_abs_F"] < 0.5
    assert set(rep["timings"]) >= {"kernel", "assemble"}
    assert rep["timings"] == {k: float(v) for k, v in cx.meta["timings"].items()}
    assert rep["seconds"] == cx.meta["seconds"]  # the run's own record, copied


def test_report_sphere_closed():
    cx, system = _example("sphere")
    rep = topology_report(cx)
    assert rep["euler_characteristic"] == 2
    assert rep["boundary_facets"] == 0 and rep["boundary_components"] == 0 and rep["closed"]
    assert rep["max_abs_F"] is None
    assert topology_report(cx, system)["max_abs_F"] < 0.01


def test_report_complex_cosine_has_a_boundary():
    cx, _ = _example("complex-cosine")
    rep = topology_report(cx)
    assert rep["boundary_facets"] > 0 and rep["boundary_components"] > 0
    assert rep["boundary_components"] == 1  # the boundary circle of a disc


def test_report_other_dimensions():
    circle_pair = extract("((x - 1)^2 + y^2 - 0.25) * ((x + 1)^2 + y^2 - 0.25)", bounds=(-2, 2),
                          div=16, variables="x, y")
    rep = topology_report(circle_pair)
    assert rep["connected_components"] == 2 and rep["orientation"] is None and rep["closed"]
    arc = extract("x^2 + y^2 - 1", bounds=[(-1.5, 1.5), (0.2, 1.5)], div=12, variables="x, y")
    assert topology_report(arc)["boundary_components"] == 2  # two end points
    # a 3-ball's boundary is one 2-sphere: x^2 + y^2 + z^2 + w^2 = 1 cut by w >= 0.3
    cap = extract("x^2 + y^2 + z^2 + w^2 - 1", bounds=[(-1.2, 1.2)] * 3 + [(0.3, 1.2)], div=8,
                  variables="x, y, z, w")
    assert topology_report(cap)["boundary_components"] == 1
    two = extract("x^2 + y^2 + z^2 + w^2 - 1", bounds=[(-1.2, 1.2)] * 3 + [(-0.3, 0.3)], div=8,
                  variables="x, y, z, w")
    assert topology_report(two)["boundary_components"] == 2


def test_report_validates():
    cx, _ = _example("sphere")
    with pytest.raises(InputError, match="R\\^4"):
        topology_report(cx, parse_system(["x^2 + y^2 + z^2 + w^2 - 1"], "x, y, z, w"))
    with pytest.raises(InputError, match="CellComplex"):
        topology_report(None)


# ----------------------------------------------------------------------- refinement

@pytest.mark.parametrize("name", ["sphere", "complex-cosine", "klein-bottle"])
def test_refine_drops_residual_by_orders_of_magnitude(name):
    cx, system = _example(name)
    refined, before, after = refine_vertices(cx, system, steps=3)
    assert before > 1e-4
    assert after < before * 1e-6
    assert after == pytest.approx(np.abs(system.evaluate_points(refined.vertices)).max())
    assert refined.counts() == cx.counts()
    assert np.array_equal(refined.edges, cx.edges)
    assert all(np.array_equal(refined.cells[r][1], cx.cells[r][1]) for r in range(2, cx.dim + 1))
    # vertices move by much less than a grid cube
    step = min((hi - lo) / d for (lo, hi), d in zip(cx.meta["bounds"], cx.meta["div"]))
    assert np.abs(refined.vertices - cx.vertices).max() < step
    assert refined.meta["refined_steps"] == 3 and refined.meta["max_abs_F"] == after
    assert "refined_steps" not in cx.meta


def test_refine_sphere_lands_on_the_unit_sphere():
    cx, system = _example("sphere")
    refined, _, _ = refine_vertices(cx, system, steps=4)
    assert np.allclose(np.linalg.norm(refined.vertices, axis=1), 1.0, atol=1e-12)


def test_refine_zero_steps_and_singular_points():
    cx, system = _example("sphere")
    same, before, after = refine_vertices(cx, system, steps=0)
    assert before == after and np.array_equal(same.vertices, cx.vertices)
    # Whitney umbrella: J vanishes on the z-axis; no vertex may get worse or go non-finite
    f = ["x^2 - y^2*z"]
    um = extract(f, bounds=(-1, 1), div=12, variables="x, y, z")
    s = parse_system(f, "x, y, z")
    refined, before, after = refine_vertices(um, s, steps=3)
    assert np.isfinite(refined.vertices).all() and after <= before
    per_vertex_before = np.abs(s.evaluate_points(um.vertices))[:, 0]
    per_vertex_after = np.abs(s.evaluate_points(refined.vertices))[:, 0]
    assert np.all(per_vertex_after <= per_vertex_before)


def test_refine_validates():
    cx, system = _example("sphere")
    with pytest.raises(InputError, match="steps"):
        refine_vertices(cx, system, steps=-1)
    with pytest.raises(InputError, match="steps"):
        refine_vertices(cx, system, steps=1.5)
    with pytest.raises(InputError, match="system"):
        refine_vertices(cx, None)
    with pytest.raises(InputError, match="R\\^2"):
        refine_vertices(cx, parse_system(["x^2 + y^2 - 1"], "x, y"))
