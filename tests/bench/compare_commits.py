"""Benchmark: two commits side by side in one run, alternating fresh processes (issue 24).

    python tests/bench/compare_commits.py REV_A [REV_B] [--rounds N] [--cases a,b,...]
                                          [--quick] [--fresh] [--json FILE]

Revisions are read from the repository that holds this script.  REV_A and REV_B are anything git names a
commit by; REV_B defaults to the working tree as it is (uncommitted edits included).  Each
commit is unpacked (`git archive | tar -x`) into a temporary folder, removed at the end;
no install is needed: every process runs with PYTHONPATH set to its tree and checks that
`gcmh_core` was imported from there (not from the editable install in .venv).

Each tree is first warmed by one process that runs every case on a tiny grid, so that
numba's compilation (cached on disk) is never timed; a case a commit cannot run (no pruned
sweep, no lazy kernel for n >= 8, ...) is skipped there with its reason.  Then, round after
round, each case runs in a fresh process at A, then at B, then A, B, ...: a shared
machine's load falls on both alike, and the ratio of the two processes of one round (a
pair) shows how much of a difference is noise.  A process measures one case at one
commit: `import gcmh_core`, the first call at the case's grid (loading the cached
kernels: the fresh-process cost, shown with --fresh), then `repeat` further calls; its
value is the best of those.  Only the public API is timed (`gcmh_core.extract`,
`gcmh_core.examples.load_example`), so commits from before a refactor run too.

Cases (name: what is measured):
* kernel-*: microseconds per candidate cube of the GCMH kernel (meta timings 'kernel' over
  'candidate_cubes', the plain sweep at every commit): the complex cosine at div 40 and
  the Hopf tori at div 32 (n = 4), and the flat torus in R^10 with k = 8 (bench_high_k's 10-8: the lazy kernel, n >= 8);
* waves-cosine-80: microseconds per cube of the GCMH kernel alone on the waves of a GCCH run
  (the complex cosine at div 80: 138 kernel calls, about 24,500 cubes), its calls recorded in
  the first run and replayed `repeat` times: the kernel's share of a whole run is too small for
  kernel-* or gcch-* to show it changing by 15 % (19d7e13 did, docs/benchmarks-compare.md);
* gcch-*: whole-run seconds of continuation (method "gcch" from the example's start): the
  complex cosine at div 80, the Klein bottle at the authors' division, the three-torus in
  R^6 at div 6;
* prune-*: whole-run seconds of the full sweep pruned by F's bounds (method "gcmh",
  gcmh_core/sweep.py; skipped at commits without it): the complex cosine at div 160 and
  320, the Klein bottle at the authors' division.

The table: each side's median over the rounds, the ratio of the medians B/A, the least
and largest ratio of a pair, and in how many pairs B was the slower; `output` says
whether A and B built the same bytes (bench_prune.digest).  Expensive cases run at most
3 rounds unless --rounds is given.  The default takes about 10 minutes on a loaded 2-core machine, --quick
(3 cases, 3 rounds) about 2.
"""

from __future__ import annotations

import argparse
import contextlib
import fcntl
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from typing import NamedTuple

HERE = os.path.dirname(os.path.abspath(__file__))


class Case(NamedTuple):
    kind: str  # "kernel", "waves" (us per candidate cube), "gcch" or "prune" (seconds of the call)
    example: str  # an example's name, or "torus-10-8" (bench_high_k.system(10, 8))
    div: int | str | None  # "paper": the example's paper_div; None: the system's own
    repeat: int  # calls timed after the first one
    max_rounds: int | None = None


CASES = {
    "kernel-cosine-40": Case("kernel", "complex-cosine", 40, 5),
    "kernel-hopf-tori-32": Case("kernel", "hopf-tori", 32, 5),
    "kernel-torus-R10": Case("kernel", "torus-10-8", None, 2, max_rounds=3),
    "waves-cosine-80": Case("waves", "complex-cosine", 80, 15),
    "gcch-cosine-80": Case("gcch", "complex-cosine", 80, 5),
    "gcch-klein-paper": Case("gcch", "klein-bottle", "paper", 5),
    "gcch-three-torus-6": Case("gcch", "three-torus", 6, 5),
    "prune-cosine-160": Case("prune", "complex-cosine", 160, 2),
    "prune-cosine-320": Case("prune", "complex-cosine", 320, 1, max_rounds=3),
    "prune-klein-paper": Case("prune", "klein-bottle", "paper", 2, max_rounds=3),
}
QUICK = ("kernel-cosine-40", "gcch-cosine-80", "prune-cosine-160")
UNITS = {"kernel": "us/cube", "waves": "us/cube", "gcch": "s", "prune": "s"}
WORKTREE = "worktree"
# A child may not map more than this (a last guard of a shared machine: a commit from
# before the lazy kernel builds the R^10 cube tables whole, about 12 GB; _needs skips it).
MEMORY_LIMIT = 8 << 30


