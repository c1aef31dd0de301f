"""The sides of a target from which the goal model's posture reaches it clear.

A reach goal of the walk (:meth:`.walk_goals.WalkGoals.reach`) accepts any free spot at
the placement's distance from the target; which of them the walk ends at is the shortest
walk's choice. Where furniture stands between some of those spots and the target (a
rack's back wall, a machine's side panel), the worker ends at the wrong side and every
motion made there is blocked. This module asks the posture model instead
(:func:`.motion.goals.posture_clear`: a posture with the hand on the target and the body
clear of the obstacles, as the goal primitive's search keeps it) at the standing spot of
``SIDES`` evenly spaced sides, nearest a given direction first, for the run of open
sides (an arc) nearest it. The first walk to a target goes there when the level line
from the target to where it ended passes through an obstacle and no posture reaches
the target from there (:func:`side_blocked`); the alternatives of a blocked goal step
walk to the open arc nearest the side they were blocked at
(:meth:`.goal_steps.GoalSteps.alternatives`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.motion.goals import LEVEL_PATH_TASKS, posture_clear
from ltl_human_motion.planning.astar import SearchBudget
from ltl_human_motion.planning.blend import wrap_angle
from ltl_human_motion.planning.plan_state import PlanContext, WorkerState, in_start_frame
from ltl_human_motion.planning.standing import board_local, ideal_placement, posture_clearance

__all__ = ["OPEN_SIDE_BUDGET", "SIDES", "Arc", "SideReach", "SideTest", "approach_open_side",
           "nearest_open_arc", "open_arc", "side_blocked", "side_spots", "side_tests"]

#: Evenly spaced sides of the target tested (every 22.5 degrees).
SIDES = 16
#: Node budget of the first walk to an open arc (the walk to the aisle side of a rack
#: from the floor in front of it took 300 nodes).
OPEN_SIDE_BUDGET = SearchBudget(1500)


#: A test of a standing pose (x, y, yaw) for a side of a target: open or not.
SideTest = Callable[[tuple[float, float, float]], bool]


@dataclass(frozen=True)
class Arc:
    """Consecutive open sides of a target: ``centre`` (rad, direction from the target
    to the standing spot) and ``half_width`` (rad, half a side's spacing beyond the
    outer sides)."""

    centre: float
    half_width: float


def side_spots(ctx: PlanContext, target: np.ndarray, placement: tuple[float, float],
               angles: np.ndarray) -> tuple[np.ndarray, ...]:
    """Where the worker stands ``placement`` (ahead, left, m) from ``target`` (3,) on the
    sides at ``angles`` (N,) (rad, direction from the target), with the steps back from
    an obstacle of :func:`.standing.ideal_placement`: x, y, yaw and free, each (N,)."""
    far = 2.0 * math.hypot(*placement)
    return ideal_placement(ctx, target, placement, target[0] + far * np.cos(angles),
                           target[1] + far * np.sin(angles), ctx.options.max_step_back)


def nearest_open_arc(ctx: PlanContext, target: np.ndarray, placement: tuple[float, float],
                     is_open: SideTest, toward: float, skip: float = 0.0, sides: int = SIDES
                     ) -> Arc | None:
    """The run of consecutive sides of ``target`` (3,) (``sides`` evenly spaced from the
    direction ``toward``, rad) nearest ``toward`` that pass ``is_open`` for the worker
    standing ``placement`` (ahead, left, m) from the target there
    (:func:`.standing.ideal_placement`, with its steps back from an obstacle; a free
    spot); sides within ``skip`` (rad) of ``toward`` are left out. None if no side is
    open. Sides are tested nearest first, and only until the run ends both ways."""
    step = 2.0 * math.pi / sides
    offsets = step * np.arange(sides)
    offsets = np.where(offsets > math.pi, offsets - 2.0 * math.pi, offsets)
    px, py, yaw, free = side_spots(ctx, target, placement, toward + offsets)
    tested: dict[int, bool] = {}

    def open_(k: int) -> bool:
        k %= sides
        if k not in tested:
            tested[k] = bool(free[k]) and abs(offsets[k]) > skip \
                and is_open((float(px[k]), float(py[k]), float(yaw[k])))
        return tested[k]

    order = sorted(range(sides), key=lambda k: abs(offsets[k]))
    first = next((k for k in order if open_(k)), None)
    if first is None:
        return None
    lo = hi = first
    while hi - lo + 1 < sides and open_(hi + 1):
        hi += 1
    while hi - lo + 1 < sides and open_(lo - 1):
        lo -= 1
    return Arc(float(wrap_angle(toward + step * (lo + hi) / 2.0)), step * (hi - lo + 1) / 2.0)


@dataclass(frozen=True)
class SideReach:
    """A hand task's reach as the side tests see it: task ``kind``, its ``target`` (3,),
    the ``placement`` (ahead, left, m) the worker stands at it, the ``hand`` that reaches
    (None: either) and the ``stance`` (J, 3) the reach starts from."""

    kind: str
    target: np.ndarray
    placement: tuple[float, float]
    hand: str | None
    stance: np.ndarray


def side_tests(ctx: PlanContext, reach: SideReach) -> tuple[SideTest, SideTest]:
    """The two tests of a standing pose (x, y, yaw) a side of the target is open by, the
    stricter first: the posture model reaches the target clear from there; the level
    line from the target to the worker passes no obstacle (:func:`side_blocked`: where
    no posture the model knows reaches in, a chamber 0.3 m behind its sill, the
    whole-body program may)."""
    return (functools.partial(_reaches_clear, ctx, reach),
            lambda pose: not side_blocked(ctx, reach.target, pose))


def open_arc(ctx: PlanContext, reach: SideReach, toward: float, skip: float = 0.0
             ) -> Arc | None:
    """The arc of sides open to ``reach``'s target nearest the direction ``toward``
    (rad; sides within ``skip`` of it left out) by the first of :func:`side_tests` that
    finds one (:func:`nearest_open_arc`), or None."""
    for test in side_tests(ctx, reach):
        arc = nearest_open_arc(ctx, reach.target, reach.placement, test, toward, skip)
        if arc is not None:
            return arc
    return None


def _reaches_clear(ctx: PlanContext, reach: SideReach, pose: tuple[float, float, float]
                   ) -> bool:
    """Whether the posture model reaches the target clear from a worker at ``pose``."""
    kind, target = reach.kind, reach.target
    local = in_start_frame(pose, target)
    board = board_local(ctx.cell, target, local, pose[2], ctx.stature) \
        if kind in LEVEL_PATH_TASKS else None
    return posture_clear(kind, local, ctx.library.skeleton, posture_clearance(ctx, pose),
                         start_pose=reach.stance, hand=reach.hand or "auto", board=board)


#: The line of :func:`side_blocked` starts this far from the target (the part's own
#: support and fixture stay out of it) and ends this far short of the standing root, m.
LINE_ENDS = (0.04, 0.15)
#: Radius of that line, m.
LINE_RADIUS = 0.02


def side_blocked(ctx: PlanContext, target: np.ndarray, pose: tuple[float, float, float]
                 ) -> bool:
    """Whether an obstacle stands on the level line from ``target`` (3,) towards the
    root of a worker at ``pose`` (x, y, yaw), at the target's height (the back wall of
    a rack between the worker and a part on its shelf)."""
    home = np.array([pose[0], pose[1], float(target[2])])
    way = home - np.asarray(target, dtype=np.float64)
    length = float(np.linalg.norm(way))
    if length <= sum(LINE_ENDS):
        return False
    way /= length
    seg = np.stack([target + LINE_ENDS[0] * way, home - LINE_ENDS[1] * way])[None]
    return bool(ctx.cell.part_set.capsule_clearance(seg, np.array([LINE_RADIUS]))[0] <= 0.0)


def approach_open_side(ctx: PlanContext, state: WorkerState, reach: SideReach,
                       walk: Callable[[Arc | None], int], walked: int, before: tuple) -> int:
    """Where the first walk to ``reach``'s target (``walked`` gait primitives, from the
    plan's ``before`` mark) ended on a side that an obstacle closes (:func:`side_blocked`)
    and no posture reaches the target from there, ``walk`` instead from where the worker
    stood before to the open arc nearest (:func:`open_arc`) and return its gait
    primitives; where there is none, or no walk gets there, the first walk is made again
    (``walk(None)``)."""
    if not side_blocked(ctx, reach.target, state.pose) or _reaches_clear(ctx, reach,
                                                                         state.pose):
        return walked
    state.restore(before)
    arc = open_arc(ctx, reach, math.atan2(before[1][1] - reach.target[1],
                                          before[1][0] - reach.target[0]))
    if arc is not None:
        try:
            return walk(arc)
        except PlanningError:
            state.restore(before)
    return walk(None)
