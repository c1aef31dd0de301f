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
    "signed_distances",
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


_PARALLEL_SLACK = 0.05
"""m. For a nearly parallel pair the closest-points pass can land on a point pair farther
apart than the closest one (by rounding; hypothesis found 6e-5 m). Where only a minimum
counts (:func:`signed_distances`), pairs more than this above it are left unrefined: the
excess is orders of magnitude smaller."""


def _closest_points_pass(P: NDArray[np.float64], Q: NDArray[np.float64]
                         ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Distances (K, L) from the clamped closest points of the two lines, and which pairs
    are nearly parallel (K, L) (their distance may be slightly high; see
    :func:`_refine_parallel`)."""
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
    denom = a * e - b * b
    s = (b * f - c * e) / np.maximum(denom, _TINY)
    s = np.minimum(np.maximum(s, 0.0), 1.0)
    t = np.minimum(np.maximum((b * s + f) / e_s, 0.0), 1.0)
    # Re-project Q(t) on P: where t was clamped this is the closest point on P; elsewhere
    # it cannot increase the (already minimal) distance.
    s = np.minimum(np.maximum((b * t - c) / a_s, 0.0), 1.0)
    # The closest points themselves (not an expansion of |r + s d1 - t d2|^2, which loses
    # precision to cancellation when the segments nearly touch).
    gap = (p0[:, None, :] - q0[None, :, :]) + s[..., None] * d1[:, None, :] \
        - t[..., None] * d2[None, :, :]
    return np.sqrt((gap * gap).sum(axis=-1)), denom <= 1e-9 * a_s * e_s


def _refine_parallel(dist: NDArray[np.float64], P: NDArray[np.float64],
                     Q: NDArray[np.float64], mask: NDArray[np.bool_]) -> None:
    """Make ``dist`` exact, in place, for the nearly parallel pairs in ``mask`` (K, L).

    Rounding loses their closest points; their minimum is attained at an end point of
    one segment, so the four end-point-to-segment distances settle it.
    """
    k, j = np.nonzero(mask)
    if not k.size:
        return
    p0, q0 = P[k, 0], Q[j, 0]
    d1, d2 = P[k, 1] - p0, Q[j, 1] - q0
    ends = _point_segment(np.concatenate((p0, P[k, 1], q0, Q[j, 1])),
                          np.concatenate((q0, q0, p0, p0)),
                          np.concatenate((d2, d2, d1, d1)))
    dist[k, j] = np.minimum(dist[k, j], ends.reshape(4, -1).min(axis=0))


def _point_segment(x: NDArray[np.float64], o: NDArray[np.float64],
                   d: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distances from points x (N, 3) to segments o + [0, 1] d (N, 3), shape (N,)."""
    u = np.clip(((x - o) * d).sum(axis=-1) / np.maximum((d * d).sum(axis=-1), _EPS), 0.0, 1.0)
    r = x - o - u[:, None] * d
    return np.sqrt((r * r).sum(axis=-1))


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
    dist, parallel = _closest_points_pass(P, Q)
    _refine_parallel(dist, P, Q, parallel)
    return dist


def signed_distances(P: NDArray[np.float64], p_radii: NDArray[np.float64],
                     Q: NDArray[np.float64], q_radii: NDArray[np.float64],
                     row_groups: NDArray[np.intp] | None = None) -> NDArray[np.float64]:
    """Signed capsule separations, exact wherever a minimum can be attained.

    Like ``segment_distances(P, Q) - p_radii[:, None] - q_radii[None, :]``, but nearly
    parallel pairs are refined only when they lie within ``_PARALLEL_SLACK`` of the
    minimum (over all pairs, or over each group of rows), the only place where their
    small excess could matter. The minimum, overall or per group, is exact.

    Parameters
    ----------
    P : ndarray, shape (K, 2, 3)
    p_radii : ndarray, shape (K,)
    Q : ndarray, shape (L, 2, 3)
    q_radii : ndarray, shape (L,)
    row_groups : ndarray of int, shape (G,), optional
        Start rows of groups of ``P`` (as for ``np.minimum.reduceat``), e.g. the samples
        of a predicted occupancy.

    Returns
    -------
    distances : ndarray, shape (K, L)
    """
    dist, parallel = _closest_points_pass(P, Q)
    signed = dist - p_radii[:, None] - q_radii[None, :]
    if parallel.any():
        if row_groups is None:
            floor = signed.min()
        else:
            floor = np.repeat(np.minimum.reduceat(signed.min(axis=1), row_groups),
                              np.diff(np.append(row_groups, len(signed))))[:, None]
        near = parallel & (signed <= floor + _PARALLEL_SLACK)
        if near.any():
            _refine_parallel(dist, P, Q, near)
            signed = dist - p_radii[:, None] - q_radii[None, :]
    return signed


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
    hs, hr, rs, r_r = _capsule_pair(human_segments, human_radii, robot_segments,
                                    robot_radii, validate)
    return float(signed_distances(hs, hr, rs, r_r).min())


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
