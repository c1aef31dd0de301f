"""The work of one item, run in a worker process (process pool or Dask worker).

A :class:`BatchJob` holds what every item of a run shares (the cell as YAML text, the
synthesis options); it is small and picklable. Each worker process keeps the parsed cell
and the motion libraries in a module-level cache (:func:`prepare_worker`), so they are
loaded once per process, not once per item.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ltl_human_motion.batch.items import ItemParams, cell_for_item
from ltl_human_motion.batch.memory import keep_freed_memory
from ltl_human_motion.kernel.cache import BoundedCache

__all__ = ["ARRAY_NAMES", "LABEL_NAMES", "STORED_NAMES", "BatchJob", "ItemAssessment",
           "ItemResult", "labels_sha256", "motion_sha256", "pool_initializer",
           "prepare_worker", "run_item"]

#: Per-item motion arrays, in the order they are hashed (``motion_sha256``) and stored.
ARRAY_NAMES = ("positions", "root_yaw", "task_index", "objects")
#: Per-frame label arrays (``labels_sha256``), stored after the motion arrays.
LABEL_NAMES = ("task_label", "phase")
STORED_NAMES = ARRAY_NAMES + LABEL_NAMES
#: Captions per item: the canonical sentence and paraphrases.
N_CAPTIONS = 4
DTYPES = ("float32", "float64")
#: Libraries kept preloaded per worker (each is ~80 MB in memory).
PRELOAD_LIMIT = 8
# Wall-clock seconds inside error messages (planner budget); moved to the timing part so
# records of failed items stay identical between runs.
_SECONDS_IN_MESSAGE = re.compile(r"(\d+ nodes), \d+(?:\.\d+)? s\b")


@dataclass(frozen=True)
class ItemAssessment:
    """A per-item assessment a higher layer hands the batch (the study's
    :func:`ltl_human_motion.study.item.assess_item`: ergonomics, cycle time, offline SSM).

    Attributes
    ----------
    run : callable
        ``run(synth, cell, item, settings) -> dict``: the figures of one stored motion
        (``record["study"]``); a module-level function, so that jobs pickle to workers.
    settings : dict
        Its settings (JSON-ready; part of the job's fingerprint).
    """

    run: Callable[[Any, Any, ItemParams, dict[str, Any]], dict[str, Any]]
    settings: dict[str, Any]


@dataclass(frozen=True)
class BatchJob:
    """What every item of a run shares.

    Attributes
    ----------
    cell_yaml : str
        The cell description (YAML text).
    cell_source : str
        Its file (for messages and ``Cell.source``).
    cell_base_dir : str or None
        Folder that relative mesh paths of the cell are resolved against.
    options : dict
        :meth:`SynthesisOptions.from_dict` keys (``verify`` is always off: the worker
        decides from the report).
    sequence_mode : str
    keep_unverified : bool
    dtype : {"float32", "float64"}
        Storage type of positions, yaw and object tracks.
    statures : tuple of float
        The stature grid (libraries are preloaded when it is small).
    descriptions : dict of str to str
        Names captions use for things of the cell (the specs file's ``descriptions``).
    assess : ItemAssessment or None
        The per-item assessment whose figures go into ``record["study"]``; None (the
        default) for none.
    """

    cell_yaml: str
    cell_source: str = "<inline>"
    cell_base_dir: str | None = None
    options: dict[str, Any] = field(default_factory=dict)
    sequence_mode: str = "random"
    keep_unverified: bool = False
    dtype: str = "float32"
    statures: tuple[float, ...] = (1.75,)
    assess: ItemAssessment | None = None
    descriptions: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.dtype not in DTYPES:
            raise ValueError(f"dtype must be one of {DTYPES}, got {self.dtype!r}")

    def fingerprint(self) -> str:
        """SHA-256 (hex) of everything that changes the produced data."""
        data = {"cell_sha256": hashlib.sha256(self.cell_yaml.encode("utf-8")).hexdigest(),
                "options": self.options, "sequence_mode": self.sequence_mode,
                "keep_unverified": self.keep_unverified, "dtype": self.dtype}
        if self.assess is not None:
            data["assess"] = self.assess.settings
        if self.descriptions:
            data["descriptions"] = self.descriptions
        return hashlib.sha256(json.dumps(data, sort_keys=True).encode("utf-8")).hexdigest()

    def synthesis_options(self):
        """The options used for every item: deterministic search limits, no raising.

        Unless the specs set ``max_seconds``, the wall-clock budget of each search is
        lifted (only ``max_nodes`` bounds it), so results do not depend on machine load.
        """
        from ltl_human_motion.planning.astar import SearchBudget
        from ltl_human_motion.planning.pipeline import SynthesisOptions
        opts = SynthesisOptions.from_dict(dict(self.options))
        planner = opts.planner
        if "max_seconds" not in self.options:
            planner = replace(planner, budget=SearchBudget(planner.budget.max_nodes, math.inf))
        return replace(opts, planner=planner, verify=False, sequence_mode=self.sequence_mode)


@dataclass
class ItemResult:
    """The outcome of one item.

    Attributes
    ----------
    record : dict
        Deterministic metadata (the manifest entry without shard placement).
    timing : dict
        Compute times and the worker (differ between runs).
    arrays : dict of str to ndarray or None
        ``positions`` (T, J, 3), ``root_yaw`` (T,), ``task_index`` (T,) int16,
        ``objects`` (T, N, 3) with N = objects of the cell sorted by name,
        ``task_label`` (T,) int16 and ``phase`` (T,) int8
        (:mod:`~ltl_human_motion.batch.captions`); None when the item failed.
    """

    record: dict[str, Any]
    timing: dict[str, Any]
    arrays: dict[str, np.ndarray] | None = None

    @property
    def index(self) -> int:
        return int(self.record["index"])


# --------------------------------------------------------------------------- worker state

@dataclass(frozen=True)
class _PreparedCell:
    """A job's cell, parsed once per process, with its synthesis options and the names
    its captions use."""

    cell: Any
    options: Any
    names: Any


#: The prepared cells of this process, by job fingerprint.
_PREPARED: BoundedCache[_PreparedCell] = BoundedCache(5)


def _prepared(job: BatchJob) -> _PreparedCell:
    def build() -> _PreparedCell:
        from ltl_human_motion.batch.captions import CellNames
        from ltl_human_motion.scene.cell_yaml import cell_from_yaml
        cell = cell_from_yaml(job.cell_yaml, source=job.cell_source,
                              base_dir=job.cell_base_dir)
        return _PreparedCell(cell, job.synthesis_options(),
                             CellNames.from_cell(cell, job.descriptions))

    return _PREPARED.get_or_build(job.fingerprint(), build)


def _cell_and_options(job: BatchJob) -> tuple[Any, Any]:
    prepared = _prepared(job)
    return prepared.cell, prepared.options


def prepare_worker(job: BatchJob) -> None:
    """Parse the cell and load the libraries of a small stature grid in this process.

    Called once per worker process (pool initializer, Dask worker plugin); items also
    call it implicitly, so it is an optimization, not a requirement. The process keeps
    freed heap memory for reuse (:func:`~ltl_human_motion.batch.memory.keep_freed_memory`).
    """
    from ltl_human_motion.planning.pipeline import get_library
    keep_freed_memory()
    _, options = _cell_and_options(job)
    if len(job.statures) <= PRELOAD_LIMIT:
        for stature in job.statures:
            get_library(float(stature), options.library_source)


def _exit_with_parent(parent: int, period: float) -> None:
    while os.getppid() == parent:
        time.sleep(period)
    os._exit(1)                     # the driver is gone: stop, do not finish the item


def pool_initializer(job: BatchJob, period: float = 1.0) -> None:
    """Initializer of process-pool workers: :func:`prepare_worker`, and exit with the driver.

    A killed driver would otherwise leave its workers computing their current items.
    """
    threading.Thread(target=_exit_with_parent, args=(os.getppid(), period), daemon=True,
                     name="lhm-exit-with-parent").start()
    prepare_worker(job)


# --------------------------------------------------------------------------- one item

def _plain(value: Any) -> Any:
    """JSON-ready plain Python; non-finite floats become None."""
    kind = type(value)                  # the common leaves first, by exact type
    if kind is float:
        return value if math.isfinite(value) else None
    if kind is int or kind is str or value is None:
        return value
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else None
    if value is None or isinstance(value, str):
        return value
    return str(value)


def _sha256_of(arrays: dict[str, np.ndarray], names: tuple[str, ...]) -> str:
    h = hashlib.sha256()
    for name in names:
        arr = np.ascontiguousarray(arrays[name])
        h.update(f"{name}|{arr.dtype.str}|{arr.shape}|".encode())
        h.update(arr.tobytes())
    return h.hexdigest()


def motion_sha256(arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 (hex) over the item arrays: names, dtypes, shapes and bytes, in order."""
    return _sha256_of(arrays, ARRAY_NAMES)


def labels_sha256(arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 (hex) over the label arrays (:data:`LABEL_NAMES`), as :func:`motion_sha256`."""
    return _sha256_of(arrays, LABEL_NAMES)


def _annotate(synth, names, record: dict[str, Any]) -> dict[str, np.ndarray]:
    """Captions and goal steps into ``record``; the per-frame label arrays."""
    from ltl_human_motion.batch.captions import GoalStep, captions, frame_labels
    steps = [GoalStep.from_dict(d) for d in synth.stats.steps]
    labels = frame_labels(synth.n_frames, [seg.end_frame for seg in synth.timeline], steps,
                          synth.stats.segments, synth.positions, synth.fps)
    record["steps"] = [s.to_dict() for s in steps]
    record["captions"] = captions(synth.sequence, steps, names, int(record["seed"]),
                                  N_CAPTIONS, labels.phase, synth.fps)
    return {"task_label": labels.task, "phase": labels.phase}


def _arrays(synth, dtype: str) -> dict[str, np.ndarray]:
    names = sorted(synth.objects)
    T = synth.n_frames
    objects = (np.stack([synth.objects[n] for n in names], axis=1) if names
               else np.zeros((T, 0, 3)))
    return {"positions": np.ascontiguousarray(synth.positions, dtype=dtype),
            "root_yaw": np.ascontiguousarray(synth.root_yaw, dtype=dtype),
            "task_index": synth.task_index.astype(np.int16),
            "objects": np.ascontiguousarray(objects, dtype=dtype)}


def _first_failure(report: dict) -> tuple[str | None, str]:
    for name, check in report.items():
        if isinstance(check, dict) and not check.get("passed", True):
            return name, str(check.get("detail", ""))
    return None, ""


def run_item(job: BatchJob, item: ItemParams) -> ItemResult:
    """Synthesize and verify one item; errors of the item become a ``failed`` record.

    Returns
    -------
    ItemResult
        ``record["status"]`` is ``"ok"`` (verified), ``"unverified"`` (a check failed
        and ``job.keep_unverified``) or ``"failed"`` (``record["error"]`` says why).
    """
    from ltl_human_motion.planning.pipeline import get_library, synthesize

    t0, c0 = time.perf_counter(), time.process_time()
    from ltl_human_motion.ltl.spec import PAPER_SPECS

    record: dict[str, Any] = {
        "index": item.index, "spec_name": item.spec_name, "spec": item.spec,
        "ltl": PAPER_SPECS.get(item.spec.strip(), item.spec), "seed": item.seed,
        "params": item.params_dict(), "status": "failed",
        "sequence": None, "lasso": None, "duration": None, "n_frames": None, "fps": None,
        "verified": False, "verification": None, "motion_sha256": None, "error": None,
        "nodes_expanded": None, "start_pose": None, "captions": None, "steps": None,
        "labels_sha256": None}
    timing: dict[str, Any] = {"worker": f"{socket.gethostname()}:{os.getpid()}"}
    arrays = None
    try:
        prepared = _prepared(job)
        cell = cell_for_item(prepared.cell, item)
        library = get_library(float(item.stature), prepared.options.library_source)
        synth = synthesize(item.spec, cell, library=library, variants=1, seed=item.seed,
                           cycles=item.cycles, stature=item.stature,
                           options=prepared.options)[0]
    except Exception as exc:
        message = str(exc)
        if _SECONDS_IN_MESSAGE.search(message):
            timing["error_message"] = message
            message = _SECONDS_IN_MESSAGE.sub(r"\1", message)
        record["error"] = {"type": type(exc).__name__, "message": message,
                           "check": getattr(exc, "check", None),
                           "task": getattr(exc, "task", None)}
        timing["compute_time"] = time.perf_counter() - t0
        timing["cpu_time"] = time.process_time() - c0
        return ItemResult(record, timing, None)
    report = _plain(synth.verification)
    failed_check, detail = _first_failure(report)
    if failed_check is None and report.get("passed", True) is False:
        failed_check, detail = "passed", "the verification report did not pass"
    verified = failed_check is None
    record.update({"sequence": list(synth.sequence), "lasso": str(synth.stats.lasso),
                   "duration": float(synth.duration), "n_frames": int(synth.n_frames),
                   "fps": float(synth.fps), "verified": verified, "verification": report,
                   "nodes_expanded": int(synth.stats.nodes_expanded),
                   "start_pose": _plain(synth.stats.start_pose),
                   "realism": _plain(synth.stats.realism)})
    if verified or job.keep_unverified:
        arrays = _arrays(synth, job.dtype)
        record["motion_sha256"] = motion_sha256(arrays)
        arrays.update(_annotate(synth, prepared.names, record))
        record["labels_sha256"] = labels_sha256(arrays)
        record["status"] = "ok" if verified else "unverified"
    if not verified:
        record["error"] = {"type": "VerificationError", "message": detail,
                           "check": failed_check, "task": None}
    if job.assess is not None and arrays is not None:
        t_assess = time.perf_counter()
        record["study"] = _plain(job.assess.run(synth, cell, item, job.assess.settings))
        timing["assess_time"] = time.perf_counter() - t_assess
    timing.update({k: float(v) for k, v in synth.stats.to_dict().items()
                   if k.endswith("_time") and k != "batch_total_time"})
    timing["compute_time"] = time.perf_counter() - t0
    timing["cpu_time"] = time.process_time() - c0
    return ItemResult(record, timing, arrays)
