"""Minimum separation between human and robot capsules, vectorized over all pairs.

A capsule is a segment (2, 3) with a radius; the separation of two capsules is the distance
between their axes (exact closest points of two segments, clamped to the segments) minus
both radii. It is *signed*: negative when the capsules overlap.

The kernel works on dot products of the segment end points and directions (small matrix
products) and never builds (K, L, 3) arrays, so one human (~17 capsules) against one arm
(7 capsules) takes a few tens of microseconds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "MAX_COORDINATE",
    "Separation",
    "check_capsules",
    "min_distance",
    "pair_distances",
    "segment_distances",
    "separation",
]

#: Coordinates beyond this (m) are rejected as nonsense by :func:`check_capsules`.
MAX_COORDINATE = 1.0e3
_EPS = 1e-30   # squared length (m^2) below which a segment counts as a point
_TINY = 1e-300


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


def check_capsules(segments: ArrayLike, radii: ArrayLike, what: str = "capsules",
                   max_coordinate: float = MAX_COORDINATE
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Validate capsules at a boundary.

    Parameters
    ----------
    segments : array-like, shape (K, 2, 3)
    radii : array-like, shape (K,)
    what : str
        Name used in error messages.
    max_coordinate : float
        Largest accepted absolute coordinate (m); larger values are nonsense.

    Returns
    -------
    segments : ndarray, shape (K, 2, 3)
    radii : ndarray, shape (K,)

    Raises
    ------
    ValueError
        Wrong shapes, no capsule, NaN/inf, negative or absurd radii, absurd coordinates.
    """
    try:
        seg = np.asarray(segments, dtype=np.float64)
        rad = np.asarray(radii, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what}: expected numeric arrays ({exc})") from exc
    if seg.ndim != 3 or seg.shape[1:] != (2, 3) or seg.shape[0] == 0:
        raise ValueError(f"{what}: segments must have shape (K, 2, 3) with K >= 1, "
                         f"got {seg.shape}")
    if rad.shape != (seg.shape[0],):
        raise ValueError(f"{what}: radii must have shape ({seg.shape[0]},), got {rad.shape}")
    # One reduction per array; NaN fails every comparison, so it takes the slow path.
    if np.abs(seg).max() <= max_coordinate and rad.min() >= 0.0 and rad.max() <= 10.0:
        return seg, rad
    if not (np.all(np.isfinite(seg)) and np.all(np.isfinite(rad))):
        raise ValueError(f"{what}: contains NaN or inf")
    if np.any(rad < 0) or np.any(rad > 10.0):
        raise ValueError(f"{what}: radii must be in [0, 10] m, got [{rad.min()}, {rad.max()}]")
    raise ValueError(f"{what}: coordinates beyond {max_coordinate} m")


