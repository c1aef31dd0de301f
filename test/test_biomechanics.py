"""Biomechanical checks: motions that must fail each check, and real clips that pass."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.biomechanics import (
    BiomechanicsLimits,
    check_biomechanics,
    joint_angles,
    self_penetration,
)
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton

SK = Skeleton(1.75)
FPS = 120.0
J = JOINT_INDEX


def _standing(n: int = 120) -> np.ndarray:
    """The rest pose held still for ``n`` frames, shape (n, J, 3)."""
    return np.repeat(SK.rest_positions()[None], n, axis=0)


def _failed(report: dict) -> list[str]:
    return [k for k, v in report.items() if not v["passed"]]


def test_standing_still_passes_every_check() -> None:
    rep = check_biomechanics(_standing(), FPS, stature=1.75)
    assert _failed(rep) == []
    assert rep["balance"]["static_frames"] == 120


def test_hyperextended_knee_is_refused_naming_joint_frame_and_value() -> None:
    p = _standing()
    # the left knee pushed 6 cm behind the hip-ankle line from frame 50 on
    p[50:, J["l_knee"], 0] -= 0.06
    rep = check_biomechanics(p, FPS, stature=1.75)
    assert _failed(rep) == ["range_of_motion"]
    rom = rep["range_of_motion"]
    assert rom["joint"] == "l_knee_flexion" and rom["frame"] == 50
    assert rom["value"] < -5.0
    assert "l_knee_flexion at frame 50" in rom["detail"] and "deg" in rom["detail"]
    # the same knee bent forward by as much is an ordinary flexion
    p[50:, J["l_knee"], 0] += 0.12
    assert joint_angles(p)["l_knee_flexion"][60] > 5.0


def test_skating_foot_is_refused() -> None:
    p = _standing(240)
    slide = np.clip((np.arange(240) - 60) / FPS, 0.0, 1.0) * 0.25     # 0.25 m/s for 1 s
    for name in ("l_ankle", "l_toe"):
        p[:, J[name], 0] += slide
    rep = check_biomechanics(p, FPS, stature=1.75)
    assert "foot_skate" in _failed(rep)
    sk = rep["foot_skate"]
    assert sk["joint"] == "left foot"
    assert "left foot" in sk["detail"] and "m/s" in sk["detail"]
    assert sk["mean"] > 0.03 or sk["value"] > 0.15


def test_forearm_through_the_torso_is_refused() -> None:
    p = _standing()
    chest, spine = SK.rest_positions()[J["chest"]], SK.rest_positions()[J["spine"]]
    # frames 30-40: the right forearm runs through the chest from side to side
    p[30:41, J["r_elbow"]] = chest + np.array([0.0, -0.20, 0.0])
    p[30:41, J["r_wrist"]] = spine + np.array([0.0, 0.15, 0.0])
    p[30:41, J["r_hand"]] = spine + np.array([0.0, 0.22, 0.0])
    rep = check_biomechanics(p, FPS, stature=1.75, limits=BiomechanicsLimits(
        other_speed=1e9, hand_speed=1e9, hand_speed_goal=1e9))
    pen = rep["self_penetration"]
    assert not pen["passed"]
    assert pen["joint"] == "r_lower_arm" and pen["other"] in ("torso", "abdomen")
    assert pen["frame"] == 30 and pen["value"] > 0.05
    assert f"r_lower_arm passes through {pen['other']} at frame 30" in pen["detail"]


def test_five_metre_per_second_hand_is_refused_in_a_goal_task() -> None:
    p = _standing()
    t = np.arange(120) / FPS
    # the right palm sweeps forward at 5 m/s for 0.1 s (frames 40-52)
    p[:, J["r_hand"], 0] += 5.0 * np.clip(t - 40 / FPS, 0.0, 0.1)
    labels = ["grasp"] * 120
    rep = check_biomechanics(p, FPS, stature=1.75, labels=labels)
    js = rep["joint_speed"]
    assert not js["passed"]
    assert js["joint"] == "r_hand" and js["value"] == pytest.approx(5.0, rel=0.05)
    assert js["limit"] == pytest.approx(2.5)
    assert 40 <= js["frame"] <= 52
    assert "r_hand at frame" in js["detail"] and "grasp" in js["detail"]


def test_hand_limit_depends_on_activity_and_scales_with_stature() -> None:
    p = _standing()
    t = np.arange(120) / FPS
    p[:, J["r_hand"], 0] += 3.0 * np.clip(t - 40 / FPS, 0.0, 0.1)       # 3 m/s
    assert not check_biomechanics(p, FPS, labels=["grasp"] * 120)["joint_speed"]["passed"]
    assert check_biomechanics(p, FPS, labels=["walk"] * 120)["joint_speed"]["passed"]
    short = check_biomechanics(p, FPS, stature=1.45, labels=["walk"] * 120)["joint_speed"]
    assert not short["passed"] and short["limit"] == pytest.approx(3.5 * 1.45 / 1.75)


def test_leaning_out_of_balance_is_refused() -> None:
    p = _standing()
    upper = [J[n] for n in ("pelvis", "spine", "chest", "neck", "head", "l_clavicle",
                            "l_shoulder", "l_elbow", "l_wrist", "l_hand", "r_clavicle",
                            "r_shoulder", "r_elbow", "r_wrist", "r_hand", "l_hip", "r_hip")]
    p[:, upper, 0] += 0.35                      # the body leans 35 cm over the toes
    rep = check_biomechanics(p, FPS, stature=1.75)
    bal = rep["balance"]
    assert not bal["passed"] and bal["joint"] == "center_of_mass"
    assert bal["value"] > 0.02
    assert "outside the support polygon" in bal["detail"]
    # a seated worker is carried by the seat: those frames are not checked
    seated = np.ones(120, dtype=bool)
    assert check_biomechanics(p, FPS, seated=seated)["balance"]["passed"]


def test_labels_must_match_frames() -> None:
    with pytest.raises(ValueError, match="one entry per frame"):
        check_biomechanics(_standing(10), FPS, labels=["walk"] * 9)


def test_self_penetration_skips_neighbours() -> None:
    depth, pairs = self_penetration(_standing(2))
    assert depth.shape == (2, len(pairs))
    assert ("l_upper_arm", "l_lower_arm") not in pairs        # they share the elbow
    assert np.all(depth < 0)


def test_real_gait_clips_pass_the_limits_they_calibrate() -> None:
    """Speeds and ranges of motion are calibrated on these clips, so they must pass."""
    from ltl_human_motion.motion import deepmimic
    from ltl_human_motion.motion.gait import clip_motion, prepare_loop
    from ltl_human_motion.motion.library import load_motion

    for name in ("walker/0walk_forward.txt", "walker/turn_left0.txt"):
        m = load_motion(deepmimic.motions_dir() / name, SK)
        p = clip_motion(prepare_loop(m, name, name), SK).positions
        rep = check_biomechanics(p, FPS, stature=1.75)
        assert rep["joint_speed"]["passed"], rep["joint_speed"]["detail"]
        assert rep["range_of_motion"]["passed"], rep["range_of_motion"]["detail"]
        assert rep["self_penetration"]["passed"], rep["self_penetration"]["detail"]


def test_s1_verifies_with_the_biomechanical_checks() -> None:
    from ltl_human_motion.ltl.spec import PAPER_SPECS
    from ltl_human_motion.planning.pipeline import SynthesisOptions, resolve_cell, synthesize
    from ltl_human_motion.planning.verify import VerificationOptions
    options = SynthesisOptions(verification=VerificationOptions(biomechanics=True))
    synth = synthesize(PAPER_SPECS["S1"], resolve_cell("paper_cell"), stature=1.75, seed=0,
                       options=options)[0]
    rep = synth.verification
    for key in ("joint_speed", "range_of_motion", "self_penetration", "balance", "foot_skate"):
        assert rep[key]["passed"], rep[key]["detail"]
    assert rep["foot_skate"]["mean"] <= 0.03
    assert rep["balance"]["static_frames"] > 100


def test_hull_distance_matches_qhull_facets() -> None:
    """The all-frames support-polygon distance equals max(n . p + c) over Qhull's facets."""
    from scipy.spatial import ConvexHull

    from ltl_human_motion.motion.biomechanics import _foot_outline, _hull_distance
    rng = np.random.default_rng(1)
    n = 400
    zeros = np.zeros((n, 1))
    feet = []
    for _ in range(2):
        ankle = rng.normal(size=(n, 2)) * 0.2
        toe = ankle + rng.normal(size=(n, 2)) * 0.1
        feet.append(_foot_outline(np.hstack([ankle, zeros]), np.hstack([toe, zeros]), 1.75))
    poly = np.concatenate(feet, 1)                                   # (n, 8, 2)
    com = rng.normal(size=(n, 2)) * 0.2
    ref = [float(np.max(h.equations[:, :2] @ c + h.equations[:, 2]))
           for h, c in ((ConvexHull(q), c) for q, c in zip(poly, com))]
    np.testing.assert_allclose(_hull_distance(poly, com), ref, rtol=0, atol=1e-12)


