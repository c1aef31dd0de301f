"""A palm path clear of the obstacles, for the whole-body program to track.

The program (:mod:`.optimizer`) tracks the reference's palm under clearance constraints.
Where the reference's palm itself passes through furniture (it comes up to a part on a
shelf from below the board, or rises through the board above on its way back) the
velocity damper holds the palm at the surface and the tracked motion stops short of the
target: a local minimum of tracking, not a lack of room. :func:`clear_palm_path`
replaces such a stretch of the palm's path by the shortest path with clearance on a
grid round it (Dijkstra's algorithm, :func:`scipy.sparse.csgraph.dijkstra`), shortened
where the straight line between its points stays clear, and run on the reference's own
timing (the same fraction of the way at every frame), so the program tracks a palm that
goes round the board's edge and in level between the boards.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ltl_human_motion.motion.goals.constraints import ObstacleField

__all__ = ["GRID_STEP", "PathRoom", "clear_palm_path", "point_clearance"]

#: Spacing of the grid the path is searched on, m.
GRID_STEP = 0.03
#: How far the grid reaches beyond the box round the path's ends, m.
GRID_PAD = 0.25
#: Clearance below which a grid point's edges cost more, m (the path keeps to the middle
#: of a gap rather than grazing one side).
COMFORT = 0.08
#: Spacing at which a shortened path's straight pieces are checked, m.
CHECK_STEP = 0.01


@dataclass(frozen=True)
class PathRoom:
    """The clearance a palm path keeps: ``radius`` (m) round the palm point (the hand's
    and forearm's capsule radius plus the program's hand margin; more with a part in
    hand) and the floor height below which the grid does not go (m, start frame)."""

    radius: float
    floor: float = 0.05


def point_clearance(field_: ObstacleField, points: np.ndarray, within: float) -> np.ndarray:
    """Clearance (N,) of ``points`` (N, 3) to the obstacles, capped at ``within`` (m)."""
    out = np.full(len(points), float(within))
    if len(points) == 0:
        return out
    idx, _, clear = field_.near(points, points, np.zeros(len(points)), within)
    np.minimum.at(out, idx, clear)
    return out


def _grid(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, tuple[int, int, int]]:
    axes = [np.arange(a, b + GRID_STEP, GRID_STEP) for a, b in zip(lo, hi, strict=True)]
    shape = tuple(len(a) for a in axes)
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return pts, shape


def _graph(free: np.ndarray, clear: np.ndarray, shape: tuple[int, int, int]):
    """The sparse graph (26-neighbour) of the free grid points; edge weight = length
    times (1 + how far under :data:`COMFORT` the clearance at its ends is)."""
    from scipy.sparse import coo_matrix
    n = int(np.prod(shape))
    index = np.arange(n).reshape(shape)
    penalty = 1.0 + np.clip(COMFORT - clear, 0.0, None) / COMFORT * 4.0
    rows, cols, weights = [], [], []
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                if (dx, dy, dz) <= (0, 0, 0):
                    continue
                src = index[max(-dx, 0):shape[0] - max(dx, 0),
                            max(-dy, 0):shape[1] - max(dy, 0),
                            max(-dz, 0):shape[2] - max(dz, 0)].ravel()
                dst = src + dx * shape[1] * shape[2] + dy * shape[2] + dz
                ok = free[src] & free[dst]
                length = GRID_STEP * float(np.sqrt(dx * dx + dy * dy + dz * dz))
                w = length * 0.5 * (penalty[src[ok]] + penalty[dst[ok]])
                rows += [src[ok], dst[ok]]
                cols += [dst[ok], src[ok]]
                weights += [w, w]
    return coo_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n, n)).tocsr()


def _nearest_free(pts: np.ndarray, free: np.ndarray, point: np.ndarray, reach: float
                  ) -> int | None:
    d = np.linalg.norm(pts - point, axis=1)
    d[~free] = np.inf
    k = int(np.argmin(d))
    return k if d[k] <= reach else None


def _segment_clear(field_: ObstacleField, a: np.ndarray, b: np.ndarray, room: PathRoom
                   ) -> bool:
    n = max(int(np.ceil(np.linalg.norm(b - a) / CHECK_STEP)), 1)
    pts = a + (b - a) * np.linspace(0.0, 1.0, n + 1)[:, None]
    return bool(np.all(point_clearance(field_, pts, room.radius) >= room.radius))


def _shorten(field_: ObstacleField, path: np.ndarray, room: PathRoom) -> np.ndarray:
    """``path`` (K, 3) with each point joined to the furthest later one the straight line
    to which keeps clear (greedy shortcutting)."""
    out, i = [path[0]], 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1 and not _segment_clear(field_, path[i], path[j], room):
            j -= 1
        out.append(path[j])
        i = j
    return np.asarray(out)


def _on_timing(path: np.ndarray, progress: np.ndarray) -> np.ndarray:
    """Points (F, 3) on polyline ``path`` (K, 3) at the fractions ``progress`` (F,) of its
    length."""
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    along = np.concatenate([[0.0], np.cumsum(seg)])
    s = progress * along[-1]
    return np.stack([np.interp(s, along, path[:, k]) for k in range(3)], axis=1)


def _window(clear: np.ndarray, room: PathRoom) -> tuple[int, int]:
    """The frames (first, last) of the palm's path to remake: from the last frame before
    it first comes within ``room`` of an obstacle where it was :data:`COMFORT` clear of
    every one (or its start), to the first such frame after it last is (or its end)."""
    bad = np.flatnonzero(clear < room.radius)
    roomy = clear >= room.radius + COMFORT
    before = np.flatnonzero(roomy[:bad[0]])
    after = np.flatnonzero(roomy[bad[-1]:])
    return (int(before[-1]) if before.size else 0,
            int(bad[-1] + after[0]) if after.size else len(clear) - 1)


def clear_palm_path(field_: ObstacleField, palm: np.ndarray, room: PathRoom
                    ) -> np.ndarray | None:
    """The palm's path ``palm`` (F, 3, start frame) with the stretch that comes within
    ``room`` of an obstacle (:func:`_window`) remade clear, on the same timing; ``palm``
    itself where it is clear already; None where no clear path joins the stretch's ends
    on the grid (an end without room, or no way between)."""
    palm = np.asarray(palm, dtype=np.float64)
    clear = point_clearance(field_, palm, room.radius + COMFORT)
    if len(palm) < 3 or np.all(clear >= room.radius):
        return palm
    first, last = _window(clear, room)
    way = palm[first:last + 1]
    from scipy.sparse.csgraph import dijkstra
    lo = palm.min(axis=0) - GRID_PAD            # (the whole path's box: a way round a
    hi = palm.max(axis=0) + GRID_PAD            # board may lie far from the stretch)
    lo[2] = max(lo[2], room.floor)
    pts, shape = _grid(lo, hi)
    clear = point_clearance(field_, pts, COMFORT + room.radius) - room.radius
    free = clear >= 0.0
    ends = [_nearest_free(pts, free, p, 2.0 * GRID_STEP) for p in (way[0], way[-1])]
    if ends[0] is None or ends[1] is None:
        return None
    dist, pred = dijkstra(_graph(free, clear, shape), indices=ends[0], return_predecessors=True)
    if not np.isfinite(dist[ends[1]]):
        return None
    nodes, k = [], ends[1]
    while k != ends[0] and k >= 0:
        nodes.append(k)
        k = int(pred[k])
    nodes.append(ends[0])
    path = _shorten(field_, np.vstack([way[:1], pts[nodes[::-1]], way[-1:]]), room)
    walked = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(way, axis=0), axis=1))])
    progress = walked / walked[-1] if walked[-1] > 0.0 else np.linspace(0.0, 1.0, len(way))
    out = palm.copy()
    out[first:last + 1] = _on_timing(path, progress)
    return out
