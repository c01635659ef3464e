"""Benchmarks of the engine: `python -m gcmh_core.bench [--cases a,b] [--repeat N]`.

Each case runs in a fresh child process (so peak memory is the case's own), after a
warm-up extraction in that process (kernels loaded from the on-disk cache).  Times
include evaluating F.  The output is a Markdown table for the README; speed is
measured here, never asserted in tests.  Peers run in the same child, so ratios are
meaningful on a shared, noisy machine.
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

PAPER = "paper (MATLAB, 8-core i9)"

CASES = {
    # name: (example, div, target text, paper figure)
    "cosine-40": ("complex-cosine", 40, "<= 2 s", "7,928 s"),
    "three-torus-7": ("three-torus", 7, "<= 5 s", "172,272 s"),
    "klein-paper": ("klein-bottle", [40, 40, 20, 40, 40], "<= 30 s", "-"),
    "sphere-256": ("sphere", 256, "<= 1.5 x skimage", "-"),
    "cosine-160-memory": ("complex-cosine", 160, "peak <= 2 GB", "-"),
    "fresh-process": ("complex-cosine", 10, "overhead <= 3 s", "-"),
}


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _child(case: str, repeat: int) -> dict:
    t_import = time.perf_counter()
    from gcmh_core import extract  # noqa: PLC0415
    from gcmh_core.examples import load_example  # noqa: PLC0415

    import_s = time.perf_counter() - t_import
    name, div, _, _ = CASES[case]
    ex = load_example(name)
    run = lambda d: extract(ex.formulas, ex.bounds, d, variables=ex.variables)  # noqa: E731
    out = dict(case=case, example=name, div=div)
    if case == "fresh-process":
        t = time.perf_counter()
        run(div)
        first = time.perf_counter() - t
        t = time.perf_counter()
        cx = run(div)
        second = time.perf_counter() - t
        out.update(seconds=second, first_seconds=first, import_seconds=import_s,
                   overhead_seconds=import_s + first - second)
    else:
        run(4 if isinstance(div, int) else [4] * len(div))  # warm-up: loads the cached kernels, starts threads
        best = None
        for _ in range(repeat):
            t = time.perf_counter()
            cx = run(div)
            dt = time.perf_counter() - t
            best = dt if best is None else min(best, dt)
        out.update(seconds=best, timings=cx.meta["timings"])
        if case == "sphere-256":
            out.update(_skimage_peer(ex, div, repeat))
    out.update(counts=cx.counts(), euler=cx.euler_characteristic(), boundary=int(len(cx.boundary_facets())),
               candidates=cx.meta["candidate_cubes"], cubes=cx.meta["cubes"], peak_mb=_peak_mb())
    return out


def _skimage_peer(ex, div, repeat) -> dict:
    """scikit-image's marching_cubes on the same function and grid, sampling included."""
    import numpy as np  # noqa: PLC0415
    from skimage.measure import marching_cubes  # noqa: PLC0415

    from gcmh_core.formula import parse_system  # noqa: PLC0415

    system = parse_system(ex.formulas, ex.variables)
    axes = [np.linspace(lo, hi, div + 1) for lo, hi in ex.bounds]
    best = None
    for _ in range(repeat):
        t = time.perf_counter()
        volume = system.evaluate_grid(axes)[..., 0]
        verts, faces, _, _ = marching_cubes(volume, 0.0)
        dt = time.perf_counter() - t
        best = dt if best is None else min(best, dt)
    return dict(peer="skimage.marching_cubes", peer_seconds=best, peer_triangles=len(faces))


def _machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"


def _row(r: dict) -> str:
    name, div, target, paper = CASES[r["case"]]
    divtxt = "x".join(map(str, div)) if isinstance(div, list) else str(div)
    secs = f"{r['seconds']:.2f} s"
    if "peer_seconds" in r:
        secs += f" (skimage {r['peer_seconds']:.2f} s, ratio {r['seconds'] / r['peer_seconds']:.2f})"
    if "overhead_seconds" in r:
        secs = (f"import {r['import_seconds']:.2f} s + first {r['first_seconds']:.2f} s vs "
                f"{r['seconds']:.2f} s warm: overhead {r['overhead_seconds']:.2f} s")
    counts = "/".join(str(c) for c in r["counts"])
    return (f"| {name} | {divtxt} | {r['cubes']:,} | {r['candidates']:,} | {secs} | {r['peak_mb']:.0f} MB "
            f"| {counts} | {r['euler']} | {r['boundary']} | {target} | {paper} |")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m gcmh_core.bench", description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated: " + ", ".join(CASES))
    parser.add_argument("--repeat", type=int, default=3, help="runs per case; the best is reported")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(_child(args.child, args.repeat)))
        return 0
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        parser.error(f"unknown case(s) {', '.join(unknown)}; choose from {', '.join(CASES)}")
    print(f"Measured {date.today().isoformat()} on {_machine()}; best of {args.repeat} warm runs per case,")
    print("each case in a fresh process (peak = that process's max RSS, Python and numba included).\n")
    print("| case | div | cubes | candidate cubes | time | peak memory | cells by dim | Euler | boundary facets | target | paper |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for case in cases:
        proc = subprocess.run([sys.executable, "-m", "gcmh_core.bench", "--child", case, "--repeat", str(args.repeat)],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            print(f"| {case} | failed: {proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else proc.returncode} |")
            continue
        print(_row(json.loads(proc.stdout.strip().splitlines()[-1])), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
