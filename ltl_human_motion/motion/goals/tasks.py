"""Table I goal tasks: their names, hand paths, reach limits and input checks.

The task names (:data:`GOAL_TASKS`), which tasks may take the level hand path, the Table I
thresholds (``chestHeight``, ``kneeHeight``, seat heights, the highest and lowest target),
the palm targets of a task (:func:`_hand_targets`) and the checks of
:func:`~ltl_human_motion.motion.goals.make_goal_primitive`'s arguments.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.vocabulary import HAND_TASKS

POSTURE_TASKS: tuple[str, ...] = ("bend", "stoop", "kneel", "sit", "standUp", "wait")


GOAL_TASKS: tuple[str, ...] = HAND_TASKS + POSTURE_TASKS


_J = JOINT_INDEX


_SIDES = ("l", "r")


_REACH_FRACTION = 0.93          # hand never further than this fraction of the arm length


_ASSEMBLE_HALF_GAP = 0.035      # m, hands either side of an assembly target


_INSERT_TRAVEL = 0.08           # m, straight push of insert / pull of extract


_MAX_TRAVEL = 0.3               # m, longest push or pull asked for (a forearm's length)


#: Hand paths of ``make_goal_primitive``: ``"arc"`` swings the palm about the shoulder
#: straight to the target; ``"level"`` first brings it, near the body, to the height it
#: comes in at, then moves it in horizontally (over a shelf board's edge, under the
#: board above), and out the same way before the body straightens.
HAND_PATHS: tuple[str, ...] = ("arc", "level")


#: Tasks whose hand may take the level path (the palm comes in over a support).
LEVEL_PATH_TASKS: tuple[str, ...] = ("grasp", "release", "move")


#: Tasks whose ``"level"`` path makes the straight push (insert) or pull (extract) start
#: or end in front of the furniture under the target (a fixture in a machine's housing:
#: the 1.55 m worker's hand, coming up from the hip, hit the base's front edge).
PUSH_LEVEL_TASKS: tuple[str, ...] = ("insert", "extract")


#: Tasks whose hands may take the level path into a region (no part to come down onto):
#: the palms rise near the body to the target's height and come in over a bench top or
#: table edge below it instead of swinging up through its front (a short worker's hands
#: in the carry stance, and a part held in them, are below a 0.92 m bench top).
LEVEL_REGION_TASKS: tuple[str, ...] = ("assemble", "leftHand", "rightHand")


#: A board this low over a hand target (underside height above the floor, fraction of
#: stature; 0.63 m at 1.75 m) is below the shoulders of a stoop (0.7-0.9 m at 1.75 m,
#: measured on the under_shelf cell): the hand goes down in front of its edge and in
#: under it, from a deep crouch (:func:`make_goal_primitive`'s ``board``).
LOW_BOARD_HEIGHT = 0.36


def chest_height(skeleton: Skeleton) -> float:
    """Table I ``chestHeight``: the chest joint's height when standing."""
    return float(skeleton.rest_positions()[_J["chest"], 2])


def knee_height(skeleton: Skeleton) -> float:
    """Table I ``kneeHeight``: the knee joint's height when standing."""
    return float(skeleton.rest_positions()[_J["l_knee"], 2])


def seat_height_range(skeleton: Skeleton) -> tuple[float, float]:
    """Seat heights (m) ``sit`` can use: 0.20 H to 0.34 H."""
    return 0.20 * skeleton.stature, 0.34 * skeleton.stature


@lru_cache(maxsize=64)
def _bones(skeleton: Skeleton) -> np.ndarray:
    """``skeleton.bone_lengths()`` (J,), computed once per skeleton (read-only)."""
    b = skeleton.bone_lengths()
    b.flags.writeable = False
    return b


def _arm_length(skeleton: Skeleton) -> float:
    b = _bones(skeleton)
    return float(b[_J["l_elbow"]] + b[_J["l_wrist"]] + b[_J["l_hand"]])


def max_reach(task: str, skeleton: Skeleton) -> float:
    """Highest target (m above the floor) ``task`` can reach; for ``sit``/``standUp`` the
    highest seat. Tasks without a target (bend, stoop, kneel, wait) return ``inf``."""
    _check_task(task)
    if task in ("sit", "standUp"):
        return seat_height_range(skeleton)[1]
    if task in ("bend", "stoop", "kneel", "wait"):
        return float("inf")
    shoulder = skeleton.rest_positions()[_J["l_shoulder"], 2]
    return float(shoulder + 0.97 * _REACH_FRACTION * _arm_length(skeleton))


def min_reach_height(task: str, skeleton: Skeleton) -> float:
    """Lowest target height (m) for ``task`` (0 for hand tasks: the floor)."""
    _check_task(task)
    if task in ("sit", "standUp"):
        return seat_height_range(skeleton)[0]
    return 0.0


