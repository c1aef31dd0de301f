"""Where else to stand for a blocked goal step: the nearest stances from which the goal
model's own motion keeps clear of every obstacle.

The candidates are the step's placement and the other hand's (mirrored across the
target), each ``STANCE_BACKS`` further back, seen from ``STANCE_SIDES`` sides of the
target and placed out of the furniture as :func:`.standing.ideal_placement` places them.
They are ranked by how far the worker would stand from the first placement's stance
(metres, and ``YAW_COST`` metres per radian of turn) and checked in that order by the goal
model: its posture search first (:func:`.motion.goals.posture_clear`, cheap), then the
goal primitive itself, made there with a fixed seed and placed in the cell
(:meth:`.goal_steps.GoalSteps.goal_clear`). A stance is a try only if the model passed it;
nothing here knows a kind of furniture.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from ltl_human_motion.planning.plan_state import Pose
from ltl_human_motion.planning.standing import ideal_placement

#: Sides of the target the candidate stances face it from: every 15 degrees. A floor part
#: 0.14 m from a cart's long face is reached clear only from spots 15 degrees wide (the
#: body beside the cart, the arm between them).
STANCE_SIDES = 24

#: Extra distance from the target of the candidate stances, m: none, and up to three
#: steps back (a knee at a desk's front; a head under the board over a low shelf).
STANCE_BACKS: tuple[float, ...] = (0.0, 0.08, 0.16, 0.24)

#: Metres of standing-spot distance one radian of turn costs in the ranking (a stance
#: turned 60 degrees on the spot ranks with one 0.26 m away).
YAW_COST = 0.25

#: Candidates closer than this to the blocked try's stance (m; and ``SAME_YAW`` rad) are
#: that stance again, not tried.
SAME_SPOT = 0.03
SAME_YAW = math.radians(5.0)

#: Stances checked are at least this far apart (m) or turned this much (rad): a stance
#: next to one checked meets the same obstacles and ends the same walk.
SPREAD = 0.12
SPREAD_YAW = math.radians(20.0)

#: A candidate this near a stance whose walk failed is not walked to, m.
WALK_FAILED_NEAR = 0.15

#: Goal primitives the model makes to check candidates, at most per step (about 20 ms
#: each; the posture search rules most candidates out before one is made).
STANCE_CHECKS = 12


@dataclass(frozen=True)
class Stance:
    """A candidate stance for a goal step.

    Attributes
    ----------
    side : float
        Direction from the target the worker comes from, rad (the walk's sector).
    spot : tuple[float, float]
        The target in the standing root's frame (ahead, left), m, its step back included.
    pose : Pose
        Where the worker stands, (x, y, yaw), m, m, rad.
    cost : float
        Distance from the blocked try's stance, m (turns at ``YAW_COST``).
    """

    side: float
    spot: tuple[float, float]
    pose: Pose
    cost: float


def candidate_stances(ctx, target: np.ndarray, stood: Pose, first: float,
                      spots: list[tuple[float, float]]) -> list[Stance]:
    """The free stances for ``target`` (3,) from ``spots`` ((ahead, left) for each hand),
    ``STANCE_BACKS`` and ``STANCE_SIDES`` sides (from ``first``, rad), nearest first to
    the first placement's stance from side ``first`` (where the blocked try stood, or
    meant to), without the blocked try's stance ``stood``."""
    step = 2.0 * math.pi / STANCE_SIDES
    sides = first + step * np.arange(STANCE_SIDES)
    found: list[Stance] = []
    reference: Pose | None = None
    for ahead, left in spots:
        for back in STANCE_BACKS:
            spot = (ahead + math.copysign(back, ahead), left)
            far = 2.0 * math.hypot(*spot)
            px, py, yaw, free = ideal_placement(
                ctx, target, spot, target[0] + far * np.cos(sides),
                target[1] + far * np.sin(sides), ctx.options.max_step_back)
            if reference is None:
                reference = (float(px[0]), float(py[0]), float(yaw[0]))
            for k in np.flatnonzero(free):
                pose = (float(px[k]), float(py[k]), float(yaw[k]))
                if _near(pose, stood, SAME_SPOT, SAME_YAW):
                    continue
                dist = math.hypot(pose[0] - reference[0], pose[1] - reference[1])
                turn = abs(math.remainder(pose[2] - reference[2], 2.0 * math.pi))
                found.append(Stance(float(sides[k]), spot, pose, dist + YAW_COST * turn))
    furthest = max(math.hypot(abs(ahead) + STANCE_BACKS[-1] + ctx.options.max_step_back, left)
                   for ahead, left in spots)
    found += _steps_back(target, stood, furthest)
    found.sort(key=lambda stance: stance.cost)
    return _distinct(found)


