"""Calibrate the cell model's estimate of a motion's length against synthesized motions.

Synthesizes the feasible corpus pairs of the ``config/`` cells (``scenarios/specs.yaml``),
S1 and S2 with one and two cycles, and two 10-part kitting jobs; fits the constants of
:class:`ltl_human_motion.tasks.model.TimeCalibration` (walking speed, time per walk, time
per task kind, a constant per motion) by non-negative least squares on the tasks of the
motions of the ``--fit`` stature and seed (each task's time from the end of the one
before to its own end), and states the relative error on the motions of the other
statures and seeds (not used for the fit). Prints the constants and the errors and writes
``bench/results/time_estimate.json``. Copy the constants into ``TIME_CALIBRATION`` of
``ltl_human_motion/tasks/model.py``. Not a test: run ``python bench/time_estimate.py``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.errors import LtlHumanMotionError  # noqa: E402
from ltl_human_motion.ltl.formula import Atom  # noqa: E402
from ltl_human_motion.planning.pipeline import resolve_cell, synthesize  # noqa: E402
from ltl_human_motion.scenarios.corpus import load_corpus  # noqa: E402
from ltl_human_motion.scene.termination import parse_task  # noqa: E402
from ltl_human_motion.tasks.model import (  # noqa: E402
    NOMINAL_DURATION,
    CellModel,
    TimeCalibration,
    estimated_duration,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paper_specs import machine  # noqa: E402

KINDS = tuple(NOMINAL_DURATION)
KITTING = ("F move(P0, R1) & F move(P1, R1) & F move(P2, R1) & F move(P3, R1) & "
           "F move(P4, R1) & F move(P5, R1) & F move(P6, R1) & F move(P7, R1) & "
           "F move(P8, R1) & F move(P9, R1)",
           "F grasp(P0) & F grasp(P1) & F grasp(P2) & F grasp(P3) & F grasp(P4) & "
           "F grasp(P5) & F grasp(P6) & F grasp(P7) & F grasp(P8) & F grasp(P9)")


@dataclass
class Sample:
    """One synthesized motion: its features under the model and its length."""

    cell: str
    spec: str
    stature: float
    seed: int
    duration: float
    features: np.ndarray      # (3 + len(KINDS),): start, distance, walks, per-kind count
    fixed: float              # seconds the model knows exactly (wait(t))
    steps: list[tuple[np.ndarray, float]]   # per task: its features, its seconds less fixed


def _unit(walk_speed: float, overhead: float, kind: str | None) -> TimeCalibration:
    return TimeCalibration(walk_speed, overhead, 0.0,
                           {k: float(k == kind) for k in KINDS})


def features(model: CellModel, tasks: list) -> tuple[np.ndarray, float] | None:
    """The estimate's features of ``tasks`` (see :class:`Sample`), or None."""
    fast = 1e12
    fixed = estimated_duration(model, tasks, _unit(fast, 0.0, None))
    if fixed is None:
        return None
    dist = estimated_duration(model, tasks, _unit(1.0, 0.0, None)) - fixed
    walks = estimated_duration(model, tasks, _unit(fast, 1.0, None)) - fixed
    counts = [estimated_duration(model, tasks, _unit(fast, 0.0, k)) - fixed for k in KINDS]
    return np.array([1.0, dist, round(walks), *np.round(counts)]), fixed


def step_rows(model: CellModel, tasks: list, ends: list[float], duration: float
              ) -> list[tuple[np.ndarray, float]] | None:
    """Per task: its features (those of the sequence up to it less those before it) and
    its seconds in the motion (from the end of the task before to its own end; the last
    task also takes the motion's tail and the constant per motion)."""
    prefix = [features(model, tasks[:i]) for i in range(len(tasks) + 1)]
    if any(p is None for p in prefix) or len(ends) != len(tasks):
        return None
    rows, before = [], 0.0
    for i in range(len(tasks)):
        f = prefix[i + 1][0] - prefix[i][0]
        seconds = ends[i] - before - (prefix[i + 1][1] - prefix[i][1])
        before = ends[i]
        f[0] = 0.0
        if i == len(tasks) - 1:
            f[0], seconds = 1.0, seconds + duration - ends[-1]
        rows.append((f, seconds))
    return rows


def jobs(kitting: bool) -> list[tuple[str, str, int]]:
    """(cell file, specification, cycles) to synthesize."""
    out = [(p.cell_file, p.spec, 1) for p in load_corpus()
           if p.feasible and "/config/" in p.cell_file]
    paper = str(ROOT / "config" / "paper_cell.yaml")
    out += [(paper, s, c) for s in ("S1", "S2") for c in (1, 2)]
    if kitting:
        out += [(str(ROOT / "config" / "kitting_cell.yaml"), s, 1) for s in KITTING]
    return out


