"""Tests of gcmh_core.complex.CellComplex on hand-built complexes (no Qt)."""

import itertools
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gcmh_core.complex import FORMAT, CellComplex

REPO = Path(__file__).resolve().parents[2]


# ---------------------------------------------------------------------------
# builders
# ---------------------------------------------------------------------------

def from_polygons(n, k, vertices, loops, meta=None):
    """A 2-complex whose 2-cells are the given vertex loops (edges found from them)."""
    edge_id = {}
    edges = []
    offsets = [0]
    faces = []
    for loop in loops:
        for a, b in zip(loop, loop[1:] + loop[:1]):
            key = (min(a, b), max(a, b))
            if key not in edge_id:
                edge_id[key] = len(edges)
                edges.append([a, b])
            faces.append(edge_id[key])
        offsets.append(len(faces))
    return CellComplex(n, k, vertices, np.array(edges, dtype=np.int64).reshape(-1, 2),
                       {2: (np.array(offsets), np.array(faces))}, meta)


def simplex_boundary(n_vertices, coords):
    """The boundary of the (n_vertices-1)-simplex as a CSR complex of dim n_vertices-2.

    r-cells are the (r+1)-subsets of the vertices (r <= n_vertices - 2)."""
    top = n_vertices - 2
    subsets = {r: list(itertools.combinations(range(n_vertices), r + 1)) for r in range(top + 1)}
    index = {r: {s: i for i, s in enumerate(subsets[r])} for r in subsets}
    edges = np.array(subsets[1], dtype=np.int64)
    cells = {}
    for r in range(2, top + 1):
        offsets, faces = [0], []
        for s in subsets[r]:
            for drop in range(len(s)):
                faces.append(index[r - 1][s[:drop] + s[drop + 1:]])
            offsets.append(len(faces))
        cells[r] = (np.array(offsets), np.array(faces))
    n = coords.shape[1]
    return CellComplex(n, n - top, coords, edges, cells)


CUBE_V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
# vertex id = 4x + 2y + z; the six square faces as loops
CUBE_LOOPS = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]


def cube_boundary(meta=None):
    return from_polygons(3, 1, CUBE_V, CUBE_LOOPS, meta)


def solid_cube():
    b = cube_boundary()
    off, fac = b.cells[2]
    return CellComplex(3, 0, b.vertices, b.edges,
                       {2: (off, fac), 3: (np.array([0, 6]), np.arange(6))})


def circle():
    """Boundary of a triangle in R^2."""
    v = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    return CellComplex(2, 1, v, [[0, 1], [1, 2], [2, 0]])


def tetrahedron_boundary():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    return from_polygons(3, 1, v, [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])


def square():
    v = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    return from_polygons(2, 0, v, [[0, 1, 2, 3]])


def quad_torus(a, b):
    """An a x b periodic grid of quads (a torus) in R^3, built with numpy."""
    i, j = np.meshgrid(np.arange(a), np.arange(b), indexing="ij")
    vid = (i * b + j).ravel()
    right = (((i + 1) % a) * b + j).ravel()
    up = (i * b + (j + 1) % b).ravel()
    edges = np.concatenate([np.column_stack([vid, right]), np.column_stack([vid, up])])
    # edge ids: horizontal edge of vertex v is v, vertical is V + v
    V = a * b
    faces = np.column_stack([vid, V + right, up, V + vid]).ravel()
    offsets = np.arange(0, 4 * V + 1, 4)
    t, p = 2 * np.pi * i.ravel() / a, 2 * np.pi * j.ravel() / b
    verts = np.column_stack([(2 + np.cos(p)) * np.cos(t), (2 + np.cos(p)) * np.sin(t), np.sin(p)])
    return CellComplex(3, 1, verts, edges, {2: (offsets, faces)})


def check_loops(cx):
    """Every 2-cell's loop visits exactly its vertices, consecutive ones sharing an edge."""
    off, loop = cx.polygons()
    f_off, f_fac = cx.cells[2]
    for c in range(cx.count(2)):
        cell_edges = {tuple(sorted(cx.edges[e])) for e in f_fac[f_off[c]:f_off[c + 1]]}
        verts = list(loop[off[c]:off[c + 1]])
        assert len(verts) == len(cell_edges)
        assert len(set(verts)) == len(verts)
        steps = {tuple(sorted(p)) for p in zip(verts, verts[1:] + verts[:1])}
        assert steps == cell_edges


