"""The shared rotation module and cache helper: conversions against each other and
against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.kernel.rotations import (
    MOCAP_FROM_ZUP,
    ZUP_FROM_YUP,
    compact_axis_angle_from_matrix,
    matrix_from_angle,
    matrix_from_axis_angle,
    matrix_from_compact_axis_angle,
    matrix_from_euler,
    matrix_from_quaternion,
    matrix_from_unit_axis_angle,
    matrix_from_yaw,
    quaternion_from_matrix,
    quaternion_from_yaw,
)
from ltl_human_motion.scene import zup_from_yup

quats = arrays(np.float64, (4,), elements=st.floats(-1.0, 1.0, allow_nan=False)).filter(
    lambda q: np.linalg.norm(q) > 0.1)


@settings(max_examples=200, deadline=None)
@given(q=quats)
def test_quaternion_round_trip(q: np.ndarray) -> None:
    R = matrix_from_quaternion(q)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)
    back = quaternion_from_matrix(R)
    unit = q / np.linalg.norm(q)
    assert min(np.abs(back - unit).max(), np.abs(back + unit).max()) < 1e-9  # q ~ -q


@settings(max_examples=100, deadline=None)
@given(v=arrays(np.float64, (3,), elements=st.floats(-3.0, 3.0, allow_nan=False)))
def test_axis_angle_forms_agree(v: np.ndarray) -> None:
    angle = np.linalg.norm(v)
    R = matrix_from_compact_axis_angle(v)
    if angle > 1e-6:
        np.testing.assert_allclose(matrix_from_axis_angle(v / angle, angle), R, atol=1e-9)
    else:
        np.testing.assert_allclose(R, np.eye(3), atol=1e-5)


def test_per_row_axes_and_rotation_vectors_from_matrices() -> None:
    rng = np.random.default_rng(3)
    axes = rng.normal(size=(50, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = rng.uniform(-np.pi, np.pi, 50)
    R = matrix_from_unit_axis_angle(axes, angles)
    for k in range(50):
        np.testing.assert_allclose(R[k], matrix_from_axis_angle(axes[k], angles[k]), atol=1e-12)
    back = compact_axis_angle_from_matrix(R)
    np.testing.assert_allclose(matrix_from_compact_axis_angle(back), R, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(back, axis=1), np.abs(angles), atol=1e-9)
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        matrix_from_unit_axis_angle(np.ones(4), 0.1)
    with pytest.raises(ValueError, match=r"\(\.\.\., 3, 3\)"):
        compact_axis_angle_from_matrix(np.eye(4))


def test_rotations_about_a_coordinate_axis() -> None:
    rng = np.random.default_rng(11)
    angles = rng.uniform(-np.pi, np.pi, (4, 5))
    for basis in range(3):
        R = matrix_from_angle(basis, angles)
        assert R.shape == (4, 5, 3, 3)
        np.testing.assert_allclose(R, matrix_from_axis_angle(np.eye(3)[basis], angles),
                                   atol=1e-12)
        c = R[..., (basis + 1) % 3, (basis + 1) % 3]
        np.testing.assert_array_equal(c, np.cos(angles))      # exact, not Rodrigues-rounded
    np.testing.assert_array_equal(matrix_from_yaw(angles), matrix_from_angle(2, angles))
    with pytest.raises(ValueError, match=r"0, 1 or 2.*got 3"):
        matrix_from_angle(3, 0.1)


def test_yaw_euler_and_frames() -> None:
    yaw = np.array([0.3, -1.2, 2.9])
    Rz = matrix_from_yaw(yaw)
    np.testing.assert_allclose(Rz, matrix_from_axis_angle([0, 0, 1], yaw), atol=1e-12)
    np.testing.assert_allclose(Rz, matrix_from_euler(np.degrees(yaw)[:, None], "Z"), atol=1e-12)
    np.testing.assert_allclose(matrix_from_quaternion(quaternion_from_yaw(0.7)),
                               matrix_from_yaw(0.7), atol=1e-12)
    R = matrix_from_euler([30.0, 20.0, 10.0], "ZYX")
    expected = (matrix_from_axis_angle([0, 0, 1], np.radians(30))
                @ matrix_from_axis_angle([0, 1, 0], np.radians(20))
                @ matrix_from_axis_angle([1, 0, 0], np.radians(10)))
    np.testing.assert_allclose(R, expected, atol=1e-12)
    p = np.random.default_rng(0).normal(size=(5, 3))
    np.testing.assert_array_equal(zup_from_yup(p), p @ ZUP_FROM_YUP.T)   # one frame change
    np.testing.assert_allclose(MOCAP_FROM_ZUP @ [1.0, 0.0, 0.0], [0, 0, 1])  # faces +z
    np.testing.assert_allclose(MOCAP_FROM_ZUP @ [0.0, 0.0, 1.0], [0, 1, 0])  # y up
    with pytest.raises(ValueError, match=r"\(3, 3\)"):
        quaternion_from_matrix(np.eye(4))
    with pytest.raises(ValueError, match="zero length"):
        matrix_from_quaternion(np.zeros(4))


def test_bounded_cache_keys_by_owner_identity_and_drops_the_oldest() -> None:
    cache: BoundedCache[int] = BoundedCache(2)
    a, b = [1], [1]                                  # equal, not identical
    assert cache.get_or_build("k", lambda: 10, owner=a) == 10
    assert cache.get_or_build("k", lambda: 20, owner=b) == 20
    assert cache.get("k", owner=a) == 10 and cache.get("k", owner=b) == 20
    cache.put("other", 30)
    assert len(cache) == 2 and cache.get("k", owner=a) is None     # the oldest went
    assert cache.get_or_build("other", lambda: 99) == 30
    with pytest.raises(ValueError, match="maxsize"):
        BoundedCache(0)
