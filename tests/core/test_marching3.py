"""The marching pass for n = 3, k = 1 (`kernels.marching3`) against the general path.

Its tables against the naive twin (tests/core/naive.py, one cube per sign case), and
whole runs against the general sweep (`sweep.MARCHING3 = False`): the same complex,
byte for byte, and the same meta, on the examples, random functions, sampled data with
exact zeros at grid vertices, rows of 63, 64, 65 and more vertices (the pass keeps a
row's signs in 64-bit words), slabs of one layer, and values that send the pass back
to the general path (not finite, overflowing differences).
"""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

from gcmh_core import extract, sweep
from gcmh_core.errors import Cancelled
from gcmh_core.examples import load_example
from gcmh_core.kernels.marching3 import cube_cases

_HERE = os.path.dirname(os.path.abspath(__file__))
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)

from test_pinned_outputs import complex_digest  # noqa: E402

from naive import naive_marching_cases  # noqa: E402

VOLATILE = ("seconds", "timings")
SQUARE_AXES = {0: (0, 1), 1: (0, 2), 2: (1, 2)}


def both_paths(monkeypatch, *args, **kwargs):
    """extract(...) by the marching pass and by the general path; asserts the pass ran."""
    ran = []
    march = sweep._marching_sweep

    def spy(*a, **kw):
        result = march(*a, **kw)
        ran.append(result is not None)
        return result

    monkeypatch.setattr(sweep, "_marching_sweep", spy)
    monkeypatch.setattr(sweep, "MARCHING3", None)
    fast = extract(*args, **kwargs)
    monkeypatch.setattr(sweep, "MARCHING3", False)
    general = extract(*args, **kwargs)
    return fast, general, ran


def assert_same(fast, general):
    assert complex_digest(fast) == complex_digest(general)
    assert fast.counts() == general.counts()
    strip = lambda cx: {key: value for key, value in cx.meta.items() if key not in VOLATILE}  # noqa: E731
    assert strip(fast) == strip(general)
    assert list(strip(fast)) == list(strip(general))  # (same order: the saved meta_json is the same text)


# ----------------------------------------------------------------------------- the tables
def test_cube_cases_match_naive():
    cases = cube_cases()
    naive = naive_marching_cases()
    assert sum(1 for c in range(256) if cases.cube_pieces[c] >= 2) > 0  # (ambiguous cases exist)
    for case in range(256):
        pieces, sizes, squares, non_ball = naive[case]
        assert cases.cube_pieces[case] == pieces, case
        starts = cases.piece_start[case]
        assert sorted(int(starts[p + 1] - starts[p]) for p in range(pieces)) == sizes, case
        assert cases.cube_nonball[case] == non_ball, case
        for kf1 in range(6):
            q = int(cases.square_rank[kf1])
            local = sum((case >> int(c) & 1) << i for i, c in enumerate(cases.square_corners[kf1]))
            anchor = tuple(int(cases.square_anchor[kf1]) >> a & 1 for a in range(3))
            assert cases.square_count[q, local] == squares.get((SQUARE_AXES[q], anchor), 0), (case, kf1)


# ----------------------------------------------------------------------------- whole runs
@pytest.mark.parametrize("name", ["sphere", "torus", "genus-two", "hyperboloid", "whitney-umbrella"])
@pytest.mark.parametrize("seed", [0, 3])
def test_examples_same_bytes(monkeypatch, name, seed):
    ex = load_example(name)
    div = ex.div if isinstance(ex.div, int) else list(ex.div)
    fast, general, ran = both_paths(monkeypatch, ex.formulas, ex.bounds, div, variables=ex.variables, seed=seed,
                                    params={p: v["value"] for p, v in ex.params.items()} or None)
    assert ran == [True]
    assert fast.counts()[0] > 0
    assert_same(fast, general)


