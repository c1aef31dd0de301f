"""Run a cell study on the batch machinery: variants x statures per layout, resumable.

Each layout is one dataset (:func:`~ltl_human_motion.batch.runner.run_batch`) under
``<out>/layouts/<label>/``: item ``i`` draws its stature from the grid and its synthesis
seed from ``(seed, i)``; the worker verifies the motion and adds its figures
(:func:`~ltl_human_motion.study.item.assess_item`) to the manifest record. A study that
was interrupted resumes where it stopped (same inputs, same folder); the report is then
made from the manifests and the stored motions.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ltl_human_motion.study.item import assess_item, assess_settings

__all__ = ["StudyConfig", "collect_layout", "run_study"]

#: Floor-path samples kept per second for the spaghetti plot and heat map.
PATH_RATE = 10.0


@dataclass(frozen=True)
class StudyConfig:
    """Inputs of a study.

    Attributes
    ----------
    cells : sequence of str
        One cell (name or YAML path) or two to compare (layout A, layout B).
    spec : str
        LTL specification (or a paper name such as ``S2``).
    variants : int
        Variants per stature: each layout gets ``variants * len(statures)`` items, and
        each item draws its stature from the grid (as batch items do), so the statures
        are equally likely, not equally counted.
    statures : sequence of float
        Body heights (m).
    robot : str or None
        Robot YAML (model, base, trajectory) for offline SSM; None: no robot.
    out : Path
    seed, workers, scheduler
        As for :func:`~ltl_human_motion.batch.runner.run_batch`.
    prediction_horizon : float
        Offline SSM with predicted occupancy this many seconds ahead (0: reactive).
    max_nodes : int
        Search bound of the planner per task (deterministic).
    sequence_mode : {"all", "random", "coverage"}
        Task sequences: ``all`` takes the shortest (variants then differ in start pose,
        part positions and planning), ``random`` random walks of the automaton.
    jitter : float
        Half-width (m) of the uniform x/y offsets of every part's position per item.
    labels : sequence of str, optional
        Layout names (default ``A``, ``B``).
    """

    cells: Sequence[str]
    spec: str
    variants: int = 50
    statures: Sequence[float] = (1.75,)
    robot: str | None = None
    out: Path = Path("out/study")
    seed: int = 0
    workers: int | None = None
    scheduler: str | None = None
    prediction_horizon: float = 0.0
    max_nodes: int = 5000
    sequence_mode: str = "all"
    jitter: float = 0.05
    labels: Sequence[str] = field(default_factory=lambda: ("A", "B"))

    def __post_init__(self) -> None:
        if not 1 <= len(self.cells) <= 2:
            raise ValueError(f"a study takes one cell or two to compare, got {len(self.cells)}")
        if isinstance(self.variants, bool) or int(self.variants) < 1:
            raise ValueError(f"variants must be >= 1, got {self.variants!r}")
        if not self.statures:
            raise ValueError("statures: give at least one stature")
        if len(self.labels) < len(self.cells):
            raise ValueError("labels: one per cell")
        if not (math.isfinite(self.jitter) and 0 <= self.jitter <= 0.5):
            raise ValueError(f"jitter must be in [0, 0.5] m, got {self.jitter}")

    @property
    def count(self) -> int:
        """Items per layout."""
        return int(self.variants) * len(self.statures)


def _specs(cfg: StudyConfig, objects: Sequence[str]):
    from ltl_human_motion.batch.specs import specs_from_yaml
    j = float(cfg.jitter)
    data: dict[str, Any] = {"version": 1, "specs": [{"name": "task", "spec": cfg.spec}],
                            "stature": [float(s) for s in cfg.statures],
                            "sequence_mode": cfg.sequence_mode,
                            "options": {"max_nodes": int(cfg.max_nodes)}}
    if j > 0:
        data["objects"] = {name: [j, j, 0.0] for name in objects}
    return specs_from_yaml(yaml.safe_dump(data, sort_keys=False), source="study")


def collect_layout(folder: Path, label: str, cell: str) -> dict[str, Any]:
    """Figures and floor paths of one layout's dataset.

    Returns
    -------
    dict
        ``label``, ``cell``, ``items`` (one dict per verified item: index, stature,
        sequence, duration and the ``study`` figures), ``failed`` (count, first errors,
        and per failed item its index, stature, seed and error: type, message, check,
        task), ``paths`` (list of (N, 2) pelvis paths at :data:`PATH_RATE`).
    """
    from ltl_human_motion.batch.reader import open_dataset
    from ltl_human_motion.motion.skeleton import JOINT_INDEX
    ds = open_dataset(folder)
    items, paths = [], []
    for it in ds.items(verified_only=True):
        r = it.record
        if "study" not in r:
            continue
        items.append({"index": r["index"], "stature": r["params"]["stature"],
                      "sequence": r["sequence"], "duration": r["duration"],
                      "seed": r["seed"], **r["study"]})
        step = max(round(it.fps / PATH_RATE), 1)
        paths.append(np.asarray(it.positions[::step, JOINT_INDEX["pelvis"], :2],
                                dtype=np.float64))
    failed = ds.failed()
    return {"label": label, "cell": cell, "items": items,
            "failed": {"count": len(failed),
                       "errors": [f.get("error") for f in failed[:5]],
                       "items": [{"index": f["index"], "stature": f["params"]["stature"],
                                  "seed": f["seed"], "sequence": f.get("sequence"),
                                  **(f.get("error") or {})} for f in failed]},
            "paths": paths}


def run_study(cfg: StudyConfig, progress: bool = True) -> dict[str, Any]:
    """Run (or finish) the study and write its report into ``cfg.out``.

    Returns
    -------
    dict
        The study JSON (also written to ``<out>/study.json``), with ``report`` naming the
        HTML page and the plots.
    """
    from tqdm import tqdm

    from ltl_human_motion.batch.runner import run_batch
    from ltl_human_motion.batch.worker import ItemAssessment
    from ltl_human_motion.planning.pipeline import resolve_cell
    from ltl_human_motion.study.report import write_report
    out = Path(cfg.out)
    objects = sorted(set.intersection(*(set(resolve_cell(c).objects) for c in cfg.cells)))
    specs = _specs(cfg, objects)
    settings = assess_settings(cfg.robot, cfg.prediction_horizon)
    total = cfg.count * len(cfg.cells)
    bar = tqdm(total=total, unit="item", desc="study", disable=not progress,
               dynamic_ncols=True, smoothing=0.05)
    t0 = time.perf_counter()
    runs = []
    try:
        for label, cell in zip(cfg.labels, cfg.cells):
            bar.set_postfix_str(f"layout {label}", refresh=True)
            summary = run_batch(cell, specs, cfg.count, out / "layouts" / label,
                                seed=cfg.seed, workers=cfg.workers, scheduler=cfg.scheduler,
                                progress=False, on_item=lambda _r: bar.update(1),
                                assess=ItemAssessment(assess_item, settings))
            bar.update(summary.skipped)
            runs.append(summary.to_dict())
            if not summary.complete:
                raise RuntimeError(f"layout {label}: {len(summary.lost)} item(s) lost "
                                   f"(worker died); run the study again to finish")
    finally:
        bar.close()
    elapsed = time.perf_counter() - t0
    layouts = [collect_layout(out / "layouts" / label, label, cell)
               for label, cell in zip(cfg.labels, cfg.cells)]
    meta = {"spec": cfg.spec, "variants": int(cfg.variants),
            "sequence_mode": cfg.sequence_mode, "jitter": float(cfg.jitter),
            "statures": [float(s) for s in cfg.statures], "robot": cfg.robot,
            "seed": int(cfg.seed), "prediction_horizon": float(cfg.prediction_horizon),
            "elapsed_s": elapsed, "batches": runs,
            "items_per_minute": (60.0 * sum(r["computed"] for r in runs) / elapsed
                                 if elapsed > 0 and not math.isclose(elapsed, 0) else None)}
    return write_report(layouts, out, meta)
