"""`gcmh extract --data FILE`: files in, the same complex as the Python API, named in the summary and
JSON; the estimate before the run; one-line errors that write nothing; the same bytes on a cluster and
from a memory-mapped file."""

import json

import numpy as np
import pytest

from gcmh_core import CellComplex
from gcmh_core.cli import main
from gcmh_core.data_files import extract_data

SEMI = np.array([1.0, 0.7, 0.45])


def ellipsoid(shape=(21, 19, 17), box=((-1.2, 1.2), (-0.9, 0.9), (-0.6, 0.6))):
    axes = [np.linspace(lo, hi, d) for (lo, hi), d in zip(box, shape)]
    X = np.meshgrid(*axes, indexing="ij")
    return sum((X[a] / SEMI[a]) ** 2 for a in range(3)).astype(np.float32)


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(code, out, err, words):
    assert code == 2, (code, out, err)
    assert out == "" and len(err.splitlines()) == 1 and err.startswith("gcmh: error: "), err
    assert words in err, err


@pytest.fixture
def npy(tmp_path):
    path = tmp_path / "e.npy"
    np.save(path, ellipsoid())
    return path


def test_data_json_names_the_files_and_matches_the_api(capsys, tmp_path, npy):
    out_npz = tmp_path / "out.npz"
    code, out, err = run(capsys, "extract", "--data", npy, "--level", "1", "--bounds", "-1.2:1.2,-0.9:0.9,-0.6:0.6",
                         "--json", "-q", "-o", out_npz)
    assert code == 0, err
    s = json.loads(out)
    assert s["data"]["files"] == [str(npy)] and s["data"]["components"][0]["level"] == 1.0
    assert s["data"]["bounds"] == [[-1.2, 1.2], [-0.9, 0.9], [-0.6, 0.6]]
    assert s["div"] == [20, 18, 16] and s["euler_characteristic"] == 2
    saved = CellComplex.load(out_npz)
    api = extract_data(str(npy), 1.0, bounds=[(-1.2, 1.2), (-0.9, 0.9), (-0.6, 0.6)])
    assert saved.vertices.tobytes() == api.vertices.tobytes()
    assert saved.meta["data"]["files"] == [str(npy)] and saved.meta["variables"] == ["x", "y", "z"]


def test_data_human_summary_names_axes_units_and_notes(capsys, tmp_path):
    nib = pytest.importorskip("nibabel")
    c, s = np.cos(0.1), np.sin(0.1)
    affine = np.array([[0.1 * c, -0.1 * s, 0, -1.0], [0.1 * s, 0.1 * c, 0, -0.9], [0, 0, 0.075, -0.6], [0, 0, 0, 1]])
    img = nib.Nifti1Image(ellipsoid(), affine)
    img.header.set_xyzt_units("mm")
    nib.save(img, tmp_path / "e.nii")
    code, out, err = run(capsys, "extract", "--data", tmp_path / "e.nii", "--level", "1", "--vars", "a,b,c", "-q")
    assert code == 0, err
    assert f"{tmp_path / 'e.nii'} = 1: 2-manifold in R^3" in out
    assert "grid 21x19x17 samples: a in [-1, 1] mm" in out
    assert "note: " in out and "not axis-aligned" in out


def test_two_files_two_levels_give_a_curve(capsys, tmp_path, npy):
    z = np.broadcast_to(np.linspace(-0.6, 0.6, 17)[None, None, :], (21, 19, 17)).astype(np.float32)
    np.save(tmp_path / "z.npy", z)
    code, out, err = run(capsys, "extract", "--data", npy, "--data", tmp_path / "z.npy", "--level", "1,0.15",
                         "--bounds", "-1.2:1.2,-0.9:0.9,-0.6:0.6", "--json", "-q")
    assert code == 0, err
    s = json.loads(out)
    assert (s["n"], s["k"]) == (3, 2) and s["boundary_facets"] == 0 and s["vertices"] > 20
    assert [c["level"] for c in s["data"]["components"]] == [1.0, 0.15]