# ----------------------------------------------------------------------------- one process at one commit
def _import_tree(tree: str):
    """`import gcmh_core` from `tree` (first on sys.path), checked; returns its import seconds."""
    # The editable install's finder (setuptools, on sys.meta_path) would answer for any
    # submodule the tree lacks (gcmh_core.sweep at an old commit) with the repository's.
    sys.meta_path[:] = [f for f in sys.meta_path if not getattr(f, "__module__", "").startswith("__editable__")]
    sys.path.insert(0, tree)
    t = time.perf_counter()
    import gcmh_core  # noqa: F401 (this import is what is timed)

    seconds = time.perf_counter() - t
    _check_tree(tree)
    return seconds


def _check_tree(tree: str) -> None:
    """Every gcmh_core module loaded so far comes from `tree`."""
    root = os.path.realpath(tree)
    for name, module in list(sys.modules.items()):
        path = getattr(module, "__file__", None)
        if name.split(".")[0] == "gcmh_core" and path and os.path.commonpath([os.path.realpath(path), root]) != root:
            raise SystemExit(f"{name} imported from {path}, not from {tree}")


def _call(case: Case, tiny: bool = False, unchecked: bool = False):
    """The case's call at this commit: a function running it once, returning the complex.
    ``unchecked``: cells not checked, at a commit whose extract can check them (check_cells=False): the
    default of the commits before the check was on by default, for a like-for-like comparison."""
    import inspect

    from gcmh_core import extract

    kw = {}
    if unchecked and "check_cells" in inspect.signature(extract).parameters:
        kw["check_cells"] = False
    if case.example == "torus-10-8":
        sys.path.insert(0, HERE)
        from bench_high_k import system

        F, bounds, div = system(10, 8)
        variables, start = None, None
        kw["n"] = 10
        div = [2] * 10 if tiny else div
    else:
        from gcmh_core.examples import load_example

        ex = load_example(case.example)
        F, bounds, variables = ex.formulas, ex.bounds, ex.variables
        start = ex.start if case.kind in ("gcch", "waves") else None
        div = ex.paper_div if case.div == "paper" else case.div
        div = 3 if tiny else div
    method = "gcch" if case.kind in ("gcch", "waves") else "gcmh"
    return lambda: extract(F, bounds, div, variables=variables, method=method, start=start, **kw)


def _recorded_kernel(run):
    """Run once with the GCMH kernel's calls recorded: (the complex, a function calling the
    compiled kernel itself on each recorded call's arguments, the cubes they hold)."""
    import importlib

    try:
        runner = importlib.import_module("gcmh_core.runner")  # (since a11766a)
    except ImportError:
        runner = None
    # the name the engine calls: runner.cubes_chunk, or _kernels.cubes_chunk before the kernels' package
    has_it = runner is not None and hasattr(runner, "cubes_chunk")
    host = runner if has_it else importlib.import_module("gcmh_core._kernels")
    try:
        gcmh = importlib.import_module("gcmh_core.kernels.gcmh")
        kernel = getattr(gcmh, "_cubes_chunk_tables", gcmh.cubes_chunk)  # (not the Python chooser before it)
    except ImportError:
        kernel = importlib.import_module("gcmh_core._kernels").cubes_chunk
    calls, engine = [], host.cubes_chunk

    def recording(*args):
        calls.append(args)
        return engine(*args)

    host.cubes_chunk = recording
    try:
        cx = run()
    finally:
        host.cubes_chunk = engine

    def replay():
        for args in calls:
            kernel(*args)

    return cx, replay, sum(int(args[1]) - int(args[0]) for args in calls)


def _needs(case: Case):
    """Why this commit cannot run the case, or None."""
    if case.example == "torus-10-8":
        # (no public API tells; without the lazy kernel the tables alone take minutes and GBs)
        import gcmh_core

        root = os.path.dirname(gcmh_core.__file__)
        sources = (os.path.join(d, f) for d, _, files in os.walk(root) for f in files if f.endswith(".py"))
        if not any(re.search(r"def \w*lazy\w*\(", open(f).read()) for f in sources):
            return "no lazy kernel for n >= 8 at this commit"
    if case.kind == "prune":
        try:
            from gcmh_core import sweep
        except ImportError:
            return "no pruned sweep (gcmh_core.sweep) at this commit"
        if not hasattr(sweep, "PRUNE"):
            return "no pruned sweep (gcmh_core.sweep.PRUNE) at this commit"
    return None


