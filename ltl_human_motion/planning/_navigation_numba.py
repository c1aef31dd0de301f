"""Compiled loops of :mod:`ltl_human_motion.planning.navigation` (imported on first use):
the bilinear floor clearance of :class:`~ltl_human_motion.planning.navigation.ClearanceMap`
and the trilinear obstacle distance of its ``_trilinear``, operation for operation as the
numpy paths compute them (the same numbers; tests hold them together), without the numpy
calls' overhead on the few dozen points of a search step."""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def _cell(grid, v):
    """``searchsorted(grid, v, side="right") - 1`` clamped to ``[0, len(grid) - 2]``."""
    lo, hi = 0, grid.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if grid[mid] <= v:
            lo = mid + 1
        else:
            hi = mid
    return min(max(lo - 1, 0), grid.shape[0] - 2)


@_jit
def bilinear(xs, ys, values, in_lo, in_hi, xy, out) -> None:
    """out[n] = clearance at xy[n] (N, 2) on the grid values (nx, ny) at xs (nx,), ys
    (ny,); -1 outside the box in_lo, in_hi (2,)."""
    for n in range(xy.shape[0]):
        x, y = xy[n, 0], xy[n, 1]
        if not (x >= in_lo[0] and x <= in_hi[0] and y >= in_lo[1] and y <= in_hi[1]):
            out[n] = -1.0
            continue
        i, j = _cell(xs, x), _cell(ys, y)
        x0, y0 = xs[i], ys[j]
        tx = (x - x0) / (xs[i + 1] - x0)
        ty = (y - y0) / (ys[j + 1] - y0)
        sx, sy = 1 - tx, 1 - ty
        v = 0.0 + values[i, j] * sx * sy
        v = v + values[i, j + 1] * sx * ty
        v = v + values[i + 1, j] * tx * sy
        v = v + values[i + 1, j + 1] * tx * ty
        out[n] = v


@_jit
def trilinear(grid, u, out) -> None:
    """out[n] = trilinear interpolation of grid (nx, ny, nz) at index coordinates u[n]
    (N, 3), finite: corners clamped to the grid, weights ``1 - f`` and ``1 - (1 - f)``,
    the eight corners summed in C order."""
    nx, ny, nz = grid.shape
    lo = np.empty(3, dtype=np.intp)
    hi = np.empty(3, dtype=np.intp)
    w = np.empty((3, 2))
    for n in range(u.shape[0]):
        for d in range(3):
            top = (nx, ny, nz)[d] - 1
            base = math.floor(u[n, d])
            w0 = 1.0 - (u[n, d] - base)
            w[d, 0], w[d, 1] = w0, 1.0 - w0
            lo[d] = int(min(max(base, 0.0), top))
            hi[d] = int(min(max(base + 1, 0.0), top))
        v = 0.0
        for f0 in range(2):
            i = lo[0] if f0 == 0 else hi[0]
            for f1 in range(2):
                j = lo[1] if f1 == 0 else hi[1]
                for f2 in range(2):
                    k = lo[2] if f2 == 0 else hi[2]
                    v = v + grid[i, j, k] * w[0, f0] * w[1, f1] * w[2, f2]
        out[n] = v
