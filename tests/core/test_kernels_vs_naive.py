"""The fast engine against the slow reference (tests/core/naive.py).

Part 1 proves the reference itself (sphere, circle, Clifford torus, a saddle
that needs the walk, ...).  Part 2 runs gcmh_core.extract and the naive code
on the same sampled values over the same perturbed grid and demands identical
complexes: same vertices (to 1e-9), and the same r-cells, each as its vertex
set together with the vertex sets of its faces, as multisets, r = 1..n-k.
Part 3 tests the numba kernels one by one against naive pieces.
"""
from __future__ import annotations

import itertools
import math
import os
import sys
from collections import Counter

import numpy as np
import pytest

_HERE = os.path.dirname(os.path.abspath(__file__))
_ROOT = os.path.dirname(os.path.dirname(_HERE))
for _p in (_HERE, _ROOT):
    if _p not in sys.path:
        sys.path.insert(0, _p)

from naive import (  # noqa: E402
    euler_characteristic,
    kuhn_path,
    naive_candidates,
    naive_extract,
    signature,
    simplex_lambdas,
    subfaces,
)

# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------

def local_axes(bounds, div, seed=0, eps=1e-3):
    """Perturbed grid lines for the self-checks (independent of the engine)."""
    rng = np.random.default_rng(seed)
    out = []
    for (lo, hi), d in zip(bounds, div):
        h = (hi - lo) / d
        out.append(lo + np.arange(d + 1) * h + rng.uniform(-1, 1, d + 1) * eps * h)
    return out


def sample(axes, func):
    """values[..., j] = F_j on the meshgrid of ``axes``."""
    X = np.meshgrid(*axes, indexing="ij")
    comps = func(*X)
    return np.stack([np.broadcast_to(c, X[0].shape) for c in comps], axis=-1).astype(np.float64)


def random_system(n, k, seed):
    """A random polynomial F: R^n -> R^k whose zero set crosses [-1, 1]^n.

    Three families, chosen by the seed: quadrics through a random point p
    (affine + quadratic part), products of two affine forms (saddles/crossings,
    which make the walk work), and intersections of random ellipsoids.
    """
    rng = np.random.default_rng(1000 + 17 * n + 101 * k + seed)
    family = seed % 3
    p = rng.uniform(-0.4, 0.4, n)
    comps = []
    for j in range(k):
        a = rng.normal(size=n)
        Q = rng.normal(size=(n, n))
        Q = 0.5 * (Q + Q.T)
        if family == 0:
            comps.append(("quad", a, 0.8 / k * Q, p))
        elif family == 1 and j == 0:
            b = rng.normal(size=n)
            comps.append(("prod", a, b, p + rng.uniform(-0.2, 0.2, n), rng.normal() * 0.05))
        elif family == 1:
            comps.append(("quad", a, 0.3 * Q, p))
        else:
            c = rng.uniform(0.5, 2.0, n)
            u = rng.normal(size=n)
            centre = p + rng.uniform(0.6, 1.2) * u / np.linalg.norm(u)
            r2 = float(np.sum(c * (p - centre) ** 2))   # passes through p
            comps.append(("ell", c, centre, r2))

    def F(*X):
        X = np.stack(X, axis=-1)
        out = []
        for comp in comps:
            if comp[0] == "quad":
                _, a, Q, q = comp
                Y = X - q
                out.append(Y @ a + np.einsum("...i,ij,...j->...", Y, Q, Y))
            elif comp[0] == "prod":
                _, a, b, q, e = comp
                Y = X - q
                out.append((Y @ a) * (Y @ b) + e)
            else:
                _, c, centre, r2 = comp
                out.append(((X - centre) ** 2) @ c - r2)
        return out

    return F


def edge_multiplicity(result):
    """How many top 2-cells contain each edge (n - k == 2)."""
    c = Counter()
    for _, faces in result["cells"][2]:
        for e in faces:
            c[e] += 1
    return c


# ---------------------------------------------------------------------------
# Part 1: the reference proves itself
# ---------------------------------------------------------------------------

def test_kuhn_simplices_tile_the_cube():
    # k! simplices per k-face, each of volume 1/k!, all distinct, covering the cube
    for m in range(1, 5):
        anchor = (0,) * m
        S = tuple(range(m))
        sims = [kuhn_path(anchor, p) for p in itertools.permutations(S)]
        assert len(sims) == math.factorial(m)
        vol = 0.0
        for s in sims:
            M = np.array([np.subtract(v, s[0]) for v in s[1:]], float)
            vol += abs(np.linalg.det(M)) / math.factorial(m)
            assert s[0] == anchor and s[-1] == (1,) * m
        assert vol == pytest.approx(1.0)
        # every point of the cube lies in the simplex of the order of its coordinates
        rng = np.random.default_rng(m)
        for x in rng.random((20, m)):
            perm = tuple(np.argsort(-x))
            s = np.array(kuhn_path(anchor, perm), float)
            lam = np.linalg.solve(np.vstack([s.T, np.ones(m + 1)]), np.append(x, 1.0))
            assert np.all(lam >= -1e-12)


