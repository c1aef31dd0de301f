"""Rotation helpers on arrays (pytransform3d naming: ``<target>_from_<source>``)."""

from __future__ import annotations

import numpy as np

__all__ = [
    "matrix_from_axis_angle",
    "matrix_from_euler",
    "matrix_from_quaternion",
    "unwrap_angles",
    "yaw_from_positions",
]


def matrix_from_quaternion(q: np.ndarray) -> np.ndarray:
    """Rotation matrices from unit quaternions in (w, x, y, z) order.

    Parameters
    ----------
    q : array-like, shape (..., 4)
        Quaternions, scalar first; they are normalized here.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
    """
    q = np.asarray(q, dtype=np.float64)
    if q.shape[-1:] != (4,):
        raise ValueError(f"quaternions must have shape (..., 4), got {q.shape}")
    norm = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(norm < 1e-9):
        raise ValueError("quaternion of zero length")
    w, x, y, z = np.moveaxis(q / norm, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def matrix_from_axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices about a fixed unit ``axis`` (3,) by ``angle`` (...,) radians.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
    """
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    angle = np.asarray(angle, dtype=np.float64)
    half = 0.5 * angle
    q = np.concatenate([np.cos(half)[..., None], np.sin(half)[..., None] * axis], axis=-1)
    return matrix_from_quaternion(q)


_AXES = {"X": np.array([1.0, 0, 0]), "Y": np.array([0, 1.0, 0]), "Z": np.array([0, 0, 1.0])}


def matrix_from_euler(angles_deg: np.ndarray, order: str) -> np.ndarray:
    """Rotation matrices from intrinsic Euler angles as used by BVH and AMC files.

    ``order`` such as ``"ZYX"`` means ``R = Rz(a0) @ Ry(a1) @ Rx(a2)``
    (the channel order of a BVH joint).

    Parameters
    ----------
    angles_deg : array-like, shape (..., len(order))
        Angles in degrees.
    order : str
        Axis letters, each of X, Y, Z.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
    """
    a = np.deg2rad(np.asarray(angles_deg, dtype=np.float64))
    order = order.upper()
    if a.shape[-1:] != (len(order),) or any(c not in _AXES for c in order):
        raise ValueError(f"angles of shape (..., {len(order)}) and axes from XYZ expected, "
                         f"got {a.shape} and {order!r}")
    out = np.broadcast_to(np.eye(3), (*a.shape[:-1], 3, 3)).copy()
    for k, c in enumerate(order):
        out = out @ matrix_from_axis_angle(_AXES[c], a[..., k])
    return out


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