# ---------------------------------------------------------------------------
# counts, Euler characteristic, boundary
# ---------------------------------------------------------------------------

def test_circle():
    cx = circle()
    assert (cx.n, cx.k, cx.dim) == (2, 1, 1)
    assert cx.counts() == [3, 3]
    assert cx.euler_characteristic() == 0
    assert cx.facet_cofaces().tolist() == [2, 2, 2]
    assert cx.boundary_facets().size == 0
    assert cx.connected_components() == 1
    assert cx.polygons()[0].tolist() == [0]


def test_open_path_boundary_is_degree_one_vertices():
    cx = CellComplex(2, 1, np.zeros((4, 2)), [[0, 1], [1, 2], [2, 3]])
    assert cx.boundary_facets().tolist() == [0, 3]
    assert cx.boundary_facets().dtype == np.int64
    assert cx.euler_characteristic() == 1


def test_tetrahedron_boundary():
    cx = tetrahedron_boundary()
    assert cx.counts() == [4, 6, 4]
    assert cx.euler_characteristic() == 2
    assert cx.boundary_facets().size == 0
    assert (cx.facet_cofaces() == 2).all()
    assert cx.connected_components() == 1
    check_loops(cx)


def test_square():
    cx = square()
    assert cx.counts() == [4, 4, 1]
    assert cx.euler_characteristic() == 1
    assert cx.boundary_facets().tolist() == [0, 1, 2, 3]
    check_loops(cx)


def test_cube_boundary():
    cx = cube_boundary()
    assert cx.counts() == [8, 12, 6]
    assert cx.euler_characteristic() == 2
    assert cx.boundary_facets().size == 0
    off, ids = cx.cell_vertices(2)
    assert [sorted(loop) for loop in CUBE_LOOPS] == [ids[off[i]:off[i + 1]].tolist() for i in range(6)]
    check_loops(cx)


def test_solid_cube():
    cx = solid_cube()
    assert cx.dim == 3
    assert cx.counts() == [8, 12, 6, 1]
    assert cx.euler_characteristic() == 1
    assert cx.boundary_facets().tolist() == list(range(6))
    off, ids = cx.cell_vertices(3)
    assert off.tolist() == [0, 8] and ids.tolist() == list(range(8))


def test_boundary_of_4_simplex():
    coords = np.vstack([np.zeros(4), np.eye(4)])
    cx = simplex_boundary(5, coords)
    assert (cx.n, cx.k, cx.dim) == (4, 1, 3)
    assert cx.counts() == [5, 10, 10, 5]
    assert cx.euler_characteristic() == 0
    assert cx.boundary_facets().size == 0
    assert (cx.facet_cofaces() == 2).all()
    for r in range(4):
        off, ids = cx.cell_vertices(r)
        assert np.diff(off).tolist() == [r + 1] * cx.count(r)
        expected = list(itertools.chain(*itertools.combinations(range(5), r + 1)))
        assert ids.tolist() == expected
    check_loops(cx)


def test_boundary_of_5_simplex_cell_vertices():
    coords = np.vstack([np.zeros(5), np.eye(5)])
    cx = simplex_boundary(6, coords)
    assert cx.counts() == [6, 15, 20, 15, 6]
    assert cx.euler_characteristic() == 2
    off, ids = cx.cell_vertices(4)
    assert np.diff(off).tolist() == [5] * 6


def test_count_out_of_range():
    with pytest.raises(ValueError):
        circle().count(2)
    with pytest.raises(ValueError):
        circle().count(-1)


def test_repr():
    assert repr(cube_boundary()) == "CellComplex(n=3, k=1, counts=[8, 12, 6])"


def test_arrays_are_read_only_but_inputs_are_not_frozen():
    v = CUBE_V.copy()
    cx = CellComplex(3, 2, v, [[0, 1]])
    assert v.flags.writeable
    with pytest.raises(ValueError):
        cx.vertices[0, 0] = 5.0
    assert cx.vertices.dtype == np.float64 and cx.edges.dtype == np.int64


def test_empty_complex():
    cx = CellComplex(3, 1, np.zeros((0, 3)), np.zeros((0, 2), dtype=np.int64))
    assert cx.counts() == [0, 0, 0]
    assert cx.euler_characteristic() == 0
    assert cx.connected_components() == 0
    assert cx.polygons()[0].tolist() == [0]
    assert cx.cell_vertices(2)[0].tolist() == [0]
    cx = CellComplex(3, 1, [], [])
    assert cx.counts() == [0, 0, 0]


