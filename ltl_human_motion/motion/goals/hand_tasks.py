"""Hand task primitives (grasp ... extract): posture, body path and hand path put together.

:func:`_hand_task` picks the cheapest postures (:func:`.postures._reach_postures`), makes
the reach, hold and return (:func:`_reach_motion`: the body leads the hand, the hand
follows its reference path, free hands stay by the hip or prop a kneeling trunk), slows
it where a hand, wrist or elbow is too fast, and tries wider swings or other postures
where an arm passes through the body.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ltl_human_motion.motion.goals.body import _frames, _Start, _trunk
from ltl_human_motion.motion.goals.hand_paths import (
    _BOARD_FRONT,
    _hand_keys,
    _hand_orientation,
    _hand_path,
    _reach_times,
    _rise_points,
)
from ltl_human_motion.motion.goals.kneeling import (
    KNEEL_DOWN_SECONDS,
    _hangs,
    _kneel_progress,
    _prop_orientation,
    _prop_point,
)
from ltl_human_motion.motion.goals.posture_checks import ObstacleClearance
from ltl_human_motion.motion.goals.postures import ReachPosture, _reach_postures
from ltl_human_motion.motion.goals.tasks import (
    _INSERT_TRAVEL,
    _J,
    _MAX_TRAVEL,
    _SIDES,
    LEVEL_PATH_TASKS,
    LEVEL_REGION_TASKS,
    PUSH_LEVEL_TASKS,
    _arm_length,
    _checked_target,
    _fmt,
    _hand_targets,
    _posture_name,
)
from ltl_human_motion.motion.goals.timelines import _finish, _n_frames, _profile
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, Skeleton
from ltl_human_motion.motion.types import MotionPrimitive

#: Fastest a hand or wrist of a model-made hand goal primitive moves over 1/30 s, m/s at
#: 1.75 m (scaled by stature): 10 % under the verifier's 2.5 m/s hand limit in goal tasks
#: (planning.biomechanics), room for the offset blending of its junctions.
HAND_RETIME_SPEED = 2.25


#: The same for an acting arm's elbow: 10 % under the verifier's 3.5 m/s for other
#: joints. The palm rising close in front of the body to a board above the shoulders
#: (:func:`_rise_points`) swings the elbow up faster than the palm moves.
ELBOW_RETIME_SPEED = 3.15


#: Factors on :data:`_LOW_REACH_WIDE` a hand task tries, in order, where the swing past the
#: thigh still passes the forearm through it (the thigh rises towards a deeply flexed
#: trunk; 1.75-1.95 m workers reaching near their feet from the carry stance).
_WIDER_SWINGS = (1.0, 2.0, 3.0)


#: A board over a part this close above its grasp point (m) leaves no room for a palm
#: that points down as the arm does (the wrist a hand's length above it, in the board):
#: the palm comes in level (:func:`_goal_hand_dir`; a part in a shelf compartment).
_LEVEL_PALM_GAP = 0.25


def _push_travel(task: str, target: np.ndarray, st: _Start, hand: str,
                 travel: float | None, path: str,
                 support: tuple[float, float, float, float] | None) -> tuple[float, bool]:
    """Length of the straight push of insert or pull of extract, metres: ``travel``
    (default ``_INSERT_TRAVEL``); on the ``"level"`` path (:data:`PUSH_LEVEL_TASKS`) over
    furniture (``support``, :func:`_support_depth`), long enough (up to ``_MAX_TRAVEL``)
    that the push starts and the pull ends ``_BOARD_FRONT`` in front of its edge, where
    the hand comes from and goes back to the hip without passing under the edge (and
    extract goes in the same straight way). Also whether the hand takes that level
    path."""
    travel = _INSERT_TRAVEL if travel is None else float(travel)
    if support is None or path != "level" or task not in PUSH_LEVEL_TASKS:
        return travel, False
    t = np.asarray(target, dtype=np.float64)
    targets, active, _ = _hand_targets(task, t, hand)
    a = targets[active[0]] - st.shoulders[active[0]]
    a[2] = 0.0
    a /= max(float(np.linalg.norm(a)), 1e-9)
    nx, ny, offset, _ = support
    towards = nx * a[0] + ny * a[1]                   # how fast the push goes in
    if towards <= 1e-6:
        return travel, False
    need = (nx * t[0] + ny * t[1] - offset + _BOARD_FRONT) / towards
    return float(np.clip(need, travel, _MAX_TRAVEL)), True


def _push_direction(task: str, target: np.ndarray, st: _Start, active: tuple[int, ...]
                    ) -> np.ndarray:
    """The horizontal unit direction (3,) from the acting shoulder to ``target`` (3,) along
    which insert pushes into it (from a point before it) and extract pulls back from it;
    zeros for other tasks."""
    if task not in ("insert", "extract"):
        return np.zeros(3)
    a = target - st.shoulders[active[0]]
    a[2] = 0.0
    n = np.linalg.norm(a)
    return a / n if n > 1e-6 else np.array([1.0, 0.0, 0.0])


@dataclass(frozen=True)
class _ReachPath:
    """How the palm of a hand task goes (:func:`_hand_task`): on the ``level`` path (else
    the arc); insert's push and extract's pull ``travel`` (m) along ``approach`` (3,)
    (:func:`_push_direction`); the low ``board`` (edge, bottom, top) over the target, the
    furniture under it, ``support`` (nx, ny, offset, top), or None; and whether the palm
    comes in level (``flat_palm``, a board close over the target)."""

    level: bool
    travel: float
    approach: np.ndarray
    board: tuple[float, float, float] | None
    support: tuple[float, float, float, float] | None
    flat_palm: bool


def _hand_task(task: str, target: np.ndarray, skeleton: Skeleton, st: _Start,
               rng: np.random.Generator, duration: float | None, hand: str,
               fps: float, path: str = "arc", travel: float | None = None,
               board: tuple[float, float, float] | None = None,
               obstacles: ObstacleClearance | None = None,
               furniture: tuple | None = None) -> MotionPrimitive:
    H = skeleton.stature
    travel, pushed = _push_travel(task, target, st, hand, travel, path,
                                  None if furniture is None else furniture[0])
    board = board if task in LEVEL_PATH_TASKS else None
    support = None if furniture is None or task not in LEVEL_PATH_TASKS + PUSH_LEVEL_TASKS \
        else furniture[0]
    ceiling = None if furniture is None or task not in LEVEL_PATH_TASKS else furniture[1]
    # Over furniture above the shoulders every path rises in front of its edge first.
    over = support is not None and support[3] > float(st.shoulders[:, 2].max())
    level = pushed or ((path == "level" or board is not None or over)
                       and task in LEVEL_PATH_TASKS) \
        or (path == "level" and task in LEVEL_REGION_TASKS)
    target = _checked_target(task, target, skeleton)
    lid = min(np.inf if board is None else board[1], np.inf if ceiling is None else ceiling[3])
    flat_palm = lid - float(target[2]) < _LEVEL_PALM_GAP
    targets, active, hand_name = _hand_targets(task, target, hand)
    approach = _push_direction(task, target, st, active)
    postures = _reach_postures(skeleton, st, targets, active, task, target, board, obstacles,
                               furniture)
    # the cheapest posture, swinging wider past the thigh where the arm would pass through
    # it, then the next postures; last the kneeling ones without the free hand's prop
    # (on the way up its forearm can pass through the thigh coming forward)
    tries = [(postures[0], w, True) for w in _WIDER_SWINGS] + \
        [(p, 1.0, True) for p in postures[1:]] + [(p, 1.0, False) for p in postures if p.kneel]
    draws = rng.bit_generator.state
    for posture, wide, prop in tries:
        rng.bit_generator.state = draws
        world, f1, f2, contact_t = _reach_motion(
            task, skeleton, st, targets, active, posture,
            _ReachPath(level, travel, approach, board, support, flat_palm), rng, duration, fps,
            wide, prop)
        penetrates = _self_penetrates(world, H)
        if not penetrates:
            break
    T = world.shape[0]
    contact = min(round(contact_t * fps), T - 1)
    meta = {"contact_frame": contact, "hand": hand_name, "target": target.tolist(),
            "hold_frames": [f1, f2], "trunk_flexion": posture.pitch, "pelvis_drop": posture.drop,
            "posture": _posture_name(world[f1], skeleton), "self_penetrating": penetrates}
    return _finish(f"{task}_{_fmt(target)}", task, world, st, fps,
                   f"goals.make_goal_primitive({task!r}, target={_fmt(target)})", meta)


def _self_penetrates(world: np.ndarray, stature: float) -> bool:
    """Whether a body capsule's bone axis enters another, non-neighbouring one in any frame
    of ``world`` (T, J, 3) (the verifier's self-penetration check)."""
    from ltl_human_motion.motion.biomechanics import max_self_penetration
    return max_self_penetration(world, stature) > 0.0


def _hanging(st: _Start) -> bool:
    """Whether the start pose's hands hang beside the body (below the hips: the arms
    down, not raised to the carry stance)."""
    return bool(np.all(st.hands[:, 2] < st.pelvis[2]))


def _reach_motion(task: str, skeleton: Skeleton, st: _Start, targets: np.ndarray,
                  active: tuple[int, ...], posture: ReachPosture,
                  path: _ReachPath, rng: np.random.Generator, duration: float | None, fps: float,
                  wide: float = 1.0, prop: bool = True) -> tuple[np.ndarray, int, int, float]:
    """Frames (T, J, 3) of a hand task's reach into ``posture``, its hold and its return;
    the first and last hold frame and the contact time (s). ``posture`` may kneel
    (:func:`_kneel_progress`). ``path``: how the palm goes (:func:`_hand_task`); ``wide``
    scales the low reach's swing outside the thigh (:func:`_hand_path`); ``prop``: a
    kneeling worker's free hand props the trunk (:func:`_free_hands`)."""
    H = skeleton.stature
    arm = _arm_length(skeleton)
    level, travel, approach = path.level, path.travel, path.approach
    board, support, flat_palm = path.board, path.support, path.flat_palm
    pitch1, drop1, kneel = posture.pitch, posture.drop, posture.kneel
    dist = max(np.linalg.norm(targets[k] - st.hands[k]) for k in active)
    t_reach, hold, t_ret = _reach_times(task, dist, pitch1, drop1, H, level, duration, rng)
    if kneel:       # the body is down at half the reach time and up again as long after
        t_reach, t_ret = (max(v, 2.0 * KNEEL_DOWN_SECONDS) for v in (t_reach, t_ret))
    # Timed for the arced path's palm speed; where the posture's trunk motion or a level
    # path makes a hand or wrist faster than HAND_RETIME_SPEED (an elbow faster than
    # ELBOW_RETIME_SPEED), the reach and return are slowed by what they exceed and the
    # motion made again (at most twice), from the same random draws (the same path,
    # only slower).
    draws = rng.bit_generator.state
    for _ in range(3):
        rng.bit_generator.state = draws
        total = t_reach + hold + t_ret
        T = _n_frames(total, fps)
        t = np.arange(T) / fps
        t1, t2 = t_reach, t_reach + hold
        sb, lean, legs, pelvis, pitch, tr = _body_path(skeleton, st, t, (t1, t2, total),
                                                       posture, level, active[0])
        shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)   # (T,2,3)
        f1 = min(round(t1 * fps), T - 1)
        f2 = min(round(t2 * fps), T - 1)
        sh1 = shoulders[f1]
        # hand key positions relative to the shoulder
        rel_home = st.hand_rel
        rel_goal = rel_home.copy()
        rel_pre = rel_home.copy()
        for k in active:
            rel_goal[k] = targets[k] - sh1[k]
            rel_pre[k] = targets[k] - travel * approach - sh1[k]
        rise = _rise_points(targets, active, sh1, support, arm, H,
                            tr[f1, [_J["neck"], _J["head"]]],
                            st.hands if task in PUSH_LEVEL_TASKS or _hanging(st) else None) \
            if level and board is None else None
        keys, contact_t, straight = _hand_keys(task, targets, active, sh1, rel_home, rel_goal,
                                               rel_pre, (t1, t2, total), level, board, H, arm,
                                               rise)
        rel = _hand_path(t, keys, (t1, t2, total), active, targets, shoulders, sh1, st, level,
                         board, dist, H, arm, rng, wide, straight)
        if task in ("leftHand", "rightHand", "assemble") and hold > 0.4:
            _add_manipulation(rel, t, t1, t2, active, rng)
        hands = shoulders + rel
        _free_hands(hands, active, st, pelvis, sb, lean if kneel and prop else None, sh1, H,
                    arm)
        hand_dir, elbow_pole = _hand_orientation(task, active, st, t, (t1, t2, total), rel_goal,
                                                 flat_palm or rise is not None)
        if kneel and prop:
            _prop_orientation(hand_dir, elbow_pole, lean,
                              tuple(k for k in range(2) if k in active or not _hangs(st, k)))
        world = _frames(skeleton, st, t, pelvis, pitch, hands, hand_dir, elbow_pole, *legs,
                        trunk=tr)
        peak = max(_peak_hand_speed(world, active, fps),
                   _peak_hand_speed(world, active, fps, ("elbow",))
                   * HAND_RETIME_SPEED / ELBOW_RETIME_SPEED)
        limit = HAND_RETIME_SPEED * H / DEFAULT_STATURE
        if peak <= limit or duration is not None:
            break
        t_reach *= 1.03 * peak / limit
        t_ret *= 1.03 * peak / limit
    return world, f1, f2, contact_t