@contextlib.contextmanager
def _sweep_mode(case: Case, tiny: bool):
    """The kernel cases take the plain sweep (commits before the pruned one have no other,
    and the pruned sweep's kernel time overlaps its threads'); the pruned sweep also on a
    tiny grid when warming (it starts at 2^16 cubes): its kernels get compiled.  Commits
    without `sweep.PRUNE` run as they are."""
    try:
        from gcmh_core import sweep
    except ImportError:
        sweep = None
    mode = False if case.kind == "kernel" else (True if tiny and case.kind == "prune" else None)
    if sweep is None or not hasattr(sweep, "PRUNE") or mode is None:
        yield
        return
    saved, sweep.PRUNE = sweep.PRUNE, mode
    try:
        yield
    finally:
        sweep.PRUNE = saved


def _limit_memory() -> None:
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def warm(spec: dict) -> dict:
    """Every case once on a tiny grid: numba compiles into the tree's cache; returns
    {case: None, or why the commit can't run it}."""
    _limit_memory()
    _import_tree(spec["tree"])
    out = {}
    for name in spec["cases"]:
        case = CASES[name]
        why = _needs(case)
        if why is None:
            try:
                with _sweep_mode(case, tiny=True):
                    _call(case, tiny=True)()
            except Exception as e:  # noqa: BLE001 (MemoryError included): the commit lacks what the case needs
                why = f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}"[:160]
        out[name] = why
    _check_tree(spec["tree"])
    return out


def measure(spec: dict) -> dict:
    """One case at one commit: the first call (fresh), then `repeat` timed calls."""
    _limit_memory()
    import_s = _import_tree(spec["tree"])
    sys.path.insert(0, HERE)
    from bench_prune import digest

    case = CASES[spec["case"]]
    run = _call(case, unchecked=bool(spec.get("unchecked")))
    values = []
    # --cpu: one thread, the whole call's CPU seconds (a loaded machine's preemption is not counted)
    clock = time.process_time if spec.get("cpu") else time.perf_counter
    with _sweep_mode(case, tiny=False):
        t = time.perf_counter()
        cx = run()
        first_s = time.perf_counter() - t
        if case.kind == "waves":
            cx, replay, cubes = _recorded_kernel(run)
            replay()  # (the first replay's memory faults are not the kernel's)
        for _ in range(case.repeat):
            t = clock()
            if case.kind == "waves":
                replay()
                values.append(1e6 * (clock() - t) / cubes)
                continue
            cx = run()
            seconds = clock() - t
            if case.kind == "kernel":
                cubes = cx.meta.get("candidate_cubes") or 0
                spent = seconds if spec.get("cpu") else cx.meta["timings"]["kernel"]
                values.append(1e6 * spent / cubes if cubes else float("nan"))
            else:
                values.append(seconds)
    _check_tree(spec["tree"])
    return dict(case=spec["case"], side=spec["side"], round=spec["round"], value=min(values), values=values,
                fresh=import_s + first_s, hash=digest(cx), pruned_cubes=cx.meta.get("pruned_cubes"),
                timings={key: round(v, 4) for key, v in cx.meta.get("timings", {}).items()})


# ----------------------------------------------------------------------------- the comparison (parent)
def summarize(results: list[dict], cases: list[str], skipped: dict | None = None) -> list[dict]:
    """One row per case from the processes' results ({case, side 'A'/'B', round, value,
    fresh, hash} or {case, side, round, error}): medians per side, the ratio of the medians,
    the pairs' ratios (rounds where both sides have a value), how many pairs B was slower in."""
    skipped = skipped or {}
    rows = []
    for name in cases:
        mine = [r for r in results if r["case"] == name]
        row = dict(case=name, unit=UNITS[CASES[name].kind])
        notes = [f"{side}: {why}" for side, why in sorted(skipped.get(name, {}).items()) if why]
        notes += [f"{r['side']} round {r['round']}: {r['error']}" for r in mine if "error" in r]
        row["note"] = "; ".join(notes)
        for key in ("value", "fresh"):
            by = {side: {r["round"]: r[key] for r in mine if r["side"] == side and key in r} for side in "AB"}
            a, b = by["A"], by["B"]
            pairs = [b[i] / a[i] for i in sorted(set(a) & set(b)) if a[i] > 0]
            med_a = statistics.median(a.values()) if a else None
            med_b = statistics.median(b.values()) if b else None
            row[key] = dict(a=med_a, b=med_b, ratio=med_b / med_a if med_a and med_b is not None else None,
                            lo=min(pairs) if pairs else None, hi=max(pairs) if pairs else None,
                            slower=sum(p > 1 for p in pairs), pairs=len(pairs))
        hashes = {side: {r["hash"] for r in mine if r["side"] == side and "hash" in r} for side in "AB"}
        same = hashes["A"] == hashes["B"] and len(hashes["A"]) == 1
        row["same_output"] = same if hashes["A"] and hashes["B"] else None
        rows.append(row)
    return rows


