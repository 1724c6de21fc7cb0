"""The Dask cluster a fleet run diagnoses on: a local one of single-threaded worker
processes, or a running one given by its address.

A diagnosis is single-threaded work (NumPy, the core), so a local worker runs one thread
and its numerical libraries one thread each (``THREADS``): N workers then use N cores,
and none competes with the others for a core. The variables are set for the workers
before they start, whatever the calling shell holds (OpenBLAS reads its own when NumPy
is imported). The cluster also runs without the machinery a batch of short tasks does
not need (``LEAN``): the workers' statistical profiler, work stealing between workers
(the scheduler hands a worker a task as it frees up), and frequent health and memory
polls. That machinery runs beside the workers in the client's process and in each
worker, and with as many workers as cores it takes their time.
"""

from __future__ import annotations

import contextlib
import copy
import logging
import os
from collections.abc import Iterator
from typing import Any

__all__ = ["LEAN", "THREADS", "client"]

#: One thread for each numerical library of a worker (BLAS, OpenMP, the core's pool).
THREADS = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
           "RAYON_NUM_THREADS": "1"}

#: Dask settings of the local cluster (the scheduler's, the nannies' and the workers').
LEAN = {
    "distributed.worker.profile.enabled": False,
    "distributed.scheduler.work-stealing": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.tick.interval": "500ms",
    "distributed.admin.system-monitor.interval": "2s",
}


def client(scheduler: str | None, workers: int) -> tuple[Any, Any]:
    """A Dask client and the local cluster it runs on (None when ``scheduler`` gives
    the address of a running one)."""
    try:
        from dask.distributed import Client
    except ImportError:
        from ..exceptions import InputError

        raise InputError("lugre fleet runs on Dask: pip install 'lugre[fleet]' "
                         "(dask[distributed], duckdb)", name="--scheduler") from None
    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except OSError as e:
            from ..exceptions import InputError

            raise InputError(f"cannot reach the Dask scheduler at {scheduler} ({e}): start "
                             "one (dask scheduler) or leave --scheduler out for a local "
                             "cluster", name="--scheduler") from None
    cluster = local_cluster(workers)
    return Client(cluster), cluster


def local_cluster(workers: int) -> Any:
    """A local cluster of ``workers`` single-threaded processes (see the module)."""
    import dask
    from dask.distributed import LocalCluster

    with dask.config.set(LEAN), _environ(THREADS):
        # (the workers' settings as a copy: a nanny keeps a reference to the global
        # ones, which the context restores, for the worker it restarts)
        config = copy.deepcopy(dask.config.config)
        return LocalCluster(n_workers=workers, processes=True, threads_per_worker=1,
                            dashboard_address=None, silence_logs=logging.ERROR, env=THREADS,
                            config=config)


@contextlib.contextmanager
def _environ(values: dict[str, str]) -> Iterator[None]:
    """``values`` in this process's environment while the workers are spawned (they
    inherit it; a restarted worker gets them from its nanny), then as before."""
    old = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
