"""Free functions on motions: root/pose decomposition, resampling, primitives from clips."""

from __future__ import annotations

import numpy as np

from ltl_human_motion.kernel.rotations import matrix_from_yaw
from ltl_human_motion.motion.rotations import unwrap_angles, yaw_from_positions

__all__ = [
    "compose",
    "decompose",
    "poses_from_world",
    "relative_root",
    "resample_positions",
]


def decompose(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Split world positions into a root track and root-relative heading-frame poses.

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)

    Returns
    -------
    root : ndarray, shape (T, 4)
        Pelvis x, y, z and heading yaw (unwrapped over time).
    poses : ndarray, shape (T, J, 3)
        Joint positions minus the pelvis, rotated by minus the heading.
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 3 or p.shape[-1] != 3:
        raise ValueError(f"positions must have shape (T, J, 3), got {p.shape}")
    yaw = unwrap_angles(yaw_from_positions(p))
    rel = p - p[:, :1, :]
    poses = np.einsum("tji,tkj->tki", matrix_from_yaw(yaw), rel)  # R^T @ rel
    root = np.concatenate([p[:, 0, :], yaw[:, None]], axis=1)
    return root, poses


def compose(root: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Inverse of :func:`decompose`: world positions (T, J, 3) from root (T, 4) and poses."""
    root = np.asarray(root, dtype=np.float64)
    rot = matrix_from_yaw(root[:, 3])
    return np.einsum("tij,tkj->tki", rot, poses) + root[:, None, :3]


def poses_from_world(positions: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Root-relative poses (T, J, 3) of world positions for a given heading track (T,)."""
    p = np.asarray(positions, dtype=np.float64)
    return np.einsum("tji,tkj->tki", matrix_from_yaw(np.asarray(yaw, dtype=np.float64)),
                     p - p[:, :1, :])


def relative_root(root: np.ndarray) -> np.ndarray:
    """Express a root track (T, 4) in the floor frame of its first frame."""
    root = np.asarray(root, dtype=np.float64)
    x0, y0, yaw0 = root[0, 0], root[0, 1], root[0, 3]
    c, s = np.cos(yaw0), np.sin(yaw0)
    dx, dy = root[:, 0] - x0, root[:, 1] - y0
    out = root.copy()
    out[:, 0] = c * dx + s * dy
    out[:, 1] = -s * dx + c * dy
    out[:, 3] = root[:, 3] - yaw0
    return out




def resample_positions(values: np.ndarray, fps_in: float, fps_out: float,
                       periodic: bool = False) -> np.ndarray:
    """Resample a time series with a cubic spline.

    Parameters
    ----------
    values : array-like, shape (T, ...)
    fps_in, fps_out : float
    periodic : bool
        Treat ``values[-1]`` as equal to ``values[0]`` (a looping clip whose last frame
        repeats the first); the result then covers one period without the repeated end.

    Returns
    -------
    ndarray, shape (T', ...)
    """
    from scipy.interpolate import CubicSpline

    v = np.asarray(values, dtype=np.float64)
    if v.shape[0] < 2:
        raise ValueError("need at least 2 frames to resample")
    if not (fps_in > 0 and fps_out > 0):
        raise ValueError(f"frame rates must be positive, got {fps_in}, {fps_out}")
    t_in = np.arange(v.shape[0]) / fps_in
    duration = t_in[-1]
    n_out = round(duration * fps_out) + (0 if periodic else 1)
    t_out = np.arange(n_out) / fps_out
    flat = v.reshape(v.shape[0], -1)
    if periodic:
        flat = flat.copy()
        flat[-1] = flat[0]
        spline = CubicSpline(t_in, flat, axis=0, bc_type="periodic")
    else:
        spline = CubicSpline(t_in, flat, axis=0)
    return spline(np.minimum(t_out, duration)).reshape((n_out, *v.shape[1:]))