def test_subfaces_counts():
    cube = ((0, 0, 0, 0), (0, 1, 2, 3))
    for m in range(5):
        assert len(subfaces(cube, m)) == math.comb(4, m) * 2 ** (4 - m)
    face = ((1, 0, 2), (0, 2))
    assert sorted(subfaces(face, 1)) == sorted(
        [((1, 0, 2), (0,)), ((1, 0, 3), (0,)), ((1, 0, 2), (2,)), ((2, 0, 2), (2,))])


def test_simplex_lambdas_by_hand():
    # k = 1: F = -1 at v0, +3 at v1 -> zero at lambda = (3/4, 1/4)
    lam = simplex_lambdas([[-1.0], [3.0]])
    assert np.allclose(lam, [0.75, 0.25])
    assert simplex_lambdas([[1.0], [3.0]]) is None
    assert simplex_lambdas([[1.0], [3.0]], sign_shortcut=False) is None
    # k = 2: F(v) = v - c on the triangle (0,0),(1,0),(0,1): lambdas of c
    V = np.array([[0, 0], [1, 0], [0, 1]], float)
    c = np.array([0.2, 0.3])
    lam = simplex_lambdas(V - c)
    assert np.allclose(lam, [0.5, 0.2, 0.3])
    assert simplex_lambdas(V - np.array([0.8, 0.8])) is None
    # singular system: both components identical -> no vertex
    assert simplex_lambdas([[-1.0, -1.0], [1.0, 1.0], [1.0, 1.0]]) is None


def test_candidates_by_hand():
    vals = np.ones((3, 2, 1))
    vals[0, 0, 0] = -1
    assert naive_candidates(vals) == [(0, 0)]
    vals[2, 1, 0] = np.nan
    assert naive_candidates(vals) == [(0, 0)]
    vals[1, 1, 0] = np.nan
    assert naive_candidates(vals) == []
    vals = np.ones((2, 2, 2, 2))
    vals[0, 0, 0, 0] = -1
    assert naive_candidates(vals) == []          # component 1 never changes sign
    vals[1, 1, 1, 1] = -0.5
    assert naive_candidates(vals) == [(0, 0, 0)]


def test_naive_circle():
    ax = local_axes([(-1.3, 1.3)] * 2, [9, 9])
    res = naive_extract(sample(ax, lambda x, y: [x * x + y * y - 1]), ax)
    V, E = len(res["vertices"]), len(res["cells"][1])
    assert V == E > 0
    deg = Counter(v for vs, _ in res["cells"][1] for v in vs)
    assert set(deg.values()) == {2}
    assert np.allclose(np.hypot(*res["vertices"].T), 1, atol=0.05)


def test_naive_sphere_is_closed_surface():
    ax = local_axes([(-1.3, 1.3)] * 3, [6, 6, 6])
    res = naive_extract(sample(ax, lambda x, y, z: [x * x + y * y + z * z - 1]), ax)
    assert euler_characteristic(res) == 2
    mult = edge_multiplicity(res)
    assert len(mult) == len(res["cells"][1])
    assert set(mult.values()) == {2}
    assert np.allclose(np.linalg.norm(res["vertices"], axis=1), 1, atol=0.06)
    assert not res["walk_dead_ends"]


def test_naive_clifford_torus():
    ax = local_axes([(-1.0, 1.0)] * 4, [6] * 4, seed=3)
    res = naive_extract(sample(ax, lambda x, y, z, w: [x * x + y * y - 0.5, z * z + w * w - 0.5]), ax)
    assert euler_characteristic(res) == 0
    assert set(edge_multiplicity(res).values()) == {2}
    assert len(res["cells"][2]) > 0


def test_naive_two_spheres_intersection_in_r3_is_a_circle():
    # n = 3, k = 2: a curve; every vertex on exactly two edges
    ax = local_axes([(-1.5, 1.5)] * 3, [7] * 3, seed=1)
    res = naive_extract(sample(ax, lambda x, y, z: [x * x + y * y + z * z - 1, x + 0.3 * y - 0.2 * z - 0.1]), ax)
    deg = Counter(v for vs, _ in res["cells"][1] for v in vs)
    assert len(deg) == len(res["vertices"]) > 0
    assert set(deg.values()) == {2}


def test_naive_walk_resolves_a_saddle_square():
    # one square, signs + - + - around it: four vertices, the walk pairs them
    ax = [np.array([0.0, 1.0]), np.array([0.0, 1.0])]
    vals = np.array([[[1.0], [-1.0]], [[-1.0], [2.0]]])
    res = naive_extract(vals, ax)
    assert len(res["vertices"]) == 4
    assert len(res["cells"][1]) == 2
    assert res["walked_faces"] and not res["walk_dead_ends"]
    # the Kuhn diagonal (0,0)-(1,1) has values 1 and 2: both positive, so the
    # two edges cut off the two negative corners
    pos = res["vertices"]
    for vs, _ in res["cells"][1]:
        a, b = sorted(vs)
        mid = 0.5 * (pos[a] + pos[b])
        assert (mid[0] > mid[1]) == (pos[a][0] > pos[a][1])   # same side of the diagonal


