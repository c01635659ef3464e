"""Benchmark: the wait before a first result (issue 18, item 3), each case in fresh processes.

    python tests/bench/bench_first_run.py [--tree DIR ...] [--repeat N] [--cases a,b,...] [--plain-install]

Run from the repository root.  For every source tree (`--tree`, default this repository;
give a `git worktree` of an older commit too to compare before and after in one run,
its column first), with numba's cache (NUMBA_CACHE_DIR) in a new temporary folder:

* cold: the first extraction on a new install, kernels compiled: the sphere in R^3
  (div 32, gcmh: the n = 3 marching pass), a 2-sphere in R^4 cut out by two equations
  (div 16, gcmh: the general cube kernel), the Bagel Klein bottle (R^5, k = 3,
  continuation "gcch" from the example's start point at its division) and `gcmh
  extract` of the sphere at div 8, whose standard error must say once that the
  kernels compile;
* warm: a fresh process on the now filled cache: its first extraction (after
  `import gcmh_core`, so the engine's own lazy imports count), the second in the same
  process, and what the first costs beyond the work (first - second); and the wall time
  of the whole `gcmh extract ... --div 8` command.  The median of `--repeat` processes.

Wall times of the calls, as a user waits for them, and CPU seconds (user + system:
compiling is one thread, so on a busy machine they are the steadier figure; parallel
kernels count once per thread); `meta['seconds']` (the JSON's `seconds`) starts after
the engine's imports and is printed beside them.
--plain-install hides scipy from the children: numba imports it (0.1-0.2 s) to look
for BLAS when it loads its first kernel, and only the test extra (scikit-image)
installs it, so a user's `pip install gcmh` has no scipy.
The machine is shared: compare the trees' columns (same run), not absolute times.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

SPHERE = dict(F=["x^2 + y^2 + z^2 - 1"], bounds=[[-1.2, 1.2]] * 3, variables=["x", "y", "z"], method="gcmh")
# n = 3, k = 1 sweeps take a pass of their own (`kernels.marching3`); this takes the general cube kernel
GENERAL = dict(F=["x1^2 + x2^2 + x3^2 + x4^2 - 1", "x1 - x2"], bounds=[[-1.2, 1.2]] * 4,
               variables=["x1", "x2", "x3", "x4"], method="gcmh")
CLI = ["extract", "--f", "x^2+y^2+z^2-1", "--vars", "x,y,z", "--bounds=-1.2:1.2", "--div", "8", "--json"]
CASES = ("sphere", "general", "klein", "cli")
COMPILING = "compiling the kernels"  # the CLI's one-line note on a cold cache

# Prepended to a child's code with --plain-install.
_HIDE_SCIPY = """
import sys
class _Hide:
    def find_spec(self, name, path=None, target=None):
        if name == "scipy" or name.startswith("scipy."):
            raise ImportError("hidden by bench_first_run --plain-install")
