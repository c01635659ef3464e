"""The pruned full sweep gives the plain sweep's complex, bit for bit, and start='auto'
(seeded by the same bounds) finds every piece the full sweep finds."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gcmh_core import extract, sweep
from gcmh_core.errors import Cancelled
from gcmh_core.examples import list_examples

EXAMPLES = [ex.name for ex in list_examples()]
SMALL_DIV = {3: 12, 4: 8, 5: 6, 6: 4}  # the whole file runs in seconds


def _run(F, bounds, div, pruned, monkeypatch, **kw):
    """One full sweep, forced to the pruned path (cut down to blocks of 8 cubes, so that
    small grids are cut too, and never given up) or to the plain one."""
    monkeypatch.setattr(sweep, "PRUNE", pruned)
    monkeypatch.setattr(sweep, "_LEAF_CUBES", 8)
    monkeypatch.setattr(sweep, "_GIVE_UP_SHARE", np.inf)
    return extract(F, bounds, div, **kw)


def _assert_same_bytes(a, b):
    assert a.vertices.tobytes() == b.vertices.tobytes()
    assert a.edges.tobytes() == b.edges.tobytes()
    assert sorted(a.cells) == sorted(b.cells)
    for r in a.cells:
        for x, y in zip(a.cells[r], b.cells[r]):
            assert x.dtype == y.dtype and x.tobytes() == y.tobytes()
    for key in ("candidate_cubes", "nonfinite_vertices", "degenerate", "cubes", "collapsed_lenses"):
        assert a.meta[key] == b.meta[key], key


def _both(F, bounds, div, monkeypatch, **kw):
    plain = _run(F, bounds, div, False, monkeypatch, **kw)
    pruned = _run(F, bounds, div, True, monkeypatch, **kw)
    assert "pruned_cubes" in pruned.meta and "pruned_cubes" not in plain.meta
    _assert_same_bytes(plain, pruned)
    return plain, pruned


@pytest.mark.parametrize("name", EXAMPLES)
def test_pruned_equals_plain_on_every_example(name, monkeypatch):
    ex = next(e for e in list_examples() if e.name == name)
    plain, pruned = _both(ex.formulas, ex.bounds, SMALL_DIV[ex.n], monkeypatch, variables=ex.variables,
                          params=ex.param_values() or None)
    assert len(plain.vertices) > 0
    assert 0 < pruned.meta["pruned_cubes"] < pruned.meta["cubes"]


@pytest.mark.parametrize("name, seed", [("sphere", 3), ("complex-cosine", 0), ("hopf-link", 1)])
def test_pruned_equals_plain_simplicial(name, seed, monkeypatch):
    ex = next(e for e in list_examples() if e.name == name)
    _both(ex.formulas, ex.bounds, SMALL_DIV[ex.n], monkeypatch, variables=ex.variables, method="cms", seed=seed)


@pytest.mark.parametrize("formulas, nonfinite", [
    (["sqrt(x) + y^2 - 0.5*z - 0.3"], True),  # nan on half the grid
    (["log(x + 0.3) - y", "z - 0.2*x"], True),  # nan beyond the branch point
    (["x^(1/3) - y*z"], True),
    (["1/(x - 0.05) - 4*y", "x^2 + y^2 + z^2 - 0.8"], False),  # a pole between grid lines
    (["tan(3*x) - y - z"], False),  # poles at x = +-pi/6
])
def test_pruned_counts_non_finite_vertices_like_plain(formulas, nonfinite, monkeypatch):
    for div in (9, [10, 7, 12]):
        plain, _ = _both(formulas, (-1, 1), div, monkeypatch, variables="x,y,z")
        assert len(plain.vertices) > 0
        assert (plain.meta["nonfinite_vertices"] > 0) == nonfinite


@st.composite
def polynomial_systems(draw):
    """k random polynomials (degree <= 3, small integer coefficients) in n variables."""
    n = draw(st.integers(2, 4))
    k = draw(st.integers(1, min(2, n - 1)))
    names = [f"x{i + 1}" for i in range(n)]
    formulas = []
    for _ in range(k):
        terms = []
        for _ in range(draw(st.integers(1, 5))):
            powers = draw(st.lists(st.integers(0, 3), min_size=n, max_size=n).filter(lambda p: sum(p) <= 3))
            coef = draw(st.integers(-3, 3).filter(bool))
            mono = "*".join(f"{v}^{p}" for v, p in zip(names, powers) if p) or "1"
            terms.append(f"({coef})*{mono}")
        terms.append(f"({draw(st.integers(-4, 4)) / 4})")
        formulas.append(" + ".join(terms))
    div = draw(st.lists(st.integers(2, {2: 16, 3: 9, 4: 5}[n]), min_size=n, max_size=n))
    return formulas, names, div, draw(st.integers(0, 3))


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(system=polynomial_systems())
def test_pruned_equals_plain_on_random_polynomial_systems(system, monkeypatch):
    formulas, names, div, seed = system
    _both(formulas, (-1.5, 1.5), div, monkeypatch, variables=names, seed=seed)


@st.composite
def small_pieces(draw):
    """Several small spheres (1 to 3 cubes across) in R^3, or their slices by a
    hyperplane in R^4 (k = 2): pieces a coarse lattice of start points may miss."""
    n = draw(st.sampled_from([3, 4]))
    m = draw(st.integers(2, 5))
    div = 14 if n == 3 else 8
    h = 3.0 / div
    factors = []
    for _ in range(m):
        c = [draw(st.floats(-1.2, 1.2)) for _ in range(n)]
        r = draw(st.floats(0.6, 1.6)) * h
        factors.append("(" + " + ".join(f"(x{i + 1} - ({ci:.4f}))^2" for i, ci in enumerate(c)) + f" - {r * r:.6f})")
    formulas = ["*".join(factors)]
    if n == 4:
        formulas.append(f"x4 - {draw(st.floats(-0.3, 0.3)):.4f}*x1 - ({draw(st.floats(-1, 1)):.4f})")
    return formulas, [f"x{i + 1}" for i in range(n)], div


@settings(max_examples=25, deadline=None, derandomize=True)
@given(system=small_pieces())
def test_auto_start_finds_every_piece_the_full_sweep_finds(system):
    formulas, names, div = system
    full = extract(formulas, (-1.5, 1.5), div, variables=names)
    auto = extract(formulas, (-1.5, 1.5), div, variables=names, method="gcch", start="auto")
    assert auto.connected_components() == full.connected_components()
    assert auto.counts() == full.counts()
    assert np.array_equal(auto.edges, full.edges)
    assert np.allclose(auto.vertices, full.vertices, rtol=0, atol=1e-12)


def test_pruning_is_the_default_for_large_grids_of_formulas_only():
    # (in R^4: GCMH sweeps in R^3 with k = 1 take the n = 3 marching pass, which is not pruned)
    big = extract("x^2 + y^2 + z^2 + w^2 - 1", (-1.5, 1.5), 24, variables="x,y,z,w")
    assert big.meta["pruned_cubes"] > 0.5 * big.meta["cubes"]
    small = extract("x^2 + y^2 + z^2 + w^2 - 1", (-1.5, 1.5), 8, variables="x,y,z,w")
    assert "pruned_cubes" not in small.meta
    ax = np.linspace(-1.5, 1.5, 49)
    x, y, z = np.meshgrid(ax, ax, ax, indexing="ij")
    sampled = extract((x**2 + y**2 + z**2 - 1)[..., None], bounds=(-1.5, 1.5))
    assert "pruned_cubes" not in sampled.meta


def test_pruned_sweep_reports_progress_and_cancels(monkeypatch):
    monkeypatch.setattr(sweep, "PRUNE", True)
    monkeypatch.setattr(sweep, "_BLOCKS_PER_TASK", 4)
    seen = []
    extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 128, variables="x,y,z", progress=lambda p, f: seen.append((p, f)))
    fractions = [f for p, f in seen if p == "extracting"]
    assert len(fractions) > 2 and fractions == sorted(fractions) and 0.5 < fractions[0] and fractions[-1] < 1
    assert seen[-1] == ("assembling", 1.0)
    polls = []

    def cancel():
        polls.append(1)
        return len(polls) > 5

    with pytest.raises(Cancelled):
        extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 128, variables="x,y,z", cancel=cancel)