def _num(x, unit: str) -> str:
    if x is None:
        return "-"
    return f"{x:.2f}" if unit == "us/cube" or x >= 10 else f"{x:.3f}"


def format_table(rows: list[dict], fresh: bool = False) -> str:
    lines = ["| case | unit | A median | B median | B/A | pairs' B/A (min-max) | B slower in | output | note |",
             "|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        measured = row["fresh"]["a"] is not None or row["fresh"]["b"] is not None
        keys = ("value", "fresh") if fresh and measured else ("value",)
        for key in keys:
            s, unit = row[key], row["unit"] if key == "value" else "s, fresh"
            name = row["case"] if key == "value" else f"{row['case']} (process)"
            ratio = "-" if s["ratio"] is None else f"{s['ratio']:.2f}"
            spread = "-" if s["lo"] is None else f"{s['lo']:.2f}-{s['hi']:.2f}"
            slower = f"{s['slower']}/{s['pairs']}" if s["pairs"] else "-"
            same = {True: "same", False: "differs", None: "-"}[row["same_output"]]
            lines.append(f"| {name} | {unit} | {_num(s['a'], unit)} | {_num(s['b'], unit)} | {ratio} | {spread} "
                         f"| {slower} | {same} | {row['note'] if key == 'value' else ''} |")
    return "\n".join(lines)


def _git(*args: str, cwd: str) -> str:
    return subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True, text=True).stdout.strip()


@contextlib.contextmanager
def checkout(repo: str, rev: str):
    """(tree folder, label, numba cache dir or None): the working tree itself, or the commit
    unpacked into a temporary folder, removed afterwards.  The folder is named after the
    commit and its numba cache kept under ~/.cache, so a later comparison of the same commit
    loads its kernels instead of compiling them (numba keys its cache by the source's path
    and mtime, and git archive gives every file the commit's time); a second comparison
    running at once takes a folder of its own."""
    if rev == WORKTREE:
        yield repo, WORKTREE, None
        return
    sha = _git("rev-parse", "--verify", f"{rev}^{{commit}}", cwd=repo)
    base = os.path.join(tempfile.gettempdir(), f"gcmh-compare-{os.getuid()}")
    os.makedirs(base, exist_ok=True)
    lock = open(os.path.join(base, f"{sha}.lock"), "w")  # (held until the end)
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        tree = os.path.join(base, sha)
        shutil.rmtree(tree, ignore_errors=True)
        os.makedirs(tree)
    except BlockingIOError:
        tree = tempfile.mkdtemp(prefix=f"{sha[:12]}-", dir=base)
    cache = os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "gcmh-compare")
    try:
        archive = subprocess.Popen(["git", "archive", sha], cwd=repo, stdout=subprocess.PIPE)
        subprocess.run(["tar", "-x", "-C", tree], stdin=archive.stdout, check=True)
        archive.stdout.close()
        if archive.wait() != 0:
            raise SystemExit(f"git archive {sha} failed")
        yield tree, sha[:12], cache
    finally:
        shutil.rmtree(tree, ignore_errors=True)
        lock.close()


