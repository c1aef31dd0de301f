"""Whether any floor pose passes a reach goal's test (:attr:`.astar.Goal.possible`):
where none does, the walk is refused before any search."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.planning.pipeline import get_library, resolve_cell
from ltl_human_motion.planning.planner import SequencePlanner
from ltl_human_motion.planning.standing import standing_offset

KITTING = Path(__file__).resolve().parents[1] / "scenarios" / "cells" / "kitting.yaml"


@pytest.fixture(scope="module")
def gear():
    """The kitting cell's gear (in the shelf, beside its side wall) for a 1.75 m worker:
    the planner, the grasp target (3,) and its standing placement."""
    cell = resolve_cell(KITTING).floor_at_zero()
    planner = SequencePlanner(cell, get_library(1.75), np.random.default_rng(0))
    target = planner.target_of("grasp", ("gear",))
    placement = standing_offset(planner.ctx, "grasp", target, "grasp(gear)", None,
                                carry_stance=True)
    return planner, target, placement


@pytest.mark.parametrize("degrees", range(0, 360, 30))
def test_possible_agrees_with_the_goal_test_on_random_poses(gear, degrees) -> None:
    planner, target, placement = gear
    goal, _ = planner.goals.reach(target, placement, "reach gear", "grasp(gear)",
                                  sector=(math.radians(degrees), 0.5))
    rng = np.random.default_rng(degrees)
    n = 100_000
    x = target[0] + rng.uniform(-1.5, 1.5, n)
    y = target[1] + rng.uniform(-1.5, 1.5, n)
    yaw = rng.uniform(-np.pi, np.pi, n)
    hits = int(goal.reached(x, y, yaw).sum())
    if hits:
        assert goal.possible()
    else:
        # so rare that random poses miss it, or none at all: never said possible when
        # a search could not end, the other way round only
        assert degrees != 60 or not goal.possible()


def test_a_side_into_the_shelf_wall_is_refused_before_any_search(gear) -> None:
    """From 60 degrees (the shelf's side wall and the cart's way) no standing spot is
    free: the approach is refused at once, blocked, with no node expanded."""
    from ltl_human_motion.errors import PlanningError

    planner, target, placement = gear
    goal, _ = planner.goals.reach(target, placement, "reach gear", "grasp(gear)",
                                  sector=(math.radians(60), 0.5))
    assert goal.possible() is False
    planner.state.start_at((0.0, 0.0, 0.0))
    with pytest.raises(PlanningError) as err:
        planner.goal_steps.approach(target, placement, "grasp(gear)",
                                    sector=(math.radians(60), 0.5))
    assert err.value.reason == "blocked"
    assert "no place to stand there keeps the body clear" in str(err.value)
    assert planner.state.expanded == 0