# ---------------------------------------------------------------------------
# polygons, cell vertices, components
# ---------------------------------------------------------------------------

def test_polygons_random_shuffled_loops():
    rng = np.random.default_rng(1)
    loops = []
    for _ in range(300):
        m = int(rng.integers(3, 10))
        ids = list(rng.permutation(1000)[:m])
        loops.append(ids)
    cx = from_polygons(3, 1, rng.normal(size=(1000, 3)), loops)
    # shuffle each cell's face list and flip edge orientations
    off, fac = cx.cells[2]
    fac = fac.copy()
    for c in range(cx.count(2)):
        fac[off[c]:off[c + 1]] = rng.permutation(fac[off[c]:off[c + 1]])
    edges = cx.edges.copy()
    flip = rng.random(len(edges)) < 0.5
    edges[flip] = edges[flip][:, ::-1]
    cx = CellComplex(3, 1, cx.vertices, edges, {2: (off, fac)})
    check_loops(cx)
    # the loop starts at the first vertex of the cell's first edge, towards its second
    p_off, p_ids = cx.polygons()
    for c in range(cx.count(2)):
        e = edges[fac[off[c]]]
        assert p_ids[p_off[c]] == e[0] and p_ids[p_off[c] + 1] == e[1]


def test_polygons_degenerate_cells_do_not_crash():
    v = np.zeros((8, 3))
    edges = [[0, 1], [1, 2], [2, 0], [3, 4], [4, 5], [5, 3], [6, 7], [0, 6]]
    cells = {2: (np.array([0, 6, 6, 10, 11]),      # two triangles; empty; dangling edge; one edge
                 np.array([0, 1, 2, 3, 4, 5, 0, 1, 2, 7, 6]))}
    cx = CellComplex(3, 1, v, edges, cells)
    off, ids = cx.polygons()
    loops = [ids[off[c]:off[c + 1]].tolist() for c in range(4)]
    assert loops[0] == [0, 1, 2]            # one of the two triangles
    assert loops[1] == []
    assert set(loops[2]) == {0, 1, 2, 6}    # walks out and back along the dangling edge
    assert loops[3] == [6, 7]
    mesh = cx.to_pyvista()                  # cells with < 3 loop vertices are skipped
    assert mesh.n_cells == 2
    assert mesh.cell_data["cell_id"].tolist() == [0, 2]


def test_polygons_cached():
    cx = cube_boundary()
    assert cx.polygons() is cx.polygons()
    assert cx.cell_vertices(2) is cx.cell_vertices(2)


def test_cell_vertices_matches_naive():
    coords = np.vstack([np.zeros(4), np.eye(4)])
    for cx in (cube_boundary(), solid_cube(), simplex_boundary(5, coords), quad_torus(5, 7)):
        def verts(r, i, cx=cx):
            if r == 0:
                return {i}
            if r == 1:
                return set(cx.edges[i].tolist())
            off, fac = cx.cells[r]
            return set().union(*[verts(r - 1, f) for f in fac[off[i]:off[i + 1]]])
        for r in range(cx.dim + 1):
            off, ids = cx.cell_vertices(r)
            assert off.dtype == np.int64 and ids.dtype == np.int64
            for i in range(cx.count(r)):
                assert ids[off[i]:off[i + 1]].tolist() == sorted(verts(r, i))


def test_connected_components():
    v = np.zeros((9, 2))
    edges = [[0, 1], [1, 2], [2, 0], [5, 3], [4, 5], [8, 7]]  # 3 pieces + isolated 6
    cx = CellComplex(2, 1, v, edges)
    assert cx.connected_components() == 4
    assert cx.component_labels().tolist() == [0, 0, 0, 3, 3, 3, 6, 7, 7]


def test_connected_components_random_against_bfs():
    rng = np.random.default_rng(7)
    for _ in range(20):
        nv = int(rng.integers(1, 200))
        ne = int(rng.integers(0, 2 * nv))
        edges = rng.integers(0, nv, size=(ne, 2))
        cx = CellComplex(3, 2, rng.normal(size=(nv, 3)), edges)
        adj = {i: set() for i in range(nv)}
        for a, b in edges:
            adj[a].add(b)
            adj[b].add(a)
        seen, comps = set(), 0
        for s in range(nv):
            if s in seen:
                continue
            comps += 1
            stack = [s]
            seen.add(s)
            while stack:
                x = stack.pop()
                for y in adj[x] - seen:
                    seen.add(y)
                    stack.append(y)
        assert cx.connected_components() == comps