def test_dry_run_estimates_from_the_header(capsys, npy):
    code, out, err = run(capsys, "extract", "--data", npy, "--level", "1", "--dry-run", "--json")
    assert code == 0, err
    e = json.loads(out)
    assert e["data"] == [str(npy)] and e["div"] == [20, 18, 16]
    assert e["grid_bytes"] >= 21 * 19 * 17 * 8  # F's values, held in memory at this size
    assert 100 < e["candidate_cubes"] < 3000


def test_bad_data_one_line_and_nothing_written(capsys, tmp_path, npy):
    out_npz = tmp_path / "never.npz"
    np.save(tmp_path / "short.npy", ellipsoid()[:-1])
    (tmp_path / "junk.nii").write_bytes(b"\x00" * 100)
    cases = [
        (["--data", tmp_path / "missing.npy"], "no such file"),
        (["--data", tmp_path / "junk.nii"], "not a readable NIfTI"),
        (["--data", npy, "--data", tmp_path / "short.npy", "--level", "1"], "different grid shapes"),
        (["--data", npy, "--level", "40"], "outside the data's range"),
        (["--data", npy, "--level", "1,2"], "2 levels for 1 components"),
        (["--data", npy, "--div", "8"], "--div does not go with --data"),
        (["--data", npy, "--f", "x"], "--f does not go with --data"),
        (["--level", "3", "--f", "x1", "--n", "2", "--bounds", "0:1"], "--level goes with --data"),
        (["--data", npy, "--level", "1", "--vars", "a,b"], "2 axis names for data with 3 axes"),
    ]
    for argv, words in cases:
        code, out, err = run(capsys, "extract", *argv, "-o", out_npz, "-q")
        one_line_error(code, out, err, words)
        assert not out_npz.exists()


def test_values_larger_than_the_memory_share_run_from_a_file(capsys, tmp_path, npy, monkeypatch):
    # a .npz is read whole, and F's values are written: in memory ...
    np.savez(tmp_path / "e.npz", e=ellipsoid())
    args = ["extract", "--data", tmp_path / "e.npz", "--level", "1", "--json", "-q", "-o"]
    code, out, _ = run(capsys, *args, tmp_path / "a.npz")
    assert code == 0 and json.loads(out)["data"]["values_on_disk"] is False
    # ... or, on a machine with little memory, to a memory-mapped temporary file, read slab by slab
    monkeypatch.setattr("gcmh_core.data_files.IN_MEMORY_SHARE", 1e-6)
    code, out, err = run(capsys, *args, tmp_path / "b.npz")
    assert code == 0, err
    assert json.loads(out)["data"]["values_on_disk"] is True and not json.loads(out)["data"]["values_from_maps"]
    # a .npy is memory-mapped: the sweep computes F's values from the map, slab by slab
    code, out, err = run(capsys, "extract", "--data", npy, "--level", "1", "--json", "-q", "-o", tmp_path / "c.npz")
    assert code == 0, err
    assert json.loads(out)["data"]["values_from_maps"] is True
    a, b, c = (CellComplex.load(tmp_path / f"{x}.npz") for x in "abc")
    assert a.vertices.tobytes() == b.vertices.tobytes() == c.vertices.tobytes()
    assert all(np.array_equal(x, y) and np.array_equal(x, z) for x, y, z in zip(a.cells[2], b.cells[2], c.cells[2]))


def test_data_on_a_cluster_gives_the_same_bytes(capsys, tmp_path, npy, cluster):
    lc, _ = cluster
    args = ["extract", "--data", npy, "--level", "1", "--json", "-q"]
    code, _, err = run(capsys, *args, "-o", tmp_path / "here.npz")
    assert code == 0, err
    code, out, err = run(capsys, *args, "--scheduler", lc.scheduler_address, "--block", "6", "-o",
                         tmp_path / "there.npz")
    assert code == 0, err
    assert json.loads(out)["blocks"] > 1
    a, b = CellComplex.load(tmp_path / "here.npz"), CellComplex.load(tmp_path / "there.npz")
    assert a.vertices.tobytes() == b.vertices.tobytes()
    assert all(np.array_equal(x, y) for x, y in zip(a.cells[2], b.cells[2]))
