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

    Tall obstacle parts (whose top is above ``tall_height``: walls, machine columns) count
    ``tall_extra`` closer, because the swinging arms pass them at shoulder width; low
    parts (bench and table tops at hip height) do not, so a worker can step up to a
    bench. Points outside the workspace get -1 (not walkable). Values are interpolated
    bilinearly (error below the grid step).

    Parameters
    ----------
    cell : Cell
    resolution : float
        Grid step in metres.
    tall_extra, tall_height : float
        Metres.
    """

    def __init__(self, cell, resolution: float = 0.04, tall_extra: float = 0.25,
                 tall_height: float = 1.2) -> None:
        from scipy.interpolate import RegularGridInterpolator
        lo = np.asarray(cell.workspace_lo[:2], dtype=np.float64)
        hi = np.asarray(cell.workspace_hi[:2], dtype=np.float64)
        xs = np.arange(lo[0], hi[0] + resolution, resolution)
        ys = np.arange(lo[1], hi[1] + resolution, resolution)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        pts = np.stack([gx.ravel(), gy.ravel()], axis=-1)
        values = np.full(len(pts), 1e3)
        for ob in cell.obstacles:
            for part in ob.parts:
                extra = tall_extra if part.aabb()[1][2] > tall_height else 0.0
                values = np.minimum(values, part.footprint().signed_distance(pts) - extra)
        self.lo, self.hi = lo, hi
        self._interp = RegularGridInterpolator((xs, ys), values.reshape(gx.shape),
                                               bounds_error=False, fill_value=-1.0)

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Clearance of floor points, shape (N,) for ``xy`` of shape (N, 2)."""
        xy = np.asarray(xy, dtype=np.float64)
        inside = np.all((xy >= self.lo) & (xy <= self.hi), axis=-1)
        return np.where(inside, self._interp(xy), -1.0)


class ObstacleField:
    """Distance to the cell's obstacles sampled on a 3D grid, for fast whole-body checks.

    The search checks thousands of body poses; the exact capsule distances of
    :mod:`ltl_human_motion.scene.predicates` stay for the final verification. The
    distance is 1-Lipschitz, so trilinear interpolation errs by at most
    ``resolution * sqrt(3) / 2`` (much less away from edges); :meth:`clear` keeps
    ``0.4 * resolution`` extra margin, and the exact verification catches the rest.

    Parameters
    ----------
    cell : Cell
    resolution : float
        Grid step, metres.
    pad : float
        The grid covers the obstacles' bounding box grown by this much; further away
        nothing can touch them.
    """

    def __init__(self, cell, resolution: float = 0.05, pad: float = 0.5) -> None:
        self.res = float(resolution)
        self.empty = not cell.obstacles
        if self.empty:
            return
        boxes = [ob.aabb() for ob in cell.obstacles]
        lo = np.min([b[0] for b in boxes], axis=0) - pad
        hi = np.max([b[1] for b in boxes], axis=0) + pad
        axes = [np.arange(lo[i], hi[i] + self.res, self.res) for i in range(3)]
        gx, gy, gz = np.meshgrid(*axes, indexing="ij")
        pts = np.stack([gx, gy, gz], axis=-1).reshape(-1, 3)
        dist = np.min(np.stack([ob.distance(pts) for ob in cell.obstacles]), axis=0)
        self.lo = lo
        self.shape = np.array(gx.shape)
        self.dist = dist.reshape(gx.shape)
        self.far = pad

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Interpolated obstacle distance of points (..., 3), shape (...)."""
        pts = np.asarray(points, dtype=np.float64)
        if self.empty:
            return np.full(pts.shape[:-1], np.inf)
        from scipy.ndimage import map_coordinates
        u = (pts.reshape(-1, 3) - self.lo) / self.res
        outside = np.any((u < 0) | (u > self.shape - 1), axis=-1)
        out = map_coordinates(self.dist, u.T, order=1, mode="nearest")
        out = np.where(outside, np.maximum(out, self.far), out)
        return out.reshape(pts.shape[:-1])

    def clear(self, poses: np.ndarray, stature: float, margin: float = 0.01,
              relative: bool = False) -> np.ndarray:
        """Whether body poses keep ``margin`` from every obstacle, or, for body parts
        already closer at the first sample, get no closer.

        Parameters
        ----------
        poses : ndarray, shape (M, S, J, 3)
            S sampled poses of each of M candidates.
        stature : float
        margin : float
        relative : bool
            For standing primitives that start where the last motion ended.

        Returns
        -------
        ok : ndarray of bool, shape (M,)
        """
        from ltl_human_motion.scene.occupancy import capsules_from_positions
        if self.empty:
            return np.ones(poses.shape[0], dtype=bool)
        seg, rad = capsules_from_positions(poses, stature)              # (M, S, K, 2, 3)
        pts = np.concatenate([seg, seg.mean(axis=-2, keepdims=True)], axis=-2)
        gap = self.distance(pts) - (rad[:, None] + margin + self.res * 0.4)   # (M, S, K, 3)
        gap = gap.min(axis=-1)                                              # (M, S, K)
        # With ``relative``, a body part that starts closer than the margin (a worker
        # standing at a bench) may stay there; it must not get closer.
        allowed = np.minimum(gap[:, :1], 0.0) - 0.005 if relative else 0.0
        return np.all(gap >= allowed, axis=(1, 2))


_CLEARANCE_CACHE: dict[str, tuple[ClearanceMap, ObstacleField]] = {}
_FIELDS_FORMAT = 1


def clearance_maps(cell) -> tuple[ClearanceMap, ObstacleField]:
    """The floor clearance map and 3D obstacle field of ``cell``, once per obstacle layout.

    Cached in memory and on disk (next to the motion library cache), keyed by a hash of
    the workspace and the obstacles; an unreadable cache file is rebuilt.
    """
    import hashlib
    import pickle
    import zipfile

    from ltl_human_motion.atomic import atomic_write_with
    from ltl_human_motion.motion.library import cache_dir
    key = hashlib.sha1(pickle.dumps((_FIELDS_FORMAT, np.asarray(cell.workspace_lo),
                                     np.asarray(cell.workspace_hi), cell.obstacles))).hexdigest()
    maps = _CLEARANCE_CACHE.get(key)
    if maps is not None:
        return maps
    path = cache_dir() / f"fields-{key[:24]}.pkl"
    try:
        with open(path, "rb") as fh:
            maps = pickle.load(fh)
        if not (isinstance(maps, tuple) and isinstance(maps[0], ClearanceMap)):
            maps = None
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ValueError,
            zipfile.BadZipFile):
        maps = None
    if maps is None:
        maps = (ClearanceMap(cell), ObstacleField(cell))
        try:
            atomic_write_with(path, lambda fh: pickle.dump(maps, fh, protocol=5))
        except OSError:
            pass            # a read-only cache folder must not stop synthesis
    if len(_CLEARANCE_CACHE) > 64:
        _CLEARANCE_CACHE.clear()
    _CLEARANCE_CACHE[key] = maps
    return maps
