"""Run a batch: derive items, farm them out, store results, resume after a crash.

Executors: ``workers=0`` runs items in this process; by default a
:class:`concurrent.futures.ProcessPoolExecutor` with ``workers`` processes; with
``scheduler`` a Dask distributed cluster (an address such as ``tcp://10.0.0.5:8786`` or
``"local"`` for a :class:`~distributed.LocalCluster` on 127.0.0.1). Only this process
writes files; workers return results, so a remote cluster needs no shared folder (it
needs the package and, for mesh cells, the mesh files).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import multiprocessing
import os
import time
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ltl_human_motion.batch.items import ItemParams, derive_item, validate_against_cell
from ltl_human_motion.batch.specs import BatchConfigError, BatchSpecs, load_specs
from ltl_human_motion.batch.store import DATASET_FORMAT, DATASET_VERSION, DatasetStore
from ltl_human_motion.batch.worker import (
    BatchJob,
    ItemAssessment,
    ItemResult,
    pool_initializer,
    prepare_worker,
    run_item,
)
from ltl_human_motion.yaml_limits import TextFileError, read_text_file

if TYPE_CHECKING:
    from ltl_human_motion.scene.cell import Cell

__all__ = ["BatchSummary", "make_job", "run_batch"]


@dataclass
class BatchSummary:
    """What a call of :func:`run_batch` did.

    Attributes
    ----------
    out : Path
    count : int
        Items in the dataset.
    skipped : int
        Items already done by an earlier run.
    computed : int
        Items computed by this run.
    lost : list of (int, str)
        Items whose worker died (not recorded; run again to retry them).
    counts : dict
        Final counts per status (``ok``, ``unverified``, ``failed``) when complete.
    complete : bool
    elapsed : float
        Wall-clock seconds of the computing phase.
    compute_time : float
        Sum of the per-item compute times of this run, seconds.
    """

    out: Path
    count: int
    skipped: int = 0
    computed: int = 0
    lost: list[tuple[int, str]] = field(default_factory=list)
    counts: dict[str, int] = field(default_factory=dict)
    verified_this_run: int = 0
    complete: bool = False
    elapsed: float = 0.0
    compute_time: float = 0.0

    @property
    def verified_per_minute(self) -> float:
        """Verified motions per wall-clock minute of this run."""
        return 60.0 * self.verified_this_run / self.elapsed if self.elapsed > 0 else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"out": str(self.out), "count": self.count, "skipped": self.skipped,
                "computed": self.computed, "lost": self.lost, "counts": self.counts,
                "verified_this_run": self.verified_this_run, "complete": self.complete,
                "elapsed": self.elapsed, "compute_time": self.compute_time,
                "verified_per_minute": self.verified_per_minute}


def make_job(cell: str | os.PathLike[str], specs: BatchSpecs, dtype: str = "float32"
             ) -> tuple[BatchJob, Cell]:
    """The shared job of a run and the parsed cell (checked against the specs).

    Parameters
    ----------
    cell : str or Path
        Cell name (``config/<name>.yaml``) or YAML path.
    specs : BatchSpecs
    dtype : {"float32", "float64"}
    """
    from ltl_human_motion.planning.pipeline import resolve_cell
    from ltl_human_motion.scene.cell_yaml import cell_from_yaml
    resolved = resolve_cell(Path(cell) if isinstance(cell, os.PathLike) else cell)
    source = Path(resolved.source)
    if not source.is_file():
        raise BatchConfigError(f"cell {cell!r}: a batch needs a cell file (got source "
                               f"{resolved.source!r})")
    try:
        text = read_text_file(source, "cell file")
    except TextFileError as exc:
        raise BatchConfigError(str(exc)) from None
    parsed = cell_from_yaml(text, source=str(source), base_dir=source.parent)
    validate_against_cell(specs, parsed)
    job = BatchJob(cell_yaml=text, cell_source=str(source), cell_base_dir=str(source.parent),
                   options=dict(specs.options), sequence_mode=specs.sequence_mode,
                   keep_unverified=specs.keep_unverified, dtype=dtype,
                   statures=specs.statures, descriptions=dict(specs.descriptions))
    return job, parsed


def _header(job: BatchJob, specs: BatchSpecs, cell: Cell, seed: int, count: int,
            shard_size: int) -> dict[str, Any]:
    from ltl_human_motion.batch.captions import PHASES
    from ltl_human_motion.motion.skeleton import JOINT_NAMES, PARENTS
    ident = {"job": job.fingerprint(), "specs": specs.fingerprint(), "seed": int(seed),
             "count": int(count), "shard_size": int(shard_size)}
    fingerprint = hashlib.sha256(json.dumps(ident, sort_keys=True).encode()).hexdigest()
    return {"format": DATASET_FORMAT, "version": DATASET_VERSION, "fingerprint": fingerprint,
            "cell": {"name": cell.name, "source": Path(job.cell_source).name,
                     "sha256": hashlib.sha256(job.cell_yaml.encode()).hexdigest()},
            "specs": specs.to_dict(), "seed": int(seed), "count": int(count),
            "shard_size": int(shard_size), "dtype": job.dtype,
            "joint_names": list(JOINT_NAMES), "joint_parents": list(PARENTS),
            "object_names": sorted(cell.objects), "phases": list(PHASES),
            "complete": False}


# --------------------------------------------------------------------------- executors

Outcome = tuple[ItemParams, ItemResult | None, str | None]


def _run_inline(job: BatchJob, items: list[ItemParams], workers: int) -> Iterator[Outcome]:
    prepare_worker(job)
    for item in items:
        yield item, run_item(job, item), None


#: Thread pools of numeric libraries in worker processes: one thread each (as Dask's
#: worker processes do), so N workers on N cores do not oversubscribe them.
_SINGLE_THREAD_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


@contextlib.contextmanager
def _worker_environment() -> Iterator[None]:
    """Set the single-thread variables the spawned workers inherit (unless already set)."""
    added = [k for k in _SINGLE_THREAD_ENV if k not in os.environ]
    for key in added:
        os.environ[key] = "1"
    try:
        yield
    finally:
        for key in added:
            os.environ.pop(key, None)


def _run_pool(job: BatchJob, items: list[ItemParams], workers: int) -> Iterator[Outcome]:
    ctx = multiprocessing.get_context("spawn")
    window = 2 * workers + 2
    pending: dict[Future, ItemParams] = {}
    queue = iter(items)
    with _worker_environment(), ProcessPoolExecutor(
            max_workers=workers, mp_context=ctx, initializer=pool_initializer,
            initargs=(job,)) as pool:
        broken: str | None = None
        while True:
            while broken is None and len(pending) < window:
                item = next(queue, None)
                if item is None:
                    break
                try:
                    pending[pool.submit(run_item, job, item)] = item
                except BrokenProcessPool as exc:
                    broken = f"process pool broke: {exc}"
                    yield item, None, broken
            if not pending:
                break
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                item = pending.pop(fut)
                try:
                    yield item, fut.result(), None
                except BrokenProcessPool as exc:
                    broken = f"a worker process died: {exc}"
                    yield item, None, broken
        if broken is not None:
            for item in queue:
                yield item, None, broken


def _run_dask(scheduler: str, job: BatchJob, items: list[ItemParams], workers: int
              ) -> Iterator[Outcome]:
    from ltl_human_motion.batch.dask_backend import run_on_dask
    yield from run_on_dask(scheduler, job, items, workers)


def _prewarm(statures: set[float], library_source: str | None) -> None:
    """Build missing libraries once here, so parallel workers do not all build them
    (one already cached is left to the workers to load)."""
    from ltl_human_motion.motion.library import library_cached, load_library
    for stature in sorted(statures):
        if not library_cached(stature, library_source):
            load_library(stature=stature, source=library_source)


# --------------------------------------------------------------------------- driver

def run_batch(cell: str | os.PathLike[str], specs: BatchSpecs | str | os.PathLike[str],
              count: int,
              out: str | os.PathLike[str], *, seed: int = 0, workers: int | None = None,
              scheduler: str | None = None, shard_size: int = 100, dtype: str = "float32",
              progress: bool = True, on_item: Callable[[ItemResult], None] | None = None,
              assess: ItemAssessment | None = None) -> BatchSummary:
    """Generate (or finish) a dataset of ``count`` items in ``out``.

    Parameters
    ----------
    cell : str or Path
        Cell name or YAML path.
    specs : BatchSpecs or path-like
        Parsed specs or a specs file.
    count : int
        Number of items (indices ``0 .. count - 1``).
    out : path-like
        Dataset folder; a folder from an interrupted run with the same inputs resumes.
    seed : int
        Global seed; item ``i`` depends only on ``(seed, i)`` and the inputs.
    workers : int, optional
        Worker processes (default: CPU count); 0 runs in this process. With
        ``scheduler="local"`` the number of Dask workers.
    scheduler : str, optional
        Dask scheduler address, or ``"local"`` for a LocalCluster on 127.0.0.1.
    shard_size : int
        Items per shard.
    dtype : {"float32", "float64"}
    progress : bool
        Show a tqdm progress bar (rate and ETA) on stderr.
    on_item : callable, optional
        Called with every stored result (e.g. to stop a test run).
    assess : ItemAssessment, optional
        Per-item assessment (:attr:`BatchJob.assess`; handed over by ``study``).

    Returns
    -------
    BatchSummary
        ``complete`` is False when worker processes died; run again to finish.
    """
    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise ValueError(f"count must be an integer >= 1, got {count!r}")
    if isinstance(shard_size, bool) or not isinstance(shard_size, int) or shard_size < 1:
        raise ValueError(f"shard_size must be an integer >= 1, got {shard_size!r}")
    workers = (os.cpu_count() or 1) if workers is None else int(workers)
    if workers < 0:
        raise ValueError(f"workers must be >= 0, got {workers}")
    if workers == 0 and scheduler is not None:
        raise ValueError("workers=0 (in-process) cannot be combined with a scheduler")
    if not isinstance(specs, BatchSpecs):
        specs = load_specs(specs)
    job, parsed_cell = make_job(cell, specs, dtype)
    if assess is not None:
        job = replace(job, assess=assess)
    store = DatasetStore(out, _header(job, specs, parsed_cell, seed, count, shard_size))
    try:
        return _run_store(store, job, specs, seed, count, workers, scheduler, progress,
                          on_item)
    finally:
        store.close()


def _run_store(store: DatasetStore, job: BatchJob, specs: BatchSpecs, seed: int, count: int,
               workers: int, scheduler: str | None, progress: bool,
               on_item: Callable[[ItemResult], None] | None) -> BatchSummary:
    summary = BatchSummary(out=store.root, count=count)
    done = store.recover()
    summary.skipped = len(done)
    todo = [derive_item(specs, seed, i) for i in range(count) if i not in done]
    # Workers preload the libraries this run needs (not the whole grid); on this machine
    # they are built here first, once, instead of by every worker at the same time.
    job = replace(job, statures=tuple(sorted({it.stature for it in todo})))
    if todo and (scheduler is None or scheduler == "local"):
        _prewarm(set(job.statures), job.synthesis_options().library_source)
    if workers == 0:
        execute = _run_inline(job, todo, 1)
    elif scheduler is None:
        execute = _run_pool(job, todo, workers)
    else:
        execute = _run_dask(scheduler, job, todo, workers)
    staged = store.staged_items()
    from tqdm import tqdm
    bar = tqdm(total=count, initial=len(done), unit="motion", disable=not progress,
               dynamic_ncols=True, smoothing=0.05, desc="batch")
    t0 = time.perf_counter()
    tally = {"ok": 0, "unverified": 0, "failed": 0}
    try:
        for item, result, lost in execute:
            if result is None:
                summary.lost.append((item.index, str(lost)))
                continue
            store.stage(result)
            staged.add(result.index)
            shard = store.shard_of(result.index)
            if store.shard_complete(shard, staged):
                store.pack(shard)
                staged.difference_update(store.shard_range(shard))
            summary.computed += 1
            summary.compute_time += float(result.timing.get("compute_time", 0.0))
            tally[result.record["status"]] += 1
            summary.verified_this_run += int(result.record["status"] == "ok")
            bar.set_postfix(tally, refresh=False)
            bar.update(1)
            if on_item is not None:
                on_item(result)
    finally:
        bar.close()
        summary.elapsed = time.perf_counter() - t0
        if hasattr(execute, "close"):
            execute.close()
    if not summary.lost:
        summary.counts = store.finalize()
        summary.complete = True
    return summary
