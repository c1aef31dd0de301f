"""The reach's posture search keeps the whole body clear of the obstacles around it.

The largest family of the scenario corpus's failures (planning:grasp:blocked, mostly at
1.95 m): the posture search kept only one board clear, so a tall worker's knees went
into a table's front as the pelvis dropped (demo_cell, seats, kitting), and the head
passed through the board above a low shelf on its way down (shelf_heights O_knee).
``make_goal_primitive(obstacles=...)`` now checks each candidate posture's contact pose
and the trunk's and legs' way into it against every obstacle part nearby.
"""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.goals import make_goal_primitive
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import world_positions
from ltl_human_motion.scene.clearance import PartSet
from ltl_human_motion.scene.occupancy import capsules_from_positions
from ltl_human_motion.scene.shapes import Box

TALL = Skeleton(1.95)


def _table(front: float, top: float) -> PartSet:
    """A table 0.6 m deep whose front faces the worker at x = ``front``, ``top`` high."""
    return PartSet([Box.from_bounds(np.array([front, -0.6, 0.0]),
                                    np.array([front + 0.6, 0.6, top]))])


def test_a_tall_workers_reach_to_a_table_keeps_the_knees_out_of_its_front() -> None:
    """A 1.95 m worker grasping a part on a 0.75 m table: the cheapest posture bends the
    knees into the table's front; with the obstacles the search stoops more instead and
    the whole motion keeps clear."""
    table = _table(0.28, 0.75)

    def obstacles(poses: np.ndarray, parts: tuple[str, ...]) -> np.ndarray:
        seg, rad = capsules_from_positions(poses, TALL.stature, parts)
        return table.body_clearance(seg, rad)

    target = np.array([0.5, -0.136, 0.84])
    clear = {}
    for around in (None, obstacles):
        mp = make_goal_primitive("grasp", target, TALL, rng=np.random.default_rng(0),
                                 obstacles=around)
        seg, rad = capsules_from_positions(world_positions(mp), TALL.stature)
        clear[around is not None] = float(np.min(table.body_clearance(seg, rad)))
        hand = world_positions(mp)[mp.meta["contact_frame"], JOINT_INDEX["r_hand"]]
        assert np.linalg.norm(hand - target) < 0.01
    assert clear[False] < 0.0 < clear[True]


def test_obstacles_that_no_posture_clears_leave_the_search_as_it_was() -> None:
    """Where every candidate posture comes near the obstacles (a wall through the
    worker), the search goes on without them: the same posture as with none."""
    wall = PartSet([Box.from_bounds(np.array([-0.3, -1.0, 0.0]), np.array([1.0, 1.0, 2.5]))])

    def obstacles(poses: np.ndarray, parts: tuple[str, ...]) -> np.ndarray:
        seg, rad = capsules_from_positions(poses, TALL.stature, parts)
        return wall.body_clearance(seg, rad)

    target = np.array([0.45, -0.136, 0.9])
    a = make_goal_primitive("grasp", target, TALL, rng=np.random.default_rng(0))
    b = make_goal_primitive("grasp", target, TALL, rng=np.random.default_rng(0),
                            obstacles=obstacles)
    assert a.meta["trunk_flexion"] == b.meta["trunk_flexion"]
    assert a.meta["pelvis_drop"] == b.meta["pelvis_drop"]


#: Pairs of the family that failed at 1.95 m at ebe5545 (planning:grasp:blocked); each
#: must verify at every stature.
REACH_PAIRS = [
    ("config/demo_cell.yaml", "F grasp(O1)"),                 # knees into the table
    ("scenarios/cells/seats.yaml", "F grasp(O1)"),            # knees into the side table
    ("scenarios/cells/shelf_heights.yaml", "F grasp(O_knee)"),  # head through the board above
    ("scenarios/cells/kitting.yaml", "F grasp(gear)"),
]


@pytest.mark.parametrize("stature", [1.55, 1.75, 1.95])
@pytest.mark.parametrize(("cell", "spec"), REACH_PAIRS)
def test_reach_family_verifies_at_every_stature(cell: str, spec: str, stature: float) -> None:
    from ltl_human_motion.scenarios.run import run_pair
    outcome = run_pair(spec, cell, stature, 0, timeout=30.0)
    assert outcome.status == "verified", outcome.message[:300]


def test_posture_clear_answers_without_the_fallback() -> None:
    """``posture_clear`` is the search's own test: a table front just clear of the
    stooping posture leaves one; a wall through the worker leaves none (where
    ``make_goal_primitive`` would go on without the obstacles)."""
    from ltl_human_motion.motion.goals import posture_clear
    target = np.array([0.5, -0.136, 0.84])
    for parts, expect in ((_table(0.28, 0.75), True),
                          (PartSet([Box.from_bounds(np.array([-0.3, -1.0, 0.0]),
                                                    np.array([1.0, 1.0, 2.5]))]), False)):
        def obstacles(poses: np.ndarray, names: tuple[str, ...], parts=parts) -> np.ndarray:
            seg, rad = capsules_from_positions(poses, TALL.stature, names)
            return parts.body_clearance(seg, rad)
        assert posture_clear("grasp", target, TALL, obstacles) is expect


#: Pairs that verify only from a spot the checked approaches find (a part on the low
#: board of an aisle rack, a part on the floor in front of a cart), each at the stature
#: it failed at (planning:grasp:blocked at ebe5545).
CHECKED_PAIRS = [
    ("scenarios/cells/aisle.yaml", "F grasp(O2)", 1.55),
    ("scenarios/cells/cluttered.yaml",
     "F (grasp(O2)) & F (grasp(O1)) & G((grasp(O2)) -> G !(grasp(O1)))", 1.55),
]


@pytest.mark.parametrize(("cell", "spec", "stature"), CHECKED_PAIRS)
def test_a_checked_approach_finds_a_clear_reach(cell: str, spec: str, stature: float) -> None:
    from ltl_human_motion.scenarios.run import run_pair
    outcome = run_pair(spec, cell, stature, 0, timeout=30.0)
    assert outcome.status == "verified", outcome.message[:300]
