"""A first run on a new install (issue 18, item 3): what a plain GCMH run compiles.

One child process extracts a curve in R^4 (the general cube kernel) with numba's
cache pointed at an empty folder, and records numba's compile events; a second child
does the same on the cache the first one filled.  (Speed is measured in
tests/bench/bench_first_run.py, never here.)
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

# Runs in the children: the run, the kernels numba compiled (module, name, argument
# types), whether each was a literal type, and how often compile_notice called back.
CHILD = r"""
import json, sys
from numba.core import event, types
import gcmh_core
from gcmh_core import compile_notice

compiled = []

class Record(event.Listener):
    def on_start(self, ev):
        func = ev.data["dispatcher"].py_func
        args = ev.data["args"]
        compiled.append(dict(module=func.__module__, name=func.__qualname__,
                             literal=any(isinstance(a, types.Literal) for a in args),
                             args=[str(a) for a in args]))
    def on_end(self, ev):
        pass

event.register("numba:compile", Record())
notices = []
with compile_notice(lambda: notices.append(1)):
    cx = gcmh_core.extract(["x1^2 + x2^2 + x3^2 + x4^2 - 1", "x1 - x2"], bounds=(-1.2, 1.2), div=3,
                           variables="x1,x2,x3,x4")
print(json.dumps(dict(compiled=compiled, notices=len(notices), modules=sorted(sys.modules),
                      chi=cx.euler_characteristic())))
"""


def _child(cache: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    proc = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, env=env, timeout=900)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> tuple[dict, dict]:
    """(the cold run, the warm run after it), on a numba cache of their own."""
    cache = str(tmp_path_factory.mktemp("numba-cache"))
    return _child(cache), _child(cache)


def _ours(compiled: list[dict]) -> list[dict]:
    return [c for c in compiled if c["module"].startswith("gcmh_core.")]


def test_the_cold_run_compiles_and_says_so_once(runs):
    cold, _ = runs
    assert cold["chi"] == 2  # the unit 3-sphere cut by a hyperplane: a 2-sphere
    names = {c["name"] for c in _ours(cold["compiled"])}
    assert {"cubes_chunk", "plane_codes", "scan_candidates"} <= names
    assert cold["notices"] == 1


def test_each_kernel_compiles_once_and_never_for_a_literal(runs):
    cold, _ = runs
    ours = _ours(cold["compiled"])
    assert [c for c in ours if c["literal"]] == []
    seen = [(c["module"], c["name"], tuple(c["args"])) for c in ours]
    assert len(seen) == len(set(seen))
    # one signature per kernel, but for the growing buffers of float and int rows
    per_kernel: dict = {}
    for module, name, _args in seen:
        per_kernel[module, name] = per_kernel.get((module, name), 0) + 1
    twice = {key: count for key, count in per_kernel.items() if count > 1}
    assert twice == {("gcmh_core.kernels.records", "_grown_rows"): 2}


def test_a_plain_gcmh_run_needs_no_simplicial_continuation_or_cluster_code(runs):
    cold, _ = runs
    names = {c["name"] for c in _ours(cold["compiled"])}
    assert not names & {"simplices_chunk", "facet_neighbours", "corner_sets_to_candidates", "_insert"}
    assert "gcmh_core.distributed" not in cold["modules"]
    assert "gcmh_core.complex_equations" not in cold["modules"]
    assert not any(m == "dask" or m.startswith("dask.") for m in cold["modules"])


def test_the_warm_run_loads_everything_from_the_cache_silently(runs):
    _, warm = runs
    assert warm["chi"] == 2
    assert _ours(warm["compiled"]) == []
    assert warm["notices"] == 0
