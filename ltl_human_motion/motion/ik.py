"""Analytic inverse kinematics and body-model helpers on the canonical skeleton."""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.skeleton import JOINT_INDEX

__all__ = ["SEGMENT_MASS", "center_of_mass", "min_jerk", "two_bone_ik"]


def two_bone_ik(base: np.ndarray, target: np.ndarray, l1: float, l2: float,
                pole: np.ndarray, max_stretch: float = 0.999,
                max_flexion: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Place the middle joint of a two-bone chain (arm or leg) analytically.

    Parameters
    ----------
    base : array-like, shape (..., 3)
        Shoulder or hip.
    target : array-like, shape (..., 3)
        Wanted end point (wrist or ankle).
    l1, l2 : float
        Upper and lower bone lengths.
    pole : array-like, shape (..., 3)
        Direction the middle joint (elbow or knee) should bend towards.
    max_stretch : float
        The chain is never straighter than this fraction of ``l1 + l2``; a target further
        away is pulled in along the base-target line.
    max_flexion : float, optional
        The chain never folds further than this angle between its bones (radians; 0 is
        straight); a target nearer the base is pushed out along the base-target line.

    Returns
    -------
    middle : ndarray, shape (..., 3)
    end : ndarray, shape (..., 3)
        Reached end point (the target unless it was out of reach).
    """
    base = np.asarray(base, dtype=np.float64)
    target = np.asarray(target, dtype=np.float64)
    pole = np.asarray(pole, dtype=np.float64)
    dmin = abs(l1 - l2) + 1e-6
    if max_flexion is not None:
        dmin = max(dmin, float(np.sqrt(l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * np.cos(max_flexion))))
    dmax = max_stretch * (l1 + l2)
    compiled = _compiled_chains(base, target, pole, l1, l2, dmin, dmax)
    if compiled is not None:
        return compiled
    v = target - base
    dist = np.linalg.norm(v, axis=-1, keepdims=True)
    u = v / np.maximum(dist, 1e-9)
    d = np.clip(dist, dmin, dmax)
    end = base + u * d
    # distance along u of the middle joint, and its offset from the line
    a = (l1 * l1 - l2 * l2 + d * d) / (2 * d)
    h = np.sqrt(np.maximum(l1 * l1 - a * a, 0.0))
    p = pole - np.sum(pole * u, axis=-1, keepdims=True) * u
    pn = np.linalg.norm(p, axis=-1, keepdims=True)
    # fall back to any perpendicular when the pole is parallel to the chain
    if np.all(pn > 1e-9):
        p = p / np.maximum(pn, 1e-12)
    else:
        alt = np.cross(u, np.array([0.0, 1.0, 0.0]))
        p = np.where(pn > 1e-9, p / np.maximum(pn, 1e-12), alt / np.maximum(
            np.linalg.norm(alt, axis=-1, keepdims=True), 1e-12))
    middle = base + u * a + p * h
    return middle, end


def _compiled_chains(base: np.ndarray, target: np.ndarray, pole: np.ndarray, l1: float,
                     l2: float, dmin: float, dmax: float
                     ) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`two_bone_ik` by the compiled loop (the same numbers), or None where it is
    not in use: numba off, bone lengths not double precision, points not (..., 3) and
    finite."""
    from ltl_human_motion.kernel.segments import compiled_module
    if not all(isinstance(x, float) for x in (l1, l2, dmin, dmax)):
        return None
    nb = compiled_module("ltl_human_motion.motion._ik_numba")
    if nb is None:
        return None
    try:
        shape = np.broadcast_shapes(base.shape, target.shape, pole.shape)
    except ValueError:
        return None
    if shape[-1:] != (3,):
        return None
    flat = []
    for x in (base, target, pole):
        rows = (x if x.shape == shape else np.broadcast_to(x, shape)).reshape(-1, 3)
        # one signature of the kernel: C-contiguous and writeable
        flat.append(rows if rows.flags.c_contiguous and rows.flags.writeable else rows.copy())
    if not all(np.isfinite(x).all() for x in flat):
        return None
    middle, end = np.empty_like(flat[0]), np.empty_like(flat[0])
    nb.two_bone(*flat, float(l1), float(l2), float(dmin), float(dmax), middle, end)
    return middle.reshape(shape), end.reshape(shape)


def min_jerk(tau: np.ndarray) -> np.ndarray:
    """Minimum-jerk position profile (Flash & Hogan 1985): 10 s^3 - 15 s^4 + 6 s^5.

    Parameters
    ----------
    tau : array-like
        Normalized time, clipped to [0, 1].
    """
    s = np.clip(np.asarray(tau, dtype=np.float64), 0.0, 1.0)
    return s ** 3 * (10.0 - 15.0 * s + 6.0 * s * s)


# Segment mass fractions (Winter 2009, Table 4.1) as (proximal, distal, mass, com fraction).
SEGMENT_MASS: tuple[tuple[str, str, float, float], ...] = (
    ("neck", "head", 0.081, 0.5),
    ("pelvis", "neck", 0.497, 0.5),
    ("l_shoulder", "l_elbow", 0.028, 0.436), ("r_shoulder", "r_elbow", 0.028, 0.436),
    ("l_elbow", "l_wrist", 0.016, 0.430), ("r_elbow", "r_wrist", 0.016, 0.430),
    ("l_wrist", "l_hand", 0.006, 0.5), ("r_wrist", "r_hand", 0.006, 0.5),
    ("l_hip", "l_knee", 0.100, 0.433), ("r_hip", "r_knee", 0.100, 0.433),
    ("l_knee", "l_ankle", 0.0465, 0.433), ("r_knee", "r_ankle", 0.0465, 0.433),
    ("l_ankle", "l_toe", 0.0145, 0.5), ("r_ankle", "r_toe", 0.0145, 0.5),
)
_PROX = np.array([JOINT_INDEX[a] for a, _, _, _ in SEGMENT_MASS])
_DIST = np.array([JOINT_INDEX[b] for _, b, _, _ in SEGMENT_MASS])
_MASS = np.array([m for _, _, m, _ in SEGMENT_MASS])
_FRAC = np.array([f for _, _, _, f in SEGMENT_MASS])


def center_of_mass(positions: np.ndarray) -> np.ndarray:
    """Whole-body centre of mass from segment masses (Winter 2009).

    Parameters
    ----------
    positions : array-like, shape (..., J, 3)

    Returns
    -------
    com : ndarray, shape (..., 3)
    """
    p = np.asarray(positions, dtype=np.float64)
    seg = p[..., _PROX, :] + _FRAC[:, None] * (p[..., _DIST, :] - p[..., _PROX, :])
    return np.einsum("k,...kd->...d", _MASS, seg) / _MASS.sum()




