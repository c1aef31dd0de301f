"""Exact segment-segment and capsule-capsule distances: the one kernel of scene and robot.

A capsule is a segment (2, 3) with a radius; the separation of two capsules is the distance
between their axes (exact closest points of two segments, clamped to the segments) minus
both radii, *signed*: negative when the capsules overlap.

One algorithm (Ericson, *Real-Time Collision Detection*, Sec. 5.1.9): the clamped closest
points of the two lines, then, for nearly parallel pairs, whose closest points rounding can
lose, the four end-point-to-segment distances (their minimum is attained at an end point).
It runs compiled (numba, one pair at a time in scalars) where numba is installed and
``LTL_HUMAN_MOTION_NUMBA`` is not ``0``; otherwise in numpy, with the same results to
rounding. Numba is imported on the first call, so code that never asks for a distance
pays nothing for it.
"""

from __future__ import annotations

import functools
import importlib
import os
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ltl_human_motion.kernel.segment_constants import EPS, PARALLEL, TINY

__all__ = [
    "MAX_COORDINATE",
    "MAX_RADIUS",
    "batched_min_signed_distances",
    "check_capsules",
    "compiled",
    "compiled_module",
    "group_min_signed_distances",
    "joint_segment_distances",
    "min_signed_distance",
    "segment_distances",
    "segment_segment_distance",
    "signed_distances",
]

#: Coordinates beyond this (m) are rejected as nonsense by :func:`check_capsules`.
MAX_COORDINATE = 1.0e3
#: Radii beyond this (m) are rejected as nonsense (no body part or robot link is 10 m thick).
MAX_RADIUS = 10.0

_PARALLEL_SLACK = 0.05
"""m. For a nearly parallel pair the closest-points pass can land on a point pair farther
apart than the closest one (by rounding; hypothesis found 6e-5 m). Where only a minimum
counts (numpy :func:`signed_distances`), pairs more than this above it are left unrefined:
the excess is orders of magnitude smaller."""


@functools.cache
def _compiled() -> ModuleType | None:
    """The numba kernels, imported (and compiled or loaded from cache) on first use."""
    if os.environ.get("LTL_HUMAN_MOTION_NUMBA", "1") == "0":
        return None
    try:
        from ltl_human_motion.kernel import _segments_numba
    except ImportError:
        return None
    return _segments_numba


def compiled() -> bool:
    """Whether the compiled kernels are in use (numba installed and not disabled); the
    first call imports numba (about a second cold): call it before a real-time loop."""
    nb = _compiled()
    if nb is None:
        return False
    seg = np.zeros((1, 2, 3))
    rad = np.zeros(1)
    nb.signed(seg, rad, seg, rad, np.empty((1, 1)))
    nb.group_min_signed(seg, rad, seg, rad, np.zeros(1, dtype=np.intp), np.empty(1))
    nb.pairwise(seg, seg, np.empty((1, 1)))
    nb.elementwise(seg, seg, np.empty(1))
    nb.indexed(seg, np.zeros((1, 2), dtype=np.intp), np.zeros((1, 2), dtype=np.intp),
               np.empty((1, 1)))
    nb.bounded(seg, rad, 1.0, 1.0)
    return True


# ---------------------------------------------------------------------------- validation

