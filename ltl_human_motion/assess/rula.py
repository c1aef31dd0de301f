"""RULA, Rapid Upper Limb Assessment (McAtamney & Corlett, Applied Ergonomics 24 (1993)
91-99): arm and wrist (group A), neck, trunk and legs (group B), muscle use and load.

Score C = Table A + muscle use + force/load (arm side); score D = Table B + muscle use +
force/load (neck/trunk/legs); the grand score is Table C(C, D), in 1..7.

Action levels: 1-2 acceptable (level 1), 3-4 investigate further (2), 5-6 investigate and
change soon (3), 7 investigate and change immediately (4).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ltl_human_motion.assess.reba import UPRIGHT_DEG, _arr, _lookup

__all__ = [
    "TABLE_A", "TABLE_B", "TABLE_C", "action_level", "force_score", "lower_arm_score",
    "neck_score", "rula_score", "trunk_score", "upper_arm_score", "wrist_score",
]

#: Table A [upper arm-1][lower arm-1][(wrist-1)*2 + twist-1] (McAtamney & Corlett 1993).
TABLE_A = np.array([
    [[1, 2, 2, 2, 2, 3, 3, 3], [2, 2, 2, 2, 3, 3, 3, 3], [2, 3, 3, 3, 3, 3, 4, 4]],
    [[2, 3, 3, 3, 3, 4, 4, 4], [3, 3, 3, 3, 3, 4, 4, 4], [3, 4, 4, 4, 4, 4, 5, 5]],
    [[3, 3, 4, 4, 4, 4, 5, 5], [3, 4, 4, 4, 4, 4, 5, 5], [4, 4, 4, 4, 4, 5, 5, 5]],
    [[4, 4, 4, 4, 4, 5, 5, 5], [4, 4, 4, 4, 4, 5, 5, 5], [4, 4, 4, 5, 5, 5, 6, 6]],
    [[5, 5, 5, 5, 5, 6, 6, 7], [5, 6, 6, 6, 6, 7, 7, 7], [6, 6, 6, 7, 7, 7, 7, 8]],
    [[7, 7, 7, 7, 7, 8, 8, 9], [7, 8, 8, 8, 8, 9, 9, 9], [9, 9, 9, 9, 9, 9, 9, 9]],
])
#: Table B [neck-1][(trunk-1)*2 + legs-1].
TABLE_B = np.array([
    [1, 3, 2, 3, 3, 4, 5, 5, 6, 6, 7, 7],
    [2, 3, 2, 3, 4, 5, 5, 5, 6, 7, 7, 7],
    [3, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 7],
    [5, 5, 5, 6, 6, 7, 7, 7, 7, 7, 8, 8],
    [7, 7, 7, 7, 7, 8, 8, 8, 8, 8, 8, 8],
    [8, 8, 8, 8, 8, 8, 8, 9, 9, 9, 9, 9],
])
#: Table C [min(score C, 8)-1][min(score D, 7)-1] (the grand score).
TABLE_C = np.array([
    [1, 2, 3, 3, 4, 5, 5],
    [2, 2, 3, 4, 4, 5, 5],
    [3, 3, 3, 4, 4, 5, 6],
    [3, 3, 3, 4, 5, 6, 6],
    [4, 4, 4, 5, 6, 7, 7],
    [4, 4, 5, 6, 6, 7, 7],
    [5, 5, 6, 6, 7, 7, 7],
    [5, 5, 6, 7, 7, 7, 7],
])


def upper_arm_score(flexion: ArrayLike, shoulder_raised: ArrayLike = False,
                    abducted: ArrayLike = False, supported: ArrayLike = False) -> np.ndarray:
    """Upper arm: 20 deg extension to 20 deg flexion 1; > 20 deg extension or 20-45 deg
    flexion 2; 45-90 deg 3; > 90 deg 4; +1 shoulder raised, +1 abducted, -1 supported or
    leaning; 1..6."""
    a = _arr(flexion)
    s = np.where(a > 90, 4, np.where(a > 45, 3, np.where((a > 20) | (a < -20), 2, 1)))
    s = (s + np.asarray(shoulder_raised, dtype=int) + np.asarray(abducted, dtype=int)
         - np.asarray(supported, dtype=int))
    return np.clip(s, 1, 6)


def lower_arm_score(elbow_flexion: ArrayLike, across_or_out: ArrayLike = False) -> np.ndarray:
    """Lower arm: 60-100 deg flexion 1; 0-60 or > 100 deg 2; +1 working across the mid-line
    or out to the side."""
    a = _arr(elbow_flexion)
    return np.where((a >= 60) & (a <= 100), 1, 2) + np.asarray(across_or_out, dtype=int)


def wrist_score(flexion: ArrayLike, deviated: ArrayLike = False) -> np.ndarray:
    """Wrist: neutral 1; 0-15 deg flexion or extension 2; > 15 deg 3; +1 deviated.
    |angle| < :data:`~ltl_human_motion.assess.reba.UPRIGHT_DEG` counts as neutral."""
    a = np.abs(_arr(flexion))
    return (np.where(a > 15, 3, np.where(a < UPRIGHT_DEG, 1, 2))
            + np.asarray(deviated, dtype=int))


def neck_score(flexion: ArrayLike, twisted: ArrayLike = False, side_bent: ArrayLike = False
               ) -> np.ndarray:
    """Neck: 0-10 deg flexion 1; 10-20 deg 2; > 20 deg 3; in extension 4; +1 twisted, +1
    side bent."""
    a = _arr(flexion)
    s = np.where(a < -UPRIGHT_DEG, 4, np.where(a > 20, 3, np.where(a > 10, 2, 1)))
    return s + np.asarray(twisted, dtype=int) + np.asarray(side_bent, dtype=int)


def trunk_score(flexion: ArrayLike, twisted: ArrayLike = False, side_bent: ArrayLike = False,
                sitting_supported: ArrayLike = False) -> np.ndarray:
    """Trunk: upright (or sitting well supported) 1; 0-20 deg flexion 2; 20-60 deg 3;
    > 60 deg 4; +1 twisted, +1 side bent."""
    a = _arr(flexion)
    s = np.where(a > 60, 4, np.where(a > 20, 3, np.where(a >= UPRIGHT_DEG, 2, 1)))
    s = np.where(np.asarray(sitting_supported, dtype=bool), 1, s)
    return s + np.asarray(twisted, dtype=int) + np.asarray(side_bent, dtype=int)


def force_score(load_kg: ArrayLike, static_or_repeated: ArrayLike = False,
                shock: ArrayLike = False) -> np.ndarray:
    """Force/load: < 2 kg intermittent 0; 2-10 kg intermittent 1; 2-10 kg static or
    repeated, or > 10 kg intermittent 2; > 10 kg static or repeated, or shock 3."""
    m = _arr(load_kg)
    rep = np.asarray(static_or_repeated, dtype=bool)
    s = np.where(m > 10, np.where(rep, 3, 2), np.where(m >= 2, np.where(rep, 2, 1), 0))
    return np.where(np.asarray(shock, dtype=bool), 3, s)


def rula_score(upper_arm: ArrayLike, lower_arm: ArrayLike, wrist: ArrayLike,
               wrist_twist: ArrayLike, neck: ArrayLike, trunk: ArrayLike, legs: ArrayLike,
               muscle_a: ArrayLike = 0, force_a: ArrayLike = 0, muscle_b: ArrayLike = 0,
               force_b: ArrayLike = 0) -> dict[str, np.ndarray]:
    """RULA from the body-part scores.

    Parameters
    ----------
    upper_arm (1-6), lower_arm (1-3), wrist (1-4), wrist_twist (1-2) : int or array
    neck (1-6), trunk (1-6), legs (1-2) : int or array
    muscle_a, force_a, muscle_b, force_b : int or array
        Muscle use (0-1) and force/load (0-3) scores for group A and group B.

    Returns
    -------
    dict
        ``table_a``, ``score_c``, ``table_b``, ``score_d``, ``rula`` (grand score).
    """
    wrist = np.asarray(wrist, dtype=np.int64)
    twist = np.asarray(wrist_twist, dtype=np.int64)
    if np.any((twist < 1) | (twist > 2)):
        raise ValueError("wrist_twist must be 1 or 2")
    ta = _lookup(TABLE_A, upper_arm, lower_arm, (wrist - 1) * 2 + twist)
    trunk = np.asarray(trunk, dtype=np.int64)
    legs = np.asarray(legs, dtype=np.int64)
    if np.any((legs < 1) | (legs > 2)):
        raise ValueError("legs must be 1 or 2")
    tb = _lookup(TABLE_B, neck, (trunk - 1) * 2 + legs)
    sc = ta + np.asarray(muscle_a, dtype=np.int64) + np.asarray(force_a, dtype=np.int64)
    sd = tb + np.asarray(muscle_b, dtype=np.int64) + np.asarray(force_b, dtype=np.int64)
    grand = _lookup(TABLE_C, np.minimum(sc, 8), np.minimum(sd, 7))
    return {"table_a": ta, "score_c": sc, "table_b": tb, "score_d": sd, "rula": grand}


def action_level(score: ArrayLike) -> np.ndarray:
    """RULA action level 1-4 of a grand score 1-7."""
    s = np.asarray(score)
    return np.searchsorted([2, 4, 6], s, side="left") + 1
