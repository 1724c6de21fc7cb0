"""The local cluster of lugre fleet run: its workers run one thread each (BLAS, OpenMP,
the core's pool), whatever the shell sets, also once restarted, and without the
profiler and work stealing; the shell's own settings are left as they were once the
cluster is up."""

from __future__ import annotations

import os

import pytest

pytest.importorskip("dask.distributed")

from lugre.fleet import cluster as C

SHELL = {"OMP_NUM_THREADS": "3", "OPENBLAS_NUM_THREADS": "3", "MKL_NUM_THREADS": "3",
         "RAYON_NUM_THREADS": "3"}


def _worker_state() -> tuple[dict, int, bool]:
    import dask
    from lugre import _core

    return ({k: os.environ.get(k) for k in C.THREADS}, _core.num_threads(),
            bool(dask.config.get("distributed.worker.profile.enabled")))


@pytest.fixture(scope="module")
def local():
    from dask.distributed import Client

    mp = pytest.MonkeyPatch()
    for k, v in SHELL.items():
        mp.setenv(k, v)
    cluster = C.local_cluster(2)
    client = Client(cluster)
    try:
        yield client, cluster
    finally:
        client.close()
        cluster.close()
        mp.undo()


def _pinned(states: dict) -> None:
    assert len(states) == 2
    for env, rayon, profiling in states.values():
        assert env == C.THREADS
        assert rayon == 1
        assert not profiling


def test_workers_run_one_thread_each(local):
    _pinned(local[0].run(_worker_state))


def test_the_shell_settings_are_kept(local):
    # (before a restart: Dask's nanny sets them in its own process to respawn a worker)
    for k, v in SHELL.items():
        assert os.environ[k] == v


def test_restarted_workers_run_one_thread_each(local):
    client = local[0]
    client.restart(wait_for_workers=True)
    _pinned(client.run(_worker_state))


def test_no_work_stealing(local):
    assert "stealing" not in local[1].scheduler.extensions
