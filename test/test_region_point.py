"""Where a part goes in a region whose middle no one reaches (planning/region_point.py),
and the lift of both hands (motion/lift.py): pure geometry on a real unseen-style cell
and the real skeleton."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.lift import lift_poses, lifted_stance
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.planning.pipeline import get_library
from ltl_human_motion.planning.plan_state import PlanContext, PlannerOptions
from ltl_human_motion.planning.region_point import region_point, spot_distance
from ltl_human_motion.scenarios.unseen import build_cell
from ltl_human_motion.scene.cell_yaml import cell_from_yaml


@pytest.fixture(scope="module")
def chamber_ctx() -> PlanContext:
    built = build_cell("chamber", 0, 1)
    cell = cell_from_yaml(built.yaml, source=built.name)
    return PlanContext.build(cell, get_library(1.55), np.random.default_rng(0),
                             PlannerOptions())


def test_a_bay_point_is_reached_through_the_door_not_the_side_wall(chamber_ctx):
    ctx = chamber_ctx
    bay = ctx.cell.region("R_bay")
    lo, hi = np.asarray(bay.lo), np.asarray(bay.hi)
    centre = (lo + hi) / 2.0
    point = region_point(ctx, bay, 0.09, 1.4, reach=0.6)
    assert point is not None
    assert np.all(point[:2] >= lo[:2] + 0.09 - 1e-9) and np.all(point[:2] <= hi[:2] - 0.09 + 1e-9)
    # nearer the door (the machine's front faces +y) than the middle, at the height asked
    assert point[1] > centre[1] and point[2] == pytest.approx(1.4)
    near = spot_distance(ctx, point[None])[0]
    assert near < spot_distance(ctx, centre[None] * [1, 1, 0] + [0, 0, 1.4])[0]
    # the machine's inside right behind its side wall is not reached through the wall
    inside_wall = np.array([lo[0] + 0.05, centre[1], 1.4])
    assert spot_distance(ctx, inside_wall[None])[0] > near


def test_a_region_within_reach_keeps_its_centre(chamber_ctx):
    ctx = chamber_ctx
    assert region_point(ctx, ctx.cell.region("R_tab"), 0.09, 0.9, reach=0.6) is None


def test_lifted_stance_raises_both_hands_and_keeps_the_arm_lengths():
    stance = np.asarray(get_library(1.75).carry_standing_pose)
    up = lifted_stance(stance, 0.2)
    for s in "lr":
        sh, el, wr, ha = (JOINT_INDEX[f"{s}_{j}"] for j in ("shoulder", "elbow", "wrist", "hand"))
        assert up[wr, 2] - stance[wr, 2] == pytest.approx(0.2, abs=1e-6)
        np.testing.assert_allclose(up[ha] - up[wr], stance[ha] - stance[wr])
        for a, b in ((sh, el), (el, wr)):
            assert np.linalg.norm(up[b] - up[a]) == pytest.approx(
                np.linalg.norm(stance[b] - stance[a]), abs=1e-9)
    poses = lift_poses(stance, 0.2, get_library(1.75).skeleton, 120.0)
    np.testing.assert_allclose(poses[0], stance, atol=1e-12)
    np.testing.assert_allclose(poses[-1], up, atol=1e-12)
    hand = poses[:, JOINT_INDEX["r_hand"], 2]
    assert np.all(np.diff(hand) >= -1e-12)
