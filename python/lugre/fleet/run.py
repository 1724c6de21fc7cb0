"""``lugre fleet run``: every recording not yet in the history diagnosed on a Dask cluster,
each result stored as it arrives.

The cluster (:mod:`lugre.fleet.cluster`) is a local one of ``workers`` processes (one
thread each: the diagnosis is single-threaded NumPy and Rust work) unless ``scheduler``
gives the address of a running one, whose workers must import lugre and read the
fleet's folder at the same path. A worker that dies has its tasks moved to another by
the scheduler (up to its ``distributed.scheduler.allowed-failures``, 3 by default); a
task that fails with an exception is retried ``RETRIES`` times; a recording whose tasks
keep failing is stored as an error and the run goes on.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .cluster import client as _client
from .discover import Axis, discover, file_stamp
from .store import open_store
from .task import diagnose_file, failed

__all__ = ["RETRIES", "RunSummary", "run"]

#: Retries of a task that raised (a worker that died is the scheduler's to retry).
RETRIES = 2


@dataclass
class RunSummary:
    """What a run did: recordings found, skipped (already stored), diagnosed, failed."""

    found: int = 0
    skipped: int = 0
    stored: int = 0
    errors: list[dict[str, Any]] = field(default_factory=list)
    seconds: float = 0.0
    workers: int = 0

    def text(self) -> str:
        if self.stored == 0:
            return (f"{self.found} recordings found, all already stored: nothing to diagnose "
                    f"({self.seconds:.1f} s)")
        rate = f", {self.stored / self.seconds:.2f} recordings/s" if self.seconds > 0 else ""
        return (f"{self.found} recordings found, {self.skipped} already stored, "
                f"{self.stored} diagnosed and stored ({len(self.errors)} with errors) in "
                f"{self.seconds:.1f} s on {self.workers} workers{rate}")


def _todo(axes: list[Axis], stamps: dict[tuple[str, str], str]
          ) -> tuple[list[tuple[Axis, Path, str]], int]:
    todo, skipped = [], 0
    for ax in axes:
        for p in ax.recordings:
            stamp = file_stamp(p)
            if stamps.get((ax.name, p.name)) == stamp:
                skipped += 1
            else:
                todo.append((ax, p, stamp))
    return todo, skipped


def _models(axes: list[Axis]) -> dict[str, Any]:
    """Each axis's model, read before any work (a bad model file stops the run here)."""
    from ..model import load_model

    return {ax.name: load_model(ax.model) for ax in axes}


def run(root: str | os.PathLike[str], db: str | os.PathLike[str], *,
        scheduler: str | None = None, workers: int | None = None, progress: Any = None,
        on_result: Callable[[dict[str, Any]], None] | None = None) -> RunSummary:
    """Diagnose the fleet under ``root`` into the history ``db``.

    Parameters
    ----------
    root : path
        One folder per axis: ``AXIS/model.json`` and the axis's recordings.
    db : path
        The history (DuckDB); created when missing. Recordings stored already (same
        file size and time) are skipped.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); default: a local
        cluster of ``workers`` processes.
    workers : int, optional
        Processes of the local cluster (default: the machine's cores).
    progress : lugre._progress.Progress, optional
        Where the batch's progress goes (a line every few seconds when enabled).
    on_result : callable, optional
        Called with each result after it is stored.
    """
    start = time.perf_counter()
    axes = discover(root)
    models = _models(axes)
    summary = RunSummary()
    with open_store(db) as store:
        todo, summary.skipped = _todo(axes, store.stamps())
        summary.found = len(todo) + summary.skipped
        for ax in axes:
            m = models[ax.name]
            from ..units import axis_units

            store.put_axis(ax.name, m.kind, axis_units(m.kind), m.to_dict())
        if todo:
            n = workers or os.cpu_count() or 1
            _distribute(todo, models, store, summary, scheduler, n, progress, on_result)
    summary.seconds = time.perf_counter() - start
    return summary


def _distribute(todo: list[tuple[Axis, Path, str]], models: dict[str, Any], store: Any,
                summary: RunSummary, scheduler: str | None, workers: int, progress: Any,
                on_result: Callable[[dict[str, Any]], None] | None) -> None:
    from dask.distributed import as_completed

    client, cluster = _client(scheduler, workers)
    try:
        summary.workers = len(client.scheduler_info().get("workers", {})) or workers
        dicts = {name: m.to_dict() for name, m in models.items()}
        futures = {}

        def submit(axis: str, path: str, stamp: str, attempt: int) -> Any:
            fut = client.submit(diagnose_file, axis, path, dicts[axis], stamp,
                                key=f"lugre-fleet-{axis}/{Path(path).name}-{stamp}-{attempt}",
                                pure=False, retries=RETRIES)
            futures[fut] = (axis, path, stamp, attempt)
            return fut

        for ax, p, stamp in todo:
            submit(ax.name, str(p), stamp, 0)
        counter = _Counter(len(todo), progress)
        pending = as_completed(list(futures))
        for fut in pending:
            axis, path, stamp, attempt = futures.pop(fut)
            result = _result(fut, axis, path, stamp)
            if result.get("transient") and attempt < RETRIES:
                # (the task raised outside the diagnosis, which returns its own errors:
                # the cluster's machinery, e.g. a worker's event loop torn down as it
                # died; the recording is diagnosed again)
                pending.add(submit(axis, path, stamp, attempt + 1))
                fut.release()
                continue
            result.pop("transient", None)
            store.put(result)
            summary.stored += 1
            if result["status"] != "ok":
                summary.errors.append(result)
            counter.tick(result["status"] != "ok")
            if on_result is not None:
                on_result(result)
            fut.release()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _result(fut: Any, axis: str, path: str, stamp: str) -> dict[str, Any]:
    """The task's result, or an error result when its workers kept dying or it raised."""
    try:
        return dict(fut.result())
    except Exception as e:  # noqa: BLE001 - any failure of the task is this recording's
        from distributed import KilledWorker

        if isinstance(e, KilledWorker):
            text = (f"{path}: the workers diagnosing it died repeatedly (out of memory, "
                    "killed): check the recording's size and the workers' memory")
        else:
            text = f"{path}: the diagnosis failed ({type(e).__name__}: {e})"
        out = failed(axis, path, stamp, " ".join(text.split()))
        # (the diagnosis returns its own errors: a raise is the cluster's, worth a retry)
        out["transient"] = not isinstance(e, KilledWorker)
        return out


class _Counter:
    """Progress of the batch: a line at most every few seconds, when enabled."""

    def __init__(self, total: int, progress: Any, every: float = 3.0) -> None:
        self.total, self.done, self.errors = total, 0, 0
        self.enabled = bool(progress is not None and progress.enabled)
        self.stream = getattr(progress, "stream", sys.stderr)
        self.every = every
        self.start = self.last = time.monotonic()

    def tick(self, error: bool) -> None:
        self.done += 1
        self.errors += int(error)
        now = time.monotonic()
        if self.enabled and (now - self.last >= self.every or self.done == self.total):
            self.last = now
            print(f"fleet: {self.done}/{self.total} recordings diagnosed ({self.errors} "
                  f"errors), {now - self.start:.0f} s", file=self.stream, flush=True)
