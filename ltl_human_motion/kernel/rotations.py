"""Rotations on arrays, with pytransform3d's names (``<target>_from_<source>``).

Quaternions are scalar first, (w, x, y, z), as in pytransform3d; ROS messages, which are
scalar last, convert at the ROS edge. Frames: REP 103 (z up); the paper's and the
motion-capture y-up frames have their matrices here, once.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "MOCAP_FROM_ZUP",
    "ZUP_FROM_MOCAP",
    "ZUP_FROM_YUP",
    "compact_axis_angle_from_matrix",
    "matrix_from_angle",
    "matrix_from_axis_angle",
    "matrix_from_compact_axis_angle",
    "matrix_from_euler",
    "matrix_from_quaternion",
    "matrix_from_unit_axis_angle",
    "matrix_from_yaw",
    "quaternion_from_matrix",
    "quaternion_from_yaw",
]

#: Rotation taking the paper's y-up vectors (x forward) to our z-up vectors (REP 103),
#: (x, y, z) -> (x, -z, y): +90 degrees about x. Shape (3, 3).
ZUP_FROM_YUP = np.array([[1.0, 0.0, 0.0],
                         [0.0, 0.0, -1.0],
                         [0.0, 1.0, 0.0]])

#: Rotation taking our z-up, x-forward vectors to the motion-capture convention of BVH
#: files (y up, facing +z): (x, y, z) -> (y, z, x). Shape (3, 3).
MOCAP_FROM_ZUP = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
#: Its inverse, from BVH/ASF motion capture (y up, facing +z) to z up: (x, y, z) -> (z, x, y).
ZUP_FROM_MOCAP = MOCAP_FROM_ZUP.T.copy()


def matrix_from_quaternion(q: ArrayLike) -> NDArray[np.float64]:
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


def quaternion_from_matrix(R: ArrayLike) -> NDArray[np.float64]:
    """The unit quaternion (w, x, y, z), shape (4,), of a rotation matrix (3, 3).

    Shepperd's method: the largest of the four diagonal combinations is the pivot, so the
    division is never by a small number.
    """
    m = np.asarray(R, dtype=np.float64)
    if m.shape != (3, 3):
        raise ValueError(f"rotation matrix must have shape (3, 3), got {m.shape}")
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * math.sqrt(trace + 1.0)
        w, x = 0.25 * s, (m[2, 1] - m[1, 2]) / s
        y, z = (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        w, x = (m[2, 1] - m[1, 2]) / s, 0.25 * s
        y, z = (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        w, x = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s
        y, z = 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        w, x = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s
        y, z = (m[1, 2] + m[2, 1]) / s, 0.25 * s
    return np.array([w, x, y, z])


def quaternion_from_yaw(yaw: float) -> NDArray[np.float64]:
    """The quaternion (w, x, y, z), shape (4,), of a rotation by ``yaw`` about +z."""
    return np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)])


def matrix_from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices about one fixed ``axis`` (3,) by ``angle`` (...,) radians.

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


def matrix_from_unit_axis_angle(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices about unit axes by angles, by Rodrigues' formula.

    Parameters
    ----------
    axis : array-like, shape (..., 3)
        Unit vectors (not normalized here).
    angle : array-like, shape (...)
        Radians.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
    """
    k = np.asarray(axis, dtype=np.float64)
    if k.shape[-1:] != (3,):
        raise ValueError(f"rotation axes: expected shape (..., 3), got {k.shape}")
    x, y, z = k[..., 0], k[..., 1], k[..., 2]
    zero = np.zeros_like(x)
    K = np.stack([np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1),
                  np.stack([-y, x, zero], -1)], -2)
    angle = np.asarray(angle, dtype=np.float64)
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def matrix_from_compact_axis_angle(rotvec: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices of rotation vectors (axis times angle), by Rodrigues' formula.

    Parameters
    ----------
    rotvec : array-like, shape (..., 3)

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
    """
    v = np.asarray(rotvec, dtype=np.float64)
    if v.shape[-1:] != (3,):
        raise ValueError(f"rotation vectors: expected shape (..., 3), got {v.shape}")
    angle = np.linalg.norm(v, axis=-1)
    safe = np.where(angle > 1e-12, angle, 1.0)
    return matrix_from_unit_axis_angle(v / safe[..., None], angle)


def compact_axis_angle_from_matrix(R: ArrayLike) -> NDArray[np.float64]:
    """Rotation vectors (axis times angle, UR's ``rx, ry, rz``) of rotation matrices.

    Parameters
    ----------
    R : array-like, shape (..., 3, 3)

    Returns
    -------
    rotvec : ndarray, shape (..., 3)
        Angle in [0, pi].
    """
    R = np.asarray(R, dtype=np.float64)
    if R.shape[-2:] != (3, 3):
        raise ValueError(f"rotation matrices: expected shape (..., 3, 3), got {R.shape}")
    trace = np.trace(R, axis1=-2, axis2=-1)
    angle = np.arccos(np.clip((trace - 1.0) / 2.0, -1.0, 1.0))
    skew = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                     R[..., 1, 0] - R[..., 0, 1]], axis=-1)
    sin = np.sin(angle)
    out = np.zeros((*R.shape[:-2], 3))
    regular = sin > 1e-6
    out[regular] = (skew[regular] * (angle[regular] / (2.0 * sin[regular]))[..., None])
    near_pi = ~regular & (angle > 1.0)
    if np.any(near_pi):
        Rp = R[near_pi]
        diag = np.clip((np.diagonal(Rp, axis1=-2, axis2=-1) + 1.0) / 2.0, 0.0, None)
        k = np.argmax(diag, axis=-1)
        # At angle pi, R = 2 a a^T - I, so row k of (R + I) / 2 is a_k * a.
        axis = (Rp[np.arange(len(Rp)), k] + np.eye(3)[k]) / 2.0
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        out[near_pi] = axis * angle[near_pi][..., None]
    return out


def matrix_from_angle(basis: int, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices about the coordinate axis ``basis`` (0: x, 1: y, 2: z).

    The entries are the angle's cosine and sine themselves (pytransform3d's
    ``active_matrix_from_angle``), exact where Rodrigues' formula rounds.

    Parameters
    ----------
    basis : int
        0, 1 or 2.
    angle : array-like, shape (...)
        Radians.

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
    """
    if basis not in (0, 1, 2):
        raise ValueError(f"rotation basis: expected 0, 1 or 2 (x, y, z), got {basis!r}")
    angle = np.asarray(angle, dtype=np.float64)
    c, s = np.cos(angle), np.sin(angle)
    i, j = (basis + 1) % 3, (basis + 2) % 3
    out = np.zeros((*angle.shape, 3, 3))
    out[..., basis, basis] = 1.0
    out[..., i, i] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    out[..., j, j] = c
    return out


def matrix_from_yaw(yaw: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices about +z, shape (..., 3, 3) for ``yaw`` (radians) of shape (...)."""
    return matrix_from_angle(2, yaw)


_AXES = {"X": np.array([1.0, 0, 0]), "Y": np.array([0, 1.0, 0]), "Z": np.array([0, 0, 1.0])}


def matrix_from_euler(angles_deg: ArrayLike, order: str) -> NDArray[np.float64]:
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
