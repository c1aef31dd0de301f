"""Angle extraction from joint positions, on synthetic postures whose angles are known,
and the motion-level assessment of a real synthesized motion."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.assess import assess_motion, body_angles, cycle_breakdown
from ltl_human_motion.assess.handling import held_masks, lifts
from ltl_human_motion.motion.skeleton import JOINT_INDEX as J
from ltl_human_motion.motion.skeleton import Skeleton

UPPER = ["spine", "chest", "neck", "head", "l_clavicle", "l_shoulder", "l_elbow", "l_wrist",
         "l_hand", "r_clavicle", "r_shoulder", "r_elbow", "r_wrist", "r_hand"]


def _rot(axis: str, deg: float) -> np.ndarray:
    a = np.radians(deg)
    c, s = np.cos(a), np.sin(a)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def _rotate(p: np.ndarray, joints: list[str], about: str, axis: str, deg: float) -> None:
    o = p[J[about]].copy()
    R = _rot(axis, deg)
    for j in joints:
        p[J[j]] = o + R @ (p[J[j]] - o)


def rest() -> np.ndarray:
    return Skeleton(1.75).rest_positions().copy()


def test_rest_pose_is_neutral():
    a = body_angles(rest())
    for name in ("trunk_flexion", "trunk_side_bend", "trunk_twist", "neck_flexion",
                 "neck_side_bend"):
        assert abs(getattr(a, name)[0]) < 1e-6, name
    assert np.all(np.abs(a.upper_arm_flexion) < 2) and np.all(a.elbow_flexion < 2)
    assert np.all(a.knee_flexion < 1e-6) and np.all(np.abs(a.shoulder_raise) < 1e-6)


@pytest.mark.parametrize("deg", [30.0, 70.0, -15.0])
def test_trunk_flexion(deg):
    p = rest()
    _rotate(p, UPPER, "pelvis", "y", deg)      # +y rotation tips +z towards +x: forward
    a = body_angles(p)
    assert a.trunk_flexion[0] == pytest.approx(deg, abs=0.5)
    # Arms hang with the trunk: relative to the trunk they did not move.
    assert np.all(np.abs(a.upper_arm_flexion[0]) < 2)
    assert abs(a.neck_flexion[0]) < 0.5


def test_trunk_twist_and_side_bend():
    p = rest()
    _rotate(p, UPPER, "pelvis", "z", 25.0)
    assert body_angles(p).trunk_twist[0] == pytest.approx(25.0, abs=0.5)
    p = rest()
    _rotate(p, UPPER, "pelvis", "x", 15.0)
    a = body_angles(p)
    assert a.trunk_side_bend[0] == pytest.approx(15.0, abs=0.5)
    assert abs(a.trunk_flexion[0]) < 0.5


def test_upper_arm_raised_100_forward_and_abducted():
    p = rest()
    _rotate(p, ["r_elbow", "r_wrist", "r_hand"], "r_shoulder", "y", -100.0)   # forward
    a = body_angles(p)
    assert a.upper_arm_flexion[0, 1] == pytest.approx(100.0, abs=2.0)
    assert abs(a.upper_arm_flexion[0, 0]) < 2.0
    assert a.upper_arm_abduction[0, 1] < 20
    p = rest()
    _rotate(p, ["l_elbow", "l_wrist", "l_hand"], "l_shoulder", "x", 60.0)     # sideways, out (+y)
    a = body_angles(p)
    assert a.upper_arm_abduction[0, 0] == pytest.approx(60.0, abs=2.0)
    assert a.upper_arm_flexion[0, 0] == pytest.approx(60.0, abs=2.0)
    p = rest()
    _rotate(p, ["r_elbow", "r_wrist", "r_hand"], "r_shoulder", "y", 30.0)     # behind
    assert body_angles(p).upper_arm_flexion[0, 1] == pytest.approx(-30.0, abs=2.0)


def test_elbow_wrist_knee_neck():
    p = rest()
    _rotate(p, ["l_wrist", "l_hand"], "l_elbow", "y", -90.0)
    _rotate(p, ["l_hand"], "l_wrist", "y", -30.0)
    _rotate(p, ["r_ankle", "r_toe"], "r_knee", "y", 45.0)
    _rotate(p, ["head"], "neck", "y", 25.0)
    a = body_angles(p)
    assert a.elbow_flexion[0, 0] == pytest.approx(90.0, abs=0.5)
    assert a.wrist_flexion[0, 0] == pytest.approx(30.0, abs=0.5)
    assert a.knee_flexion[0, 1] == pytest.approx(45.0, abs=0.5)
    assert a.neck_flexion[0] == pytest.approx(25.0, abs=0.5)


def test_rotated_and_translated_body_reads_the_same():
    p = rest()
    _rotate(p, UPPER, "pelvis", "y", 30.0)
    q = (_rot("z", 130.0) @ p.T).T + np.array([2.0, -1.0, 0.0])
    a, b = body_angles(p), body_angles(q)
    assert b.trunk_flexion[0] == pytest.approx(a.trunk_flexion[0], abs=1e-6)
    assert np.allclose(b.upper_arm_flexion, a.upper_arm_flexion, atol=1e-6)


def test_bad_positions_raise():
    with pytest.raises(ValueError, match="shape"):
        body_angles(np.zeros((5, 22, 3)))
    bad = rest()[None].repeat(2, 0)
    bad[1, 3, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        body_angles(bad)


@pytest.fixture(scope="module")
def s1():
    from ltl_human_motion.planning import synthesize

    return synthesize("S1", "paper_cell", variants=1, seed=1)[0]


def test_assess_synthesized_motion(s1):
    rep = assess_motion(s1, {"O1": 4.0})
    T = s1.n_frames
    assert rep.reba.shape == (T,) and rep.rula.shape == (T,)
    assert 1 <= rep.reba.min() and rep.reba.max() <= 15
    assert 1 <= rep.rula.min() and rep.rula.max() <= 7
    # The worker picks O1 from 0.2 m: that is the worst posture of the motion.
    grasp = next(t for t in rep.per_task if t["kind"] == "grasp")
    walk = next(t for t in rep.per_task if t["task"] == "walking")
    assert grasp["reba"]["max"] > walk["reba"]["mean"]
    assert rep.summary["reba"]["max"] == max(t["reba"]["max"] for t in rep.per_task
                                             if t["reba"]["max"] is not None)
    # O1 is held from its grasp until the assembly: one lift of 4 kg, low and close.
    assert len(rep.lifts) == 1 and rep.lifts[0]["object"] == "O1"
    o = rep.lifts[0]["origin"]
    assert o["V"] < 40 and 0 < o["H"] < 80 and o["load"] == 4.0
    assert rep.lifts[0]["destination"]["V"] > 80
    assert rep.summary["max_load_kg"] == 4.0


def test_held_masks_follow_the_part(s1):
    held = held_masks(s1.positions, s1.objects)
    mask, hand = held["O1"]
    assert hand in (0, 1) and mask.any()
    moving = np.linalg.norm(np.diff(s1.objects["O1"], axis=0), axis=1) > 1e-6
    assert np.all(mask[1:][moving] | mask[:-1][moving])     # it only moves while held
    assert len(lifts(s1.positions, s1.objects)) == 1


def test_cycle_breakdown(s1):
    c = cycle_breakdown(s1)
    assert c["cycle_time"] == pytest.approx(s1.duration)
    assert sum(c["total"].values()) == pytest.approx(s1.duration, abs=1e-9)
    assert sum(c["share"].values()) == pytest.approx(1.0)
    assert c["total"]["walking"] > 0 and c["total"]["value_adding"] > 0
    assert c["walking_distance"] > 1.0         # R0 -> O1 -> bench is several metres
    assert [t["task"] for t in c["per_task"]] == s1.sequence
    assert c["per_task"][0]["approach_distance"] > 0.5
    two = cycle_breakdown(s1, cycles=2)
    assert two["per_cycle"]["walking"] == pytest.approx(c["total"]["walking"] / 2)
    with pytest.raises(ValueError, match="cycles"):
        cycle_breakdown(s1, cycles=0)


def test_settings_are_checked():
    from ltl_human_motion.assess import ErgonomicsSettings
    with pytest.raises(ValueError, match="reba_coupling"):
        ErgonomicsSettings(reba_coupling="great")
    with pytest.raises(ValueError, match="duration"):
        ErgonomicsSettings(duration="4h")


def test_a_grasp_on_the_knees_is_coded_kneeling_by_owas():
    """A reach deep under a low board kneels (under_shelf grasp(O3)): OWAS codes the legs
    as kneeling (6) where a knee rests on the floor, though the task is a grasp."""
    from pathlib import Path

    from ltl_human_motion.assess import owas
    from ltl_human_motion.planning import synthesize

    cell = Path(__file__).resolve().parents[1] / "scenarios" / "cells" / "under_shelf.yaml"
    m = synthesize("F grasp(O3)", str(cell), seed=0)[0]
    rep = assess_motion(m)
    seg = next(s for s in m.timeline if s.task == "grasp(O3)")
    f = (seg.start_frame + seg.end_frame) // 2
    assert m.positions[f, J["l_knee"], 2] < m.positions[f, J["l_ankle"], 2]
    a = body_angles(m.positions[f:f + 1], m.motion.skeleton.stature)
    legs = owas.legs_code(a.knee_flexion[:, 0], a.knee_flexion[:, 1], False, False, True,
                          False)
    assert int(legs[0]) == 6
    want = owas.action_category(owas.back_code(a.trunk_flexion, a.trunk_twist),
                                owas.arms_code(a.upper_arm_flexion[:, 0],
                                               a.upper_arm_flexion[:, 1]), legs,
                                owas.load_code(np.zeros(1)))
    assert rep.owas[f] == int(want[0])
