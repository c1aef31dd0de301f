"""occ(x): the body as a set of capsules, one per segment of the canonical skeleton
(the table and its radii: :mod:`ltl_human_motion.motion.capsules`). The floor is not part
of O(t): the feet stand on it.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ltl_human_motion.motion.capsules import capsule_ends, capsule_radii, part_indices
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, N_JOINTS

__all__ = [
    "body_boxes",
    "body_radius_xy",
    "capsules_from_positions",
    "occ",
]

_IA, _IB = capsule_ends()
_IAB = np.stack([_IA, _IB], axis=-1).ravel()       # end points a0, b0, a1, b1, ...


def capsules_from_positions(positions: np.ndarray, stature: float = DEFAULT_STATURE,
                            parts: str | Iterable[str] | None = None
                            ) -> tuple[np.ndarray, np.ndarray]:
    """The capsules occupied by the body: occ(x) (or occ(x, BP) with ``parts``).

    Parameters
    ----------
    positions : array-like, shape (..., J, 3)
        Joint positions of the canonical skeleton (world frame).
    stature : float
        Worker height in metres (scales the radii).
    parts : str or iterable of str, optional
        Body parts to keep (default: all).

    Returns
    -------
    segments : ndarray, shape (..., K, 2, 3)
        Capsule axis end points.
    radii : ndarray, shape (K,)
    """
    pos = np.asarray(positions, dtype=np.float64)
    if pos.ndim < 2 or pos.shape[-2:] != (N_JOINTS, 3):
        raise ValueError(f"positions must have shape (..., {N_JOINTS}, 3), got {pos.shape}")
    if parts is None:
        ends, radii = _IAB, capsule_radii(stature)
    else:
        idx = part_indices(parts)
        ends, radii = np.stack([_IA[idx], _IB[idx]], axis=-1).ravel(), capsule_radii(stature)[idx]
    # One gather of both end points of every capsule: (..., 2K, 3) -> (..., K, 2, 3).
    segments = np.take(pos, ends, axis=-2).reshape(*pos.shape[:-2], -1, 2, 3)
    return segments, radii


_BOX_JOINTS = np.unique(_IAB)                        # joints that end a capsule


def body_boxes(positions: np.ndarray, stature: float = DEFAULT_STATURE
               ) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned box of the whole occ(x), per frame.

    The same numbers as the least and greatest capsule end point coordinate less and plus
    its capsule's radius (:func:`capsules_from_positions`), taken per joint with the
    largest radius of the capsules the joint ends.

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)
        Joint positions of the canonical skeleton.
    stature : float

    Returns
    -------
    lo, hi : ndarray, shape (T, 3)
    """
    pos = np.asarray(positions, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[1:] != (N_JOINTS, 3):
        raise ValueError(f"positions must have shape (T, {N_JOINTS}, 3), got {pos.shape}")
    radius = np.full(N_JOINTS, -np.inf)
    np.maximum.at(radius, _IAB, np.repeat(capsule_radii(stature), 2))
    first, *rest = _BOX_JOINTS.tolist()
    lo = pos[:, first] - radius[first]
    hi = pos[:, first] + radius[first]
    for j in rest:                  # elementwise over (T, 3), one joint at a time: fast
        np.minimum(lo, pos[:, j] - radius[j], out=lo)
        np.maximum(hi, pos[:, j] + radius[j], out=hi)
    return lo, hi


def occ(positions: np.ndarray, parts: str | Iterable[str] | None = None,
        stature: float = DEFAULT_STATURE) -> tuple[np.ndarray, np.ndarray]:
    """Alias of :func:`capsules_from_positions` with the paper's argument order."""
    return capsules_from_positions(positions, stature=stature, parts=parts)


def body_radius_xy(stature: float = DEFAULT_STATURE) -> float:
    """Radius of a vertical cylinder around the pelvis that holds the standing rest pose.

    Useful as the disc radius of floor-plane planning (:meth:`Cell.segment_blocked`).
    """
    from ltl_human_motion.motion.skeleton import Skeleton
    rest = Skeleton(stature=stature).rest_positions()
    seg, rad = capsules_from_positions(rest, stature)
    pts = seg.reshape(-1, 3)[:, :2] - rest[JOINT_INDEX["pelvis"], :2]
    return float(np.max(np.linalg.norm(pts, axis=-1) + np.repeat(rad, 2)))