sys.meta_path.insert(0, _Hide())
"""


def child(spec: dict) -> dict:
    """Two extractions in this fresh process: the first one's wall time and the second's."""
    t = time.perf_counter()
    import gcmh_core

    out = dict(import_s=time.perf_counter() - t)
    if spec["case"] in ("sphere", "general"):
        case = dict(SPHERE if spec["case"] == "sphere" else GENERAL)
        F, bounds, variables = case.pop("F"), case.pop("bounds"), case.pop("variables")
        args, kw = (F, bounds, spec["div"]), dict(variables=variables, **case)
    else:  # the Klein bottle by continuation, from its start point at its division
        from gcmh_core.examples import load_example

        ex = load_example("klein-bottle")
        args, kw = (ex.formulas, ex.bounds, ex.div), dict(variables=ex.variables, method="gcch", start=ex.start)
    for name in ("first", "second"):
        t, c = time.perf_counter(), _cpu(resource.RUSAGE_SELF)
        cx = gcmh_core.extract(*args, **kw)
        out[f"{name}_s"] = time.perf_counter() - t
        out[f"{name}_cpu"] = _cpu(resource.RUSAGE_SELF) - c
        out[f"{name}_meta_s"] = cx.meta["seconds"]
    out["cells"] = cx.counts() if hasattr(cx, "counts") else None
    out["scipy"] = "scipy" in sys.modules
    return out


def _python(tree: str, code: str, plain: bool) -> list[str]:
    prelude = (_HIDE_SCIPY if plain else "") + f"import sys\nsys.path.insert(0, {tree!r})\n"
    return [sys.executable, "-c", prelude + code]


def run_child(tree: str, cache: str, spec: dict, plain: bool) -> dict:
    code = (f"sys.path.insert(0, {HERE!r})\nimport json, bench_first_run as b\n"
            f"print(json.dumps(b.child(json.loads({json.dumps(spec)!r}))))")
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    proc = subprocess.run(_python(tree, code, plain), capture_output=True, text=True, env=env, timeout=1800)
    if proc.returncode != 0:
        lines = proc.stderr.strip().splitlines()
        return dict(error=lines[-1] if lines else f"exit {proc.returncode}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def run_cli(tree: str, cache: str, plain: bool) -> dict:
    code = f"from gcmh_core.cli import main\nsys.exit(main({CLI!r}))"
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    t, c = time.perf_counter(), _cpu(resource.RUSAGE_CHILDREN)
    proc = subprocess.run(_python(tree, code, plain), capture_output=True, text=True, env=env, timeout=1800)
    wall, cpu = time.perf_counter() - t, _cpu(resource.RUSAGE_CHILDREN) - c
    if proc.returncode != 0:
        lines = proc.stderr.strip().splitlines()
        return dict(error=lines[-1] if lines else f"exit {proc.returncode}")
    summary = json.loads(proc.stdout.strip().splitlines()[-1])
    return dict(first_s=wall, first_cpu=cpu, first_meta_s=summary.get("seconds"), notes=proc.stderr.count(COMPILING))


def _cpu(who: int) -> float:
    """User + system CPU seconds (of this process, or of its finished children)."""
    usage = resource.getrusage(who)
    return usage.ru_utime + usage.ru_stime


def measure(tree: str, cases: list[str], repeat: int, plain: bool) -> dict:
    """{(case, "cold" | "warm"): result} for one source tree, each case on a cache of its own."""
    results = {}
    for case in cases:
        cache = tempfile.mkdtemp(prefix="gcmh-bench-numba-")
        try:
            if case == "cli":
                results[case, "cold"] = run_cli(tree, cache, plain)
                warm = [run_cli(tree, cache, plain) for _ in range(repeat)]
            else:
                spec = dict(case=case, div=16 if case == "general" else 32)
                results[case, "cold"] = run_child(tree, cache, spec, plain)
                warm = [run_child(tree, cache, spec, plain) for _ in range(repeat)]
            results[case, "warm"] = _median(warm)
        finally:
            shutil.rmtree(cache, ignore_errors=True)
    return results


def _median(runs: list[dict]) -> dict:
    bad = [r for r in runs if "error" in r]
    if bad:
        return bad[0]
    out = dict(runs[0])
    for key, value in runs[0].items():
        if isinstance(value, float):
            out[key] = statistics.median(r[key] for r in runs)
    return out


def _cell(res: dict | None, key: str) -> str:
    if res is None:
        return "—"
    if "error" in res:
        return f"error: {res['error'][:60]}"
    value = res.get(key)
    if value is None:
        return "—"
    return str(value) if isinstance(value, int) else f"{value:.3f}"


ROWS = [  # (label, case, cold/warm, how the value is read)
    ("sphere div 32, cold: first extraction", "sphere", "cold", "first_s"),
    ("  its CPU seconds", "sphere", "cold", "first_cpu"),
    ("sphere div 32, warm: first extraction", "sphere", "warm", "first_s"),
    ("  its meta['seconds']", "sphere", "warm", "first_meta_s"),
    ("  second extraction", "sphere", "warm", "second_s"),
    ("  first - second (beyond the work)", "sphere", "warm", "extra"),
    ("  the same in CPU seconds", "sphere", "warm", "extra_cpu"),
    ("  import gcmh_core", "sphere", "warm", "import_s"),
    ("curve in R^4 (k = 2) div 16, cold: first extraction", "general", "cold", "first_s"),
    ("  its CPU seconds", "general", "cold", "first_cpu"),
    ("  warm: first - second (beyond the work)", "general", "warm", "extra"),
    ("Klein bottle gcch, cold: first extraction", "klein", "cold", "first_s"),
    ("  its CPU seconds", "klein", "cold", "first_cpu"),
    ("Klein bottle gcch, warm: first extraction", "klein", "warm", "first_s"),
    ("  second extraction", "klein", "warm", "second_s"),
    ("  first - second (beyond the work)", "klein", "warm", "extra"),
    ("gcmh extract div 8, cold: wall", "cli", "cold", "first_s"),
    ("  its CPU seconds", "cli", "cold", "first_cpu"),
    ("  'compiling' notes on stderr (should be 1)", "cli", "cold", "notes"),
    ("gcmh extract div 8, warm: wall", "cli", "warm", "first_s"),
    ("  its CPU seconds", "cli", "warm", "first_cpu"),
    ("  its JSON seconds", "cli", "warm", "first_meta_s"),
    ("  'compiling' notes on stderr (should be 0)", "cli", "warm", "notes"),
]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python tests/bench/bench_first_run.py", description=__doc__.splitlines()[0])
    parser.add_argument("--tree", action="append", help="a source tree to measure (repeatable; default: this one)")
    parser.add_argument("--repeat", type=int, default=3, help="fresh warm processes per case (the median)")
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--plain-install", action="store_true", help="hide scipy, as a plain install has none")
    args = parser.parse_args(argv)
    trees = [os.path.abspath(t) for t in (args.tree or [ROOT])]
    cases = [c for c in args.cases.split(",") if c]
    unknown = set(cases) - set(CASES)
    if unknown:
        parser.error(f"unknown case(s) {', '.join(sorted(unknown))}; choose from {', '.join(CASES)}")
    sys.path.insert(0, HERE)
    from bench import machine

    print(f"# {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, {machine()}")
    print(f"# python tests/bench/bench_first_run.py {' '.join(argv if argv is not None else sys.argv[1:])}".rstrip())
    measured = {}
    for tree in trees:
        measured[tree] = measure(tree, cases, args.repeat, args.plain_install)
        for res in measured[tree].values():
            if "first_s" in res and "second_s" in res:
                res["extra"] = res["first_s"] - res["second_s"]
                res["extra_cpu"] = res["first_cpu"] - res["second_cpu"]
    print("| seconds (wall) | " + " | ".join(os.path.relpath(t) if t != ROOT else "this tree" for t in trees) + " |")
    print("|---|" + "---|" * len(trees))
    for label, case, when, key in ROWS:
        if case in cases:
            print(f"| {label} | " + " | ".join(_cell(measured[t].get((case, when)), key) for t in trees) + " |")
    scipy = {t: any(r.get("scipy") for r in measured[t].values()) for t in trees}
    print(f"# scipy imported in the children: {', '.join(f'{os.path.basename(t)} {v}' for t, v in scipy.items())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
