"""Big volumes (issue 29, item 3): on a Dask cluster, F's values from memory-mapped files are read
block by block from the maps (`data_files.MappedValues`), never written whole, and give the bytes of
the local run; the budget estimates such a run before anything is read."""

import json
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

from gcmh_core import TooLargeError
from gcmh_core import data_files as df
from gcmh_core.data_files import MappedValues, estimate_data, extract_data, load_components

SIDE = 33  # samples per axis: 32^3 cubes


def blob(dtype=np.float32, shift=0.0):
    """An ellipsoid's quadratic on [-1, 1]^3 (uneven semi-axes, a few planes of NaN in a corner)."""
    t = np.linspace(-1.0, 1.0, SIDE)
    x, y, z = np.meshgrid(t, t, t, indexing="ij")
    v = (x * x + 1.7 * (y - shift) ** 2 + 2.3 * z * z).astype(dtype)
    v[:3, :3, :4] = np.nan
    return v


@pytest.fixture
def files(tmp_path):
    np.save(tmp_path / "a.npy", blob())
    np.save(tmp_path / "b.npy", blob(np.float64, shift=0.2))
    np.save(tmp_path / "c.npy", np.stack([blob(), blob(shift=-0.1)], axis=-1))  # a trailing component axis
    return {name: str(tmp_path / f"{name}.npy") for name in "abc"}


def assert_identical(a, b):
    assert (a.n, a.k) == (b.n, b.k) and len(a.vertices) > 50
    assert a.vertices.dtype == b.vertices.dtype and a.vertices.tobytes() == b.vertices.tobytes()
    assert a.edges.tobytes() == b.edges.tobytes() and sorted(a.cells) == sorted(b.cells)
    for r in a.cells:
        for x, y in zip(a.cells[r], b.cells[r]):
            assert x.dtype == y.dtype and x.tobytes() == y.tobytes()
    assert a.meta["data"]["nonfinite_samples"] == b.meta["data"]["nonfinite_samples"] > 0
    assert a.meta["nonfinite_vertices"] == b.meta["nonfinite_vertices"]  # (continuation may meet none)


@pytest.mark.parametrize("specs, levels, components", [
    (["a"], "0.5", None), (["a", "b"], "0.5,0.8", None), (["c"], "0.6,0.5", True),
])
def test_mapped_values_are_the_written_values_slice_by_slice(files, specs, levels, components):
    specs = [files[s] for s in specs]
    written = load_components(specs, levels, components=components).values
    plan = df._plan(specs, levels, None, components)
    assert plan.mappable
    mapped = MappedValues(plan)
    assert mapped.shape == written.shape and mapped.dtype == written.dtype
    for index in [(), (slice(3, 9),), (slice(3, 9), slice(None), slice(2, 5)), (slice(None, None, 4),) * 3,
                  (slice(0, 12), slice(None), slice(None), 0), (5, slice(2, 30, 3), 7), (slice(1, 4), 2, 3, -1)]:
        got, want = mapped[index], written[index]
        assert got.shape == want.shape and got.tobytes() == want.tobytes(), index
    # a worker gets the recipe (a few hundred bytes), not the values, and reopens the files' maps
    text = pickle.dumps(mapped)
    assert len(text) < 1000
    again = pickle.loads(text)
    assert all(df._mapped(f.values) for f in again.plan.fields)
    assert again[7:11].tobytes() == written[7:11].tobytes()
    with pytest.raises(IndexError):
        mapped[..., 0]


def test_a_local_cluster_reads_its_blocks_from_the_memory_map(files, monkeypatch):
    pytest.importorskip("distributed")
    here = extract_data(None, data=load_components(files["a"], 0.5))  # F's values written whole
    assert here.meta["data"]["values_from_maps"] is False

    def refused(*args, **kwargs):
        raise AssertionError("F's values were written whole")

    monkeypatch.setattr(df, "_output", refused)  # no F written in memory or to a temporary file ...
    monkeypatch.setattr(np, "save", refused)     # ... nor saved for the workers (they are other processes)
    there = extract_data(files["a"], 0.5, scheduler="local", block=[8, 16, 11])
    assert there.meta["blocks"] > 8 and there.meta["scheduler"] == "local"
    assert there.meta["data"]["values_from_maps"] is True and there.meta["nonfinite_vertices"] > 0
    assert_identical(here, there)
    assert_identical(here, extract_data(files["a"], 0.5))  # (in this process: the sweep reads the map)


def test_a_remote_cluster_gets_block_slices_read_from_the_maps(files, cluster, monkeypatch):
    here = extract_data(None, data=load_components([files["a"], files["b"]], "0.5,0.8"))
    monkeypatch.setattr(df, "_output", lambda *a, **k: pytest.fail("F's values were written whole"))
    there = extract_data([files["a"], files["b"]], "0.5,0.8", scheduler=cluster[0].scheduler_address, block=10)
    assert there.meta["blocks"] == 64
    assert_identical(here, there)


