"""Compiled loop of :class:`~ltl_human_motion.planning.navigation.ClearanceMap` (imported
on first use): the bilinear clearance of floor points, operation for operation as the
numpy path computes it (the same numbers; tests hold them together), without the numpy
calls' overhead on the few dozen points of a search step."""

from __future__ import annotations

import numba

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
