"""Goal primitives keep within the verifier's joint speed limits by construction
(motion/goals/primitive.py ``within_speed_limits``): a primitive whose timing model moves a
joint too fast is slowed down, the task's frames moved with it; the others are left as
they are. A generated cell where that refused a floor grasp, synthesized and verified."""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.biomechanics import BiomechanicsLimits, _speeds_and_limits
from ltl_human_motion.motion.goals import make_goal_primitive, reach_placement
from ltl_human_motion.motion.goals.primitive import GOAL_SPEED_ROOM, within_speed_limits
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import MotionPrimitive, world_positions

STATURE = 1.55


def _ratio(mp: MotionPrimitive) -> float:
    limits = BiomechanicsLimits()
    speed, limit = _speeds_and_limits(world_positions(mp), mp.fps, [mp.task] * mp.n_frames,
                                      limits, STATURE / limits.reference_stature)
    return float(np.max(speed / limit))


def _grasp() -> MotionPrimitive:
    skeleton = Skeleton(STATURE)
    d, lat = reach_placement("grasp", 0.3, skeleton)
    return make_goal_primitive("grasp", np.array([d, lat, 0.3]), skeleton,
                               rng=np.random.default_rng(0), hand="r_hand")


def test_a_primitive_within_the_limits_is_unchanged():
    mp = _grasp()
    assert _ratio(mp) <= 1.0
    assert within_speed_limits(mp, STATURE) is mp


def test_a_too_fast_primitive_is_slowed_to_the_room_below_its_limits():
    """The same grasp played faster (every k-th frame, its fastest joint about 20 % over
    its limit); slowed, it is at GOAL_SPEED_ROOM of it, and the palm is where it was at
    the contact frame, which moved with the motion."""
    mp = _grasp()
    k = int(np.ceil(1.2 / _ratio(mp)))
    half = MotionPrimitive(name=mp.name, task=mp.task, poses=mp.poses[::k], root=mp.root[::k],
                           fps=mp.fps, source=mp.source,
                           meta=dict(mp.meta, contact_frame=mp.meta["contact_frame"] // k,
                                     hold_frames=[f // k for f in mp.meta["hold_frames"]]))
    assert _ratio(half) > 1.0
    slowed = within_speed_limits(half, STATURE)
    assert abs(_ratio(slowed) - GOAL_SPEED_ROOM) < 0.02
    hand = JOINT_INDEX["r_hand"]
    before = world_positions(half)[half.meta["contact_frame"], hand]
    after = world_positions(slowed)[slowed.meta["contact_frame"], hand]
    assert np.linalg.norm(after - before) < 0.01
    assert slowed.n_frames > half.n_frames


def test_a_short_workers_floor_grasp_in_a_generated_cell_verifies():
    """Generated cell 2 (seed 0): a 1.55 m worker's grasp of a part near the floor took the
    knee to 2.23 m/s against its 2.21 m/s limit and was refused by verification."""
    from ltl_human_motion.planning import synthesize
    from ltl_human_motion.scenarios.generator import generate_scenarios
    from ltl_human_motion.scene.cell_yaml import cell_from_yaml
    scen = generate_scenarios(3, seed=0)[2]
    cell = cell_from_yaml(scen.yaml, source=scen.name)
    motion = synthesize("F grasp(P2)", cell, stature=scen.stature, seed=0)[0]
    assert motion.verification["passed"]