def _child(mode: str, spec: dict, tree: str, cache: str | None, timeout: float) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "GCMH_EXAMPLES_DIR", "NUMBA_CACHE_DIR")}
    env["PYTHONPATH"] = tree
    if spec.get("cpu"):
        env["NUMBA_NUM_THREADS"] = "1"
    if cache:
        env["NUMBA_CACHE_DIR"] = cache
    cmd = [sys.executable, os.path.abspath(__file__), mode, json.dumps(dict(spec, tree=tree))]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, cwd=tree, env=env, timeout=timeout)
    except subprocess.TimeoutExpired:
        return dict(error=f"killed after {timeout:.0f} s")
    if proc.returncode != 0:
        lines = proc.stderr.strip().splitlines()
        return dict(error=lines[-1] if lines else f"exit {proc.returncode}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python tests/bench/compare_commits.py", description=__doc__.splitlines()[0])
    ap.add_argument("rev_a", metavar="REV_A")
    ap.add_argument("rev_b", metavar="REV_B", nargs="?", default=WORKTREE,
                    help=f"a commit, or '{WORKTREE}' (the default): the working tree as it is")
    ap.add_argument("--rounds", type=int, default=None,
                    help="pairs of processes per case (default 5, the expensive cases 3; --quick 3)")
    ap.add_argument("--cases", default=None, help="comma-separated, from: " + ", ".join(CASES))
    ap.add_argument("--quick", action="store_true", help=f"{', '.join(QUICK)}; 3 rounds")
    ap.add_argument("--fresh", action="store_true", help="also print each process's import + first call")
    ap.add_argument("--json", help="write every process's result here")
    ap.add_argument("--cpu", action="store_true",
                    help="one thread, CPU seconds of the whole call (kernel cases: CPU us per candidate cube of the "
                    "whole run): steadier than wall time on a loaded machine")
    ap.add_argument("--unchecked", action="store_true",
                    help="both sides with check_cells=False where extract has it (the cell check is on by default "
                    "since issue 25; the commits before ran without it)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds a process may take")
    args = ap.parse_args(argv)
    cases = args.cases.split(",") if args.cases else list(QUICK if args.quick else CASES)
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        ap.error(f"unknown case(s) {', '.join(unknown)}; choose from {', '.join(CASES)}")
    rounds = args.rounds or (3 if args.quick else 5)
    repo = _git("rev-parse", "--show-toplevel", cwd=HERE)  # (the repository of this script)
    t0 = time.perf_counter()
    with checkout(repo, args.rev_a) as (tree_a, label_a, cache_a), \
            checkout(repo, args.rev_b) as (tree_b, label_b, cache_b):
        trees = {"A": (tree_a, cache_a), "B": (tree_b, cache_b)}
        skipped: dict[str, dict[str, str | None]] = {name: {} for name in cases}
        for side, (tree, cache) in trees.items():
            print(f"# warming {side} ({tree}) ...", file=sys.stderr, flush=True)
            res = _child("--warm", dict(cases=cases), tree, cache, timeout=max(args.timeout, 900.0))
            for name in cases:
                skipped[name][side] = res.get("error") or res.get(name)
        results = []
        for i in range(rounds):
            for name in cases:
                cap = CASES[name].max_rounds if args.rounds is None else None  # (--rounds says it for all)
                if any(skipped[name].values()) or i >= (cap or rounds):
                    continue
                for side, (tree, cache) in trees.items():
                    spec = dict(case=name, side=side, round=i, cpu=args.cpu, unchecked=args.unchecked)
                    res = _child("--measure", spec, tree, cache, args.timeout)
                    results.append(dict(spec, **res))
                    print(f"# round {i + 1}/{rounds} {name} {side}: {res.get('value', res.get('error'))}",
                          file=sys.stderr, flush=True)
    rows = summarize(results, cases, skipped)
    sys.path.insert(0, HERE)
    from bench import machine

    # (by the commits compared: a branch name may have moved on meanwhile)
    subject = {lab: "the working tree" if lab == WORKTREE else _git("log", "-1", "--format=%h %cs %s", lab, cwd=repo)
               for lab in (label_a, label_b)}
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"# {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, {machine()}, load {load} (at the end), "
          f"{time.perf_counter() - t0:.0f} s")
    print(f"# A = {subject[label_a]}\n# B = {subject[label_b]}")
    print(f"# python tests/bench/compare_commits.py {' '.join(argv if argv is not None else sys.argv[1:])}")
    if args.cpu:
        print("# --cpu: NUMBA_NUM_THREADS=1, CPU seconds of the whole call (kernel cases: per candidate cube)")
    print(format_table(rows, fresh=args.fresh))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(dict(a=label_a, b=label_b, rounds=rounds, skipped=skipped, results=results), fh, indent=1)
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] in ("--warm", "--measure"):
        print(json.dumps((warm if sys.argv[1] == "--warm" else measure)(json.loads(sys.argv[2]))))
        sys.exit(0)
    sys.exit(main())