def test_naive_walk_in_3d_consistent():
    # many ambiguous faces: a product of two planes in R^3 (a crossing)
    ax = local_axes([(-1, 1)] * 3, [4] * 3, seed=5)
    res = naive_extract(sample(ax, lambda x, y, z: [(x - 0.1 * y + 0.05) * (y + 0.2 * z - 0.03) + 0.01]), ax)
    assert res["walked_faces"]
    assert not res["walk_dead_ends"]
    # an edge is on at most two polygons, and every polygon is a closed loop
    assert max(edge_multiplicity(res).values()) <= 2
    for vs, faces in res["cells"][2]:
        deg = Counter(v for e in faces for v in res["cells"][1][e][0])
        assert set(deg.values()) == {2} and set(deg) == set(vs)


@pytest.mark.parametrize("n,k", [(3, 1), (4, 2), (4, 1)])
def test_naive_random_faces_of_faces(n, k):
    # structural sanity on random systems: boundary of a boundary is empty
    # (each (r-2)-cell appears an even number of times among faces of faces)
    for seed in range(3):
        div = [3] * n
        ax = local_axes([(-1, 1)] * n, div, seed=seed)
        res = naive_extract(sample(ax, random_system(n, k, seed)), ax)
        assert not res["walk_dead_ends"]
        cells = res["cells"]
        for r in range(2, n - k + 1):
            for vs, faces in cells[r]:
                cnt = Counter()
                for f in faces:
                    assert cells[r - 1][f][0] <= vs
                    for g in cells[r - 1][f][1]:
                        cnt[g] += 1
                assert all(c % 2 == 0 for c in cnt.values()), (seed, r)


# ---------------------------------------------------------------------------
# Part 2: engine vs naive
# ---------------------------------------------------------------------------

CASES = [(2, 1), (3, 1), (3, 2), (4, 1), (4, 2), (5, 3), (6, 3)]
SEEDS = list(range(8))


def _engine():
    try:
        import gcmh_core
        from gcmh_core import grid
    except ImportError as exc:  # pragma: no cover - the engine is required
        pytest.fail(f"engine not importable: {exc}")
    assert hasattr(gcmh_core, "extract"), "gcmh_core.extract missing"
    assert hasattr(grid, "perturbed_axes"), "gcmh_core.grid.perturbed_axes missing"
    return gcmh_core, grid


def case_grid(n, k, seed):
    rng = np.random.default_rng(7 * seed + n * 131 + k)
    hi = 2 if n >= 6 else (3 if n >= 5 else 4)
    div = [int(d) for d in rng.integers(2, hi + 1, n)]
    bounds = [(-1.0, 1.0)] * n
    return bounds, div


def match_vertices(A, B, tol=1e-9):
    """Bijection i -> j with |A[i] - B[j]| < tol, or an assertion error."""
    assert A.shape == B.shape, f"vertex count: naive {len(A)}, engine {len(B)}"
    if len(A) == 0:
        return {}
    oa = np.lexsort(A.T[::-1])
    ob = np.lexsort(B.T[::-1])
    if np.allclose(A[oa], B[ob], rtol=0, atol=tol):
        mapping = {int(i): int(j) for i, j in zip(oa, ob)}
    else:
        # lexicographic order can flip on ties at the 1e-15 level: match by distance
        mapping = {}
        for i, a in enumerate(A):
            d = np.max(np.abs(B - a), axis=1)
            j = int(np.argmin(d))
            assert d[j] < tol, f"naive vertex {i} at {a} has no engine twin (nearest {d[j]:.3g})"
            mapping[i] = j
    assert len(set(mapping.values())) == len(A), "vertex matching is not one-to-one"
    return mapping


def _same_points(A, B, tol=1e-9):
    try:
        match_vertices(A, B, tol)
        return True
    except AssertionError:
        return False


def engine_signature(cx):
    out = {}
    dim = cx.n - cx.k
    edges = np.asarray(cx.edges)
    out[1] = [(frozenset(map(int, e)), frozenset(frozenset([int(v)]) for v in e)) for e in edges]
    prev = [frozenset(map(int, e)) for e in edges]
    for r in range(2, dim + 1):
        off, vids = cx.cell_vertices(r)
        foff, faces = cx.cells[r]
        cur = []
        for i in range(len(off) - 1):
            X = frozenset(int(v) for v in vids[off[i]:off[i + 1]])
            Fs = frozenset(prev[int(f)] for f in faces[foff[i]:foff[i + 1]])
            out.setdefault(r, []).append((X, Fs))
            cur.append(X)
        out.setdefault(r, [])
        prev = cur
    return out


def _describe(cells, verts, limit=4):
    lines = []
    for X, Fs in list(cells)[:limit]:
        lines.append(f"  cell on {len(X)} vertices {sorted(X)} with {len(Fs)} faces; "
                     f"first vertex at {np.round(verts[min(X)], 4).tolist()}")
    return "\n".join(lines)


