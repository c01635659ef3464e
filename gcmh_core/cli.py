"""Command line interface: ``gcmh examples`` and ``gcmh extract``.

Examples::

    gcmh examples
    gcmh extract --example complex-cosine --json
    gcmh extract --example klein-bottle --div 16 -o klein.npz --vtu klein.vtu
    gcmh extract --f "x**2 + y**2 + z**2 - 1" --vars x,y,z --bounds -1.5:1.5 --div 24
    gcmh extract --f "x1**2 + x2**2 - 1/2" --f "x3**2 + x4**2 - 1/2" --bounds -1:1,-1:1,-1:1,-1:1
    gcmh extract --example complex-cosine --div 160 --scheduler local
    gcmh extract --example three-torus --div 12 --scheduler tcp://10.0.0.5:8786 --block 6
    gcmh extract --example sphere --div 200 --dry-run     # the estimate only
    gcmh extract --example sphere -o - > sphere.npz       # the .npz on standard output
    gcmh extract --example hyperboloid --param a=-0.3     # a parameter's value (repeatable)
    gcmh extract --complex --f "z^2 = w" --vars z,w --div 16   # equations over C^m
    gcmh extract --data scan.nii.gz --level 400 --vtu scan.vtu  # an isosurface of your own data
    gcmh extract --data u.npy --data v.npy --level 0.5,0 # two fields: where both meet their levels

Exit status: 0 on success, 2 for bad input or a run that would not fit (one line
on stderr, nothing written; --force runs it anyway), 1 when an output file cannot
be written or no examples are found, 130 when interrupted (Ctrl-C), 143 when
terminated (SIGTERM).  Outputs are checked before the run and replaced atomically:
an interrupted run leaves the old files as they were and no temporary file.
"""

from __future__ import annotations

import _thread
import argparse
import contextlib
import json
import math
import os
import signal
import stat
import sys
import threading
from collections.abc import Sequence

from .errors import InputError
from .safe_io import AtomicFile, check_output

# Nothing heavy is imported here: the engine (numba, sympy) is imported inside main(),
# after the signal handlers are in place, so Ctrl-C while it loads ends in one line too.

PROG = "gcmh"

# Options whose value may start with "-" (a negative bound, a formula "-x + 1").
_GLUE_OPTIONS = ("--bounds", "--start", "--f", "-f", "--formula", "--param")


