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
