"""Quality checks on motion primitives, summarized as a JSON-ready report.

Checks on every primitive (world positions of the primitive started at the origin):

* ``bone_length``: largest deviation of any bone from its canonical length (m);
* ``floor``: lowest ankle/toe joint height (m); must be >= ``-floor_tolerance``;
* ``foot_skate``: mean horizontal speed (m/s) of a foot's contact point over the frames
  where it is within ``contact_height`` of its rest height, each frame weighted by
  ``2 - 2**(h / c)`` (1 on the floor, 0 at the contact height; the foot-skating measure of
  Zhang et al., "MOJO", 2021). Per foot the joint nearer the floor (heel = ankle, or
  ball = toe) is the contact point; the larger of the two feet is reported;
* ``joint_speed``: largest speed (m/s) of any joint between two frames (no jumps); the
  swing foot of normal walking peaks near 5 m/s and hands in fast reaching reach 5 to
  7 m/s, so the limit is 7 m/s;
* ``self_penetration``: deepest entry (m) of a body capsule's bone axis into another,
  non-neighbouring capsule (:func:`~ltl_human_motion.motion.biomechanics.
  self_penetration`); must be <= 0 (a foot through the other shank, an arm through the
  trunk). Loops whose processing makes the feet cross are dropped by this.

The gait library drops the (few) primitives that fail, so every primitive it holds passes.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass

import numpy as np

from ltl_human_motion.motion.skeleton import JOINT_INDEX, PARENTS, Skeleton
from ltl_human_motion.motion.types import MotionPrimitive, world_positions

__all__ = ["QualityThresholds", "check_primitives", "goal_sample", "primitive_metrics"]

_FEET = tuple(JOINT_INDEX[n] for n in ("l_ankle", "l_toe", "r_ankle", "r_toe"))


@dataclass(frozen=True)
class QualityThresholds:
    """Pass limits of the quality checks (metres, seconds)."""

    bone_length: float = 1e-3
    floor_tolerance: float = 1e-3
    contact_height: float = 0.02
    foot_skate: float = 0.50
    joint_speed: float = 7.0
    self_penetration: float = 0.0


def primitive_metrics(positions: np.ndarray, fps: float, skeleton: Skeleton,
                      thresholds: QualityThresholds = QualityThresholds()) -> dict:
    """Quality metrics of one motion.

    Parameters
    ----------
    positions : ndarray, shape (T, J, 3)
        World positions (z up, floor at 0).
    fps : float
    skeleton : Skeleton

    Returns
    -------
    dict
        ``bone_length``, ``floor``, ``foot_skate``, ``joint_speed`` and ``passed``.
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 3 or p.shape[1:] != (skeleton.n_joints, 3):
        raise ValueError(f"positions must have shape (T, {skeleton.n_joints}, 3), got {p.shape}")
    parents = np.array(PARENTS)
    child = np.arange(1, len(PARENTS))
    lengths = np.linalg.norm(p[:, child] - p[:, parents[child]], axis=-1)
    bone_dev = float(np.max(np.abs(lengths - skeleton.bone_lengths()[child]))) if len(p) else 0.0
    feet = list(_FEET)
    floor = float(p[:, feet, 2].min())
    rest_h = skeleton.rest_positions()[feet, 2]
    skate = 0.0
    if p.shape[0] > 1:
        vel = np.linalg.norm(np.diff(p[:, feet, :2], axis=0), axis=-1) * fps   # (T-1, 4)
        h = np.maximum(p[:, feet, 2] - rest_h, 0.0)
        h = 0.5 * (h[1:] + h[:-1]) / thresholds.contact_height
        # per foot, the joint nearer the floor is the contact point (heel or ball)
        h2 = h.reshape(-1, 2, 2)
        pick = np.argmin(h2, axis=2)                                            # (T-1, 2)
        h_c = np.take_along_axis(h2, pick[..., None], 2)[..., 0]
        v_c = np.take_along_axis(vel.reshape(-1, 2, 2), pick[..., None], 2)[..., 0]
        weight = np.where(h_c < 1.0, 2.0 - np.exp2(h_c), 0.0)   # 1 on the floor, 0 at limit
        counts = (h_c < 1.0).sum(0)
        mean_v = np.where(counts > 0, (v_c * weight).sum(0) / np.maximum(counts, 1), 0.0)
        skate = float(mean_v.max())
        speed = float((np.linalg.norm(np.diff(p, axis=0), axis=-1) * fps).max())
    else:
        speed = 0.0
    from ltl_human_motion.motion.biomechanics import self_penetration
    pen = float(self_penetration(p, skeleton.stature)[0].max()) if len(p) else 0.0
    passed = (bone_dev <= thresholds.bone_length and floor >= -thresholds.floor_tolerance
              and skate <= thresholds.foot_skate and speed <= thresholds.joint_speed
              and pen <= thresholds.self_penetration)
    return {"bone_length": bone_dev, "floor": floor, "foot_skate": skate,
            "joint_speed": speed, "self_penetration": pen, "passed": bool(passed)}


