""":func:`make_goal_primitive`: one goal primitive of Table I for the exact target.

Checks the arguments and hands the task to its model: hand tasks to
:func:`.hand_tasks._hand_task`, bend/stoop/kneel to :func:`.down_up._down_up`, sit,
standUp and wait to theirs.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.gait import LIBRARY_FPS
from ltl_human_motion.motion.goals.body import _Start
from ltl_human_motion.motion.goals.down_up import _down_up, _sit_primitive, _stand_up, _wait
from ltl_human_motion.motion.goals.hand_tasks import _hand_task
from ltl_human_motion.motion.goals.posture_checks import ObstacleClearance
from ltl_human_motion.motion.goals.tasks import _MAX_TRAVEL, _check_furniture, _check_options
from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.motion.types import MotionPrimitive, world_positions
from ltl_human_motion.vocabulary import HAND_TASKS


def make_goal_primitive(task: str, target: np.ndarray | None, skeleton: Skeleton, *,
                        start_pose: np.ndarray | None = None,
                        rng: np.random.Generator | None = None, duration: float | None = None,
                        hand: str = "auto", fps: float = LIBRARY_FPS,
                        path: str = "arc", travel: float | None = None,
                        board: tuple[float, float, float] | None = None,
                        obstacles: ObstacleClearance | None = None,
                        support: tuple | None = None, ceiling: tuple | None = None
                        ) -> MotionPrimitive:
    """A goal primitive for one Table I task, made for the exact target.

    Parameters
    ----------
    task : str
        One of :data:`GOAL_TASKS`: grasp, release, move, leftHand, rightHand, assemble,
        insert, extract, bend, stoop, kneel, sit, standUp, wait.
    target : array-like, shape (3,), or None
        In the primitive's start frame (root floor position at the origin, facing +x,
        z = height above the floor). Hand tasks: where the palm goes (assemble: the middle
        between both palms; insert: the end of the push, which starts 8 cm before it along
        the horizontal shoulder-target direction; extract: where the hand takes the part,
        it is then pulled back 8 cm). sit: the point of the seat surface under the
        buttocks (must be behind the worker); standUp: the seat (only its height is used;
        the worker starts seated above the origin). bend/stoop/kneel: optional hand target
        reached in the low posture. wait: ignored.
    skeleton : Skeleton
    start_pose : array-like, shape (J, 3), optional
        Pose to start from (and return to): start-frame positions, or a root-relative
        pose (pelvis at the origin) which is then stood on the floor. Default: the standing
        pose of the gait library. For standUp it is the pose *ended in*.
    rng : numpy.random.Generator, optional
        Seeded variation of timing, hand-path bow, manipulation and sway (default seed 0).
    duration : float, optional
        Total length in seconds (hand and down-up tasks: the hold absorbs the change;
        sit/standUp: the descent/ascent; wait: the wait). ValueError when too short.
    hand : {"auto", "l_hand", "r_hand", "both"}
        Acting hand; auto = left for targets with y > 0, else right (kneel: its knee).
    fps : float
    path : {"arc", "level"}
        Hand path of grasp, release and move (:data:`HAND_PATHS`; insert and extract over
        a ``support``: :data:`PUSH_LEVEL_TASKS`); other tasks ignore it.
    travel : float, optional
        Length of insert's straight push and extract's pull, metres (default 8 cm).
    board : (edge, bottom, top), optional
        A low board over the target of grasp, release or move (start frame: front edge
        at x = edge, underside and top at heights bottom and top, metres): the posture
        keeps clear of it; the hand comes in level under it from in front of its edge.
    obstacles : ObstacleClearance, optional
        The obstacles around the worker, kept clear of where a posture does.
    support, ceiling : (nx, ny, offset, top), (nx, ny, offset, bottom, top), optional
        The furniture under a hand target and a board over it (:func:`_slab_depth`);
        over a support above the shoulders the level path rises (:func:`_rise_points`).

    Returns
    -------
    MotionPrimitive
        ``meta``: ``contact_frame`` (where the task's termination condition first holds),
        ``hand`` (l_hand, r_hand, both or none), ``target``, ``hold_frames``, ``posture``.

    Raises
    ------
    ValueError
        Unknown task, malformed or unreachable target, too short duration.
    """
    _check_options(task, skeleton, fps, duration, path)
    rng = np.random.default_rng(0) if rng is None else rng
    st = _Start(skeleton, start_pose)
    if task in HAND_TASKS:
        if travel is not None and not 0.0 < float(travel) <= _MAX_TRAVEL:
            raise ValueError(f"travel must be in (0, {_MAX_TRAVEL}] m, got {travel!r}")
        board, furniture = _check_furniture(board, support, ceiling)
        mp = _hand_task(task, target, skeleton, st, rng, duration, hand, fps, path, travel,
                        board, obstacles, furniture)
    else:
        mp = _body_task(task, target, skeleton, st, rng, duration, fps, hand)
    return within_speed_limits(mp, skeleton.stature)


def _body_task(task: str, target: np.ndarray | None, skeleton: Skeleton, st: _Start,
               rng: np.random.Generator, duration: float | None, fps: float,
               hand: str) -> MotionPrimitive:
    """The model of a task without a hand target: bend, stoop, kneel, wait, sit, standUp."""
    if task in ("bend", "stoop", "kneel"):
        return _down_up(task, skeleton, st, rng, duration, fps, target, hand)
    if task == "wait":
        return _wait(skeleton, st, rng, duration, fps)
    if task == "sit":
        return _sit_primitive(skeleton, st, rng, duration, fps, target)
    return _stand_up(skeleton, st, rng, duration, fps, target)


#: How fast a goal primitive slowed down for the verifier's joint speed limits may move
#: its fastest joint, as a fraction of its limit (the junction blends and foot locking
#: add a little at its ends).
GOAL_SPEED_ROOM = 0.97


def within_speed_limits(mp: MotionPrimitive, stature: float) -> MotionPrimitive:
    """``mp`` unchanged where every joint keeps within the verifier's speed limits for
    its task (:func:`~ltl_human_motion.motion.biomechanics.check_biomechanics`); else
    the same motion slowed down, uniformly in time, until its fastest joint moves at
    :data:`GOAL_SPEED_ROOM` of its limit (a 1.55 m worker's crouch to the floor took its
    knee to 2.23 m/s against 2.21). The timing models (Fitts, MTM) know no joint limits;
    the verifier's are a constraint of the motion, not a check that refuses it."""
    from ltl_human_motion.motion.biomechanics import BiomechanicsLimits, _speeds_and_limits
    limits = BiomechanicsLimits()
    speed, limit = _speeds_and_limits(world_positions(mp), mp.fps, [mp.task] * mp.n_frames,
                                      limits, float(stature) / limits.reference_stature)
    ratio = float(np.max(speed / limit)) if speed.size else 0.0
    if ratio <= 1.0:
        return mp
    from ltl_human_motion.motion.ops import resample_positions
    factor = ratio / GOAL_SPEED_ROOM
    T = mp.n_frames
    poses = resample_positions(mp.poses, mp.fps / factor, mp.fps)
    root = resample_positions(mp.root, mp.fps / factor, mp.fps)
    n = len(poses)

    def frame(f: int) -> int:
        return min(round(int(f) * (n - 1) / (T - 1)), n - 1)

    meta = dict(mp.meta)
    if "contact_frame" in meta:
        meta["contact_frame"] = frame(meta["contact_frame"])
    if "hold_frames" in meta:
        meta["hold_frames"] = [frame(f) for f in meta["hold_frames"]]
    return MotionPrimitive(name=mp.name, task=mp.task, poses=poses, root=root, fps=mp.fps,
                           source=mp.source + f" (slowed {factor:.3f}x for joint speed limits)",
                           meta=meta)