class _UsageError(Exception):
    """An argparse error, turned into one line on stderr and exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse hook
        raise _UsageError(message)


def _glue_values(argv: Sequence[str]) -> list[str]:
    """``--bounds -1.5:1.5`` -> ``--bounds=-1.5:1.5`` so argparse takes it as a value."""
    out: list[str] = []
    i = 0
    argv = list(argv)
    while i < len(argv):
        arg = argv[i]
        if (
            arg in _GLUE_OPTIONS
            and i + 1 < len(argv)
            and argv[i + 1].startswith("-")
            and not argv[i + 1].startswith("--")
            and argv[i + 1] != "-"
        ):
            # "--bounds=-1:1" for long options, "-f-x" for the short one
            out.append(f"{arg}={argv[i + 1]}" if arg.startswith("--") else f"{arg}{argv[i + 1]}")
            i += 2
            continue
        out.append(arg)
        i += 1
    return out


def _build_parser() -> _Parser:
    from .extract import METHODS

    parser = _Parser(
        prog=PROG,
        description="Extract implicit manifolds F^-1(0), F: R^n -> R^k, as cell complexes (GCMH).",
        allow_abbrev=False,
    )
    from . import __version__

    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p_ex = sub.add_parser(
        "examples", help="list the example manifolds", allow_abbrev=False,
        description="List the example manifolds (name, n, k, title).",
    )
    p_ex.add_argument("--json", action="store_true", help="print a JSON list instead of a table")

    p = sub.add_parser(
        "extract",
        help="extract a manifold and print a summary",
        allow_abbrev=False,
        description=(
            "Extract M = F^-1(0) from an example (--example NAME) or from formulas "
            "(--f EXPR, once per component). Bounds may use pi: --bounds -pi/2:pi/2."
        ),
    )
    src = p.add_argument_group("what to extract")
    src.add_argument("--example", metavar="NAME", help="an example name (see `gcmh examples`)")
    src.add_argument(
        "--data", action="append", metavar="FILE[:NAME,...]",
        help="sampled values from a file, one component of F each (repeat for k components): .npy, "
        "file.npz:NAME, .vti, .vtk, .nrrd, .mha, .nii, .nii.gz, file.h5:/PATH; bounds from the file",
    )
    src.add_argument(
        "--level", metavar="C[,C2,...]",
        help="with --data: M is where each component equals its level (one for all, or one per component; "
        "default 0)",
    )
    src.add_argument(
        "--components", action="store_true",
        help="with --data: the last axis of each array holds components of F, not a grid axis",
    )
    src.add_argument(
        "--f", "-f", "--formula", dest="formulas", action="append", metavar="EXPR",
        help="one component of F (repeat for k components), e.g. --f 'x**2 + y**2 - 1'",
    )
    src.add_argument("--vars", metavar="X1,...,XN", help="variable names (default x1..xn)")
    src.add_argument(
        "--param", dest="params", action="append", metavar="NAME=VALUE",
        help="value of a parameter of the formulas (repeat for each), e.g. --param a=0.3 or --param 'c=pi/4'",
    )
    src.add_argument(
        "--complex", action="store_true",
        help="each --f is an equation over C^m ('z^2 = w'; i is the imaginary unit) and --vars names the "
        "complex variables; solved as the real system of Re and Im parts (real variables z_re, z_im, ...; "
        f"bounds default to {-2}:{2})",
    )
    src.add_argument("--n", type=str, metavar="N", help="number of variables when --vars is omitted")
    src.add_argument(
        "--bounds", metavar="LO:HI[,LO:HI...]",
        help="domain box: one LO:HI for every axis, or one per axis; entries may use pi",
    )
    grid = p.add_argument_group("grid and method")
    grid.add_argument("--div", metavar="D|D1,...,DN", help="divisions per axis (default: the example's, else 10)")
    grid.add_argument(
        "--seed", metavar="S", default="0",
        help="seed of the grid perturbation: any non-negative integer (default 0)",
    )
    grid.add_argument(
        "--method", default="gcmh", metavar="|".join(METHODS),
        help="gcmh: every grid cube (default); gcch: continuation from --start; "
        "cms, ccs: the paper's simplicial baselines (whole grid, continuation)",
    )
    grid.add_argument("--start", metavar="X1,...,XN|auto", help="start point on M (continuation methods), or auto")
    grid.add_argument(
        "--periodic", action="append", metavar="NAME[:flip=A,B]|none",
        help="glue the domain along an angle (repeat for each): --periodic t makes t a circle, "
        "--periodic s:flip=t also reverses t across the seam of s (the closed Klein bottle: "
        "--periodic s:flip=t --periodic t); 'none' cuts an example's glued domain open",
    )
    dist = p.add_argument_group("on a dask cluster (pip install gcmh[cluster])")
    dist.add_argument(
        "--scheduler", metavar="local|tcp://HOST:PORT",
        help="run on dask: 'local' starts a cluster on this machine; an address uses a running `dask scheduler`",
    )
    dist.add_argument(
        "--block", metavar="B|B1,...,BN", help="cubes per block along each axis (default: sized to the workers)"
    )
    out = p.add_argument_group("output")
    out.add_argument(
        "-o", "--output", metavar="OUT.npz",
        help="save the cell complex (.npz, gcmh-complex/1; '-' writes it to standard output)",
    )
    out.add_argument("--vtu", metavar="OUT.vtu", help="save the cell complex as a VTK unstructured grid")
    out.add_argument(
        "--section", metavar="VAR=C",
        help="cut the result by the hyperplane VAR = C (C a constant: 0.5, -pi/4): -o and --vtu write the "
        "section, a complex of one dimension less, and the summary describes it too (gcmh_core.section)",
    )
    out.add_argument("--json", action="store_true", help="print one JSON object instead of a summary")
    out.add_argument(
        "--homology", action="store_true",
        help="also compute the homology: Betti numbers over Q and Z/2 and torsion (gcmh_core.homology)",
    )
    out.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.add_argument(
        "--check-cells", action="store_true",
        help="check every cube's cells against CMS's Euler characteristic (n = 3..7): by default only the "
        "cubes where a cell can be wrong are (those a certificate can't show to be a graph over a face)",
    )
    p.add_argument(
        "--confirm", action="store_true",
        help="repeat the run on a second grid (the next seed, 1.5 times the div) and say whether the Euler "
        "characteristic, pieces and boundary agree (formulas only)",
    )
    guard = p.add_argument_group("before the run")
    guard.add_argument(
        "--dry-run", action="store_true",
        help="print the estimated memory and time of the run (with --json: as JSON) and stop",
    )
    guard.add_argument(
        "--force", action="store_true",
        help="run even when the estimate exceeds the available memory or five minutes "
        "(limits: $GCMH_MEMORY_LIMIT, $GCMH_TIME_LIMIT seconds)",
    )
    return parser


# --------------------------------------------------------------------------
# Argument parsing helpers (each raises InputError with a one-line message)
# --------------------------------------------------------------------------


def _parse_int(text: str, what: str, minimum: int | None = None) -> int:
    try:
        value = int(str(text).strip())
    except ValueError:
        raise InputError(f"{what} must be an integer, got {text!r}") from None
    if minimum is not None and value < minimum:
        raise InputError(f"{what} must be at least {minimum}, got {value}")
    return value


def _parse_per_axis(text: str, flag: str, n: int | None) -> int | list[int]:
    """`flag D` or `flag D1,...,Dn`: one positive integer, or one per axis."""
    parts = str(text).split(",")
    if any(not s.strip() for s in parts):
        letter = flag.lstrip("-")[0].upper()
        raise InputError(f"{flag}: expected {letter} or {letter}1,...,{letter}n, got {text!r}")
    values = [_parse_int(s, flag, minimum=1) for s in parts]
    if len(values) == 1:
        return values[0]
    if n is not None and len(values) != n:
        raise InputError(f"{flag}: got {len(values)} values for n = {n} variables (give 1 or {n})")
    return values


def _parse_scheduler(text: str) -> str:
    from .distributed import check_scheduler  # (dask itself is imported only to run)

    try:
        return check_scheduler(text)
    except InputError as err:
        raise InputError(f"--scheduler: {err}") from None


def _parse_bounds(text: str) -> list[tuple[float, float]]:
    from .examples import evaluate_constant

    pairs = []
    items = str(text).split(",")
    for i, item in enumerate(items, start=1):
        if item.count(":") != 1:
            raise InputError(f"--bounds: expected LO:HI[,LO:HI,...], got {item.strip()!r} in {text!r}")
        lo_text, hi_text = item.split(":")
        try:
            lo, hi = evaluate_constant(lo_text), evaluate_constant(hi_text)
        except InputError as err:
            raise InputError(f"--bounds: {err}") from None
        if not lo < hi:
            where = f"interval {i}" if len(items) > 1 else "interval"
            raise InputError(
                f"--bounds: lower bound {lo:g} must be below upper bound {hi:g} ({where} {item.strip()!r})"
            )
        pairs.append((lo, hi))
    return pairs


def _parse_vars(text: str) -> list[str]:
    names = [s.strip() for s in str(text).split(",")]
    for name in names:
        if not name.isidentifier():
            raise InputError(f"--vars: {name!r} is not a valid variable name")
    if len(set(names)) != len(names):
        raise InputError(f"--vars: repeated variable name in {text!r}")
    return names


def _parse_start(text: str, n: int):
    from .examples import evaluate_constant

    if str(text).strip().lower() == "auto":
        return "auto"
    parts = str(text).split(",")
    if len(parts) != n:
        raise InputError(f"--start: expected {n} coordinates (or auto), got {len(parts)}")
    try:
        return [evaluate_constant(s) for s in parts]
    except InputError as err:
        raise InputError(f"--start: {err}") from None


STDOUT = "-"


def _check_output(path: str, option: str) -> str:
    """`path` checked before the run (InputError); '-' for -o is standard output."""
    if path == STDOUT and option == "-o":
        if _isatty(sys.stdout):
            raise InputError("-o -: standard output is a terminal; redirect it to a file or a pipe")
        return STDOUT
    if path == STDOUT:
        raise InputError(f"{option} -: only the .npz (-o -) can go to standard output; give {option} a file name")
    try:
        check_output(path, option)
    except InputError as err:
        if option == "-o" and _is_special(path):
            raise InputError(f"{err}; use -o - to write the .npz to standard output") from None
        raise
    return path


def _is_special(path: str) -> bool:
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


# --------------------------------------------------------------------------
# Commands
# --------------------------------------------------------------------------


def _cmd_examples(args) -> int:
    from .examples import list_examples

    examples = list_examples(on_error=lambda name, err: print(f"{PROG}: warning: example {name!r} left out: "
                                                             f"{_one_line(str(err))}", file=sys.stderr))
    if not examples:
        where = os.environ.get("GCMH_EXAMPLES_DIR")
        return _fail(f"no examples found{f' in {where!r} (GCMH_EXAMPLES_DIR)' if where else ''}", status=1)
    if args.json:
        print(json.dumps([{"name": e.name, "n": e.n, "k": e.k, "title": e.title, "params": e.params,
                           "complex": e.complex} for e in examples], indent=1))
        return 0
    width = max(len(e.name) for e in examples)
    print(f"{'name':<{width}}  {'n':>2} {'k':>2}  title")
    for e in examples:
        params = "".join(f"; {p} = {v['value']:g} in [{v['min']:g}, {v['max']:g}]" for p, v in e.params.items())
        print(f"{e.name:<{width}}  {e.n:>2} {e.k:>2}  {e.title}{params}")
    return 0


def _data_job(args) -> dict:
    """The job of ``--data``: the files are read when the run starts (`data_files.extract_data`)."""
    from .data_files import parse_levels

    given = [flag for flag, value in (("--example", args.example), ("--f", args.formulas), ("--n", args.n),
                                      ("--param", args.params), ("--complex", args.complex),
                                      ("--div", args.div), ("--periodic", args.periodic)) if value]
    if given:
        why = "the grid is the data's" if given[0] == "--div" else "F is the data minus the level"
        raise InputError(f"{given[0]} does not go with --data ({why})")
    levels = parse_levels(args.level)
    variables = _parse_vars(args.vars) if args.vars is not None else None
    bounds = _parse_bounds(args.bounds) if args.bounds is not None else None
    method = args.method.strip().lower()
    scheduler = _parse_scheduler(args.scheduler) if args.scheduler is not None else None
    block = _parse_per_axis(args.block, "--block", None) if args.block is not None else None
    if block is not None and scheduler is None:
        raise InputError("--block is the block size of a cluster run: give --scheduler too")
    start = None
    if args.start is not None:
        start = "auto" if args.start.strip().lower() == "auto" else args.start
    return dict(name=None, n=None, k=None, F=None, bounds=bounds, div=None, variables=variables,
                seed=_parse_int(args.seed, "--seed", minimum=0), method=method, start=start, scheduler=scheduler,
                block=block, params=None, periodic=None, title=None,
                data=dict(specs=list(args.data), levels=levels, components=True if args.components else None))


def _job_from_args(args) -> dict:
    """Validate the extract arguments; return the keyword arguments of extract()."""
    if args.data:
        return _data_job(args)
    if args.level is not None or args.components:
        raise InputError(f"{'--level' if args.level is not None else '--components'} goes with --data FILE")
    if args.example and args.formulas:
        raise InputError("use either --example or --f, not both")
    if not args.example and not args.formulas:
        raise InputError("nothing to extract: give --example NAME, --f EXPR or --data FILE (see gcmh examples)")

    n_opt = _parse_int(args.n, "--n", minimum=1) if args.n is not None else None
    if n_opt is not None:
        from ._validate import check_n

        check_n(n_opt)   # (before n names, bounds or anything else of n entries is made)
    bounds = _parse_bounds(args.bounds) if args.bounds is not None else None
    from ._validate import parse_params  # (numpy: after main() has installed the signal handlers)

    params = parse_params(args.params)
    if args.complex and args.example:
        raise InputError("--complex goes with --f (an example says itself whether it is complex)")

    if args.example:
        from .examples import load_example

        if args.vars is not None or args.n is not None:
            raise InputError("--vars and --n go with --f, not with --example")
        ex = load_example(args.example)
        n, variables, formulas = ex.n, list(ex.variables), list(ex.formulas)
        if ex.params:
            params = {**ex.param_values(), **(params or {})}
        if bounds is None:
            bounds = list(ex.bounds)
        div = ex.div
        from .extract import CONTINUATION_METHODS

        periodic = list(ex.periodic) or None
        start: list[float] | str | None = ex.start if args.method.strip().lower() in CONTINUATION_METHODS else None
        if start is not None and params != (ex.param_values() or None):
            start = "auto"  # (the example's start point lies on M at its default values only)
        name = ex.name
    elif args.complex:
        from .complex_equations import DEFAULT_BOUNDS, split_complex

        if args.vars is None:
            raise InputError("--complex needs --vars: the complex variables, e.g. --vars z,w")
        if args.n is not None:
            raise InputError("--n does not go with --complex: --vars names the complex variables")
        formulas, variables, _ = split_complex(list(args.formulas), _parse_vars(args.vars),
                                               allow_parameters=params is not None)
        n = len(variables)
        if bounds is None:
            bounds = [DEFAULT_BOUNDS]
        div = 10
        start = None
        name = None
        periodic = None
    else:
        formulas = list(args.formulas)
        if args.vars is not None:
            variables = _parse_vars(args.vars)
            n = len(variables)
            if n_opt is not None and n_opt != n:
                raise InputError(f"--n {n_opt} does not match the {n} names in --vars")
        else:
            if n_opt is not None:
                n = n_opt
            elif bounds is not None and len(bounds) > 1:
                n = len(bounds)
            else:
                raise InputError("how many variables? give --vars x,y,... or --n N (or one LO:HI per axis in --bounds)")
            variables = [f"x{i}" for i in range(1, n + 1)]
        if bounds is None:
            raise InputError("--bounds LO:HI[,LO:HI,...] is required with --f")
        div = 10
        start = None
        name = None
        periodic = None

    if args.periodic:
        items = [item.strip() for item in args.periodic]
        if "none" in items:
            if len(items) > 1:
                raise InputError("--periodic none cuts the domain open: it goes alone")
            periodic = None
        else:
            periodic = items
    if len(bounds) == 1:
        bounds = bounds * n
    elif len(bounds) != n:
        raise InputError(f"--bounds: got {len(bounds)} intervals for n = {n} variables (give 1 or {n})")
    if len(formulas) > n:
        raise InputError(f"{len(formulas)} formulas for n = {n} variables: need k <= n")
    if args.div is not None:
        div = _parse_per_axis(args.div, "--div", n)
    if args.start is not None:
        start = _parse_start(args.start, n)
    if periodic:  # (an example's glued axes again too: --div may have changed the grid)
        from ._validate import glued_axes

        periodic = glued_axes(periodic, variables, div)
    seed = _parse_int(args.seed, "--seed", minimum=0)
    method = args.method.strip().lower()
    scheduler = _parse_scheduler(args.scheduler) if args.scheduler is not None else None
    block = _parse_per_axis(args.block, "--block", n) if args.block is not None else None
    if block is not None and scheduler is None:
        raise InputError("--block is the block size of a cluster run: give --scheduler too")

    return dict(
        name=name,
        n=n,
        k=len(formulas),
        F=formulas,
        bounds=[(float(lo), float(hi)) for lo, hi in bounds],
        div=div,
        variables=variables,
        seed=seed,
        method=method,
        start=start,
        scheduler=scheduler,
        block=block,
        params=params,
        periodic=periodic,
        title=" ; ".join(args.formulas) + " over C" if args.complex else None,
    )


class _Progress:
    """tqdm bar on stderr fed by extract's progress(phase, fraction) callback."""

    def __init__(self, enabled: bool):
        self.bar = None
        if not enabled:
            return
        try:
            from tqdm import tqdm
        except ImportError:  # pragma: no cover - tqdm is a dependency
            return
        self.bar = tqdm(
            total=100,
            file=sys.stderr,
            delay=1.0,  # only for runs longer than about a second
            leave=False,
            dynamic_ncols=True,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}<{remaining}",
            desc="gcmh",
        )
        self.phase: str | None = None

    def __call__(self, phase: str, fraction: float) -> None:
        bar = self.bar
        if bar is None:
            return
        if phase != self.phase:
            self.phase = phase
            bar.set_description_str(str(phase), refresh=False)
        try:
            target = 100.0 * min(max(float(fraction), 0.0), 1.0)
        except (TypeError, ValueError):
            return
        delta = target - bar.n
        if delta >= 0:
            bar.update(delta)
        else:  # a new phase restarted at 0
            bar.n = target
            bar.last_print_n = target

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


