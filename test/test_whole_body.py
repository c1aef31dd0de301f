"""The whole-body program: constraints hold on every frame the verifier checks."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.goals import make_goal_primitive, reach_placement
from ltl_human_motion.motion.goals.kinematics import body_kinematics
from ltl_human_motion.motion.goals.optimizer import track_reference
from ltl_human_motion.motion.skeleton import JOINT_INDEX, PARENTS, Skeleton
from ltl_human_motion.motion.types import world_positions
from ltl_human_motion.planning.constrained_goals import (
    CONTACT_TOLERANCE,
    END_TOLERANCE,
    PartSetField,
    constrained_primitive,
)
from ltl_human_motion.scene.clearance import PartSet
from ltl_human_motion.scene.occupancy import capsules_from_positions
from ltl_human_motion.scene.shapes import Box

STATURE = 1.55
_FEET = [JOINT_INDEX[j] for j in ("l_ankle", "l_toe", "r_ankle", "r_toe")]


@pytest.fixture(scope="module")
def reach():
    """A 1.55 m worker's right-hand grasp of a part at 1.45 m (start frame)."""
    skeleton = Skeleton(STATURE)
    d, lat = reach_placement("grasp", 1.45, skeleton)
    mp = make_goal_primitive("grasp", np.array([d, lat, 1.45]), skeleton,
                             rng=np.random.default_rng(0), hand="r_hand")
    return mp, world_positions(mp)


def _clearance(positions: np.ndarray, parts: PartSet) -> np.ndarray:
    """Least clearance of every frame's body capsules (T, J, 3) to ``parts``, exact."""
    seg, rad = capsules_from_positions(positions, STATURE)
    return parts.body_clearance(seg, rad, exact_below=np.inf)


def _bone_lengths(positions: np.ndarray) -> np.ndarray:
    child = np.arange(1, positions.shape[1])
    return np.linalg.norm(positions[:, child] - positions[:, np.array(PARENTS[1:])], axis=-1)


def test_configurations_reproduce_the_motion(reach):
    _, ref = reach
    kin = body_kinematics(STATURE)
    q = kin.configurations(ref[::20])
    back = np.array([kin.positions(x) for x in q])
    assert np.abs(back - ref[::20]).max() < 1e-6


def test_motion_far_from_obstacles_is_the_reference(reach):
    _, ref = reach
    far = PartSet([Box.from_bounds(np.array([3.0, 3.0, 0.0]), np.array([3.5, 3.5, 1.0]))])
    result = track_reference(ref, STATURE, PartSetField(far, (0.0, 0.0, 0.0)),
                             tracked=("r_hand",), fps=120.0)
    assert not result.constrained
    assert np.array_equal(result.positions, ref)


def test_upper_arm_under_a_board_keeps_clear_and_reaches(reach):
    """A board 5.5 cm above the elbow at contact: the reference's upper arm enters it by
    about 4 cm; the program keeps every capsule clear on every frame, reaches the
    target, keeps the feet planted and the bones their length."""
    mp, ref = reach
    contact = int(mp.meta["contact_frame"])
    elbow = ref[contact, JOINT_INDEX["r_elbow"]]
    board = PartSet([Box.from_bounds(np.array([elbow[0] - 0.1, -0.6, elbow[2] + 0.055]),
                                     np.array([elbow[0] + 0.1, 0.0, elbow[2] + 0.09]))])
    assert _clearance(ref, board).min() < -0.02
    made, miss, result = constrained_primitive(mp, board, (0.0, 0.0, 0.0), STATURE)
    assert made is not None, (miss, result.end_miss, result.least_clearance)
    out = world_positions(made)
    assert _clearance(out, board).min() >= 0.0
    hand = JOINT_INDEX["r_hand"]
    assert np.linalg.norm(out[contact, hand] - ref[contact, hand]) <= CONTACT_TOLERANCE
    assert np.abs(out[:, _FEET] - ref[:, _FEET]).max() < 1e-3
    assert np.abs(_bone_lengths(out) - _bone_lengths(ref)).max() < END_TOLERANCE
    speed = np.linalg.norm(np.diff(out, axis=0), axis=-1).max() * made.fps
    assert speed < 2.5


