"""Compiled bounds of :meth:`ltl_human_motion.scene.clearance.PartSet.body_clearance`
(imported on first use): the bounding-box gaps of bodies and of their capsules to the
parts, operation for operation as the numpy path computes them (the same numbers; tests
hold them together), without its temporaries of frames x parts x capsules; and the
exact segment-box distance of ``geometry.segment_aabb_distance`` the same way."""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def _gap(lo0, lo1, lo2, hi0, hi1, hi2, plo, phi):
    """``box_gap`` of the box lo, hi and the part box plo, phi (3,)."""
    g0 = np.maximum(np.maximum(plo[0] - hi0, lo0 - phi[0]), 0.0)
    g1 = np.maximum(np.maximum(plo[1] - hi1, lo1 - phi[1]), 0.0)
    g2 = np.maximum(np.maximum(plo[2] - hi2, lo2 - phi[2]), 0.0)
    return math.sqrt(g0 * g0 + g1 * g1 + g2 * g2)


@_jit
def body_bounds(seg, rad, lo, hi, plo, phi, exact_below):
    """Bounds of bodies (F, K, 2, 3) with radii (K,) and boxes lo, hi (F, 3) against
    parts plo, phi (P, 3).

    Returns ``body`` (F, P): the body box gap less the largest radius; the (frame, part)
    pairs below ``exact_below`` in row-major order, ``f_idx``, ``p_idx`` (M,); and
    ``caps`` (M, K): each pair's capsule box gaps less the capsule radii.
    """
    F, K = seg.shape[0], seg.shape[1]
    P = plo.shape[0]
    rmax = rad.max()
    body = np.empty((F, P))
    f_idx = np.empty(F * P, dtype=np.intp)
    p_idx = np.empty(F * P, dtype=np.intp)
    M = 0
    for f in range(F):
        for p in range(P):
            body[f, p] = _gap(lo[f, 0], lo[f, 1], lo[f, 2], hi[f, 0], hi[f, 1], hi[f, 2],
                              plo[p], phi[p]) - rmax
            if body[f, p] < exact_below:
                f_idx[M] = f
                p_idx[M] = p
                M += 1
    caps = np.empty((M, K))
    for m in range(M):
        s, p = seg[f_idx[m]], p_idx[m]
        for k in range(K):
            a, b = s[k, 0], s[k, 1]
            caps[m, k] = _gap(np.minimum(a[0], b[0]), np.minimum(a[1], b[1]),
                              np.minimum(a[2], b[2]), np.maximum(a[0], b[0]),
                              np.maximum(a[1], b[1]), np.maximum(a[2], b[2]),
                              plo[p], phi[p]) - rad[k]
    return body, f_idx[:M].copy(), p_idx[:M].copy(), caps


@_jit
def _box_point(a, d, t, lo, hi, n):
    """``point_box_distance`` of the point a + t d (3,) to box n of lo, hi (N, 3)."""
    e0 = max(max(lo[n, 0] - (a[0] + t * d[0]), (a[0] + t * d[0]) - hi[n, 0]), 0.0)
    e1 = max(max(lo[n, 1] - (a[1] + t * d[1]), (a[1] + t * d[1]) - hi[n, 1]), 0.0)
    e2 = max(max(lo[n, 2] - (a[2] + t * d[2]), (a[2] + t * d[2]) - hi[n, 2]), 0.0)
    return math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)


@_jit
def segment_aabb_distance(a, b, lo, hi, out) -> None:
    """out[n] = ``geometry.segment_aabb_distance`` of segment [a[n], b[n]] and box
    lo[n], hi[n] (all (N, 3)): the 15 candidates of the closed form (ends, face
    crossings, clipped stationary points of the pieces), operation for operation."""
    knots = np.empty(8)
    d = np.empty(3)
    an = np.empty(3)
    for n in range(a.shape[0]):
        for k in range(3):
            an[k] = a[n, k]
            d[k] = b[n, k] - a[n, k]
        knots[0], knots[1] = 0.0, 1.0
        for k in range(3):
            for j, face in ((2 + k, lo[n, k]), (5 + k, hi[n, k])):
                c = (face - an[k]) / d[k]
                knots[j] = min(max(c, 0.0), 1.0) if math.isfinite(c) else 0.0
        knots.sort()
        best = np.inf
        for i in range(8):
            best = min(best, _box_point(an, d, knots[i], lo, hi, n))
        for i in range(7):
            t0, t1 = knots[i], knots[i + 1]
            half = 0.5 * (t0 + t1)
            num = 0.0
            den = 0.0
            for k in range(3):
                mid = an[k] + half * d[k]
                if mid < lo[n, k]:
                    off, slope = an[k] - lo[n, k], d[k]
                elif mid > hi[n, k]:
                    off, slope = an[k] - hi[n, k], d[k]
                else:
                    off, slope = 0.0, 0.0
                num = num + off * slope if k else off * slope
                den = den + slope * slope if k else slope * slope
            num = -num
            stat = num / den if den > 0 else t0
            stat = min(max(stat, t0), t1)
            best = min(best, _box_point(an, d, stat, lo, hi, n))
        out[n] = best


@_jit
def point_bounds(rows, lo, hi) -> None:
    """lo[m], hi[m] (3,): the least and greatest coordinates of the points rows[m] (M, N, 3),
    N >= 1, taken as ``np.minimum`` and ``np.maximum`` fold them point after point (a NaN
    propagates; of two equal values the later one is kept)."""
    for m in range(rows.shape[0]):
        for c in range(3):
            a = b = rows[m, 0, c]
            for n in range(1, rows.shape[1]):
                v = rows[m, n, c]
                a = a if (a < v or a != a) else v
                b = b if (b > v or b != b) else v
            lo[m, c] = a
            hi[m, c] = b