def _check_task(task: str) -> None:
    if task not in GOAL_TASKS:
        if task in ("walk", "carry"):
            raise ValueError(f"{task!r} is a gait task: use the gait library, not a goal "
                             f"primitive")
        raise ValueError(f"unknown goal task {task!r}; expected one of {', '.join(GOAL_TASKS)}")


def _hand_targets(task: str, target: np.ndarray, hand: str) -> tuple[np.ndarray, tuple, str]:
    """Palm targets (2, 3), active hand indices and the meta hand name."""
    t = np.asarray(target, dtype=np.float64)
    targets = np.stack([t, t])
    if task == "assemble" or hand == "both":
        targets[0, 1] += _ASSEMBLE_HALF_GAP
        targets[1, 1] -= _ASSEMBLE_HALF_GAP
        return targets, (0, 1), "both"
    if task == "leftHand":
        side = "l"
    elif task == "rightHand":
        side = "r"
    elif hand == "auto":
        side = "l" if t[1] > 0.0 else "r"
    elif hand in ("l_hand", "left", "l"):
        side = "l"
    elif hand in ("r_hand", "right", "r"):
        side = "r"
    else:
        raise ValueError(f"hand must be 'auto', 'l_hand', 'r_hand' or 'both', got {hand!r}")
    return targets, ((0,) if side == "l" else (1,)), f"{side}_hand"


def _checked_target(task: str, target: np.ndarray | None, skeleton: Skeleton) -> np.ndarray:
    """``target`` (3,) of a hand task as floats; ValueError if missing, malformed or out of
    the task's height range."""
    if target is None:
        raise ValueError(f"{task} needs a target position (3,) in the start frame")
    target = np.asarray(target, dtype=np.float64)
    if target.shape != (3,) or not np.all(np.isfinite(target)):
        raise ValueError(f"target must be a finite array of shape (3,), got {target.shape}")
    if target[2] < 0.0 or target[2] > max_reach(task, skeleton):
        raise ValueError(f"{task}: target height {target[2]:.3f} m is outside [0, "
                         f"{max_reach(task, skeleton):.3f}] m for a {skeleton.stature:.2f} m "
                         f"worker")
    return target


def _check_board(board: tuple[float, float, float]) -> tuple[float, float, float]:
    """``board`` as three floats (edge, bottom, top); ValueError if malformed."""
    b = np.asarray(board, dtype=np.float64)
    if b.shape != (3,) or not np.all(np.isfinite(b)) or not b[1] <= b[2]:
        raise ValueError(f"board must be (edge, bottom, top) with bottom <= top, got {board!r}")
    return float(b[0]), float(b[1]), float(b[2])


def _check_furniture(board: tuple | None, support: tuple | None, ceiling: tuple | None
                     ) -> tuple[tuple[float, ...] | None, tuple | None]:
    """``board`` (edge, bottom, top), and ``support`` (nx, ny, offset, top) and ``ceiling``
    (nx, ny, offset, bottom, top) as one pair (None without either), as floats;
    ValueError if malformed."""
    board = None if board is None else _check_board(board)
    out = []
    for name, value, n in (("support", support, 4), ("ceiling", ceiling, 5)):
        v = None if value is None else np.asarray(value, dtype=np.float64)
        if v is not None and (v.shape != (n,) or not np.all(np.isfinite(v))):
            raise ValueError(f"{name} must be {n} finite numbers, got {value!r}")
        out.append(None if v is None else tuple(float(x) for x in v))
    return board, (None if out == [None, None] else tuple(out))


def _fmt(target: np.ndarray | None) -> str:
    if target is None:
        return "none"
    return "[" + ",".join(f"{v:.3f}" for v in np.asarray(target)) + "]"


def _posture_name(pose: np.ndarray, skeleton: Skeleton) -> str:
    """Table I posture of a pose: 'stoop', 'bend' or 'upright' (joint-based)."""
    head_low = pose[_J["head"], 2] < chest_height(skeleton)
    butt_low = min(pose[_J["l_hip"], 2], pose[_J["r_hip"], 2]) < knee_height(skeleton)
    if head_low and butt_low:
        return "stoop"
    if head_low:
        return "bend"
    return "upright"


def _check_options(task: str, skeleton: Skeleton, fps: float, duration: float | None,
                   path: str) -> None:
    """ValueError unless the arguments of :func:`make_goal_primitive` are well formed."""
    _check_task(task)
    if not isinstance(skeleton, Skeleton):
        raise ValueError(f"skeleton must be a Skeleton, got {type(skeleton).__name__}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps!r}")
    if duration is not None and not duration > 0:
        raise ValueError(f"duration must be positive, got {duration!r}")
    if path not in HAND_PATHS:
        raise ValueError(f"path must be one of {', '.join(HAND_PATHS)}, got {path!r}")
