"""Arm transitions between two standing stances (walking arms <-> carrying arms).

The palms move on a smooth curve (a quadratic Bezier through a via point beside the
body, outside the trunk and thighs) with the minimum-jerk timing; wrists follow the palm
direction and elbows come from two-bone IK, so the forearms never pass through the trunk.
The duration is the longer of Fitts' law for the palm's path and the time that keeps its
peak speed at :data:`ARM_PEAK_SPEED` (:mod:`~ltl_human_motion.motion.timing`).
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.ik import min_jerk, two_bone_ik
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, Skeleton
from ltl_human_motion.motion.timing import fitts_time, min_move_time

__all__ = ["ARM_PEAK_SPEED", "arm_transition_poses"]

_J = JOINT_INDEX
#: Peak palm speed of an unhurried arm transport, m/s at 1.75 m (scaled with stature):
#: deliberate reaching peaks at 1-2 m/s (Flash & Hogan 1985's point-to-point moves).
ARM_PEAK_SPEED = 1.6
#: Lateral clearance of the via point from the body axis, as a fraction of stature:
#: outside the pelvis capsule (0.135 m at 1.75 m = 0.077 H) plus the hand's own radius.
_VIA_LATERAL = 0.125


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def arm_transition_poses(start: np.ndarray, end: np.ndarray, skeleton: Skeleton,
                         fps: float) -> np.ndarray:
    """Root-relative poses (T, J, 3) taking the arms from ``start`` to ``end`` (J, 3).

    Only the arm joints (elbow, wrist, palm) move; the first frame is ``start`` and the
    last is ``end`` exactly.
    """
    a = np.asarray(start, dtype=np.float64)
    b = np.asarray(end, dtype=np.float64)
    H = skeleton.stature
    bones = skeleton.bone_lengths()
    paths, lengths = [], []
    for s, side in (("l", 1.0), ("r", -1.0)):
        h0, h1 = a[_J[f"{s}_hand"]], b[_J[f"{s}_hand"]]
        via = 0.5 * (h0 + h1)
        via[1] = side * max(side * via[1], side * h0[1], side * h1[1], _VIA_LATERAL * H)
        ctrl = 2.0 * via - 0.5 * (h0 + h1)
        u = np.linspace(0.0, 1.0, 33)[:, None]
        curve = (1 - u) ** 2 * h0 + 2 * u * (1 - u) * ctrl + u ** 2 * h1
        paths.append((h0, ctrl, h1))
        lengths.append(float(np.sum(np.linalg.norm(np.diff(curve, axis=0), axis=-1))))
    dist = max(lengths)
    total = max(fitts_time(dist), min_move_time(dist, ARM_PEAK_SPEED * H / DEFAULT_STATURE))
    n = max(2, round(total * fps) + 1)
    sig = min_jerk(np.linspace(0.0, 1.0, n))[:, None]
    out = np.repeat(a[None], n, axis=0)
    for (h0, ctrl, h1), s in zip(paths, "lr"):
        sh, el, wr, ha = (_J[f"{s}_{j}"] for j in ("shoulder", "elbow", "wrist", "hand"))
        palm = (1 - sig) ** 2 * h0 + 2 * sig * (1 - sig) * ctrl + sig ** 2 * h1
        d0, d1 = _unit(a[ha] - a[wr]), _unit(b[ha] - b[wr])
        hand_dir = _unit((1 - sig) * d0 + sig * d1)
        wrist = palm - bones[ha] * hand_dir
        p0 = a[el] - 0.5 * (a[sh] + a[wr])
        p1 = b[el] - 0.5 * (b[sh] + b[wr])
        side = np.array([0.0, 1.0 if s == "l" else -1.0, 0.0])
        pole = (1 - sig) * p0 + sig * p1 + 0.02 * side
        shoulder = np.repeat(a[sh][None], n, axis=0)
        elbow, wrist = two_bone_ik(shoulder, wrist, bones[el], bones[wr], pole, max_stretch=1.0)
        out[:, el], out[:, wr] = elbow, wrist
        out[:, ha] = wrist + bones[ha] * hand_dir
    # the IK end poses equal the stances up to rounding; remove the residual smoothly
    for ref, w in ((a, 1.0 - sig), (b, sig)):
        i = 0 if ref is a else -1
        out += w[:, :, None] * (ref - out[i])[None]
    out[0], out[-1] = a, b
    return out