def extract_as_gcmh(values, **kw):
    """The engine's GCMH output as the paper (and the naive twin) define it: without what
    the assembly adds to make cells regular (lens collapse and halved double edges,
    gcmh_core._regular, tested in test_regular) and balls (the split of pieces M_A joins
    through a cube, and the solids' Euler check, gcmh_core._balls, tested in test_balls and
    test_solid_balls; the lens cells of higher dimensions, _balls.collapse_lens_cells, and the
    whole-ball lenses coned, _balls.cone_lens_balls, in test_regular_high_n)."""
    from gcmh_core import _balls, runner

    gcmh_core, _ = _engine()
    keep = runner.collapse_lenses, runner.subdivide_double_edges, runner.split_non_ball_cells, runner.checks_cells
    keep_lens_cells, keep_cone = _balls.collapse_lens_cells, runner.cone_lens_balls
    runner.cone_lens_balls = lambda vertices, edges, cells: (vertices, edges, cells, 0)
    _balls.collapse_lens_cells = lambda e, c, inc: (e, c, inc)
    runner.collapse_lenses = lambda edges, cells: (edges, cells, 0, 0)
    runner.subdivide_double_edges = lambda vertices, edges, cells: (vertices, edges, cells, 0)
    runner.split_non_ball_cells = lambda grid, records, cubes, common: records
    runner.checks_cells = lambda *args: False
    try:
        return gcmh_core.extract(values, **kw)
    finally:
        runner.collapse_lenses, runner.subdivide_double_edges, runner.split_non_ball_cells, runner.checks_cells \
            = keep
        _balls.collapse_lens_cells, runner.cone_lens_balls = keep_lens_cells, keep_cone


# the naive twin's runs of the random cases, kept for test_random_cases_are_not_vacuous (the topology
# and the walk depend on the values only, not on where the grid lines sit): the twin is slow
_NAIVE_RUNS: dict = {}


def compare(n, k, seed, values=None, bounds=None, div=None):
    """Run engine and naive on the same sampled values; fail on any difference."""
    gcmh_core, grid = _engine()
    random_case = values is None
    if values is None:
        bounds, div = case_grid(n, k, seed)
    axes = grid.perturbed_axes(np.array(bounds, float), np.array(div, np.int64), seed)
    if values is None:
        values = sample(axes, random_system(n, k, seed))
    # Sampled values can't be moved, so the engine places them on the exact grid
    # (amplitude 0); the values themselves come from the perturbed grid, which
    # keeps them generic.  The topology depends on the values only.
    flat = grid.perturbed_axes(np.array(bounds, float), np.array(div, np.int64), seed, 0.0)
    ref = naive_extract(values, flat)
    if random_case:
        _NAIVE_RUNS[(n, k, seed)] = ref
    cx = extract_as_gcmh(values, bounds=bounds, div=div, seed=seed)
    tag = f"(n={n}, k={k}, seed={seed}, div={div})"
    assert _same_points(ref["vertices"], np.asarray(cx.vertices)), f"{tag} vertex positions differ"

    assert cx.n == n and cx.k == k
    if "non_ball_cells" in cx.meta and ref["non_ball_cells"] is not None:  # (not counted by the twin in R^7)
        assert int(cx.meta["non_ball_cells"]) == ref["non_ball_cells"], f"{tag} pieces that are not balls"
    if "candidate_cubes" in cx.meta:
        assert int(cx.meta["candidate_cubes"]) == len(ref["candidates"]), \
            f"{tag} candidate cubes: engine {cx.meta['candidate_cubes']}, naive {len(ref['candidates'])}"

    V_ref = ref["vertices"]
    V_eng = np.asarray(cx.vertices)
    assert V_eng.shape == V_ref.shape, (
        f"{tag} vertex count: engine {len(V_eng)}, naive {len(V_ref)} "
        f"(if every vertex is off, the engine may not use perturbed_axes(bounds, div, seed) for sampled data)")
    vmap = match_vertices(V_ref, V_eng)

    sig_ref = signature(ref, vmap)
    sig_eng = engine_signature(cx)
    for r in range(1, n - k + 1):
        a, b = Counter(sig_ref[r]), Counter(sig_eng.get(r, []))
        if a != b:
            only_ref, only_eng = a - b, b - a
            vs_a = Counter(X for X, _ in sig_ref[r])
            vs_b = Counter(X for X, _ in sig_eng.get(r, []))
            pytest.fail(
                f"{tag} r={r}: naive {sum(a.values())} cells, engine {sum(b.values())}; "
                f"vertex sets agree: {vs_a == vs_b}\n"
                f"only in naive ({sum(only_ref.values())}):\n{_describe(only_ref, V_eng)}\n"
                f"only in engine ({sum(only_eng.values())}):\n{_describe(only_eng, V_eng)}")
    return ref, cx


@pytest.mark.parametrize("n,k", CASES)
@pytest.mark.parametrize("seed", SEEDS)
def test_extract_matches_naive(n, k, seed):
    compare(n, k, seed)


