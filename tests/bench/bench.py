"""Benchmarks: the paper's experiments rerun on this machine, side by side with its figures.

    python tests/bench/bench.py [--tables table1,table2,table3,sphere,engine]
                                [--limit SECONDS] [--repeat N] [--max-div D]

Run from the repository root with the project installed (`pip install -e .`); the
sphere table also wants scikit-image and pyvista (the `test` extra).

* table1: complex cosine, div 5 .. 320, CMS, GCMH, CCS, GCCH (paper Table 1);
* table2: top cells of CCS and GCCH (paper Table 2; needs table1's runs);
* table3: three-torus in R^6, GCMH and GCCH, div 2 .. 7 and beyond (paper Table 3);
* sphere: n = 3, k = 1 at div 64, 128, 256 against scikit-image's marching_cubes and
  VTK's flying edges (pyvista) on the same function and grid, sampling included;
* engine: the Klein bottle at the authors' division, the kernels' time per cube, and a
  fresh process's overhead.

Every run is a fresh child process (so its peak memory is its own) that first loads
the cached kernels on a tiny grid, then reports the best of `--repeat` runs (one run
when a run takes more than a third of `--limit`).  A series (one method of one table)
stops once a run passes `--limit` seconds, or before a run predicted (from the last one,
time ~ div^n for a sweep, div^(n-k) for continuation) to take more than 3 x `--limit`:
larger divisions are marked "skipped" with the reason.
Speed is measured here, never asserted in tests; on a shared machine compare peers of
the same run (the ratios), not absolute times.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import time
from datetime import date

from gcmh_core.extract import CONTINUATION_METHODS

PAPER_MACHINE = "MATLAB 2021b, 8-core i9"

# paper Table 1 (seconds), Table 2 (top cells), Table 3 (seconds)
PAPER_T1 = {
    "cms": {5: 3.83, 10: 55.54, 20: 2048.63, 40: 12362.45},
    "gcmh": {5: 2.16, 10: 34.20, 20: 589.38, 40: 7927.68},
    "ccs": {5: 0.69, 10: 2.25, 20: 8.34, 40: 38.30, 80: 236.79, 160: 2837.64, 320: 41355.25},
    "gcch": {5: 0.54, 10: 1.54, 20: 5.54, 40: 22.35, 80: 87.22, 160: 396.12, 320: 1912.98},
}
PAPER_T2 = {"ccs": {5: 1162, 10: 4378, 20: 17258, 40: 68354}, "gcch": {5: 148, 10: 612, 20: 2112, 40: 8336}}
AUTHORS_CODE_T2 = {5: 97, 10: 397, 20: 1573}  # the authors' published MATLAB code, run under Octave
PAPER_T3 = {
    "gcmh": {2: 93.61, 3: 1055.67, 4: 5910.59, 5: 22686.60, 6: 67749.18, 7: 172271.80},
    "gcch": {2: 93.07, 3: 734.47, 4: 846.46, 5: 2946.30, 6: 7126.96, 7: 13545.33},
}

TABLE1_DIVS = [5, 10, 20, 40, 80, 160, 320]
TABLE3_DIVS = [2, 3, 4, 5, 6, 7, 8, 10, 12, 16, 20]
SPHERE_DIVS = [64, 128, 256]
SPHERE_DIVS_SMALL = [16, 32]  # with --max-div below 64 (a quick check of the script)
TABLES = ("table1", "table2", "table3", "sphere", "engine")


# ----------------------------------------------------------------------------- one run (child process)
def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


HERE = os.path.dirname(os.path.abspath(__file__))

# A fresh-process case starts here instead of this script, so that the time of
# `import gcmh_core` (numpy, numba, sympy, the cached kernels' index) is measured
# before anything else is imported.  argv: the spec, then this script's folder.
_FRESH = (
    "import time; t = time.perf_counter(); import gcmh_core; s = time.perf_counter() - t; "
    "import json, sys; sys.path.insert(0, sys.argv[2]); import bench; "
    "print(json.dumps(bench._child(json.loads(sys.argv[1]), import_seconds=s)))"
)


def _child(spec: dict, import_seconds: float = 0.0) -> dict:
    from gcmh_core import extract
    from gcmh_core.examples import load_example

    import_s = import_seconds
    ex = load_example(spec["example"])
    method = spec.get("method", "gcmh")
    start = ex.start if method in CONTINUATION_METHODS else None
    div = spec["div"]

    def run(d):
        return extract(ex.formulas, ex.bounds, d, variables=ex.variables, method=method, start=start)

    out = dict(spec)
    if spec.get("fresh"):
        t = time.perf_counter()
        run(div)
        first = time.perf_counter() - t
        t = time.perf_counter()
        cx = run(div)
        second = time.perf_counter() - t
        out.update(seconds=second, first_seconds=first, import_seconds=import_s,
                   overhead_seconds=import_s + first - second)
    elif spec.get("peers"):
        run(3 if isinstance(div, int) else [3] * len(div))
        cx = run(div)
        out.update(peak_mb=peak_mb())  # (GCMH's own, before the peers run)
        out.update(_sphere_peers(ex, div, spec.get("repeat", 1), run))
    else:
        run(3 if isinstance(div, int) else [3] * len(div))  # loads the cached kernels, starts the threads
        best, cx = None, None
        for _ in range(spec.get("repeat", 1)):
            t = time.perf_counter()
            cx = run(div)
            dt = time.perf_counter() - t
            best = dt if best is None else min(best, dt)
            if dt > spec.get("limit", 60) / 3:
                break
        out.update(seconds=best)
    out.update(kernel_seconds=cx.meta["timings"]["kernel"], kernel_cubes=cx.meta.get("candidate_cubes", 0))
    out.update(counts=cx.counts(), euler=cx.euler_characteristic(), boundary=int(len(cx.boundary_facets())),
               visited=cx.meta.get("visited_cubes", cx.meta.get("candidate_cubes")))
    out.setdefault("peak_mb", peak_mb())
    return out


def _sphere_peers(ex, div, repeat, run) -> dict:
    """GCMH (the marching pass for n = 3), its general path (as before that pass: pruned
    sweep, kernel per cube, global assembly), scikit-image's marching_cubes and VTK's
    flying edges on the same function and grid, each from F's formula to its mesh
    (sampling included).  The four take turns, round after round (a shared machine's
    load then falls on all of them alike); small grids get more rounds: repeat x 256 / div.
    Returns each one's best and median seconds."""
    import numpy as np

    from gcmh_core import sweep
    from gcmh_core.formula import parse_system

    system = parse_system(ex.formulas, ex.variables)
    axes = [np.linspace(lo, hi, div + 1) for lo, hi in ex.bounds]
    out = {}

    def general():
        sweep.MARCHING3 = False
        try:
            return run(div)
        finally:
            sweep.MARCHING3 = None

    cases = {"seconds": lambda: run(div), "general_seconds": general}
    try:
        from skimage.measure import marching_cubes

        cases["skimage_seconds"] = lambda: marching_cubes(system.evaluate_grid(axes)[..., 0], 0.0)[1]
    except ImportError:
        out.update(skimage_seconds=None)
    try:
        import pyvista as pv
        import vtk

        def flying_edges():
            # F's C-order samples as they are: VTK's x is the array's last axis, so the
            # axes are given reversed (an order="F" copy would charge VTK for a transpose)
            volume = system.evaluate_grid(axes)[..., 0]
            image = pv.ImageData(dimensions=volume.shape[::-1], spacing=[(hi - lo) / div for lo, hi in ex.bounds][::-1],
                                 origin=[lo for lo, _ in ex.bounds][::-1])
            image.point_data["F"] = volume.reshape(-1)
            return image.contour([0.0], scalars="F", method="flying_edges")

        cases["vtk_seconds"] = flying_edges
        out.update(vtk_smp=f"{vtk.vtkSMPTools.GetBackend()}, {vtk.vtkSMPTools.GetEstimatedNumberOfThreads()} thread(s)")
    except ImportError:
        out.update(vtk_seconds=None)
    times: dict[str, list[float]] = {key: [] for key in cases}
    results = {key: fn() for key, fn in cases.items()}  # (warm)
    for _ in range(repeat * max(1, 256 // div)):
        for key, fn in cases.items():
            t = time.perf_counter()
            fn()
            times[key].append(time.perf_counter() - t)
    for key, seconds in times.items():
        out[key] = min(seconds)
        out[key.replace("seconds", "median")] = float(np.median(seconds))
    if "skimage_seconds" in results:
        out.update(skimage_triangles=len(results["skimage_seconds"]))
    if "vtk_seconds" in results:
        out.update(vtk_triangles=int(results["vtk_seconds"].n_cells))
    out.update(rounds=len(times["seconds"]))
    return out


# ----------------------------------------------------------------------------- the series (parent)
class Runner:
    def __init__(self, limit: float, repeat: int, max_div: int | None):
        self.limit, self.repeat, self.max_div = limit, repeat, max_div
        self.results: dict[tuple, dict] = {}

    def run(self, key: tuple, spec: dict) -> dict:
        spec = dict(spec, repeat=self.repeat, limit=self.limit)
        # a hard stop far beyond the series limit, so one runaway run can't hold the benchmark
        timeout = max(120.0, 20 * self.limit)
        try:
            if spec.get("fresh"):
                cmd = ["-c", _FRESH, json.dumps(spec), HERE]
            else:
                cmd = [os.path.join(HERE, "bench.py"), "--child", json.dumps(spec)]
            proc = subprocess.run([sys.executable, *cmd], capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            res = dict(spec, error=f"killed after {timeout:.0f} s", seconds=float("inf"))
        else:
            if proc.returncode != 0:
                lines = proc.stderr.strip().splitlines()
                res = dict(spec, error=lines[-1] if lines else f"exit {proc.returncode}", seconds=float("inf"))
            else:
                res = json.loads(proc.stdout.strip().splitlines()[-1])
        self.results[key] = res
        return res

    def series(self, table: str, example: str, method: str, divs, growth: float, **extra) -> None:
        """Runs div by div; stops after a run over the limit, or before one predicted to take
        more than 3 x the limit (time ~ div^growth: n for a full sweep, n - k for continuation)."""
        why, last = None, None
        for div in divs:
            if self.max_div is not None and div > self.max_div:
                continue
            if why is None and last is not None:
                predicted = last[1] * (div / last[0]) ** growth
                if predicted > 3 * self.limit:
                    why = f"predicted {predicted:.0f} s"
            if why is not None:
                self.results[(table, method, div)] = dict(skipped=why)
                continue
            res = self.run((table, method, div), dict(example=example, method=method, div=div, **extra))
            print(f"  {table} {method} div {div}: {_secs(res)}", file=sys.stderr, flush=True)
            last = (div, res.get("seconds", float("inf")))
            if last[1] > self.limit:
                why = f"div {div} took > {self.limit:g} s"


def _secs(r: dict | None) -> str:
    if r is None:
        return "-"
    if "skipped" in r:
        return "skipped"
    if "error" in r:
        return f"failed ({r['error']})"
    s = r["seconds"]
    return f"{s:.3f} s" if s < 1 else f"{s:.2f} s"


def _paper(x) -> str:
    return "-" if x is None else (f"{x:,.2f} s" if isinstance(x, float) else f"{x:,}")


def _cells(r: dict | None) -> str:
    return "/".join(str(c) for c in r["counts"]) if r and "counts" in r else "-"


def _ratio(a: dict | None, b: dict | None) -> str:
    if not a or not b or "seconds" not in a or "seconds" not in b or not b["seconds"] or a["seconds"] == float("inf"):
        return "-"
    return f"{a['seconds'] / b['seconds']:.1f}"


def _mem(r):
    return f"{r['peak_mb']:.0f} MB" if r and "peak_mb" in r else "-"


def _paper_ratio(a: str, b: str, div: int) -> str:
    return f"{PAPER_T1[a][div] / PAPER_T1[b][div]:.1f}" if div in PAPER_T1[a] and div in PAPER_T1[b] else "-"


def print_table1(R: Runner) -> None:
    print("### Table 1: complex cosine z = cos(w), F: R^4 -> R^2, time per method\n")
    print("| div | method | time | paper | peak memory | cells by dim (0/1/2) | Euler | boundary facets |")
    print("|---|---|---|---|---|---|---|---|")
    for div in TABLE1_DIVS:
        for m in ("cms", "gcmh", "ccs", "gcch"):
            r = R.results.get(("table1", m, div))
            if r is None:
                continue
            print(f"| {div} | {m.upper()} | {_secs(r)} | {_paper(PAPER_T1[m].get(div))} | {_mem(r)} | {_cells(r)} "
                  f"| {r.get('euler', '-')} | {r.get('boundary', '-')} |")
    print("\nRatios of times (larger favours the hypercube methods), this run and the paper's:\n")
    print("| div | CMS / GCMH | paper | CCS / GCCH | paper |")
    print("|---|---|---|---|---|")
    for div in TABLE1_DIVS:
        g = {m: R.results.get(("table1", m, div)) for m in ("cms", "gcmh", "ccs", "gcch")}
        if any(g.values()):
            print(f"| {div} | {_ratio(g['cms'], g['gcmh'])} | {_paper_ratio('cms', 'gcmh', div)} "
                  f"| {_ratio(g['ccs'], g['gcch'])} | {_paper_ratio('ccs', 'gcch', div)} |")
    print()


def print_table2(R: Runner) -> None:
    print("### Table 2: output size (top cells, the 2-cells) of the complex cosine\n")
    print("| div | CCS | paper CCS | GCCH | paper GCCH | authors' code (GCMH) |")
    print("|---|---|---|---|---|---|")
    for div in TABLE1_DIVS:
        c, g = R.results.get(("table1", "ccs", div)), R.results.get(("table1", "gcch", div))
        if not (c and "counts" in c) and not (g and "counts" in g):
            continue
        top = lambda r: f"{r['counts'][-1]:,}" if r and "counts" in r else "-"  # noqa: E731
        print(f"| {div} | {top(c)} | {_paper(PAPER_T2['ccs'].get(div))} | {top(g)} "
              f"| {_paper(PAPER_T2['gcch'].get(div))} | {_paper(AUTHORS_CODE_T2.get(div))} |")
    print()


def print_table3(R: Runner) -> None:
    print("### Table 3: three-torus S^1 x S^1 x S^1 in R^6 (F: R^6 -> R^3)\n")
    print("| div | method | time | paper | peak memory | cells by dim (0/1/2/3) | Euler | boundary facets |")
    print("|---|---|---|---|---|---|---|---|")
    for div in TABLE3_DIVS:
        for m in ("gcmh", "gcch"):
            r = R.results.get(("table3", m, div))
            if r is None:
                continue
            print(f"| {div} | {m.upper()} | {_secs(r)} | {_paper(PAPER_T3[m].get(div))} | {_mem(r)} | {_cells(r)} "
                  f"| {r.get('euler', '-')} | {r.get('boundary', '-')} |")
    print()


def print_sphere(R: Runner) -> None:
    print("### n = 3, k = 1: the unit sphere against scikit-image and VTK (sampling included)\n")
    print("GCMH: the marching pass for n = 3 (the default); general: the path every other n and k "
          "takes (pruned sweep, kernel per cube, assembly), the same complex.\n")
    print("| div | GCMH | GCMH general path | skimage marching_cubes | VTK flying edges | GCMH / skimage "
          "| GCMH / VTK | general / VTK | GCMH / VTK, medians | GCMH peak memory | cells by dim | Euler |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    smp = None
    for div in SPHERE_DIVS_SMALL + SPHERE_DIVS:
        r = R.results.get(("sphere", "gcmh", div))
        if r is None or "seconds" not in r:
            continue
        sk, vt, gen = r.get("skimage_seconds"), r.get("vtk_seconds"), r.get("general_seconds")
        smp = r.get("vtk_smp", smp)
        med, vmed = r.get("median"), r.get("vtk_median")  # (GCMH's and VTK's median seconds)
        f = lambda x: "-" if x is None else f"{x:.3f} s"  # noqa: E731
        q = lambda x, s=r["seconds"]: "-" if not x else f"{s / x:.2f}"  # noqa: E731
        print(f"| {div} | {_secs(r)} | {f(gen)} | {f(sk)} ({r.get('skimage_triangles', 0):,} triangles) "
              f"| {f(vt)} ({r.get('vtk_triangles', 0):,} triangles) | {q(sk)} | {q(vt)} "
              f"| {'-' if not (gen and vt) else f'{gen / vt:.2f}'} "
              f"| {'-' if not (med and vmed) else f'{med / vmed:.2f}'} "
              f"| {_mem(r)} | {_cells(r)} | {r.get('euler', '-')} |")
    if smp:
        print(f"\nTimes: the best of the rounds (GCMH, general, skimage and VTK take turns; repeat x 256 / div "
              f"rounds); medians in the JSON.  VTK's SMP backend: {smp}.")
    print()


def print_engine(R: Runner) -> None:
    print("### Other engine cases\n")
    print("| case | time | peak memory | cells by dim | Euler | target |")
    print("|---|---|---|---|---|---|")
    for m in ("gcmh", "gcch"):
        r = R.results.get(("engine", f"klein-{m}", 0))
        if r:
            print(f"| Klein bottle, authors' div 40x40x20x40x40, {m.upper()} | {_secs(r)} | {_mem(r)} | {_cells(r)} "
                  f"| {r.get('euler', '-')} | {'GCCH <= 3 s' if m == 'gcch' else '-'} |")
    for m in ("gcmh", "cms"):  # the per-cube work, where the two methods differ
        r = R.results.get(("engine", f"kernel-{m}", 0))
        if r and r.get("kernel_cubes"):
            us = 1e6 * r["kernel_seconds"] / r["kernel_cubes"]
            print(f"| {m.upper()} kernel alone, complex cosine div 80: {us:.2f} us per candidate cube "
                  f"({r['kernel_cubes']:,} cubes, {numba_threads()} threads, wall) | {_secs(r)} | {_mem(r)} "
                  f"| {_cells(r)} | {r.get('euler', '-')} | - |")
    r = R.results.get(("engine", "fresh", 0))
    if r and "overhead_seconds" in r:
        print(f"| fresh process: import {r['import_seconds']:.2f} s + first run {r['first_seconds']:.2f} s vs "
              f"{r['seconds']:.3f} s warm (complex cosine div 10) | overhead {r['overhead_seconds']:.2f} s | {_mem(r)} "
              f"| {_cells(r)} | {r.get('euler', '-')} | overhead <= 3 s |")
    print()


def numba_threads() -> int:
    import numba

    return numba.get_num_threads()


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return f"{cpu}, {cores} cores, Python {platform.python_version()}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python tests/bench/bench.py", description=__doc__.splitlines()[0])
    parser.add_argument("--tables", default=",".join(TABLES), help="comma-separated: " + ", ".join(TABLES))
    parser.add_argument("--limit", type=float, default=30.0,
                        help="a series stops after a run that takes longer than this many seconds (default 30)")
    parser.add_argument("--repeat", type=int, default=2, help="runs per case; the best is reported (default 2)")
    parser.add_argument("--max-div", type=int, default=None, help="skip divisions above this")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(_child(json.loads(args.child))))
        return 0
    tables = [t.strip() for t in args.tables.split(",") if t.strip()]
    unknown = [t for t in tables if t not in TABLES]
    if unknown:
        parser.error(f"unknown table(s) {', '.join(unknown)}; choose from {', '.join(TABLES)}")
    if args.limit <= 0 or args.repeat < 1:
        parser.error("--limit must be positive and --repeat at least 1")
    R = Runner(args.limit, args.repeat, args.max_div)
    t0 = time.perf_counter()
    if "table1" in tables or "table2" in tables:
        for m in ("cms", "gcmh", "ccs", "gcch"):
            R.series("table1", "complex-cosine", m, TABLE1_DIVS, growth=2 if m in CONTINUATION_METHODS else 4)
    if "table3" in tables:
        for m in ("gcmh", "gcch"):
            R.series("table3", "three-torus", m, TABLE3_DIVS, growth=3 if m == "gcch" else 6)
    if "sphere" in tables:
        small = R.max_div is not None and R.max_div < SPHERE_DIVS[0]
        R.series("sphere", "sphere", "gcmh", SPHERE_DIVS_SMALL if small else SPHERE_DIVS, growth=3, peers=True)
    if "engine" in tables:
        for m in ("gcmh", "gcch"):
            R.run(("engine", f"klein-{m}", 0), dict(example="klein-bottle", method=m, div=[40, 40, 20, 40, 40]))
        for m in ("gcmh", "cms"):
            R.run(("engine", f"kernel-{m}", 0), dict(example="complex-cosine", method=m, div=80))
        R.run(("engine", "fresh", 0), dict(example="complex-cosine", method="gcmh", div=10, fresh=True))
    print(f"Measured {date.today().isoformat()} on {machine()} (paper: {PAPER_MACHINE}); "
          f"best of {args.repeat} warm runs, each in a fresh process (peak = its max RSS, Python and numba included); "
          f"a series stops after a run over {args.limit:g} s or before one predicted over {3 * args.limit:g} s. "
          f"Total {time.perf_counter() - t0:.0f} s.\n")
    if "table1" in tables:
        print_table1(R)
    if "table1" in tables or "table2" in tables:
        print_table2(R)
    if "table3" in tables:
        print_table3(R)
    if "sphere" in tables:
        print_sphere(R)
    if "engine" in tables:
        print_engine(R)
    return 0


if __name__ == "__main__":
    sys.exit(main())