def _whole_complex_checks(cx) -> tuple:
    off, _ids = cx.polygons()
    return (cx.euler_characteristic(), cx.boundary_facets().size, bool((np.diff(off) == 4).all()),
            cx.cell_vertices(2)[1].size, cx.connected_components())


def test_quad_torus_large_has_no_loop_per_cell():
    # Speed is measured in the benchmarks, not asserted here: what this guards is that whole-complex
    # queries are array code.  A loop over cells in Python runs a line per cell; count the lines run.
    _whole_complex_checks(quad_torus(6, 5))      # first calls (numba compiles, caches fill) untraced
    cx = quad_torus(500, 400)        # 200k quads, 400k edges
    assert cx.counts() == [200_000, 400_000, 200_000]
    lines = 0

    def tracer(frame, event, arg):
        nonlocal lines
        lines += event == "line"
        return tracer

    sys.settrace(tracer)
    try:
        got = _whole_complex_checks(cx)
    finally:
        sys.settrace(None)
    assert got == (0, 0, True, 800_000, 1)
    assert lines < 20_000, f"{lines} Python lines for 200,000 cells: a loop per cell?"
    # spot-check loops
    small = quad_torus(6, 5)
    check_loops(small)


# ---------------------------------------------------------------------------
# validation
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("args, match", [
    ((0, 0, np.zeros((0, 0)), []), "n must be"),
    ((3, 4, np.zeros((0, 3)), []), "k must"),
    ((3, 1, np.zeros((4, 2)), []), "vertices must have shape"),
    ((3, 1, np.array([["a", "b", "c"]]), []), "vertices must be"),
    ((2, 1, np.zeros((3, 2)), [[0, 1, 2]]), "edges must have shape"),
    ((2, 1, np.zeros((3, 2)), [[0.0, 1.0]]), "edges must be an integer array"),
    ((2, 1, np.zeros((3, 2)), [[0, 3]]), "vertex 3"),
    ((2, 1, np.zeros((3, 2)), [[0, -1]]), "vertex -1"),
    ((2, 2, np.zeros((3, 2)), [[0, 1]]), "no edges"),
    ((2, 1, np.zeros((3, 2)), [[0, 1]], {2: ([0, 1], [0])}), "cells has key 2"),
    ((2, 0, np.zeros((3, 2)), [[0, 1]], {2: ([0, 2], [0])}), "offsets end at 2"),
    ((2, 0, np.zeros((3, 2)), [[0, 1]], {2: ([1, 1], [0])}), "start at 0"),
    ((2, 0, np.zeros((3, 2)), [[0, 1]], {2: ([0, 1, 0], [0])}), "non-decreasing"),
    ((2, 0, np.zeros((3, 2)), [[0, 1]], {2: ([0, 1], [1])}), "1-cell 1"),
    ((2, 0, np.zeros((3, 2)), [[0, 1]], {2: ([0, 1], [0.0])}), "integer array"),
    ((2, 0, np.zeros((3, 2)), [[0, 1]], {2: [0, 1, 2]}), "pair"),
    ((2, 0, np.zeros((3, 2)), [[0, 1]], None, [1, 2]), "meta must be a dict"),
])
def test_constructor_validation(args, match):
    with pytest.raises(ValueError, match=match):
        CellComplex(*args)


def test_face_ids_checked_against_lower_level():
    cx = solid_cube()
    off, fac = cx.cells[2]
    with pytest.raises(ValueError, match="2-cell 6"):
        CellComplex(3, 0, cx.vertices, cx.edges, {2: (off, fac), 3: ([0, 1], [6])})


def test_missing_levels_are_empty():
    cx = CellComplex(3, 0, CUBE_V, [[0, 1]])
    assert cx.counts() == [8, 1, 0, 0]
    assert sorted(cx.cells) == [2, 3]


# ---------------------------------------------------------------------------
# files
# ---------------------------------------------------------------------------

