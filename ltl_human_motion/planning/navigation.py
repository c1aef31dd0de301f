"""A navigation function on a floor grid: the A* heuristic that knows about obstacles.

The straight-line heuristic of the paper traps a greedy search in front of a wall. We
compute, once per walk, the shortest 8-connected path length from every free floor cell
to the goal cells (Dijkstra, :func:`scipy.sparse.csgraph.dijkstra`), and the direction
of steepest descent. The heuristic then measures the way around obstacles, and an
unreachable goal is known before any primitive is expanded.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

_NEIGHBOURS = ((1, 0), (0, 1), (1, 1), (1, -1))


class NavigationField:
    """Geodesic distance to a goal set over the free floor.

    Parameters
    ----------
    lo, hi : array-like, shape (2,)
        Floor area covered, metres.
    free : callable
        ``free(xy (N, 2)) -> bool (N,)``: where the walking root may be.
    goal : callable
        ``goal(xy (N, 2)) -> bool (N,)``: goal cells.
    resolution : float
        Cell size in metres.
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray,
                 free: Callable[[np.ndarray], np.ndarray],
                 goal: Callable[[np.ndarray], np.ndarray], resolution: float = 0.1) -> None:
        lo = np.asarray(lo, dtype=np.float64)
        hi = np.asarray(hi, dtype=np.float64)
        if lo.shape != (2,) or hi.shape != (2,) or np.any(hi <= lo):
            raise ValueError(f"need lo < hi of shape (2,), got {lo} and {hi}")
        self.lo, self.res = lo, float(resolution)
        self.shape = tuple(np.maximum(np.ceil((hi - lo) / resolution).astype(int) + 1, 2))
        nx, ny = self.shape
        gx, gy = np.meshgrid(lo[0] + np.arange(nx) * self.res, lo[1] + np.arange(ny) * self.res,
                             indexing="ij")
        centres = np.stack([gx.ravel(), gy.ravel()], axis=-1)
        self.free = np.asarray(free(centres), dtype=bool).reshape(self.shape)
        goal_cells = np.asarray(goal(centres), dtype=bool).reshape(self.shape) & self.free
        self.has_goal = bool(goal_cells.any())
        ids = np.arange(nx * ny).reshape(self.shape)
        rows, cols, weights = [], [], []
        for dx, dy in _NEIGHBOURS:
            a = ids[0:nx - dx, max(0, -dy):ny - max(0, dy)]
            b = ids[dx:nx, max(0, dy):ny - max(0, -dy)]
            ok = self.free.ravel()[a.ravel()] & self.free.ravel()[b.ravel()]
            rows.append(a.ravel()[ok])
            cols.append(b.ravel()[ok])
            weights.append(np.full(int(ok.sum()), self.res * np.hypot(dx, dy)))
        r, c, w = np.concatenate(rows), np.concatenate(cols), np.concatenate(weights)
        graph = coo_matrix((w, (r, c)), shape=(nx * ny, nx * ny)).tocsr()
        if self.has_goal:
            dist = dijkstra(graph, directed=False, indices=np.flatnonzero(goal_cells),
                            min_only=True)
        else:
            dist = np.full(nx * ny, np.inf)
        self.dist = dist.reshape(self.shape)
        finite = np.where(np.isfinite(self.dist), self.dist, np.nan)
        big = np.nanmax(finite) + 1.0 if np.isfinite(self.dist).any() else 1.0
        filled = np.where(np.isfinite(self.dist), self.dist, big)
        gxd, gyd = np.gradient(filled, self.res)
        self.descent = np.arctan2(-gyd, -gxd)

    def _cells(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        i = np.clip(np.rint((np.asarray(x) - self.lo[0]) / self.res).astype(int), 0,
                    self.shape[0] - 1)
        j = np.clip(np.rint((np.asarray(y) - self.lo[1]) / self.res).astype(int), 0,
                    self.shape[1] - 1)
        return i, j

    def distance(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Path length to the goal from floor points, shape like ``x`` (inf: no way)."""
        i, j = self._cells(x, y)
        return self.dist[i, j]

    def heading(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Direction of the shortest way to the goal, radians, shape like ``x``."""
        i, j = self._cells(x, y)
        return self.descent[i, j]

    def reachable_from(self, x: float, y: float) -> bool:
        """Whether a way to the goal starts at (x, y)."""
        return bool(np.isfinite(self.distance(np.array([x]), np.array([y]))[0]))


class ClearanceMap:
    """Floor clearance from obstacle footprints, sampled once on a grid.

    ``Cell.floor_clearance`` is exact but slow for the thousands of queries of a search;
    this map interpolates it bilinearly (error below the grid step). Points outside the
    workspace get -1 (not walkable).

    Parameters
    ----------
    cell : Cell
    resolution : float
        Grid step in metres.
    """

    def __init__(self, cell, resolution: float = 0.04) -> None:  # noqa: ANN001
        from scipy.interpolate import RegularGridInterpolator
        lo = np.asarray(cell.workspace_lo[:2], dtype=np.float64)
        hi = np.asarray(cell.workspace_hi[:2], dtype=np.float64)
        xs = np.arange(lo[0], hi[0] + resolution, resolution)
        ys = np.arange(lo[1], hi[1] + resolution, resolution)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        pts = np.stack([gx.ravel(), gy.ravel()], axis=-1)
        values = np.minimum(cell.floor_clearance(pts), 1e3).reshape(gx.shape)
        self.lo, self.hi = lo, hi
        self._interp = RegularGridInterpolator((xs, ys), values, bounds_error=False,
                                               fill_value=-1.0)

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Clearance of floor points, shape (N,) for ``xy`` of shape (N, 2)."""
        xy = np.asarray(xy, dtype=np.float64)
        inside = np.all((xy >= self.lo) & (xy <= self.hi), axis=-1)
        return np.where(inside, self._interp(xy), -1.0)