def test_compiled_hull_distance_equals_the_numpy_path(monkeypatch) -> None:
    """The numba support-polygon distance gives the numpy path's numbers exactly, with
    repeated corners too."""
    from ltl_human_motion.kernel import segments
    from ltl_human_motion.motion import biomechanics
    rng = np.random.default_rng(2)
    poly = rng.normal(size=(300, 8, 2)) * 0.2
    poly[:20, 4:] = poly[:20, :4]
    com = rng.normal(size=(300, 2)) * 0.2
    compiled = biomechanics._hull_distance(poly, com)
    monkeypatch.setattr(segments, "compiled_module", lambda name: None)
    monkeypatch.setattr(biomechanics, "compiled_module", lambda name: None)
    np.testing.assert_array_equal(compiled, biomechanics._hull_distance(poly, com))


def test_a_crouch_keeps_its_feet_when_bone_lengths_are_restored() -> None:
    """A deep model-made grasp (pelvis tilt capped, trunk flexed 60+ degrees) keeps its
    feet where the model put them through the pipeline's bone-length restoration; the
    rigid-hip rebuild of retargeting swings the hips back with the chest and the feet
    slide by centimetres."""
    from ltl_human_motion.motion.goals import make_goal_primitive, reach_placement
    from ltl_human_motion.motion.retarget import enforce_bone_lengths
    sk = Skeleton(1.55)
    x, y = reach_placement("grasp", 0.08, sk, board=(0.115, 0.40, 0.42))
    mp = make_goal_primitive("grasp", np.array([x, y, 0.08]), sk,
                             rng=np.random.default_rng(0), board=(x - 0.115, 0.40, 0.42))
    world = mp.poses + mp.root[:, None, :3]
    feet = [J["l_ankle"], J["l_toe"], J["r_ankle"], J["r_toe"]]
    kept = enforce_bone_lengths(world, sk, rigid_hips=False)
    assert np.abs(kept[:, feet] - world[:, feet]).max() < 1e-3
    rigid = enforce_bone_lengths(world, sk)
    assert np.abs(rigid[:, feet] - world[:, feet]).max() > 0.01
    angles = joint_angles(kept)
    assert max(angles["l_hip_flexion"].max(), angles["r_hip_flexion"].max()) <= 125.0


def test_a_low_reach_from_the_carry_stance_keeps_the_forearm_out_of_the_thigh(
        monkeypatch) -> None:
    """A 1.85 m worker grasping near the feet from the carry stance (the paper cell's O1)
    swings the hand wider past the thigh where the usual swing passes the forearm through
    it (the thigh rises towards the flexed trunk; at the contact pose the arm is clear)."""
    from ltl_human_motion.motion import goals
    from ltl_human_motion.motion.goals import hand_tasks, postures
    from ltl_human_motion.planning.pipeline import get_library
    sk = Skeleton(1.85)
    carry = get_library(1.85).carry_standing_pose

    def deepest() -> float:
        mp = goals.make_goal_primitive("grasp", np.array([0.278, -0.129, 0.25]), sk,
                                       rng=np.random.default_rng(0), start_pose=carry)
        return float(self_penetration(mp.poses + mp.root[:, None, :3], 1.85)[0].max())

    assert deepest() <= 0.0
    monkeypatch.setattr(hand_tasks, "_WIDER_SWINGS", (1.0,))
    monkeypatch.setattr(postures, "_POSTURE_TRIES", 1)
    assert deepest() > 0.0