def _body_path(skeleton: Skeleton, st: _Start, t: np.ndarray,
               times: tuple[float, float, float], posture: ReachPosture, level: bool,
               first: int
               ) -> tuple[np.ndarray, ...]:
    """The body of a hand task at times ``t`` (T,) (``times`` = reach end, hold end,
    total; ``posture`` as :func:`_reach_motion`'s): the pelvis's progress to the posture
    and the trunk lean's (each (T,)), the ankles, toes and knee poles (each (T, 2, 3), or
    None: the start pose's), the pelvis (T, 3), the trunk pitch (T,) and the trunk
    (T, J, 3). The posture leads the hand: it is reached at 85 % of the reach time (level
    path: half, before the hand comes in, and kept until it is out again); a kneeling
    one kneels down in that time (:func:`_kneel_progress`, ``first`` the foot stepping
    back first)."""
    t1, t2, total = times
    pitch1, drop1, shift1 = posture.pitch, posture.drop, posture.shift
    capped, kneel = posture.capped, posture.kneel
    t_ret = total - t2
    body_keys = ([(0.0, 0.0), (0.5 * t1, 1.0), (t2 + 0.5 * t_ret, 1.0), (total, 0.0)] if level
                 else [(0.0, 0.0), (0.85 * t1, 1.0), (t2 + 0.15 * t_ret, 1.0), (total, 0.0)])
    sb = _profile(t, body_keys)
    lean, legs = sb, (None, None, None)
    if kneel:
        sb, lean, legs = _kneel_progress(skeleton, st, t, (0.5 * t1, t2 + 0.5 * t_ret, total),
                                         (drop1, shift1), first)
    pelvis = np.tile(st.pelvis, (t.size, 1))
    pelvis[:, 2] -= drop1 * sb
    pelvis[:, 0] += shift1 * sb
    pitch = pitch1 * lean
    return sb, lean, legs, pelvis, pitch, _trunk(skeleton, pelvis, pitch, capped, st.hips(),
                                                 kneel)


