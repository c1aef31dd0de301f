"""occ(x): the body as a set of capsules, one per segment of the canonical skeleton.

Each capsule is the set of points within ``radius`` of the segment between two joints
(a joint repeated gives a sphere, used for the knees). Radii are given for a 1.75 m
worker and scale linearly with stature; they follow typical segment girths
(anthropometric circumference / 2 pi, rounded up by about 1 cm for clothing).

The body parts Table I refers to are ``l_hand`` (lh), ``r_hand`` (rh), ``l_knee`` (lk),
``r_knee`` (rk), ``head`` and ``buttocks`` (a capsule across the hip joints, behind and
below the pelvis). The floor is not part of O(t): the feet stand on it.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, N_JOINTS

__all__ = [
    "BODY_CAPSULES",
    "BODY_PARTS",
    "PART_ALIASES",
    "body_boxes",
    "body_radius_xy",
    "capsule_ends",
    "capsule_radii",
    "capsules_from_positions",
    "occ",
    "part_indices",
]

#: ``(part, joint_a, joint_b, radius at 1.75 m)``.
BODY_CAPSULES: tuple[tuple[str, str, str, float], ...] = (
    ("head", "neck", "head", 0.105),
    ("abdomen", "spine", "chest", 0.130),
    ("torso", "chest", "neck", 0.130),
    ("pelvis", "pelvis", "spine", 0.135),
    ("buttocks", "l_hip", "r_hip", 0.105),
    ("l_clavicle", "l_clavicle", "l_shoulder", 0.060),
    ("r_clavicle", "r_clavicle", "r_shoulder", 0.060),
    ("l_upper_arm", "l_shoulder", "l_elbow", 0.050),
    ("r_upper_arm", "r_shoulder", "r_elbow", 0.050),
    ("l_lower_arm", "l_elbow", "l_wrist", 0.042),
    ("r_lower_arm", "r_elbow", "r_wrist", 0.042),
    ("l_hand", "l_wrist", "l_hand", 0.045),
    ("r_hand", "r_wrist", "r_hand", 0.045),
    ("l_thigh", "l_hip", "l_knee", 0.075),
    ("r_thigh", "r_hip", "r_knee", 0.075),
    ("l_knee", "l_knee", "l_knee", 0.055),
    ("r_knee", "r_knee", "r_knee", 0.055),
    ("l_shank", "l_knee", "l_ankle", 0.055),
    ("r_shank", "r_knee", "r_ankle", 0.055),
    ("l_foot", "l_ankle", "l_toe", 0.035),
    ("r_foot", "r_ankle", "r_toe", 0.035),
    # The palms: the "lh"/"rh" of Table I (the paper's hand markers), spheres at the palm
    # centres inside the hand capsules; used by leftHand, rightHand and grasp.
    ("l_palm", "l_hand", "l_hand", 0.045),
    ("r_palm", "r_hand", "r_hand", 0.045),
)

#: Part names in capsule order.
BODY_PARTS: tuple[str, ...] = tuple(c[0] for c in BODY_CAPSULES)

#: Table I abbreviations and groups -> parts.
PART_ALIASES: dict[str, tuple[str, ...]] = {
    "lh": ("l_palm",), "rh": ("r_palm",), "lk": ("l_knee",), "rk": ("r_knee",),
    "hands": ("l_hand", "r_hand"),
    "left_arm": ("l_upper_arm", "l_lower_arm", "l_hand"),
    "right_arm": ("r_upper_arm", "r_lower_arm", "r_hand"),
    "legs": ("l_thigh", "r_thigh", "l_knee", "r_knee", "l_shank", "r_shank", "l_foot", "r_foot"),
}

_IA = np.array([JOINT_INDEX[c[1]] for c in BODY_CAPSULES])
_IB = np.array([JOINT_INDEX[c[2]] for c in BODY_CAPSULES])
_R = np.array([c[3] for c in BODY_CAPSULES])
_IAB = np.stack([_IA, _IB], axis=-1).ravel()       # end points a0, b0, a1, b1, ...


def capsule_ends() -> tuple[np.ndarray, np.ndarray]:
    """Joint indices of the two ends of every capsule, ``(a (K,), b (K,))`` (a copy)."""
    return _IA.copy(), _IB.copy()


def capsule_radii(stature: float = DEFAULT_STATURE) -> np.ndarray:
    """Capsule radii for a worker of ``stature`` metres, shape (K,)."""
    if not stature > 0:
        raise ValueError(f"stature must be positive, got {stature!r}")
    return _R * (float(stature) / DEFAULT_STATURE)


def part_indices(parts: str | Iterable[str] | None) -> np.ndarray:
    """Capsule indices of body parts (names of :data:`BODY_PARTS` or :data:`PART_ALIASES`).

    ``None`` means the whole body. Returns an int array of shape (k,).
    """
    if parts is None:
        return np.arange(len(BODY_CAPSULES))
    names = (parts,) if isinstance(parts, str) else tuple(parts)
    out: list[int] = []
    for name in names:
        expanded = PART_ALIASES.get(name, (name,))
        for n in expanded:
            if n not in BODY_PARTS:
                raise ValueError(f"unknown body part {n!r}; expected one of "
                                 f"{', '.join(BODY_PARTS + tuple(PART_ALIASES))}")
            out.append(BODY_PARTS.index(n))
    return np.array(sorted(set(out)), dtype=np.int64)


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
