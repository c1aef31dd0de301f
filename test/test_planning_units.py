"""Unit tests of the planning building blocks: blending, navigation field, A*, turns."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import MotionPrimitive
from ltl_human_motion.planning.astar import (
    Goal,
    SearchBudget,
    SearchFailure,
    SearchOptions,
    SearchResult,
    astar,
)
from ltl_human_motion.planning.blend import PlacedSegment, blend_weights, concatenate
from ltl_human_motion.planning.gait_index import GaitIndex
from ltl_human_motion.planning.navigation import NavigationField
from ltl_human_motion.planning.turns import make_step_primitive, make_turn_primitive


def test_blend_weights_are_cubic_c1_from_one_to_zero() -> None:
    w = blend_weights(9)
    assert w.shape == (9,)
    assert np.all(np.diff(w) < 0)
    assert 0.0 < w[-1] < w[0] < 1.0
    s = np.array([0.0, 1.0])
    # The polynomial itself: w(0) = 1, w(1) = 0 and zero slope at both ends.
    poly = 1 - 3 * s**2 + 2 * s**3
    slope = -6 * s + 6 * s**2
    np.testing.assert_allclose(poly, [1.0, 0.0])
    np.testing.assert_allclose(slope, [0.0, 0.0])
    # Symmetry w(s) + w(1 - s) = 1.
    np.testing.assert_allclose(w + w[::-1], 1.0)
    with pytest.raises(ValueError, match="nf must be >= 0"):
        blend_weights(-1)


def test_concatenate_overlaps_and_blends_positions_and_heading() -> None:
    rng = np.random.default_rng(3)
    a = PlacedSegment(rng.normal(size=(20, 4, 3)), np.linspace(3.0, 3.1, 20), label=0)
    b = PlacedSegment(rng.normal(size=(15, 4, 3)), np.linspace(-3.1, -3.0, 15) , label=1,
                      blend_in=5)
    pos, yaw, labels, spans = concatenate([a, b])
    assert pos.shape == (30, 4, 3) and yaw.shape == (30,) and labels.shape == (30,)
    assert spans == [(0, 20), (15, 30)]
    np.testing.assert_array_equal(pos[:15], a.positions[:15])
    np.testing.assert_array_equal(pos[20:], b.positions[5:])
    w = blend_weights(5)[:, None, None]
    np.testing.assert_allclose(pos[15:20], w * a.positions[15:] + (1 - w) * b.positions[:5])
    # Heading crosses +-pi without a jump of 2 pi.
    assert np.max(np.abs(np.diff(yaw))) < 0.1
    assert labels[0] == 0 and labels[-1] == 1


def test_a_foot_mismatch_at_a_junction_is_spread_to_the_speed_it_may_add() -> None:
    """Offset blending spreads a swing foot's 10 cm jump over up to 0.5 s, so it adds at
    most JUNCTION_ADDED_SPEED; every other joint keeps the JUNCTION_SPREAD window."""
    from ltl_human_motion.planning.blend import JUNCTION_ADDED_SPEED, JUNCTION_SPREAD
    fps, J = 120.0, len(JOINT_INDEX)
    a = PlacedSegment(np.zeros((200, J, 3)), np.zeros(200))
    jump = np.zeros((200, J, 3))
    jump[:, JOINT_INDEX["l_ankle"], 0] = 0.10
    jump[:, JOINT_INDEX["l_hand"], 0] = 0.10
    b = PlacedSegment(jump, np.zeros(200), blend_in=5)
    spread = round(JUNCTION_SPREAD * fps)
    pos = concatenate([a, b], spread=spread, fps=fps)[0]
    speed = np.abs(np.diff(pos[:, :, 0], axis=0)) * fps
    assert speed[:, JOINT_INDEX["l_ankle"]].max() <= JUNCTION_ADDED_SPEED * 1.01
    moving = np.flatnonzero(speed[:, JOINT_INDEX["l_ankle"]] > 1e-9)
    assert moving[-1] - moving[0] > 2 * spread
    hand = np.flatnonzero(speed[:, JOINT_INDEX["l_hand"]] > 1e-9)
    assert hand[-1] - hand[0] <= 2 * spread
    np.testing.assert_array_equal(concatenate([a, b], spread=spread)[0][:, JOINT_INDEX["l_hand"]],
                                  pos[:, JOINT_INDEX["l_hand"]])


def test_a_junction_share_puts_the_whole_mismatch_on_one_side() -> None:
    """A junction whose share is 0 leaves the outgoing motion as it was and ramps the
    whole mismatch out over twice the window after it (the same added speed as the
    halves of the default); share 1 the other way round; a stretch of 2 halves the
    added speed."""
    from ltl_human_motion.planning.blend import junction_frames
    fps, J, spread = 120.0, len(JOINT_INDEX), 24
    a = PlacedSegment(np.zeros((200, J, 3)), np.zeros(200))
    jump = np.zeros((200, J, 3))
    jump[:, JOINT_INDEX["l_hand"], 0] = 0.10
    b = PlacedSegment(jump, np.zeros(200), blend_in=6)
    hand = JOINT_INDEX["l_hand"]
    pos, _, _, spans = concatenate([a, b], spread=spread, fps=fps)
    c = junction_frames(spans)[0]
    assert c == 197
    half = np.abs(np.diff(pos[:, hand, 0])).max() * fps
    for share, kept, moved in ((0.0, slice(0, c), slice(c, None)),
                               (1.0, slice(c, None), slice(0, c))):
        one = concatenate([a, b], spread=spread, fps=fps, shares={0: share})[0]
        ref = np.concatenate([a.positions[:c], b.positions[c - 194:]])
        np.testing.assert_array_equal(one[kept, hand], ref[kept, hand])
        assert np.abs(one[moved, hand] - ref[moved, hand]).max() > 0.09
        assert np.abs(np.diff(one[:, hand, 0])).max() * fps <= half * 1.01
    long = concatenate([a, b], spread=spread, fps=fps, stretch={0: 2.0})[0]
    assert np.abs(np.diff(long[:, hand, 0])).max() * fps <= 0.51 * half


def test_junctions_near_colliding_frames_move_their_mismatch_off_that_side() -> None:
    from ltl_human_motion.planning.junction_repair import shares_off
    hits = np.zeros(400, bool)
    hits[95:99] = True                    # before the junction at 100
    hits[305:307] = True                  # after the one at 300
    assert shares_off(hits, [100, 120, 300], {}, 120.0, wide=False) == {0: 0.0, 2: 1.0}
    wide = shares_off(hits, [100, 120, 300], {}, 120.0, wide=True)
    assert wide == {0: 0.0, 1: 0.0, 2: 1.0}
    assert shares_off(hits, [100, 120, 300], wide, 120.0, wide=True) is None
    assert shares_off(np.zeros(400, bool), [100], {}, 120.0, wide=False) is None


def _wall_free(xy: np.ndarray) -> np.ndarray:
    """Free floor: everything except a wall x in [0.9, 1.1], y in [-1, 3]."""
    inside = (np.abs(xy[:, 0] - 1.0) <= 0.1) & (xy[:, 1] >= -1.0) & (xy[:, 1] <= 3.0)
    return ~inside


def test_navigation_field_measures_the_way_around_a_wall() -> None:
    goal = (2.0, 1.0)
    field = NavigationField(np.array([-3.0, -3.0]), np.array([3.0, 3.0]), _wall_free,
                            lambda xy: np.hypot(xy[:, 0] - goal[0], xy[:, 1] - goal[1]) < 0.2)
    d = float(field.distance(np.array([0.0]), np.array([1.0]))[0])
    straight = 2.0
    # Around the wall's end at y = -1: down 2 m, across, and up again.
    assert d > straight + 2.5
    assert field.reachable_from(0.0, 1.0)
    # In front of the wall the way leads away from the straight line (towards -y).
    heading = float(field.heading(np.array([0.6]), np.array([1.0]))[0])
    assert np.sin(heading) < 0


def test_navigation_field_knows_an_enclosed_goal_is_unreachable() -> None:
    def free(xy: np.ndarray) -> np.ndarray:
        ring = np.abs(np.hypot(xy[:, 0] - 2.0, xy[:, 1]) - 0.6) < 0.15
        return ~ring

    field = NavigationField(np.array([-3.0, -3.0]), np.array([3.0, 3.0]), free,
                            lambda xy: np.hypot(xy[:, 0] - 2.0, xy[:, 1]) < 0.2)
    assert field.has_goal
    assert not field.reachable_from(0.0, 0.0)


def _straight_and_turning_gait() -> GaitIndex:
    """A toy gait: 0.3 m forward, or forward while turning +-30 degrees (10 frames, 60 Hz)."""
    prims = []
    for k, turn in enumerate((0.0, np.radians(30), -np.radians(30))):
        t = np.linspace(0, 1, 11)
        yaw = turn * t
        root = np.stack([0.3 * t * np.cos(yaw / 2), 0.3 * t * np.sin(yaw / 2),
                         np.full(11, 0.9), yaw], axis=-1)
        prims.append(MotionPrimitive(f"p{k}", "walk", np.zeros((11, 23, 3)), root, 60.0))
    succ = [[0, 1, 2]] * 3
    return GaitIndex.build(prims, succ, nf=0)


def _point_goal(x: float, y: float, radius: float = 0.2) -> Goal:
    return Goal(lambda px, py, yaw: np.hypot(px - x, py - y) <= radius,
                lambda px, py: np.maximum(np.hypot(px - x, py - y) - radius, 0.0),
                lambda px, py: np.arctan2(y - py, x - px), "point")


def test_astar_reaches_a_goal_behind_the_start_with_a_chain_of_primitives() -> None:
    index = _straight_and_turning_gait()
    res = astar(index, (0.0, 0.0, 0.0), _point_goal(-1.5, 0.5),
                clearance=lambda xy: np.full(len(xy), np.inf),
                options=SearchOptions(heuristic_speed=0.5, cost_noise=0.0))
    assert isinstance(res, SearchResult)
    assert len(res.primitives) == len(res.poses) > 3
    assert np.hypot(res.end_pose[0] + 1.5, res.end_pose[1] - 0.5) <= 0.2
    # Replaying the chain from the poses gives the reported end pose.
    x, y, yaw = res.poses[-1]
    d = index.disp[res.primitives[-1]]
    end = (x + np.cos(yaw) * d[0] - np.sin(yaw) * d[1], y + np.sin(yaw) * d[0] + np.cos(yaw) * d[1])
    np.testing.assert_allclose(end, res.end_pose[:2], atol=1e-9)


def test_astar_reports_blocked_and_budget_failures() -> None:
    index = _straight_and_turning_gait()
    walls = astar(index, (0.0, 0.0, 0.0), _point_goal(3.0, 0.0),
                  clearance=lambda xy: np.where(np.hypot(xy[:, 0], xy[:, 1]) > 0.8, -1.0, 1.0),
                  options=SearchOptions(body_radius=0.1))
    assert isinstance(walls, SearchFailure) and walls.reason == "blocked"
    tiny = astar(index, (0.0, 0.0, 0.0), _point_goal(30.0, 0.0),
                 clearance=lambda xy: np.full(len(xy), np.inf),
                 budget=SearchBudget(max_nodes=5, max_seconds=10.0))
    assert isinstance(tiny, SearchFailure) and tiny.reason == "budget"


def test_astar_ends_early_at_a_goal_with_no_place_to_stop() -> None:
    # The heuristic's distance is 0 around (1, 0), but no pose there passes the goal
    # test (the 1.95 m worker's 5 cm final adjustment at a table): the search says so
    # after ``at_goal_nodes``, not after its whole budget.
    index = _straight_and_turning_gait()
    near = _point_goal(1.0, 0.0, radius=0.5)
    hopeless = Goal(lambda px, py, yaw: np.zeros(np.shape(px), dtype=bool), near.distance,
                    near.heading, "no stop")
    res = astar(index, (0.0, 0.0, 0.0), hopeless,
                clearance=lambda xy: np.full(len(xy), np.inf),
                budget=SearchBudget(max_nodes=5000, at_goal_nodes=100))
    assert isinstance(res, SearchFailure) and res.reason == "no_stop"
    assert res.closest == 0.0 and res.expanded < 500


@pytest.mark.parametrize("angle", [np.pi / 2, -np.pi, np.radians(45)])
def test_turn_primitive_turns_on_the_spot_with_feet_on_the_floor(angle: float) -> None:
    sk = Skeleton()
    rest = sk.rest_positions()
    stand = rest - rest[0]
    mp = make_turn_primitive(stand, float(rest[0, 2]), angle, sk, 120.0)
    assert mp.root[-1, 3] == pytest.approx(angle)
    np.testing.assert_allclose(mp.root[:, :2], 0.0)
    np.testing.assert_allclose(mp.poses[0], stand, atol=1e-6)
    np.testing.assert_allclose(mp.poses[-1], stand, atol=1e-6)
    feet = mp.poses[:, [JOINT_INDEX[j] for j in ("l_ankle", "r_ankle")], 2] + mp.root[:, None, 2]
    assert feet.min() >= rest[JOINT_INDEX["l_ankle"], 2] - 1e-6
    lengths = np.linalg.norm(mp.poses[:, JOINT_INDEX["l_knee"]] - mp.poses[:, JOINT_INDEX["l_hip"]],
                             axis=-1)
    np.testing.assert_allclose(lengths, lengths[0], atol=1e-6)


def test_step_back_moves_the_root_back() -> None:
    sk = Skeleton(1.6)
    rest = sk.rest_positions()
    mp = make_step_primitive(rest - rest[0], float(rest[0, 2]), -0.3, 0.0, 0.0, sk, 120.0)
    np.testing.assert_allclose(mp.root[-1, :2], [-0.3, 0.0], atol=1e-9)
    speeds = np.linalg.norm(np.diff(mp.poses + mp.root[:, None, :3] * [1, 1, 0], axis=0),
                            axis=-1) * 120
    assert speeds.max() < 3.0


@pytest.mark.parametrize("stature", [1.55, 1.95])
def test_steps_and_turns_keep_every_body_part_out_of_the_others(stature: float) -> None:
    from ltl_human_motion.motion.biomechanics import self_penetration
    from ltl_human_motion.motion.gait import standing_pose
    from ltl_human_motion.planning.turns import STEPS, TURN_ANGLES_DEG

    sk = Skeleton(stature)
    bones = sk.bone_lengths()
    parents = np.asarray(sk.parents)
    # the planner's own steps also turn against their direction (a step left turning right)
    against = [(0.0, 0.25, -75.0), (0.15, 0.15, -90.0), (0.25, 0.0, -105.0),
               (0.19, -0.15, 163.0), (-0.2, 0.2, -135.0)]
    for (dx, dy, deg), carry in [*((c, False) for c in STEPS),
                                 *(((0.0, 0.0, d), False) for d in TURN_ANGLES_DEG),
                                 *((c, k) for c in against for k in (False, True))]:
        stand, height = standing_pose(sk, carry=carry)
        mp = make_step_primitive(stand, height, dx, dy, np.radians(deg), sk, 120.0,
                                 "carry" if carry else "walk")
        depth, pairs = self_penetration(mp.poses, stature)
        f, k = np.unravel_index(int(np.argmax(depth)), depth.shape)
        assert depth[f, k] <= 0.0, (dx, dy, deg, pairs[k], f, depth[f, k])
        # the arms turn about the shoulders: their bones keep their lengths
        arm = [JOINT_INDEX[f"{s}_{j}"] for s in "lr" for j in ("elbow", "wrist", "hand")]
        d = np.linalg.norm(mp.poses[:, arm] - mp.poses[:, parents[arm]], axis=-1)
        assert np.abs(d - bones[arm]).max() < 1e-9


def test_the_planner_and_a_bare_search_use_the_same_search_settings() -> None:
    from ltl_human_motion.planning.plan_state import PlannerOptions
    assert PlannerOptions().search == SearchOptions()
    tuned = PlannerOptions(heuristic_speed=0.4, body_radius=0.2).search
    assert (tuned.heuristic_speed, tuned.body_radius) == (0.4, 0.2)
