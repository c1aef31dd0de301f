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
def _box_point2(a0, a1, a2, d0, d1, d2, t, lo0, lo1, lo2, hi0, hi1, hi2):
    """The square of ``point_box_distance`` of the point a + t d to the box lo, hi (the
    sum its square root is taken of)."""
    e0 = max(max(lo0 - (a0 + t * d0), (a0 + t * d0) - hi0), 0.0)
    e1 = max(max(lo1 - (a1 + t * d1), (a1 + t * d1) - hi1), 0.0)
    e2 = max(max(lo2 - (a2 + t * d2), (a2 + t * d2) - hi2), 0.0)
    return e0 * e0 + e1 * e1 + e2 * e2


@_jit
def _segment_aabb(a0, a1, a2, b0, b1, b2, lo0, lo1, lo2, hi0, hi1, hi2, knots):
    """``geometry.segment_aabb_distance`` of segment [a, b] and box lo, hi: the 15
    candidates of the closed form (ends, face crossings, clipped stationary points of
    the pieces), operation for operation; the least of their squared distances has the
    least root, so one square root is taken (knots: scratch (8,))."""
    d0, d1, d2 = b0 - a0, b1 - a1, b2 - a2
    knots[0], knots[1] = 0.0, 1.0
    for j, face, a, d in ((2, lo0, a0, d0), (3, lo1, a1, d1), (4, lo2, a2, d2),
                          (5, hi0, a0, d0), (6, hi1, a1, d1), (7, hi2, a2, d2)):
        c = (face - a) / d
        knots[j] = min(max(c, 0.0), 1.0) if math.isfinite(c) else 0.0
    for i in range(1, 8):            # insertion sort: np.sort's values, faster on 8
        v = knots[i]
        j = i - 1
        while j >= 0 and knots[j] > v:
            knots[j + 1] = knots[j]
            j -= 1
        knots[j + 1] = v
    best = np.inf
    for i in range(8):
        best = min(best, _box_point2(a0, a1, a2, d0, d1, d2, knots[i], lo0, lo1, lo2,
                                     hi0, hi1, hi2))
    for i in range(7):
        t0, t1 = knots[i], knots[i + 1]
        half = 0.5 * (t0 + t1)
        num = 0.0
        den = 0.0
        for k, a, d, lo, hi in ((0, a0, d0, lo0, hi0), (1, a1, d1, lo1, hi1),
                                (2, a2, d2, lo2, hi2)):
            mid = a + half * d
            if mid < lo:
                off, slope = a - lo, d
            elif mid > hi:
                off, slope = a - hi, d
            else:
                off, slope = 0.0, 0.0
            num = num + off * slope if k else off * slope
            den = den + slope * slope if k else slope * slope
        num = -num
        stat = num / den if den > 0 else t0
        stat = min(max(stat, t0), t1)
        best = min(best, _box_point2(a0, a1, a2, d0, d1, d2, stat, lo0, lo1, lo2, hi0, hi1,
                                     hi2))
    return math.sqrt(best)


@_jit
def segment_aabb_distance(a, b, lo, hi, out) -> None:
    """out[n] = ``geometry.segment_aabb_distance`` of segment [a[n], b[n]] and box
    lo[n], hi[n] (all (N, 3)) (:func:`_segment_aabb`)."""
    knots = np.empty(8)
    for n in range(a.shape[0]):
        out[n] = _segment_aabb(a[n, 0], a[n, 1], a[n, 2], b[n, 0], b[n, 1], b[n, 2],
                               lo[n, 0], lo[n, 1], lo[n, 2], hi[n, 0], hi[n, 1], hi[n, 2],
                               knots)


@_jit
def exact_box_caps(seg, rad, f_idx, p_idx, caps, exact_below, is_box, center, half,
                   others) -> int:
    """The exact values of :func:`body_bounds`' capsule bounds below ``exact_below``
    against axis-aligned boxes, in place: caps[m, k] = the segment-box distance
    (:func:`_segment_aabb`) of capsule k of frame f_idx[m] (seg (F, K, 2, 3)) and box
    p_idx[m] (``is_box`` (P,), ``center``, ``half`` (P, 3)), both moved by the box's
    centre, less rad[k]. The flat indices m * K + k of the pairs below ``exact_below``
    with another part are written to ``others``; returns their count."""
    K = seg.shape[1]
    knots = np.empty(8)
    n_others = 0
    for m in range(f_idx.shape[0]):
        f, p = f_idx[m], p_idx[m]
        for k in range(K):
            if not caps[m, k] < exact_below:
                continue
            if not is_box[p]:
                others[n_others] = m * K + k
                n_others += 1
                continue
            caps[m, k] = _cap_box(seg, f, k, p, center, half, knots) - rad[k]
    return n_others


@_jit
def _cap_box(seg, f, k, p, center, half, knots):
    """The segment-box distance (:func:`_segment_aabb`) of capsule k of frame f of seg
    (F, K, 2, 3) and the axis-aligned box p (``center``, ``half`` (P, 3)), both moved by
    the box's centre."""
    c0, c1, c2 = center[p, 0], center[p, 1], center[p, 2]
    h0, h1, h2 = half[p, 0], half[p, 1], half[p, 2]
    return _segment_aabb(seg[f, k, 0, 0] - c0, seg[f, k, 0, 1] - c1, seg[f, k, 0, 2] - c2,
                         seg[f, k, 1, 0] - c0, seg[f, k, 1, 1] - c1, seg[f, k, 1, 2] - c2,
                         -h0, -h1, -h2, h0, h1, h2, knots)