@pytest.mark.parametrize("seed", [0, 1])
def test_extract_matches_naive_beyond_bit_masks(seed):
    """n = 7: a cube's 128 corners do not fit the kernel's int64 corner masks, and its
    sign prune goes corner by corner instead (`_tables.MASKED_N`)."""
    compare(7, 3, seed)


def test_sampled_data_sits_on_the_exact_grid():
    # sampled values are F at the grid's own vertices: no perturbation of positions
    gcmh_core, grid = _engine()
    bounds, div, seed = [(-1.0, 1.0)] * 2, [5, 4], 3
    axes = [np.linspace(lo, hi, d + 1) for (lo, hi), d in zip(bounds, div)]
    exact = grid.perturbed_axes(np.array(bounds), np.array(div), seed, 0.0)
    assert all(np.array_equal(a, b) for a, b in zip(axes, exact))
    vals = sample(axes, lambda x, y: [x * x + y * y - 0.5])
    ref = naive_extract(vals, axes)
    cx = gcmh_core.extract(vals, bounds=bounds, div=div, seed=seed)
    V = np.asarray(cx.vertices)
    assert len(V) == len(ref["vertices"])
    assert _same_points(ref["vertices"], V)


def test_random_cases_are_not_vacuous():
    # the random systems must actually cross the grids, and the walk must run
    _, grid = _engine()
    walked = 0
    for n, k in CASES:
        tops = 0
        for seed in SEEDS:
            ref = _NAIVE_RUNS.get((n, k, seed))
            if ref is None:  # (run alone: the twin again)
                bounds, div = case_grid(n, k, seed)
                ax = grid.perturbed_axes(np.array(bounds, float), np.array(div, np.int64), seed)
                ref = naive_extract(sample(ax, random_system(n, k, seed)), ax)
            tops += len(ref["cells"][n - k]) > 0
            walked += len(ref["walked_faces"])
        assert tops >= len(SEEDS) // 2, (n, k, tops)
    assert walked > 0


def test_extract_sphere_matches_naive_self_check():
    gcmh_core, grid = _engine()
    bounds, div = [(-1.3, 1.3)] * 3, [6, 6, 6]
    axes = grid.perturbed_axes(np.array(bounds), np.array(div, np.int64), 0)
    vals = sample(axes, lambda x, y, z: [x * x + y * y + z * z - 1])
    cx = gcmh_core.extract(vals, bounds=bounds, div=div, seed=0)
    assert cx.euler_characteristic() == 2
    assert euler_characteristic(naive_extract(vals, axes)) == 2


def test_extract_nonfinite_values_match_naive():
    _, grid = _engine()
    n, k, seed = 3, 1, 11
    bounds, div = [(-1.0, 1.0)] * 3, [4, 4, 4]
    axes = grid.perturbed_axes(np.array(bounds), np.array(div, np.int64), seed)
    vals = sample(axes, lambda x, y, z: [x * x + y * y + z * z - 0.6])
    vals[2, 1, 1, 0] = np.nan
    vals[1, 3, 2, 0] = np.inf
    ref, cx = compare(n, k, seed, vals, bounds, div)
    assert len(ref["candidates"]) < len(naive_candidates(np.nan_to_num(vals, posinf=1.0)))
    assert len(ref["cells"][2]) > 0


@pytest.mark.parametrize("n,k,seed,div", [(4, 2, 0, 1), (4, 2, 1, 1), (4, 2, 3, 3), (5, 3, 0, 2)])
def test_degenerate_sampled_data_gives_no_empty_cells(n, k, seed, div):
    # Integer-valued samples put zeros on grid vertices and make walks end early, so
    # some vertices stay isolated.  Contract: an r-cell is a connected component WITH
    # AT LEAST ONE EDGE; an isolated vertex is no cell.  (Exact naive == engine is not
    # demanded here: coincident vertices make coordinate matching ambiguous.)
    gcmh_core, _ = _engine()
    rng = np.random.default_rng(seed)
    vals = rng.integers(-1 if div == 1 else -2, 2 if div == 1 else 3,
                        size=(div + 1,) * n + (k,)).astype(float)
    axes = [np.linspace(0.0, 1.0, div + 1)] * n
    ref = naive_extract(vals, axes)
    cx = gcmh_core.extract(vals, bounds=[(0.0, 1.0)] * n, div=div, seed=seed)
    sig = engine_signature(cx)
    for r in range(2, n - k + 1):
        empty = [i for i, (X, Fs) in enumerate(sig[r]) if len(X) < 2 or not Fs]
        assert all(len(X) >= 2 and Fs for X, Fs in signature(ref)[r])
        assert not empty, (
            f"(n={n}, k={k}, seed={seed}, div={div}) engine has {len(empty)} of {len(sig[r])} "
            f"{r}-cells with no vertices/faces (naive: {len(ref['cells'][r])} cells, none empty); "
            f"looks like cubes_chunk step 3 makes components of isolated vertices")


