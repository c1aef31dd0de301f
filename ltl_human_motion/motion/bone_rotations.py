"""World rotations of the canonical skeleton's joints, derived from joint positions.

A joint with several children (pelvis, chest) gets the rotation that best maps its rest
child offsets onto the current ones (Kabsch); a joint with one child gets the swing that
turns its parent-rotated rest bone onto the current bone, plus a twist about the bone that
aligns a reference direction (legs: the foot, spine: the shoulder line); leaves keep their
parent's rotation. The BVH writer (:func:`ltl_human_motion.motion.bvh.save`) and the
worker's URDF joint angles (:mod:`ltl_human_motion.motion.urdf`) read them.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.kernel.rotations import matrix_from_unit_axis_angle
from ltl_human_motion.motion.skeleton import JOINT_INDEX, JOINT_NAMES, PARENTS, Skeleton

__all__ = ["CHILDREN", "joint_rotations", "kabsch_matrices", "swing_matrices",
           "twist_matrices", "unit_vectors"]

#: The children of every joint of the canonical skeleton, by index.
CHILDREN: tuple[tuple[int, ...], ...] = tuple(
    tuple(c for c, p in enumerate(PARENTS) if p == j) for j in range(len(PARENTS)))
# Twist references: (from joint, to joint) whose direction fixes the twist about a bone.
_TWIST_REF: dict[str, tuple[str, str]] = {
    "l_hip": ("l_ankle", "l_toe"), "l_knee": ("l_ankle", "l_toe"),
    "r_hip": ("r_ankle", "r_toe"), "r_knee": ("r_ankle", "r_toe"),
    "l_ankle": ("l_knee", "l_ankle"), "r_ankle": ("r_knee", "r_ankle"),
    "spine": ("r_clavicle", "l_clavicle"),
}


def unit_vectors(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors (..., 3) of ``v`` (..., 3) and their lengths (...)."""
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, 1e-12), n[..., 0]


def swing_matrices(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Smallest rotations taking unit vectors ``u`` (..., 3) onto ``v`` (..., 3)."""
    cross = np.cross(u, v)
    s = np.linalg.norm(cross, axis=-1)
    c = np.clip(np.sum(u * v, axis=-1), -1.0, 1.0)
    axis = cross / np.maximum(s, 1e-12)[..., None]
    # Anti-parallel: any axis perpendicular to u.
    helper = np.where(np.abs(u[..., :1]) < 0.9, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
    perp, _ = unit_vectors(np.cross(u, helper))
    axis = np.where((s < 1e-9)[..., None], perp, axis)
    angle = np.arctan2(s, c)
    return matrix_from_unit_axis_angle(axis, angle)


def twist_matrices(rot: np.ndarray, bone: np.ndarray, ref_rest: np.ndarray, ref_cur: np.ndarray
           ) -> np.ndarray:
    """Turn ``rot`` about unit ``bone`` so ``rot @ ref_rest`` best matches ``ref_cur``."""
    u = np.einsum("...ij,...j->...i", rot, ref_rest)
    up = u - np.sum(u * bone, axis=-1, keepdims=True) * bone
    wp = ref_cur - np.sum(ref_cur * bone, axis=-1, keepdims=True) * bone
    nu, nw = np.linalg.norm(up, axis=-1), np.linalg.norm(wp, axis=-1)
    angle = np.arctan2(np.sum(bone * np.cross(up, wp), axis=-1), np.sum(up * wp, axis=-1))
    # Fade the twist out as the reference becomes parallel to the bone (ill-defined).
    weight = np.clip((np.minimum(nu, nw) / np.maximum(np.linalg.norm(ref_cur, axis=-1), 1e-12)
                      - 0.15) / 0.2, 0.0, 1.0)
    return matrix_from_unit_axis_angle(bone, angle * weight) @ rot


def kabsch_matrices(rest: np.ndarray, cur: np.ndarray) -> np.ndarray:
    """Rotations (T, 3, 3) best mapping rest vectors (K, 3) onto current ones (T, K, 3)."""
    H = np.einsum("ki,tkj->tij", rest, cur)
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.swapaxes(Vt, -1, -2) @ np.swapaxes(U, -1, -2)))
    D = np.zeros_like(H)
    D[:, 0, 0] = 1.0
    D[:, 1, 1] = 1.0
    D[:, 2, 2] = d
    return np.swapaxes(Vt, -1, -2) @ D @ np.swapaxes(U, -1, -2)


def joint_rotations(positions: np.ndarray, skeleton: Skeleton | None = None) -> np.ndarray:
    """World rotation of every joint per frame, derived from joint positions (z up).

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)
    skeleton : Skeleton, optional
        Gives the rest pose (default: stature 1.75 m).

    Returns
    -------
    rotations : ndarray, shape (T, J, 3, 3)
        ``G[t, j]`` maps rest-pose offsets of ``j``'s children onto their current ones.
    """
    pos = np.asarray(positions, dtype=np.float64)
    skeleton = skeleton or Skeleton()
    if pos.ndim != 3 or pos.shape[1:] != (skeleton.n_joints, 3):
        raise ValueError(f"positions must have shape (T, {skeleton.n_joints}, 3), got {pos.shape}")
    rest = skeleton.rest_positions()
    T, J = pos.shape[:2]
    G = np.zeros((T, J, 3, 3))
    for j in range(J):
        parent = PARENTS[j]
        base = G[:, parent] if parent >= 0 else np.broadcast_to(np.eye(3), (T, 3, 3))
        kids = CHILDREN[j]
        if len(kids) >= 2:
            G[:, j] = kabsch_matrices(rest[list(kids)] - rest[j],
                                      pos[:, list(kids)] - pos[:, j:j + 1])
        elif len(kids) == 1:
            c = kids[0]
            rest_dir, _ = unit_vectors(rest[c] - rest[j])
            cur_dir, _ = unit_vectors(pos[:, c] - pos[:, j])
            moved = np.einsum("tij,j->ti", base, rest_dir)
            rot = swing_matrices(moved, cur_dir) @ base
            ref = _TWIST_REF.get(JOINT_NAMES[j])
            if ref is not None:
                a, b = JOINT_INDEX[ref[0]], JOINT_INDEX[ref[1]]
                rot = twist_matrices(rot, cur_dir, rest[b] - rest[a], pos[:, b] - pos[:, a])
            G[:, j] = rot
        else:
            G[:, j] = base
    return G