def test_world_pose_is_the_start_frame_turned(reach):
    """The same board seen from a worker standing at (2, 1) turned by 90 degrees."""
    mp, ref = reach
    contact = int(mp.meta["contact_frame"])
    elbow = ref[contact, JOINT_INDEX["r_elbow"]]
    lo = np.array([elbow[0] - 0.1, -0.6, elbow[2] + 0.055])
    hi = np.array([elbow[0] + 0.1, 0.0, elbow[2] + 0.09])
    # start-frame (x, y) -> world (2 - y, 1 + x)
    world = Box.from_bounds(np.array([2.0 - hi[1], 1.0 + lo[0], lo[2]]),
                            np.array([2.0 - lo[1], 1.0 + hi[0], hi[2]]))
    made, _, _ = constrained_primitive(mp, PartSet([world]), (2.0, 1.0, np.pi / 2),
                                       STATURE)
    assert made is not None
    placed = world_positions(made, 2.0, 1.0, np.pi / 2)
    assert _clearance(placed, PartSet([world])).min() >= 0.0


def test_a_hand_path_through_a_board_is_never_returned_colliding(reach):
    """A board between the palm and its target: the program either keeps the body clear
    and still reaches (it does not here) or the motion is refused; a colliding motion
    is never returned."""
    mp, ref = reach
    contact = int(mp.meta["contact_frame"])
    hand = ref[contact, JOINT_INDEX["r_hand"]]
    board = PartSet([Box.from_bounds(np.array([hand[0] - 0.15, -0.6, hand[2] - 0.10]),
                                     np.array([hand[0] + 0.3, 0.4, hand[2] - 0.07]))])
    made, miss, result = constrained_primitive(mp, board, (0.0, 0.0, 0.0), STATURE)
    if made is None:
        assert miss > CONTACT_TOLERANCE or result.least_clearance < 0 \
            or result.end_miss > END_TOLERANCE
    else:
        assert _clearance(world_positions(made), board).min() >= 0.0


def test_a_palm_held_off_its_target_gives_up_at_the_first_frame_it_misses(reach):
    """A wall between the palm and the part: the program cannot reach it. Told to give up
    where the palm misses the contact frame, it stops there (the frames after are the
    reference's) with the same miss at that frame as the full run; a tolerance it meets
    changes nothing."""
    mp, ref = reach
    contact = int(mp.meta["contact_frame"])
    hand = JOINT_INDEX["r_hand"]
    palm = ref[contact, hand]
    wall = PartSet([Box.from_bounds(np.array([palm[0] - 0.15, -0.8, 0.0]),
                                    np.array([palm[0] - 0.1, 0.4, 2.0]))])
    field_ = PartSetField(wall, (0.0, 0.0, 0.0))
    full = track_reference(ref, STATURE, field_, tracked=("r_hand",), fps=mp.fps)
    missed = float(np.linalg.norm(full.positions[contact, hand] - palm))
    assert missed > CONTACT_TOLERANCE
    early = track_reference(ref, STATURE, field_, tracked=("r_hand",), fps=mp.fps,
                            give_up=((contact,), CONTACT_TOLERANCE))
    assert np.array_equal(early.positions[:contact + 1], full.positions[:contact + 1])
    solved = int(np.flatnonzero(np.any(early.positions != ref, axis=(1, 2))).max())
    assert solved < len(ref) - 1 and np.array_equal(early.positions[solved + 1:],
                                                    ref[solved + 1:])
    kept = track_reference(ref, STATURE, field_, tracked=("r_hand",), fps=mp.fps,
                           give_up=((contact,), 10.0))
    assert np.array_equal(kept.positions, full.positions)