def test_continuation_on_a_cluster_takes_the_values_written(files, cluster):
    # (a wave can need any cube's values: the values are written once, as for a local run)
    here = extract_data(files["a"], 0.5, method="gcch")
    there = extract_data(files["a"], 0.5, method="gcch", scheduler=cluster[0].scheduler_address)
    assert_identical(here, there)


def test_the_budget_estimates_a_cluster_run_before_reading(files, monkeypatch):
    values = SIDE**3 * 8
    local = estimate_data(files["a"], 0.5)
    remote = estimate_data(files["a"], 0.5, scheduler="local")
    assert local.grid_bytes >= values > remote.grid_bytes  # the cluster's run holds no F's values here
    assert estimate_data(files["a"], 0.5, scheduler="local", method="gcch").grid_bytes >= values
    assert 200 < remote.candidate_cubes < 20_000
    # a machine with too little memory: refused from the headers and a plane's guess, nothing read
    monkeypatch.setattr("gcmh_core.budget.available_memory", lambda: remote.peak_bytes // 4)
    monkeypatch.setattr(df, "_fill", lambda *a: pytest.fail("the data were read"))
    with pytest.raises(TooLargeError, match=r"the grid is the file's samples: subsample the volume") as info:
        extract_data(files["a"], 0.5, scheduler="local")
    assert "smaller div" not in str(info.value) and "gcch" not in str(info.value)


# A child: write nothing, compile on a tiny volume, estimate (`gcmh extract --dry-run`'s estimate), then run
# with the high-water mark reset (as tests/core/test_budget.py measures) and print both.
PEAK_CHILD = r"""
import json, sys
import numpy as np
from gcmh_core.data_files import estimate_data, extract_data
path, tiny = sys.argv[1], sys.argv[2]
extract_data(tiny, 0.0)
est = estimate_data(path, 0.0)
def status(key):
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith(key))
import ctypes
ctypes.CDLL("libc.so.6").malloc_trim(0)
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")
base = status("VmRSS:")
cx = extract_data(path, 0.0)
print(json.dumps(dict(measured=(status("VmHWM:") - base) * 1024, estimate=est.peak_bytes,
                      expected=est.candidate_cubes, cand=cx.meta["candidate_cubes"],
                      split=cx.meta["non_ball_split"])))
"""


def rough_sphere(side: int, noise: float, seed: int = 1) -> np.ndarray:
    """Distance to a sphere of radius 0.7 on [-1, 1]^3, float32, plus Gaussian noise (standard deviation
    ``noise``): near the grid spacing the isosurface has pieces that are not balls in some cubes."""
    t = np.linspace(-1.0, 1.0, side, dtype=np.float32)
    x, y, z = np.meshgrid(t, t, t, indexing="ij", sparse=True)
    v = np.sqrt(x * x + y * y + z * z) - np.float32(0.7)
    return (v + np.random.default_rng(seed).normal(0, noise, v.shape).astype(np.float32)) if noise else v


@pytest.mark.skipif(not os.path.exists("/proc/self/clear_refs"), reason="measures the peak from /proc (Linux)")
@pytest.mark.parametrize("side, noise, hands_over", [(256, 0.0, False), (128, 0.02, True), (200, 0.012, True)])
def test_the_estimate_is_within_its_margin_of_the_measured_peak(tmp_path, side, noise, hands_over):
    # rough data send the n = 3 marching pass to the general kernel (a piece of M in a cube that is not a
    # ball), whose records take about five times the memory: the estimate must see it coming
    # (budget._hands_over); smooth data stay in the pass.  The budget lets a run through with room for
    # a factor MEMORY_MARGIN of error.
    from gcmh_core.budget import MEMORY_MARGIN

    np.save(tmp_path / "v.npy", rough_sphere(side, noise))
    np.save(tmp_path / "tiny.npy", rough_sphere(12, noise))
    proc = subprocess.run([sys.executable, "-c", PEAK_CHILD, str(tmp_path / "v.npy"), str(tmp_path / "tiny.npy")],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    m = json.loads(proc.stdout.splitlines()[-1])
    print(f"\n  {side}^3 noise {noise}: candidates {m['cand']:,} (expected {m['expected']:,}), non-ball cells "
          f"{m['split']}, peak {m['measured'] / 1e6:.0f} MB, estimate {m['estimate'] / 1e6:.0f} MB")
    assert (m["split"] > 0) is hands_over, m  # (the case the volume was made for)
    assert m["measured"] > 20e6, m  # (tens of MB: above the allocator's noise)
    assert 1 / MEMORY_MARGIN <= m["estimate"] / m["measured"] <= MEMORY_MARGIN, m