COMPILE_NOTE = ("gcmh: first run: compiling the kernels, once per install (10-20 s; later runs load them "
                "from numba's cache)")


def _cmd_extract(args) -> int:
    job = _job_from_args(args)
    outputs = []
    if args.output is not None:   # (-o '' is an empty file name, said; not "no output")
        outputs.append(("npz", _check_output(args.output, "-o")))
    if args.vtu is not None:
        outputs.append(("vtu", _check_output(args.vtu, "--vtu")))
    files = [os.path.realpath(path) for _, path in outputs if path != STDOUT]
    if len(set(files)) < len(files):
        raise InputError(f"-o and --vtu name the same file ({args.vtu!r}): give each its own")
    if any(path == STDOUT for _, path in outputs) and args.json:
        raise InputError("-o - writes the .npz to standard output: it can't take --json too")
    if args.confirm and job.get("data"):
        raise InputError("--confirm repeats the run on a finer grid: it needs formulas, not sampled data")
    if args.section is not None:  # a bad VAR=C is refused before the run
        from .section import parse_section_spec

        parse_section_spec(args.section, job["variables"])
    if args.dry_run:
        return _dry_run(args, job)

    import gcmh_core

    # said when numba really compiles one of the kernels this run needs (not by looking for cache files:
    # which kernels a run needs depends on the run)
    notice = contextlib.nullcontext() if args.quiet else gcmh_core.compile_notice(
        lambda: print(COMPILE_NOTE, file=sys.stderr, flush=True))
    progress = _Progress(enabled=not args.quiet and _isatty(sys.stderr))
    try:
        with notice, _signals.held_while_numba_loads():
            if job.get("data"):
                cx = _extract_data(args, job, progress)
            else:
                cx = gcmh_core.extract(
                    job["F"],
                    job["bounds"],
                    job["div"],
                    variables=job["variables"],
                    seed=job["seed"],
                    method=job["method"],
                    start=job["start"],
                    progress=progress,
                    scheduler=job["scheduler"],
                    block=job["block"],
                    force=args.force,
                    params=job["params"],
                    periodic=job["periodic"],
                    check_cells=True if args.check_cells else None,
                )
    finally:
        progress.close()

    section = None
    if args.section is not None:
        from .section import section_summary

        section = section_summary(cx, args.section, job["variables"])
    _write_outputs(cx if section is None else section[0], outputs)
    summary = _summary(cx, job, outputs)
    if section is not None:
        summary["section"] = dict(section[1], line=section[2])
    if args.confirm:
        from .confirm import confirm

        summary["confirmation"] = confirm(
            job["F"], result=cx, variables=job["variables"], method=job["method"], start=job["start"],
            scheduler=job["scheduler"], force=args.force, params=job["params"], periodic=job["periodic"],
            check_cells=True if args.check_cells else None,
        ).as_dict()
    if args.homology:
        from .homology import summary as homology_summary

        try:
            summary["homology"] = homology_summary(cx)[0]
        except InputError as err:  # a cell that is not a ball: said; the run's outputs stand
            summary["homology"] = {"error": str(err)}
    report = sys.stderr if any(path == STDOUT for _, path in outputs) else sys.stdout
    if args.json:
        print(json.dumps(summary), file=report)
    else:
        print(_human(summary, job), file=report)
    return 0


