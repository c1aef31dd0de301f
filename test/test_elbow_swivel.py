"""The goal model's elbows never flip where the elbow pole lies along the arm
(:func:`ltl_human_motion.motion.goals.body._elbow_pole`)."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.goals import make_goal_primitive
from ltl_human_motion.motion.goals.body import (
    POLE_DEGENERATE,
    _elbow_pole,
    _goal_elbow_pole,
    _swivel_reference,
)
from ltl_human_motion.motion.goals.hand_tasks import ELBOW_RETIME_SPEED
from ltl_human_motion.motion.ik import two_bone_ik
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import world_positions

UPPER, LOWER = 0.30, 0.28


def _sweep_through_pole(k: int, frames: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Shoulders at the origin and wrists (frames, 3) of arm ``k`` bent to 0.4 m, swept
    at constant speed through the direction of its goal pole, 1 cm beside it."""
    pole = _goal_elbow_pole(k) / np.linalg.norm(_goal_elbow_pole(k))
    side = np.cross(pole, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    beside = np.cross(pole, side)
    angle = np.linspace(-0.6, 0.6, frames)
    u = np.cos(angle)[:, None] * pole + np.sin(angle)[:, None] * side + 0.01 * beside
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    return np.zeros((frames, 3)), 0.4 * u


@pytest.mark.parametrize("k", [0, 1])
def test_an_arm_swept_through_its_pole_keeps_its_elbow_moving_smoothly(k):
    shoulder, wrist = _sweep_through_pole(k)
    pole = np.broadcast_to(_goal_elbow_pole(k), wrist.shape)
    flipped, _ = two_bone_ik(shoulder, wrist, UPPER, LOWER, pole, max_stretch=1.0)
    kept, _ = two_bone_ik(shoulder, wrist, UPPER, LOWER,
                          _elbow_pole(shoulder, wrist, pole, k, (UPPER, LOWER), 1 / 120),
                          max_stretch=1.0)
    wrist_step = np.linalg.norm(np.diff(wrist, axis=0), axis=-1).max()
    assert np.linalg.norm(np.diff(flipped, axis=0), axis=-1).max() > 20 * wrist_step
    assert np.linalg.norm(np.diff(kept, axis=0), axis=-1).max() < 3 * wrist_step
    u = wrist / np.linalg.norm(wrist, axis=-1, keepdims=True)
    unit = pole / np.linalg.norm(pole, axis=-1, keepdims=True)
    share = np.linalg.norm(unit - np.sum(unit * u, axis=-1, keepdims=True) * u, axis=-1)
    away = share >= POLE_DEGENERATE
    assert away.any() and np.allclose(kept[away], flipped[away])


@pytest.mark.parametrize("frames", [3, 5, 10])
def test_a_sweep_too_quick_to_swivel_in_keeps_the_elbow_with_the_arm(frames):
    """Passing the pole in a few frames leaves no time to turn the elbow at
    :data:`SWIVEL_SPEED`: the swivel is held over the whole motion, and the elbow moves
    no faster than the wrist."""
    shoulder, wrist = _sweep_through_pole(1, frames)
    pole = np.broadcast_to(_goal_elbow_pole(1), wrist.shape)
    kept, _ = two_bone_ik(shoulder, wrist, UPPER, LOWER,
                          _elbow_pole(shoulder, wrist, pole, 1, (UPPER, LOWER), 1 / 120),
                          max_stretch=1.0)
    wrist_step = np.linalg.norm(np.diff(wrist, axis=0), axis=-1).max()
    assert np.linalg.norm(np.diff(kept, axis=0), axis=-1).max() <= wrist_step


def test_the_swivel_reference_is_perpendicular_and_continuous():
    rng = np.random.default_rng(0)
    u = rng.normal(size=(2000, 3))
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    for k in (0, 1):
        r = _swivel_reference(u, k)
        assert np.allclose(np.linalg.norm(r, axis=-1), 1.0)
        assert np.abs(np.sum(r * u, axis=-1)).max() < 1e-9
        nudged = u + 1e-4 * rng.normal(size=u.shape)
        nudged /= np.linalg.norm(nudged, axis=-1, keepdims=True)
        near_cut = u @ np.array([-0.6, -0.8 if k == 0 else 0.8, 0.0]) > 0.9
        step = np.linalg.norm(_swivel_reference(nudged, k) - r, axis=-1)
        assert step[~near_cut].max() < 1e-2


@pytest.mark.parametrize("target", [(0.0, -0.3, 1.45), (-0.2, -0.7, 0.78)])
def test_a_tall_workers_reach_beside_and_behind_the_shoulder_is_timed_as_any_other(target):
    """Targets where the right elbow's goal pole lies along the arm: the reach took
    26.7 s and 5.7 s, slowed for an elbow that flipped in a frame."""
    skeleton = Skeleton(1.95)
    mp = make_goal_primitive("grasp", np.array(target), skeleton,
                             rng=np.random.default_rng(0), hand="r_hand")
    world = world_positions(mp)
    elbow = world[:, JOINT_INDEX["r_elbow"]]
    window = round(mp.fps / 30.0)
    speed = np.linalg.norm(elbow[window:] - elbow[:-window], axis=-1).max() * mp.fps / window
    assert mp.n_frames / mp.fps < 4.0
    assert speed <= ELBOW_RETIME_SPEED * skeleton.stature / DEFAULT_STATURE
