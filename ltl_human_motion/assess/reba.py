"""REBA, Rapid Entire Body Assessment (Hignett & McAtamney, Applied Ergonomics 31 (2000)
201-205): body-part scores, Tables A, B and C, load/force, coupling and activity.

Every function is vectorized: scalars or arrays of the same shape in, arrays out.

Group A (trunk, neck, legs) and load/force give score A; group B (upper arm, lower arm,
wrist; the worse side) and coupling give score B; Table C combines them into score C; the
activity score is added: REBA = C + activity, in 1..15.

Action levels (the paper's Table 5): 1 negligible, 2-3 low, 4-7 medium, 8-10 high,
11-15 very high.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "COUPLING", "TABLE_A", "TABLE_B", "TABLE_C", "action_level", "legs_score",
    "load_score", "lower_arm_score", "neck_score", "reba_score", "trunk_score",
    "upper_arm_score", "wrist_score",
]

#: Table A [trunk-1][neck-1][legs-1] (Hignett & McAtamney 2000, Table 4).
TABLE_A = np.array([
    [[1, 2, 3, 4], [1, 2, 3, 4], [3, 3, 5, 6]],
    [[2, 3, 4, 5], [3, 4, 5, 6], [4, 5, 6, 7]],
    [[2, 4, 5, 6], [4, 5, 6, 7], [5, 6, 7, 8]],
    [[3, 5, 6, 7], [5, 6, 7, 8], [6, 7, 8, 9]],
    [[4, 6, 7, 8], [6, 7, 8, 9], [7, 8, 9, 9]],
])
#: Table B [upper arm-1][lower arm-1][wrist-1] (the paper's Table 5 part B).
TABLE_B = np.array([
    [[1, 2, 2], [1, 2, 3]],
    [[1, 2, 3], [2, 3, 4]],
    [[3, 4, 5], [4, 5, 5]],
    [[4, 5, 5], [5, 6, 7]],
    [[6, 7, 8], [7, 8, 8]],
    [[7, 8, 8], [8, 9, 9]],
])
#: Table C [score A-1][score B-1] (the paper's Table 6).
TABLE_C = np.array([
    [1, 1, 1, 2, 3, 3, 4, 5, 6, 7, 7, 7],
    [1, 2, 2, 3, 4, 4, 5, 6, 6, 7, 7, 8],
    [2, 3, 3, 3, 4, 5, 6, 7, 7, 8, 8, 8],
    [3, 4, 4, 4, 5, 6, 7, 8, 8, 9, 9, 9],
    [4, 4, 4, 5, 6, 7, 8, 8, 9, 9, 9, 9],
    [6, 6, 6, 7, 8, 8, 9, 9, 10, 10, 10, 10],
    [7, 7, 7, 8, 9, 9, 9, 10, 10, 11, 11, 11],
    [8, 8, 8, 9, 10, 10, 10, 10, 10, 11, 11, 11],
    [9, 9, 9, 10, 10, 10, 11, 11, 11, 12, 12, 12],
    [10, 10, 10, 11, 11, 11, 11, 12, 12, 12, 12, 12],
    [11, 11, 11, 11, 12, 12, 12, 12, 12, 12, 12, 12],
    [12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12],
])
#: Coupling score by the quality of the hand hold (the paper's coupling table).
COUPLING = {"good": 0, "fair": 1, "poor": 2, "unacceptable": 3}


def _arr(x: ArrayLike) -> np.ndarray:
    return np.asarray(x, dtype=np.float64)


def trunk_score(flexion: ArrayLike, twisted_or_side: ArrayLike = False) -> np.ndarray:
    """Trunk: upright 1; 0-20 deg flexion or extension 2; 20-60 deg flexion or > 20 deg
    extension 3; > 60 deg flexion 4; +1 if twisted or side flexed.

    "Upright" is exactly 0 in the paper; a measured posture is never exactly 0, so
    |angle| < 5 deg (:data:`UPRIGHT_DEG`) counts as upright.
    """
    a = _arr(flexion)
    s = np.where(np.abs(a) < UPRIGHT_DEG, 1,
                 np.where(a > 60, 4, np.where((a > 20) | (a < -20), 3, 2)))
    return s + np.asarray(twisted_or_side, dtype=int)


#: deg. Trunk and neck angles within this of neutral count as "upright" (our reading of
#: the paper's "upright" = 0 deg for measured, never exactly zero, angles).
UPRIGHT_DEG = 5.0


def neck_score(flexion: ArrayLike, twisted_or_side: ArrayLike = False) -> np.ndarray:
    """Neck: 0-20 deg flexion 1; > 20 deg flexion or in extension 2; +1 twisted or side
    flexed. Extension counts beyond :data:`UPRIGHT_DEG`."""
    a = _arr(flexion)
    s = np.where((a > 20) | (a < -UPRIGHT_DEG), 2, 1)
    return s + np.asarray(twisted_or_side, dtype=int)


def legs_score(unilateral: ArrayLike, knee_flexion: ArrayLike, sitting: ArrayLike = False
               ) -> np.ndarray:
    """Legs: bilateral weight bearing, walking or sitting 1; unilateral, feather weight
    bearing or unstable 2; +1 if the knee(s) flex 30-60 deg, +2 above 60 deg (not when
    sitting)."""
    base = np.where(np.asarray(unilateral, dtype=bool), 2, 1)
    k = _arr(knee_flexion)
    add = np.where(k > 60, 2, np.where(k >= 30, 1, 0))
    return base + np.where(np.asarray(sitting, dtype=bool), 0, add)


def load_score(load_kg: ArrayLike, shock: ArrayLike = False) -> np.ndarray:
    """Load/force: < 5 kg 0; 5-10 kg 1; > 10 kg 2; +1 for shock or rapid build-up."""
    m = _arr(load_kg)
    return np.where(m > 10, 2, np.where(m >= 5, 1, 0)) + np.asarray(shock, dtype=int)


def upper_arm_score(flexion: ArrayLike, abducted_or_rotated: ArrayLike = False,
                    shoulder_raised: ArrayLike = False, supported: ArrayLike = False
                    ) -> np.ndarray:
    """Upper arm: 20 deg extension to 20 deg flexion 1; > 20 deg extension or 20-45 deg
    flexion 2; 45-90 deg flexion 3; > 90 deg 4; +1 abducted or rotated, +1 shoulder
    raised, -1 supported, leaning or gravity assisted; at least 1."""
    a = _arr(flexion)
    s = np.where(a > 90, 4, np.where(a > 45, 3, np.where((a > 20) | (a < -20), 2, 1)))
    s = (s + np.asarray(abducted_or_rotated, dtype=int) + np.asarray(shoulder_raised, dtype=int)
         - np.asarray(supported, dtype=int))
    return np.clip(s, 1, 6)


def lower_arm_score(elbow_flexion: ArrayLike) -> np.ndarray:
    """Lower arm: 60-100 deg flexion 1; < 60 or > 100 deg 2."""
    a = _arr(elbow_flexion)
    return np.where((a >= 60) & (a <= 100), 1, 2)


def wrist_score(flexion: ArrayLike, deviated_or_twisted: ArrayLike = False) -> np.ndarray:
    """Wrist: 0-15 deg flexion/extension 1; > 15 deg 2; +1 deviated or twisted."""
    a = np.abs(_arr(flexion))
    return np.where(a > 15, 2, 1) + np.asarray(deviated_or_twisted, dtype=int)


def _lookup(table: np.ndarray, *idx: ArrayLike) -> np.ndarray:
    ii = []
    for axis, i in enumerate(idx):
        i = np.asarray(i, dtype=np.int64)
        n = table.shape[axis]
        if np.any((i < 1) | (i > n)):
            raise ValueError(f"table index {axis}: scores must lie in 1..{n}, got "
                             f"{np.unique(i[(i < 1) | (i > n)]).tolist()}")
        ii.append(i - 1)
    return table[tuple(np.broadcast_arrays(*ii))]


def reba_score(trunk: ArrayLike, neck: ArrayLike, legs: ArrayLike, upper_arm: ArrayLike,
               lower_arm: ArrayLike, wrist: ArrayLike, load: ArrayLike = 0,
               coupling: ArrayLike = 0, activity: ArrayLike = 0) -> dict[str, np.ndarray]:
    """REBA from the body-part scores.

    Parameters
    ----------
    trunk, neck, legs, upper_arm, lower_arm, wrist : int or array of int
        Body-part scores with their adjustments (trunk 1-5, neck 1-3, legs 1-4, upper arm
        1-6, lower arm 1-2, wrist 1-3).
    load : int or array
        Load/force score (0-3), added to Table A.
    coupling : int or array
        Coupling score (0-3, see :data:`COUPLING`), added to Table B.
    activity : int or array
        Activity score (0-3), added to score C.

    Returns
    -------
    dict
        ``table_a``, ``score_a``, ``table_b``, ``score_b``, ``score_c``, ``reba``
        (arrays of the broadcast shape).
    """
    ta = _lookup(TABLE_A, trunk, neck, legs)
    tb = _lookup(TABLE_B, upper_arm, lower_arm, wrist)
    sa = np.minimum(ta + np.asarray(load, dtype=np.int64), 12)
    sb = np.minimum(tb + np.asarray(coupling, dtype=np.int64), 12)
    sc = _lookup(TABLE_C, sa, sb)
    return {"table_a": ta, "score_a": sa, "table_b": tb, "score_b": sb, "score_c": sc,
            "reba": sc + np.asarray(activity, dtype=np.int64)}


def action_level(score: ArrayLike) -> np.ndarray:
    """Action level 0-4 of a REBA score (0 negligible, 1 low, 2 medium, 3 high, 4 very
    high)."""
    s = np.asarray(score)
    return np.searchsorted([1, 3, 7, 10], s, side="left")
