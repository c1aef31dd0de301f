"""Compiled loop of :mod:`ltl_human_motion.motion.biomechanics` (imported on first use):
the per-frame support polygon, operation for operation as the numpy path computes it (the
same numbers; a test holds them together)."""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def hull_distance(points: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Signed distance (T,) of ``q`` (T, 2) to the convex hull of ``points`` (T, V, 2):
    the largest signed distance to the lines of the hull's edges (negative inside)."""
    T, V = points.shape[0], points.shape[1]
    out = np.empty(T)
    for f in range(T):
        extent = 0.0
        for k in range(V):
            extent = max(extent, abs(points[f, k, 0]), abs(points[f, k, 1]))
        tol = 1e-12 * extent
        best = -np.inf
        for i in range(V):
            xi, yi = points[f, i, 0], points[f, i, 1]
            for j in range(V):
                if i == j:
                    continue
                ex = points[f, j, 0] - xi
                ey = points[f, j, 1] - yi
                length = math.hypot(ex, ey)
                if not length > tol:
                    continue
                edge = True
                for k in range(V):
                    beyond = ey * (points[f, k, 0] - xi) - ex * (points[f, k, 1] - yi)
                    if not beyond <= length * tol:
                        edge = False
                        break
                if not edge:
                    continue
                d = (ey * (q[f, 0] - xi) - ex * (q[f, 1] - yi)) / max(length, 1e-300)
                best = max(best, d)
        out[f] = best
    return out
