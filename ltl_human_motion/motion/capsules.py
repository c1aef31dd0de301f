"""The body's capsules: one per segment of the canonical skeleton, the body parts the
scene's occupancy occ(x) (:mod:`ltl_human_motion.scene.occupancy`), the self-penetration
check and the worker's URDF are made of.

Each capsule is the set of points within ``radius`` of the segment between two joints
(a joint repeated gives a sphere, used for the knees). Radii are given for a 1.75 m
worker and scale linearly with stature; they follow typical segment girths
(anthropometric circumference / 2 pi, rounded up by about 1 cm for clothing).

The body parts Table I refers to are ``l_hand`` (lh), ``r_hand`` (rh), ``l_knee`` (lk),
``r_knee`` (rk), ``head`` and ``buttocks`` (a capsule across the hip joints, behind and
below the pelvis).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX

__all__ = [
    "BODY_CAPSULES",
    "BODY_PARTS",
    "PART_ALIASES",
    "capsule_ends",
    "capsule_radii",
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
