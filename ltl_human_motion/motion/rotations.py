"""Heading helpers of skeleton poses; the rotation conversions live in
:mod:`ltl_human_motion.kernel.rotations` (re-exported here for old imports)."""

from __future__ import annotations

import numpy as np

from ltl_human_motion.kernel.rotations import (
    matrix_from_axis_angle,
    matrix_from_euler,
    matrix_from_quaternion,
)

__all__ = [
    "matrix_from_axis_angle",
    "matrix_from_euler",
    "matrix_from_quaternion",
    "unwrap_angles",
    "yaw_from_positions",
]


def yaw_from_positions(positions: np.ndarray) -> np.ndarray:
    """Heading (yaw about +z) of canonical-skeleton poses.

    The forward direction is perpendicular to the sum of the hip and shoulder left-right
    axes, projected on the floor (0 when facing +x).

    Parameters
    ----------
    positions : array-like, shape (..., J, 3)

    Returns
    -------
    yaw : ndarray, shape (...)
    """
    from ltl_human_motion.motion.skeleton import JOINT_INDEX as J

    p = np.asarray(positions, dtype=np.float64)
    lateral = (p[..., J["l_hip"], :] - p[..., J["r_hip"], :]
               + p[..., J["l_shoulder"], :] - p[..., J["r_shoulder"], :])
    return np.arctan2(-lateral[..., 0], lateral[..., 1])


def unwrap_angles(angles: np.ndarray) -> np.ndarray:
    """``np.unwrap`` along the first axis (continuous yaw over time)."""
    return np.unwrap(np.asarray(angles, dtype=np.float64), axis=0)
