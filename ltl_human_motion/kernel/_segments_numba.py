"""Compiled loops of :mod:`ltl_human_motion.kernel.segments` (imported only on first use).

The same algorithm as the numpy path (clamped closest points of the two lines, then the
end-point distances for nearly parallel pairs), one pair at a time in scalars: no
temporary arrays, so the 17 x 7 query costs a few microseconds. ``cache=True`` keeps the
machine code in ``__pycache__`` (or numba's user cache) across processes.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ltl_human_motion.kernel.segment_constants import EPS, PARALLEL, TINY

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def _clamp01(x: float) -> float:
    return min(max(x, 0.0), 1.0)


@_jit
def _point_segment(x0, x1, x2, o0, o1, o2, d0, d1, d2) -> float:
    """Distance from point x to segment o + [0, 1] d."""
    w0, w1, w2 = x0 - o0, x1 - o1, x2 - o2
    u = _clamp01((w0 * d0 + w1 * d1 + w2 * d2) / max(d0 * d0 + d1 * d1 + d2 * d2, EPS))
    r0, r1, r2 = w0 - u * d0, w1 - u * d1, w2 - u * d2
    return math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)


@_jit
def _pair(p0, p1, p2, u0, u1, u2, q0, q1, q2, v0, v1, v2) -> float:
    """Exact distance between segments p + [0, 1] u and q + [0, 1] v."""
    r0, r1, r2 = p0 - q0, p1 - q1, p2 - q2
    a = u0 * u0 + u1 * u1 + u2 * u2
    e = v0 * v0 + v1 * v1 + v2 * v2
    b = u0 * v0 + u1 * v1 + u2 * v2
    c = u0 * r0 + u1 * r1 + u2 * r2
    f = v0 * r0 + v1 * r1 + v2 * r2
    a_s = max(a, EPS)
    e_s = max(e, EPS)
    denom = a * e - b * b
    s = _clamp01((b * f - c * e) / max(denom, TINY))
    t = _clamp01((b * s + f) / e_s)
    s = _clamp01((b * t - c) / a_s)
    g0 = r0 + s * u0 - t * v0
    g1 = r1 + s * u1 - t * v1
    g2 = r2 + s * u2 - t * v2
    d = math.sqrt(g0 * g0 + g1 * g1 + g2 * g2)
    if denom <= PARALLEL * a_s * e_s:
        d = min(d, _point_segment(p0, p1, p2, q0, q1, q2, v0, v1, v2),
                _point_segment(p0 + u0, p1 + u1, p2 + u2, q0, q1, q2, v0, v1, v2),
                _point_segment(q0, q1, q2, p0, p1, p2, u0, u1, u2),
                _point_segment(q0 + v0, q1 + v1, q2 + v2, p0, p1, p2, u0, u1, u2))
    return d


@_jit
def _pair_of(P, k, Q, j) -> float:
    return _pair(P[k, 0, 0], P[k, 0, 1], P[k, 0, 2],
                 P[k, 1, 0] - P[k, 0, 0], P[k, 1, 1] - P[k, 0, 1], P[k, 1, 2] - P[k, 0, 2],
                 Q[j, 0, 0], Q[j, 0, 1], Q[j, 0, 2],
                 Q[j, 1, 0] - Q[j, 0, 0], Q[j, 1, 1] - Q[j, 0, 1], Q[j, 1, 2] - Q[j, 0, 2])


@_jit
def pairwise(P, Q, out) -> None:
    """out[k, j] = distance of segments P[k] (K, 2, 3) and Q[j] (L, 2, 3)."""
    for k in range(P.shape[0]):
        for j in range(Q.shape[0]):
            out[k, j] = _pair_of(P, k, Q, j)


@_jit
def signed(P, pr, Q, qr, out) -> None:
    """out[k, j] = capsule separation of (P[k], pr[k]) and (Q[j], qr[j])."""
    for k in range(P.shape[0]):
        for j in range(Q.shape[0]):
            out[k, j] = _pair_of(P, k, Q, j) - pr[k] - qr[j]


@_jit
def group_min_signed(P, pr, Q, qr, starts, out) -> None:
    """out[g] = minimum separation over rows starts[g]:starts[g + 1] of P (as reduceat)."""
    n = starts.shape[0]
    for g in range(n):
        stop = starts[g + 1] if g + 1 < n else P.shape[0]
        best = np.inf
        for k in range(starts[g], stop):
            for j in range(Q.shape[0]):
                d = _pair_of(P, k, Q, j) - pr[k] - qr[j]
                if d < best:
                    best = d
        out[g] = best


@_jit
def batched_min_signed(P, pr, Q, qr, out) -> None:
    """out[m] = minimum separation of capsules P[m] (M, K, 2, 3) against Q[m] (M, L, 2, 3),
    pair by pair as :func:`group_min_signed` with one group."""
    for m in range(P.shape[0]):
        Pm = P[m]
        Qm = Q[m]
        best = np.inf
        for k in range(Pm.shape[0]):
            for j in range(Qm.shape[0]):
                d = _pair_of(Pm, k, Qm, j) - pr[k] - qr[j]
                if d < best:
                    best = d
        out[m] = best


@_jit
def elementwise(A, B, out) -> None:
    """out[n] = distance of segments A[n] (N, 2, 3) and B[n] (N, 2, 3)."""
    for n in range(A.shape[0]):
        out[n] = _pair_of(A, n, B, n)


@_jit
def bounded(seg, rad, max_coordinate, max_radius) -> bool:
    """Whether every coordinate is finite and within +-max_coordinate and every radius
    finite and within [0, max_radius] (NaN fails every comparison)."""
    for x in seg.ravel():
        if not abs(x) <= max_coordinate:
            return False
    for r in rad:
        if not (r >= 0.0 and r <= max_radius):
            return False
    return True


@_jit
def indexed(X, ends_a, ends_b, out) -> None:
    """out[t, p] = distance of segments X[t, ends_a[p, 0]] - X[t, ends_a[p, 1]] and
    X[t, ends_b[p, 0]] - X[t, ends_b[p, 1]] (X (T, J, 3), ends (P, 2), out (T, P))."""
    for t in range(X.shape[0]):
        x = X[t]
        for p in range(ends_a.shape[0]):
            i, j = ends_a[p, 0], ends_a[p, 1]
            k, m = ends_b[p, 0], ends_b[p, 1]
            out[t, p] = _pair(x[i, 0], x[i, 1], x[i, 2],
                              x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2],
                              x[k, 0], x[k, 1], x[k, 2],
                              x[m, 0] - x[k, 0], x[m, 1] - x[k, 1], x[m, 2] - x[k, 2])


#: Slack (m) of the bounds of :func:`indexed_max_excess`: far above the rounding of a
#: pair's distance and of the joints' summed travel, far below any clearance that matters.
_BOUND_SLACK = 1e-9


@_jit
def indexed_max_excess(X, seg_ends, pair_a, pair_b, reach, where) -> float:
    """max over t, p of reach[p] minus the distance of segments seg_ends[pair_a[p]] and
    seg_ends[pair_b[p]] of X[t] (X (T, J, 3) finite, seg_ends (S, 2) joint indices,
    pair_a, pair_b, reach (P,)), and where it first occurs in C order (where[0] = t,
    where[1] = p): the numbers of ``reach - indexed(...)`` and its argmax. A pair is not
    measured where a lower bound of its distance keeps it ``_BOUND_SLACK`` below the best
    so far: its distance when last measured less the travel of its end joints since
    (a segment's points move no further than its ends), or the gap of the two segments'
    bounding spheres."""
    S, P, J = seg_ends.shape[0], pair_a.shape[0], X.shape[1]
    mid = np.empty((S, 3))
    half = np.empty(S)
    travel = np.zeros(J)            # each joint's path length so far
    last = np.full(P, -1.0)         # each pair's distance when last measured
    at = np.zeros((P, 4))           # its end joints' travel then
    best = -np.inf
    found = False
    for t in range(X.shape[0]):
        x = X[t]
        if t:
            for j in range(J):
                d0, d1, d2 = x[j, 0] - X[t - 1, j, 0], x[j, 1] - X[t - 1, j, 1], \
                    x[j, 2] - X[t - 1, j, 2]
                travel[j] += math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        for s in range(S):
            i, j = seg_ends[s, 0], seg_ends[s, 1]
            d0, d1, d2 = x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2]
            mid[s, 0], mid[s, 1], mid[s, 2] = x[i, 0] + 0.5 * d0, x[i, 1] + 0.5 * d1, \
                x[i, 2] + 0.5 * d2
            half[s] = 0.5 * math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        for p in range(P):
            a, b = pair_a[p], pair_b[p]
            i, j = seg_ends[a, 0], seg_ends[a, 1]
            k, m = seg_ends[b, 0], seg_ends[b, 1]
            if found:
                if last[p] >= 0.0:
                    moved = max(travel[i] - at[p, 0], travel[j] - at[p, 1]) \
                        + max(travel[k] - at[p, 2], travel[m] - at[p, 3])
                    if reach[p] - (last[p] - moved) + _BOUND_SLACK < best:
                        continue
                room = reach[p] - best + _BOUND_SLACK + half[a] + half[b]
                g0, g1, g2 = mid[a, 0] - mid[b, 0], mid[a, 1] - mid[b, 1], mid[a, 2] - mid[b, 2]
                if room < 0.0 or g0 * g0 + g1 * g1 + g2 * g2 > room * room:
                    continue
            d = _pair(x[i, 0], x[i, 1], x[i, 2],
                      x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2],
                      x[k, 0], x[k, 1], x[k, 2],
                      x[m, 0] - x[k, 0], x[m, 1] - x[k, 1], x[m, 2] - x[k, 2])
            last[p] = d
            at[p, 0], at[p, 1], at[p, 2], at[p, 3] = travel[i], travel[j], travel[k], travel[m]
            e = reach[p] - d
            if not found or e > best:
                best = e
                where[0], where[1] = t, p
                found = True
    return best
