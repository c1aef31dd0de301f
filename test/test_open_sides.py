"""Which side of a target the worker reaches it from (planning/open_sides.py) and how far
back they stand where the placement model's distance is inside furniture
(planning/stand_distance.py): the geometry on real unseen-style cells and the real
posture model, then the motions synthesized and verified as a user runs them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ltl_human_motion.planning import synthesize
from ltl_human_motion.planning.open_sides import SideReach, open_arc, side_blocked
from ltl_human_motion.planning.pipeline import get_library
from ltl_human_motion.planning.plan_state import PlanContext, PlannerOptions
from ltl_human_motion.planning.stand_distance import farther_placement, has_spot
from ltl_human_motion.scenarios.unseen import build_cell
from ltl_human_motion.scene.cell_yaml import cell_from_yaml
from ltl_human_motion.scene.predicates import collision


def _cell(family: str, seed: int, index: int):
    built = build_cell(family, seed, index)
    return cell_from_yaml(built.yaml, source=built.name)


def _ctx(cell, stature: float) -> PlanContext:
    return PlanContext.build(cell, get_library(stature), np.random.default_rng(0),
                             PlannerOptions())


@pytest.fixture(scope="module")
def aisle():
    """Two racks with a 0.9 m aisle between them along y; P_l14 on the left rack's
    1.4 m board, 0.14 m behind its aisle-side edge; the rack's back wall behind it."""
    return _cell("aisle", 0, 0)


def _rack_x(cell, name: str) -> tuple[float, float]:
    lo, hi = next(o for o in cell.obstacles if o.name == name).aabb()
    return float(lo[0]), float(hi[0])


def test_the_back_of_a_rack_closes_that_side_and_the_aisle_is_open(aisle):
    ctx = _ctx(aisle, 1.75)
    target = np.asarray(aisle.objects["P_l14"].position) + np.array([0.0, 0.0, 0.043])
    left = _rack_x(aisle, "rack_left")
    behind = (left[0] - 0.35, float(target[1]), 0.0)
    in_aisle = (left[1] + 0.45, float(target[1]), math.pi)
    assert side_blocked(ctx, target, behind)
    assert not side_blocked(ctx, target, in_aisle)
    stance = np.asarray(ctx.library.carry_standing_pose)
    arc = open_arc(ctx, SideReach("grasp", target, (0.58, -0.12), None, stance),
                   toward=math.pi)
    assert arc is not None
    # the arc found from behind the rack faces the aisle (+x), not the back wall
    assert abs(arc.centre) < arc.half_width + 0.4


def test_a_shelf_part_is_grasped_from_the_aisle_not_behind_the_rack(aisle):
    """The shortest walk ends behind the rack, where every motion met the back wall
    (before: refused, 'the right hand enters rack_left by 4.5 cm')."""
    motion = synthesize("F grasp(P_l14)", aisle, stature=1.75, seed=0)[0]
    positions = motion.motion.positions
    assert not collision(positions, aisle, stature=1.75).any()
    track = np.asarray(motion.objects["P_l14"])
    lifted = int(np.argmax(np.isfinite(track).all(axis=1)))
    left, right = _rack_x(aisle, "rack_left"), _rack_x(aisle, "rack_right")
    assert left[1] < positions[lifted, 0, 0] < right[0]


def test_a_tall_worker_stands_back_from_a_machine_chamber():
    """A 1.95 m worker's placement for a vise at hip height is 0.23 m, inside the machine
    on every side whose line to the vise is open: the placement moves back to where the
    front has room and the goal model still reaches."""
    cell = _cell("chamber", 1, 0)
    ctx = _ctx(cell, 1.95)
    target = np.asarray(cell.objects["done"].position) + np.array([0.0, 0.0, 0.007])
    placement = (0.234, -0.136)
    assert not has_spot(ctx, target, placement, open_line=True)
    farther = farther_placement(ctx, target, placement, lambda local: True)
    assert farther is not None and farther[0] > placement[0]
    assert farther[1] == placement[1] and has_spot(ctx, target, farther, open_line=True)
    assert farther_placement(ctx, target, placement, lambda local: False) is None


def test_a_chamber_vise_is_reached_through_the_door_not_the_side_wall():
    """The roof of the machine over the vise squared the first walk to its nearest edge,
    the side wall (before: refused, 'the right upper arm enters cnc by 4.4 cm')."""
    cell = _cell("chamber", 1, 0)
    motion = synthesize("F extract(done, vise_a)", cell, stature=1.55, seed=0)[0]
    assert not collision(motion.motion.positions, cell, stature=1.55).any()
