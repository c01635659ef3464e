"""Benchmark of one rotation-slider step: project V vertices R^n -> R^3 in place.

    python tests/bench/bench_view.py            # table for 10k, 100k, 1M vertices; n = 3, 4, 5, 10
    python tests/bench/bench_view.py --render   # also time a render off screen (needs GL: xvfb-run or EGL)
    python tests/bench/bench_view.py --mapping stereographic   # a nonlinear view: normals from the projected mesh

(run from the repository root; not collected by pytest: no ``test_`` prefix)

The test surface is a flat torus (a product of two circles) of V vertices,
turned into R^n by a fixed orthogonal map and built as a real
``gcmh_core.CellComplex`` of quads; the step is exactly what the window does
when a slider moves (:meth:`gcmh_studio.scene.Scene.set_projection`): one
``(V, n) @ (n, 3)`` float32 matmul into the VTK points buffer, one
``(V, m) @ (m, 3)`` matmul for the vertex normals (m = n(n-1)/2), and the
VTK Modified() calls. Render time depends on the GPU (software Mesa here).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

# the test surface is the window tests' own (one copy): tests/app/app_helpers.py
sys.path.append(str(Path(__file__).resolve().parents[1] / "app"))
from app_helpers import torus_complex


def bench(V: int, n: int, steps: int = 20, render: bool = False, mapping: str = "orthographic") -> dict:
    import pyvista as pv

    from gcmh_studio.projection import ProjectionModel
    from gcmh_studio.scene import Scene, Style

    side = int(round(math.sqrt(V)))
    cx = torus_complex(side, n)
    pl = pv.Plotter(off_screen=True, window_size=[800, 600])
    try:
        scene = Scene(pl)
        model = ProjectionModel(n=n, mapping=mapping if n >= 4 else "orthographic")
        t0 = time.perf_counter()
        scene.set_complex(cx, cx.point_names(), model.view(), Style(color_by="x1", axes=False))
        build = time.perf_counter() - t0
        if render:
            pl.ren_win.Render()
        tp, tn, tt, tr = [], [], [], []
        for s in range(steps):
            model.angles[s % len(model.angles)] += 3.0
            view = model.view()
            t0 = time.perf_counter()
            scene.projector.project_view(view, out=scene.drawn.pts)
            t1 = time.perf_counter()
            scene._set_view(view)
            scene.drawn.write_normals()
            t2 = time.perf_counter()
            scene.set_projection(view, render=False)   # the whole step as the window does it
            t3 = time.perf_counter()
            if render:
                pl.ren_win.Render()
            t4 = time.perf_counter()
            tp.append(t1 - t0)
            tn.append(t2 - t1)
            tt.append(t3 - t2)
            tr.append(t4 - t3)
    finally:
        pl.close()
    med = lambda a: 1000 * float(np.median(a))  # noqa: E731
    return dict(V=side * side, n=n, build_s=build, project_ms=med(tp), normals_ms=med(tn),
                step_ms=med(tt), render_ms=med(tr) if render else float("nan"))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python tests/bench/bench_view.py", description=__doc__.split("\n")[0])
    p.add_argument("--sizes", default="10000,100000,1000000", help="vertex counts (comma-separated)")
    p.add_argument("--dims", default="3,4,5,10", help="ambient dimensions n (comma-separated, >= 3)")
    p.add_argument("--steps", type=int, default=20)
    p.add_argument("--render", action="store_true", help="also time an off-screen render")
    p.add_argument("--mapping", default="orthographic", choices=("orthographic", "perspective", "stereographic"),
                   help="the view's mapping (nonlinear ones take normals from the projected mesh; n >= 4)")
    a = p.parse_args(argv)
    sizes = [int(s) for s in a.sizes.split(",")]
    dims = [int(s) for s in a.dims.split(",")]
    print(f"{'vertices':>10} {'n':>3} {'project ms':>11} {'normals ms':>11} {'step ms':>9} {'render ms':>10} "
          f"{'build s':>8}")
    for V in sizes:
        for n in dims:
            r = bench(V, n, a.steps, a.render, a.mapping)
            print(f"{r['V']:>10,} {r['n']:>3} {r['project_ms']:>11.2f} {r['normals_ms']:>11.2f} "
                  f"{r['step_ms']:>9.2f} {r['render_ms']:>10.1f} {r['build_s']:>8.2f}", flush=True)
    print(f"mapping: {a.mapping}; step = points + normals written in place + VTK Modified "
          "(what a slider move costs before drawing)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