@functools.cache
def compiled_module(name: str) -> ModuleType | None:
    """The compiled-loop module ``name`` (e.g. ``"ltl_human_motion.planning.
    _navigation_numba"``) where the compiled kernels are in use, else None (numba missing
    or disabled, or the module fails to import): the numpy paths run instead. Decided
    once per name."""
    if not compiled():
        return None
    try:
        return importlib.import_module(name)
    except ImportError:
        return None

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
    segments : ndarray, shape (K, 2, 3), C-contiguous float64
    radii : ndarray, shape (K,), C-contiguous float64

    Raises
    ------
    ValueError
        Wrong shapes, no capsule, NaN/inf, negative or absurd radii, absurd coordinates.
    """
    try:
        seg = _as_kernel_array(segments)
        rad = _as_kernel_array(radii)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what}: expected numeric arrays ({exc})") from exc
    if seg.ndim != 3 or seg.shape[1:] != (2, 3) or seg.shape[0] == 0:
        raise ValueError(f"{what}: segments must have shape (K, 2, 3) with K >= 1, "
                         f"got {seg.shape}")
    if rad.shape != (seg.shape[0],):
        raise ValueError(f"{what}: radii must have shape ({seg.shape[0]},), got {rad.shape}")
    nb = _compiled()
    if nb is not None:
        if nb.bounded(seg, rad, max_coordinate, MAX_RADIUS):
            return seg, rad
    # One reduction per array; NaN fails every comparison, so it takes the slow path.
    elif np.abs(seg).max() <= max_coordinate and rad.min() >= 0.0 and rad.max() <= MAX_RADIUS:
        return seg, rad
    if not (np.all(np.isfinite(seg)) and np.all(np.isfinite(rad))):
        raise ValueError(f"{what}: contains NaN or inf")
    if np.any(rad < 0) or np.any(rad > MAX_RADIUS):
        raise ValueError(f"{what}: radii must be in [0, {MAX_RADIUS}] m, "
                         f"got [{rad.min()}, {rad.max()}]")
    raise ValueError(f"{what}: coordinates beyond {max_coordinate} m")


# ---------------------------------------------------------------------------- numpy path
def _clamped_closest(a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64],
                     e: NDArray[np.float64], f: NDArray[np.float64]
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Parameters ``s`` on P and ``t`` on Q of the clamped closest points, and which pairs
    are nearly parallel, from the dot products a = d1.d1, b = d1.d2, c = d1.r, e = d2.d2,
    f = d2.r (r = p0 - q0), all broadcast to one shape (...)."""
    a_s = np.maximum(a, EPS)    # a point has d1 = 0, so b = c = 0 as well
    e_s = np.maximum(e, EPS)
    # Closest points of the two lines, clamped to P; for parallel lines (denom ~ 0) any s
    # works, and the huge ratio is clamped to an end of P.
    denom = a * e - b * b
    s = np.minimum(np.maximum((b * f - c * e) / np.maximum(denom, TINY), 0.0), 1.0)
    t = np.minimum(np.maximum((b * s + f) / e_s, 0.0), 1.0)
    # Re-project Q(t) on P: where t was clamped this is the closest point on P; elsewhere
    # it cannot increase the (already minimal) distance.
    s = np.minimum(np.maximum((b * t - c) / a_s, 0.0), 1.0)
    return s, t, denom <= PARALLEL * a_s * e_s