# ---------------------------------------------------------------------------
# Part 3: kernel by kernel
# ---------------------------------------------------------------------------

def _bits(corner, n):
    return tuple((corner >> a) & 1 for a in range(n))


@pytest.mark.parametrize("k", [1, 2, 3, 4, 5])
def test_simplex_crosses_matches_naive_solve(k):
    from gcmh_core.kernels.solve import _zero_side, simplex_crosses
    rng = np.random.default_rng(40 + k)
    m = k + 1
    corner_off = np.arange(m, dtype=np.int64)
    corners = np.arange(m, dtype=np.int64)[None]  # one simplex, as a table
    full = (1 << k) - 1
    mat = np.empty((k, k))
    rhs = np.empty(k)
    lam = np.empty(k + 1)
    hits = 0
    for trial in range(3000):
        vals = rng.normal(size=(m, k))
        if trial % 3 == 0:      # bias towards simplices that hold a zero
            lam_true = rng.dirichlet(np.ones(m))
            vals -= lam_true @ vals
        pos_mask = np.zeros(m, np.int64)
        for i in range(m):
            for j in range(k):
                if vals[i, j] >= 0:
                    pos_mask[i] |= 1 << j
        got = simplex_crosses(vals, 0, corner_off, corners, 0, k, pos_mask, full, mat, rhs, lam)
        if got == 2:  # on a facet up to rounding: the kernels ask _zero_side
            got = _zero_side(vals, 0, corner_off, corners, 0, k, lam)
        want = simplex_lambdas(vals)
        assert bool(got) == (want is not None), (k, trial, vals, want)
        if got:
            hits += 1
            assert np.allclose(lam, want, rtol=0, atol=1e-9), (k, trial, lam, want)
    assert hits > 500


@pytest.mark.parametrize("k", [1, 2, 3])
def test_zero_on_a_facet_is_inside_like_naive(k):
    """A component 0 on the facet opposite corner i and < 0 at i: the zero is inside
    (value 0 = +epsilon), in the kernel as in the naive solve; scaled rows answer alike."""
    from gcmh_core.kernels.solve import _zero_side, simplex_crosses
    rng = np.random.default_rng(70 + k)
    m = k + 1
    idx = np.arange(m, dtype=np.int64)
    mat, rhs, lam = np.empty((k, k)), np.empty(k), np.empty(m)
    inside = 0
    for trial in range(300):
        vals = rng.normal(size=(m, k))
        i = trial % m
        vals[:, 0] = 0.0
        vals[i, 0] = -abs(vals[i, 0]) - 0.1
        vals[:, 1:] *= 10.0 ** rng.integers(-12, 13, size=k - 1)  # any scale per component
        pos = np.array([sum(1 << j for j in range(k) if vals[c, j] >= 0) for c in range(m)], np.int64)
        got = simplex_crosses(vals, 0, idx, idx[None], 0, k, pos, (1 << k) - 1, mat, rhs, lam)
        if got == 2:
            got = _zero_side(vals, 0, idx, idx[None], 0, k, lam)
        want = simplex_lambdas(vals)
        assert bool(got) == (want is not None), (k, trial, vals)
        if got:
            inside += 1
            assert np.allclose(lam, want, atol=1e-9) and lam[i] == 0.0 or lam[i] >= 0.0
    assert inside > 30


def test_simplex_crosses_singular_and_offsets():
    from gcmh_core.kernels.solve import _zero_side, simplex_crosses
    k = 2
    mat, rhs, lam = np.empty((k, k)), np.empty(k), np.empty(k + 1)
    # identical components -> flat: decided by simulation of simplicity, as the exact twin decides
    vals = np.array([[-1.0, -1.0], [1.0, 1.0], [2.0, 2.0]])
    pos = np.array([0, 3, 3], np.int64)
    idx = np.arange(3, dtype=np.int64)
    assert simplex_crosses(vals, 0, idx, idx[None], 0, k, pos, 3, mat, rhs, lam) == 2
    assert bool(_zero_side(vals, 0, idx, idx[None], 0, k, lam)) == (simplex_lambdas(vals) is not None)
    # rows reached through o + corner_off[corner]: same answer as the packed layout
    rng = np.random.default_rng(9)
    V = np.array([[0, 0], [1, 0], [0, 1]], float)
    big = rng.normal(size=(20, 2))
    big[[5 + 0, 5 + 3, 5 + 7]] = V - np.array([0.2, 0.3])
    corner_off = np.array([0, 3, 7, 11], np.int64)     # "corner" c lives at row o + corner_off[c]
    corners = np.array([[9, 9, 9], [0, 1, 2]], np.int64)  # the simplex is row 1
    posm = np.array([(v >= 0) @ [1, 2] for v in big[5 + corner_off]], np.int64)
    assert simplex_crosses(big, 5, corner_off, corners, 1, k, posm, 3, mat, rhs, lam)
    assert np.allclose(lam, [0.5, 0.2, 0.3])