def test_save_load_round_trip(tmp_path):
    coords = np.vstack([np.zeros(4), np.eye(4)]) + 0.1 * np.random.default_rng(3).normal(size=(5, 4))
    cx = simplex_boundary(5, coords)
    cx.meta.update({
        "bounds": np.array([[-1.0, 1.0]] * 4),
        "div": np.int64(10),
        "seed": 0,
        "method": "gcmh",
        "formulas": ["x1^2 + x2^2 + x3^2 + x4^2 - 1"],
        "variables": ("x", "y", "z", "w"),
        "seconds": np.float64(0.25),
        "nonfinite_vertices": 0,
    })
    path = tmp_path / "c.npz"
    cx.save(path)
    with np.load(path, allow_pickle=False) as z:
        assert set(z.files) == {"format", "n", "k", "vertices", "cells_1",
                                "cells_2_offsets", "cells_2_faces",
                                "cells_3_offsets", "cells_3_faces", "meta_json"}
        assert str(z["format"]) == FORMAT == "gcmh-complex/1"
        assert int(z["n"]) == 4 and int(z["k"]) == 1
        assert z["vertices"].dtype == np.float64
        assert z["cells_1"].dtype == np.int64
        assert z["cells_3_faces"].dtype == np.int64
        assert json.loads(str(z["meta_json"]))["div"] == 10
    back = CellComplex.load(path)
    assert (back.n, back.k) == (4, 1)
    assert back.vertices.tobytes() == cx.vertices.tobytes()
    assert back.edges.tobytes() == cx.edges.tobytes()
    for r in (2, 3):
        for a, b in zip(back.cells[r], cx.cells[r]):
            assert a.dtype == b.dtype == np.int64
            assert np.array_equal(a, b)
    # the run's seconds depend on the machine: left out unless asked for (run_json)
    assert back.meta == {
        "bounds": [[-1.0, 1.0]] * 4, "div": 10, "seed": 0, "method": "gcmh",
        "formulas": ["x1^2 + x2^2 + x3^2 + x4^2 - 1"], "variables": ["x", "y", "z", "w"],
        "nonfinite_vertices": 0,
    }
    assert back.counts() == cx.counts()
    cx.save(tmp_path / "t.npz", timings=True)
    with np.load(tmp_path / "t.npz", allow_pickle=False) as z:
        assert json.loads(str(z["run_json"])) == {"seconds": 0.25}
    assert CellComplex.load(tmp_path / "t.npz").meta["seconds"] == 0.25


def test_save_load_dim1_and_uncompressed(tmp_path):
    cx = circle()
    cx.save(tmp_path / "circle.npz", compressed=False)
    with np.load(tmp_path / "circle.npz") as z:
        assert set(z.files) == {"format", "n", "k", "vertices", "cells_1", "meta_json"}
    back = CellComplex.load(tmp_path / "circle.npz")
    assert back.counts() == [3, 3] and back.meta == {}


def test_load_extra_keys_go_to_meta(tmp_path):
    cx = circle()
    path = tmp_path / "x.npz"
    np.savez(path, format=np.array(FORMAT), n=np.array(2), k=np.array(1),
             vertices=cx.vertices, cells_1=cx.edges, div=np.array([4, 4]))
    back = CellComplex.load(path)
    assert back.meta == {"div": [4, 4]}


def _npz(path, **arrays):
    np.savez(path, **arrays)
    return path


