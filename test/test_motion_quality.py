"""Quality checks flag broken motions and pass clean ones; retarget helpers."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.quality import QualityThresholds, check_primitives, primitive_metrics
from ltl_human_motion.motion.retarget import enforce_bone_lengths, fix_feet, mirror_positions
from ltl_human_motion.motion.skeleton import JOINT_INDEX as J
from ltl_human_motion.motion.skeleton import MIRROR_PERMUTATION, Skeleton
from ltl_human_motion.motion.types import MotionPrimitive

SK = Skeleton()


def _standing(T: int = 30) -> np.ndarray:
    return np.repeat(SK.rest_positions()[None], T, axis=0)


def test_clean_standing_passes() -> None:
    m = primitive_metrics(_standing(), 120.0, SK)
    assert m["passed"] and m["bone_length"] < 1e-12 and m["foot_skate"] == 0.0


def test_each_check_can_fail() -> None:
    p = _standing()
    p[:, J["l_hand"], 2] -= 0.05                       # stretched hand bone
    assert primitive_metrics(p, 120.0, SK)["bone_length"] == pytest.approx(0.05)
    p = _standing() - np.array([0.0, 0.0, 0.03])       # sunk into the floor
    m = primitive_metrics(p, 120.0, SK)
    assert not m["passed"] and m["floor"] == pytest.approx(0.0175 - 0.03)
    p = _standing()
    p[:, [J["l_ankle"], J["l_toe"]], 0] += np.linspace(0, 0.3, 30)[:, None]   # sliding foot
    m = primitive_metrics(p, 120.0, SK)
    assert m["foot_skate"] == pytest.approx(0.3 / 29 * 120, rel=1e-6) and not m["passed"]
    p = _standing()
    p[15:, J["r_hand"], 0] += 0.2                      # a jump between two frames
    m = primitive_metrics(p, 120.0, SK, QualityThresholds(bone_length=1.0))
    assert m["joint_speed"] == pytest.approx(24.0) and not m["passed"]


def test_report_summary() -> None:
    rest = SK.rest_positions()
    poses = np.repeat((rest - rest[0])[None], 10, axis=0)
    root = np.zeros((10, 4))
    root[:, 2] = rest[0, 2]
    good = MotionPrimitive("good", "wait", poses, root, 120.0)
    root_bad = root.copy()
    root_bad[:, 2] -= 0.05
    bad = MotionPrimitive("bad", "wait", poses, root_bad, 120.0)
    rep = check_primitives([good, bad], SK, kind="test", details=True)
    assert rep["count"] == 2 and rep["passed"] == 1 and rep["failed"] == ["bad"]
    assert not rep["ok"] and rep["by_task"]["wait"] == {"count": 2, "passed": 1}
    assert set(rep["primitives"]) == {"good", "bad"}


def test_fix_feet_lifts_scuffing_toes_and_keeps_lengths() -> None:
    p = _standing(40)
    # the right foot swings forward fast with its toe dragging 1 cm into the floor
    p[:, [J["r_ankle"], J["r_toe"]], 0] += np.linspace(0, 0.6, 40)[:, None]
    p[:, J["r_toe"], 2] = -0.01
    p[:, J["r_toe"]] = p[:, J["r_ankle"]] + SK.bone_lengths()[J["r_toe"]] * (
        (p[:, J["r_toe"]] - p[:, J["r_ankle"]])
        / np.linalg.norm(p[:, J["r_toe"]] - p[:, J["r_ankle"]], axis=1, keepdims=True))
    out = fix_feet(p, 120.0, SK)
    assert out[:, [J["l_toe"], J["r_toe"], J["l_ankle"], J["r_ankle"]], 2].min() >= 0.0175 - 1e-9
    foot = np.linalg.norm(out[:, J["r_toe"]] - out[:, J["r_ankle"]], axis=1)
    np.testing.assert_allclose(foot, SK.bone_lengths()[J["r_toe"]])


def test_mirror_and_bone_lengths() -> None:
    rng = np.random.default_rng(0)
    p = _standing(5) + rng.normal(scale=0.02, size=(5, 23, 3))
    m = mirror_positions(p)
    np.testing.assert_allclose(mirror_positions(m), p)
    np.testing.assert_allclose(m[:, J["l_hand"], 1], -p[:, J["r_hand"], 1])
    assert MIRROR_PERMUTATION[J["l_knee"]] == J["r_knee"]
    fixed = enforce_bone_lengths(p, SK)
    assert primitive_metrics(fixed, 120.0, SK, QualityThresholds(
        floor_tolerance=1.0, foot_skate=10.0, joint_speed=100.0))["bone_length"] < 1e-12
