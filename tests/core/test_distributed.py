"""Extraction on a Dask cluster (gcmh_core.distributed) gives the single-process complex, bit for bit."""

import io
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from gcmh_core import Cancelled, InputError, extract
from gcmh_core.examples import load_example

distributed = pytest.importorskip("distributed")

from gcmh_core import complex as gcx  # noqa: E402
from gcmh_core import distributed as gd  # noqa: E402

# (`cluster`: tests/core/conftest.py, two worker processes shared by the session; `own_cluster`: one test's own)


def _assert_identical(a, b):
    """Every array of the two complexes, byte for byte (dtype and shape included)."""
    assert (a.n, a.k) == (b.n, b.k)
    for x, y in [(a.vertices, b.vertices), (a.edges, b.edges)]:
        assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes()
    assert sorted(a.cells) == sorted(b.cells)
    for r in a.cells:
        for x, y in zip(a.cells[r], b.cells[r]):
            assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes()
    for key in ("cubes", "candidate_cubes", "nonfinite_vertices", "degenerate"):
        assert a.meta[key] == b.meta[key], key


def _run(name, div, **kw):
    ex = load_example(name)
    return extract(ex.formulas, ex.bounds, div, variables=ex.variables, **kw)


@pytest.mark.parametrize("name, div, blocks", [
    ("sphere", 12, [None, 5, [1, 12, 12], [12, 2, 7]]),
    ("complex-cosine", 10, [None, 4, [10, 1, 10, 3]]),
    ("three-torus", 4, [None, 3, [4, 4, 1, 4, 2, 4]]),
])
def test_blocks_give_the_single_process_bytes(cluster, name, div, blocks):
    address = cluster[0].scheduler_address
    single = _run(name, div)
    assert single.counts()[0] > 0
    for block in blocks:
        cx = _run(name, div, scheduler=address, block=block)
        _assert_identical(single, cx)
        assert cx.meta["blocks"] > 1 and cx.meta["scheduler"] == address