def _extract_data(args, job, progress):
    from .data_files import extract_data

    d = job["data"]
    start = job["start"]
    if isinstance(start, str) and start != "auto":
        from .examples import evaluate_constant

        try:
            start = [evaluate_constant(s) for s in start.split(",")]
        except InputError as err:
            raise InputError(f"--start: {err}") from None
    return extract_data(d["specs"], d["levels"], job["bounds"], components=d["components"], variables=job["variables"],
                        seed=job["seed"], method=job["method"], start=start, progress=progress,
                        scheduler=job["scheduler"], block=job["block"], force=args.force,
                        check_cells=True if args.check_cells else None)


def _dry_run(args, job) -> int:
    from .budget import estimate
    from .formula import parse_system

    if job.get("data"):
        from .data_files import estimate_data

        d = job["data"]
        cost = estimate_data(d["specs"], d["levels"], job["bounds"], components=d["components"], method=job["method"],
                             scheduler=job["scheduler"])
        if args.json:
            print(json.dumps({**cost.as_dict(), "data": d["specs"]}))
        else:
            print(cost.describe() + " (grid: with F's values from " + ", ".join(d["specs"]) + ")"
                  + ("" if cost.fits else "; would be refused without --force"))
        return 0
    F = job["F"]
    if job["params"] is not None:  # (the estimate takes a System with the values in it)
        F = parse_system(F, job["variables"], params=job["params"])
    cost = estimate(
        F, job["bounds"], job["div"], variables=job["variables"], method=job["method"],
        scheduler=job["scheduler"], periodic=job["periodic"],
    )
    if args.json:
        print(json.dumps(cost.as_dict()))
    else:
        print(cost.describe() + ("" if cost.fits else "; would be refused without --force"))
    return 0


