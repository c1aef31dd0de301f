"""The canonical skeleton every motion source is retargeted onto.

Joints (index: name, parent):

====  ============  ===========
 idx  name          parent
====  ============  ===========
   0  pelvis        (root)
   1  spine         pelvis
   2  chest         spine
   3  neck          chest
   4  head          neck
   5  l_clavicle    chest
   6  l_shoulder    l_clavicle
   7  l_elbow       l_shoulder
   8  l_wrist       l_elbow
   9  l_hand        l_wrist
  10  r_clavicle    chest
  11  r_shoulder    r_clavicle
  12  r_elbow       r_shoulder
  13  r_wrist       r_elbow
  14  r_hand        r_wrist
  15  l_hip         pelvis
  16  l_knee        l_hip
  17  l_ankle       l_knee
  18  l_toe         l_ankle
  19  r_hip         pelvis
  20  r_knee        r_hip
  21  r_ankle       r_knee
  22  r_toe         r_ankle
====  ============  ===========

Frame: metres, z up, right-handed (REP 103). In the rest pose the body stands on the
floor (z = 0), faces +x, and its left side is +y. ``l_hand`` is the palm centre.

Segment proportions follow Drillis & Contini (1966) as tabulated in Winter,
*Biomechanics and Motor Control of Human Movement* (4th ed., 2009), Fig. 4.1:
joint heights and widths are fractions of the stature H.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

JOINT_NAMES: tuple[str, ...] = (
    "pelvis", "spine", "chest", "neck", "head",
    "l_clavicle", "l_shoulder", "l_elbow", "l_wrist", "l_hand",
    "r_clavicle", "r_shoulder", "r_elbow", "r_wrist", "r_hand",
    "l_hip", "l_knee", "l_ankle", "l_toe",
    "r_hip", "r_knee", "r_ankle", "r_toe",
)
PARENTS: tuple[int, ...] = (
    -1, 0, 1, 2, 3,
    2, 5, 6, 7, 8,
    2, 10, 11, 12, 13,
    0, 15, 16, 17,
    0, 19, 20, 21,
)
JOINT_INDEX: dict[str, int] = {name: i for i, name in enumerate(JOINT_NAMES)}
N_JOINTS = len(JOINT_NAMES)

# Left/right swap used for mirroring, as an index permutation.
MIRROR_PERMUTATION: tuple[int, ...] = tuple(
    JOINT_INDEX[n.replace("l_", "\0").replace("r_", "l_").replace("\0", "r_")]
    if n[:2] in ("l_", "r_") else i
    for i, n in enumerate(JOINT_NAMES)
)

DEFAULT_STATURE = 1.75
MIN_STATURE = 1.40
MAX_STATURE = 2.10

# Rest pose as fractions of stature: (x forward, y left, z up).
_REST_FRACTIONS = np.array([
    (0.000, 0.000, 0.530),   # pelvis
    (0.000, 0.000, 0.620),   # spine
    (0.000, 0.000, 0.720),   # chest
    (0.000, 0.000, 0.840),   # neck
    (0.010, 0.000, 0.930),   # head (centre)
    (0.000, 0.020, 0.800),   # l_clavicle
    (0.000, 0.115, 0.818),   # l_shoulder
    (0.000, 0.120, 0.630),   # l_elbow
    (0.000, 0.120, 0.485),   # l_wrist
    (0.000, 0.120, 0.430),   # l_hand
    (0.000, -0.020, 0.800),  # r_clavicle
    (0.000, -0.115, 0.818),  # r_shoulder
    (0.000, -0.120, 0.630),  # r_elbow
    (0.000, -0.120, 0.485),  # r_wrist
    (0.000, -0.120, 0.430),  # r_hand
    (0.000, 0.052, 0.500),   # l_hip
    (0.000, 0.052, 0.285),   # l_knee
    (0.000, 0.052, 0.039),   # l_ankle
    (0.110, 0.052, 0.010),   # l_toe
    (0.000, -0.052, 0.500),  # r_hip
    (0.000, -0.052, 0.285),  # r_knee
    (0.000, -0.052, 0.039),  # r_ankle
    (0.110, -0.052, 0.010),  # r_toe
], dtype=np.float64)


@dataclass(frozen=True)
class Skeleton:
    """The canonical skeleton scaled to one stature.

    Attributes
    ----------
    stature : float
        Body height in metres (1.40 to 2.10).
    names : tuple of str, length J
    parents : tuple of int, length J (-1 for the root)
    """

    stature: float = DEFAULT_STATURE
    names: tuple[str, ...] = field(default=JOINT_NAMES, repr=False)
    parents: tuple[int, ...] = field(default=PARENTS, repr=False)

    def __post_init__(self) -> None:
        if not (MIN_STATURE <= float(self.stature) <= MAX_STATURE):
            raise ValueError(
                f"stature must be between {MIN_STATURE} and {MAX_STATURE} m, got {self.stature!r}")

    @property
    def n_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        """Index of joint ``name``; ValueError naming the known joints if unknown."""
        try:
            return JOINT_INDEX[name]
        except KeyError:
            raise ValueError(
                f"unknown joint {name!r}; expected one of {', '.join(self.names)}") from None

    def rest_positions(self) -> np.ndarray:
        """Rest pose, shape (J, 3): standing on z = 0, facing +x, arms down."""
        return _REST_FRACTIONS * self.stature

    def bone_lengths(self) -> np.ndarray:
        """Length of the bone from each joint's parent to the joint, shape (J,); 0 for the root."""
        rest = self.rest_positions()
        lengths = np.zeros(len(self.names))
        for j, p in enumerate(self.parents):
            if p >= 0:
                lengths[j] = np.linalg.norm(rest[j] - rest[p])
        return lengths

    def scaled(self, stature: float) -> Skeleton:
        """The same skeleton at another stature."""
        return Skeleton(stature=stature)
