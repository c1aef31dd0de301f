"""Turning on the spot: model-made standing-to-standing gait primitives.

The real walking clips only turn while walking forward, so a worker facing a bench
could not leave it. A turn primitive rotates the body about the pelvis with a
minimum-jerk heading profile while the feet step one after the other (the foot on the
turning side first), each lifted on a sine arc; knees follow by two-bone IK.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.ik import min_jerk, two_bone_ik
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import MotionPrimitive, yaw_matrix

TURN_ANGLES_DEG = (-180.0, -135.0, -90.0, -45.0, 45.0, 90.0, 135.0)
_FOOT = {"l": ("l_ankle", "l_toe"), "r": ("r_ankle", "r_toe")}


def _progress(t: np.ndarray, a: float, b: float) -> np.ndarray:
    return min_jerk(np.clip((t - a) / (b - a), 0.0, 1.0))


def make_turn_primitive(stand: np.ndarray, height: float, angle: float, skeleton: Skeleton,
                        fps: float, task: str = "walk", lift: float = 0.06) -> MotionPrimitive:
    """A primitive turning the standing body by ``angle`` radians about +z.

    Parameters
    ----------
    stand : array-like, shape (J, 3)
        Root-relative standing pose facing +x (walk or carry arms).
    height : float
        Pelvis height above the floor.
    angle : float
        Turn, radians (positive: to the left).
    skeleton : Skeleton
    fps : float
    task : {"walk", "carry"}
    lift : float
        Foot clearance of each step, metres.

    Returns
    -------
    MotionPrimitive
        Starts and ends in ``stand``; ``root[-1, 3] == angle``.
    """
    stand = np.asarray(stand, dtype=np.float64)
    duration = 0.5 + 0.45 * abs(angle) / (np.pi / 2)
    n = int(round(duration * fps)) + 1
    t = np.linspace(0.0, 1.0, n)
    heading = angle * _progress(t, 0.05, 0.95)
    body = np.einsum("tij,kj->tki", yaw_matrix(heading), stand)        # (T, J, 3)
    first, second = ("l", "r") if angle > 0 else ("r", "l")
    windows = {first: (0.05, 0.55), second: (0.45, 0.95)}
    for side, (a, b) in windows.items():
        s = _progress(t, a, b)
        foot_yaw = angle * s
        for name in _FOOT[side]:
            j = JOINT_INDEX[name]
            body[:, j] = np.einsum("tij,j->ti", yaw_matrix(foot_yaw), stand[j])
            body[:, j, 2] += lift * np.sin(np.pi * s)
        hip, knee, ankle = (JOINT_INDEX[f"{side}_{x}"] for x in ("hip", "knee", "ankle"))
        l1 = float(np.linalg.norm(stand[knee] - stand[hip]))
        l2 = float(np.linalg.norm(stand[ankle] - stand[knee]))
        pole = np.stack([np.cos(foot_yaw), np.sin(foot_yaw), np.zeros(n)], axis=-1)
        body[:, knee], body[:, ankle] = two_bone_ik(body[:, hip], body[:, ankle], l1, l2,
                                                     pole, max_stretch=1.0)
    poses = np.einsum("tji,tkj->tki", yaw_matrix(heading), body)     # back to heading frame
    root = np.zeros((n, 4))
    root[:, 2] = height
    root[:, 3] = heading
    deg = int(round(np.degrees(angle)))
    return MotionPrimitive(name=f"{task}_turn_{deg:+d}", task=task, poses=poses, root=root,
                           fps=fps, source=f"planner: turn on the spot by {deg} degrees",
                           meta={"turn": float(angle)})


def turn_primitives(library) -> list[MotionPrimitive]:  # noqa: ANN001 - MotionLibrary
    """Turn primitives for walking and carrying on the library's body."""
    out = []
    for task, stand in (("walk", library.standing_pose), ("carry", library.carry_standing_pose)):
        for deg in TURN_ANGLES_DEG:
            out.append(make_turn_primitive(stand, library.standing_height, np.radians(deg),
                                           library.skeleton, library.fps, task))
    return out