def _isatty(stream) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, OSError, ValueError):  # no such method, or a closed / detached stream
        return False


def _write_outputs(cx, outputs) -> None:
    """Write every output to a temporary file beside it, then move them all into place
    (signals held meanwhile, so the set is replaced whole).  On any failure or
    interrupt the temporaries go and the old files stay."""
    files = []
    try:
        for kind, path in outputs:
            if path == STDOUT:
                continue
            try:
                with _signals.held():  # (a temporary made is a temporary listed)
                    files.append(out := AtomicFile(path, f".{kind}", "-o" if kind == "npz" else "--vtu"))
                if kind == "npz":
                    with open(out.temp, "wb") as f:
                        cx.save(f)
                else:  # VTK crashed when a signal's exception was raised inside it; VTK's own file
                    # writer aborted on a full disk (free(): invalid pointer): it writes to memory, Python the file
                    with _signals.held(), open(out.temp, "wb") as f:
                        cx.save_vtu(f)
            except OSError as err:
                raise _WriteError(f"cannot write {path!r}: {err.strerror or err}") from None
            except ImportError as err:
                raise _WriteError(f"cannot write {path!r}: {err}") from None
        if any(path == STDOUT for _, path in outputs):
            try:
                cx.save(sys.stdout.buffer)
                sys.stdout.buffer.flush()
            except BrokenPipeError:
                raise _WriteError("standard output was closed before the .npz was written") from None
        with _signals.held():  # the set is replaced whole, then a signal counts
            for out in files:
                try:
                    out.commit()
                except OSError as err:
                    raise _WriteError(f"cannot write {out.path!r}: {err.strerror or err}") from None
    finally:
        with _signals.held():
            for out in files:
                out.discard()


