"""Compiled loop of :func:`ltl_human_motion.motion.ik.two_bone_ik` (imported on first use):
one chain at a time in scalars, operation for operation as the numpy path computes it
(numpy's sums over x, y, z start from +0.0; ``np.clip`` and ``np.maximum`` keep their
signed zeros), so the numbers are the same; a test holds them together."""

from __future__ import annotations

import math

import numba

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def chain(b0, b1, b2, t0, t1, t2, q0, q1, q2, l1, l2, dmin, dmax):
    """One chain of :func:`two_bone` (base b, target t, pole q): the middle joint and the
    end, (m0, m1, m2, e0, e1, e2)."""
    v0, v1, v2 = t0 - b0, t1 - b1, t2 - b2
    dist = math.sqrt(0.0 + v0 * v0 + v1 * v1 + v2 * v2)
    dd = dist if dist > 1e-9 else 1e-9
    u0, u1, u2 = v0 / dd, v1 / dd, v2 / dd
    d = dmin if dist < dmin else dist
    d = dmax if d > dmax else d
    a = (l1 * l1 - l2 * l2 + d * d) / (2 * d)
    hh = l1 * l1 - a * a
    h = math.sqrt(hh if hh > 0.0 else 0.0)
    s = 0.0 + q0 * u0 + q1 * u1 + q2 * u2
    p0, p1, p2 = q0 - s * u0, q1 - s * u1, q2 - s * u2
    pn = math.sqrt(0.0 + p0 * p0 + p1 * p1 + p2 * p2)
    if pn > 1e-9:
        p0, p1, p2 = p0 / pn, p1 / pn, p2 / pn
    else:                              # np.cross(u, (0, 1, 0)), normalized
        c0, c1, c2 = u1 * 0.0 - u2 * 1.0, u2 * 0.0 - u0 * 0.0, u0 * 1.0 - u1 * 0.0
        cn = math.sqrt(0.0 + c0 * c0 + c1 * c1 + c2 * c2)
        cn = cn if cn > 1e-12 else 1e-12
        p0, p1, p2 = c0 / cn, c1 / cn, c2 / cn
    return (b0 + u0 * a + p0 * h, b1 + u1 * a + p1 * h, b2 + u2 * a + p2 * h,
            b0 + u0 * d, b1 + u1 * d, b2 + u2 * d)


@_jit
def two_bone(base, target, pole, l1, l2, dmin, dmax, middle, end) -> None:
    """``two_bone_ik`` of chains base[n], target[n], pole[n] (N, 3), finite: middle[n]
    and end[n] (N, 3); ``dmin``, ``dmax``: the clip of the base-target distance."""
    for n in range(base.shape[0]):
        middle[n, 0], middle[n, 1], middle[n, 2], end[n, 0], end[n, 1], end[n, 2] = chain(
            base[n, 0], base[n, 1], base[n, 2], target[n, 0], target[n, 1], target[n, 2],
            pole[n, 0], pole[n, 1], pole[n, 2], l1, l2, dmin, dmax)