def test_default_block_size():
    assert gd.default_block([20, 20, 20], 2).tolist() == [10, 10, 10]  # 8 blocks for 2 workers
    block = gd.default_block([160] * 4, 2)  # a block's vertices stay under the memory budget
    assert np.prod(block + 1) <= gd.BLOCK_VERTICES and np.prod(-(-160 // block)) >= 8
    assert gd.default_block([3, 1, 2], 100).tolist() == [1, 1, 1]  # never below one cube


def test_sampled_data_through_the_cluster(cluster):
    axes = [np.linspace(-1.5, 1.5, 15)] * 3
    x, y, z = np.meshgrid(*axes, indexing="ij")
    values = (x**2 + y**2 + z**2 - 1)[..., None]
    values[0, 0, 0] = np.nan  # counted once, by the block that owns it
    single = extract(values, bounds=(-1.5, 1.5))
    cx = extract(values, bounds=(-1.5, 1.5), scheduler=cluster[0].scheduler_address, block=[5, 14, 3])
    _assert_identical(single, cx)
    assert cx.meta["nonfinite_vertices"] == 1


def test_continuation_through_the_cluster(cluster, monkeypatch):
    monkeypatch.setattr(gd, "LOCAL_WAVE", 24)  # send most waves of these small runs (<= 51 cubes) to the workers
    monkeypatch.setattr(gd, "MIN_CHUNK", 8)
    address = cluster[0].scheduler_address
    for name, div in [("complex-cosine", 12), ("sphere", 16)]:
        ex = load_example(name)
        single = _run(name, div, method="gcch", start=ex.start)
        cx = _run(name, div, method="gcch", start=ex.start, scheduler=address)
        _assert_identical(single, cx)
        assert cx.meta["tasks"] > 2 and cx.meta["visited_cubes"] == single.meta["visited_cubes"]


@pytest.mark.parametrize("method", ["cms", "ccs"])
def test_simplicial_methods_through_the_cluster(cluster, monkeypatch, method):
    monkeypatch.setattr(gd, "LOCAL_WAVE", 16)
    monkeypatch.setattr(gd, "MIN_CHUNK", 8)
    ex = load_example("complex-cosine")
    kw = dict(method=method, start=ex.start) if method == "ccs" else dict(method=method)
    single = _run("complex-cosine", 8, **kw)
    cx = _run("complex-cosine", 8, scheduler=cluster[0].scheduler_address, block=None if method == "ccs" else 3, **kw)
    _assert_identical(single, cx)
    assert cx.meta["tasks"] > 2


class _KillOnce(distributed.WorkerPlugin):
    """Kills the worker process that starts the first gcmh block task (once: the marker file)."""

    def __init__(self, marker):
        self.marker = marker

    def transition(self, key, start, finish, **kwargs):
        if finish == "executing" and str(key).startswith("gcmh-block-"):
            try:
                os.close(os.open(self.marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
            except FileExistsError:
                return
            os._exit(1)


def test_a_killed_worker_is_replaced_and_the_result_is_identical(own_cluster, tmp_path):
    lc, client = own_cluster
    marker = str(tmp_path / "killed")
    single = _run("complex-cosine", 10)
    client.register_plugin(_KillOnce(marker), name="kill-once")
    try:
        cx = _run("complex-cosine", 10, scheduler=lc.scheduler_address, block=5)
    finally:
        client.unregister_worker_plugin("kill-once")
    assert os.path.exists(marker)  # a worker did die mid-run
    _assert_identical(single, cx)
    client.wait_for_workers(2, timeout=300)  # an event; the bound only ends a hung run  # the nanny restarted it


class _KillAlways(distributed.WorkerPlugin):
    """Kills every worker that starts a gcmh block task: dask gives up after a few deaths."""

    def transition(self, key, start, finish, **kwargs):
        if finish == "executing" and str(key).startswith("gcmh-block-"):
            os._exit(1)


def test_a_task_that_keeps_killing_workers_is_a_clear_error(own_cluster):
    lc, client = own_cluster
    client.register_plugin(_KillAlways(), name="kill-always")
    try:
        with pytest.raises(InputError, match="killed dask workers again and again"):
            _run("sphere", 6, scheduler=lc.scheduler_address, block=6)  # one task
    finally:
        client.unregister_worker_plugin("kill-always")
    client.wait_for_workers(2, timeout=300)  # an event; the bound only ends a hung run
    _assert_identical(_run("sphere", 6), _run("sphere", 6, scheduler=lc.scheduler_address))  # healthy again


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:1", "tcp://no-such-host.invalid:8786"])
def test_unreachable_scheduler_is_caught_by_the_probe(address, monkeypatch):
    # the plain TCP probe answers (dask's Client would wait out its timeout, twice)
    timeouts = []
    connect = gd.socket.create_connection

    def probe(where, timeout):
        timeouts.append(timeout)
        return connect(where, timeout=timeout)

    monkeypatch.setattr(gd.socket, "create_connection", probe)
    with pytest.raises(InputError, match=r"^cannot reach the dask scheduler at tcp://\S+: \S"):
        extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 6, variables="x,y,z", scheduler=address)
    assert timeouts == [gd.CONNECT_TIMEOUT]


def test_a_server_that_is_not_dask_is_a_clear_error(monkeypatch):
    import socket

    monkeypatch.setattr(gd, "CONNECT_TIMEOUT", 0.5)  # the deadline of the identity question
    with socket.socket() as server:  # accepts TCP connections, never says a word
        server.bind(("127.0.0.1", 0))
        server.listen()
        address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
        message = r"does not answer as a dask scheduler \(.+\); is `dask scheduler` running"
        with pytest.raises(InputError, match=message):
            extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 6, variables="x,y,z", scheduler=address)


def test_a_worker_address_is_not_a_scheduler(cluster):
    worker = next(iter(cluster[1].scheduler_info()["workers"]))
    with pytest.raises(InputError, match="is a dask Worker, not a scheduler"):
        extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 6, variables="x,y,z", scheduler=worker)


@pytest.mark.parametrize("scheduler, block, message", [
    ("somewhere", None, "scheduler must be 'local' or an address"),
    ("tcp://host", None, "scheduler must be 'local' or an address"),
    ("tcp://host:99999", None, "port 99999"),
    (8786, None, "scheduler must be"),
    ("local", 0, "at least 1 cube"),
    ("local", [2, 2], "block has 2 entries"),
    ("local", 2.5, "block must be a positive integer"),
    ("local", True, "block must be a positive integer"),
    (None, 4, "pass scheduler too"),
])
def test_bad_scheduler_or_block(scheduler, block, message):
    with pytest.raises(InputError, match=message):
        extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 6, variables="x,y,z", scheduler=scheduler, block=block)


