"""Minimum separation between human and robot capsules, over all pairs.

A capsule is a segment (2, 3) with a radius; the separation of two capsules is the distance
between their axes (exact closest points of two segments, clamped to the segments) minus
both radii. It is *signed*: negative when the capsules overlap.

The distances come from the shared kernel :mod:`ltl_human_motion.kernel.segments`
(compiled with numba: one human, 17 capsules, against one arm, 7 capsules, takes a few
microseconds); this module adds the human/robot vocabulary and the closest pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ltl_human_motion.kernel.segments import (
    MAX_COORDINATE,
    check_capsules,
    min_signed_distance,
    segment_distances,
    signed_distances,
)

__all__ = [
    "MAX_COORDINATE",
    "Separation",
    "check_capsules",
    "min_distance",
    "pair_distances",
    "segment_distances",
    "separation",
    "signed_distances",
]


@dataclass(frozen=True)
class Separation:
    """Result of :func:`separation`.

    Attributes
    ----------
    distance : float
        Minimum signed capsule separation (m).
    human_index, robot_index : int
        The closest pair.
    pair_distances : ndarray, shape (K, L)
        Signed separation of every pair.
    """

    distance: float
    human_index: int
    robot_index: int
    pair_distances: NDArray[np.float64]


def _capsule_pair(human_segments: ArrayLike, human_radii: ArrayLike,
                  robot_segments: ArrayLike, robot_radii: ArrayLike, validate: bool
                  ) -> tuple[NDArray[np.float64], ...]:
    """The four arrays, checked (``validate``) or as given."""
    if validate:
        hs, hr = check_capsules(human_segments, human_radii, "human capsules")
        rs, r_r = check_capsules(robot_segments, robot_radii, "robot capsules")
        return hs, hr, rs, r_r
    return (np.asarray(human_segments), np.asarray(human_radii), np.asarray(robot_segments),
            np.asarray(robot_radii))


def pair_distances(human_segments: ArrayLike, human_radii: ArrayLike,
                   robot_segments: ArrayLike, robot_radii: ArrayLike,
                   validate: bool = True) -> NDArray[np.float64]:
    """Signed separation of every human-robot capsule pair.

    Parameters
    ----------
    human_segments : array-like, shape (K, 2, 3)
    human_radii : array-like, shape (K,)
    robot_segments : array-like, shape (L, 2, 3)
    robot_radii : array-like, shape (L,)
    validate : bool
        Check shapes and values (skip only for arrays already checked).

    Returns
    -------
    distances : ndarray, shape (K, L)
    """
    hs, hr, rs, r_r = _capsule_pair(human_segments, human_radii, robot_segments,
                                    robot_radii, validate)
    return segment_distances(hs, rs) - hr[:, None] - r_r[None, :]


def min_distance(human_segments: ArrayLike, human_radii: ArrayLike,
                 robot_segments: ArrayLike, robot_radii: ArrayLike,
                 validate: bool = True) -> float:
    """Minimum signed human-robot capsule separation (m).

    Parameters are those of :func:`pair_distances`.

    Returns
    -------
    float
        Negative when a pair overlaps.
    """
    hs, hr, rs, r_r = _capsule_pair(human_segments, human_radii, robot_segments,
                                    robot_radii, validate)
    return min_signed_distance(hs, hr, rs, r_r)


def separation(human_segments: ArrayLike, human_radii: ArrayLike,
               robot_segments: ArrayLike, robot_radii: ArrayLike,
               validate: bool = True) -> Separation:
    """Minimum separation with the closest pair and all pair distances.

    Parameters are those of :func:`pair_distances`.

    Returns
    -------
    Separation
    """
    d = pair_distances(human_segments, human_radii, robot_segments, robot_radii, validate)
    k, j = np.unravel_index(int(np.argmin(d)), d.shape)
    return Separation(float(d[k, j]), int(k), int(j), d)
