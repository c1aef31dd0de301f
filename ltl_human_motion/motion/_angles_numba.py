"""Compiled loop of :func:`ltl_human_motion.motion.biomechanics.joint_angles` (imported on
first use): the arguments of its inverse trigonometric functions, operation for operation
as the numpy path computes them (the same numbers; a test holds them together), without
the overhead of some hundred numpy calls on the one or few poses of an IK step. The
functions themselves (``arctan2``, ``arcsin``, ``arccos``, ``degrees``) stay numpy's:
numpy's vectorized ones round differently from the C library's in the last bit."""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def _unit(v0, v1, v2):
    """``v / np.maximum(norm3(v), 1e-12)`` (NaN stays NaN)."""
    n = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    if n < 1e-12:
        n = 1e-12
    return v0 / n, v1 / n, v2 / n


@_jit
def _dot(a0, a1, a2, b0, b1, b2):
    """``kernel.vectors.dot3``: numpy's sum from +0.0, left to right."""
    return 0.0 + a0 * b0 + a1 * b1 + a2 * b2


@_jit
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@_jit
def _clip(x):
    """``np.clip(x, -1, 1)`` (NaN stays NaN)."""
    if x < -1.0:
        return -1.0
    if x > 1.0:
        return 1.0
    return x


@_jit
def _diff(x, j, i):
    return x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2]


@_jit
def _frame(x, lat_a, lat_b, up_a, up_b):
    """``biomechanics._frame`` of lateral x[lat_a] - x[lat_b] and up x[up_a] - x[up_b]:
    forward, left and up axes, 9 floats."""
    l0, l1, l2 = _unit(*_diff(x, lat_a, lat_b))
    w0, w1, w2 = _diff(x, up_a, up_b)
    d = _dot(w0, w1, w2, l0, l1, l2)
    u0, u1, u2 = _unit(w0 - d * l0, w1 - d * l1, w2 - d * l2)
    f0, f1, f2 = _cross(l0, l1, l2, u0, u1, u2)
    return f0, f1, f2, l0, l1, l2, u0, u1, u2


@_jit
def _side(x, leg, arm, side, fr, ch, t, y, z, s, c, k):
    """Knee, hip and arm arguments of one side (``leg``: hip, knee, ankle, toe; ``arm``:
    shoulder, elbow, wrist joints) into rows 2k, 2k + 1 of y, z (arctan2), s (arcsin) and
    row k of c (arccos); ``fr``, ``ch``: the pelvis and chest frames."""
    th = _diff(x, leg[1], leg[0])
    sh = _diff(x, leg[2], leg[1])
    ft = _diff(x, leg[3], leg[2])
    a0, a1, a2 = _cross(sh[0], sh[1], sh[2], ft[0], ft[1], ft[2])
    ax = _unit(-a0, -a1, -a2)
    cr = _cross(th[0], th[1], th[2], sh[0], sh[1], sh[2])
    y[2 * k, t] = _dot(cr[0], cr[1], cr[2], ax[0], ax[1], ax[2])
    z[2 * k, t] = _dot(th[0], th[1], th[2], sh[0], sh[1], sh[2])
    u = _unit(th[0], th[1], th[2])
    y[2 * k + 1, t] = _dot(u[0], u[1], u[2], fr[0], fr[1], fr[2])
    z[2 * k + 1, t] = -_dot(u[0], u[1], u[2], fr[6], fr[7], fr[8])
    s[2 * k, t] = _clip(side * _dot(u[0], u[1], u[2], fr[3], fr[4], fr[5]))
    ua = _unit(*_diff(x, arm[1], arm[0]))
    fa = _unit(*_diff(x, arm[2], arm[1]))
    c[k, t] = _clip(_dot(ua[0], ua[1], ua[2], fa[0], fa[1], fa[2]))
    s[2 * k + 1, t] = _clip(-_dot(ua[0], ua[1], ua[2], ch[0], ch[1], ch[2]))


@_jit
def angle_arguments(p, joints, y, z, s, c) -> None:
    """For poses p (T, J, 3) and the joint indices ``joints`` (21,): pelvis, spine, chest,
    neck, head, l/r shoulder, l/r hip, then per side (l, r) hip, knee, ankle, toe, elbow,
    wrist. Fills y, z (7, T): the arctan2(y, z) arguments of l knee
    flexion, l hip flexion, r knee, r hip, trunk flexion, trunk rotation, neck flexion;
    s (6, T): the clipped arcsin arguments of l hip abduction, l shoulder extension,
    r ..., trunk lateral, neck lateral; c (2, T): the clipped arccos arguments of the l,
    r elbow flexion."""
    pel, spi, che, nec, hea = joints[0], joints[1], joints[2], joints[3], joints[4]
    for t in range(p.shape[0]):
        x = p[t]
        fr = _frame(x, joints[7], joints[8], spi, pel)
        ch = _frame(x, joints[5], joints[6], nec, che)
        for k in range(2):
            b = 9 + 6 * k
            leg = (joints[b], joints[b + 1], joints[b + 2], joints[b + 3])
            arm = (joints[5 + k], joints[b + 4], joints[b + 5])
            _side(x, leg, arm, 1.0 - 2.0 * k, fr, ch, t, y, z, s, c, k)
        y[4, t] = _dot(ch[6], ch[7], ch[8], fr[0], fr[1], fr[2])
        z[4, t] = _dot(ch[6], ch[7], ch[8], fr[6], fr[7], fr[8])
        s[4, t] = _clip(_dot(ch[6], ch[7], ch[8], fr[3], fr[4], fr[5]))
        y[5, t] = _dot(ch[3], ch[4], ch[5], -fr[0], -fr[1], -fr[2])
        z[5, t] = _dot(ch[3], ch[4], ch[5], fr[3], fr[4], fr[5])
        h = _unit(*_diff(x, hea, nec))
        y[6, t] = _dot(h[0], h[1], h[2], ch[0], ch[1], ch[2])
        z[6, t] = _dot(h[0], h[1], h[2], ch[6], ch[7], ch[8])
        s[5, t] = _clip(_dot(h[0], h[1], h[2], ch[3], ch[4], ch[5]))
