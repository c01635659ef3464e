"""Benchmark: the full GCMH sweep pruned by F's interval bounds against the plain sweep.

    python tests/bench/bench_prune.py [--repeat N] [--estimate-plain-320] [--cases a,b,...]

Run from the repository root.  Cases (issue 18, item 2): the complex cosine at div 160
and 320, the three-torus at div 20 (with continuation, method "gcch" from the
example's start, for comparison) and the Klein bottle at the authors' division
(`paper_div`).  Each run is a fresh child process (its peak memory, ru_maxrss, is its
own) that first loads the cached kernels on a tiny grid; the time is the best of
`--repeat` runs (one run when it takes over 20 s).  `hash` is a sha256 over the complex's bytes (vertices, edges, every
CSR array): the pruned and the plain sweep must agree.  The plain sweep of the complex
cosine at div 320 takes about a minute and 1.7 GB; --estimate-plain-320 skips it and
prints 16 x the div 160 time instead (marked "est.").
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import time
from datetime import datetime, timezone

HERE = os.path.dirname(os.path.abspath(__file__))

CASES = {  # name: (example, div or "paper", the paths to run)
    "cosine-160": ("complex-cosine", 160, ("pruned", "plain", "gcch")),
    "cosine-320": ("complex-cosine", 320, ("pruned", "plain", "gcch")),
    "three-torus-20": ("three-torus", 20, ("pruned", "plain", "gcch")),
    "klein-paper": ("klein-bottle", "paper", ("pruned", "plain", "gcch")),
}


def digest(cx) -> str:
    import numpy as np

    h = hashlib.sha256()
    h.update(np.ascontiguousarray(cx.vertices, np.float64).tobytes())
    h.update(np.ascontiguousarray(cx.edges, np.int64).tobytes())
    for r in sorted(cx.cells):
        for arr in cx.cells[r]:
            h.update(np.ascontiguousarray(arr, np.int64).tobytes())
    return h.hexdigest()[:16]


def child(spec: dict) -> dict:
    """One case in this (fresh) process: warm up on a tiny grid, then the timed runs."""
    sys.path.insert(0, HERE)
    from gcmh_core import extract, sweep
    from gcmh_core.examples import load_example

    from bench import peak_mb

    ex = load_example(spec["example"])
    div = ex.paper_div if spec["div"] == "paper" else spec["div"]
    path = spec["path"]
    method = "gcch" if path == "gcch" else "gcmh"
    if method == "gcmh":
        sweep.PRUNE = path == "pruned"
    start = ex.start if method == "gcch" else None

    def run(d):
        return extract(ex.formulas, ex.bounds, d, variables=ex.variables, method=method, start=start)

    run(3 if isinstance(div, int) else [3] * len(div))
    best, cx = None, None
    for _ in range(spec["repeat"]):
        t = time.perf_counter()
        cx = run(div)
        dt = time.perf_counter() - t
        best = dt if best is None else min(best, dt)
        if dt > 20:  # (the plain sweeps of the complex cosine: once is enough)
            break
    return dict(spec, div=div, seconds=best, peak_mb=peak_mb(), hash=digest(cx),
                candidate_cubes=cx.meta.get("candidate_cubes"), cubes=cx.meta.get("cubes"),
                pruned_cubes=cx.meta.get("pruned_cubes"), counts=cx.counts(),
                timings={k: round(v, 3) for k, v in cx.meta["timings"].items()})


def run_child(spec: dict) -> dict:
    proc = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", json.dumps(spec)],
                          capture_output=True, text=True, timeout=1800)
    if proc.returncode != 0:
        lines = proc.stderr.strip().splitlines()
        return dict(spec, error=lines[-1] if lines else f"exit {proc.returncode}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python tests/bench/bench_prune.py", description=__doc__.splitlines()[0])
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--estimate-plain-320", action="store_true")
    parser.add_argument("--cases", default=",".join(CASES))
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(child(json.loads(args.child))))
        return 0
    sys.path.insert(0, HERE)
    from bench import machine

    print(f"# {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, {machine()}")
    print(f"# python tests/bench/bench_prune.py {' '.join(argv if argv is not None else sys.argv[1:])}".rstrip())
    print("| case | div | path | seconds | peak MB | hash | candidate cubes | cubes left by the bounds |")
    print("|---|---|---|---|---|---|---|---|")
    results: dict = {}
    for name in args.cases.split(","):
        example, div, paths = CASES[name]
        for path in paths:
            spec = dict(example=example, div=div, path=path, repeat=args.repeat)
            if name == "cosine-320" and path == "plain" and args.estimate_plain_320:
                base = results.get(("cosine-160", "plain"))
                secs = f"~{16 * base['seconds']:.0f} (est.: 16 x div 160)" if base and "seconds" in base else "—"
                print(f"| {example} | {div} | plain | {secs} | — | — | — | — |", flush=True)
                continue
            res = results[(name, path)] = run_child(spec)
            if "error" in res:
                print(f"| {example} | {div} | {path} | error: {res['error']} | | | | |", flush=True)
                continue
            left = "" if res["pruned_cubes"] is None else f"{res['cubes'] - res['pruned_cubes']:,} of {res['cubes']:,}"
            print(f"| {example} | {res['div']} | {path} | {res['seconds']:.2f} | {res['peak_mb']:.0f} | {res['hash']} "
                  f"| {res['candidate_cubes']:,} | {left} |", flush=True)
        hashes = {results[(name, p)]["hash"] for p in paths if "hash" in results.get((name, p), {})}
        print(f"|   | | | | | {'same bytes' if len(hashes) == 1 else 'HASHES DIFFER'} | | |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