def test_cancel_stops_the_run_and_its_tasks(cluster):
    lc, client = cluster
    seen = []

    def progress(phase, fraction):
        seen.append((phase, fraction))

    def cancel():  # once a block is done
        return any("blocks" in phase and fraction > 0 for phase, fraction in seen)

    with pytest.raises(Cancelled):
        _run("complex-cosine", 12, scheduler=lc.scheduler_address, block=2, progress=progress, cancel=cancel)
    assert seen[0] == (f"connecting to {lc.scheduler_address}", 0.0)
    assert seen[1] == ("extracting: 0/1296 blocks", 0.0)

    def pending(dask_scheduler):
        return [k for k in dask_scheduler.tasks if str(k).startswith("gcmh-")]

    deadline = time.time() + 10
    while client.run_on_scheduler(pending) and time.time() < deadline:
        time.sleep(0.1)
    assert client.run_on_scheduler(pending) == []  # cancelled, not left running


def test_progress_counts_blocks(cluster):
    seen = []
    _run("sphere", 8, scheduler=cluster[0].scheduler_address, block=4, progress=lambda p, f: seen.append((p, f)))
    blocks = [p for p, _ in seen if "blocks" in p]
    assert blocks[0] == "extracting: 0/8 blocks" and blocks[-1] == "extracting: 8/8 blocks"
    assert seen[-1] == ("assembling", 1.0)


def test_local_scheduler_starts_and_closes_its_own_cluster():
    # sampled data reaches a LocalCluster's workers through a temporary .npy they memory-map
    axes = [np.linspace(-1.5, 1.5, 11)] * 3
    x, y, z = np.meshgrid(*axes, indexing="ij")
    values = (x**2 + y**2 + z**2 - 1)[..., None]
    single = extract(values, bounds=(-1.5, 1.5))
    cx = extract(values, bounds=(-1.5, 1.5), scheduler="local", block=4)
    _assert_identical(single, cx)
    assert cx.meta["workers"] >= 1 and cx.meta["scheduler"] == "local" and cx.meta["blocks"] == 27


def _npz_bytes(cx):
    out = io.BytesIO()
    cx.save(out)
    return out.getvalue()


# the cluster's run details stay out of the file once complex.VOLATILE_META holds them
_RUN_META_UNSAVED = set(gd.RUN_META) <= set(gcx.VOLATILE_META)


@pytest.mark.xfail(not _RUN_META_UNSAVED, strict=True,
                   reason="complex.VOLATILE_META does not hold distributed.RUN_META yet (issue 25, item 5)")
