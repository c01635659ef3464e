"""Benchmark of slicing in the real window under Xvfb: one step of the slice's slider, end to end.

    xvfb-run -a .venv/bin/python tests/bench/bench_sections.py             # exact sections (and the slab today)
    xvfb-run -a .venv/bin/python tests/bench/bench_sections.py --no-slab   # exact sections only

(run from the repository root; not collected by pytest: no ``test_`` prefix)

For each example: open it at its default div, turn the slice on along VAR, then move the slice's slider
by 2 % of the range, STEPS times, timing each step from ``setValue`` to the end of the render that shows
it (a VTK EndEvent on the render window), as tests/bench/bench_classroom.py times a rotation step; then
the step's two parts back to back: the scene's slice alone ("slice ms": the section cut and written into
its mesh, or the slab clipped) and a render alone ("render ms").
"section" rows draw the exact section (gcmh_studio.sections.SectionScene, put in the window's viewer in
place of Scene here: the hook the viewer takes); "slab" rows draw today's window of cells.  The strip's
profile (chi and pieces at 121 values, in its worker thread) is timed from the slice turned on.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.append(str(Path(__file__).resolve().parent))

from bench_classroom import _app, _end_of_render, _spin, _window

CASES = (("three-sphere", "w"), ("three-sphere-slices", "w"), ("three-torus", "x2"), ("three-torus", "x1"),
         ("klein-bottle-closed", "t"), ("torus-angles", "s"))   # the last two: sections across a glued seam
STEPS = 15
STRIP_FIRST = False   # --strip-first: the steps after the strip's profile is drawn (not while it is computed)


def slice_steps(app, name: str, var: str, exact: bool) -> dict:
    import gcmh_studio.qt_viewer as viewer_module
    from gcmh_core.examples import load_example
    from gcmh_studio.scene import Scene
    from gcmh_studio.sections import SectionScene

    viewer_module.Scene = SectionScene if exact else Scene    # (the viewer's hook: see docs/sections.md)
    w = _window(app)
    try:
        ex = load_example(name)
        done = {}
        w.runFinished.connect(lambda s: done.setdefault("status", s))
        w.load_example(name, div=ex.div)
        _spin(app, 600, until=lambda: "status" in done)
        sb = w.projection_panel.slice_box
        box = _end_of_render(w)
        t_on = time.perf_counter()
        sb.slice_combo.setCurrentIndex(ex.variables.index(var))
        sb.slice_c.setValue(300)
        sb.setChecked(True)
        _spin(app, 2.0)
        if STRIP_FIRST:   # (the strip's worker shares the GIL and the cores with the steps while it runs)
            _spin(app, 300, until=lambda: sb.strip.profile is not None or sb.strip.isHidden())
        steps = []
        for k in range(STEPS):
            n0 = box["n"]
            t0 = time.perf_counter()
            sb.slice_c.setValue(300 + 20 * (k + 1))
            _spin(app, 30, until=lambda n0=n0: box["n"] > n0)
            steps.append(time.perf_counter() - t0)
            _spin(app, 0.05)
        _spin(app, 300, until=lambda: sb.strip.profile is not None or sb.strip.isHidden())
        strip_s = time.perf_counter() - t_on if sb.strip.profile is not None else float("nan")
        sc = w.viewer.scene
        text = sc.sections.text() if isinstance(sc, SectionScene) else ""
        # the parts of a step, back to back (a busy machine slows all alike: compare them): the scene's
        # slice alone (the section, or the slab's clip, into the mesh), then a render alone
        col = ex.variables.index(var)
        u = np.eye(len(ex.variables))[col]
        lo, hi = float(w.result.vertices[:, col].min()), float(w.result.vertices[:, col].max())
        cut, draw = [], []
        for k in range(8):
            t0 = time.perf_counter()
            sc.set_slice(u, lo + (0.3 + 0.05 * k) * (hi - lo), 0.02 * (hi - lo), render=False)
            cut.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            w.plotter.ren_win.Render()
            draw.append(time.perf_counter() - t0)
        return dict(name=name, var=var, vertices=w.result.count(0), kind="section" if exact else "slab",
                    median_ms=1000 * float(np.median(steps)), max_ms=1000 * float(np.max(steps)),
                    cut_ms=1000 * float(np.median(cut)), render_ms=1000 * float(np.median(draw)),
                    strip_s=strip_s, text=text, load=os.getloadavg()[0])
    finally:
        w.close()
        _spin(app, 0.2)
        viewer_module.Scene = Scene


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python tests/bench/bench_sections.py", description=__doc__.split("\n")[0])
    p.add_argument("--no-slab", action="store_true", help="skip today's slab rows")
    p.add_argument("--only", metavar="NAME", help="only this example")
    p.add_argument("--strip-first", action="store_true",
                   help="time the steps once the strip's profile is drawn (its worker shares the cores)")
    a = p.parse_args(argv)
    global STRIP_FIRST
    STRIP_FIRST = a.strip_first
    app = _app()
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.1f}; window 1200x800, {STEPS} steps of 2 % of the range")
    print(f"{'example':20} {'along':>5} {'vertices':>9} {'draws':>8} {'median ms':>10} {'max ms':>7} "
          f"{'slice ms':>9} {'render ms':>10} {'strip s':>8} {'load':>5}  picture says")
    for name, var in (c for c in CASES if a.only in (None, c[0])):
        for exact in (True, False) if not a.no_slab else (True,):
            r = slice_steps(app, name, var, exact)
            print(f"{r['name']:20} {r['var']:>5} {r['vertices']:>9,} {r['kind']:>8} {r['median_ms']:>10.0f} "
                  f"{r['max_ms']:>7.0f} {r['cut_ms']:>9.0f} {r['render_ms']:>10.0f} {r['strip_s']:>8.2f} "
                  f"{r['load']:>5.1f}  {r['text']}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