def collect(todo: list[tuple[str, str, int]], stature: float, seed: int) -> list[Sample]:
    samples = []
    for cell_file, spec, cycles in todo:
        cell = resolve_cell(cell_file)
        try:
            m = synthesize(spec, cell, seed=seed, cycles=cycles, stature=stature)[0]
        except LtlHumanMotionError:
            continue
        if not m.verification.get("passed"):
            continue
        model = CellModel.from_cell(cell)
        tasks = [Atom(*parse_task(t)) for t in m.sequence]
        got = features(model, tasks)
        duration = float(m.motion.duration)
        steps = step_rows(model, tasks, [s.end_frame / m.motion.fps for s in m.timeline],
                          duration)
        if got is None or steps is None:
            continue
        samples.append(Sample(Path(cell_file).stem, spec, stature, seed, duration, *got,
                              steps))
    return samples


def fit(samples: list[Sample]) -> np.ndarray:
    """Non-negative least squares of each task's seconds on its features (columns no
    sample uses get their nominal value)."""
    from scipy.optimize import nnls
    X = np.array([f for s in samples for f, _ in s.steps])
    y = np.array([t for s in samples for _, t in s.steps])
    used = X.any(axis=0)
    coef = np.zeros(X.shape[1])
    coef[used], _ = nnls(X[:, used], y)
    for j, kind in enumerate(KINDS):
        if not used[3 + j]:
            coef[3 + j] = NOMINAL_DURATION[kind]
    return coef


def calibration(coef: np.ndarray, motions: int, errors: list[float]) -> TimeCalibration:
    return TimeCalibration(
        walk_speed=float(1.0 / coef[1]) if coef[1] > 0 else 1e12,
        walk_overhead=float(coef[2]), start=float(coef[0]),
        durations={k: float(v) for k, v in zip(KINDS, coef[3:])}, motions=motions,
        median_error=statistics.median(errors) if errors else 0.0,
        max_error=max(errors, default=0.0))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fit", type=float, nargs=2, default=[1.75, 0],
                        metavar=("STATURE", "SEED"))
    parser.add_argument("--check", type=float, nargs="+", default=[1.6, 1.9],
                        help="statures of the held-out motions (seed: the fit's + 1)")
    parser.add_argument("--no-kitting", action="store_true",
                        help="leave out the two 10-part kitting jobs (111 s of motion each)")
    parser.add_argument("--out", default=str(ROOT / "bench" / "results" / "time_estimate.json"))
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    todo = jobs(not args.no_kitting)
    stature, seed = float(args.fit[0]), int(args.fit[1])
    train = collect(todo, stature, seed)
    coef = fit(train)
    test = [s for st in args.check for s in collect(todo, st, seed + 1)]
    rel = [abs(float(s.features @ coef) + s.fixed - s.duration) / s.duration for s in test]
    rel_train = [abs(float(s.features @ coef) + s.fixed - s.duration) / s.duration
                 for s in train]
    cal = calibration(coef, len(train), rel)
    worst = sorted(zip(rel, test), key=lambda x: -x[0])[:5]
    result = {
        "machine": machine(), "wall_s": time.perf_counter() - t0,
        "fit": {"stature": stature, "seed": seed, "motions": len(train),
                "median_error": statistics.median(rel_train), "max_error": max(rel_train)},
        "check": {"statures": args.check, "seed": seed + 1, "motions": len(test),
                  "median_error": cal.median_error, "max_error": cal.max_error,
                  "p90_error": float(np.percentile(rel, 90)) if rel else None,
                  "worst": [{"cell": s.cell, "spec": s.spec, "stature": s.stature,
                             "motion_s": s.duration,
                             "estimate_s": float(s.features @ coef) + s.fixed,
                             "error": e} for e, s in worst]},
        "calibration": {"walk_speed": cal.walk_speed, "walk_overhead": cal.walk_overhead,
                        "start": cal.start, "durations": dict(cal.durations)},
        "nominal_model": _nominal_error(test),
    }
    atomic_write_text(Path(args.out), json.dumps(result, indent=1) + "\n")
    print(json.dumps({k: result[k] for k in ("fit", "check", "calibration",
                                             "nominal_model")}, indent=1))
    return 0


def _nominal_error(samples: list[Sample]) -> dict[str, float]:
    """The error of the search's own cost (nominal durations, 1 m/s) on the same motions."""
    from ltl_human_motion.tasks.model import WALK_SPEED
    coef = np.array([0.0, 1.0 / WALK_SPEED, 0.0, *(NOMINAL_DURATION[k] for k in KINDS)])
    rel = [abs(float(s.features @ coef) + s.fixed - s.duration) / s.duration for s in samples]
    under = [(float(s.features @ coef) + s.fixed) / s.duration for s in samples]
    return {"median_error": statistics.median(rel) if rel else 0.0,
            "max_error": max(rel, default=0.0),
            "median_ratio_estimate_to_motion": statistics.median(under) if under else 0.0}


if __name__ == "__main__":
    sys.exit(main())