@pytest.mark.parametrize("n,k", [(1, 1), (2, 1), (3, 1), (3, 2), (4, 2), (5, 3)])
def test_candidate_cubes_match_naive(n, k):
    from gcmh_core.grid import candidate_corner_sets, candidate_cubes, candidate_origins, candidate_scan
    rng = np.random.default_rng(n * 10 + k)
    for trial in range(20):
        shape = tuple(int(s) for s in rng.integers(2, 5 if n < 5 else 4, n)) + (k,)
        vals = rng.normal(size=shape) + rng.normal(scale=0.7, size=k)
        if trial % 4 == 1:
            vals[rng.random(shape) < 0.05] = np.nan
        if trial % 4 == 2:
            vals[rng.random(shape) < 0.05] = rng.choice([np.inf, -np.inf])
        if trial % 4 == 3:
            vals = np.round(vals)                         # exact zeros: >= 0 is positive
        mask = candidate_cubes(vals)
        assert mask.shape == tuple(s - 1 for s in shape[:-1])
        got = sorted(tuple(int(i) for i in ix) for ix in zip(*np.nonzero(mask)))
        assert got == naive_candidates(vals), (n, k, trial)
        # the same test on cubes given corner by corner (as continuation gathers them)
        cubes = list(np.ndindex(*mask.shape))
        corners = np.array([vals[tuple(np.add(c, bits))] for c in cubes for bits in np.ndindex(*(2,) * n)])
        assert candidate_corner_sets(corners, 2**n).tolist() == [bool(mask[c]) for c in cubes], (n, k, trial)
        origins, _ = candidate_origins(vals)  # the same cubes, as rows, in C order
        assert origins.dtype == np.int64 and origins.shape == (len(got), n)
        assert [tuple(int(i) for i in row) for row in origins] == got
        # in two slabs along axis 0 that share a layer, the second given the first's codes
        cut = int(rng.integers(1, shape[0] - 1)) if shape[0] > 2 else 1
        first, carry, first_bad = candidate_scan(vals[: cut + 1])
        second, _, second_bad = candidate_scan(vals[cut:], carry)
        second[:, 0] += cut
        assert [tuple(int(i) for i in row) for row in np.concatenate([first, second])] == got
        # whether a value is not finite: in the second slab, also on the layer it was given
        assert first_bad == (not np.isfinite(vals[: cut + 1]).all())
        assert second_bad == (not np.isfinite(vals[cut:]).all()), (n, k, trial)


@pytest.mark.parametrize("n,k", [(2, 1), (3, 2), (4, 2), (5, 3), (6, 2), (6, 3), (6, 5), (7, 3)])
def test_corner_masks_of_faces_and_simplices(n, k):
    """The kernel's bit-mask sign prune: bit c of a mask is cube corner c of the set."""
    from gcmh_core.kernels.tables import MASKED_N, _faces, cube_tables, simplex_tables

    T = cube_tables(n, k)
    if n > MASKED_N:  # 2^n corners do not fit an int64: the kernels test corner by corner
        assert len(T.ksimplex_corner_mask) == len(T.kface_corner_mask) == len(T.k1face_corner_mask) == 0
        assert len(simplex_tables(n, k).corner_mask) == 0
        return
    def as_set(mask):
        return {c for c in range(2**n) if int(np.uint64(np.int64(mask))) >> c & 1}

    for s, corners in enumerate(T.ksimplex_corners):
        assert as_set(T.ksimplex_corner_mask[s]) == set(corners.tolist())
    for dim, masks in ((k, T.kface_corner_mask), (k + 1, T.k1face_corner_mask)):
        faces = _faces(n, dim)
        assert len(masks) == len(faces)
        for (free, fixed, _), mask in zip(faces, masks):
            # a face's corners: those that agree with `fixed` off its free axes
            want = {c for c in range(2**n) if (c & ~free) == fixed}
            assert as_set(mask) == want
    # the simplicial baselines' simplices (chains padded with -1)
    if n <= 6:
        S = simplex_tables(n, k)
        for row, mask in zip(S.corners, S.corner_mask):
            assert as_set(mask) == {int(c) for c in row if c >= 0}
    # a k-face's k! simplices follow one another and cover exactly its corners
    kf = math.factorial(k)
    for fi, mask in enumerate(T.kface_corner_mask):
        union = set()
        for s in range(fi * kf, (fi + 1) * kf):
            assert T.ksimplex_face[s] == fi
            union |= as_set(T.ksimplex_corner_mask[s])
        assert union == as_set(mask)


