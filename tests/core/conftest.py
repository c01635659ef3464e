"""Fixtures shared by the core tests."""

import pytest


@pytest.fixture(scope="session")
def cluster():
    """(LocalCluster, Client): two single-threaded worker processes, shared by every test that runs on Dask
    (starting and closing one costs seconds, and its workers load numba's kernels once)."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc:
        with distributed.Client(lc, set_as_default=False) as client:
            client.wait_for_workers(2, timeout=60)
            yield lc, client


@pytest.fixture
def own_cluster():
    """(LocalCluster, Client) of this test alone: for tests that kill workers, so that a nanny slow to
    restart one on a loaded machine cannot leave the shared cluster without workers for the tests after."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc:
        with distributed.Client(lc, set_as_default=False) as client:
            client.wait_for_workers(2, timeout=300)
            yield lc, client
