"""Issue 26: what a user types or opens never crashes, hangs or misleads (items 3, 4 and 6 of the library).

Complex equations too large to expand, example folders with one bad file, nesting that would overflow the
stack, a number of variables no grid can hold, a seam with an empty flip, and writers on a full disk (a
small tmpfs when root may mount one, else a mocked ENOSPC): one clear message, nothing left behind.
"""

import errno
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from gcmh_core import extract
from gcmh_core._validate import glued_axes
from gcmh_core.budget import estimate_run
from gcmh_core.cli import main
from gcmh_core.complex import CellComplex
from gcmh_core.complex_equations import MAX_TERMS, expansion_terms, split_complex
from gcmh_core.errors import InputError
from gcmh_core.examples import examples_dir, list_examples, load_example
from gcmh_core.formula import MAX_VARIABLES, FormulaError, parse_system

SPHERE = ["x^2 + y^2 + z^2 - 1"]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# ---------------------------------------------------------------- item 3: complex mode's expansion
@pytest.mark.parametrize("equation", ["(z+w+1)^64 = 1", "(z+1)^64*(w+1)^64 = 1", "exp((z+w)^64) = 1",
                                      "(z^2+1)^30 = w", "((z+w)^8+1)^8 = 1", "z^-40 = (w+1)^40"])
def test_an_equation_too_large_to_expand_is_refused_before_sympy_expands_it(equation, monkeypatch):
    import sympy

    def no_expansion(*a, **k):   # the refusal must come first
        raise AssertionError("sympy expanded the equation")

    monkeypatch.setattr(sympy, "expand_complex", no_expansion)
    with pytest.raises(FormulaError, match=f"at most {MAX_TERMS}"):
        split_complex([equation], "z, w")


@pytest.mark.parametrize("equation", ["z = cos(w)", "z^2 + w^3 = 1", "sin(z)^20 = w", "z^-5 = w", "exp(z)*exp(w) = 1",
                                      "(z+w+1)^6 = 1"])
def test_the_bound_leaves_equations_that_fit(equation):
    texts, _, _ = split_complex([equation], "z, w")
    assert len(texts) == 2


def test_the_estimate_bounds_the_terms_sympy_finds():
    """Over polynomials and functions of them: the estimate is never below the terms of the real split."""
    import sympy

    z, w = sympy.symbols("z w")
    x1, y1, x2, y2 = sympy.symbols("x1 y1 x2 y2", real=True)
    rng = np.random.default_rng(5)
    atoms = [z, w, sympy.Integer(1), sympy.I, z * w]
    for _ in range(40):
        e = sum(atoms[i] for i in rng.choice(len(atoms), size=rng.integers(1, 4))) ** int(rng.integers(1, 6))
        if rng.random() < 0.5:
            e = e * (z + rng.integers(1, 3)) ** int(rng.integers(1, 4))
        expanded = sympy.expand(sympy.expand_complex(e.xreplace({z: x1 + sympy.I * y1, w: x2 + sympy.I * y2})))
        re, im = expanded.as_real_imag()
        found = len(sympy.Add.make_args(sympy.expand(re))) + len(sympy.Add.make_args(sympy.expand(im)))
        assert expansion_terms(e, [z, w]) >= found / 2, e   # (each estimated term gives at most a Re and an Im)


def test_the_command_line_and_an_example_file_refuse_it(capsys, tmp_path, monkeypatch):
    code, out, err = run(capsys, "extract", "--complex", "--f", "(z+w+1)^64 = 1", "--vars", "z,w", "-o",
                         str(tmp_path / "a.npz"))
    assert code == 2 and err.startswith("gcmh: error:") and "expands to about" in err and len(err.splitlines()) == 1
    (tmp_path / "big.toml").write_text('title = "big"\ndescription = "d"\ncomplex = ["(z+w+1)^64 = 1"]\n'
                                       'complex_variables = ["z", "w"]\nbounds = [-1, 1]\ndiv = 8\n')
    shutil.copy(examples_dir() / "sphere.toml", tmp_path / "sphere.toml")
    monkeypatch.setenv("GCMH_EXAMPLES_DIR", str(tmp_path))
    bad = []
    assert [e.name for e in list_examples(on_error=lambda name, e: bad.append(name))] == ["sphere"]
    assert bad == ["big"]
    with pytest.raises(InputError, match="expands to about"):
        load_example("big")


# ---------------------------------------------------------------- item 6: bad example files, nesting, n
def _examples_dir_with(tmp_path, files: dict) -> Path:
    d = tmp_path / "examples"
    d.mkdir()
    for name in ("sphere", "torus"):
        shutil.copy(examples_dir() / f"{name}.toml", d / f"{name}.toml")
    for name, text in files.items():
        (d / name).write_bytes(text if isinstance(text, bytes) else text.encode())
    return d