class _WriteError(Exception):
    pass


def _as_int_list(value, n):
    try:
        if value is None:
            return None
        if isinstance(value, int) or getattr(value, "ndim", None) == 0:
            return [int(value)] * n
        return [int(v) for v in value]
    except (TypeError, ValueError):
        return None


def _summary(cx, job, outputs) -> dict:
    meta = getattr(cx, "meta", {}) or {}
    n, k = int(cx.n), int(cx.k)
    div = _as_int_list(meta.get("div"), n) or _as_int_list(job["div"], n)
    counts = [int(c) for c in cx.counts()]
    seconds = meta.get("seconds")
    return {
        "n": n,
        "k": k,
        "method": str(meta.get("method", job["method"])),
        "div": div,
        "seconds": float(seconds) if seconds is not None else None,
        "vertices": counts[0] if counts else 0,
        "cells": counts,
        "euler_characteristic": int(cx.euler_characteristic()),
        "boundary_facets": int(len(cx.boundary_facets())),
        "nonfinite_vertices": int(meta.get("nonfinite_vertices", 0) or 0),
        # events the kernels could not resolve (meta["degenerate"]): 0 on a trustworthy complex
        "degenerate": int(meta.get("degenerate", 0) or 0),
        # cells that are not balls (a tube through a cube gave GCMH one disc per end): cut into
        # discs for surfaces, refined by CMS for solids (`_balls`); what is left is wrong there
        "non_ball_cells": int(meta.get("non_ball_left", meta.get("non_ball_cells", 0)) or 0),
        "non_ball_split": int(meta.get("non_ball_split", 0) or 0),
        # whether every cube's cells were checked against CMS's Euler characteristic (n = 4..7)
        "cells_checked": bool(meta.get("cells_checked", False)),
        "halved_edges": int(meta.get("halved_edges", 0) or 0),
        "example": job["name"],
        "params": meta.get("params") or {},
        "singular_vertices": meta.get("singular_vertices"),
        # the critical points of M solved for (`critical`): [{"x": point, "rank": rank of J}]
        "critical_points": meta.get("critical_points") or [],
        # cubes checked against CMS (the others certified graphs over a face), and why a run's
        # topology is not checked (n >= 8, or the check turned off), else None
        "checked_cubes": int(meta.get("checked_cubes", 0) or 0),
        "topology_unchecked": meta.get("topology_unchecked"),
        # how a Dask run went (not saved in the .npz: distributed.RUN_META)
        "scheduler": meta.get("scheduler"),
        "workers": meta.get("workers"),
        "tasks": meta.get("tasks"),
        "blocks": meta.get("blocks"),
        "timings": meta.get("timings"),
        "files": {kind: str(path) for kind, path in outputs},
        # with --data: the files, each component's level and data range, the box, axis names and units
        "data": meta.get("data"),
    }