def _steps_back(target: np.ndarray, stood: Pose, furthest: float) -> list[Stance]:
    """Stances ``STANCE_BACKS`` straight back from ``stood`` (the blocked try's), facing
    as it did, no further than ``furthest`` (m) from ``target`` (3,): where furniture in
    front kept the worker further back than the placement, the placement's own
    candidates lie further back still."""
    x, y, yaw = stood
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = float(target[0]) - x, float(target[1]) - y
    ahead, left = c * dx + s * dy, -s * dx + c * dy
    side = math.atan2(-dy, -dx)
    return [Stance(side, (ahead + back, left), (x - c * back, y - s * back, yaw), back)
            for back in STANCE_BACKS[1:] if math.hypot(ahead + back, left) <= furthest]


def _distinct(stances: list[Stance]) -> list[Stance]:
    """``stances`` without those within ``SAME_SPOT`` and ``SAME_YAW`` of an earlier one
    (two sides' probes the furniture pushes to one spot)."""
    kept: list[Stance] = []
    for stance in stances:
        if not any(_near(stance.pose, k.pose, SAME_SPOT, SAME_YAW) for k in kept):
            kept.append(stance)
    return kept


def _near(a: Pose, b: Pose, spot: float, turn: float) -> bool:
    """Whether pose ``a`` is within ``spot`` metres and ``turn`` rad of ``b``."""
    return math.hypot(a[0] - b[0], a[1] - b[1]) < spot \
        and abs(math.remainder(a[2] - b[2], 2.0 * math.pi)) < turn


def clear_stances(candidates: list[Stance], posture_ok: Callable[[Pose], bool],
                  motion_ok: Callable[[Pose], bool | None]) -> Iterator[Stance]:
    """The ``candidates``, at least ``SPREAD`` apart (or ``SPREAD_YAW`` turned; the nearer
    first), ordered by what the goal model says of them: first those where the posture
    search finds a clear posture (``posture_ok``) and the goal primitive made there is
    clear (``motion_ok`` True, one seed; at most ``STANCE_CHECKS`` made), then, nearest
    first, those where that primitive was blocked (False) or no posture was clear (the
    try there makes its primitives with the plan's own seeds); never one where the goal
    model did not reach the target (``motion_ok`` None)."""
    checked: list[Stance] = []
    blocked: list[Stance] = []
    unposed: list[Stance] = []
    for stance in candidates:
        if len(checked) >= STANCE_CHECKS:
            break
        if any(_near(stance.pose, k.pose, SPREAD, SPREAD_YAW) for k in checked):
            continue
        if not posture_ok(stance.pose):
            if not any(_near(stance.pose, k.pose, SPREAD, SPREAD_YAW) for k in unposed):
                unposed.append(stance)
            continue
        checked.append(stance)
        clear = motion_ok(stance.pose)
        if clear:
            yield stance
        elif clear is not None:
            blocked.append(stance)
    yield from sorted(blocked + unposed, key=lambda stance: stance.cost)


class StanceTries:
    """The clear stances of one blocked step, found lazily (the later ones are searched
    only when the walks to the earlier ones failed), never one within ``WALK_FAILED_NEAR``
    of a stance whose walk failed (its walk goal has no place to stop that keeps the body
    clear)."""

    def __init__(self, find: Callable[[], Iterator[Stance]]) -> None:
        self._find = find
        self._source: Iterator[Stance] | None = None
        self._failed: list[Stance] = []

    def next(self) -> Stance | None:
        """The next clear stance, or None if there is none."""
        if self._source is None:
            self._source = self._find()
        for stance in self._source:
            if not any(_near(stance.pose, k.pose, WALK_FAILED_NEAR, math.pi)
                       for k in self._failed):
                return stance
        return None

    def walk_failed(self, stance: Stance) -> None:
        """No walk got to ``stance``."""
        self._failed.append(stance)
