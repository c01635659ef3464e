"""Benchmark: the cube tables and whole extractions for large k (issue 14, item 2).

    python tests/bench/bench_high_k.py [--cases 6-4,8-6,9-7,10-8,10-9,11-10,12-10] [--old-max-n 9] [--no-extract]

Run from the repository root.  The cases are flat 2-tori in R^n (k = n - 2):
x1^2 + x2^2 = 1, x3^2 + x4^2 = 1, x5 = ... = xn = 0, div 10 on the first four axes
and 1 on the others (10-8 is the issue's torus in R^10, 12-10 the same in R^12), and circles
(k = n - 1: x1^2 + x2^2 = 1, x3 = ... = xn = 0, div 10 on two axes): 10-9 and 11-10.

Each measurement is a fresh child process; its peak is the resident high-water mark
above what the process held just before (VmHWM reset through /proc/self/clear_refs):
* "old": the loop builder the tables had up to issue 14 (`loop_cube_tables`, kept in
  tests/core/test_tables.py as the twin); R^10 takes minutes and about 12 GB, so it
  runs only for n <= --old-max-n (default 9);
* "new": `kernels.tables.cube_tables` (for n >= 8 and k >= 6, the faces only: the lazy kernel finds
  the Kuhn simplices it needs);
* "extract": the kernels loaded on tiny grids first (R^4, R^7 and R^8), then the tables
  (timed alone) and `extract` (its phases from meta['timings']), chi and boundary facets.

Times of large tables depend on how fresh the memory is: on this VM the first touch of
pages the host has not backed yet costs 5-10 ns a byte (R^10, k = 8: 4-6 s in a fresh
process, 0.8 s for a third build in one process).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

CASES = ["6-4", "8-6", "9-7", "10-8", "10-9", "11-10", "12-10"]


def system(n: int, k: int):
    """(formulas, bounds, div): a flat torus (k = n - 2) or circle (k = n - 1) in R^n."""
    circles = n - k  # 2: a torus, 1: a circle
    F = [f"x{2 * i + 1}^2+x{2 * i + 2}^2-1" for i in range(circles)]
    F += [f"x{i}" for i in range(2 * circles + 1, n + 1)]
    bounds = [(-1.5, 1.5)] * (2 * circles) + [(-1.0, 1.0)] * (n - 2 * circles)
    div = [10] * (2 * circles) + [1] * (n - 2 * circles)
    return F, bounds, div


def _status(key: str) -> int:
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) * 1024 for line in f if line.startswith(key))


def _reset_peak() -> int:
    """Reset the high-water mark; returns the resident bytes now."""
    try:
        import ctypes

        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")
    return _status("VmRSS:")


def child(spec: dict) -> dict:
    n, k, what = spec["n"], spec["k"], spec["what"]
    import numpy as np

    import gcmh_core
    from gcmh_core.kernels import tables as _tables

    out = dict(n=n, k=k, what=what)
    if what == "extract":  # load the compiled kernels first: their time is not the case's
        # (n = 3, k = 1 takes the marching pass: the general kernel needs a case of its own;
        # R^7 the candidate pass without corner masks, R^8 the lazy kernel)
        gcmh_core.extract(["x1^2+x2^2+x3^2+x4^2-1", "x4-0.1"], bounds=(-1.5, 1.5), div=3)
        for m in (7, 8):
            F, bounds, div = system(m, m - 2)
            gcmh_core.extract(F, bounds=bounds, div=[2] * m, n=m)
        _tables.cube_tables.cache_clear()
        _tables.simplex_tables.cache_clear()
    if what == "old":
        sys.path.insert(0, os.path.join(ROOT, "tests", "core"))
        from test_tables import loop_cube_tables as build
    else:
        build = _tables.cube_tables
    base = _reset_peak()
    t = time.perf_counter()
    tables = build(n, k)
    out["tables_s"] = time.perf_counter() - t
    out["tables_mb"] = (_status("VmHWM:") - base) / 1e6
    out["arrays_mb"] = sum(a.nbytes for a in tables if isinstance(a, np.ndarray)) / 1e6
    if what == "extract":
        F, bounds, div = system(n, k)
        t = time.perf_counter()
        cx = gcmh_core.extract(F, bounds=bounds, div=div, n=n)
        out["extract_s"] = time.perf_counter() - t
        out["peak_mb"] = (_status("VmHWM:") - base) / 1e6
        out["phases"] = {key: round(v, 3) for key, v in cx.meta["timings"].items()}
        out["candidates"] = cx.meta["candidate_cubes"]
        out["chi"] = cx.euler_characteristic()
        out["boundary_facets"] = len(cx.boundary_facets())
        out["counts"] = cx.counts()
    return out


def run_child(spec: dict) -> dict:
    proc = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", json.dumps(spec)],
                          capture_output=True, text=True, cwd=ROOT)
    if proc.returncode != 0:
        return dict(spec, error=(proc.stderr.strip().splitlines() or ["?"])[-1])
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--old-max-n", type=int, default=9, help="run the loop builder up to this n")
    ap.add_argument("--no-extract", action="store_true", help="tables only")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(json.loads(args.child))))
        return 0
    print(f"{'case':>6} {'old tables':>20} {'new tables':>20} {'speed-up':>9} {'memory':>7}  extraction")
    for case in args.cases.split(","):
        n, k = map(int, case.split("-"))
        old = run_child(dict(n=n, k=k, what="old")) if n <= args.old_max_n else None
        new = run_child(dict(n=n, k=k, what="new"))
        cells = ["-" * 20, "", "", ""]
        if old and "error" not in old:
            cells[0] = f"{old['tables_s']:8.2f} s {old['tables_mb']:7.0f} MB"
        if "error" not in new:
            cells[1] = f"{new['tables_s']:8.2f} s {new['tables_mb']:7.0f} MB"
            if old and "error" not in old:
                cells[2] = f"{old['tables_s'] / new['tables_s']:8.0f}x"
                cells[3] = f"{old['tables_mb'] / max(new['tables_mb'], 1):6.1f}x"
        else:
            cells[1] = new["error"][:20]
        line = f"{case:>6} {cells[0]:>20} {cells[1]:>20} {cells[2]:>9} {cells[3]:>7}"
        if not args.no_extract:
            ex = run_child(dict(n=n, k=k, what="extract"))
            if "error" in ex:
                line += f"  {ex['error']}"
            else:
                ph = ex["phases"]
                line += (f"  {ex['tables_s'] + ex['extract_s']:.1f} s (tables {ex['tables_s']:.1f}, "
                         f"candidates {ph.get('candidates', 0):.1f}, kernel {ph.get('kernel', 0):.1f}), "
                         f"peak {ex['peak_mb']:.0f} MB, {ex['candidates']} cubes, chi {ex['chi']}, "
                         f"{ex['boundary_facets']} boundary facets")
        print(line, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
