"""OWAS, Ovako Working posture Analysing System (Karhu, Kansi & Kuorinka, Applied
Ergonomics 8 (1977) 199-201; action categories of Karhu et al. 1981): a four-digit posture
code (back, arms, legs, load) and its action category 1-4 (1 no action, 2 corrective
actions in the near future, 3 as soon as possible, 4 immediately).

Codes: back 1 straight, 2 bent, 3 twisted, 4 bent and twisted; arms 1 both below shoulder
level, 2 one at or above, 3 both at or above; legs 1 sitting, 2 standing on both straight
legs, 3 on one straight leg, 4 standing or squatting on both bent knees, 5 on one bent
knee, 6 kneeling, 7 walking; load 1 below 10 kg, 2 10-20 kg, 3 above 20 kg.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["ACTION_CATEGORY", "BENT_DEG", "KNEE_BENT_DEG", "TWISTED_DEG", "action_category",
           "arms_code", "back_code", "legs_code", "load_code"]

#: deg. Trunk flexion beyond this is "bent", twist beyond this "twisted", knee flexion
#: beyond this "bent knee" (OWAS names the postures, not angles; our thresholds).
BENT_DEG = 20.0
TWISTED_DEG = 20.0
KNEE_BENT_DEG = 30.0

#: ACTION_CATEGORY[back-1][arms-1][legs-1][load-1] (the OWAS action category table).
ACTION_CATEGORY = np.array([
    [[[1, 1, 1], [1, 1, 1], [1, 1, 1], [2, 2, 2], [2, 2, 2], [1, 1, 1], [1, 1, 1]],
     [[1, 1, 1], [1, 1, 1], [1, 1, 1], [2, 2, 2], [2, 2, 2], [1, 1, 1], [1, 1, 1]],
     [[1, 1, 1], [1, 1, 1], [1, 1, 1], [2, 2, 3], [2, 2, 3], [1, 1, 1], [1, 1, 2]]],
    [[[2, 2, 3], [2, 2, 3], [2, 2, 3], [3, 3, 3], [3, 3, 3], [2, 2, 2], [2, 3, 3]],
     [[2, 2, 3], [2, 2, 3], [2, 3, 3], [3, 4, 4], [3, 4, 4], [3, 3, 4], [2, 3, 4]],
     [[3, 3, 4], [2, 2, 3], [3, 3, 3], [3, 4, 4], [4, 4, 4], [4, 4, 4], [2, 3, 4]]],
    [[[1, 1, 1], [1, 1, 1], [1, 1, 2], [3, 3, 3], [4, 4, 4], [1, 1, 1], [1, 1, 1]],
     [[2, 2, 3], [1, 1, 1], [1, 1, 2], [4, 4, 4], [4, 4, 4], [3, 3, 3], [1, 1, 1]],
     [[2, 2, 3], [1, 1, 1], [2, 3, 3], [4, 4, 4], [4, 4, 4], [4, 4, 4], [1, 1, 1]]],
    [[[2, 3, 3], [2, 2, 3], [2, 2, 3], [4, 4, 4], [4, 4, 4], [4, 4, 4], [2, 3, 4]],
     [[3, 3, 4], [2, 3, 4], [3, 3, 4], [4, 4, 4], [4, 4, 4], [4, 4, 4], [2, 3, 4]],
     [[4, 4, 4], [2, 3, 4], [3, 3, 4], [4, 4, 4], [4, 4, 4], [4, 4, 4], [2, 3, 4]]],
])


def back_code(flexion: ArrayLike, twist: ArrayLike) -> np.ndarray:
    """1 straight, 2 bent, 3 twisted, 4 bent and twisted."""
    bent = np.asarray(flexion, dtype=np.float64) > BENT_DEG
    twisted = np.asarray(twist, dtype=np.float64) > TWISTED_DEG
    return np.where(bent & twisted, 4, np.where(twisted, 3, np.where(bent, 2, 1)))


def arms_code(left_elevation: ArrayLike, right_elevation: ArrayLike) -> np.ndarray:
    """1 both arms below shoulder level, 2 one at or above, 3 both (upper-arm elevation
    >= 90 deg puts the elbow at or above the shoulder)."""
    up = (np.abs(np.asarray(left_elevation, dtype=np.float64)) >= 90).astype(int) \
        + (np.abs(np.asarray(right_elevation, dtype=np.float64)) >= 90).astype(int)
    return up + 1


def legs_code(knee_left: ArrayLike, knee_right: ArrayLike, one_leg: ArrayLike = False,
              sitting: ArrayLike = False, kneeling: ArrayLike = False,
              walking: ArrayLike = False) -> np.ndarray:
    """Legs code 1-7 from knee flexion (deg) and the support state."""
    kl = np.asarray(knee_left, dtype=np.float64) > KNEE_BENT_DEG
    kr = np.asarray(knee_right, dtype=np.float64) > KNEE_BENT_DEG
    one = np.asarray(one_leg, dtype=bool)
    standing = np.where(one, np.where(kl | kr, 5, 3), np.where(kl & kr, 4,
                                                               np.where(kl | kr, 5, 2)))
    out = np.where(np.asarray(walking, dtype=bool), 7, standing)
    out = np.where(np.asarray(kneeling, dtype=bool), 6, out)
    return np.where(np.asarray(sitting, dtype=bool), 1, out)


def load_code(load_kg: ArrayLike) -> np.ndarray:
    """1 below 10 kg, 2 10-20 kg, 3 above 20 kg."""
    m = np.asarray(load_kg, dtype=np.float64)
    return np.where(m > 20, 3, np.where(m >= 10, 2, 1))


def action_category(back: ArrayLike, arms: ArrayLike, legs: ArrayLike, load: ArrayLike
                    ) -> np.ndarray:
    """Action category 1-4 of posture codes (back 1-4, arms 1-3, legs 1-7, load 1-3)."""
    from ltl_human_motion.assess.reba import _lookup
    return _lookup(ACTION_CATEGORY, back, arms, legs, load)