@pytest.mark.parametrize("div", [1, 2, [1, 3, 2], [5, 62, 63], [4, 3, 64], [3, 5, 65], [2, 3, 130], 17])
def test_grid_shapes_same_bytes(monkeypatch, div):
    """Tiny grids and rows of 63..131 vertices (one word, a full word, one bit past it)."""
    fast, general, ran = both_paths(monkeypatch, "x^2 + 2*y^2 + 3*z^2 - 1 + 0.3*sin(5*x*z)", (-1.1, 1.1), div,
                                    variables="x,y,z")
    assert ran == [True]
    assert_same(fast, general)


@pytest.mark.parametrize("seed", range(8))
def test_random_sampled_with_exact_zeros_same_bytes(monkeypatch, seed):
    """Random cubic polynomials sampled and rounded, so many grid vertices are exactly 0
    (0 counts as >= 0), with ambiguous faces and cubes."""
    rng = np.random.default_rng(seed)
    shape = tuple(int(s) for s in rng.integers(3, 12, 3))
    axes = [np.linspace(-1, 1, s) for s in shape]
    X = np.meshgrid(*axes, indexing="ij")
    coef = rng.normal(size=(3, 3, 3))
    F = sum(coef[a, b, c] * X[0] ** a * X[1] ** b * X[2] ** c for a in range(3) for b in range(3) for c in range(3))
    F = np.round(F * 2) / 2  # exact zeros
    assert np.count_nonzero(F == 0) > 0
    fast, general, ran = both_paths(monkeypatch, F[..., None], bounds=(-1, 1))
    assert ran == [True]
    assert_same(fast, general)


@pytest.mark.parametrize("seed", range(6))
def test_random_formulas_same_bytes(monkeypatch, seed):
    rng = np.random.default_rng(100 + seed)
    terms = [f"{rng.normal():.3f}*{m}" for m in ("x^2", "y^2", "z^2", "x*y", "y*z", "x*z", "x", "y", "z")]
    formula = " + ".join(terms) + f" + {rng.normal() * 0.3:.3f} + 0.2*cos(7*x)*sin(5*y)"
    div = [int(d) for d in rng.integers(8, 40, 3)]
    fast, general, ran = both_paths(monkeypatch, formula, (-1.3, 1.3), div, variables="x,y,z", seed=seed)
    assert ran == [True]
    assert_same(fast, general)


def test_slabs_of_one_layer_same_bytes(monkeypatch):
    monkeypatch.setattr(sweep, "MARCH_SLAB_VERTICES", 1)
    fast, general, ran = both_paths(monkeypatch, "x^2 + y^2 + z^2 - 0.8", (-1, 1), [9, 70, 6], variables="x,y,z")
    assert ran == [True]
    assert_same(fast, general)


def test_pruned_and_plain_sweeps_give_the_same_bytes(monkeypatch):
    fast, general, _ = both_paths(monkeypatch, "x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 48, variables="x,y,z")
    monkeypatch.setattr(sweep, "PRUNE", True)
    pruned = extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 48, variables="x,y,z")
    assert complex_digest(fast) == complex_digest(general) == complex_digest(pruned)
    assert pruned.meta["pruned_cubes"] > 0  # (PRUNE = True still takes the pruned sweep)


@pytest.mark.parametrize("poison", [np.nan, np.inf, -np.inf])
def test_nonfinite_values_take_the_general_path(monkeypatch, poison):
    ax = np.linspace(-1, 1, 11)
    X, Y, Z = np.meshgrid(ax, ax, ax, indexing="ij")
    F = X**2 + Y**2 + Z**2 - 0.5
    F[5, 5, 8] = poison  # a vertex next to the sphere
    fast, general, ran = both_paths(monkeypatch, F[..., None], bounds=(-1, 1))
    assert ran == [False]
    assert fast.meta["nonfinite_vertices"] == 1
    assert_same(fast, general)


def test_overflowing_differences_take_the_general_path(monkeypatch):
    """F(b) - F(a) = inf: the general solve finds no crossing there; the pass must not either."""
    ax = np.linspace(-1, 1, 7)
    X, Y, Z = np.meshgrid(ax, ax, ax, indexing="ij")
    F = np.where(X + 0.1 * Y + 0.01 * Z > 0, 1.5e308, -1.5e308)
    fast, general, ran = both_paths(monkeypatch, F[..., None], bounds=(-1, 1))
    assert ran == [False]
    assert_same(fast, general)


