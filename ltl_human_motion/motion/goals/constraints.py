"""The goal-motion program's inequality rows: clearance to the obstacles (velocity
dampers on the exact capsule distances), clearance between the body's own capsules, and
joint speeds.

Every row is linear in the step ``dq`` (nv,) and returned as ``G dq <= h``.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Protocol

import numpy as np

from ltl_human_motion.motion.capsules import BODY_CAPSULES
from ltl_human_motion.motion.goals.kinematics import (
    BodyKinematics,
    HeldPart,
    body_capsules,
    frames_capsules,
    point_jacobians,
)

__all__ = ["ObstacleField", "SelfPairs", "balance_rows", "clearance_rows",
           "reference_clearance", "rom_rows", "self_rows", "speed_rows"]

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
#: Capsules of the planted feet, which the program holds where the stance put them
#: (stepping is the gait's job): they keep the verifier's clearance of 0, not a margin
#: they could only gain by moving. A stance a few millimetres from a machine's base
#: otherwise asks the fixed foot to back off, and no step of the program is feasible.
_FOOT_CAPSULES = np.array([i for i, c in enumerate(BODY_CAPSULES) if c[0][2:] == "foot"])


def _margins(margins: tuple[float, float, float], n: int) -> np.ndarray:
    """The clearance kept (n,) by each capsule of :func:`.body_capsules` (the body's, then a
    held part's edges)."""
    body, hand, part = margins
    out = np.full(n, part)
    out[:len(BODY_CAPSULES)] = body
    out[_HAND_CAPSULES] = hand
    out[_FOOT_CAPSULES] = 0.0
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
        a, b, rad = frames_capsules(kin, pos[lo:hi], part)
        K = len(rad)
        cap, _, clear = field_.near(a.reshape(-1, 3), b.reshape(-1, 3),
                                    np.tile(rad, hi - lo), within)
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


@lru_cache(maxsize=4)
def _com_weights(joints: int) -> np.ndarray:
    """Weights (J,) of the joint positions in the verifier's centre of mass (Winter's
    segment masses, :func:`~ltl_human_motion.motion.ik.center_of_mass`, which is linear
    in them). Shared: read-only."""
    from ltl_human_motion.motion.ik import SEGMENT_MASS
    from ltl_human_motion.motion.skeleton import JOINT_INDEX
    w = np.zeros(joints)
    for a, b, mass, frac in SEGMENT_MASS:
        w[JOINT_INDEX[a]] += mass * (1.0 - frac)
        w[JOINT_INDEX[b]] += mass * frac
    w /= w.sum()
    w.flags.writeable = False
    return w


def support_edges(pos: np.ndarray, stature: float) -> np.ndarray:
    """The support polygon of both feet at joint positions ``pos`` (J, 3), as the
    verifier's balance check outlines them: its edges' lines (E, 3), ``n . x + c <= 0``
    inside, with unit outward normals ``n``. (Eight corners: a monotone-chain hull here
    is microseconds, where importing scipy's Qhull would cost a new process 0.6 s.)"""
    from ltl_human_motion.motion.biomechanics import _foot_outline
    from ltl_human_motion.motion.skeleton import JOINT_INDEX
    corners = np.concatenate([
        _foot_outline(pos[None, JOINT_INDEX[f"{s}_ankle"]], pos[None, JOINT_INDEX[f"{s}_toe"]],
                      stature)[0] for s in ("l", "r")])
    hull = _convex_hull(corners)
    a, b = hull, np.roll(hull, -1, axis=0)
    d = b - a
    n = np.stack([d[:, 1], -d[:, 0]], axis=1)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return np.column_stack([n, -np.einsum("ij,ij->i", n, a)])


def _convex_hull(points: np.ndarray) -> np.ndarray:
    """Vertices (V, 2) of the convex hull of ``points`` (N, 2), counter-clockwise
    (Andrew's monotone chain)."""
    pts = sorted(map(tuple, np.asarray(points, dtype=np.float64)))

    def half(seq: list) -> list:
        out: list = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def balance_rows(kin: BodyKinematics, pos: np.ndarray, edges: np.ndarray,
                 influence: float, damper: float, reference: np.ndarray | None = None,
                 slack: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Velocity-damper rows ``G dq <= h`` keeping the centre of mass of joint positions
    ``pos`` (J, 3) over the support polygon ``edges`` (E, 3) (:func:`support_edges`): for
    each edge the centre of mass is nearer than ``influence`` to, one step may use the
    fraction ``damper`` of its distance inside, down to ``slack`` m outside (the
    verifier's outline is grown by its ``balance_margin``). Where the ``reference`` pose
    (J, 3) of the same frame has its centre of mass further out, the program's may go as
    far out as that, no further."""
    w = _com_weights(len(pos))
    inside = -(edges[:, :2] @ (w @ pos)[:2] + edges[:, 2])                      # (E,)
    floor = np.full(len(edges), -slack)
    if reference is not None:
        floor = np.minimum(-(edges[:, :2] @ (w @ reference)[:2] + edges[:, 2]), floor)
    near = np.flatnonzero(inside - floor < influence)
    if near.size == 0:
        return np.zeros((0, kin.model.nv)), np.zeros(0)
    joints = np.flatnonzero(w)
    J = np.einsum("k,kin->in", w[joints], point_jacobians(kin, joints))      # (3, nv)
    return edges[near, :2] @ J[:2], damper * np.maximum(inside[near] - floor[near], 0.0)


#: Finite-difference step of the range-of-motion rows, m.
_ROM_FD_STEP = 1e-5


@lru_cache(maxsize=4)
def _angle_joints(joints: int) -> dict[str, np.ndarray]:
    """The joints (indices) each anatomical angle of
    :func:`~ltl_human_motion.motion.biomechanics.joint_angles` reads, for poses of
    ``joints`` joints: those whose position made NaN makes the angle NaN. Moving any other
    joint leaves the angle as it is to the bit, so its central difference is exactly 0."""
    from ltl_human_motion.motion.biomechanics import joint_angles
    rng = np.random.default_rng(0)
    poses = np.broadcast_to(rng.normal(size=(joints, 3)), (joints, joints, 3)).copy()
    poses[np.arange(joints), np.arange(joints)] = np.nan
    with np.errstate(invalid="ignore"):
        angles = joint_angles(poses)
    return {name: np.flatnonzero(np.isnan(a)) for name, a in angles.items()}


def rom_rows(kin: BodyKinematics, pos: np.ndarray, ranges: dict[str, tuple[float, float]],
             influence: float, margin: float, damper: float
             ) -> tuple[np.ndarray, np.ndarray]:
    """Velocity-damper rows ``G dq <= h`` keeping the verifier's anatomical joint angles
    (:func:`~ltl_human_motion.motion.biomechanics.joint_angles`, degrees, of joint
    positions ``pos`` (J, 3)) within ``ranges`` (by key without side: ``knee_flexion``
    -> (lo, hi)) less ``margin`` degrees: a row for each angle within ``influence``
    degrees of a limit, one step using the fraction ``damper`` of what is left (an
    angle already past the margin, as a reference may hold it, only goes no further). The
    angles' gradients are central differences of the joint positions pushed through the
    joints' Jacobians."""
    from ltl_human_motion.motion.biomechanics import joint_angles
    angles = joint_angles(pos[None])
    near = []
    for name, a in angles.items():
        key = name[2:] if name[:2] in ("l_", "r_") else name
        lo, hi = ranges[key]
        value = float(a[0])
        if value - lo < influence:
            near.append((name, 1.0, value - lo - margin))
        if hi - value < influence:
            near.append((name, -1.0, hi - value - margin))
    if not near:
        return np.zeros((0, kin.model.nv)), np.zeros(0)
    n = len(pos)
    names = sorted({name for name, _, _ in near})
    read = _angle_joints(n)
    joints = np.unique(np.concatenate([read[name] for name in names]))
    k = len(joints)
    steps = np.concatenate([np.eye(3), -np.eye(3)]) * _ROM_FD_STEP                    # (6, 3)
    moved = np.broadcast_to(pos, (6, k, n, 3)).copy()                                # step, joint
    moved[:, np.arange(k), joints] += steps[:, None, :]
    perturbed = joint_angles(moved.reshape(-1, n, 3), names)
    J = point_jacobians(kin, np.arange(n))                                           # (n, 3, nv)
    G, h = [], []
    for name, sign, room in near:
        v = perturbed[name].reshape(6, k)
        diff = np.zeros((3, n))
        diff[:, joints] = v[:3] - v[3:]
        grad = diff.T / (2 * _ROM_FD_STEP)                 # (n, 3), laid out as einsum read it
        G.append(-sign * np.einsum("jc,jcn->n", grad, J))
        h.append(damper * max(room, 0.0))
    return np.array(G), np.array(h)