def check_primitives(primitives: Iterable[MotionPrimitive], skeleton: Skeleton,
                     kind: str = "", thresholds: QualityThresholds = QualityThresholds(),
                     details: bool = False) -> dict:
    """Check every primitive and summarize.

    Returns
    -------
    dict
        ``{"kind", "thresholds", "count", "passed", "failed": [names], "worst": {metric:
        value}, "by_task": {task: {"count", "passed"}}, "primitives": {...} (details)}``.
    """
    per: dict[str, dict] = {}
    for mp in primitives:
        m = primitive_metrics(world_positions(mp), mp.fps, skeleton, thresholds)
        m["task"] = mp.task
        per[mp.name] = m
    worst = {"bone_length": 0.0, "floor": float("inf"), "foot_skate": 0.0, "joint_speed": 0.0,
             "self_penetration": -float("inf")}
    by_task: dict[str, dict] = {}
    for m in per.values():
        worst["bone_length"] = max(worst["bone_length"], m["bone_length"])
        worst["floor"] = min(worst["floor"], m["floor"])
        worst["foot_skate"] = max(worst["foot_skate"], m["foot_skate"])
        worst["joint_speed"] = max(worst["joint_speed"], m["joint_speed"])
        worst["self_penetration"] = max(worst["self_penetration"], m["self_penetration"])
        t = by_task.setdefault(m["task"], {"count": 0, "passed": 0})
        t["count"] += 1
        t["passed"] += int(m["passed"])
    if not per:
        worst["floor"] = 0.0
        worst["self_penetration"] = 0.0
    report = {
        "kind": kind, "thresholds": asdict(thresholds), "count": len(per),
        "passed": sum(int(m["passed"]) for m in per.values()),
        "failed": sorted(n for n, m in per.items() if not m["passed"]),
        "worst": worst, "by_task": by_task,
    }
    report["ok"] = report["passed"] == report["count"]
    if details:
        report["primitives"] = per
    return report


def goal_sample(skeleton: Skeleton, seed: int = 0) -> list[MotionPrimitive]:
    """One or more goal primitives of every Table I goal task, at representative targets.

    Hand tasks are made at reach placements for heights from the floor to near the maximum
    reach; posture tasks with their defaults.
    """
    from ltl_human_motion.motion.goals import (
        GOAL_TASKS,
        HAND_TASKS,
        make_goal_primitive,
        max_reach,
        reach_placement,
    )

    rng = np.random.default_rng(seed)
    out: list[MotionPrimitive] = []
    H = skeleton.stature
    for task in GOAL_TASKS:
        if task in HAND_TASKS:
            top = max_reach(task, skeleton)
            heights = (0.03, 0.45, 0.9, 1.2, top - 0.05) if task in (
                "grasp", "release", "move") else (0.55 * H,)
            for h in heights:
                x, y = reach_placement(task, h, skeleton)
                out.append(make_goal_primitive(task, np.array([x, y, h]), skeleton, rng=rng))
        else:
            out.append(make_goal_primitive(task, None, skeleton, rng=rng))
    return out
