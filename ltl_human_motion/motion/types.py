"""Motion data types: one place for them, operations live in other modules.

Positions are world-frame joint positions of the canonical skeleton
(:mod:`ltl_human_motion.motion.skeleton`), metres, z up.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.kernel.rotations import matrix_from_yaw
from ltl_human_motion.motion.skeleton import Skeleton


@dataclass(frozen=True, eq=False)
class Motion:
    """A full-body motion sampled at a fixed rate.

    Attributes
    ----------
    positions : ndarray, shape (T, J, 3)
        Joint positions in the world frame (metres, z up).
    fps : float
        Frames per second.
    skeleton : Skeleton
    name : str
    """

    positions: np.ndarray
    fps: float
    skeleton: Skeleton = field(default_factory=Skeleton)
    name: str = ""

    def __post_init__(self) -> None:
        pos = np.asarray(self.positions, dtype=np.float64)
        if pos.ndim != 3 or pos.shape[2] != 3 or pos.shape[1] != self.skeleton.n_joints:
            raise ValueError(
                f"positions must have shape (T, {self.skeleton.n_joints}, 3), got {pos.shape}")
        if not np.all(np.isfinite(pos)):
            raise ValueError("positions contain NaN or infinite values")
        if not (self.fps > 0):
            raise ValueError(f"fps must be positive, got {self.fps!r}")
        object.__setattr__(self, "positions", pos)

    @property
    def n_frames(self) -> int:
        return int(self.positions.shape[0])

    @property
    def duration(self) -> float:
        """Duration in seconds, (T - 1) / fps."""
        return max(self.n_frames - 1, 0) / self.fps

    @property
    def timestamps(self) -> np.ndarray:
        """Frame times in seconds, shape (T,)."""
        return np.arange(self.n_frames) / self.fps

    def joint(self, name: str) -> np.ndarray:
        """Trajectory of one joint, shape (T, 3)."""
        return self.positions[:, self.skeleton.index(name)]


@dataclass(frozen=True, eq=False)
class MotionPrimitive:
    """A motion primitive ``mp = (M, B, ta)`` (Definition 1 of the paper).

    Attributes
    ----------
    name : str
        Unique within a library, e.g. ``"walk_forward_m0_s3"``.
    task : str
        The Table I task name: ``"walk"``, ``"carry"`` (gait primitives) or a goal task
        such as ``"grasp"``.
    poses : ndarray, shape (T, J, 3)
        ``M``: joint positions relative to the root (pelvis) position, expressed in the
        root's heading frame (yaw removed; pelvis tilt stays in the pose).
    root : ndarray, shape (T, 4)
        ``B``: root x, y, z and heading yaw (radians, about +z) in the primitive's start
        frame; ``root[0] == (0, 0, z0, 0)``. Roll and pitch of the pelvis are carried by
        ``poses``, so only the heading is needed to place a primitive.
    fps : float
    source : str
        Where it came from: a clip path and frame range, or a generator and its target.
    meta : dict
        Free-form extra data (e.g. the hand target of a goal primitive).
    """

    name: str
    task: str
    poses: np.ndarray
    root: np.ndarray
    fps: float
    source: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        poses = np.asarray(self.poses, dtype=np.float64)
        root = np.asarray(self.root, dtype=np.float64)
        if poses.ndim != 3 or poses.shape[2] != 3:
            raise ValueError(f"poses must have shape (T, J, 3), got {poses.shape}")
        if root.shape != (poses.shape[0], 4):
            raise ValueError(f"root must have shape ({poses.shape[0]}, 4), got {root.shape}")
        object.__setattr__(self, "poses", poses)
        object.__setattr__(self, "root", root)

    @property
    def n_frames(self) -> int:
        return int(self.poses.shape[0])

    @property
    def duration(self) -> float:
        return (self.n_frames - 1) / self.fps


yaw_matrix = matrix_from_yaw
"""Old name of :func:`ltl_human_motion.kernel.rotations.matrix_from_yaw`."""


def world_positions(primitive: MotionPrimitive, x: float = 0.0, y: float = 0.0,
                    yaw: float = 0.0, frames: np.ndarray | None = None) -> np.ndarray:
    """World joint positions of ``primitive`` started at floor pose (x, y, yaw).

    Parameters
    ----------
    primitive : MotionPrimitive
    x, y, yaw : float
    frames : array-like of int, shape (F,), optional
        Only these frames (the same values as the full result's rows).

    Returns
    -------
    positions : ndarray, shape (T, J, 3) or (F, J, 3)
    """
    root, poses = primitive.root, primitive.poses
    if frames is not None:
        root, poses = root[frames], poses[frames]
    return place_poses(root, poses, x, y, yaw)


def place_poses(root: np.ndarray, poses: np.ndarray, x: float = 0.0, y: float = 0.0,
                yaw: float = 0.0) -> np.ndarray:
    """World joint positions of frames given by their root and root-relative pose.

    Row by row what :func:`world_positions` computes, for rows gathered from any
    primitives (all placed at the same floor pose).

    Parameters
    ----------
    root : ndarray, shape (T, 4)
        x, y, z, yaw of the root in the start frame.
    poses : ndarray, shape (T, J, 3)
        Root-relative poses in the heading frame.
    x, y, yaw : float

    Returns
    -------
    positions : ndarray, shape (T, J, 3)
    """
    heading = yaw + root[:, 3]
    # The poses turned about z by the heading (yaw_matrix(heading) @ pose, written out),
    # plus the root's floor position turned by ``yaw`` and its height.
    ch, sh = np.cos(heading)[:, None], np.sin(heading)[:, None]     # (T, 1)
    px, py = poses[..., 0], poses[..., 1]                           # (T, J)
    c, s = np.cos(yaw), np.sin(yaw)
    rx = x + c * root[:, 0] - s * root[:, 1]
    ry = y + s * root[:, 0] + c * root[:, 1]
    out = np.empty(poses.shape)
    out[..., 0] = (ch * px - sh * py) + rx[:, None]
    out[..., 1] = (sh * px + ch * py) + ry[:, None]
    out[..., 2] = poses[..., 2] + root[:, 2][:, None]
    return out


def end_pose(primitive: MotionPrimitive, x: float = 0.0, y: float = 0.0,
             yaw: float = 0.0) -> tuple[float, float, float]:
    """Floor pose (x, y, yaw) of the root at the last frame when started at (x, y, yaw)."""
    r = primitive.root[-1]
    c, s = np.cos(yaw), np.sin(yaw)
    return (float(x + c * r[0] - s * r[1]), float(y + s * r[0] + c * r[1]), float(yaw + r[3]))