def test_balance_rows_are_the_centre_of_mass_distance_to_the_support_edges(reach):
    """The balance rows are the first-order change of the centre of mass's distance
    inside each edge of the feet's support polygon (the verifier's outline): the
    standing pose is inside every edge, and a small step of the configuration changes
    each distance by ``-G dq`` to within second order."""
    from ltl_human_motion.motion.goals.constraints import balance_rows, support_edges
    from ltl_human_motion.motion.ik import center_of_mass
    _, ref = reach
    kin = body_kinematics(STATURE)
    q = kin.configurations(ref[:1])[0]
    pos = kin.positions(q)
    edges = support_edges(pos, STATURE)
    inside = -(edges[:, :2] @ center_of_mass(pos)[:2] + edges[:, 2])
    assert inside.min() > 0.0
    G, h = balance_rows(kin, pos, edges, influence=1.0, damper=0.3)
    assert np.allclose(h, 0.3 * inside)
    import pinocchio as pin
    dq = np.random.default_rng(0).normal(0.0, 1e-3, kin.model.nv)
    moved = kin.positions(pin.integrate(kin.model, q, dq))
    after = -(edges[:, :2] @ center_of_mass(moved)[:2] + edges[:, 2])
    assert np.allclose(inside - after, G @ dq, atol=1e-5)


def test_range_rows_are_the_anatomical_angles_first_order_change(reach):
    """A range-of-motion row is the first-order change of the verifier's anatomical
    angle (degrees) it bounds: at the reach's contact pose, with every range narrowed
    to within a degree of the angles there, each row's ``G dq`` is the angle's change
    (lower limits: its decrease) over a small step, to within second order."""
    import pinocchio as pin

    from ltl_human_motion.motion.biomechanics import joint_angles
    from ltl_human_motion.motion.goals.constraints import rom_rows
    mp, ref = reach
    kin = body_kinematics(STATURE)
    q = kin.configurations(ref[int(mp.meta["contact_frame"])][None])[0]
    pos = kin.positions(q)
    before = {k: float(v[0]) for k, v in joint_angles(pos[None]).items()}
    ranges = {"knee_flexion": (before["r_knee_flexion"] - 1.0, 150.0),
              "elbow_flexion": (0.0, before["r_elbow_flexion"] + 1.0)}
    others = {k[2:] if k[:2] in ("l_", "r_") else k for k in before} - set(ranges)
    ranges.update({k: (-1e3, 1e3) for k in others})
    G, h = rom_rows(kin, pos, ranges, influence=2.0, margin=0.0, damper=1.0)
    dq = np.random.default_rng(1).normal(0.0, 1e-4, kin.model.nv)
    after = {k: float(v[0]) for k, v in joint_angles(
        kin.positions(pin.integrate(kin.model, q, dq))[None]).items()}
    change = {k: after[k] - before[k] for k in before}
    # rows in order: r/l knee lower limits, r/l elbow upper limits, as near as each is
    expected = [-change[n] for n in ("l_knee_flexion", "r_knee_flexion")
                if before[n] - ranges["knee_flexion"][0] < 2.0] + [
        change[n] for n in ("l_elbow_flexion", "r_elbow_flexion")
        if ranges["elbow_flexion"][1] - before[n] < 2.0]
    assert len(expected) == len(h) >= 2
    assert np.allclose(sorted(G @ dq), sorted(expected), atol=2e-3)


def test_the_support_polygons_hull_is_qhulls():
    """The hand-written hull of the feet's eight corners has Qhull's edges (scipy's
    ``ConvexHull`` equations), in any order, on random point sets."""
    from scipy.spatial import ConvexHull

    from ltl_human_motion.motion.goals.constraints import _convex_hull
    rng = np.random.default_rng(0)
    for _ in range(100):
        points = rng.normal(size=(8, 2))
        hull = _convex_hull(points)
        d = np.roll(hull, -1, axis=0) - hull
        n = np.stack([d[:, 1], -d[:, 0]], axis=1)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        ours = np.column_stack([n, -np.einsum("ij,ij->i", n, hull)])
        theirs = ConvexHull(points).equations
        assert len(ours) == len(theirs)
        assert all(np.abs(ours - e).sum(axis=1).min() < 1e-9 for e in theirs)