@pytest.mark.parametrize("make", [
    lambda p: p.write_text("hello, not a complex") and p,
    lambda p: p.write_bytes(b"PK\x03\x04 truncated zip") and p,
    lambda p: _npz(p, n=np.array(2)),
    lambda p: _npz(p, format=np.array("gcmh-complex/99"), n=np.array(2), k=np.array(1),
                   vertices=np.zeros((1, 2)), cells_1=np.zeros((0, 2), dtype=np.int64)),
    lambda p: _npz(p, format=np.array(FORMAT), n=np.array(2), k=np.array(1),
                   vertices=np.zeros((1, 2))),
    lambda p: _npz(p, format=np.array(FORMAT), n=np.array(2), k=np.array(1),
                   vertices=np.zeros((1, 2)), cells_1=np.array([[0, 5]])),
    lambda p: _npz(p, format=np.array(FORMAT), n=np.array(2), k=np.array(1),
                   vertices=np.zeros((1, 2), dtype=np.float32),
                   cells_1=np.zeros((0, 2), dtype=np.int64)),
    lambda p: _npz(p, format=np.array(FORMAT), n=np.array(3), k=np.array(1),
                   vertices=np.zeros((1, 3)), cells_1=np.zeros((0, 2), dtype=np.int64)),
    lambda p: _npz(p, format=np.array(FORMAT), n=np.array(2), k=np.array(1),
                   vertices=np.zeros((1, 2)), cells_1=np.zeros((0, 2), dtype=np.int64),
                   meta_json=np.array("{not json")),
    lambda p: _npz(p, format=np.array(FORMAT), n=np.array(2), k=np.array(1),
                   vertices=np.zeros((1, 2)), cells_1=np.zeros((0, 2), dtype=np.int64),
                   meta=np.array([{"a": 1}], dtype=object)),
    lambda p: (np.save(p.with_suffix(".npy"), np.zeros(3)), p.with_suffix(".npy"))[1],
], ids=["text", "truncated-zip", "no-format", "wrong-format", "no-edges", "bad-edge-id",
        "float32-vertices", "missing-cells-2", "bad-meta-json", "pickled-member", "npy"])
def test_load_bad_file_raises_value_error(tmp_path, make):
    path = make(tmp_path / "bad.npz")
    with pytest.raises(ValueError, match="not a valid gcmh-complex/1 file"):
        CellComplex.load(path)


# ---------------------------------------------------------------------------
# pyvista
# ---------------------------------------------------------------------------

def test_to_pyvista_polygons_and_save_vtu(tmp_path):
    pv = pytest.importorskip("pyvista")
    cx = cube_boundary(meta={"variables": ["x", "y", "z"]})
    mesh = cx.to_pyvista()
    assert isinstance(mesh, pv.UnstructuredGrid)
    assert mesh.n_points == 8 and mesh.n_cells == 6
    assert set(mesh.celltypes.tolist()) == {pv.CellType.POLYGON}
    assert np.array_equal(mesh.points, CUBE_V)
    assert np.array_equal(mesh.point_data["y"], CUBE_V[:, 1])
    path = tmp_path / "cube.vtu"
    cx.save_vtu(path)
    back = pv.read(path)
    assert back.n_cells == 6 and back.n_points == 8
    for i, name in enumerate("xyz"):
        assert np.array_equal(back.point_data[name], CUBE_V[:, i])


def test_to_pyvista_lines_padded():
    pv = pytest.importorskip("pyvista")
    mesh = circle().to_pyvista()
    assert mesh.n_points == 3 and mesh.n_cells == 3
    assert set(mesh.celltypes.tolist()) == {pv.CellType.LINE}
    assert np.array_equal(mesh.points[:, 2], np.zeros(3))
    assert sorted(mesh.point_data.keys()) == ["x1", "x2"]


def test_to_pyvista_4d_3complex(tmp_path):
    pv = pytest.importorskip("pyvista")
    coords = np.vstack([np.zeros(4), np.eye(4)])
    cx = simplex_boundary(5, coords)
    mesh = cx.to_pyvista()
    assert mesh.n_cells == 10   # the 2-skeleton
    assert set(mesh.celltypes.tolist()) == {pv.CellType.POLYGON}
    assert np.array_equal(mesh.points, coords[:, :3])
    path = tmp_path / "s.vtu"
    cx.save_vtu(path)
    back = pv.read(path)
    for i in range(4):
        assert np.array_equal(back.point_data[f"x{i + 1}"], coords[:, i])


def test_to_pyvista_empty_and_points_only():
    pytest.importorskip("pyvista")
    mesh = CellComplex(3, 1, np.zeros((0, 3)), []).to_pyvista()
    assert mesh.n_points == 0 and mesh.n_cells == 0
    points = CellComplex(3, 3, np.eye(3), []).to_pyvista()
    assert points.n_points == 3 and points.n_cells == 3


def test_missing_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        CellComplex.load(tmp_path / "nothing.npz")


def test_import_does_not_load_gui_or_vtk():
    code = (
        "import sys, gcmh_core.complex\n"
        "bad = [m for m in ('pyvista', 'vtk', 'vtkmodules', 'PyQt5', 'qtpy', 'pyvistaqt')"
        " if m in sys.modules]\n"
        "assert not bad, bad\n"
    )
    subprocess.run([sys.executable, "-c", code], cwd=REPO, check=True)
