"""Compiled loops of :mod:`ltl_human_motion.planning.footlock` (imported on first use):
the sequential passes over a motion's frames, operation for operation as the Python/numpy
paths compute them (the same numbers; tests hold them together)."""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def decay_envelope(w: np.ndarray, step: float) -> np.ndarray:
    """``w`` (T,) raised so that no value falls by more than ``step`` per frame towards
    either end (a backward pass, then a forward pass)."""
    out = w.copy()
    T = out.shape[0]
    for t in range(T - 2, -1, -1):
        out[t] = max(out[t], out[t + 1] - step)
    for t in range(1, T):
        out[t] = max(out[t], out[t - 1] - step)
    return out


@_jit
def rate_limited(x: np.ndarray, step: float) -> np.ndarray:
    """``x`` (T, 3) with every frame-to-frame change at most ``step`` (a forward, then a
    backward pass)."""
    rows = x.copy()
    T = rows.shape[0]
    for t in range(1, T):
        _limit(rows, t, t - 1, step)
    for t in range(T - 2, -1, -1):
        _limit(rows, t, t + 1, step)
    return rows


@_jit
def _limit(rows, t, prev, step):
    px, py, pz = rows[prev, 0], rows[prev, 1], rows[prev, 2]
    dx, dy, dz = rows[t, 0] - px, rows[t, 1] - py, rows[t, 2] - pz
    n = math.sqrt(dx * dx + dy * dy + dz * dz)
    if n > step:
        k = step / n
        rows[t, 0] = px + dx * k
        rows[t, 1] = py + dy * k
        rows[t, 2] = pz + dz * k


@_jit
def _clip01(x: float) -> float:
    """``np.clip(x, 0, 1)``, signed zero and NaN included."""
    if x < 0.0:
        return 0.0
    if x > 1.0:
        return 1.0
    return x


@_jit
def _floor(x: float, least: float) -> float:
    """``np.maximum(x, least)`` of a finite ``x``."""
    return x if x > least else least


@_jit
def segment_gaps(p0, p1, q0, q1, gap, dist) -> None:
    """``footlock._segment_gaps`` frame by frame: gap[t] (3,) from the closest point of
    segment [q0[t], q1[t]] to that of [p0[t], p1[t]] and dist[t] its length (all (T, 3),
    finite), each sum over x, y, z in numpy's order."""
    for t in range(p0.shape[0]):
        u0, u1, u2 = p1[t, 0] - p0[t, 0], p1[t, 1] - p0[t, 1], p1[t, 2] - p0[t, 2]
        v0, v1, v2 = q1[t, 0] - q0[t, 0], q1[t, 1] - q0[t, 1], q1[t, 2] - q0[t, 2]
        w0, w1, w2 = p0[t, 0] - q0[t, 0], p0[t, 1] - q0[t, 1], p0[t, 2] - q0[t, 2]
        a = u0 * u0 + u1 * u1 + u2 * u2
        b = 0.0 + u0 * v0 + u1 * v1 + u2 * v2      # (numpy's sums start from +0.0)
        c = v0 * v0 + v1 * v1 + v2 * v2
        d = 0.0 + u0 * w0 + u1 * w1 + u2 * w2
        e = 0.0 + v0 * w0 + v1 * w1 + v2 * w2
        den = a * c - b * b
        sp = _clip01((b * e - c * d) / _floor(den, 1e-12)) if den > 1e-12 else 0.0
        s = (b * sp + e) / _floor(c, 1e-12)
        if s < 0:
            sp = _clip01(-d / _floor(a, 1e-12))
        elif s > 1:
            sp = _clip01((b - d) / _floor(a, 1e-12))
        s = _clip01(s)
        g0 = (p0[t, 0] + sp * u0) - (q0[t, 0] + s * v0)
        g1 = (p0[t, 1] + sp * u1) - (q0[t, 1] + s * v1)
        g2 = (p0[t, 2] + sp * u2) - (q0[t, 2] + s * v2)
        gap[t, 0], gap[t, 1], gap[t, 2] = g0, g1, g2
        dist[t] = math.sqrt(g0 * g0 + g1 * g1 + g2 * g2)


@_jit
def slower_foot_speed(ank, toe, fps, out) -> None:
    """out[t] for t >= 1: the slower horizontal speed of ``ank`` and ``toe`` (T, 3) from
    frame t - 1 to t (``np.linalg.norm`` of the steps, then their minimum, times fps)."""
    for t in range(1, ank.shape[0]):
        ax, ay = ank[t, 0] - ank[t - 1, 0], ank[t, 1] - ank[t - 1, 1]
        tx, ty = toe[t, 0] - toe[t - 1, 0], toe[t, 1] - toe[t - 1, 1]
        sa = math.sqrt(ax * ax + ay * ay)
        st = math.sqrt(tx * tx + ty * ty)
        out[t] = (sa if sa <= st else st) * fps
