"""How far from a target to stand where the placement model's distance is in furniture.

:func:`.standing.standing_offset` gives the distance from which the goal model's
posture reaches a target best, for the target's height alone: a tall worker's part at
hip height is best reached standing close over it. A part 0.37 m inside a machine's
chamber leaves no free spot that close on any side, even with the steps back
:func:`.standing.ideal_placement` allows, and the walk's search runs its budget out
looking for one. :func:`farther_placement` moves the placement back in
``STEP`` increments to the nearest distance where two neighbouring sides of the target
have a free spot from which the level line to the target passes no obstacle
(:func:`.open_sides.side_blocked`) and from which the goal model still reaches it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ltl_human_motion.planning.open_sides import SIDES, side_blocked, side_spots
from ltl_human_motion.planning.plan_state import PlanContext

__all__ = ["FURTHEST", "STEP", "farther_placement", "has_spot"]

#: Increment of the distance tried, m.
STEP = 0.08
#: Furthest the placement moves back, m.
FURTHEST = 0.48


def has_spot(ctx: PlanContext, target: np.ndarray, placement: tuple[float, float],
             open_line: bool = False) -> bool:
    """Whether two neighbouring sides of ``target`` (3,) (of ``SIDES``) have a free
    standing spot for ``placement`` (ahead, left, m; :func:`.standing.ideal_placement`
    with its steps back), with ``open_line`` each one whose level line to the target
    passes no obstacle. One side alone is a sliver of floor the walk's search does not
    hit within its budget: a 1.95 m worker's vise 0.35 m inside a machine had a spot
    only straight in front, at the last step back, and the walk spent 7,500 nodes (5 s)
    before it stopped there."""
    px, py, yaw, free = side_spots(ctx, target, placement,
                                   2.0 * math.pi * np.arange(SIDES) / SIDES)
    ok = free.copy()
    if open_line:
        for k in np.flatnonzero(free):
            ok[k] = not side_blocked(ctx, target, (float(px[k]), float(py[k]), float(yaw[k])))
    return bool(np.any(ok & np.roll(ok, 1)))


def farther_placement(ctx: PlanContext, target: np.ndarray, placement: tuple[float, float],
                      reaches: Callable[[tuple[float, float, float]], bool]
                      ) -> tuple[float, float] | None:
    """Where no two neighbouring sides of ``target`` (3,) have a free spot for
    ``placement`` (ahead, left, m) whose level line to the target is open
    (:func:`has_spot`), the nearest placement further back (by ``STEP``, up to
    ``FURTHEST``) that has one and from which ``reaches((ahead, left, height))`` (the
    goal model's reach test in the start frame);
    None where ``placement`` has such a spot, or no placement further back does."""
    if has_spot(ctx, target, placement, open_line=True):
        return None
    d, lat = placement
    for k in range(1, round(FURTHEST / STEP) + 1):
        ahead = d + k * STEP
        if has_spot(ctx, target, (ahead, lat), open_line=True) \
                and reaches((ahead, lat, float(target[2]))):
            return ahead, lat
    return None
