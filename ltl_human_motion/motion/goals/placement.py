"""Where the worker stands for a goal task: :func:`reach_placement`.

The target's distance in front of the standing root (and lateral offset) that gives the
cheapest posture of the posture search (:func:`.postures._grid`), memoized per task,
height, stature, hand, board and start pose.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ltl_human_motion.motion.goals.body import _Start
from ltl_human_motion.motion.goals.postures import _grid, least_cost
from ltl_human_motion.motion.goals.tasks import (
    LEVEL_PATH_TASKS,
    _check_board,
    _check_task,
    _hand_targets,
    max_reach,
    min_reach_height,
)
from ltl_human_motion.motion.skeleton import Skeleton

#: How much nearer the worker a low board's edge may be than where reach_placement puts
#: it, m: the walk ends within a few cm and degrees of the standing place, and the edge
#: across a turned worker comes nearer on one side.
_BOARD_PLACE_MARGIN = 0.04


@lru_cache(maxsize=512)
def _placement(task: str, height: float, stature: float, hand: str,
               board: tuple[float, float, float] | None = None,
               start: bytes | None = None, full_tilt: bool = True) -> tuple[float, float]:
    """:func:`reach_placement` (``start``: the start pose's float64 bytes, or None)."""
    skeleton = Skeleton(stature)
    H = stature
    if task in ("sit", "standUp"):
        return -0.10 * H, 0.0
    if task in ("bend", "stoop", "kneel", "wait"):
        return 0.0, 0.0
    both = task == "assemble" or hand == "both"
    lateral = 0.0 if both else (0.07 * H if (task == "leftHand" or hand in ("l_hand", "left"))
                                else -0.07 * H)
    st = _Start(skeleton, None if start is None
                else np.frombuffer(start, dtype=np.float64).reshape(-1, 3))
    best = (np.inf, None)
    # Under a low board: with _BOARD_PLACE_MARGIN where that leaves a place, else without;
    # a place for a capped or kneeling posture before one for a full pelvis tilt
    # (_grid_base).
    tries = [(0.0, False)] if board is None else [
        (m, full) for full in ((False, True) if full_tilt else (False,))
        for m in (_BOARD_PLACE_MARGIN, 0.0)]
    for margin, full in tries:
        for x in np.linspace(0.12 * H, 0.45 * H, 12):
            target = np.array([x, lateral, height])
            targets, active, _ = _hand_targets(task, target, "both" if both else (
                "l_hand" if lateral > 0 else "r_hand"))
            if board is None:
                c = least_cost(skeleton, st, targets, active, task, capped_only=not full)
            else:
                _, _, _, cost, capped, kneel = _grid(
                    skeleton, st, targets, active, task, (x - board[0] - margin, board[1],
                                                          board[2]))
                c = float(np.min(cost if full else np.where(capped | kneel, cost, np.inf)))
            if c < best[0]:
                best = (c, float(x))
        if best[1] is not None:
            break
    if best[1] is None:
        raise ValueError(f"{task}: no standing place reaches a target at height {height:.3f} m")
    return best[1], lateral


def reach_placement(task: str, target_height: float, skeleton: Skeleton,
                    hand: str = "auto", board: tuple[float, float, float] | None = None,
                    start_pose: np.ndarray | None = None, full_tilt: bool = True
                    ) -> tuple[float, float]:
    """Where to put the target relative to the standing root for a comfortable posture.

    Parameters
    ----------
    task : str
    target_height : float
        Height of the target above the floor (for sit/standUp: the seat height).
    skeleton : Skeleton
    hand : str
        ``"auto"`` uses the right hand for one-handed tasks (leftHand: left).
    board : (depth, bottom, top), optional
        A low board over the target of grasp, release or move: the target lies ``depth``
        behind its front edge, under its underside at height ``bottom`` (top: ``top``).
        The worker then stands where the crouched body stays in front of the edge.
    start_pose : ndarray, shape (J, 3), optional
        The pose the goal primitive will start from (as :func:`make_goal_primitive`
        takes it); default the skeleton's rest pose. A reach under a low board is tight
        enough that the start's feet and arms decide whether a place reaches.
    full_tilt : bool
        Under a low board, whether a place may need the pelvis tilted in full, past the
        hips' range of motion (only where no place reaches without it).

    Returns
    -------
    distance_in_front, lateral_offset : float
        The target should be at ``(distance_in_front, lateral_offset, target_height)`` in
        the goal primitive's start frame (x forward, y left); equivalently the worker stands
        ``distance_in_front`` behind the target, facing it, with the target
        ``lateral_offset`` to the left. sit: negative distance (the seat is behind).
        Tasks without a target return (0, 0).

    Raises
    ------
    ValueError
        Unknown task, or the height is outside ``[min_reach_height, max_reach]``.
    """
    _check_task(task)
    h = float(target_height)
    lo, hi = min_reach_height(task, skeleton), max_reach(task, skeleton)
    if not (lo - 1e-9 <= h <= hi + 1e-9):
        raise ValueError(f"{task}: target height {h:.3f} m is outside [{lo:.3f}, {hi:.3f}] m "
                         f"for a {skeleton.stature:.2f} m worker")
    if board is not None and task in LEVEL_PATH_TASKS:
        board = tuple(round(v, 4) for v in _check_board(board))
    else:
        board = None
    start = None if start_pose is None else \
        np.ascontiguousarray(start_pose, dtype=np.float64).tobytes()
    return _placement(task, round(h, 4), float(skeleton.stature), hand, board, start,
                      bool(full_tilt))
