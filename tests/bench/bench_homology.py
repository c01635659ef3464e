"""Benchmark: homology of a result against the extraction that made it, in one process.

    python tests/bench/bench_homology.py [--example complex-cosine] [--div 320] [--repeat 3]
                                         [--markdown]

Extracts the example (as `gcmh extract --example NAME --div D`), then times
`gcmh_core.homology.homology` on the result with and without generators, and its phases
alone (incidence numbers, the chain complex, the coreductions, orienting a surface), and
prints CPU seconds (process_time: the machine is shared, wall time mostly measures the
other jobs) and wall seconds, and CPU seconds per million cells.  The kernels are loaded
(compiled or read from numba's cache) on a small result first, so no time includes
compilation.  Target (issue 28): the homology adds at most half of the extraction's time,
and takes at most 1 s per million cells.  Speed is measured here, never asserted in tests.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from datetime import datetime, timezone


def _best(fn, repeat):
    """(CPU seconds, wall seconds, result): the least of `repeat` runs."""
    cpu, wall, out = float("inf"), float("inf"), None
    for _ in range(repeat):
        t, w = time.process_time(), time.perf_counter()
        out = fn()
        cpu, wall = min(cpu, time.process_time() - t), min(wall, time.perf_counter() - w)
    return cpu, wall, out


TICK_MS = 10


def gui_ticks(cx):
    """(share of ticks kept, longest gap in ms, seconds) while QtHomologyBox computes ``cx``'s homology
    (with generators, w1 and curvature) in its worker thread and a QTimer ticks on the GUI thread."""
    import numpy as np
    from qtpy.QtCore import QEventLoop, QTimer
    from qtpy.QtWidgets import QApplication

    from gcmh_studio.qt_homology_box import QtHomologyBox

    app = QApplication.instance() or QApplication([])
    box = QtHomologyBox()
    ticks = []
    timer = QTimer()
    timer.setInterval(TICK_MS)
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    loop = QEventLoop()
    box.computed.connect(loop.quit)
    timer.start()
    t0 = time.perf_counter()
    box.set_result(cx)
    loop.exec_()
    t1 = time.perf_counter()
    timer.stop()
    app.processEvents()
    pts = [t0, *[t for t in ticks if t0 <= t <= t1], t1]
    share = min(1.0, (len(pts) - 2) / max((t1 - t0) * 1000 / TICK_MS, 1))
    return share, 1000 * float(max(np.diff(pts))), t1 - t0


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--example", default="complex-cosine")
    ap.add_argument("--div", type=lambda t: [int(x) for x in t.split(",")] if "," in t else int(t), default=320,
                    help="grid divisions: one number, or one per variable (16,16,6)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--markdown", action="store_true", help="print a table row for docs/benchmarks.md")
    ap.add_argument("--ticks", action="store_true",
                    help="also: the Topology tab's box computes it while a GUI timer ticks every 10 ms "
                         "(the share of ticks kept and the longest gap, as tests/bench/bench_classroom.py)")
    args = ap.parse_args(argv)

    import numpy as np

    from gcmh_core import extract
    from gcmh_core._homology_kernels import _coreduce, _orient_top
    from gcmh_core.examples import load_example
    from gcmh_core.homology import _chain_complex, _incidences, homology

    ex = load_example(args.example)

    def run(div):
        return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic or None,
                       params=ex.param_values() or None)

    homology(run(8))   # the kernels, loaded before any timing
    c_extract, t_extract, cx = _best(lambda: run(args.div), 1)
    cells = sum(cx.counts())
    mc = cells / 1e6
    c_groups, t_groups, h = _best(lambda: homology(cx, generators=False), args.repeat)
    c_gens, t_gens, hg = _best(lambda: homology(cx, generators=True), args.repeat)
    c_inc, _, signs = _best(lambda: _incidences(cx), args.repeat)
    c_chain, _, chain = _best(lambda: _chain_complex(cx, signs), args.repeat)
    base, dims, bd_off, bd, _, cb_off, cb = chain
    c_core, _, _ = _best(lambda: _coreduce(dims, cx.dim, bd_off, bd, cb_off, cb), args.repeat)
    c_orient = float("nan")
    if cx.dim == 2:
        off, fac = cx.cells[2]
        c_orient, _, _ = _best(lambda: _orient_top(np.asarray(off), np.asarray(fac), signs[2], cx.count(1)),
                               args.repeat)
    load = os.getloadavg()[0]
    when = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    print(f"{args.example} div {args.div}: cells {cx.counts()} ({cells:,}); {h.describe()}; "
          f"critical cells {h.critical}")
    print("                      CPU s     wall s   CPU s per M cells   x extraction (CPU)")
    print(f"extraction            {c_extract:7.3f}  {t_extract:8.3f}")
    print(f"homology (groups)     {c_groups:7.3f}  {t_groups:8.3f}  {c_groups / mc:8.2f}  {c_groups / c_extract:8.3f}")
    print(f"homology (generators) {c_gens:7.3f}  {t_gens:8.3f}  {c_gens / mc:8.2f}  {c_gens / c_extract:8.3f}   "
          f"H1 generators of {[len(c) for c in hg.generators[1]] if len(hg.generators) > 1 else []} edges")
    print(f"  incidences          {c_inc:7.3f}")
    print(f"  chain complex       {c_chain:7.3f}")
    print(f"  coreductions        {c_core:7.3f}")
    print(f"  orienting (w1)      {c_orient:7.3f}")
    print(f"{when}, {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {load:.1f}")
    if args.ticks:
        share, gap, seconds = gui_ticks(cx)
        print(f"GUI while the box computes ({seconds:.2f} s): {100 * share:.0f}% of 10 ms ticks kept, "
              f"longest gap {gap:.0f} ms")
    if args.markdown:
        print(f"| {when} | {args.example} | {args.div} | {cells:,} | {c_extract:.2f} s | "
              f"{c_groups:.2f} s ({c_groups / mc:.2f} s/M, {c_groups / c_extract:.2f}x) | "
              f"{c_gens:.2f} s ({c_gens / mc:.2f} s/M, {c_gens / c_extract:.2f}x) | {c_inc:.2f} / {c_chain:.2f} / "
              f"{c_core:.2f} / {c_orient:.2f} s | {t_extract:.1f} / {t_groups:.2f} / {t_gens:.2f} s | {load:.1f} |")


if __name__ == "__main__":
    main()
