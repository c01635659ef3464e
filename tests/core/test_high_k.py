"""Issue 14 item 2, every k up to 10: k = 8 against the slow naive twin on a small case, and tori in R^10
(k = 8) and R^12 (k = 10) closed with chi 0.  The tables' own twin is in test_tables, the lazy kernel's
(n >= 8) against the tables' kernel in test_lazy_kernel; speed is in tests/bench/bench_high_k.py."""

import numpy as np
import pytest
from test_kernels_vs_naive import compare

import gcmh_core
from gcmh_core import grid


def test_k8_in_r9_matches_the_naive_twin():
    """A circle in R^9 cut by seven tilted hyperplanes (each mixing two axes, so no Kuhn simplex is decided by
    one sign flip): the engine's k = 8 vertices, edges and cells are the naive twin's.  (The twin solves all
    8! simplices of each of the cube's 18 8-faces in Python: about 15 s.)"""
    n, k = 9, 8
    bounds = [(0.0, 1.5), (-0.5, 0.5)] + [(-1, 1)] * 7   # one cube, an arc of the circle through it
    div = [1] * n
    axes = grid.perturbed_axes(np.array(bounds, float), np.array(div, np.int64), 0)
    X = np.stack(np.meshgrid(*axes, indexing="ij"), -1)
    F = [X[..., 0] ** 2 + X[..., 1] ** 2 - 1]
    F += [X[..., i] + 0.3 * X[..., (i + 1) % n] - 0.05 * i for i in range(2, n)]
    ref, cx = compare(n, k, 0, values=np.stack(F, -1), bounds=bounds, div=div)
    assert cx.count(0) == 2 and cx.count(1) == 1


def test_a_torus_in_r10_is_closed():
    """x1^2 + x2^2 = 1, x3^2 + x4^2 = 1, x5 = ... = x10 = 0: a torus, k = 8 (each 8-face has 40,320 Kuhn
    simplices); on a coarse grid its two circles are polygons, and the product is closed with chi 0."""
    F = ["x1^2 + x2^2 - 1", "x3^2 + x4^2 - 1"] + [f"x{i} - 0.01*x{i - 1}" for i in range(5, 11)]
    cx = gcmh_core.extract(F, [(-1.5, 1.5)] * 4 + [(-1, 1)] * 6, [3] * 4 + [1] * 6, n=10, force=True)
    assert cx.k == 8 and cx.dim == 2
    assert cx.euler_characteristic() == 0 and len(cx.boundary_facets()) == 0
    assert cx.connected_components() == 1


@pytest.mark.parametrize("n", [11, 12])
def test_k9_and_k10(n):
    """A torus in R^11 (k = 9) and in R^12 (k = 10: 3.6M Kuhn simplices per 10-face, 40M in an 11-face's walk),
    its flat axes tilted as above: closed, chi 0; and a circle in R^11 (k = 10), one loop."""
    F = ["x1^2 + x2^2 - 1", "x3^2 + x4^2 - 1"] + [f"x{i} - 0.01*x{i - 1}" for i in range(5, n + 1)]
    cx = gcmh_core.extract(F, [(-1.5, 1.5)] * 4 + [(-1, 1)] * (n - 4), [3] * 4 + [1] * (n - 4), n=n, force=True)
    assert cx.k == n - 2 and cx.dim == 2
    assert cx.euler_characteristic() == 0 and len(cx.boundary_facets()) == 0 and cx.connected_components() == 1
    if n == 11:
        F = ["x1^2 + x2^2 - 1"] + [f"x{i} - 0.01*x{i - 1}" for i in range(3, 12)]
        cx = gcmh_core.extract(F, [(-1.5, 1.5)] * 2 + [(-1, 1)] * 9, [5] * 2 + [1] * 9, n=11, force=True)
        assert cx.k == 10 and cx.counts()[0] == cx.counts()[1] > 0
        assert cx.euler_characteristic() == 0 and len(cx.boundary_facets()) == 0 and cx.connected_components() == 1


def test_the_tables_build_of_a_run_reports_progress_and_cancels():
    """extract's progress hears the cube tables' build and its cancel stops it there."""
    from gcmh_core.errors import Cancelled
    from gcmh_core.kernels import tables as _tables

    F = ["x1^2 + x2^2 - 1", "x3^2 + x4^2 - 1"] + [f"x{i}" for i in range(5, 10)]
    bounds, div = [(-1.5, 1.5)] * 4 + [(-1, 1)] * 5, [3] * 4 + [1] * 5
    _tables.cube_tables.cache_clear()
    seen = []
    with pytest.raises(Cancelled):
        gcmh_core.extract(F, bounds, div, n=9, force=True, progress=lambda p, f: seen.append((p, f)),
                          cancel=lambda: any(p.startswith("cube tables") and f > 0.3 for p, f in seen))
    phases = [p for p, _ in seen]
    assert "cube tables: faces" in phases and not any(p == "extracting" for p in phases)


def test_k10_kernel_runs_are_short_so_a_cancel_is_heard():
    """At k = 10 a cube takes milliseconds: the runner cuts the candidate cubes into runs of a quarter second
    (`budget.kernel_batch_cubes`) and polls cancel between them; a cancel set in the kernel phase stops the run
    before the next run."""
    from gcmh_core import runner
    from gcmh_core.errors import Cancelled

    n = 12
    F = ["x1^2 + x2^2 - 1", "x3^2 + x4^2 - 1"] + [f"x{i} - 0.01*x{i - 1}" for i in range(5, n + 1)]
    bounds, div = [(-1.5, 1.5)] * 4 + [(-1, 1)] * (n - 4), [5] * 4 + [1] * (n - 4)
    runs = []
    keep = runner.Grid.run_kernel

    def counted(self, values, cube_lin, origin, value_off):
        if len(cube_lin) <= self.kernel_batch:
            runs.append(len(cube_lin))
        return keep(self, values, cube_lin, origin, value_off)

    runner.Grid.run_kernel = counted
    try:
        with pytest.raises(Cancelled):
            gcmh_core.extract(F, bounds, div, n=n, force=True, cancel=lambda: len(runs) >= 2)
    finally:
        runner.Grid.run_kernel = keep
    assert len(runs) == 2 and max(runs) <= 100  # (at most 71 cubes a run at k = 10; the grid has 128 candidates)