_CELL_NAMES = {0: "vertices", 1: "edges", 2: "faces"}


def _component_text(c: dict) -> str:
    """One component of F from data: "scan.nii = 400" or "flow.vti:v[1] = 0"."""
    part = "" if c["component"] is None else f"[{c['component']}]"
    return f"{c['source']}{part} = {c['level']:g}"


def _places(count: int) -> str:
    return "1 place" if count == 1 else f"{count} places"


def _human(s: dict, job: dict) -> str:
    dim = s["n"] - s["k"]
    if s.get("data"):
        what = " ; ".join(_component_text(c) for c in s["data"]["components"])
    else:
        what = job["name"] or job.get("title") or " ; ".join(job["F"])
    if s["params"]:
        what += " at " + ", ".join(f"{p} = {v:g}" for p, v in s["params"].items())
    div = "x".join(str(d) for d in s["div"]) if s["div"] else "?"
    if job.get("periodic"):
        div += ", glued " + " ".join(job["periodic"])
    cells = ", ".join(f"{c} {_CELL_NAMES.get(r, f'{r}-cells')}" for r, c in enumerate(s["cells"]))
    lines = [
        f"{what}: {dim}-manifold in R^{s['n']} (n={s['n']}, k={s['k']}), method {s['method']}, div {div}",
        f"  {cells}",
        f"  Euler characteristic {s['euler_characteristic']}, {s['boundary_facets']} boundary facets"
        + (f", {s['nonfinite_vertices']} non-finite vertices" if s["nonfinite_vertices"] else ""),
    ]
    if s.get("data"):
        d = s["data"]
        axes = ", ".join(f"{v} in [{lo:g}, {hi:g}]" + (f" {u}" if u else "")
                         for v, u, (lo, hi) in zip(d["variables"], d["units"], d["bounds"]))
        lines.append(f"  grid {'x'.join(map(str, d['shape']))} samples: {axes}")
        lines.extend(f"  note: {note}" for note in d["notes"])
    if s["degenerate"]:
        lines.append(f"  warning: {s['degenerate']} degenerate events the engine could not resolve "
                     "(cells there may be malformed): try another --seed")
    if s["non_ball_cells"]:
        how = "a finer --div" if s["n"] > 7 else "--method cms, or a finer --div"  # (CMS stops at n = 7)
        lines.append(f"  warning: at {_places(s['non_ball_cells'])} a piece of M inside a cube is not a ball, so the "
                     f"topology is wrong there: use {how}")
    if s["non_ball_split"]:
        # (where the cells are checked, a surface's cubes are refined too: `runner.split_non_ball_cells`)
        cut = s["n"] - s["k"] == 2 and not s["cells_checked"]
        how = "cut into discs" if cut else "replaced by the simplicial (CMS) cells of their cubes"
        # (where the check is partial, n >= 8, the cells found are mended; others may not have been found)
        so = "so those cells are balls now" if s["topology_unchecked"] else "so the topology is right"
        lines.append(f"  note: at {_places(s['non_ball_split'])} a piece of M inside a cube was not a ball; "
                     f"GCMH's cells there were {how}, {so}")
    if s["topology_unchecked"]:
        lines.append(f"  warning: the topology is not fully checked: {s['topology_unchecked']}")
    if s["singular_vertices"]:
        lines.append(f"  notice: F's Jacobian nearly loses rank at {s['singular_vertices']} vertices: "
                     "M is singular there, the parameters are at or near a critical value")
    for point in s["critical_points"]:
        where = ", ".join(f"{x:.4g}" for x in point["x"])
        lines.append(f"  notice: M has a critical point at ({where}), where F's Jacobian has rank {point['rank']} "
                     f"< {s['k']}")
    if "confirmation" in s:
        lines.append(f"  {s['confirmation']['message']}")
    if s.get("section"):
        lines.append(f"  {s['section']['line']}")
    if s.get("homology"):
        from .homology import summary_line

        lines.append(f"  {summary_line(s['homology'])}")
    seconds = s["seconds"]
    tail = f"  {seconds:.2f} s" if seconds is not None and math.isfinite(seconds) else "  done"
    if s["files"]:
        tail += ("; wrote the section to " if s.get("section") else "; wrote ") + ", ".join(s["files"].values())
    lines.append(tail)
    return "\n".join(lines)