def _free_hands(hands: np.ndarray, active: tuple[int, ...], st: _Start, pelvis: np.ndarray,
                sb: np.ndarray, lean: np.ndarray | None, sh1: np.ndarray, stature: float,
                arm: float) -> None:
    """Set the hands (T, 2, 3) that are not ``active`` in place: by the hip while the
    trunk leans (they do not swing forward into the furniture the other hand reaches
    over; ``sb`` (T,): the body's progress); kneeling (``lean`` (T,) given), a hand that
    hangs free (:func:`_hangs`) goes down onto the floor under the shoulder (``sh1``
    (2, 3) in the posture) as the trunk leans, to prop it (:func:`_prop_point`)."""
    for k in range(2):
        if k in active:
            continue
        hands[:, k] = pelvis + (st.hands[k] - st.pelvis) + np.array([0.0, 0.0, 0.04]) * \
            sb[:, None]
        if lean is not None and _hangs(st, k):
            hands[:, k] += lean[:, None] * (_prop_point(sh1[k], stature, arm) - hands[:, k])


def _add_manipulation(rel: np.ndarray, t: np.ndarray, t1: float, t2: float,
                      active: tuple[int, ...], rng: np.random.Generator) -> None:
    """Add small manipulation movements (1 cm, 0.7-1.4 Hz) to the acting hands' shoulder
    offsets ``rel`` (T, 2, 3) while they are in the region, between times t1 and t2."""
    env = _profile(t, [(t1, 0.0), (t1 + 0.2, 1.0), (t2 - 0.2, 1.0), (t2, 0.0)])
    env = np.where((t > t1) & (t < t2), env, 0.0)
    for k in active:
        f = rng.uniform(0.7, 1.4, size=3)
        ph = rng.uniform(0.0, 2 * np.pi, size=3)
        amp = np.array([0.010, 0.008, 0.008])
        wob = amp * np.sin(2 * np.pi * f * t[:, None] + ph)
        rel[:, k] += env[:, None] * wob


def _peak_hand_speed(world: np.ndarray, active: tuple[int, ...], fps: float,
                     parts: tuple[str, ...] = ("hand", "wrist")) -> float:
    """Largest speed (m/s) of an acting arm's ``parts`` (default the palm and wrist) in
    ``world`` (T, J, 3), as displacements over 1/30 s (the verifier's window)."""
    w = max(1, round(fps / 30.0))
    if len(world) <= w:
        return 0.0
    joints = [_J[f"{_SIDES[k]}_{n}"] for k in active for n in parts]
    d = world[w:, joints] - world[:-w, joints]
    return float(np.sqrt(np.max(np.sum(d * d, axis=-1)))) * fps / w