def _point_segment(x: NDArray[np.float64], o: NDArray[np.float64],
                   d: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distances from points x (N, 3) to segments o + [0, 1] d (N, 3), shape (N,)."""
    u = np.clip(((x - o) * d).sum(axis=-1) / np.maximum((d * d).sum(axis=-1), EPS), 0.0, 1.0)
    r = x - o - u[:, None] * d
    return np.sqrt((r * r).sum(axis=-1))


def _parallel_ends(p0: NDArray[np.float64], d1: NDArray[np.float64], q0: NDArray[np.float64],
                   d2: NDArray[np.float64]) -> NDArray[np.float64]:
    """Exact distances (N,) of nearly parallel segment pairs p0 + [0,1] d1, q0 + [0,1] d2
    (each (N, 3)): the least of the four end-point-to-segment distances."""
    ends = _point_segment(np.concatenate((p0, p0 + d1, q0, q0 + d2)),
                          np.concatenate((q0, q0, p0, p0)),
                          np.concatenate((d2, d2, d1, d1)))
    return ends.reshape(4, -1).min(axis=0)


def _pairwise_pass(P: NDArray[np.float64], Q: NDArray[np.float64]
                   ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Closest-point distances (K, L) of all pairs and which pairs are nearly parallel
    (their distance may be slightly high until :func:`_refine_parallel`)."""
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
    s, t, parallel = _clamped_closest(a, b, c, e, f)
    # The closest points themselves (not an expansion of |r + s d1 - t d2|^2, which loses
    # precision to cancellation when the segments nearly touch).
    gap = (p0[:, None, :] - q0[None, :, :]) + s[..., None] * d1[:, None, :] \
        - t[..., None] * d2[None, :, :]
    return np.sqrt((gap * gap).sum(axis=-1)), parallel


def _refine_parallel(dist: NDArray[np.float64], P: NDArray[np.float64],
                     Q: NDArray[np.float64], mask: NDArray[np.bool_]) -> None:
    """Make ``dist`` (K, L) exact, in place, for the nearly parallel pairs in ``mask``."""
    k, j = np.nonzero(mask)
    if k.size:
        p0, q0 = P[k, 0], Q[j, 0]
        ends = _parallel_ends(p0, P[k, 1] - p0, q0, Q[j, 1] - q0)
        dist[k, j] = np.minimum(dist[k, j], ends)


def _numpy_segment_distances(P: NDArray[np.float64], Q: NDArray[np.float64]
                             ) -> NDArray[np.float64]:
    dist, parallel = _pairwise_pass(P, Q)
    _refine_parallel(dist, P, Q, parallel)
    return dist


def _numpy_signed_distances(P: NDArray[np.float64], p_radii: NDArray[np.float64],
                            Q: NDArray[np.float64], q_radii: NDArray[np.float64],
                            row_groups: NDArray[np.intp] | None = None
                            ) -> NDArray[np.float64]:
    """Signed separations (K, L), refining the nearly parallel pairs only within
    ``_PARALLEL_SLACK`` of the minimum (overall or per group of rows)."""
    dist, parallel = _pairwise_pass(P, Q)
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


def _numpy_elementwise(p0: NDArray[np.float64], d1: NDArray[np.float64],
                       q0: NDArray[np.float64], d2: NDArray[np.float64]) -> NDArray[np.float64]:
    """Exact distances (N,) of segment pairs given by start points and directions (N, 3)."""
    r = p0 - q0
    s, t, parallel = _clamped_closest((d1 * d1).sum(-1), (d1 * d2).sum(-1), (d1 * r).sum(-1),
                                      (d2 * d2).sum(-1), (d2 * r).sum(-1))
    gap = r + s[:, None] * d1 - t[:, None] * d2
    dist = np.sqrt((gap * gap).sum(axis=-1))
    (n,) = np.nonzero(parallel)
    if n.size:
        dist[n] = np.minimum(dist[n], _parallel_ends(p0[n], d1[n], q0[n], d2[n]))
    return dist


# ---------------------------------------------------------------------------- public API
def _as_kernel_array(a: ArrayLike) -> NDArray[np.float64]:
    """``a`` as a writeable C-contiguous float64 array, the one array type the compiled
    kernels are built for (no copy when it already is one; a read-only view, e.g. from
    ``np.broadcast_to`` or ``np.frombuffer``, is copied, so that it does not trigger a
    second compilation in the middle of a control loop)."""
    arr = np.ascontiguousarray(a, dtype=np.float64)
    return arr if arr.flags.writeable else arr.copy()


def _contiguous(*arrays: ArrayLike) -> list[NDArray[np.float64]]:
    """The arrays as :func:`_as_kernel_array` gives them."""
    return [_as_kernel_array(a) for a in arrays]


def segment_segment_distance(p0: ArrayLike, p1: ArrayLike, q0: ArrayLike,
                             q1: ArrayLike) -> NDArray[np.float64]:
    """Exact minimum distance between segments ``[p0, p1]`` and ``[q0, q1]``, elementwise.

    Robust for degenerate (point) segments and exact for parallel ones.

    Parameters
    ----------
    p0, p1, q0, q1 : array-like, shape (..., 3), broadcast together

    Returns
    -------
    d : ndarray, shape (...)
    """
    p0, p1, q0, q1 = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                           for x in (p0, p1, q0, q1)))
    shape = p0.shape[:-1]
    if p0.shape[-1:] != (3,):
        raise ValueError(f"segment end points must have shape (..., 3), got {p0.shape}")
    a = np.stack((p0, p1), axis=-2).reshape(-1, 2, 3)
    b = np.stack((q0, q1), axis=-2).reshape(-1, 2, 3)
    nb = _compiled()
    if nb is not None:
        out = np.empty(len(a))
        nb.elementwise(a, b, out)
    else:
        out = _numpy_elementwise(a[:, 0], a[:, 1] - a[:, 0], b[:, 0], b[:, 1] - b[:, 0])
    return out.reshape(shape)