def _one_line(message: str) -> str:
    return " ".join(part.strip() for part in str(message).splitlines() if part.strip())


def _fail(message: str, status: int = 2) -> int:
    print(f"{PROG}: error: {_one_line(message)}", file=sys.stderr)
    return status


class _Terminated(BaseException):
    """SIGTERM, raised where the program is (like KeyboardInterrupt for SIGINT), so that
    every `finally` runs: temporary files are removed, old outputs stay."""


class _Signals:
    """SIGINT -> KeyboardInterrupt, SIGTERM -> _Terminated, raised where the program is,
    once only (a second signal must not interrupt the cleanup), and held back while
    `held()`: inside it a signal is remembered and raised when it ends."""

    def __init__(self):
        self.hold = 0
        self.pending = None
        self.raised = False

    def handler(self, signum, frame):
        if self.raised:
            return
        if self.hold:
            self.pending = signum
            return
        self.fire(signum)

    def fire(self, signum):
        self.raised = True
        raise KeyboardInterrupt if signum == signal.SIGINT else _Terminated

    @contextlib.contextmanager
    def held(self):
        self.hold += 1
        try:
            yield
        finally:
            self.hold -= 1
            if not self.hold and self.pending is not None and not self.raised:
                self.fire(self.pending)

    def install(self) -> dict:
        previous = {}
        try:
            for sig in (signal.SIGINT, signal.SIGTERM):
                previous[sig] = signal.signal(sig, self.handler)
        except ValueError:  # not the main thread: leave the handlers alone
            pass
        return previous

    @contextlib.contextmanager
    def held_while_numba_loads(self):
        """Hold signals while numba holds its compiler lock (it loads a cached kernel or compiles
        one there): llvmlite calls back into Python through ctypes then, and a KeyboardInterrupt
        raised inside such a callback is printed and dropped, so the run went on to the end."""
        from ._config import numba_events  # (numba itself loads when the block starts)

        lock = threading.Lock()

        def locked(ev) -> None:
            with lock:
                self.hold += 1

        def released(ev) -> None:
            signum = None
            with lock:
                self.hold -= 1
                if not self.hold and not self.raised:
                    signum, self.pending = self.pending, None
            if signum is not None:  # raised in the main thread, at its next step outside numba
                _thread.interrupt_main(signum)

        with numba_events("numba:compiler_lock", locked, released):
            yield


_signals = _Signals()


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gcmh`` console script; returns the exit status."""
    if argv is None:
        argv = sys.argv[1:]
    global _signals
    _signals = _Signals()
    previous = _signals.install()
    try:
        return _main(argv)
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except _Terminated:
        print(f"{PROG}: terminated", file=sys.stderr)
        return 143
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def _main(argv: Sequence[str]) -> int:
    try:
        parser = _build_parser()
        args = parser.parse_args(_glue_values(argv))
        if args.command is None:
            return _fail("choose a command: examples or extract (see gcmh --help)")
        if args.command == "examples":
            return _cmd_examples(args)
        return _cmd_extract(args)
    except _UsageError as err:
        return _fail(str(err))
    except InputError as err:
        return _fail(str(err))
    except _WriteError as err:
        return _fail(str(err), status=1)
    except MemoryError:
        return _fail("out of memory: try a smaller --div", status=1)
    except BrokenPipeError:  # e.g. gcmh examples | head -1
        try:
            sys.stdout = open(os.devnull, "w")
        except OSError:
            pass
        return 0


if __name__ == "__main__":
    sys.exit(main())
