"""Compiled bounds of :meth:`ltl_human_motion.scene.clearance.PartSet.body_clearance`
(imported on first use): the bounding-box gaps of bodies and of their capsules to the
parts, operation for operation as the numpy path computes them (the same numbers; tests
hold them together), without its temporaries of frames x parts x capsules."""

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