#: How far (m) above the least clearance found a bound must be for the values it bounds
#: to be passed over unread: far more than their rounding errors (about 1e-14 m).
PASS_OVER = 1e-9


@_jit
def body_clearance_boxes(seg, rad, lo, hi, plo, phi, exact_below, center, half, out) -> None:
    """out[f] = ``PartSet.body_clearance`` of body f (seg (F, K, 2, 3), its box lo, hi
    (F, 3), all finite) against parts that are all axis-aligned boxes (plo, phi,
    ``center``, ``half`` (P, 3)): the least of the values of :func:`body_bounds` and
    :func:`exact_box_caps`, as they compute them. The parts near the body are read in
    order of their body bound; a part or capsule whose bound (each value it bounds is
    at least that, to rounding) is ``PASS_OVER`` above the least found is passed over:
    it cannot be the least."""
    F, K, P = seg.shape[0], seg.shape[1], plo.shape[0]
    rmax = rad.max()
    knots = np.empty(8)
    bound = np.empty(P)
    order = np.empty(P, dtype=np.int64)
    for f in range(F):
        best = np.inf
        n_near = 0
        for p in range(P):
            v = _gap(lo[f, 0], lo[f, 1], lo[f, 2], hi[f, 0], hi[f, 1], hi[f, 2],
                     plo[p], phi[p]) - rmax
            if v < exact_below:
                bound[p] = v
                i = n_near
                while i > 0 and bound[order[i - 1]] > v:
                    order[i] = order[i - 1]
                    i -= 1
                order[i] = p
                n_near += 1
            else:
                best = min(best, v)
        for i in range(n_near):
            p = order[i]
            if bound[p] >= best + PASS_OVER:
                break
            for k in range(K):
                a, b = seg[f, k, 0], seg[f, k, 1]
                cap = _gap(np.minimum(a[0], b[0]), np.minimum(a[1], b[1]),
                           np.minimum(a[2], b[2]), np.maximum(a[0], b[0]),
                           np.maximum(a[1], b[1]), np.maximum(a[2], b[2]),
                           plo[p], phi[p]) - rad[k]
                if cap >= best + PASS_OVER:
                    continue
                if cap < exact_below:
                    cap = _cap_box(seg, f, k, p, center, half, knots) - rad[k]
                best = min(best, cap)
        out[f] = best


@_jit
def pair_bounds(seg, rad, plo, phi, exact_below, is_box, center, half, out, others) -> int:
    """``PartSet.pair_clearance`` of capsules seg (N, 2, 3) with radii (N,) against every
    part (plo, phi (P, 3)) into out (N, P): the box gap less the radius, exact below
    ``exact_below`` for axis-aligned boxes (``is_box`` (P,), ``center``, ``half``
    (P, 3); :func:`_cap_box`). The flat indices n * P + p of the pairs below
    ``exact_below`` with another part are written to ``others``; returns their count."""
    N, P = seg.shape[0], plo.shape[0]
    knots = np.empty(8)
    n_others = 0
    one = seg.reshape(N, 1, 2, 3)
    for n in range(N):
        a, b = seg[n, 0], seg[n, 1]
        lo0, lo1, lo2 = np.minimum(a[0], b[0]), np.minimum(a[1], b[1]), np.minimum(a[2], b[2])
        hi0, hi1, hi2 = np.maximum(a[0], b[0]), np.maximum(a[1], b[1]), np.maximum(a[2], b[2])
        for p in range(P):
            v = _gap(lo0, lo1, lo2, hi0, hi1, hi2, plo[p], phi[p]) - rad[n]
            if v < exact_below:
                if is_box[p]:
                    v = _cap_box(one, n, 0, p, center, half, knots) - rad[n]
                else:
                    others[n_others] = n * P + p
                    n_others += 1
            out[n, p] = v
    return n_others


@_jit
def polygon_signed_distance(p, a, ab, normal, eps, out) -> None:
    """out[n] = ``geometry.point_polygon_signed_distance`` of p[n] (N, 2) to the convex
    polygon with edges a[v] + t ab[v] (V, 2) and unit outward normals (V, 2) (``eps``:
    its least squared edge length), operation for operation."""
    for n in range(p.shape[0]):
        px, py = p[n, 0], p[n, 1]
        inside = True
        best = np.inf
        for v in range(a.shape[0]):
            ox, oy = px - a[v, 0], py - a[v, 1]
            if not ox * normal[v, 0] + oy * normal[v, 1] <= 0.0:
                inside = False
            t = (ox * ab[v, 0] + oy * ab[v, 1]) / max(ab[v, 0] * ab[v, 0] + ab[v, 1] * ab[v, 1],
                                                       eps)
            t = min(max(t, 0.0), 1.0)
            dx, dy = px - (a[v, 0] + t * ab[v, 0]), py - (a[v, 1] + t * ab[v, 1])
            best = min(best, math.sqrt(dx * dx + dy * dy))
        out[n] = -best if inside else best


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
