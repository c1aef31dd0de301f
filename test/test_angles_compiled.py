"""The joint angles' compiled loop (motion._angles_numba) gives the numpy path's numbers
bit for bit: on random poses, degenerate ones (coincident joints) and NaN joints, for
every key and for a subset of keys, in the same key order."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.kernel.segments import compiled_module
from ltl_human_motion.motion import biomechanics
from ltl_human_motion.motion.gait import standing_pose
from ltl_human_motion.motion.skeleton import Skeleton


def _numpy_path(p: np.ndarray, names=None) -> dict[str, np.ndarray]:
    real = biomechanics.compiled_module
    biomechanics.compiled_module = lambda name: None
    try:
        return biomechanics.joint_angles(p, names)
    finally:
        biomechanics.compiled_module = real


@pytest.mark.parametrize("frames", [0, 1, 7, 240])
def test_compiled_angles_equal_the_numpy_path(frames: int) -> None:
    if compiled_module("ltl_human_motion.motion._angles_numba") is None:
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(frames)
    base = standing_pose(Skeleton(1.75))[0]
    for scale in (0.0, 1e-13, 0.02, 0.4, 5.0):
        p = base + scale * rng.normal(size=(frames,) + base.shape)
        if frames > 3:
            p[1, 4] = np.nan
            p[2] = p[2, 0]
        for names in (None, ["r_knee_flexion", "neck_flexion", "l_hip_abduction", "other"]):
            want, got = _numpy_path(p, names), biomechanics.joint_angles(p, names)
            assert list(got) == list(want)
            for key, value in want.items():
                assert got[key].shape == value.shape == (frames,)
                assert np.array_equal(got[key], value, equal_nan=True), key
                assert np.array_equal(np.signbit(got[key]), np.signbit(value)), key