def test_local_scheduler_writes_the_single_process_file_byte_for_byte(cluster):
    ex = load_example("complex-cosine")
    single = _run("complex-cosine", 9)
    local = _run("complex-cosine", 9, scheduler="local", block=4)
    assert local.meta["scheduler"] == "local" and local.meta["blocks"] > 1  # (kept on the object, for the summary)
    assert _npz_bytes(local) == _npz_bytes(single)
    # the same on a running cluster, for continuation and for sampled data
    address = cluster[0].scheduler_address
    single = _run("complex-cosine", 9, method="gcch", start=ex.start)
    assert _npz_bytes(_run("complex-cosine", 9, method="gcch", start=ex.start, scheduler=address)) == _npz_bytes(single)
    axes = [np.linspace(-1.5, 1.5, 12)] * 3
    x, y, z = np.meshgrid(*axes, indexing="ij")
    values = (x**2 + y**2 + z**2 - 1)[..., None]
    single = extract(values, bounds=(-1.5, 1.5))
    assert _npz_bytes(extract(values, bounds=(-1.5, 1.5), scheduler=address, block=5)) == _npz_bytes(single)


def test_a_pruned_sweep_and_its_blocks_write_the_same_file(cluster, monkeypatch):
    # (a one-process sweep of a large grid skips cubes by F's bounds and says how many; the blocks don't)
    monkeypatch.setattr("gcmh_core.sweep.PRUNE", True)
    monkeypatch.setattr("gcmh_core.sweep._GIVE_UP_SHARE", 1.0)   # (a small grid: pruned however little it saves)
    single = _run("complex-cosine", 12)
    assert single.meta["pruned_cubes"] > 0
    local = _run("complex-cosine", 12, scheduler=cluster[0].scheduler_address, block=6)
    assert "pruned_cubes" not in local.meta
    assert _npz_bytes(local) == _npz_bytes(single)


def test_sampled_continuation_through_the_cluster(cluster, monkeypatch):
    monkeypatch.setattr(gd, "LOCAL_WAVE", 16)  # the whole array is scattered to every worker once
    monkeypatch.setattr(gd, "MIN_CHUNK", 8)
    axes = [np.linspace(-1.5, 1.5, 17)] * 3
    x, y, z = np.meshgrid(*axes, indexing="ij")
    values = (x**2 + y**2 + z**2 - 1)[..., None]
    single = extract(values, bounds=(-1.5, 1.5), method="gcch", start=(0.0, 0.0, 1.0))
    cx = extract(values, bounds=(-1.5, 1.5), method="gcch", start=(0.0, 0.0, 1.0),
                 scheduler=cluster[0].scheduler_address)
    _assert_identical(single, cx)
    assert cx.meta["tasks"] > 2


def test_missing_dask_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(InputError, match=r"pip install -e \"\.\[cluster\]\""):
        extract("x^2 + y^2 + z^2 - 1", (-1.5, 1.5), 6, variables="x,y,z", scheduler="local")


def test_importing_gcmh_core_does_not_import_dask():
    code = ("import sys, gcmh_core, gcmh_core.distributed; "
            "assert not any(m == 'dask' or m.startswith(('dask.', 'distributed')) for m in sys.modules), "
            "'dask imported'")
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2]))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr


def test_a_refinement_across_blocks_gives_the_single_process_bytes(cluster):
    """In R^8 a cube whose cells are not balls is refined with the cubes its pieces bulge into, at the
    assembly (`runner.Grid.refine_deferred`): blocks of one cube a side put them in other tasks, whose
    records carry the cubes to refine back to the client."""
    from test_regular_high_n import random_system  # (tests/core is on the path: rootdir conftest)

    texts, box = random_system(8, 4, 9), [(-1, 1)] * 8
    single = extract(texts, box, 2, seed=9, force=True)
    blocks = extract(texts, box, 2, seed=9, force=True, scheduler=cluster[0].scheduler_address, block=1)
    assert single.meta["non_ball_split"] >= 1 and single.meta["non_ball_left"] == 0
    assert blocks.meta["blocks"] == 256 and blocks.meta["non_ball_split"] == single.meta["non_ball_split"]
    _assert_identical(single, blocks)
