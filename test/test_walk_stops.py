"""Where a walk to a reach may end (planning/walk_goals.py, steps.py, astar.py): the body
model decides whether the worker can turn on the spot and step into a stop, not a disc
on the walking map; and a placement needs two neighbouring open sides, not a sliver of
floor (planning/stand_distance.py). Real unseen-style cells, the real gait library, the
motions synthesized and verified as a user runs them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ltl_human_motion.planning import synthesize
from ltl_human_motion.planning.pipeline import get_library
from ltl_human_motion.planning.planner import SequencePlanner
from ltl_human_motion.planning.stand_distance import has_spot
from ltl_human_motion.scenarios.unseen import build_cell
from ltl_human_motion.scene.cell_yaml import cell_from_yaml
from ltl_human_motion.scene.predicates import collision


def _cell(family: str, index: int):
    built = build_cell(family, 0, index)
    return cell_from_yaml(built.yaml, source=built.name)


@pytest.fixture(scope="module")
def aisle():
    """Racks 0.83 m apart along x, shelf boards at 0.9, 1.4 and 2.4 m; P_l09 on the
    left rack's 0.9 m board."""
    return _cell("aisle", 1)


def test_the_body_turns_in_an_aisle_narrower_than_the_walking_maps_turn_room(aisle):
    planner = SequencePlanner(aisle, get_library(1.75), np.random.default_rng(0))
    ctx, executor = planner.ctx, planner.executor
    left = float(aisle.obstacle("rack_left").aabb()[0][1])
    middle = (left + float(aisle.obstacle("rack_right").aabb()[1][1])) / 2.0
    x, y = np.array([1.9, 1.9]), np.array([middle, left - 0.08])
    # the walking map, widened for the arms at the boards, has no room to turn there
    assert ctx.clearance(np.stack([x, y], axis=-1))[0] < ctx.turn_room
    # the body, turned from along the aisle to facing the rack, does: in its middle
    # only, not with the hips 8 cm from the boards
    ok = executor.turn_clear(x, y, np.zeros(2), np.full(2, math.pi / 2))
    assert ok.tolist() == [True, False]


@pytest.mark.slow
@pytest.mark.parametrize("stature", [1.55, 1.75])
def test_a_part_on_a_rack_is_grasped_from_the_aisle(aisle, stature):
    motion = synthesize("F grasp(P_l09)", aisle, stature=stature, seed=0)[0]
    assert not collision(motion.motion.positions, aisle, stature=stature).any()


@pytest.mark.slow
def test_a_tall_workers_insert_deep_in_a_chamber_stands_where_the_walk_can_stop():
    """A 1.95 m worker's vise 0.35 m inside a machine: the placement model's distance
    leaves a free spot on one side only, at the last step back; the placement moves
    back to where two neighbouring sides are open, and the walk there is short."""
    cell = _cell("chamber", 1)
    motion = synthesize("F insert(blank, vise_b)", cell, stature=1.95, seed=0)[0]
    assert not collision(motion.motion.positions, cell, stature=1.95).any()
    insert = next(g for g in motion.stats.goal_primitives if g["task"].startswith("insert"))
    assert insert["expanded"] < 2000


def test_one_open_side_is_not_a_place_to_stand():
    from ltl_human_motion.planning.plan_state import PlanContext, PlannerOptions
    cell = _cell("chamber", 1)
    ctx = PlanContext.build(cell, get_library(1.95), np.random.default_rng(0),
                            PlannerOptions())
    vise = np.array([0.581, -2.35, 1.04])
    assert not has_spot(ctx, vise, (0.234, -0.1365), open_line=True)
    assert has_spot(ctx, vise, (0.234 + 0.16, -0.1365), open_line=True)


def test_a_worker_wedged_between_a_conveyor_and_a_pallet_steps_away_before_turning():
    """A 1.55 m worker takes a part off a conveyor next to a floor pallet (generator seed
    1) and faces the belt 0.24 m from it: every turn on the spot swings a thigh 1-1.5 cm
    into the conveyor on a frame the search does not sample. Before, each repair forbade
    one turn and the next search took another, until the walk was refused after 19 s of
    CPU; now the turns are forbidden together and the worker first steps away from the
    belt, and the move is verified."""
    built = build_cell("conveyor", 1, 0)
    cell = cell_from_yaml(built.yaml, source=built.name)
    motion = synthesize("F move(P_c1, R_tab)", cell, stature=1.55, seed=0)[0]
    assert not collision(motion.motion.positions, cell, stature=1.55).any()
    names = [s[0] for s in motion.stats.segments]
    grasped = next(i for i, n in enumerate(names) if n.startswith("grasp_"))
    assert any(n.startswith("carry_step_") for n in names[grasped + 1:grasped + 4])


def test_a_worker_facing_a_rack_with_a_part_in_hand_steps_away_before_walking_out(aisle):
    """A 1.55 m worker takes P_l09 off the left rack's 0.9 m board and stands facing
    the rack 0.28 m from it, the part in front of him: no search gets away from there
    (the squeeze search gave up after 1,001 nodes and the carry was refused). He first
    steps back towards the aisle's middle, then walks out."""
    motion = synthesize("F carry(P_l09, Zone)", aisle, stature=1.55, seed=0)[0]
    assert not collision(motion.motion.positions, aisle, stature=1.55).any()
    names = [s[0] for s in motion.stats.segments]
    grasped = next(i for i, n in enumerate(names) if n.startswith("grasp_"))
    assert any(n.startswith("carry_step_") for n in names[grasped + 1:grasped + 4])
