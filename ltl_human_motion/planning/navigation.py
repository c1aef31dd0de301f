"""A navigation function on a floor grid: the A* heuristic that knows about obstacles.

The straight-line heuristic of the paper traps a greedy search in front of a wall. We
compute, once per walk, the shortest 8-connected path length from every free floor cell
to the goal cells (Dijkstra, :func:`scipy.sparse.csgraph.dijkstra`), and the direction
of steepest descent. The heuristic then measures the way around obstacles, and an
unreachable goal is known before any primitive is expanded.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from types import ModuleType

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from ltl_human_motion.kernel.cache import BoundedCache

_NEIGHBOURS = ((1, 0), (0, 1), (1, 1), (1, -1))


class FloorGrid:
    """A floor grid: cell centres, the free cells and the graph joining free neighbours.

    The part of a :class:`NavigationField` that does not depend on the goal; fields for
    different goals on the same floor share one grid (:func:`floor_grid`).

    Parameters
    ----------
    lo, hi : array-like, shape (2,)
        Floor area covered, metres.
    free : callable
        ``free(xy (N, 2)) -> bool (N,)``: where the walking root may be.
    resolution : float
        Cell size in metres.
    cell_cost : callable, optional
        ``cell_cost(xy (N, 2)) -> (N,)``, at least 1: how much a metre through each cell
        counts (an edge counts the mean of its two cells); default 1 everywhere.

    Attributes
    ----------
    lo : ndarray, shape (2,)
    res : float
    shape : (int, int)
    centres : ndarray, shape (nx * ny, 2)
    free : ndarray of bool, shape (nx, ny)
    graph : scipy.sparse.csr_matrix, shape (nx * ny, nx * ny)
        8-connected free neighbours, both directions, weighted by the step length.
    clearance : callable or None
        The floor clearance map the free cells come from (set by :func:`floor_grid`):
        a walk led by a field on this grid keeps its clearance on that map.
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray,
                 free: Callable[[np.ndarray], np.ndarray], resolution: float = 0.1,
                 cell_cost: Callable[[np.ndarray], np.ndarray] | None = None) -> None:
        lo = np.asarray(lo, dtype=np.float64)
        hi = np.asarray(hi, dtype=np.float64)
        if lo.shape != (2,) or hi.shape != (2,) or np.any(hi <= lo):
            raise ValueError(f"need lo < hi of shape (2,), got {lo} and {hi}")
        self.lo, self.res = lo, float(resolution)
        self.clearance: Callable[[np.ndarray], np.ndarray] | None = None
        self.shape = tuple(np.maximum(np.ceil((hi - lo) / resolution).astype(int) + 1, 2))
        nx, ny = self.shape
        gx, gy = np.meshgrid(lo[0] + np.arange(nx) * self.res, lo[1] + np.arange(ny) * self.res,
                             indexing="ij")
        self.centres = np.stack([gx.ravel(), gy.ravel()], axis=-1)
        self.cost = (np.ones(nx * ny) if cell_cost is None
                     else np.asarray(cell_cost(self.centres), dtype=np.float64))
        self._connect(np.asarray(free(self.centres), dtype=bool).reshape(self.shape))

    def _connect(self, free: np.ndarray) -> None:
        """Set the free cells (nx, ny) and the graph joining free neighbours."""
        nx, ny = self.shape
        self.free = free
        self.free.flags.writeable = False              # grids are shared (floor_grid)
        ids = np.arange(nx * ny).reshape(self.shape)
        cost = self.cost
        rows, cols, weights = [], [], []
        for dx, dy in _NEIGHBOURS:
            a = ids[0:nx - dx, max(0, -dy):ny - max(0, dy)]
            b = ids[dx:nx, max(0, dy):ny - max(0, -dy)]
            ok = self.free.ravel()[a.ravel()] & self.free.ravel()[b.ravel()]
            rows.append(a.ravel()[ok])
            cols.append(b.ravel()[ok])
            weights.append(self.res * np.hypot(dx, dy)
                           * 0.5 * (cost[a.ravel()[ok]] + cost[b.ravel()[ok]]))
        r, c, w = np.concatenate(rows), np.concatenate(cols), np.concatenate(weights)
        # Both directions stored, so the search needs no symmetrized copy per goal.
        self.graph = coo_matrix((np.concatenate([w, w]), (np.concatenate([r, c]),
                                                          np.concatenate([c, r]))),
                                shape=(nx * ny, nx * ny)).tocsr()

    def blocked(self, centre: tuple[float, float], radius: float) -> FloorGrid:
        """A copy of this grid whose cells within ``radius`` of ``centre`` (x, y) are not
        free (same cell costs and clearance map)."""
        grid = FloorGrid.__new__(FloorGrid)
        grid.lo, grid.res, grid.shape, grid.centres = self.lo, self.res, self.shape, self.centres
        grid.clearance, grid.cost = self.clearance, self.cost
        near = np.hypot(self.centres[:, 0] - centre[0], self.centres[:, 1] - centre[1]) <= radius
        grid._connect(self.free & ~near.reshape(self.shape))
        return grid