def test_log_and_sqrt_formulas_same_bytes(monkeypatch):
    """Formulas that are not finite on part of the grid: the pass hands over, same result."""
    fast, general, ran = both_paths(monkeypatch, "log(x + 0.5) + y^2 + sqrt(z + 1) - 1", (-1, 1), 12,
                                    variables="x,y,z")
    assert ran == [False]
    assert_same(fast, general)


def test_periodic_axes_take_the_general_path(monkeypatch):
    fast, general, ran = both_paths(monkeypatch, "cos(x) + cos(y) + cos(z)", (0, "2*pi"), 12, variables="x,y,z",
                                    periodic=["x", "y", "z"])
    assert ran == []
    assert_same(fast, general)
    assert fast.euler_characteristic() == -4  # (Schwarz P in the 3-torus: genus 3)


def test_cms_and_other_dimensions_never_take_the_pass(monkeypatch):
    for args, kwargs in [(("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 6), dict(variables="x,y,z", method="cms")),
                         (("x^2 + y^2 - 1", (-1.5, 1.5), 6), dict(variables="x,y")),
                         (("x^2 + y^2 + z^2 + w^2 - 1", (-1.5, 1.5), 5), dict(variables="x,y,z,w"))]:
        fast, general, ran = both_paths(monkeypatch, *args, **kwargs)
        assert ran == []
        assert_same(fast, general)


def test_progress_and_cancel(monkeypatch):
    monkeypatch.setattr(sweep, "MARCH_SLAB_VERTICES", 1)
    seen = []
    extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 10, variables="x,y,z", progress=lambda p, f: seen.append((p, f)))
    fractions = [f for p, f in seen if p == "extracting"]
    assert len(fractions) == 10 and fractions == sorted(fractions)
    assert seen[-1] == ("assembling", 1.0)
    polls = []

    def cancel():
        polls.append(1)
        return len(polls) > 3

    with pytest.raises(Cancelled):
        extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 10, variables="x,y,z", cancel=cancel)


def test_checkerboard_grows_the_outputs_same_bytes(monkeypatch):
    """F changes sign along every grid edge: every cube is ambiguous, and the outputs
    outgrow the room the pass starts with (a surface crossing the grid twice)."""
    rng = np.random.default_rng(7)
    i, j, k = np.indices((24, 23, 70))
    F = np.where((i + j + k) % 2 == 0, 1.0, -1.0) * rng.uniform(0.5, 2.0, i.shape)
    fast, general, ran = both_paths(monkeypatch, F[..., None], bounds=(-1, 1))
    assert ran == [True]
    assert fast.counts()[0] > 2 * (24 * 23 + 23 * 70 + 24 * 70)
    assert_same(fast, general)


def test_a_run_inside_a_progress_callback_keeps_its_own_work_arrays(monkeypatch):
    inner = []

    def progress(phase, fraction):
        if phase == "extracting" and not inner:
            inner.append(extract("x^2 + y^2 + z^2 - 0.5", (-1, 1), [6, 7, 8], variables="x,y,z"))

    monkeypatch.setattr(sweep, "MARCH_SLAB_VERTICES", 1)
    outer = extract("x^2 + 2*y^2 + z^2 - 1", (-1.5, 1.5), [11, 9, 10], variables="x,y,z", progress=progress)
    monkeypatch.setattr(sweep, "MARCHING3", False)
    assert complex_digest(outer) == complex_digest(
        extract("x^2 + 2*y^2 + z^2 - 1", (-1.5, 1.5), [11, 9, 10], variables="x,y,z"))
    assert complex_digest(inner[0]) == complex_digest(
        extract("x^2 + y^2 + z^2 - 0.5", (-1, 1), [6, 7, 8], variables="x,y,z"))