@pytest.mark.parametrize("n,k", [(2, 1), (3, 1), (3, 2), (4, 2), (5, 3), (6, 3)])
def test_cube_tables_match_naive_kuhn(n, k):
    from gcmh_core.kernels.tables import cube_tables
    T = cube_tables(n, k)
    origin = (0,) * n
    cube = (origin, tuple(range(n)))
    # faces of each dimension r >= k: same set as naive subfaces
    for r in range(k, n + 1):
        rows = range(T.face_start[r], T.face_start[r + 1])
        got = sorted((_bits(int(T.face_fixed[f]), n), tuple(a for a in range(n) if T.face_free[f] >> a & 1))
                     for f in rows)
        assert got == sorted(subfaces(cube, r))
    # Kuhn k-simplices: corner chains equal the naive Kuhn paths, perm rank in itertools order
    kf0 = T.face_start[k]
    want = set()
    for anchor, S in subfaces(cube, k):
        for rank, p in enumerate(itertools.permutations(S)):
            want.add((anchor, S, rank, tuple(kuhn_path(anchor, p))))
    got = set()
    for s in range(len(T.ksimplex_corners)):
        f = kf0 + T.ksimplex_face[s]
        anchor = _bits(int(T.face_fixed[f]), n)
        S = tuple(a for a in range(n) if T.face_free[f] >> a & 1)
        got.add((anchor, S, int(T.ksimplex_perm[s]), tuple(_bits(int(c), n) for c in T.ksimplex_corners[s])))
    assert got == want
    # walk template: (k+1)! simplices, each facet j = chain minus vertex j; boundary nodes map to
    # the Kuhn simplex of the cube with the same corner set
    m = k + 1
    assert len(T.walk_simplex_corners) == math.factorial(m)
    nb_ = T.walk_boundary_nodes
    assert nb_ == 2 * m * math.factorial(k)
    f1 = T.face_start[m]
    for fi in range(T.face_start[m + 1] - f1):
        cmap = T.walk_corner_map[fi]
        for t in range(len(T.walk_simplex_corners)):
            chain = [int(cmap[c]) for c in T.walk_simplex_corners[t]]
            for j in range(m + 1):
                facet = set(chain[:j] + chain[j + 1:])
                node = T.walk_simplex_nodes[t, j]
                if node < nb_:
                    assert j in (0, m)
                    s = T.walk_boundary_simplex[fi, node]
                    assert set(int(c) for c in T.ksimplex_corners[s]) == facet
                else:
                    assert 0 < j < m
                    assert set(int(cmap[c]) for c in T.walk_interior_corners[node - nb_]) == facet


# ---------------------------------------------------------------------------
# Part 4: the simplicial baseline (CMS) against its slow twin
# ---------------------------------------------------------------------------

def compare_cms(n, k, seed):
    from naive import naive_cms

    gcmh_core, grid = _engine()
    bounds, div = case_grid(n, k, seed)
    axes = grid.perturbed_axes(np.array(bounds, float), np.array(div, np.int64), seed)
    values = sample(axes, random_system(n, k, seed))
    flat = grid.perturbed_axes(np.array(bounds, float), np.array(div, np.int64), seed, 0.0)
    ref = naive_cms(values, flat)
    cx = gcmh_core.extract(values, bounds=bounds, div=div, seed=seed, method="cms")
    tag = f"CMS (n={n}, k={k}, seed={seed}, div={div})"
    V_ref, V_eng = ref["vertices"], np.asarray(cx.vertices)
    assert V_eng.shape == V_ref.shape, f"{tag} vertex count: engine {len(V_eng)}, naive {len(V_ref)}"
    vmap = match_vertices(V_ref, V_eng)
    sig_ref, sig_eng = signature(ref, vmap), engine_signature(cx)
    for r in range(1, n - k + 1):
        assert Counter(sig_ref[r]) == Counter(sig_eng.get(r, [])), (
            f"{tag} r={r}: naive {len(sig_ref[r])} cells, engine {len(sig_eng.get(r, []))}")
    return ref, cx


CMS_CASES = [(2, 1), (3, 1), (3, 2), (4, 1), (4, 2), (5, 3)]


@pytest.mark.parametrize("n,k", CMS_CASES)
@pytest.mark.parametrize("seed", SEEDS[:5])
def test_cms_matches_naive(n, k, seed):
    compare_cms(n, k, seed)


def test_cms_cases_are_not_vacuous():
    tops = sum(len(compare_cms(n, k, seed)[0]["cells"][n - k]) > 0 for n, k in CMS_CASES for seed in SEEDS[:5])
    assert tops >= len(CMS_CASES) * 2


def test_non_ball_pieces_match_naive():
    """Pieces of G_H that M_A joins through a face (issue 13): the kernel's count equals the
    naive marching over each face's Kuhn simplices, on one cube and on the diagonal tube."""
    one = np.ones((2, 2, 2, 1))
    one[0, 0, 0] = one[1, 1, 1] = -1.0
    ref, _ = compare(3, 1, 0, values=one, bounds=[(0.0, 1.0)] * 3, div=[1, 1, 1])
    assert ref["non_ball_cells"] == 1
    ax = np.linspace(-1, 1, 9)
    X, Y, Z = np.meshgrid(ax, ax, ax, indexing="ij")
    m = (X + Y + Z) / 3
    tube = ((X - m) ** 2 + (Y - m) ** 2 + (Z - m) ** 2 - 0.04)[..., None]
    ref, _ = compare(3, 1, 0, values=tube, bounds=[(-1.0, 1.0)] * 3, div=[8, 8, 8])
    assert ref["non_ball_cells"] > 0