def segment_distances(P: NDArray[np.float64], Q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Exact distances between every segment of ``P`` and every segment of ``Q``.

    Parameters
    ----------
    P : ndarray, shape (K, 2, 3)
    Q : ndarray, shape (L, 2, 3)

    Returns
    -------
    distances : ndarray, shape (K, L)
        Distance between the closest points (clamped to both segments).
    """
    p0 = P[:, 0]
    q0 = Q[:, 0]
    d1 = P[:, 1] - p0
    d2 = Q[:, 1] - q0
    K = len(P)
    # One matrix product gives p0.d2, d1.q0 and d1.d2 for all pairs.
    G = np.concatenate((p0, d1)) @ np.concatenate((q0, d2)).T   # (2K, 2L)
    L = len(Q)
    p0d2, d1q0, b = G[:K, L:], G[K:, :L], G[K:, L:]
    a = (d1 * d1).sum(axis=1)[:, None]                          # (K, 1)
    e = (d2 * d2).sum(axis=1)[None, :]                          # (1, L)
    c = (d1 * p0).sum(axis=1)[:, None] - d1q0                   # d1 . (p0 - q0)
    f = p0d2 - (d2 * q0).sum(axis=1)[None, :]                   # d2 . (p0 - q0)
    a_s = np.maximum(a, _EPS)   # a point has d1 = 0, so b = c = 0 as well
    e_s = np.maximum(e, _EPS)
    # Closest points of the two lines, clamped to P; for parallel lines (denom ~ 0) any s
    # works, and the huge ratio is clamped to an end of P.
    s = (b * f - c * e) / np.maximum(a * e - b * b, _TINY)
    s = np.minimum(np.maximum(s, 0.0), 1.0)
    t = np.minimum(np.maximum((b * s + f) / e_s, 0.0), 1.0)
    # Re-project Q(t) on P: where t was clamped this is the closest point on P; elsewhere
    # it cannot increase the (already minimal) distance.
    s = np.minimum(np.maximum((b * t - c) / a_s, 0.0), 1.0)
    # The closest points themselves (not an expansion of |r + s d1 - t d2|^2, which loses
    # precision to cancellation when the segments nearly touch).
    gap = (p0[:, None, :] - q0[None, :, :]) + s[..., None] * d1[:, None, :] \
        - t[..., None] * d2[None, :, :]
    dist = np.sqrt((gap * gap).sum(axis=-1))
    # Nearly parallel pairs lose the closest points to rounding; for them the minimum is
    # attained at an end point of one segment, so the end points settle it exactly.
    near_parallel = a * e - b * b <= 1e-9 * a_s * e_s
    if np.any(near_parallel):
        k, j = np.nonzero(near_parallel)
        ends = np.minimum.reduce([_point_segment(P[k, 0], q0[j], d2[j]),
                                  _point_segment(P[k, 1], q0[j], d2[j]),
                                  _point_segment(Q[j, 0], p0[k], d1[k]),
                                  _point_segment(Q[j, 1], p0[k], d1[k])])
        dist[k, j] = np.minimum(dist[k, j], ends)
    return dist


def _point_segment(x: NDArray[np.float64], o: NDArray[np.float64],
                   d: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distances from points x (N, 3) to segments o + [0, 1] d (N, 3), shape (N,)."""
    u = np.clip(((x - o) * d).sum(axis=-1) / np.maximum((d * d).sum(axis=-1), _EPS), 0.0, 1.0)
    r = x - o - u[:, None] * d
    return np.sqrt((r * r).sum(axis=-1))


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
    if validate:
        hs, hr = check_capsules(human_segments, human_radii, "human capsules")
        rs, r_r = check_capsules(robot_segments, robot_radii, "robot capsules")
    else:
        hs, hr = np.asarray(human_segments), np.asarray(human_radii)
        rs, r_r = np.asarray(robot_segments), np.asarray(robot_radii)
    return segment_distances(hs, rs) - hr[:, None] - r_r[None, :]


def min_distance(human_segments: ArrayLike, human_radii: ArrayLike,
                 robot_segments: ArrayLike, robot_radii: ArrayLike,
                 validate: bool = True) -> float:
    """Minimum signed human-robot capsule separation (m).

    Parameters
    ----------
    human_segments : array-like, shape (K, 2, 3)
    human_radii : array-like, shape (K,)
    robot_segments : array-like, shape (L, 2, 3)
    robot_radii : array-like, shape (L,)
    validate : bool

    Returns
    -------
    float
        Negative when a pair overlaps.
    """
    return float(pair_distances(human_segments, human_radii, robot_segments, robot_radii,
                                validate).min())


def separation(human_segments: ArrayLike, human_radii: ArrayLike,
               robot_segments: ArrayLike, robot_radii: ArrayLike,
               validate: bool = True) -> Separation:
    """Minimum separation with the closest pair and all pair distances.

    Parameters
    ----------
    human_segments : array-like, shape (K, 2, 3)
    human_radii : array-like, shape (K,)
    robot_segments : array-like, shape (L, 2, 3)
    robot_radii : array-like, shape (L,)
    validate : bool

    Returns
    -------
    Separation
    """
    d = pair_distances(human_segments, human_radii, robot_segments, robot_radii, validate)
    k, j = np.unravel_index(int(np.argmin(d)), d.shape)
    return Separation(float(d[k, j]), int(k), int(j), d)
