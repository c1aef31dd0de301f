"""Dask distributed executor of a batch (imported only when a scheduler is given).

``run_on_dask("local", ...)`` starts a :class:`~distributed.LocalCluster` on 127.0.0.1
(worker processes, one thread each, no dashboard); any other string is the address of an
existing scheduler (``dask scheduler``, dask-jobqueue, dask-kubernetes). A worker plugin
parses the cell and loads the libraries once per worker; tasks carry one small item each
and return the item's result. At most ``2 * workers + 2`` tasks are in flight, so the
driver's memory does not grow with the count.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from ltl_human_motion.batch.items import ItemParams
from ltl_human_motion.batch.specs import BatchConfigError
from ltl_human_motion.batch.worker import BatchJob, ItemResult, prepare_worker, run_item
from ltl_human_motion.errors import MissingDependencyError

try:
    from distributed import Client, LocalCluster, as_completed
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError as exc:  # pragma: no cover - dask is in requirements
    raise MissingDependencyError("a Dask scheduler needs dask distributed: pip install "
                                 "'dask[distributed]'") from exc

__all__ = ["BatchWorkerPlugin", "open_client", "run_on_dask"]


class BatchWorkerPlugin(WorkerPlugin):
    """Prepares every (current and future) worker for one job."""

    name = "ltl-human-motion-batch"

    def __init__(self, job: BatchJob) -> None:
        self.job = job

    def setup(self, worker) -> None:
        prepare_worker(self.job)


@contextlib.contextmanager
def open_client(scheduler: str, workers: int) -> Iterator[Client]:
    """A client of ``scheduler`` (an address, or ``"local"`` for a loopback LocalCluster)."""
    if scheduler == "local":
        cluster = LocalCluster(host="127.0.0.1", dashboard_address=None,
                               n_workers=max(int(workers), 1), processes=True,
                               threads_per_worker=1)
        try:
            with Client(cluster) as client:
                yield client
        finally:
            cluster.close()
    else:
        try:
            client = Client(scheduler)
        except (OSError, TimeoutError, ValueError) as exc:
            raise BatchConfigError(f"cannot connect to the Dask scheduler {scheduler!r}: "
                                   f"{exc}") from exc
        with client:
            yield client


def _run(job: BatchJob, item: ItemParams) -> ItemResult:
    return run_item(job, item)


def run_on_dask(scheduler: str, job: BatchJob, items: list[ItemParams], workers: int
                ) -> Iterator[tuple[ItemParams, ItemResult | None, str | None]]:
    """Run ``items`` on a Dask cluster; yield ``(item, result, None)`` as they finish.

    A task whose worker died (``KilledWorker``, lost connection) yields
    ``(item, None, reason)``: it is not recorded, and the next run retries it.
    """
    with open_client(scheduler, workers) as client:
        client.register_plugin(BatchWorkerPlugin(job))
        n_workers = max(len(client.scheduler_info().get("workers", {})), 1)
        window = 2 * n_workers + 2
        queue = iter(items)
        job_future = client.scatter(job, broadcast=True)
        submitted: dict[str, ItemParams] = {}

        def submit(item: ItemParams):
            fut = client.submit(_run, job_future, item, pure=False,
                                key=f"lhm-item-{item.index}-{job.fingerprint()[:12]}")
            submitted[fut.key] = item
            return fut

        ac = as_completed([submit(it) for it in _take(queue, window)])
        for fut in ac:
            item = submitted.pop(fut.key)
            try:
                result = fut.result()
            except Exception as exc:
                yield item, None, f"{type(exc).__name__}: {exc}"
            else:
                yield item, result, None
            finally:
                fut.release()
            nxt = next(queue, None)
            if nxt is not None:
                ac.add(submit(nxt))


def _take(queue: Iterator[ItemParams], n: int) -> list[ItemParams]:
    out = []
    for _ in range(n):
        item = next(queue, None)
        if item is None:
            break
        out.append(item)
    return out
