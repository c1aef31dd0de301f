"""The posture search of hand tasks: trunk flexion and pelvis drop on a grid.

For hand targets the trunk flexion and the knee bend (pelvis drop) are chosen on a grid
minimizing ``flexion^2 + (drop / 0.14 H)^2 + 0.5 (d / arm - 0.8)^2`` subject to the hand
being within 93 % of the arm's length from the shoulder, the legs reaching the planted
feet, balance, the hips and knees within their range of motion, no body part through
another, and the checks of :mod:`.posture_checks` (boards, furniture, obstacles). Under a
low board the search also kneels (:func:`_kneel_set`) and, last, tilts the pelvis in full.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion.goals.body import (
    _KNEE_ON_FLOOR,
    _balance_shift,
    _body,
    _goal_elbow_pole,
    _goal_hand_dir,
    _kneel_legs,
    _legs_in_range,
    _posture_legs,
    _Start,
    _trunk,
)
from ltl_human_motion.motion.goals.kneeling import _hangs, _prop_point
from ltl_human_motion.motion.goals.posture_checks import (
    ObstacleClearance,
    _board_depth,
    _board_way_blocked,
    _obstacle_blocked,
    _slab_depth,
    _support_depth,
    _turns_before_edge,
)
from ltl_human_motion.motion.goals.tasks import (
    _J,
    _REACH_FRACTION,
    _SIDES,
    LEVEL_PATH_TASKS,
    _arm_length,
    _bones,
    _check_board,
    _hand_targets,
)
from ltl_human_motion.motion.skeleton import Skeleton

#: Clearance (m) a reaching posture keeps between body parts at contact, over the
#: self-penetration check of planning.biomechanics (capsule axis outside the other
#: capsule): the seeded timing and the blend of the start pose move the arm by a few mm.
_SELF_CLEARANCE = 0.005


#: Cost added to a posture under a low board whose pelvis tilts in full (past the hips'
#: 125 degree range of motion at the depth such reaches take): larger than any capped
#: posture's, so it is taken only where none reaches.
_UNCAPPED_COST = 100.0


#: Cost added to a posture kneeling on both knees (:func:`_kneel_set`): a reach under a
#: low board that no crouch within the hips' range of motion makes is done kneeling,
#: sat back and leant forward (thighs near vertical, so the hips flex by the pelvis's
#: tilt and the sit-back only); before the full-tilt crouch, past that range.
_KNEEL_COST = 50.0


#: Largest trunk flexion of a kneeling reach, rad (92 degrees: the chest 78 degrees
#: forward, the head a few degrees past horizontal, peering under the board).
_KNEEL_PITCH_MAX = 1.6


#: Target-independent part of :func:`_grid` per (skeleton, start pose); see :func:`_grid_base`.
_GRID_CACHE: BoundedCache[tuple[np.ndarray, ...]] = BoundedCache(32)


def _grid_base(skeleton: Skeleton, st: _Start, low_board: bool = False
               ) -> tuple[np.ndarray, ...]:
    """The candidate postures of :func:`_grid`, which do not depend on the targets.

    Balance shifts, trunk poses, the posture cost and the leg/head feasibility depend only
    on the skeleton and the start pose, of which a worker has a few (walking and carrying
    stance), so they are computed once per pair and kept (read-only arrays). Under a low
    board (``low_board``) the capped postures, within the hip and knee ranges of motion,
    come with two more sets: kneeling on both knees (:func:`_kneel_set`, from a standing
    start), and the crouch with the pelvis tilted in full and the ranges not asked for
    (the deepest reach in under the board), at :data:`_UNCAPPED_COST` more, so that one
    is taken only where no other posture reaches.

    Returns
    -------
    P, D, shift, base_cost : ndarray, shape (C,)
    shoulders : ndarray, shape (C, 2, 3)
        Left and right shoulder of each candidate.
    feasible, capped, kneel : ndarray of bool, shape (C,)
        Whether the candidate can be taken; whether its pelvis tilt is capped; whether
        it kneels.
    """
    def build() -> tuple[np.ndarray, ...]:
        if low_board:
            full = _grid_set(skeleton, st, False)
            full[3][:] += _UNCAPPED_COST
            sets = [_grid_set(skeleton, st, True)] + ([] if st.seated
                                                      else [_kneel_set(skeleton, st)]) + [full]
            out = tuple(np.concatenate(arrays) for arrays in zip(*sets))
        else:
            out = _grid_set(skeleton, st, True)
        for arr in out:
            arr.flags.writeable = False
        return out
    return _GRID_CACHE.get_or_build((skeleton, st.pose.tobytes(), low_board), build)


def _grid_set(skeleton: Skeleton, st: _Start, cap: bool) -> tuple[np.ndarray, ...]:
    """One set of :func:`_grid_base`'s candidates: capped pelvis tilt within the hip and
    knee ranges of motion, or (not ``cap``) full tilt with the ranges not asked for."""
    H = skeleton.stature
    b = _bones(skeleton)
    leg = b[_J["l_knee"]] + b[_J["l_ankle"]]
    pitch_v = np.linspace(0.0, 1.45, 30)
    drop_v = np.linspace(0.0, 0.36 * H, 25)
    P, D = np.meshgrid(pitch_v, drop_v, indexing="ij")
    P, D = P.ravel(), D.ravel()
    pelvis = np.tile(st.pelvis, (P.size, 1))
    pelvis[:, 2] -= D
    shift = _balance_shift(skeleton, pelvis, P, st, cap=cap)
    pelvis[:, 0] += shift
    tr = _trunk(skeleton, pelvis, P, cap, st.hips())
    cost = P ** 2 + (D / (0.14 * H)) ** 2
    feasible = np.ones(P.size, bool)
    for k, s in enumerate(_SIDES):
        hip = tr[:, _J[f"{s}_hip"]]
        d = np.linalg.norm(hip - st.ankles[k], axis=-1)
        feasible &= (d <= leg * 1.0000001) & (d >= 0.30 * leg)
    # the head must not go below the hands' height band (no diving into the floor)
    feasible &= tr[:, _J["head"], 2] > 0.12 * H
    shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)
    if cap:
        feasible &= _legs_in_range(skeleton, st, pelvis, P, tr, shoulders)
    return P, D, shift, cost, shoulders, feasible, np.full(P.size, cap), np.zeros(P.size, bool)


def _kneel_set(skeleton: Skeleton, st: _Start) -> tuple[np.ndarray, ...]:
    """Kneeling candidates of :func:`_grid_base` (its return values): trunk flexion up to
    :data:`_KNEEL_PITCH_MAX`, the hips from a thigh's length over the knees (upright) to
    sat back 60 degrees, the knees from 0.1 m behind to 0.4 m in front of the standing
    ankles; within the hip and knee ranges of motion (:data:`_ROM_MARGIN`), the head
    clear of the floor. Cost: :data:`_KNEEL_COST`, the trunk flexion and the feet's
    steps back."""
    H = skeleton.stature
    b = _bones(skeleton)
    thigh = b[_J["l_knee"]]
    rest = skeleton.rest_positions()
    hip_z = rest[_J["l_hip"], 2] - rest[0, 2]
    P, A, K = (a.ravel() for a in np.meshgrid(
        np.linspace(0.0, _KNEEL_PITCH_MAX, 33),
        thigh * np.cos(np.radians(np.linspace(0.0, 60.0, 13))),
        np.linspace(-0.1, 0.4, 6), indexing="ij"))
    pelvis = np.tile(st.pelvis, (P.size, 1))
    pelvis[:, 2] = _KNEE_ON_FLOOR * H + A - hip_z
    pelvis[:, 0] = float(st.ankles[:, 0].mean()) + K - np.sqrt(thigh ** 2 - A ** 2)
    D, shift = st.pelvis[2] - pelvis[:, 2], pelvis[:, 0] - st.pelvis[0]
    tr = _trunk(skeleton, pelvis, P, False, kneel=True)
    ankles, toes, pole, feasible = _kneel_legs(
        skeleton, np.stack([tr[:, _J["l_hip"]], tr[:, _J["r_hip"]]], 1))
    feasible &= tr[:, _J["head"], 2] > 0.12 * H
    shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)
    feasible &= _legs_in_range(skeleton, st, pelvis, P, tr, shoulders,
                               (ankles, toes, pole))
    step = np.abs(st.ankles[None, :, 0] - ankles[..., 0]).max(axis=1)
    cost = P ** 2 + (D / (0.14 * H)) ** 2 + step + _KNEEL_COST
    return (P, D, shift, cost, shoulders, feasible, np.zeros(P.size, bool),
            np.ones(P.size, bool))


def _reach_cost(skeleton: Skeleton, st: _Start, targets: np.ndarray, active: tuple[int, ...],
                board: tuple[float, float, float] | None
                ) -> tuple[np.ndarray, ...]:
    """The candidates of :func:`_grid_base` with the hands' reach: P, D, shift, cost,
    feasible (the hands within reach and, under ``board``, turned before its edge),
    capped, kneel, each (C,)."""
    arm = _arm_length(skeleton)
    P, D, shift, cost, shoulders, feasible, capped, kneel = _grid_base(skeleton, st,
                                                                        board is not None)
    for k in active:
        d = np.linalg.norm(targets[k] - shoulders[:, k], axis=-1)
        feasible = feasible & (d <= _REACH_FRACTION * arm)
        cost = cost + 0.5 * (d / arm - 0.8) ** 2
    if board is not None:
        feasible = feasible & _turns_before_edge(shoulders, active, board)
    return P, D, shift, cost, feasible, capped, kneel


def _self_blocked(poses: np.ndarray, stature: float) -> np.ndarray:
    """Whether contact poses (C, J, 3) put a body part within ``_SELF_CLEARANCE`` of
    another (planning.biomechanics' self-penetration), (C,)."""
    from ltl_human_motion.motion.biomechanics import self_penetration
    return self_penetration(poses, stature)[0].max(axis=1) > -_SELF_CLEARANCE


def _body_board_blocked(skeleton: Skeleton, st: _Start,
                        posture: tuple[np.ndarray, np.ndarray, np.ndarray], poses: np.ndarray,
                        active: tuple[int, ...], board: tuple[float, float, float] | None,
                        capped: np.ndarray, kneel: np.ndarray) -> np.ndarray:
    """Whether each candidate posture (pitch, drop, shift, each (C,)) with the hands on
    the targets (``poses`` (C, J, 3)) puts a body part through another, or into the low
    ``board`` there or on the way to it; bool (C,)."""
    blocked = _self_blocked(poses, skeleton.stature)
    if board is not None:
        blocked |= _board_depth(poses, board, skeleton.stature) > 0.0
        blocked |= _board_way_blocked(skeleton, st, posture, active, board, capped, kneel)
    return blocked


def _furniture_depths(poses: np.ndarray, furniture: tuple | None, stature: float
                      ) -> list[np.ndarray]:
    """How deep (C,) the postures ``poses`` (C, J, 3) go into the furniture under the
    targets, then into the board over them (``furniture``: see :func:`_grid`), for those
    given."""
    under, over = furniture or (None, None)
    return ([] if under is None else [_support_depth(poses, under, stature)]) \
        + ([] if over is None else [_slab_depth(poses, over, stature)])


def _cheapest_clear(skeleton: Skeleton, st: _Start, targets: np.ndarray,
                    active: tuple[int, ...], task: str,
                    board: tuple[float, float, float] | None,
                    obstacles: ObstacleClearance | None, furniture: tuple | None
                    ) -> list[int] | None:
    """The candidates (indices into :func:`_grid_base`'s arrays) of :func:`_grid`'s
    :data:`_POSTURE_TRIES` cheapest feasible postures, measured cheapest first
    :data:`_LEAST_CHUNK` at a time: the first ones clear of the body, the board and the
    furniture, where the cheapest of them is clear of the obstacles (``_grid`` then
    measures no other against them, and a clear one makes its furniture tests apply to
    all). None where ``_grid``'s answer needs every candidate measured: none is clear
    of the body, board and furniture, or the cheapest such one meets an obstacle."""
    P, D, shift, cost, feasible, capped, kneel = _reach_cost(skeleton, st, targets, active,
                                                             board)
    idx = np.flatnonzero(feasible)
    order = idx[np.argsort(cost[idx], kind="stable")]
    H = skeleton.stature
    chosen: list[int] = []
    for k in range(0, order.size, _LEAST_CHUNK):
        some = order[k:k + _LEAST_CHUNK]
        posture = (P[some], D[some], shift[some])
        poses = _contact_poses(skeleton, st, *posture, targets, active, task,
                               cap=capped[some], kneel=kneel[some])
        blocked = _body_board_blocked(skeleton, st, posture, poses, active, board,
                                      capped[some], kneel[some])
        for depth in _furniture_depths(poses, furniture, H):
            blocked |= depth > 0.0
        for i in np.flatnonzero(~blocked).tolist():
            one = some[i:i + 1]
            if not chosen and obstacles is not None and _obstacle_blocked(
                    skeleton, st, (P[one], D[one], shift[one]), poses[i:i + 1], active,
                    obstacles, capped[one], kneel[one])[0]:
                return None
            chosen.append(int(some[i]))
            if len(chosen) == _POSTURE_TRIES:
                return chosen
    return chosen or None


#: Candidates :func:`least_cost` measures at a time, cheapest first.
_LEAST_CHUNK = 24


def least_cost(skeleton: Skeleton, st: _Start, targets: np.ndarray, active: tuple[int, ...],
               task: str, capped_only: bool = False) -> float:
    """The least cost of :func:`_grid` without a board, obstacles or furniture (over the
    capped or kneeling candidates only, with ``capped_only``): the same number, with the
    body test run on the cheapest candidates :data:`_LEAST_CHUNK` at a time until one
    passes instead of on every candidate (a standing place's search asks only this)."""
    P, D, shift, cost, feasible, capped, kneel = _reach_cost(skeleton, st, targets, active,
                                                             None)
    if capped_only:
        feasible = feasible & (capped | kneel)
    idx = np.flatnonzero(feasible)
    order = idx[np.argsort(cost[idx], kind="stable")]
    for k in range(0, order.size, _LEAST_CHUNK):
        some = order[k:k + _LEAST_CHUNK]
        poses = _contact_poses(skeleton, st, P[some], D[some], shift[some], targets, active,
                               task, cap=capped[some], kneel=kneel[some])
        free = ~_self_blocked(poses, skeleton.stature)
        if free.any():
            return float(cost[some[int(np.argmax(free))]])
    return float("inf")


def _grid(skeleton: Skeleton, st: _Start, targets: np.ndarray, active: tuple[int, ...],
          task: str | None = None, board: tuple[float, float, float] | None = None,
          obstacles: ObstacleClearance | None = None, strict: bool = False,
          furniture: tuple[tuple[float, ...] | None, tuple[float, ...] | None] | None = None
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Costs of trunk flexion / pelvis drop candidates for hand targets.

    A candidate is infeasible when a hand cannot reach its target, or when its posture
    with the hands on the targets (:func:`_contact_poses`) puts a body part through
    another (a low reach with the hand in the thigh) or into the low ``board`` (edge,
    bottom, top) over the targets; unless no candidate keeps out of it (the planner's
    exact check decides then), when the trunk or legs go into the furniture under the
    targets (``furniture[0]``, :func:`_support_depth`) or the body into a board over them
    (``furniture[1]``, (nx, ny, offset, bottom, top), :func:`_slab_depth`); and, with
    ``obstacles``, when it or the trunk and legs on the way to it come nearer an obstacle
    than ``_OBSTACLE_CLEARANCE`` (:func:`_obstacle_blocked`; unless every candidate does
    and not ``strict``; where the cheapest candidate is clear the others are not
    measured).

    Returns pitch (C,), drop (C,), shift (C,), cost (C,) (inf where infeasible),
    whether the pelvis tilt is capped (C,) and whether the posture kneels (C,)
    (:func:`_grid_base`).
    """
    P, D, shift, cost, feasible, capped, kneel = _reach_cost(skeleton, st, targets, active,
                                                             board)
    idx = np.flatnonzero(feasible)
    if idx.size:
        poses = _contact_poses(skeleton, st, P[idx], D[idx], shift[idx], targets, active,
                               task, cap=capped[idx], kneel=kneel[idx])
        blocked = _body_board_blocked(skeleton, st, (P[idx], D[idx], shift[idx]), poses,
                                      active, board, capped[idx], kneel[idx])
        for depth in _furniture_depths(poses, furniture, skeleton.stature):
            if not np.all(blocked | (depth > 0.0)):
                blocked |= depth > 0.0
        if obstacles is not None and not np.all(blocked):
            free = np.flatnonzero(~blocked)
            # The cheapest candidate first: where it is clear it is the posture (the
            # others are not measured); else every candidate.
            free = np.r_[free[np.argmin(cost[idx[free]])], free]
            for probe, some in ((True, free[:1]), (False, free[1:])):
                hit = _obstacle_blocked(skeleton, st, (P[idx[some]], D[idx[some]],
                                                       shift[idx[some]]), poses[some],
                                        active, obstacles, capped[idx[some]],
                                        kneel[idx[some]])
                if probe and not hit[0]:
                    break
                if not probe and (strict or not np.all(hit)):
                    blocked[some[hit]] = True
        feasible = feasible.copy()
        feasible[idx[blocked]] = False
    cost = np.where(feasible, cost, np.inf)
    return P, D, shift, cost, capped, kneel


def posture_clear(task: str, target: np.ndarray, skeleton: Skeleton,
                  obstacles: ObstacleClearance, *, start_pose: np.ndarray | None = None,
                  hand: str = "auto", board: tuple[float, float, float] | None = None
                  ) -> bool:
    """Whether some posture of hand task ``task`` reaches ``target`` (3,) (start frame)
    with the body clear of ``obstacles`` as :func:`make_goal_primitive`'s search keeps
    it, without that search's fallback (a cheap test of a standing place before the
    worker walks there). ``start_pose``, ``hand`` and ``board`` as there."""
    st = _Start(skeleton, start_pose)
    targets, active, _ = _hand_targets(task, np.asarray(target, dtype=np.float64), hand)
    board = _check_board(board) if board is not None and task in LEVEL_PATH_TASKS else None
    cost = _grid(skeleton, st, targets, active, task, board, obstacles, strict=True)[3]
    return bool(np.isfinite(cost).any())


def _contact_poses(skeleton: Skeleton, st: _Start, pitch: np.ndarray, drop: np.ndarray,
                   shift: np.ndarray, targets: np.ndarray, active: tuple[int, ...],
                   task: str | None, cap: bool | np.ndarray = True,
                   kneel: np.ndarray | None = None) -> np.ndarray:
    """Poses (C, J, 3) of posture candidates (C,) with the active hands on ``targets``
    (2, 3) and a free hand by the hip, as :func:`_hand_task` holds them at contact;
    ``kneel`` ((C,) of bool): the candidates on their knees (:func:`_kneel_legs`), the
    free palm on the floor (:func:`_prop_point`)."""
    C = pitch.size
    pelvis = np.tile(st.pelvis, (C, 1))
    pelvis[:, 2] -= drop
    pelvis[:, 0] += shift
    tr = _trunk(skeleton, pelvis, pitch, cap, st.hips(), False if kneel is None else kneel)
    hands = np.empty((C, 2, 3))
    hand_dir = np.broadcast_to(st.hand_dir, (C, 2, 3)).copy()
    elbow_pole = np.broadcast_to(st.elbow_pole, (C, 2, 3)).copy()
    for k, s in enumerate(_SIDES):
        if k in active:
            hands[:, k] = targets[k]
            hand_dir[:, k] = _goal_hand_dir(task, k, targets[k] - tr[:, _J[f"{s}_shoulder"]])
            elbow_pole[:, k] = _goal_elbow_pole(k)
        else:
            hands[:, k] = pelvis + (st.hands[k] - st.pelvis) + np.array([0.0, 0.0, 0.04])
            if kneel is not None and np.any(kneel) and _hangs(st, k):
                prop = _prop_point(tr[:, _J[f"{s}_shoulder"]], skeleton.stature,
                                   _arm_length(skeleton))
                hands[:, k] = np.where(np.asarray(kneel)[:, None], prop, hands[:, k])
    return _body(skeleton, pelvis, pitch, *_posture_legs(skeleton, st, tr, kneel),
                 hands, hand_dir, elbow_pole, tr)


#: Postures a hand task tries, cheapest first, for one whose whole motion keeps the arms
#: out of the body (the posture search checks the contact pose; the way out, with the
#: body rising and the hand coming home, can pass a forearm through a thigh).
_POSTURE_TRIES = 4


@dataclass(frozen=True)
class ReachPosture:
    """One posture of the search (:func:`_grid`): trunk flexion ``pitch`` (rad), pelvis
    ``drop`` below standing and forward ``shift`` (m), whether the pelvis tilt is
    ``capped`` (:func:`.body._trunk`) and whether it kneels on both knees."""

    pitch: float
    drop: float
    shift: float
    capped: bool
    kneel: bool


def _reach_postures(skeleton: Skeleton, st: _Start, targets: np.ndarray, active: tuple,
                    task: str, target: np.ndarray,
                    board: tuple[float, float, float] | None = None,
                    obstacles: ObstacleClearance | None = None,
                    furniture: tuple | None = None
                    ) -> list[ReachPosture]:
    """The cheapest feasible postures (:func:`_grid`, at most :data:`_POSTURE_TRIES`,
    cheapest first); ValueError where none reaches."""
    chosen = _cheapest_clear(skeleton, st, targets, active, task, board, obstacles, furniture)
    if chosen is not None:
        P, D, S, _, _, _, capped, kneel = _grid_base(skeleton, st, board is not None)
        order = np.asarray(chosen, dtype=np.intp)
    else:
        P, D, S, cost, capped, kneel = _grid(skeleton, st, targets, active, task, board,
                                             obstacles, furniture=furniture)
        order = np.argsort(cost, kind="stable")[:_POSTURE_TRIES]
        order = order[np.isfinite(cost[order])]
    if order.size == 0:
        raise ValueError(
            f"{task}: target {np.round(target, 3).tolist()} (start frame) is out of reach for a "
            f"{skeleton.stature:.2f} m worker")
    return [ReachPosture(float(P[i]), float(D[i]), float(S[i]), bool(capped[i]),
                         bool(kneel[i])) for i in order]
