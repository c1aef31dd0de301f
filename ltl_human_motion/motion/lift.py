"""Lifting both hands, and what they hold, straight up from a standing stance.

A worker carrying a carton at hip height to a table whose top is higher than the
carton's bottom lifts it before the last step in, then sets it down. The lift keeps the
hands' horizontal positions and orientations (a part held in both hands stays level);
wrists and palms rise by the same amount, the elbows follow by two-bone IK with the bend
they had. Timing as for the arm transitions (:mod:`.arm_transition`): Fitts' law for the
rise, the peak palm speed bounded, the minimum-jerk profile.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.arm_transition import ARM_PEAK_SPEED
from ltl_human_motion.motion.ik import min_jerk, two_bone_ik
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, Skeleton
from ltl_human_motion.motion.timing import fitts_time, min_move_time

__all__ = ["lift_poses", "lifted_stance"]

_J = JOINT_INDEX


def lifted_stance(stance: np.ndarray, rise: float | np.ndarray) -> np.ndarray:
    """``stance`` (J, 3), root-relative, with both wrists and hands ``rise`` metres higher
    (a scalar, or (T,) for T poses, then (T, J, 3)); the elbows keep their bend towards
    where they pointed. Where an arm cannot reach that high, its wrist stops at 99.9 % of
    its length and the hand keeps its offset from the wrist."""
    base = np.asarray(stance, dtype=np.float64)
    r = np.asarray(rise, dtype=np.float64)
    out = np.repeat(base[None], r.size, axis=0)
    up = np.zeros((r.size, 3))
    up[:, 2] = r.reshape(-1)
    for s in "lr":
        sh, el, wr, ha = (_J[f"{s}_{j}"] for j in ("shoulder", "elbow", "wrist", "hand"))
        l1 = float(np.linalg.norm(base[el] - base[sh]))
        l2 = float(np.linalg.norm(base[wr] - base[el]))
        pole = base[el] - 0.5 * (base[sh] + base[wr])
        elbow, wrist = two_bone_ik(np.broadcast_to(base[sh], up.shape), base[wr] + up,
                                   l1, l2, np.broadcast_to(pole, up.shape))
        out[:, el] = elbow
        out[:, wr] = wrist
        out[:, ha] = wrist + (base[ha] - base[wr])
    return out[0] if r.ndim == 0 else out


def lift_poses(stance: np.ndarray, rise: float, skeleton: Skeleton, fps: float,
               lowering: bool = False) -> np.ndarray:
    """Root-relative poses (T, J, 3) from ``stance`` (J, 3) to :func:`lifted_stance`
    ``rise`` metres up (``lowering``: from there back down), minimum-jerk in time."""
    H = skeleton.stature
    dist = abs(float(rise))
    total = max(fitts_time(dist), min_move_time(dist, ARM_PEAK_SPEED * H / DEFAULT_STATURE))
    n = max(2, round(total * fps) + 1)
    s = min_jerk(np.linspace(0.0, 1.0, n))
    if lowering:
        s = s[::-1]
    return lifted_stance(stance, float(rise) * s)
