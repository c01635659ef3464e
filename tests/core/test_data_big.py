"""Big volumes (issue 29, item 3): on a Dask cluster, F's values from memory-mapped files are read
block by block from the maps (`data_files.MappedValues`), never written whole, and give the bytes of
the local run; the budget estimates such a run before anything is read."""

import pickle

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
    with pytest.raises(TooLargeError):
        extract_data(files["a"], 0.5, scheduler="local")
