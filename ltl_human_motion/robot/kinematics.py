"""Forward kinematics and collision capsules of Universal Robots e-Series arms.

Standard Denavit-Hartenberg parameters as published by Universal Robots; link ``i``
transforms as ``Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``. Poses from :func:`tcp_pose` are in
the robot's base frame, as the controller reports ``actual_TCP_pose``; capsules from
:func:`robot_capsules` are in the cell's world frame (z up, metres) through the base pose.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ltl_human_motion.kernel.rotations import compact_axis_angle_from_matrix

__all__ = [
    "UR_MODELS",
    "URModel",
    "forward_kinematics",
    "pose_from_xyz_rpy",
    "robot_capsules",
    "tcp_pose",
    "ur_model",
]

_ALPHA = (np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0)


@dataclass(frozen=True)
class URModel:
    """Geometry of one arm model.

    Attributes
    ----------
    name : str
        ``"ur3e"``, ``"ur5e"``, ``"ur10e"``, ``"ur16e"`` or a custom name.
    d, a, alpha : tuple of 6 float
        DH offsets (m), lengths (m) and twists (rad).
    link_radii : tuple of 7 float
        Capsule radii (m) of base, upper arm, forearm, wrist 1, wrist 2, wrist 3 and tool.
    tool_length : float
        Length (m) of the tool capsule along the flange z axis (0 for a bare flange).
    """

    name: str
    d: tuple[float, ...]
    a: tuple[float, ...]
    alpha: tuple[float, ...] = _ALPHA
    link_radii: tuple[float, ...] = (0.08, 0.065, 0.055, 0.045, 0.045, 0.045, 0.05)
    tool_length: float = 0.15
    _dh: NDArray[np.float64] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for label, values, n in (("d", self.d, 6), ("a", self.a, 6), ("alpha", self.alpha, 6),
                                 ("link_radii", self.link_radii, 7)):
            arr = np.asarray(values, dtype=np.float64)
            if arr.shape != (n,) or not np.all(np.isfinite(arr)):
                raise ValueError(f"URModel.{label}: expected {n} finite numbers, got {values!r}")
        if min(self.link_radii) < 0 or not np.isfinite(self.tool_length) \
                or self.tool_length < 0:
            raise ValueError("URModel: radii and tool_length must be finite and >= 0")
        object.__setattr__(self, "_dh", np.array([self.d, self.a, self.alpha], dtype=np.float64))

    def with_tool(self, length: float, radius: float) -> URModel:
        """The same arm with another tool capsule."""
        radii = (*self.link_radii[:6], float(radius))
        return URModel(self.name, self.d, self.a, self.alpha, radii, float(length))


UR_MODELS: dict[str, URModel] = {
    "ur3e": URModel("ur3e", (0.15185, 0, 0, 0.13105, 0.08535, 0.0921),
                    (0, -0.24355, -0.2132, 0, 0, 0),
                    link_radii=(0.065, 0.055, 0.045, 0.038, 0.038, 0.038, 0.045)),
    "ur5e": URModel("ur5e", (0.1625, 0, 0, 0.1333, 0.0997, 0.0996),
                    (0, -0.425, -0.3922, 0, 0, 0)),
    "ur10e": URModel("ur10e", (0.1807, 0, 0, 0.17415, 0.11985, 0.11655),
                     (0, -0.6127, -0.57155, 0, 0, 0),
                     link_radii=(0.1, 0.085, 0.07, 0.055, 0.055, 0.055, 0.055)),
    "ur16e": URModel("ur16e", (0.1807, 0, 0, 0.17415, 0.11985, 0.11655),
                     (0, -0.4784, -0.36, 0, 0, 0),
                     link_radii=(0.1, 0.085, 0.07, 0.055, 0.055, 0.055, 0.055)),
}


def ur_model(name: str | URModel) -> URModel:
    """The model called ``name`` (case-insensitive); a :class:`URModel` passes through."""
    if isinstance(name, URModel):
        return name
    key = str(name).lower()
    if key not in UR_MODELS:
        raise ValueError(f"unknown UR model {name!r}; expected one of {sorted(UR_MODELS)}")
    return UR_MODELS[key]


def _joints(q: ArrayLike) -> NDArray[np.float64]:
    q = np.asarray(q, dtype=np.float64)
    if q.ndim < 1 or q.shape[-1] != 6:
        raise ValueError(f"joint positions: expected shape (..., 6), got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise ValueError("joint positions contain NaN or inf")
    return q


def forward_kinematics(q: ArrayLike, model: str | URModel = "ur5e") -> NDArray[np.float64]:
    """Frames of all links in the base frame.

    Parameters
    ----------
    q : array-like, shape (..., 6)
        Joint positions (rad).
    model : str or URModel

    Returns
    -------
    frames : ndarray, shape (..., 7, 4, 4)
        ``frames[..., 0]`` is the base (identity), ``frames[..., i]`` the frame after joint
        ``i`` (DH frame ``i``); ``frames[..., 6]`` is the flange (tool0).
    """
    m = ur_model(model)
    q = _joints(q)
    d, a, alpha = m._dh
    ct, st = np.cos(q), np.sin(q)
    ca, sa = np.cos(alpha), np.sin(alpha)
    links = np.zeros((*q.shape, 4, 4))
    links[..., 0, 0] = ct
    links[..., 0, 1] = -st * ca
    links[..., 0, 2] = st * sa
    links[..., 0, 3] = a * ct
    links[..., 1, 0] = st
    links[..., 1, 1] = ct * ca
    links[..., 1, 2] = -ct * sa
    links[..., 1, 3] = a * st
    links[..., 2, 1] = sa
    links[..., 2, 2] = ca
    links[..., 2, 3] = d
    links[..., 3, 3] = 1.0
    frames = np.empty((*q.shape[:-1], 7, 4, 4))
    frames[..., 0, :, :] = np.eye(4)
    for i in range(6):
        frames[..., i + 1, :, :] = frames[..., i, :, :] @ links[..., i, :, :]
    return frames


def tcp_pose(q: ArrayLike, model: str | URModel = "ur5e") -> NDArray[np.float64]:
    """Flange pose ``[x, y, z, rx, ry, rz]`` in the base frame (UR's ``actual_TCP_pose``).

    Parameters
    ----------
    q : array-like, shape (..., 6)
    model : str or URModel

    Returns
    -------
    pose : ndarray, shape (..., 6)
        Position (m) and rotation vector (rad).
    """
    flange = forward_kinematics(q, model)[..., 6, :, :]
    rotvec = compact_axis_angle_from_matrix(flange[..., :3, :3])
    return np.concatenate([flange[..., :3, 3], rotvec], axis=-1)


def pose_from_xyz_rpy(xyz: ArrayLike = (0.0, 0.0, 0.0),
                      rpy: ArrayLike = (0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    """Homogeneous transform (4, 4) from a position and roll-pitch-yaw (rad, fixed XYZ)."""
    p = np.asarray(xyz, dtype=np.float64)
    r = np.asarray(rpy, dtype=np.float64)
    if p.shape != (3,) or r.shape != (3,) or not (np.all(np.isfinite(p))
                                                   and np.all(np.isfinite(r))):
        raise ValueError(f"base pose: expected finite xyz (3,) and rpy (3,), got {xyz}, {rpy}")
    cr, sr = np.cos(r[0]), np.sin(r[0])
    cp, sp = np.cos(r[1]), np.sin(r[1])
    cy, sy = np.cos(r[2]), np.sin(r[2])
    T = np.eye(4)
    T[:3, :3] = np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                          [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                          [-sp, cp * sr, cp * cr]])
    T[:3, 3] = p
    return T


def robot_capsules(q: ArrayLike, model: str | URModel = "ur5e",
                   base: ArrayLike | None = None
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Collision capsules of the arm (7 links: base to tool) in the world frame.

    Parameters
    ----------
    q : array-like, shape (..., 6)
        Joint positions (rad).
    model : str or URModel
    base : array-like, shape (4, 4), optional
        World-from-base transform (default identity).

    Returns
    -------
    segments : ndarray, shape (..., 7, 2, 3)
        Capsule axis end points (m).
    radii : ndarray, shape (7,)
    """
    m = ur_model(model)
    frames = forward_kinematics(q, m)
    if base is not None:
        B = np.asarray(base, dtype=np.float64)
        if B.shape != (4, 4) or not np.all(np.isfinite(B)):
            raise ValueError(f"base: expected a finite (4, 4) transform, got shape {B.shape}")
        frames = B @ frames
    origins = frames[..., :3, 3]  # (..., 7, 3)
    tool_tip = origins[..., 6, :] + m.tool_length * frames[..., 6, :3, 2]
    starts = origins
    ends = np.concatenate([origins[..., 1:, :], tool_tip[..., None, :]], axis=-2)
    segments = np.stack([starts, ends], axis=-2)
    return segments, np.asarray(m.link_radii, dtype=np.float64)
