"""The goal-motion program's inequality rows: clearance to the obstacles (velocity
dampers on the exact capsule distances), clearance between the body's own capsules, and
joint speeds.

Every row is linear in the step ``dq`` (nv,) and returned as ``G dq <= h``.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from ltl_human_motion.motion.capsules import BODY_CAPSULES
from ltl_human_motion.motion.goals.kinematics import (
    BodyKinematics,
    HeldPart,
    body_capsules,
    point_jacobians,
)

__all__ = ["ObstacleField", "SelfPairs", "clearance_rows", "reference_clearance",
           "self_rows", "speed_rows"]

_FD_STEP = 1e-4


class ObstacleField(Protocol):
    """The obstacles around the worker, in the motion's frame.

    ``near(a, b, radii, within)``: for capsules ``[a, b]`` (N, 3), (N, 3) with radii (N,),
    every (capsule, obstacle part) pair whose clearance is below ``within``, as
    (capsule indices (M,), part indices (M,), clearances (M,)).
    ``exact(a, b, radii, part)``: the exact clearance (M,) of capsules (M, 3) to one
    part each (M,).
    """

    def near(self, a: np.ndarray, b: np.ndarray, radii: np.ndarray, within: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...

    def exact(self, a: np.ndarray, b: np.ndarray, radii: np.ndarray, part: np.ndarray
              ) -> np.ndarray: ...


class SelfPairs(Protocol):
    """Pairs of the body's own capsules kept apart: joint indices ``ends_a`` (P, 2) and
    ``ends_b`` (P, 2) of each pair's segments, and the least distance (P,) between the
    two segments (the verifier's self-penetration threshold plus a margin)."""

    ends_a: np.ndarray
    ends_b: np.ndarray
    least: np.ndarray


#: Capsules that take ``hand_margin``: the hands and forearms.
_HAND_CAPSULES = np.array([i for i, c in enumerate(BODY_CAPSULES)
                           if c[0][2:] in ("hand", "palm", "lower_arm")])


def _margins(margins: tuple[float, float, float], n: int) -> np.ndarray:
    """The clearance kept (n,) by each capsule of :func:`.body_capsules` (the body's, then a
    held part's edges)."""
    body, hand, part = margins
    out = np.full(n, part)
    out[:len(BODY_CAPSULES)] = body
    out[_HAND_CAPSULES] = hand
    return out




def _rows(kin: BodyKinematics, grads: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """Rows (M, nv): the sum over ``grads`` [(d value / d point (M, 3), joints (M,))] of
    the gradient pushed through each joint's translational Jacobian."""
    joints = np.unique(np.concatenate([j for _, j in grads]))
    J = point_jacobians(kin, joints)
    where = np.searchsorted(joints, np.arange(int(joints.max()) + 1))
    rows = np.zeros((len(grads[0][1]), kin.model.nv))
    for g, j in grads:
        rows += np.einsum("mi,min->mn", g, J[where[j]])
    return rows


def clearance_rows(kin: BodyKinematics, pos: np.ndarray, field_: ObstacleField,
                   held: HeldPart | None, influence: float, damper: float,
                   margins: tuple[float, float, float]
                   ) -> tuple[np.ndarray, np.ndarray, float]:
    """Velocity-damper rows ``G dq <= h`` for every near (capsule, part) pair at joint
    positions ``pos`` (J, 3) (pairs nearer than ``influence``; each step may use the
    fraction ``damper`` of what is left above the capsule's margin: body, hands and
    forearms, part in hand), and the least clearance."""
    a, b, rad, ja, jb = body_capsules(kin, pos, held)
    cap, part, clear = field_.near(a, b, rad, influence)
    if cap.size == 0:
        return np.zeros((0, kin.model.nv)), np.zeros(0), np.inf
    # d(clearance)/d(a), d(clearance)/d(b) by central differences of the exact distance
    M = cap.size
    eye = np.eye(3) * _FD_STEP
    pa = np.concatenate([a[cap][None] + eye[:, None], a[cap][None] - eye[:, None],
                         np.broadcast_to(a[cap], (6, M, 3))])
    pb = np.concatenate([np.broadcast_to(b[cap], (6, M, 3)),
                         b[cap][None] + eye[:, None], b[cap][None] - eye[:, None]])
    vals = field_.exact(pa.reshape(-1, 3), pb.reshape(-1, 3), np.tile(rad[cap], 12),
                        np.tile(part, 12)).reshape(12, M)
    grad_a = ((vals[0:3] - vals[3:6]) / (2 * _FD_STEP)).T              # (M, 3)
    grad_b = ((vals[6:9] - vals[9:12]) / (2 * _FD_STEP)).T
    rows = _rows(kin, [(grad_a, ja[cap]), (grad_b, jb[cap])])
    # d + rows dq - margin >= (1 - xi) (d - margin)  <=>  -rows dq <= xi (d - margin)
    return -rows, damper * (clear - _margins(margins, len(rad))[cap]), float(clear.min())


def reference_clearance(kin: BodyKinematics, positions: np.ndarray, field_: ObstacleField,
                        within: float, held: HeldPart | None = None,
                        held_from: int = 0) -> np.ndarray:
    """Least clearance (m) of each frame's capsules (T, J, 3) to the obstacles, (T,);
    ``inf`` where every pair is at least ``within`` apart."""
    pos = np.asarray(positions, dtype=np.float64)
    out = np.full(len(pos), np.inf)
    for lo, hi, part in ((0, held_from, None), (held_from, len(pos), held)):
        if hi <= lo:
            continue
        caps = [body_capsules(kin, p, part) for p in pos[lo:hi]]
        K = len(caps[0][2])
        a = np.concatenate([c[0] for c in caps])
        b = np.concatenate([c[1] for c in caps])
        cap, _, clear = field_.near(a, b, np.tile(caps[0][2], hi - lo), within)
        np.minimum.at(out, lo + cap // K, clear)
    return out




def self_rows(kin: BodyKinematics, pos: np.ndarray, pairs: SelfPairs, influence: float,
              damper: float) -> tuple[np.ndarray, np.ndarray]:
    """Velocity-damper rows ``G dq <= h`` keeping each pair of the body's own segments at
    least ``pairs.least`` apart, for the pairs within ``influence`` of it."""
    from ltl_human_motion.kernel.segments import segment_segment_distance
    ea, eb = pairs.ends_a, pairs.ends_b
    ends = np.stack([pos[ea[:, 0]], pos[ea[:, 1]], pos[eb[:, 0]], pos[eb[:, 1]]])   # (4, P, 3)
    gap = segment_segment_distance(*ends) - pairs.least
    near = np.flatnonzero(gap < influence)
    if near.size == 0:
        return np.zeros((0, kin.model.nv)), np.zeros(0)
    e = ends[:, near]
    M = near.size
    steps = np.concatenate([np.eye(3), -np.eye(3)]) * _FD_STEP                      # (6, 3)
    pert = np.broadcast_to(e, (4, 6, 4, M, 3)).copy()                              # end, step
    for k in range(4):
        pert[k, :, k] += steps[:, None, :]
    vals = segment_segment_distance(*np.moveaxis(pert, 2, 0))                      # (4, 6, M)
    grads = (vals[:, :3] - vals[:, 3:]) / (2 * _FD_STEP)                           # (4, 3, M)
    joints = (ea[near, 0], ea[near, 1], eb[near, 0], eb[near, 1])
    rows = _rows(kin, [(grads[k].T, joints[k]) for k in range(4)])
    return -rows, damper * gap[near]


def speed_rows(kin: BodyKinematics, limits: np.ndarray, seconds: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``G dq <= h`` bounding every joint's displacement over a step of ``seconds``
    by its speed limit ``limits`` (J,) m/s, per axis at ``limit / sqrt(2)`` (so the
    speed itself is at most 1.22 times the limit; callers pass limits with room)."""
    J = point_jacobians(kin, np.arange(len(limits))).reshape(-1, kin.model.nv)   # (3J, nv)
    bound = np.repeat(np.asarray(limits) * seconds / np.sqrt(2.0), 3)
    return np.vstack([J, -J]), np.concatenate([bound, bound])
