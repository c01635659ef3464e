"""Benchmark of one parameter step in the window (issue 17): a slider moved, the manifold re-extracted and drawn.

    xvfb-run -a .venv/bin/python tests/bench/bench_params.py            # Klein bottle and hyperboloid (~2 min)
    xvfb-run -a .venv/bin/python tests/bench/bench_params.py --steps 5  # fewer steps per case

(run from the repository root; not collected by pytest: no ``test_`` prefix)

A step is timed as the user waits: from the slider's value changing to the end of the render that
shows the new result (a VTK EndEvent after the window's ``resultChanged``). "coarse" steps are made
with the slider held (the window's coarse grid, aimed at 100 ms a step; the first steps of a system
tune it, so the median of the last steps is given); "full" steps let the slider go (the full grid).
The peer in the same run is ``gcmh_core.extract`` alone at the same grid and value, without the
window: "overhead" is the step over it (the worker's hand-offs, the drawing arrays, the topology
report and the render). Cases: the Klein bottle at its default div with its bagel radius as a
parameter R (the 3 of its formulas), and the hyperboloid x^2 + y^2 - z^2 = a at div 64; GCMH (the
whole grid) and GCCH (continuation from the previous result).
Targets (issue 17, a quiet 2-core machine under Xvfb): coarse <= 100 ms, full <= 1 s.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.append(str(Path(__file__).resolve().parents[1] / "app"))


def _app():
    d = os.path.join("/tmp", f"runtime-{os.getuid()}")
    os.makedirs(d, mode=0o700, exist_ok=True)
    os.environ.setdefault("XDG_RUNTIME_DIR", d)
    from qtpy.QtWidgets import QApplication

    return QApplication.instance() or QApplication([])


def _spin(app, seconds: float, until=None) -> bool:
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        app.processEvents()
        if until is not None and until():
            return True
        time.sleep(0.001)
    return until is None


def _klein_state():
    from gcmh_core.examples import load_example

    ex = load_example("klein-bottle")
    formulas = [f.replace("(3 +", "(R +") for f in ex.formulas]
    assert all("R +" in f for f in formulas[:2])
    return dict(n=ex.n, k=ex.k, variables=list(ex.variables), formulas=formulas, bounds=[list(b) for b in ex.bounds],
                div=ex.div, start=list(ex.start), params={"R": {"value": 3.0, "min": 2.0, "max": 4.0}}), \
        "R", ex.view


def _hyperboloid_state():
    from gcmh_core.examples import load_example

    ex = load_example("hyperboloid")
    return dict(n=ex.n, k=ex.k, variables=list(ex.variables), formulas=list(ex.formulas),
                bounds=[list(b) for b in ex.bounds], div=64, start=list(ex.start),
                params={"a": {"value": 0.5, "min": -1.0, "max": 1.0}}), "a", ex.view


def _peer_ms(job, repeats: int = 3) -> float:
    """gcmh_core.extract alone on the step's job (median ms), the window's run_job without the window."""
    from gcmh_studio.jobs import run_job

    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run_job(job)
        ts.append(time.perf_counter() - t0)
    return 1000 * float(np.median(ts))


def bench_case(app, label: str, state: dict, name: str, view: dict, method: str, steps: int,
               args_verbose: bool = False) -> list[dict]:
    from gcmh_studio.qt_main_window import QtMainWindow

    w = QtMainWindow(example=None, warm_up=False)
    w.resize(1200, 800)
    w.show()
    _spin(app, 0.3)
    rows = []
    try:
        fp = w.formula_panel
        fp.set_state(dict(state, method=method))
        w.model.expect(label, fp.formulas(), fp.variables(), view=view)
        _spin(app, 30, until=lambda: not fp.checking())
        done = {"n": 0}
        w.runFinished.connect(lambda how: done.__setitem__("n", done["n"] + 1))
        w.run()
        _spin(app, 300, until=lambda: done["n"] > 0 and not w.is_running())
        renders = {"n": 0}
        w.plotter.ren_win.AddObserver("EndEvent", lambda *a: renders.__setitem__("n", renders["n"] + 1))
        shown = {"n": 0, "renders": 0}   # results shown, and the renders done when the last one was

        def on_shown(cx):
            shown["n"] += 1
            shown["renders"] = renders["n"]

        w.resultChanged.connect(on_shown)
        row = fp.parameters.rows[name]
        lo, hi = row.state["min"], row.state["max"]
        # (never the value on show: the slider would not move)
        values = [v for v in np.linspace(lo + 0.55 * (hi - lo), lo + 0.95 * (hi - lo), steps + 3)
                  if abs(v - row.state["value"]) > 0.02 * (hi - lo)]

        def step(value: float, release: bool) -> tuple[float, object]:
            """One step to ``value`` (slider held; ``release``: then let go): ms to the frame that shows it."""
            pos = int(round((value - lo) / (hi - lo) * 200))
            s0 = shown["n"]
            t0 = time.perf_counter()
            if release:
                row.slider.setSliderDown(False)
            else:
                row.slider.setSliderDown(True)
                row.slider.setValue(pos)
            target = row.state["value"]

            def drawn():
                cx = w.result
                if shown["n"] <= s0 or cx is None or w.is_running():
                    return False
                if cx.meta.get("params", {}).get(name) != target:
                    return False
                if release and w.model.job.step != "full":
                    return False
                return renders["n"] > shown["renders"]

            ok = _spin(app, 60, until=drawn)
            if args_verbose:
                print(f"  {label} {method} {'full' if release else 'coarse'} {target:.4g}: "
                      f"{1000 * (time.perf_counter() - t0):.0f} ms{'' if ok else ' (timed out)'}", file=sys.stderr)
            return (1000 * (time.perf_counter() - t0) if ok else float("nan")), w.model.job

        coarse, full = [], []
        for i, v in enumerate(values):
            ms, job = step(v, release=False)
            if i >= 3:   # (the first steps aim the coarse grid)
                coarse.append((ms, job))
        for v in values[:max(3, steps // 2)]:
            step(v, release=False)
            full.append(step(v, release=True))
        for kind, got in (("coarse", coarse), ("full", full)):
            ms = [m for m, _ in got]
            job = got[-1][1]
            job.step = None
            peer = _peer_ms(job)
            div = job.div if isinstance(job.div, int) else "x".join(map(str, job.div))
            rows.append(dict(case=label, method=method, kind=kind, grid=div, step_ms=float(np.median(ms)),
                             worst_ms=float(np.max(ms)), peer_ms=peer, vertices=w.result.count(0) if kind == "full"
                             else None))
    finally:
        w.close()
        _spin(app, 0.2)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=10, help="coarse steps per case (full steps: half as many)")
    ap.add_argument("--only", choices=("klein", "hyperboloid"), help="one case")
    ap.add_argument("-v", "--verbose", action="store_true", help="each step's time on stderr")
    args = ap.parse_args()
    app = _app()
    from gcmh_studio.jobs import warm_up_kernels

    warm_up_kernels(("gcmh", "gcch"))
    rows = []
    cases = [("klein", "Klein bottle (R)", _klein_state), ("hyperboloid", "hyperboloid (a)", _hyperboloid_state)]
    for key, label, make in cases:
        if args.only in (None, key):
            state, name, view = make()
            for method in ("gcmh", "gcch"):
                rows += bench_case(app, label, state, name, view, method, args.steps, args.verbose)
    print(f"\none parameter step, slider change -> rendered frame (median of {args.steps} coarse, "
          f"{max(3, args.steps // 2)} full; machine load {os.getloadavg()[0]:.2f})")
    head = f"{'case':<18} {'method':<6} {'step':<6} {'grid':<16} {'step ms':>8} {'worst':>7} " \
           f"{'extract ms':>10} {'overhead':>9}  target"
    print(head)
    print("-" * len(head))
    for r in rows:
        target = 100 if r["kind"] == "coarse" else 1000
        ok = "ok" if r["step_ms"] <= target else "over"
        print(f"{r['case']:<18} {r['method']:<6} {r['kind']:<6} {str(r['grid']):<16} {r['step_ms']:>8.0f} "
              f"{r['worst_ms']:>7.0f} {r['peer_ms']:>10.0f} {r['step_ms'] / r['peer_ms']:>8.1f}x  "
              f"<= {target} ms {ok}")


if __name__ == "__main__":
    main()