class NavigationField:
    """Geodesic distance to a goal set over the free floor.

    Parameters
    ----------
    lo, hi, free, resolution
        The floor grid, as for :class:`FloorGrid` (``free(xy (N, 2)) -> bool (N,)``).
    goal : callable
        ``goal(xy (N, 2)) -> bool (N,)``: goal cells.
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray,
                 free: Callable[[np.ndarray], np.ndarray],
                 goal: Callable[[np.ndarray], np.ndarray], resolution: float = 0.1) -> None:
        self._solve(FloorGrid(lo, hi, free, resolution), goal)

    @classmethod
    def on_grid(cls, grid: FloorGrid, goal: Callable[[np.ndarray], np.ndarray]
                ) -> NavigationField:
        """The field of ``goal`` on a grid already made (see :func:`floor_grid`)."""
        field = cls.__new__(cls)
        field._solve(grid, goal)
        return field

    def _solve(self, grid: FloorGrid, goal: Callable[[np.ndarray], np.ndarray]) -> None:
        self.grid = grid
        self.lo, self.res, self.shape, self.free = grid.lo, grid.res, grid.shape, grid.free
        nx, ny = self.shape
        goal_cells = np.asarray(goal(grid.centres), dtype=bool).reshape(self.shape) & self.free
        self.goal_cells = goal_cells
        self.has_goal = bool(goal_cells.any())
        if self.has_goal:
            dist = dijkstra(grid.graph, directed=True, indices=np.flatnonzero(goal_cells),
                            min_only=True)
        else:
            dist = np.full(nx * ny, np.inf)
        self.dist = dist.reshape(self.shape)
        finite = np.where(np.isfinite(self.dist), self.dist, np.nan)
        big = np.nanmax(finite) + 1.0 if np.isfinite(self.dist).any() else 1.0
        filled = np.where(np.isfinite(self.dist), self.dist, big)
        gxd, gyd = np.gradient(filled, self.res)
        self.descent = np.arctan2(-gyd, -gxd)
        for arr in (self.dist, self.descent, self.goal_cells):
            arr.flags.writeable = False                # fields may be shared (cached)

    def without(self, centre: tuple[float, float], radius: float) -> NavigationField:
        """The field of the same goal cells with the floor within ``radius`` of
        ``centre`` (x, y) blocked: the way around a spot the walk cannot pass."""
        cells = self.goal_cells.ravel()
        return NavigationField.on_grid(self.grid.blocked(centre, radius), lambda xy: cells)

    def _cells(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # (clamped by the ufuncs: np.clip's dispatch cost more than the search's heuristic)
        i = np.rint((np.asarray(x) - self.lo[0]) / self.res).astype(int)
        j = np.rint((np.asarray(y) - self.lo[1]) / self.res).astype(int)
        return (np.minimum(np.maximum(i, 0), self.shape[0] - 1),
                np.minimum(np.maximum(j, 0), self.shape[1] - 1))

    def _at(self, table: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``table`` (nx, ny) at the cells of floor points (x, y): by the compiled loop for
        float vectors (the search's successors; the same numbers), else :meth:`_cells`."""
        nb = _compiled_loops()
        if nb is not None and type(x) is np.ndarray and type(y) is np.ndarray \
                and x.ndim == 1 and x.shape == y.shape and x.dtype == np.float64 \
                and y.dtype == np.float64:
            out = np.empty(x.shape[0])
            nb.cell_values(table, float(self.lo[0]), float(self.lo[1]), self.res, x, y, out)
            return out
        i, j = self._cells(x, y)
        return table[i, j]

    def distance(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Path length to the goal from floor points, shape like ``x`` (inf: no way)."""
        return self._at(self.dist, x, y)

    def heading(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Direction of the shortest way to the goal, radians, shape like ``x``."""
        return self._at(self.descent, x, y)

    def reachable_from(self, x: float, y: float) -> bool:
        """Whether a way to the goal starts at (x, y)."""
        return bool(np.isfinite(self.distance(np.array([x]), np.array([y]))[0]))


_LOOPS: list[ModuleType | None] = []


def _compiled_loops() -> ModuleType | None:
    """The compiled loops (:mod:`._navigation_numba`), where the compiled kernel is in use
    (decided on the first call)."""
    if not _LOOPS:
        from ltl_human_motion.kernel.segments import compiled_module
        _LOOPS.append(compiled_module("ltl_human_motion.planning._navigation_numba"))
    return _LOOPS[0]


#: How much closer than its footprint a tall part counts for walking (the swinging arms
#: pass it at shoulder width), metres.
TALL_EXTRA = 0.25
#: Tall parts reach down below this height (about the shoulder of a 1.95 m worker), m.
TALL_TOP = 1.6


class ClearanceMap:
    """Floor clearance from obstacle footprints, sampled once on a grid.

    Tall obstacle parts (whose top is above ``tall_height``: walls, machine columns) count
    ``tall_extra`` closer, because the swinging arms pass them at shoulder width; low
    parts (bench and table tops at hip height) do not, so a worker can step up to a
    bench. Points outside the workspace get -1 (not walkable). Values are interpolated
    bilinearly (error below the grid step), with the arithmetic of SciPy's
    ``RegularGridInterpolator`` (same values, without importing ``scipy.interpolate``).

    Parameters
    ----------
    cell : Cell
    resolution : float
        Grid step in metres.
    tall_extra, tall_height : float
        Metres.
    tall_top : float
        Parts wholly above this height (an overhead board, a machine's roof) are no
        tall parts: the arms swing below it. Metres.
    """

    def __init__(self, cell, resolution: float = 0.04, tall_extra: float = TALL_EXTRA,
                 tall_height: float = 1.2, tall_top: float = TALL_TOP) -> None:
        lo = np.asarray(cell.workspace_lo[:2], dtype=np.float64)
        hi = np.asarray(cell.workspace_hi[:2], dtype=np.float64)
        xs = np.arange(lo[0], hi[0] + resolution, resolution)
        ys = np.arange(lo[1], hi[1] + resolution, resolution)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        pts = np.stack([gx.ravel(), gy.ravel()], axis=-1)
        values = np.full(len(pts), 1e3)
        for ob in cell.obstacles:
            for part in ob.parts:
                plo, phi = part.aabb()
                extra = tall_extra if phi[2] > tall_height and plo[2] < tall_top else 0.0
                values = np.minimum(values, part.footprint().signed_distance(pts) - extra)
        self.lo, self.hi = lo, hi
        self._xs, self._ys = xs, ys
        self._values = np.ascontiguousarray(values.reshape(gx.shape))
        # Interpolated inside both the workspace and the grid; -1 elsewhere.
        self._in_lo = np.maximum(lo, [xs[0], ys[0]])
        self._in_hi = np.minimum(hi, [xs[-1], ys[-1]])

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Clearance of floor points, shape (N,) for ``xy`` of shape (N, 2)."""
        xy = np.asarray(xy, dtype=np.float64)
        nb = _compiled_loops()
        if nb is not None:
            flat = np.ascontiguousarray(xy).reshape(-1, 2)
            out = np.empty(len(flat))
            nb.bilinear(self._xs, self._ys, self._values, self._in_lo, self._in_hi, flat, out)
            return out.reshape(xy.shape[:-1])
        x, y = xy[..., 0], xy[..., 1]
        xs, ys = self._xs, self._ys
        flat, ny = self._values.ravel(), self._values.shape[1]
        # The grid cell of each point (the last one for points on the far edge) and the
        # point's place in it, then the bilinear sum in SciPy's order.
        i = np.searchsorted(xs, x, side="right") - 1
        np.minimum(np.maximum(i, 0, out=i), len(xs) - 2, out=i)
        j = np.searchsorted(ys, y, side="right") - 1
        np.minimum(np.maximum(j, 0, out=j), len(ys) - 2, out=j)
        with np.errstate(invalid="ignore"):          # non-finite points end up at -1
            x0, y0 = xs[i], ys[j]
            tx = (x - x0) / (xs[i + 1] - x0)
            ty = (y - y0) / (ys[j + 1] - y0)
            sx, sy = 1 - tx, 1 - ty
            k = i * ny + j                           # flat index of corner (i, j)
            out = 0.0 + flat[k] * sx * sy
            out = out + flat[k + 1] * sx * ty
            k += ny
            out = out + flat[k] * tx * sy
            out = out + flat[k + 1] * tx * ty
        inside = ((x >= self._in_lo[0]) & (x <= self._in_hi[0])
                  & (y >= self._in_lo[1]) & (y <= self._in_hi[1]))
        return np.where(inside, out, -1.0)

    def placed_paths(self, disp: np.ndarray, path: np.ndarray, ids: np.ndarray,
                     pose: tuple[float, float, float]
                     ) -> tuple[np.ndarray, np.ndarray] | None:
        """Where gait primitives ``ids`` (M,) started at ``pose`` (x, y, yaw) end, (M, 3),
        and the least clearance along their root paths, (M,), in one compiled call
        (``disp`` (P, 3) and ``path`` (P, S, 2): every primitive's displacement and root
        path in its start frame); None where the compiled kernel is not in use."""
        nb = _compiled_loops()
        if nb is None:
            return None
        x, y, yaw = (float(v) for v in pose)
        ends = np.empty((len(ids), 3))
        gap = np.empty(len(ids))
        nb.placed_paths(disp, path, ids, x, y, yaw, float(np.cos(yaw)), float(np.sin(yaw)),
                        self._xs, self._ys, self._values, self._in_lo, self._in_hi, ends, gap)
        return ends, gap

    def placed_paths_from(self, disp: np.ndarray, path: np.ndarray, ids: np.ndarray,
                          starts: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """:meth:`placed_paths` with a start pose per primitive: ``ids`` (M,) started at
        ``starts`` (M, 3) (x, y, yaw), their end poses (M, 3) and least root-path
        clearances (M,); None where the compiled kernel is not in use."""
        nb = _compiled_loops()
        if nb is None:
            return None
        ends = np.empty((len(ids), 3))
        gap = np.empty(len(ids))
        nb.placed_paths_from(disp, path, ids, starts, np.cos(starts[:, 2]),
                             np.sin(starts[:, 2]), self._xs, self._ys, self._values,
                             self._in_lo, self._in_hi, ends, gap)
        return ends, gap


def _trilinear(grid: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Trilinear interpolation of ``grid`` (nx, ny, nz) at index coordinates ``u`` (N, 3).

    The arithmetic of ``scipy.ndimage.map_coordinates(grid, u.T, order=1,
    mode="nearest")``, value for value (per axis the weights ``1 - f`` and
    ``1 - (1 - f)`` of the fractional part ``f``, corners outside the grid clamped to
    its edge, the eight corners summed in C order), without importing ``scipy.ndimage``.

    Returns
    -------
    values : ndarray, shape (N,)
    """
    nb = _compiled_loops()
    if nb is not None and np.isfinite(u).all():
        out = np.empty(len(u))
        nb.trilinear(np.ascontiguousarray(grid, dtype=np.float64),
                     np.ascontiguousarray(u, dtype=np.float64), out)
        return out
    flat = np.ascontiguousarray(grid, dtype=np.float64).ravel()
    step = (grid.shape[1] * grid.shape[2], grid.shape[2], 1)       # elements per axis step
    offsets, weights = [], []
    for d in range(3):
        n = grid.shape[d]
        base = np.floor(u[:, d])
        w0 = 1.0 - (u[:, d] - base)
        weights.append((w0, 1.0 - w0))
        offsets.append((np.clip(base, 0, n - 1).astype(np.intp) * step[d],
                        np.clip(base + 1, 0, n - 1).astype(np.intp) * step[d]))
    out = np.zeros(len(u))
    for f0 in (0, 1):
        for f1 in (0, 1):
            at = offsets[0][f0] + offsets[1][f1]
            for f2 in (0, 1):
                out = out + flat[at + offsets[2][f2]] * weights[0][f0] * weights[1][f1] \
                    * weights[2][f2]
    return out


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
        # Each part's distance is computed only within ``pad`` of its bounding box; beyond,
        # the field holds ``pad`` (min(distance, pad) is 1-Lipschitz too, and every test
        # of :meth:`clear` passes well below ``pad``). A large cell's grid has millions of
        # points, most of them far from any one part.
        dist = np.full([len(a) for a in axes], float(pad))
        for ob in cell.obstacles:
            for part in ob.parts:
                plo, phi = part.aabb()
                sl = tuple(slice(int(np.searchsorted(a, plo[i] - pad, side="left")),
                                 int(np.searchsorted(a, phi[i] + pad, side="right")))
                           for i, a in enumerate(axes))
                sub = np.meshgrid(*(a[k] for a, k in zip(axes, sl)), indexing="ij")
                pts = np.stack(sub, axis=-1).reshape(-1, 3)
                if pts.size:
                    dist[sl] = np.minimum(dist[sl], part.distance(pts).reshape(sub[0].shape))
        self.lo = lo
        self.shape = np.array(dist.shape)
        self.dist = dist
        self.far = pad
        parts = [part.aabb() for ob in cell.obstacles for part in ob.parts]
        self.part_lo = np.array([b[0] for b in parts])          # (P, 3)
        self.part_hi = np.array([b[1] for b in parts])

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Interpolated obstacle distance of points (..., 3), shape (...)."""
        pts = np.asarray(points, dtype=np.float64)
        if self.empty:
            return np.full(pts.shape[:-1], np.inf)
        nb = _compiled_loops()
        if nb is not None and np.isfinite(pts).all():
            out = np.empty(pts.shape[:-1])
            nb.field_distances(np.ascontiguousarray(self.dist, dtype=np.float64), self.lo,
                               self.res, float(self.far),
                               np.ascontiguousarray(pts.reshape(-1, 3)), out.reshape(-1))
            return out
        u = (pts.reshape(-1, 3) - self.lo) / self.res
        outside = np.any((u < 0) | (u > self.shape - 1), axis=-1)
        out = _trilinear(self.dist, u)
        out = np.where(outside, np.maximum(out, self.far), out)
        return out.reshape(pts.shape[:-1])

    def points_clear(self, centres: np.ndarray, offsets: np.ndarray, threshold: float,
                     standing: np.ndarray) -> np.ndarray:
        """Whether the points ``centres[m, s] + offsets`` (a part in hand read at points on
        its box) keep a field gap (:meth:`distance` less ``threshold``) of at least 0 at
        every sample, or, for ``standing[m]``, of at least the least gap at the first
        sample (if below 0) less 5 mm.

        The compiled kernel, where in use, reads only the points near an obstacle part's
        bounding box (the others keep ``threshold`` whatever the grid says) and stops at
        the first point that fails: the same answers as reading every point.

        Parameters
        ----------
        centres : ndarray, shape (M, S, 3)
        offsets : ndarray, shape (K, 3), K >= 1
        threshold : float
        standing : ndarray of bool, shape (M,)

        Returns
        -------
        ok : ndarray of bool, shape (M,)
        """
        c = np.asarray(centres, dtype=np.float64)
        o = np.asarray(offsets, dtype=np.float64)
        if self.empty:
            return np.ones(len(c), dtype=bool)
        nb = _compiled_loops()
        if nb is None or not (np.isfinite(c).all() and np.isfinite(o).all()):
            gap = self.distance(c[..., None, :] + o).min(axis=-1) - threshold   # (M, S)
            allowed = np.where(standing, np.minimum(gap[:, 0], 0.0) - 0.005, 0.0)
            return gap.min(axis=1) >= allowed
        groups = _point_groups(o.tobytes(), o.shape[0])
        # Points this far from every part's box read at least ``threshold``: the grid's
        # corners around them are within sqrt(3) res (a micrometre spare for rounding).
        limit = threshold + self.res * np.sqrt(3.0) + 1e-6
        out = np.empty(len(c), dtype=np.bool_)
        nb.held_points_clear(np.ascontiguousarray(self.dist, dtype=np.float64),
                             np.asarray(self.lo, dtype=np.float64), float(self.res),
                             float(self.far), np.ascontiguousarray(c), groups.offsets,
                             groups.starts, groups.lo, groups.hi, self.part_lo, self.part_hi,
                             float(limit) if limit < self.far else np.inf, float(threshold),
                             np.ascontiguousarray(standing, dtype=np.bool_), out)
        return out

    def clear(self, poses: np.ndarray, stature: float, margin: float = 0.01,
              relative: bool = False, parts: np.ndarray | None = None) -> np.ndarray:
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
        parts : ndarray of int, shape (K,), optional
            Only these body capsules (indices into ``motion.capsules.BODY_PARTS``); default all.

        Returns
        -------
        ok : ndarray of bool, shape (M,)
        """
        from ltl_human_motion.scene.geometry import box_gap, point_bounds
        if self.empty:
            return np.ones(poses.shape[0], dtype=bool)
        # Each capsule is sampled at its end points (joints) and its middle; the joints
        # are shared by capsules, so the field is read once per joint.
        ia, ib, long, radii = _capsule_table(float(stature), _parts_key(parts))
        pos = np.asarray(poses, dtype=np.float64)
        ok = np.ones(pos.shape[0], dtype=bool)
        # A candidate whose joints (and so its sample points) all keep more than the
        # largest radius, the margins and the largest interpolation error (sqrt(3) res)
        # from every part's bounding box passes whatever the grid says (points off the
        # grid read at least ``far``): read the grid only for the others.
        limit = radii.max() + margin + self.res * (0.4 + np.sqrt(3.0))
        if limit <= self.far:
            lo, hi = point_bounds(pos.reshape(pos.shape[0], -1, 3))
            box = box_gap(lo[:, None], hi[:, None], self.part_lo, self.part_hi).min(axis=1)
            check = box < limit
        else:
            check = np.ones(pos.shape[0], dtype=bool)
        if not check.any():
            return ok
        pos = pos[check]
        nb = _compiled_loops()
        if nb is not None and np.isfinite(pos).all():
            # (every candidate and sample; the bounding-box test is done)
            ok[check] = self._compiled_clear(nb, pos, np.arange(len(pos)),
                                             np.arange(pos.shape[1]),
                                             self._sample_test(stature, parts, margin),
                                             relative, np.inf)
            return ok
        d_joint = self.distance(pos)                                        # (m, S, J)
        d_mid = self.distance((pos[..., ia[long], :] + pos[..., ib[long], :]) / 2.0)
        closest = np.minimum(d_joint[..., ia], d_joint[..., ib])            # (m, S, K)
        closest[..., long] = np.minimum(closest[..., long], d_mid)
        gap = closest - (radii + margin + self.res * 0.4)                   # (m, S, K)
        # With ``relative``, a body part that starts closer than the margin (a worker
        # standing at a bench) may stay there; it must not get closer.
        allowed = np.minimum(gap[:, :1], 0.0) - 0.005 if relative else 0.0
        ok[check] = np.all(gap >= allowed, axis=(1, 2))
        return ok

    def clear_samples(self, poses: np.ndarray, cand: np.ndarray, samples: np.ndarray,
                      stature: float, margin: float = 0.01, relative: bool = False,
                      parts: np.ndarray | None = None) -> np.ndarray:
        """:meth:`clear` of ``poses[cand][:, samples]``, in one compiled call where the
        compiled kernel is in use (the same answers; the search's hot path).

        Parameters
        ----------
        poses : ndarray, shape (M, S, J, 3)
        cand : ndarray of int, shape (N,)
        samples : ndarray of int, shape (S',)
        stature, margin, relative, parts
            As for :meth:`clear`.

        Returns
        -------
        ok : ndarray of bool, shape (N,)
        """
        nb = _compiled_loops()
        pos = np.asarray(poses, dtype=np.float64)
        if self.empty or nb is None or not np.isfinite(pos).all():
            return self.clear(pos[cand][:, samples], stature, margin, relative, parts)
        test = self._sample_test(stature, parts, margin)
        return self._compiled_clear(nb, pos, cand, samples, test, relative, test[5])

    def _sample_test(self, stature: float, parts: np.ndarray | None, margin: float
                     ) -> tuple:
        """What the compiled test of :meth:`clear_samples` reads for a body, its parts and
        margin, computed once per field: the capsules of :func:`_capsule_table` (ia, ib,
        long, radii), the gap each needs (K,) and the bounding-box pre-test's limit (inf
        where the field is too small for it)."""
        cache = self.__dict__.setdefault("_sample_tests", {})
        key = (float(stature), _parts_key(parts), margin)
        test = cache.get(key)
        if test is None:
            ia, ib, long, radii = _capsule_table(key[0], key[1])
            limit = radii.max() + margin + self.res * (0.4 + np.sqrt(3.0))
            test = (ia, ib, long, radii, radii + margin + self.res * 0.4,
                    float(limit) if limit <= self.far else np.inf)
            cache[key] = test
        return test

    def _compiled_clear(self, nb: ModuleType, pos: np.ndarray, cand: np.ndarray,
                        samples: np.ndarray, test: tuple, relative: bool, limit: float
                        ) -> np.ndarray:
        """The compiled test of :meth:`clear_samples` for the capsules and gaps of
        :meth:`_sample_test` (``limit``: of the bounding-box pre-test, ``inf`` to read
        the field for every candidate), shape (N,)."""
        ia, ib, long, _, need, _ = test
        out = np.empty(len(cand), dtype=np.bool_)
        nb.body_samples_clear(
            np.ascontiguousarray(self.dist, dtype=np.float64),
            np.asarray(self.lo, dtype=np.float64), float(self.res), float(self.far),
            np.ascontiguousarray(pos), np.asarray(cand, dtype=np.int64),
            np.asarray(samples, dtype=np.int64), ia, ib, long, need, bool(relative),
            self.part_lo, self.part_hi, limit, out)
        return out


#: Side (m) of the cubes the points of a part in hand are grouped in for
#: :meth:`ObstacleField.points_clear` (a group near no obstacle is not read).
POINT_GROUP_SIZE = 0.15


@dataclass(frozen=True)
class PointGroups:
    """Points grouped by the cube of side ``POINT_GROUP_SIZE`` they lie in.

    Attributes
    ----------
    offsets : ndarray, shape (K, 3)
        The points, group after group.
    starts : ndarray of int, shape (G + 1,)
        Group g is ``offsets[starts[g]:starts[g + 1]]``.
    lo, hi : ndarray, shape (G, 3)
        Each group's bounding box.
    """

    offsets: np.ndarray
    starts: np.ndarray
    lo: np.ndarray
    hi: np.ndarray


@lru_cache(maxsize=32)
def _point_groups(data: bytes, n: int) -> PointGroups:
    """:class:`PointGroups` of the points (n, 3) stored in ``data`` (float64, C order).
    Shared: callers must not write to them."""
    pts = np.frombuffer(data, dtype=np.float64).reshape(n, 3)
    cube = np.floor((pts - pts.min(axis=0)) / POINT_GROUP_SIZE).astype(np.int64)
    keys, group = np.unique(cube, axis=0, return_inverse=True)
    group = group.reshape(-1)
    order = np.argsort(group, kind="stable")
    starts = np.r_[0, np.cumsum(np.bincount(group, minlength=len(keys)))].astype(np.int64)
    lo = np.array([pts[order[a:b]].min(axis=0) for a, b in zip(starts[:-1], starts[1:])])
    hi = np.array([pts[order[a:b]].max(axis=0) for a, b in zip(starts[:-1], starts[1:])])
    return PointGroups(np.ascontiguousarray(pts[order]), starts, lo, hi)


def _parts_key(parts: np.ndarray | None) -> tuple[int, ...] | None:
    """``parts`` (capsule indices) as the key of :func:`_capsule_table`."""
    return None if parts is None else tuple(np.asarray(parts).tolist())


@lru_cache(maxsize=32)
def _capsule_table(stature: float, parts: tuple[int, ...] | None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The capsules :meth:`ObstacleField.clear` reads: end joints (K,), whether each is
    long (not a sphere) and radii (K,) at ``stature``, of ``parts`` (default all).
    Shared: callers must not write to them."""
    from ltl_human_motion.motion.capsules import capsule_ends, capsule_radii
    ia, ib = capsule_ends()
    radii = capsule_radii(stature)
    if parts is not None:
        sel = np.asarray(parts, dtype=np.int64)
        ia, ib, radii = ia[sel], ib[sel], radii[sel]
    ia, ib = np.ascontiguousarray(ia, dtype=np.int64), np.ascontiguousarray(ib, dtype=np.int64)
    return ia, ib, ia != ib, radii


_CLEARANCE_CACHE: BoundedCache[tuple[ClearanceMap, ObstacleField]] = BoundedCache(64)
_FIELDS_FORMAT = 4
_GRID_CACHE: BoundedCache[FloorGrid] = BoundedCache(16)
#: Default extra cost of a metre through the narrowest walkable floor (see
#: :func:`floor_grid`): a gap the body barely fits counts twice its length. The squeeze
#: through a narrow aisle uses it; the walking map's fields count such floor far longer
#: (:data:`.walk_goals.LANE_NARROW_COST`).
NARROW_COST = 1.0


def floor_grid(clearance: ClearanceMap, lo: np.ndarray, hi: np.ndarray, radius: float,
               resolution: float, passage: float | None = None,
               narrow_cost: float = NARROW_COST) -> FloorGrid:
    """The :class:`FloorGrid` whose free cells keep ``radius`` of floor clearance; with
    ``passage``, a metre through a cell with less clearance than that counts up to
    ``1 + narrow_cost`` metres (linear from ``passage`` down to ``radius``), so the
    fields lead through gaps the body barely fits only when there is no roomier way.

    Built once per clearance map (one per obstacle layout, :func:`clearance_maps`),
    area, radius and resolution, and shared by every navigation field on that floor.

    Parameters
    ----------
    clearance : ClearanceMap
    lo, hi : array-like, shape (2,)
    radius, resolution : float
        Metres.
    """
    key = (np.asarray(lo, dtype=np.float64).tobytes(),
           np.asarray(hi, dtype=np.float64).tobytes(), float(radius), float(resolution),
           None if passage is None else float(passage), float(narrow_cost))

    def cell_cost(xy: np.ndarray) -> np.ndarray:
        narrow = (passage - clearance(xy)) / max(passage - radius, 1e-9)
        return 1.0 + narrow_cost * np.clip(narrow, 0.0, 1.0)

    def build() -> FloorGrid:
        grid = FloorGrid(lo, hi, lambda xy: clearance(xy) > radius, resolution,
                         None if passage is None else cell_cost)
        grid.clearance = clearance
        return grid

    return _GRID_CACHE.get_or_build(key, build, owner=clearance)


_STAND_CACHE: BoundedCache[ClearanceMap] = BoundedCache(16)


def layout_key(cell) -> str:
    """A hash of the cell's workspace and obstacles (what the maps depend on), computed
    once per obstacles tuple and workspace (the cells of a batch share them)."""
    import hashlib
    import pickle
    lo = np.asarray(cell.workspace_lo, dtype=np.float64)
    hi = np.asarray(cell.workspace_hi, dtype=np.float64)
    return _LAYOUT_KEYS.get_or_build(
        (lo.tobytes(), hi.tobytes()),
        lambda: hashlib.sha1(pickle.dumps((_FIELDS_FORMAT, _code_fingerprint(),
                                           np.asarray(cell.workspace_lo),
                                           np.asarray(cell.workspace_hi), cell.obstacles))
                             ).hexdigest(), owner=cell.obstacles)


_LAYOUT_KEYS: BoundedCache[str] = BoundedCache(32)


@lru_cache(maxsize=1)
def _code_fingerprint() -> str:
    """A hash of this module's source: maps pickled by other code are never loaded (the
    lane-keeping fields of the scenario work read stale maps until this was keyed)."""
    import hashlib
    return hashlib.sha1(Path(__file__).read_bytes()).hexdigest()


def stand_clearance_map(cell) -> ClearanceMap:
    """Floor clearance from every obstacle footprint with no allowance for tall parts.

    Where a worker *stands* to reach (a goal primitive that is then checked exactly),
    a tall rack or wall is as close as its footprint: the arms do not swing there. The
    walking map (:func:`clearance_maps`) counts tall parts ``tall_extra`` closer. Kept in
    memory per cell (cheap to build).
    """
    return _STAND_CACHE.get_or_build(layout_key(cell),
                                     lambda: ClearanceMap(cell, tall_extra=0.0))


def clearance_maps(cell) -> tuple[ClearanceMap, ObstacleField]:
    """The floor clearance map and 3D obstacle field of ``cell``, once per obstacle layout.

    Cached in memory and on disk (next to the motion library cache), keyed by a hash of
    the workspace and the obstacles; an unreadable cache file is rebuilt.
    """
    import pickle
    import zipfile

    from ltl_human_motion.atomic import atomic_write_with
    from ltl_human_motion.motion.library import cache_dir
    key = layout_key(cell)
    maps = _CLEARANCE_CACHE.get(key)
    if maps is not None:
        return maps
    path = cache_dir() / f"fields-{key[:24]}.pkl"
    try:
        with open(path, "rb") as fh:
            maps = pickle.load(fh)
        if not (isinstance(maps, tuple) and len(maps) == 2
                and isinstance(maps[0], ClearanceMap) and isinstance(maps[1], ObstacleField)
                and hasattr(maps[0], "_values")
                and (maps[1].empty or hasattr(maps[1], "part_lo"))):
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
    return _CLEARANCE_CACHE.put(key, maps)
