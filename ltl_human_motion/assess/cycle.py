"""Cycle time and waste of a motion: walking, value-adding work and waiting.

Frames are classified by the task they execute (``task_index``): the approach gait between
tasks and ``walk``/``carry``/``enter`` steps are walking, ``wait`` steps waiting, every
other goal task (grasp, assemble, insert, move, hand and posture tasks) value-adding work,
as in lean time studies (walking and waiting are waste).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ltl_human_motion.assess.ergonomics import _WALK_KINDS, task_kind
from ltl_human_motion.motion.skeleton import JOINT_INDEX

if TYPE_CHECKING:
    from ltl_human_motion.planning.result import SynthesizedMotion

__all__ = ["CATEGORIES", "cycle_breakdown", "floor_path"]

CATEGORIES = ("walking", "value_adding", "waiting")


def floor_path(positions: np.ndarray) -> np.ndarray:
    """Pelvis path on the floor, shape (T, 2)."""
    return np.asarray(positions)[:, JOINT_INDEX["pelvis"], :2]


def _path_length(xy: np.ndarray, mask: np.ndarray) -> float:
    if len(xy) < 2:
        return 0.0
    step = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    return float(np.sum(step[mask[1:] & mask[:-1]]))


def cycle_breakdown(synth: SynthesizedMotion, cycles: int = 1) -> dict[str, Any]:
    """Time and distance by category, per task step and per cycle.

    Parameters
    ----------
    synth : SynthesizedMotion
    cycles : int
        Work cycles the motion contains (figures "per cycle" divide by it).

    Returns
    -------
    dict
        ``cycle_time`` (s), ``total`` {category: seconds}, ``share`` {category: fraction},
        ``walking_distance`` (m), ``per_cycle`` (the same divided by ``cycles``) and
        ``per_task``: for each step its approach walk (time, distance) and its own time and
        category.
    """
    if int(cycles) < 1:
        raise ValueError(f"cycles must be >= 1, got {cycles}")
    fps = synth.fps
    T = synth.n_frames
    idx = synth.task_index
    cat = np.full(T, "walking", dtype=object)
    kinds = [task_kind(synth.task_label(i)) for i in range(len(synth.timeline))]
    per_task = []
    xy = floor_path(synth.positions)
    prev_end = 0
    for i, (seg, kind) in enumerate(zip(synth.timeline, kinds)):
        c = ("walking" if kind in _WALK_KINDS else "waiting" if kind == "wait"
             else "value_adding")
        cat[seg.start_frame:seg.end_frame] = c
        approach = np.zeros(T, dtype=bool)
        approach[prev_end:seg.start_frame] = idx[prev_end:seg.start_frame] < 0
        own = np.zeros(T, dtype=bool)
        own[seg.start_frame:seg.end_frame] = True
        per_task.append({
            "step": i, "task": synth.task_label(i), "category": c,
            "approach_time": float(approach.sum()) / fps,
            "approach_distance": _path_length(xy, approach),
            "task_time": seg.n_frames / fps,
            "task_distance": _path_length(xy, own) if c == "walking" else 0.0,
        })
        prev_end = seg.end_frame
    duration = synth.duration
    # Frame counts as shares of the duration (T frames span (T - 1) / fps seconds).
    total = {c: float(np.sum(cat == c)) / max(T, 1) * duration for c in CATEGORIES}
    walk_mask = cat == "walking"
    distance = _path_length(xy, walk_mask)
    n = int(cycles)
    return {
        "cycle_time": duration / n,
        "cycles": n,
        "total": total,
        "share": {c: (total[c] / duration if duration > 0 else 0.0) for c in CATEGORIES},
        "walking_distance": distance,
        "per_cycle": {"cycle_time": duration / n, "walking_distance": distance / n,
                      **{c: total[c] / n for c in CATEGORIES}},
        "per_task": per_task,
    }
