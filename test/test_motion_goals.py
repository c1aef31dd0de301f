"""Goal primitives made by the body model, for every Table I task."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion.biomechanics import self_penetration
from ltl_human_motion.motion.gait import standing_pose
from ltl_human_motion.motion.goals import (
    GOAL_TASKS,
    chest_height,
    knee_height,
    make_goal_primitive,
    max_reach,
    reach_placement,
    seat_height_range,
)
from ltl_human_motion.motion.ik import center_of_mass, two_bone_ik
from ltl_human_motion.motion.quality import primitive_metrics
from ltl_human_motion.motion.skeleton import JOINT_INDEX as J
from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.motion.types import world_positions

SK = Skeleton(1.75)
STAND, STAND_Z = standing_pose(SK)
STAND_WORLD = STAND + np.array([0.0, 0.0, STAND_Z])


def _make(task, target=None, sk=SK, **kw):
    mp = make_goal_primitive(task, None if target is None else np.asarray(target, float), sk,
                             rng=np.random.default_rng(kw.pop("seed", 0)), **kw)
    return mp, world_positions(mp)


def _target(task: str, h: float, sk: Skeleton = SK) -> np.ndarray:
    x, y = reach_placement(task, h, sk)
    return np.array([x, y, h])


@pytest.mark.parametrize("task", GOAL_TASKS)
def test_every_task_passes_quality_and_returns_to_standing(task: str) -> None:
    target = _target(task, 1.0) if task not in (
        "bend", "stoop", "kneel", "sit", "standUp", "wait") else None
    mp, w = _make(task, target)
    m = primitive_metrics(w, mp.fps, SK)
    assert m["passed"], m
    assert mp.task == task and mp.fps == 120.0
    assert {"contact_frame", "hand", "target"} <= set(mp.meta)
    assert 0 <= mp.meta["contact_frame"] < mp.n_frames
    assert mp.root[0, 0] == 0 and mp.root[0, 1] == 0 and mp.root[0, 3] == 0
    if task != "standUp":
        np.testing.assert_allclose(w[0], STAND_WORLD, atol=1e-6)
    if task not in ("sit", "standUp"):
        np.testing.assert_allclose(w[-1], STAND_WORLD, atol=1e-6)
    if task == "standUp":
        end = w[-1] - np.array([w[-1, 0, 0], w[-1, 0, 1], 0.0])
        np.testing.assert_allclose(end, STAND_WORLD, atol=1e-6)


@pytest.mark.parametrize(("stature", "height"), [
    (s, h) for s in (1.55, 1.95) for h in (0.02, 0.3, 0.75, 1.1, 1.5, 1.9)])
def test_grasp_reaches_any_height(height: float, stature: float) -> None:
    sk = Skeleton(stature)
    if height > max_reach("grasp", sk):
        with pytest.raises(ValueError, match="outside"):
            _target("grasp", height, sk)
        return
    target = _target("grasp", height, sk)
    mp, w = _make("grasp", target, sk)
    f = mp.meta["contact_frame"]
    hand = J[mp.meta["hand"]]
    assert np.linalg.norm(w[f, hand] - target) < 1e-3
    assert primitive_metrics(w, mp.fps, sk)["passed"]
    # balance: the centre of mass stays over the feet in every frame
    com = center_of_mass(w)
    heel = w[0, [J["l_ankle"], J["r_ankle"]], 0].min() - 0.035 * stature
    toe = w[0, [J["l_toe"], J["r_toe"]], 0].max() + 0.01 * stature
    assert np.all((com[:, 0] > heel) & (com[:, 0] < toe))


@pytest.mark.parametrize("stature", [1.55, 1.75, 1.95])
@pytest.mark.parametrize("task", ["grasp", "move"])
def test_low_reaches_keep_the_hand_out_of_the_thigh(task: str, stature: float) -> None:
    # targets at thigh height, where reach placement used to put the hand into the thigh
    sk = Skeleton(stature)
    for height in (0.3, 0.4, 0.5, 0.6):
        for hand in ("l_hand", "r_hand"):
            x, y = reach_placement(task, height, sk, hand=hand)
            mp = make_goal_primitive(task, np.array([x, y, height]), sk, hand=hand,
                                     rng=np.random.default_rng(1))
            depth, pairs = self_penetration(world_positions(mp), stature)
            f, k = np.unravel_index(int(np.argmax(depth)), depth.shape)
            assert depth[f, k] <= 0.0, (height, hand, pairs[k], f, depth[f, k])


def test_hand_selection_and_two_hands() -> None:
    left, _wl = _make("grasp", [0.45, 0.15, 1.0])
    right, _wr = _make("grasp", [0.45, -0.15, 1.0])
    assert left.meta["hand"] == "l_hand" and right.meta["hand"] == "r_hand"
    forced, _ = _make("grasp", [0.45, 0.15, 1.0], hand="r_hand")
    assert forced.meta["hand"] == "r_hand"
    lh, _ = _make("leftHand", [0.45, -0.05, 1.0])
    assert lh.meta["hand"] == "l_hand"
    target = _target("assemble", 1.0)
    asm, w = _make("assemble", target)
    assert asm.meta["hand"] == "both"
    lo, hi = asm.meta["hold_frames"]
    for hand in ("l_hand", "r_hand"):
        # both palms stay within a few centimetres of the target while assembling
        d = np.linalg.norm(w[lo:hi + 1, J[hand]] - target, axis=1)
        assert d.max() < 0.06
    # the manipulation moves the hands a little, not a lot
    span = np.ptp(w[lo:hi + 1, J["r_hand"]], axis=0)
    assert 0.003 < span.max() < 0.04


def test_insert_and_extract_paths() -> None:
    target = _target("insert", 1.0)
    ins, w = _make("insert", target)
    hand = J[ins.meta["hand"]]
    f = ins.meta["contact_frame"]
    assert np.linalg.norm(w[f, hand] - target) < 1e-3
    before = w[ins.meta["hold_frames"][0], hand]
    assert 0.07 < np.linalg.norm(before - target) < 0.09       # pushed the last 8 cm
    ext, w = _make("extract", target)
    f = ext.meta["contact_frame"]
    assert np.linalg.norm(w[f, J[ext.meta["hand"]]] - target) == pytest.approx(0.08, abs=2e-3)


def test_bend_and_stoop_follow_table_one() -> None:
    chest, knee = chest_height(SK), knee_height(SK)
    bend, w = _make("bend")
    f = bend.meta["contact_frame"]
    assert w[f, J["head"]][2] < chest
    assert min(w[f, J["l_hip"], 2], w[f, J["r_hip"], 2]) > knee
    # bend keeps the knees nearly straight
    leg = np.linalg.norm(w[f, J["l_hip"]] - w[f, J["l_ankle"]])
    assert leg > 0.97 * (SK.bone_lengths()[J["l_knee"]] + SK.bone_lengths()[J["l_ankle"]])
    stoop, w = _make("stoop")
    f = stoop.meta["contact_frame"]
    assert w[f, J["head"]][2] < chest
    assert max(w[f, J["l_hip"], 2], w[f, J["r_hip"], 2]) < knee
    assert bend.meta["posture"] == "bend" and stoop.meta["posture"] == "stoop"


def test_kneel_sit_and_stand_up() -> None:
    kneel, w = _make("kneel")
    f = kneel.meta["contact_frame"]
    assert w[f, J["r_knee"], 2] < 0.06 and w[f, J["l_knee"], 2] > 0.3
    left, w = _make("kneel", hand="l_hand")
    assert w[left.meta["contact_frame"], J["l_knee"], 2] < 0.06
    _lo, hi = seat_height_range(SK)
    seat = np.array([reach_placement("sit", 0.45, SK)[0], 0.0, 0.45])
    sit, w = _make("sit", seat)
    f = sit.meta["contact_frame"]
    assert f == sit.n_frames - 1
    hips = w[f, [J["l_hip"], J["r_hip"]]].mean(axis=0)
    # (the hips turn with the seated pelvis's 3.4 degree tilt: 0.1 mm lower)
    assert hips[2] - seat[2] == pytest.approx(0.055 * SK.stature, abs=2e-4)
    assert np.linalg.norm(hips[:2] - seat[:2]) < 0.03
    _up, w = _make("standUp", [0.0, 0.0, 0.45])
    assert w[0, J["l_hip"], 2] == pytest.approx(0.45 + 0.055 * SK.stature, abs=2e-4)
    assert w[-1, 0, 2] == pytest.approx(STAND_Z, abs=1e-6)
    with pytest.raises(ValueError, match="seat height"):
        _make("sit", [seat[0], 0.0, hi + 0.1])
    with pytest.raises(ValueError, match="behind the worker"):
        _make("sit", [0.3, 0.0, 0.45])


def test_a_seated_reach_keeps_the_pelvis_on_the_seat() -> None:
    """Seated, the seat bears the weight: a reach to a desk in front leans the trunk but
    does not slide the pelvis (and the knees with it) forward towards the feet, where
    they went into the desk front (seats/job/seated_assembly)."""
    seat = np.array([reach_placement("sit", 0.45, SK)[0], 0.0, 0.45])
    _sit, w = _make("sit", seat)
    seated = w[-1] - np.array([w[-1, 0, 0], w[-1, 0, 1], 0.0])
    for path in ("arc", "level"):
        mp, wa = _make("assemble", [0.6, -0.05, 0.9], start_pose=seated, path=path)
        knee = wa[:, J["r_knee"], 0]
        assert np.ptp(wa[:, 0, 0]) < 1e-6 and np.ptp(knee) < 1e-6
        assert np.linalg.norm(wa[mp.meta["contact_frame"], J["r_hand"]]
                              - [0.6, -0.05 - 0.035, 0.9]) < 0.03


def test_the_level_path_of_a_region_task_rises_before_it_comes_in() -> None:
    """assemble / leftHand / rightHand on the level path bring the palms up near the body
    to the target's height before they move in over what is under it (a short worker's
    hands, and a part in them, swung up through a bench front on the arc)."""
    sk = Skeleton(1.55)
    target = np.array([0.55, 0.0, 1.05])
    for task in ("assemble", "rightHand"):
        mp, w = _make(task, target, sk=sk, path="level",
                      start_pose=standing_pose(sk)[0])
        hand = w[: mp.meta["contact_frame"] + 1, J["r_hand"]]
        below = hand[:, 2] < target[2] - 0.05
        # While the palm is still well below the target it stays near the body.
        assert np.max(hand[below, 0]) < target[0] - 0.2


def test_wait_stays_within_a_small_ball() -> None:
    mp, w = _make("wait", duration=3.0)
    assert mp.n_frames == round(3.0 * 120) + 1
    assert np.linalg.norm(w - w[0], axis=-1).max() < 0.02


def test_seeds_vary_the_motion_but_stay_valid() -> None:
    target = _target("grasp", 0.9)
    a, wa = _make("grasp", target, seed=1)
    b, wb = _make("grasp", target, seed=2)
    _a2, wa2 = _make("grasp", target, seed=1)
    np.testing.assert_array_equal(wa, wa2)
    assert a.n_frames != b.n_frames or np.abs(wa - wb).max() > 1e-3
    for mp, w in ((a, wa), (b, wb)):
        assert np.linalg.norm(w[mp.meta["contact_frame"], J[mp.meta["hand"]]] - target) < 1e-3


def test_duration_and_errors() -> None:
    target = _target("assemble", 1.0)
    mp, _ = _make("assemble", target, duration=6.0)
    assert mp.n_frames == 721
    with pytest.raises(ValueError, match="too short"):
        _make("assemble", target, duration=0.5)
    with pytest.raises(ValueError, match="unknown goal task"):
        _make("jump", target)
    with pytest.raises(ValueError, match="gait task"):
        _make("walk", target)
    with pytest.raises(ValueError, match="needs a target"):
        _make("grasp", None)
    with pytest.raises(ValueError, match="out of reach"):
        _make("grasp", [3.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="outside"):
        _make("grasp", [0.4, 0.0, max_reach("grasp", SK) + 0.05])
    with pytest.raises(ValueError, match="shape"):
        _make("grasp", [0.4, 0.0])


def test_custom_start_pose_is_respected() -> None:
    carry, _ = standing_pose(SK, carry=True)
    target = _target("release", 0.9)
    mp, w = _make("release", target, start_pose=carry)
    np.testing.assert_allclose(mp.poses[0], carry, atol=1e-6)
    np.testing.assert_allclose(mp.poses[-1], carry, atol=1e-6)
    assert np.linalg.norm(w[mp.meta["contact_frame"], J[mp.meta["hand"]]] - target) < 2e-3


def test_two_bone_ik_reaches_and_keeps_lengths() -> None:
    rng = np.random.default_rng(5)
    base = rng.normal(size=(200, 3))
    target = base + rng.normal(size=(200, 3)) * 0.3
    pole = rng.normal(size=(200, 3))
    mid, end = two_bone_ik(base, target, 0.3, 0.25, pole)
    np.testing.assert_allclose(np.linalg.norm(mid - base, axis=1), 0.3)
    np.testing.assert_allclose(np.linalg.norm(end - mid, axis=1), 0.25)
    reach = np.linalg.norm(target - base, axis=1)
    ok = (reach < 0.999 * 0.55) & (reach > 0.05 + 1e-6)
    np.testing.assert_allclose(end[ok], target[ok], atol=1e-9)


def test_two_bone_ik_folds_no_further_than_max_flexion() -> None:
    """A target nearer the base than the fold allows is pushed out along the
    base-target line; the others are reached as without the limit."""
    rng = np.random.default_rng(6)
    base = rng.normal(size=(300, 3))
    target = base + rng.normal(size=(300, 3)) * 0.15
    pole = rng.normal(size=(300, 3))
    limit = np.radians(147.0)
    mid, end = two_bone_ik(base, target, 0.3, 0.25, pole, max_flexion=limit)
    free_mid, free_end = two_bone_ik(base, target, 0.3, 0.25, pole)
    upper, lower = mid - base, end - mid
    cos = np.sum(upper * lower, axis=1) / (0.3 * 0.25)
    flexion = np.arccos(np.clip(cos, -1.0, 1.0))
    assert flexion.max() <= limit + 1e-9
    free_flexion = np.arccos(np.clip(np.sum((free_mid - base) * (free_end - free_mid), axis=1)
                                     / (0.3 * 0.25), -1.0, 1.0))
    folded = free_flexion > limit
    assert folded.any() and (~folded).any()
    np.testing.assert_allclose(end[~folded], free_end[~folded], atol=1e-12)
    out = (end - base)[folded]
    along = (target - base)[folded]
    cross = np.linalg.norm(np.cross(out, along), axis=1)
    np.testing.assert_allclose(cross, 0.0, atol=1e-9)


def test_reach_onto_a_table_keeps_the_knees_out_of_it() -> None:
    # A 1.95 m worker standing obliquely at a 0.75 m table reaches a part 10 cm in from
    # its edge: the unconstrained posture bends a knee into the table; with the table as
    # ``support`` the trunk and legs stay out of it (2 cm clearance at contact).
    from ltl_human_motion.motion.goals import _support_depth
    sk = Skeleton(1.95)
    target = np.array([0.434, -0.136, 0.85])
    inward = np.array([np.cos(0.852), -np.sin(0.852)])         # the edge 49 deg across
    support = (*inward, float(inward @ target[:2]) - 0.1, 0.75)
    free = make_goal_primitive("grasp", target, sk, hand="r_hand")
    kept = make_goal_primitive("grasp", target, sk, hand="r_hand", support=support)
    depth = [float(_support_depth(world_positions(mp, 0.0, 0.0, 0.0), support, 1.95).max())
             for mp in (free, kept)]
    assert depth[0] > 0.0 >= depth[1]


def test_extract_over_furniture_pulls_out_in_front_of_its_edge() -> None:
    # A fixture 0.2 m behind a base's front edge (top 0.98 m): on the level path the
    # pull ends in front of the edge and the hand comes in the same straight way.
    target = np.array([0.6, -0.1, 1.06])
    support = (1.0, 0.0, 0.4, 0.98)
    mp = make_goal_primitive("extract", target, SK, hand="r_hand", path="level",
                             support=support)
    palm = world_positions(mp, 0.0, 0.0, 0.0)[:, J["r_hand"]]
    beyond = palm[:, 0] > 0.4
    assert beyond.any() and np.all(palm[beyond, 2] > 0.98)


@pytest.mark.parametrize(("z", "seed"), [(0.9, 4), (0.9, 1), (0.3, 2), (1.2, 3)])
def test_a_retimed_reach_is_slower_along_the_same_path(monkeypatch, z: float,
                                                       seed: int) -> None:
    """A reach whose hand would pass the retiming speed is made again slower from the same
    random draws: the palm keeps within 1 cm of the fast version's path (the body's lead
    over the hand is timed, not placed; other draws bow it 1-2 cm away) and its peak
    speed is under the limit."""
    from scipy.spatial.distance import cdist

    from ltl_human_motion.motion import goals
    from ltl_human_motion.motion.goals import hand_tasks
    x, y = goals.reach_placement("grasp", z, SK)
    target = np.array([x, y, z])

    def made(limit: float) -> np.ndarray:
        monkeypatch.setattr(hand_tasks, "HAND_RETIME_SPEED", limit)
        mp = goals.make_goal_primitive("grasp", target, SK, rng=np.random.default_rng(seed))
        return mp.poses + mp.root[:, None, :3]

    fast, slow = made(1e9), made(0.6)
    assert len(slow) > len(fast)
    assert goals._peak_hand_speed(slow, (1,), 120.0) <= 0.6 * SK.stature / 1.75 + 1e-9
    d = cdist(slow[:, J["r_hand"]], fast[:, J["r_hand"]])
    assert max(d.min(axis=1).max(), d.min(axis=0).max()) < 0.01


def test_hips_stay_level_in_a_standing_bend_and_turn_with_a_crouching_pelvis() -> None:
    """A bend from the standing height keeps the hips where the pelvis holds them (the
    legs stay straight enough to reach the floor); a crouch turns them with the pelvis's
    tilt, back and up about the pelvis joint."""
    from ltl_human_motion.motion import goals
    rest = SK.rest_positions()
    hips = [J["l_hip"], J["r_hip"]]
    pelvis = np.array([rest[0], rest[0] - [0.0, 0.0, 0.3 * SK.stature]])
    pitch = np.array([0.8, 0.8])
    tr = goals._trunk(SK, pelvis, pitch)
    np.testing.assert_allclose(tr[0, hips] - pelvis[0], rest[hips] - rest[0], atol=1e-12)
    off = tr[1, hips] - pelvis[1]
    assert np.all(off[:, 0] < rest[hips, 0] - rest[0, 0] - 0.01)
    np.testing.assert_allclose(np.linalg.norm(off, axis=1),
                               np.linalg.norm(rest[hips] - rest[0], axis=1), atol=1e-12)


def _into_board(w: np.ndarray, side: str, board_lo: np.ndarray, board_hi: np.ndarray,
                radius: float) -> float:
    """How deep (m) the hand capsule (wrist to hand, ``radius``) of frames ``w`` (T, J, 3)
    comes into the box board_lo-board_hi at its deepest; negative: clear by that much."""
    s = np.linspace(0.0, 1.0, 9)[:, None, None]
    pts = w[None, :, J[f"{side}_wrist"]] + s * (w[None, :, J[f"{side}_hand"]]
                                                - w[None, :, J[f"{side}_wrist"]])
    gap = np.maximum(np.maximum(board_lo - pts, pts - board_hi), 0.0)
    return float(radius - np.linalg.norm(gap, axis=-1).min())


def test_a_grasp_over_a_board_above_the_shoulders_rises_in_front_of_its_edge() -> None:
    """A 1.55 m worker grasps a part 5 cm behind the edge of a wall shelf whose board
    (1.58-1.60 m) is above the shoulders: told of the board (``support``), every path
    raises the hand in front of the edge and comes in over it with the palm level,
    clear of the board on every frame. Without it the arc about the shoulder swings the
    hand under the board at arm's length and up through it (shelf_heights' O_over)."""
    sk = Skeleton(1.55)
    edge, top = 0.25, 1.60
    target = np.array([0.30, -0.18, 1.685])
    lo, hi = np.array([edge, -0.6, top - 0.02]), np.array([edge + 0.3, 0.6, top])
    radius = 0.045 * 1.55 / 1.75
    for path in ("arc", "level"):
        mp, w = _make("grasp", target, sk=sk, path=path, hand="r_hand",
                      support=(1.0, 0.0, edge, top), start_pose=standing_pose(sk)[0])
        assert np.linalg.norm(w[mp.meta["contact_frame"], J["r_hand"]] - target) < 1e-3
        assert _into_board(w, "r", lo, hi, radius) < 0.0
    _, w = _make("grasp", target, sk=sk, path="arc", hand="r_hand",
                 start_pose=standing_pose(sk)[0])
    assert _into_board(w, "r", lo, hi, radius) > 0.02


def test_a_grasp_under_a_board_close_over_the_part_keeps_the_palm_level() -> None:
    """A 1.95 m worker grasps a part in a shelf compartment, 16 cm under the board above
    it (generated cell gen_0_10): the palm comes in level, so the wrist is not a hand's
    length above it, in the board (4.9 cm deep with the palm pointing down as the arm
    does); the hand clears the board on every frame of both paths."""
    sk = Skeleton(1.95)
    edge, bottom, top = 0.5665, 0.88, 0.90
    target = np.array([0.70, -0.14, 0.717])
    lo, hi = np.array([edge, -0.6, bottom]), np.array([edge + 0.35, 0.6, top])
    radius = 0.045 * 1.95 / 1.75
    for path in ("arc", "level"):
        mp, w = _make("grasp", target, sk=sk, path=path, hand="r_hand",
                      board=(edge, bottom, top), support=(1.0, 0.0, edge, 0.6),
                      start_pose=standing_pose(sk)[0])
        contact = mp.meta["contact_frame"]
        assert np.linalg.norm(w[contact, J["r_hand"]] - target) < 1e-3
        assert abs(w[contact, J["r_wrist"], 2] - target[2]) < 0.01
        assert _into_board(w, "r", lo, hi, radius) < 0.0


def test_a_reach_deep_under_a_low_board_kneels_within_the_range_of_motion() -> None:
    """A part on the floor 17 cm behind the edge of a board 0.44 m up (under_shelf's O3)
    is out of reach of every crouch whose hips stay within their 125 degree range of
    motion; the worker kneels on both knees instead (one foot steps back, then the
    other), leans forward with the free palm on the floor, and reaches in under the
    board. Every frame keeps the hips and knees within their range, the body clear of
    the board, and each foot still while on the floor, one at a time off it."""
    from ltl_human_motion.motion.biomechanics import BiomechanicsLimits, joint_angles
    for stature in (1.55, 1.75, 1.95):
        sk = Skeleton(stature)
        start = standing_pose(sk)[0]
        depth, bottom, top = 0.17, 0.44, 0.46
        x, y = reach_placement("grasp", 0.10, sk, board=(depth, bottom, top),
                               start_pose=start)
        target = np.array([x, y, 0.10])
        mp, w = _make("grasp", target, sk=sk, board=(x - depth, bottom, top),
                      start_pose=start)
        f1, _ = mp.meta["hold_frames"]
        assert np.linalg.norm(w[mp.meta["contact_frame"], J[mp.meta["hand"]]] - target) < 1e-3
        assert w[f1, J["l_knee"], 2] < 0.06 and w[f1, J["r_knee"], 2] < 0.06
        free = "l" if mp.meta["hand"] == "r_hand" else "r"
        assert w[f1, J[f"{free}_hand"], 2] < 0.06
        rom = BiomechanicsLimits().rom
        angles = joint_angles(w)
        for name in ("hip_flexion", "knee_flexion"):
            for s in ("l", "r"):
                assert angles[f"{s}_{name}"].max() <= rom[name][1]
                assert angles[f"{s}_{name}"].min() >= rom[name][0]
        # no joint but the reaching arm's comes within 3 cm of the board
        edge = x - depth
        body = [j for n, j in J.items() if not n.startswith(mp.meta["hand"][0] + "_")
                or n.endswith(("hip", "knee", "ankle", "toe"))]
        r = 0.03
        into = (w[:, body, 0] > edge - r) & (w[:, body, 2] > bottom - r) \
            & (w[:, body, 2] < top + r)
        assert not into.any()
        rest_toe = w[0, J["l_toe"], 2]
        lifted = np.stack([w[:, J[f"{s}_toe"], 2] > rest_toe + 0.005 for s in ("l", "r")], 1)
        assert not np.all(lifted, axis=1).any()
        for k, s in enumerate(("l", "r")):
            moving = np.linalg.norm(np.diff(w[:, J[f"{s}_toe"], :2], axis=0), axis=1) > 1e-4
            assert np.all(lifted[1:, k] | lifted[:-1, k] | ~moving)


def test_without_kneeling_the_reach_under_the_low_board_folds_the_hips(monkeypatch) -> None:
    """The same reach with the kneeling postures taken away falls back on the crouch with
    the pelvis tilted in full, whose hips fold past their 125 degree range of motion
    (the failure the kneel replaces)."""
    from ltl_human_motion.motion import goals
    from ltl_human_motion.motion.biomechanics import joint_angles
    from ltl_human_motion.motion.goals import postures
    sk = Skeleton(1.75)
    start = standing_pose(sk)[0]

    kneel_set = goals._kneel_set

    def no_kneel(skeleton, st):
        out = list(kneel_set(skeleton, st))
        out[5] = np.zeros_like(out[5])                 # none feasible
        return tuple(out)

    monkeypatch.setattr(postures, "_kneel_set", no_kneel)
    monkeypatch.setattr(postures, "_GRID_CACHE", BoundedCache(32))
    goals._placement.cache_clear()
    try:
        x, y = reach_placement("grasp", 0.10, sk, board=(0.17, 0.44, 0.46), start_pose=start)
        _, w = _make("grasp", np.array([x, y, 0.10]), sk=sk, board=(x - 0.17, 0.44, 0.46),
                     start_pose=start)
    finally:
        goals._placement.cache_clear()
    angles = joint_angles(w)
    assert max(angles["l_hip_flexion"].max(), angles["r_hip_flexion"].max()) > 125.0
