"""Benchmark: homology of a result against the extraction that made it, in one process.

    python tests/bench/bench_homology.py [--example complex-cosine] [--div 320] [--repeat 3]
                                         [--markdown]

Extracts the example (as `gcmh extract --example NAME --div D`), then times
`gcmh_core.homology.homology` on the result with and without generators, the
incidence numbers and the coreductions alone, and prints the cells per second.  The
kernels are loaded (compiled or read from numba's cache) on a small result first, so
neither time includes compilation.  Target (issue 28): the homology adds at most half of
the extraction's time, and takes at most 1 s per million cells.  Speed is measured
here, never asserted in tests.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from datetime import datetime, timezone


def _best(fn, repeat):
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


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
    ap.add_argument("--div", type=int, default=320)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--markdown", action="store_true", help="print a table row for docs/benchmarks.md")
    ap.add_argument("--ticks", action="store_true",
                    help="also: the Topology tab's box computes it while a GUI timer ticks every 10 ms "
                         "(the share of ticks kept and the longest gap, as tests/bench/bench_classroom.py)")
    args = ap.parse_args(argv)

    from gcmh_core import extract
    from gcmh_core._homology_kernels import _coreduce
    from gcmh_core.examples import load_example
    from gcmh_core.homology import _chain_complex, _incidences, homology

    ex = load_example(args.example)

    def run(div):
        return extract(ex.formulas, ex.bounds, div, variables=ex.variables, periodic=ex.periodic or None,
                       params=ex.param_values() or None)

    homology(run(8))   # the kernels, loaded before any timing
    t_extract, cx = _best(lambda: run(args.div), 1)
    cells = sum(cx.counts())
    t_groups, h = _best(lambda: homology(cx, generators=False), args.repeat)
    t_gens, hg = _best(lambda: homology(cx, generators=True), args.repeat)
    t_inc, signs = _best(lambda: _incidences(cx), args.repeat)
    chain = _chain_complex(cx, signs)
    base, dims, bd_off, bd, _, cb_off, cb = chain
    t_core, _ = _best(lambda: _coreduce(dims, cx.dim, bd_off, bd, cb_off, cb), args.repeat)
    load = os.getloadavg()[0]
    when = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    print(f"{args.example} div {args.div}: cells {cx.counts()} ({cells:,}); {h.describe()}; "
          f"critical cells {h.critical}")
    print(f"extraction            {t_extract:8.3f} s")
    print(f"homology (groups)     {t_groups:8.3f} s  = {t_groups / t_extract:.2f} x extraction, "
          f"{cells / t_groups / 1e6:.2f} M cells/s")
    print(f"homology (generators) {t_gens:8.3f} s  = {t_gens / t_extract:.2f} x extraction, "
          f"{cells / t_gens / 1e6:.2f} M cells/s; H1 generators of {[len(c) for c in hg.generators[1]]} edges")
    print(f"  incidences          {t_inc:8.3f} s")
    print(f"  coreductions        {t_core:8.3f} s")
    print(f"{when}, {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {load:.1f}")
    if args.ticks:
        share, gap, seconds = gui_ticks(cx)
        print(f"GUI while the box computes ({seconds:.2f} s): {100 * share:.0f}% of 10 ms ticks kept, "
              f"longest gap {gap:.0f} ms")
    if args.markdown:
        print(f"| {when} | {args.example} | {args.div} | {cells:,} | {t_extract:.2f} s | {t_groups:.2f} s "
              f"({t_groups / t_extract:.2f}x) | {t_gens:.2f} s ({t_gens / t_extract:.2f}x) | "
              f"{cells / t_groups / 1e6:.2f} M | {t_inc:.2f} s | {t_core:.2f} s | {load:.1f} |")


if __name__ == "__main__":
    main()