def joint_segment_distances(X: ArrayLike, ends_a: ArrayLike, ends_b: ArrayLike
                            ) -> NDArray[np.float64]:
    """Exact distances between segments joining points of ``X``, pair by pair.

    The numbers of :func:`segment_segment_distance` (the same pair kernel) for segments
    given by the indices of their end points, without gathering the end points first.

    Parameters
    ----------
    X : array-like, shape (T, J, 3)
        Points (e.g. joint positions of T poses).
    ends_a, ends_b : array-like of int, shape (P, 2)
        Pair ``p`` joins ``X[:, ends_a[p, 0]]`` to ``X[:, ends_a[p, 1]]`` and
        ``X[:, ends_b[p, 0]]`` to ``X[:, ends_b[p, 1]]``.

    Returns
    -------
    d : ndarray, shape (T, P)
    """
    (x,) = _contiguous(X)
    ia = np.ascontiguousarray(ends_a, dtype=np.intp)
    ib = np.ascontiguousarray(ends_b, dtype=np.intp)
    if x.ndim != 3 or x.shape[-1] != 3 or ia.ndim != 2 or ia.shape[1:] != (2,) \
            or ia.shape != ib.shape:
        raise ValueError(f"joint segments: expected points (T, J, 3) and two (P, 2) index "
                         f"arrays, got {x.shape}, {ia.shape} and {ib.shape}")
    if ia.size and not (0 <= min(ia.min(), ib.min()) and max(ia.max(), ib.max()) < x.shape[1]):
        raise ValueError(f"joint segments: indices beyond the {x.shape[1]} points")
    nb = _compiled()
    if nb is not None:
        out = np.empty((len(x), len(ia)))
        nb.indexed(x, ia, ib, out)
        return out
    a = x[:, ia.ravel()].reshape(-1, 2, 3)
    b = x[:, ib.ravel()].reshape(-1, 2, 3)
    d = _numpy_elementwise(a[:, 0], a[:, 1] - a[:, 0], b[:, 0], b[:, 1] - b[:, 0])
    return d.reshape(len(x), len(ia))


def segment_distances(P: ArrayLike, Q: ArrayLike) -> NDArray[np.float64]:
    """Exact distances between every segment of ``P`` and every segment of ``Q``.

    Parameters
    ----------
    P : array-like, shape (K, 2, 3)
    Q : array-like, shape (L, 2, 3)

    Returns
    -------
    distances : ndarray, shape (K, L)
        Distance between the closest points (clamped to both segments).
    """
    P, Q = _contiguous(P, Q)
    nb = _compiled()
    if nb is None:
        return _numpy_segment_distances(P, Q)
    out = np.empty((len(P), len(Q)))
    nb.pairwise(P, Q, out)
    return out


