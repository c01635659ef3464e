"""The `gcmh` command line: listing, extraction, JSON, files, and one-line errors."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gcmh_core
from gcmh_core.cli import _glue_values, main
from gcmh_core.examples import example_names

REPO = Path(__file__).resolve().parents[2]
JSON_KEYS = {
    "n", "k", "method", "div", "seconds", "vertices", "cells",
    "euler_characteristic", "boundary_facets", "nonfinite_vertices",
}
SPHERE = ["extract", "--f", "x^2 + y^2 + z^2 - 1", "--vars", "x,y,z"]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_line_error(code, out, err):
    assert code == 2, (code, out, err)
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("gcmh: error: ")
    assert "Traceback" not in err
    assert out == ""


# ---------------------------------------------------------------- examples


def test_examples_lists_every_example(capsys):
    code, out, err = run(capsys, "examples")
    assert code == 0 and err == ""
    lines = out.splitlines()
    for name in example_names():
        line = next(row for row in lines if row.split()[0] == name)
        ex = gcmh_core.examples.load_example(name)
        assert line.split()[1:3] == [str(ex.n), str(ex.k)]
        assert ex.title in line


def test_examples_json(capsys):
    code, out, _ = run(capsys, "examples", "--json")
    assert code == 0
    data = json.loads(out)
    assert [d["name"] for d in data] == example_names()
    assert {"name", "n", "k", "title"} <= set(data[0])


# ---------------------------------------------------------------- argv glue


def test_glue_negative_values():
    assert _glue_values(["--bounds", "-1.5:1.5", "--div", "8"]) == ["--bounds=-1.5:1.5", "--div", "8"]
    assert _glue_values(["--start", "-1,0,0"]) == ["--start=-1,0,0"]
    assert _glue_values(["--f", "-x + 1", "-f", "-y"]) == ["--f=-x + 1", "-f-y"]
    assert _glue_values(["--bounds", "--json"]) == ["--bounds", "--json"]
    assert _glue_values(["--bounds", "0:1"]) == ["--bounds", "0:1"]


# ---------------------------------------------------------------- bad input


BAD = {
    "unknown example": ["extract", "--example", "no-such-manifold"],
    "bad formula": ["extract", "--f", "x^2 +* y", "--vars", "x,y,z", "--bounds", "-1:1"],
    "unknown name in formula": ["extract", "--f", "sinn(x) + y + z", "--vars", "x,y,z", "--bounds", "-1:1"],
    "bad bounds": [*SPHERE, "--bounds", "-1.5:abc"],
    "bounds not a pair": [*SPHERE, "--bounds", "-1.5"],
    "bounds with eval": [*SPHERE, "--bounds", "__import__('os'):1"],
    "div 0": [*SPHERE, "--bounds", "-1:1", "--div", "0"],
    "div not a number": [*SPHERE, "--bounds", "-1:1", "--div", "eight"],
    "div count": [*SPHERE, "--bounds", "-1:1", "--div", "4,4"],
    "lower > upper": [*SPHERE, "--bounds", "1.5:-1.5"],
    "lower > upper on one axis": [*SPHERE, "--bounds", "-1:1,1:-1,-1:1"],
    "wrong number of bounds": [*SPHERE, "--bounds", "-1:1,-1:1"],
    "no vars and one bounds pair": ["extract", "--f", "x1^2 + x2^2 - 1", "--bounds", "-1:1"],
    "no bounds": [*SPHERE],
    "nothing to extract": ["extract", "--div", "4"],
    "example and formula": ["extract", "--example", "sphere", "--f", "x"],
    "start count": [*SPHERE, "--bounds", "-1:1", "--start", "1,0"],
    "unknown method": ["extract", "--example", "sphere", "--div", "4", "--method", "nosuch"],
    "unknown option": ["extract", "--example", "sphere", "--frobnicate"],
    "unknown command": ["frobnicate"],
    "no command": [],
    "missing value": ["extract", "--example"],
    "seed": ["extract", "--example", "sphere", "--seed", "x"],
    "output folder missing": ["extract", "--example", "sphere", "--div", "4", "-o", "no/such/dir/out.npz"],
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_one_line_exit_2_no_file(case, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = BAD[case]
    if argv and argv[0] == "extract" and "-o" not in argv:
        argv = [*argv, "-o", str(tmp_path / "out.npz"), "--vtu", str(tmp_path / "out.vtu")]
    code, out, err = run(capsys, *argv)
    assert_one_line_error(code, out, err)
    assert list(tmp_path.iterdir()) == []


def test_bad_formula_message_names_the_problem(capsys):
    code, out, err = run(capsys, "extract", "--f", "sinn(x) + y + z", "--vars", "x,y,z", "--bounds", "-1:1")
    assert_one_line_error(code, out, err)
    assert "sinn" in err


def test_unknown_example_lists_known(capsys):
    code, out, err = run(capsys, "extract", "--example", "no-such-manifold")
    assert_one_line_error(code, out, err)
    assert "sphere" in err


def test_keyboard_interrupt_exit_130(capsys, monkeypatch, tmp_path):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(gcmh_core, "extract", interrupted)
    out_file = tmp_path / "out.npz"
    code, out, err = run(capsys, "extract", "--example", "sphere", "-o", str(out_file))
    assert code == 130
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert not out_file.exists() and list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- extraction


def test_negative_bounds_as_typed_json(capsys):
    code, out, err = run(capsys, *SPHERE, "--bounds", "-1.5:1.5", "--div", "12", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert JSON_KEYS <= set(data)
    assert (data["n"], data["k"], data["method"]) == (3, 1, "gcmh")
    assert data["div"] == [12, 12, 12]
    assert len(data["cells"]) == 3 and data["cells"][0] == data["vertices"] > 0
    assert data["euler_characteristic"] == 2
    assert data["boundary_facets"] == 0
    assert data["nonfinite_vertices"] == 0
    assert data["seconds"] >= 0


def test_default_variable_names_from_bounds(capsys):
    code, out, err = run(
        capsys, "extract", "--f", "x1^2 + x2^2 - 1/2", "--f", "x3^2 + x4^2 - 1/2",
        "--bounds", "-1:1,-1:1,-1:1,-1:1", "--div", "6,6,6,6", "--json",
    )
    assert code == 0, err
    data = json.loads(out)
    assert (data["n"], data["k"], data["div"]) == (4, 2, [6, 6, 6, 6])
    assert len(data["cells"]) == 3


def test_n_option(capsys):
    code, out, err = run(capsys, "extract", "--f", "x1^2 + x2^2 + x3^2 - 1", "--n", "3",
                         "--bounds", "-1.5:1.5", "--div", "8", "--json", "--seed", "3")
    assert code == 0, err
    assert json.loads(out)["euler_characteristic"] == 2


def test_pi_bounds_and_example(capsys):
    code, out, err = run(capsys, "extract", "--example", "complex-cosine", "--div", "6",
                         "--bounds", "-pi/2:pi/2", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert (data["n"], data["k"], data["div"]) == (4, 2, [6] * 4)
    assert len(data["cells"]) == 3


def test_human_summary(capsys):
    code, out, err = run(capsys, "extract", "--example", "sphere", "--div", "10")
    assert code == 0, err
    assert "Euler characteristic 2" in out
    assert "vertices" in out and "edges" in out and "faces" in out


def test_output_npz_loadable(capsys, tmp_path):
    target = tmp_path / "sphere.npz"
    code, out, err = run(capsys, "extract", "--example", "sphere", "--div", "10", "-o", str(target), "--json")
    assert code == 0, err
    data = json.loads(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sphere.npz"]  # no temp files left
    cx = gcmh_core.CellComplex.load(target)
    assert cx.counts() == data["cells"]
    assert cx.euler_characteristic() == data["euler_characteristic"] == 2


def test_output_vtu(capsys, tmp_path):
    pv = pytest.importorskip("pyvista")
    target = tmp_path / "torus.vtu"
    code, out, err = run(capsys, "extract", "--example", "torus", "--div", "16,16,6", "--vtu", str(target), "--quiet")
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["torus.vtu"]
    mesh = pv.read(target)
    assert mesh.n_points > 0


# ---------------------------------------------------------------- python -m


def _module_env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def test_python_m_examples():
    proc = subprocess.run(
        [sys.executable, "-m", "gcmh_core.cli", "examples"],
        capture_output=True, text=True, cwd=REPO, env=_module_env(), timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert "klein-bottle" in proc.stdout


def test_python_m_bad_input(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "gcmh_core.cli", "extract", *SPHERE[1:], "--bounds", "-1:1", "--div", "0",
         "-o", str(tmp_path / "x.npz")],
        capture_output=True, text=True, cwd=REPO, env=_module_env(), timeout=300,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("gcmh: error: ")
    assert proc.stdout == ""
    assert list(tmp_path.iterdir()) == []


def test_python_m_extract_json():
    proc = subprocess.run(
        [sys.executable, "-m", "gcmh_core.cli", "extract", *SPHERE[1:], "--bounds", "-1.5:1.5", "--div", "8", "--json"],
        capture_output=True, text=True, cwd=REPO, env=_module_env(), timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""  # no progress bar when stderr is not a terminal
    assert JSON_KEYS <= set(json.loads(proc.stdout))


# ---------------------------------------------------------------- on a dask cluster

DIST_BAD = {
    "scheduler not an address": ["extract", "--example", "sphere", "--div", "4", "--scheduler", "somewhere"],
    "scheduler without port": ["extract", "--example", "sphere", "--div", "4", "--scheduler", "tcp://localhost"],
    "unreachable scheduler": ["extract", "--example", "sphere", "--div", "4", "--scheduler", "tcp://127.0.0.1:1"],
    "block 0": ["extract", "--example", "sphere", "--div", "4", "--scheduler", "local", "--block", "0"],
    "block not a number": ["extract", "--example", "sphere", "--div", "4", "--scheduler", "local", "--block", "big"],
    "block count": ["extract", "--example", "sphere", "--div", "4", "--scheduler", "local", "--block", "2,2"],
    "block empty entry": ["extract", "--example", "sphere", "--div", "4", "--scheduler", "local", "--block", "2,,2"],
    "block without scheduler": ["extract", "--example", "sphere", "--div", "4", "--block", "2"],
}


@pytest.mark.parametrize("case", sorted(DIST_BAD))
def test_bad_cluster_options_one_line_exit_2_no_file(case, capsys, tmp_path):
    pytest.importorskip("distributed")
    out_file = tmp_path / "out.npz"
    code, out, err = run(capsys, *DIST_BAD[case], "-o", str(out_file))
    assert_one_line_error(code, out, err)
    assert ("--block" in err or "block" in err) if "block" in case else ("scheduler" in err)
    assert list(tmp_path.iterdir()) == []


def test_python_m_extract_on_a_local_cluster(tmp_path, capsys):
    pytest.importorskip("distributed")
    common = ["extract", "--example", "complex-cosine", "--div", "8", "--json"]
    code, single, err = run(capsys, *common, "-o", str(tmp_path / "one.npz"))   # the reference, in process
    assert code == 0, err
    dist = subprocess.run([sys.executable, "-m", "gcmh_core.cli", *common, "--scheduler", "local",
                           "--block", "4,8,2,8", "-o", str(tmp_path / "dask.npz")],
                          capture_output=True, text=True, cwd=REPO, env=_module_env(), timeout=600)
    assert dist.returncode == 0, dist.stderr
    assert dist.stderr == ""  # no dask log lines, no progress bar off a terminal
    a, b = json.loads(single), json.loads(dist.stdout)
    assert (b["scheduler"], b["blocks"]) == ("local", 2 * 1 * 4 * 1)
    assert {k: a[k] for k in JSON_KEYS - {"seconds"}} == {k: b[k] for k in JSON_KEYS - {"seconds"}}
    with np.load(tmp_path / "one.npz") as x, np.load(tmp_path / "dask.npz") as y:
        arrays = [key for key in x.files if key == "vertices" or key.startswith("cells_")]
        assert "vertices" in arrays and "cells_1" in arrays
        for key in arrays:
            assert x[key].tobytes() == y[key].tobytes(), key


def test_first_run_says_the_kernels_compile(capsys, monkeypatch):
    """The note comes when numba compiles one of the run's kernels (gcmh_core.compile_notice: its own test in
    test_first_run runs a child with an empty cache); --quiet says nothing. Here a compile is played."""
    import contextlib

    import gcmh_core.cli as cli

    @contextlib.contextmanager
    def compiling(callback):
        callback()   # as numba's compile event would, once
        yield

    monkeypatch.setattr(gcmh_core, "compile_notice", compiling)
    code, out, err = run(capsys, "extract", "--example", "sphere", "--div", "6")
    assert code == 0 and err.count(cli.COMPILE_NOTE) == 1 and "compiling the kernels, once per install" in err
    code, out, err = run(capsys, "extract", "--example", "sphere", "--div", "6", "--quiet")
    assert code == 0 and "compiling" not in err
    monkeypatch.undo()
    gcmh_core.extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 4, variables="x,y,z")  # (cached by now)
    code, out, err = run(capsys, "extract", "--example", "sphere", "--div", "6")
    assert code == 0 and "compiling" not in err   # a warm run: nothing compiles, nothing is said


# ---------------------------------------------------------------- glued axes and parameters, checked first


def test_periodic_is_checked_before_the_run_and_the_dry_run(capsys):
    """--periodic goes through the example loader's check (_validate.glued_axes): one line, before any work."""
    for extra in ([], ["--dry-run"]):
        code, out, err = run(capsys, "extract", "--example", "klein-bottle", "--periodic", "u", *extra)
        assert_one_line_error(code, out, err)
        assert "periodic axis 'u' is not a variable (variables: x, y, z, s, t)" in err
    # an example's own glued axes are checked again against a --div that breaks them
    code, out, err = run(capsys, "extract", "--example", "klein-bottle-closed", "--div", "12,12,6,12,11", "--dry-run")
    assert_one_line_error(code, out, err)
    assert "needs an even div, got 11" in err


def test_shared_checks_name_their_option():
    from gcmh_core._validate import glued_axes, parse_params

    assert parse_params(["a=pi/4", " b = -1"]) == {"a": pytest.approx(0.7853981633974483), "b": -1.0}
    assert parse_params([]) is None
    with pytest.raises(gcmh_core.InputError, match="^--param: expected NAME=VALUE, e.g. --param a=0.3, got 'a'$"):
        parse_params(["a"])
    with pytest.raises(gcmh_core.InputError, match="^-p: a is given twice$"):
        parse_params(["a=1", "a=2"], option="-p")
    assert glued_axes(["t", "s:flip=t"], ["x", "y", "z", "s", "t"], [8, 8, 4, 8, 8]) == ["s:flip=t", "t"]
    assert glued_axes(None, ["x", "y"], 4) == []
