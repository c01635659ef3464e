"""Benchmark of the Dask path: `python tests/bench/bench_cluster.py [--cases a,b] [--workers W]`.

Each case runs twice in fresh child processes: once in one process (numba's threads
on every core), once on a LocalCluster of W single-threaded worker processes, started
the way `extract(..., scheduler="local")` starts one, and reached through its address.
Both are timed warm (kernels loaded, cluster up, after a small warm-up run); the
cluster's start-up and its workers' first task are reported apart.  Peak memory is
max RSS: per worker process, and of the client process (which also hosts the
LocalCluster's scheduler).  The two complexes are compared array by array.  The
output is a Markdown table; speed is measured here, never asserted in tests.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from datetime import datetime, timezone

# bench.py sits in this script's folder, which Python puts first on sys.path when it
# runs the script (and the LocalCluster's spawned workers inherit that path).
from bench import machine, peak_mb

CASES = {
    # name: (example, div)
    "cosine-160": ("complex-cosine", 160),
    "three-torus-12": ("three-torus", 12),
}


def _digest(cx) -> str:
    import hashlib

    h = hashlib.sha256()
    h.update(cx.vertices.tobytes())
    h.update(cx.edges.tobytes())
    for r in sorted(cx.cells):
        for arr in cx.cells[r]:
            h.update(arr.tobytes())
    return h.hexdigest()[:16]


def _child(case: str, mode: str, workers: int) -> dict:
    from gcmh_core import extract
    from gcmh_core.examples import load_example

    name, div = CASES[case]
    ex = load_example(name)

    def run(d, **kw):
        return extract(ex.formulas, ex.bounds, d, variables=ex.variables, **kw)

    out = dict(case=case, mode=mode, example=name, div=div)
    if mode == "single":
        run(4)  # warm-up: cached kernels loaded, numba's threads started
        t = time.perf_counter()
        cx = run(div)
        out.update(seconds=time.perf_counter() - t)
    else:
        import logging

        from distributed import Client, LocalCluster

        t = time.perf_counter()
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                               scheduler_kwargs={"dashboard": False}, silence_logs=logging.ERROR)
        client = Client(cluster, set_as_default=False)
        client.wait_for_workers(workers)
        start_s = time.perf_counter() - t
        address = cluster.scheduler_address
        t = time.perf_counter()
        run(4, scheduler=address, block=2)  # first tasks: workers import gcmh_core and load the kernels
        first_s = time.perf_counter() - t
        t = time.perf_counter()
        run(4, scheduler=address, block=2)
        warm_small_s = time.perf_counter() - t
        base = client.run(peak_mb)  # a worker with gcmh_core, numba and the kernels loaded
        t = time.perf_counter()
        cx = run(div, scheduler=address)
        out.update(seconds=time.perf_counter() - t, start_seconds=start_s, first_seconds=first_s,
                   warm_small_seconds=warm_small_s, blocks=cx.meta["blocks"], block=cx.meta["block"])
        peaks = client.run(peak_mb)
        out.update(worker_peak_mb=sorted(peaks.values()), worker_base_mb=max(base.values()))
        client.close()
        cluster.close()
    out.update(counts=cx.counts(), euler=cx.euler_characteristic(), digest=_digest(cx),
               cubes=cx.meta["cubes"], candidates=cx.meta["candidate_cubes"], peak_mb=peak_mb())
    return out


def _load() -> str:
    try:
        return "load average " + " ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "load average unknown"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python tests/bench/bench_cluster.py", description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated: " + ", ".join(CASES))
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--mode", default="single", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.workers < 1:
        parser.error("--workers must be at least 1")
    if args.child:
        print(json.dumps(_child(args.child, args.mode, args.workers)))
        return 0
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        parser.error(f"unknown case(s) {', '.join(unknown)}; choose from {', '.join(CASES)}")
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    print(f"Measured {stamp} on {machine()} ({_load()} at start); one warm run per row,")
    print(f"each in a fresh process; cluster = LocalCluster of {args.workers} single-threaded worker processes.\n")
    print("| case | div | cubes | run | time | peak memory | cells by dim | identical |")
    print("|---|---|---|---|---|---|---|---|")
    notes = []
    for case in cases:
        rows = {}
        for mode in ("single", "cluster"):
            proc = subprocess.run(
                [sys.executable, os.path.abspath(__file__), "--child", case, "--mode", mode,
                 "--workers", str(args.workers)],
                capture_output=True, text=True,
            )
            if proc.returncode != 0:
                last = proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else proc.returncode
                print(f"| {case} | | | {mode} | failed: {last} | | | |", flush=True)
                continue
            rows[mode] = r = json.loads(proc.stdout.strip().splitlines()[-1])
            name, div = CASES[case]
            counts = "/".join(str(c) for c in r["counts"])
            if mode == "single":
                run, mem, same = "1 process", f"{r['peak_mb']:.0f} MB", "-"
            else:
                blocks = "x".join(map(str, r["block"]))
                run = f"{args.workers} workers, {r['blocks']} blocks of {blocks}"
                mem = ("workers " + ", ".join(f"{m:.0f}" for m in r["worker_peak_mb"])
                       + f" MB; client {r['peak_mb']:.0f} MB")
                same = "yes" if "single" in rows and rows["single"]["digest"] == r["digest"] else "NO"
                notes.append(f"{case}: cluster start {r['start_seconds']:.2f} s; first tasks (div 4, "
                             f"workers load gcmh_core and the cached kernels) {r['first_seconds']:.2f} s "
                             f"vs {r['warm_small_seconds']:.2f} s warm; a warm idle worker holds "
                             f"{r['worker_base_mb']:.0f} MB")
            speed = ""
            if mode == "cluster" and "single" in rows:
                speed = f" ({rows['single']['seconds'] / r['seconds']:.2f}x)"
            print(f"| {name} | {div} | {r['cubes']:,} | {run} | {r['seconds']:.1f} s{speed} | {mem} | {counts} "
                  f"| {same} |", flush=True)
    print()
    for note in notes:
        print(f"- {note}")
    print(f"- {_load()} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