def signed_distances(P: ArrayLike, p_radii: ArrayLike, Q: ArrayLike, q_radii: ArrayLike,
                     row_groups: ArrayLike | None = None) -> NDArray[np.float64]:
    """Signed capsule separations, exact wherever a minimum can be attained.

    Compiled, every pair is exact. In numpy, nearly parallel pairs are refined only when
    they lie within ``_PARALLEL_SLACK`` of the minimum (over all pairs, or over each group
    of rows), the only place where their small excess could matter; the minimum, overall
    or per group, is exact either way.

    Parameters
    ----------
    P : array-like, shape (K, 2, 3)
    p_radii : array-like, shape (K,)
    Q : array-like, shape (L, 2, 3)
    q_radii : array-like, shape (L,)
    row_groups : array-like of int, shape (G,), optional
        Start rows of groups of ``P`` (as for ``np.minimum.reduceat``), e.g. the samples
        of a predicted occupancy.

    Returns
    -------
    distances : ndarray, shape (K, L)
    """
    P, pr, Q, qr = _contiguous(P, p_radii, Q, q_radii)
    nb = _compiled()
    if nb is None:
        groups = None if row_groups is None else np.asarray(row_groups, dtype=np.intp)
        return _numpy_signed_distances(P, pr, Q, qr, groups)
    out = np.empty((len(P), len(Q)))
    nb.signed(P, pr, Q, qr, out)
    return out


def min_signed_distance(P: ArrayLike, p_radii: ArrayLike, Q: ArrayLike,
                        q_radii: ArrayLike) -> float:
    """Minimum signed capsule separation (m) of capsules P (K, 2, 3), (K,) against
    Q (L, 2, 3), (L,); exact. Negative when a pair overlaps."""
    return float(group_min_signed_distances(P, p_radii, Q, q_radii, _ONE_GROUP)[0])


_ONE_GROUP = np.zeros(1, dtype=np.intp)


def batched_min_signed_distances(P: ArrayLike, p_radii: ArrayLike, Q: ArrayLike,
                                 q_radii: ArrayLike) -> NDArray[np.float64]:
    """``min_signed_distance(P[m], p_radii, Q[m], q_radii)`` for every ``m``, in one call.

    The same numbers as the one-query function (same pair kernel, same order), for many
    independent queries, e.g. the control steps of an offline run.

    Parameters
    ----------
    P : array-like, shape (M, K, 2, 3)
    p_radii : array-like, shape (K,)
    Q : array-like, shape (M, L, 2, 3)
    q_radii : array-like, shape (L,)

    Returns
    -------
    minima : ndarray, shape (M,)
    """
    P, pr, Q, qr = _contiguous(P, p_radii, Q, q_radii)
    if P.ndim != 4 or Q.ndim != 4 or len(P) != len(Q):
        raise ValueError(f"batched capsules: expected (M, K, 2, 3) and (M, L, 2, 3), got "
                         f"{P.shape} and {Q.shape}")
    nb = _compiled()
    if nb is None:
        return np.array([min_signed_distance(P[m], pr, Q[m], qr) for m in range(len(P))],
                        dtype=np.float64).reshape(len(P))
    out = np.empty(len(P))
    nb.batched_min_signed(P, pr, Q, qr, out)
    return out


def group_min_signed_distances(P: ArrayLike, p_radii: ArrayLike, Q: ArrayLike,
                               q_radii: ArrayLike, row_groups: ArrayLike
                               ) -> NDArray[np.float64]:
    """Minimum signed separation of each group of rows of ``P`` against all of ``Q``.

    The batched query of the control loop: the capsules of many predicted samples stacked
    in ``P``, one minimum per sample, exact.

    Parameters
    ----------
    P, p_radii, Q, q_radii
        Capsules (K, 2, 3), (K,) and (L, 2, 3), (L,), as for :func:`signed_distances`.
    row_groups : array-like of int, shape (G,)
        Increasing start rows of the groups, the first 0 (as for ``np.minimum.reduceat``).

    Returns
    -------
    minima : ndarray, shape (G,)
    """
    P, pr, Q, qr = _contiguous(P, p_radii, Q, q_radii)
    starts = np.ascontiguousarray(row_groups, dtype=np.intp)
    nb = _compiled()
    if nb is None:
        d = _numpy_signed_distances(P, pr, Q, qr, None if len(starts) == 1 else starts)
        return np.minimum.reduceat(d.min(axis=1), starts)
    out = np.empty(len(starts))
    nb.group_min_signed(P, pr, Q, qr, starts, out)
    return out