def test_one_bad_example_file_leaves_the_others_listed_and_is_named(capsys, tmp_path, monkeypatch):
    d = _examples_dir_with(tmp_path, {"deep.toml": "x = " + "[" * 5000 + "]" * 5000 + "\n",
                                      "broken.toml": "title = \n", "binary.toml": b"\xff\xfe\x00",
                                      "huge.toml": "# " + "x" * (2 << 20) + "\n"})
    monkeypatch.setenv("GCMH_EXAMPLES_DIR", str(d))
    bad = {}
    good = list_examples(on_error=lambda name, e: bad.setdefault(name, str(e)))
    assert [e.name for e in good] == ["sphere", "torus"]
    assert sorted(bad) == ["binary", "broken", "deep", "huge"]
    assert "nested too deeply" in bad["deep"] and "larger than" in bad["huge"]
    with pytest.warns(UserWarning, match="'deep' left out"):
        assert len(list_examples()) == 2


def test_a_complex_whose_meta_is_nested_too_deeply_is_a_clear_error(tmp_path):
    cx = extract(SPHERE, variables="x,y,z", bounds=[-1.5, 1.5], div=4)
    p = tmp_path / "a.npz"
    cx.save(p)
    with zipfile.ZipFile(p) as z:
        members = {name: z.read(name) for name in z.namelist()}
    deep = np.array("[" * 100_000 + "]" * 100_000)
    import io

    buf = io.BytesIO()
    np.lib.format.write_array(buf, deep, allow_pickle=False)
    members["meta_json.npy"] = buf.getvalue()
    with zipfile.ZipFile(p, "w") as z:
        for name, data in members.items():
            z.writestr(name, data)
    with pytest.raises(ValueError, match="nested too deeply"):
        CellComplex.load(p)


def test_n_past_what_a_grid_can_hold_is_refused_before_anything_is_made(capsys):
    with pytest.raises(InputError, match=f"at most {MAX_VARIABLES}"):
        parse_system(["x1"], [f"x{i}" for i in range(100_000)])
    with pytest.raises(InputError, match="between 1 and 62"):
        extract(["x1"], n=100_000, bounds=[-1, 1], div=1)
    # the index check on a huge grid says its size in a line (not a number of 30000 digits)
    with pytest.raises(InputError) as err:
        estimate_run(62, 1, 10**6)
    assert "about 10^" in str(err.value) and len(str(err.value)) < 200


def test_the_name_check_is_linear():
    """A name given twice is found in a set: 60 names take the same calls per name as 6 (counted, not timed)."""
    import sys as _sys

    def calls(n):
        count = [0]

        def tracer(frame, event, arg):
            if event == "line" and frame.f_code.co_name == "_check_variables":
                count[0] += 1
            return tracer

        from gcmh_core.formula import _check_variables

        _sys.settrace(tracer)
        try:
            _check_variables([f"x{i}" for i in range(n)])
        finally:
            _sys.settrace(None)
        return count[0]

    assert calls(60) <= 10 * calls(6) + 20


@pytest.mark.parametrize("entry", ["t:flip=", "t:flip= ", "t:flip=s,", "t:flip=,s"])
def test_an_empty_flip_is_refused_not_read_as_a_plain_seam(entry):
    with pytest.raises(InputError, match="flip= needs axis names"):
        glued_axes([entry], ["s", "t"], 10)
    assert glued_axes(["t:flip=s"], ["s", "t"], 10) == ["t:flip=s"]


# ---------------------------------------------------------------- item 4: a full disk
def test_every_writer_on_a_full_disk_says_so_and_leaves_the_old_file(full_disk, fill_disk, capsys):
    cx = extract(SPHERE, variables="x,y,z", bounds=[-1.5, 1.5], div=30)
    for name, save in (("a.npz", cx.save), ("a.vtu", cx.save_vtu)):
        old = full_disk / name
        old.write_bytes(b"old content")
        fill_disk(full_disk, leave=2048)
        with pytest.raises(OSError) as err:
            save(old)
        assert err.value.errno == errno.ENOSPC
        assert old.read_bytes() == b"old content"
        assert sorted(os.listdir(full_disk)) == sorted(["ballast", "a.npz"] + (["a.vtu"] if name == "a.vtu" else []))
        os.unlink(full_disk / "ballast")


def test_the_command_line_on_a_full_disk_is_one_line_and_leaves_nothing(full_disk, fill_disk):
    fill_disk(full_disk, leave=2048)
    for flag, name in (("-o", "a.npz"), ("--vtu", "a.vtu")):
        r = subprocess.run([sys.executable, "-m", "gcmh_core.cli", "extract", "--f", SPHERE[0], "--vars", "x,y,z",
                            "--bounds", "-1.5:1.5", "--div", "40", "-q", flag, str(full_disk / name)],
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 1 and r.stderr.count("\n") == 1 and "No space left" in r.stderr, r.stderr
        assert sorted(os.listdir(full_disk)) == ["ballast"]


def test_a_vtu_written_through_memory_reads_back(tmp_path):
    import pyvista as pv

    cx = extract(SPHERE, variables="x,y,z", bounds=[-1.5, 1.5], div=8)
    cx.save_vtu(tmp_path / "a.vtu")
    grid = pv.read(tmp_path / "a.vtu")
    assert grid.n_points == cx.count(0) and set(grid.point_data.keys()) >= {"x", "y", "z"}
    with open(tmp_path / "b.vtu", "wb") as f:
        cx.save_vtu(f)
    assert (tmp_path / "b.vtu").read_bytes() == (tmp_path / "a.vtu").read_bytes()
    assert json.loads(json.dumps(cx.meta, default=str))
