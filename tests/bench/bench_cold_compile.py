"""Benchmark: the cold compile of a first run (issue 24, item 1), source trees in turn.

    python tests/bench/bench_cold_compile.py TREE [TREE ...] [--rounds N] [--example NAME]

Each round runs, for every tree in turn (a `git worktree` or `git archive` of a commit, or
this repository), a fresh process with numba's cache (NUMBA_CACHE_DIR) in a new empty
folder and PYTHONPATH set to the tree: `import gcmh_core`, then the example's extraction
(`gcmh extract --example NAME`: its division, method gcmh) twice.  Printed per process, in
CPU seconds of the process (compiling is one thread, so they are steadier than wall time on
a shared machine): the import and first call minus the second call (what the compile
costs), and the CPU seconds of numba's outermost compilations of the GCMH chunk kernel's
modules (a function of `kernels.gcmh`, `kernels.lazy` or `kernels.cells` that another
compiled function did not call: a driver or a phase, with the helpers it compiles), from
numba's compile events.  Then each tree's median.  Only the ratios
of one run compare: the machine is shared.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
# The kernel family timed on its own: an outermost compilation holds its callees' (numba's events nest).
KERNELS = ("gcmh_core.kernels.gcmh", "gcmh_core.kernels.lazy", "gcmh_core.kernels.cells")


def child(tree: str, example: str) -> dict:
    """One fresh process: import, first call, second call, in CPU seconds; the kernel's compile."""
    sys.meta_path[:] = [f for f in sys.meta_path if not getattr(f, "__module__", "").startswith("__editable__")]
    sys.path.insert(0, tree)
    from numba.core import event

    compiles: dict[str, float] = {}
    depth = [0]
    started: list[float] = []

    class Listener(event.Listener):
        def on_start(self, ev):
            depth[0] += 1
            started.append(time.process_time())

        def on_end(self, ev):
            depth[0] -= 1
            seconds = time.process_time() - started.pop()
            func = getattr(ev.data.get("dispatcher"), "py_func", None)
            if depth[0] == 0 and getattr(func, "__module__", "") in KERNELS:
                name = f"{func.__module__}.{func.__name__}"
                compiles[name] = compiles.get(name, 0.0) + seconds

    event.register("numba:compile", Listener())
    t0 = time.process_time()
    import gcmh_core
    from gcmh_core.examples import load_example

    ex = load_example(example)
    for name, module in list(sys.modules.items()):
        path = getattr(module, "__file__", None) or ""
        if name.split(".")[0] == "gcmh_core" and path and not os.path.realpath(path).startswith(os.path.realpath(tree)):
            raise SystemExit(f"{name} imported from {path}, not from {tree}")

    def call():
        return gcmh_core.extract(ex.formulas, ex.bounds, ex.div, variables=ex.variables, method="gcmh")

    call()
    t1 = time.process_time()
    call()
    t2 = time.process_time()
    return dict(first=t1 - t0, second=t2 - t1, compile=(t1 - t0) - (t2 - t1), kernel=sum(compiles.values()),
                kernels=compiles)


def run(tree: str, example: str) -> dict:
    cache = tempfile.mkdtemp(prefix="gcmh-cold-")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "NUMBA_CACHE_DIR", "GCMH_EXAMPLES_DIR")}
    env.update(PYTHONPATH=tree, NUMBA_CACHE_DIR=cache, NUMBA_NUM_THREADS="1")
    try:
        proc = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", tree, "--example", example],
                              capture_output=True, text=True, cwd=tree, env=env)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    if proc.returncode != 0:
        raise SystemExit(f"{tree}: {proc.stderr.strip().splitlines()[-1:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python tests/bench/bench_cold_compile.py", description=__doc__.splitlines()[0])
    ap.add_argument("trees", nargs="*", default=[ROOT], metavar="TREE")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--example", default="complex-cosine")
    ap.add_argument("--child", metavar="TREE", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child, args.example)))
        return 0
    got: dict[str, list[dict]] = {t: [] for t in args.trees}
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load {os.getloadavg()[0]:.2f}, "
          f"example {args.example}, CPU s")
    print("| round | tree | first call (with import) | second | compile (first - second) | GCMH kernel's compile |")
    print("|---|---|---|---|---|---|")
    for r in range(args.rounds):
        order = args.trees if r % 2 == 0 else args.trees[::-1]
        for tree in order:
            res = run(tree, args.example)
            got[tree].append(res)
            print(f"| {r + 1} | {tree} | {res['first']:.2f} | {res['second']:.2f} | {res['compile']:.2f} | "
                  f"{res['kernel']:.2f} |", flush=True)
    print(f"# load {os.getloadavg()[0]:.2f} at the end; medians:")
    for tree, runs in got.items():
        print(f"{tree}: compile {statistics.median(r['compile'] for r in runs):.2f} s, GCMH kernel "
              f"{statistics.median(r['kernel'] for r in runs):.2f} s ({len(runs)} processes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
