"""Where in a region a part is put down: its centre when that is within reach of a free
standing spot, else the point of the region nearest one.

A ``move(O, R)`` holds once the part is inside R, anywhere. The planner aims at R's
centre; for a region deep in furniture (a machine's bay behind its door, the back of a
wide table) the centre can lie beyond every reach while the near side of R is an
ordinary one. A person puts the part down just inside the near side. The choice here is
by the floor only: the horizontal distance from a point of R to the nearest floor spot
where the worker stands clear (``PlanContext.stand_map`` over ``stand_room``).
"""

from __future__ import annotations

import math

import numpy as np

from ltl_human_motion.planning.plan_state import PlanContext

#: Grid step (m) of the candidate points in a region, and the radii (m) and headings at
#: which a point's nearest free standing spot is looked for.
POINT_STEP = 0.1
SPOT_RADII = np.arange(0.1, 1.6, 0.05)
SPOT_HEADINGS = 32
#: Step (m) of the samples along the way from a spot to a point, and the clearance (m)
#: the way keeps from obstacles: a forearm's radius.
LINE_STEP = 0.05
LINE_CLEARANCE = 0.04
#: A point must come at least this much (m) nearer a free spot than the centre to be
#: chosen instead of it.
NEARER_BY = 0.05


def spot_distance(ctx: PlanContext, points: np.ndarray) -> np.ndarray:
    """Horizontal distance (m) from each point (N, 3) to the nearest sampled floor spot
    where the worker stands clear and from which the straight way to the point, at the
    point's height, keeps ``LINE_CLEARANCE`` from every obstacle (an arm reaches in
    through a door, not through a machine's side wall), shape (N,); ``inf`` where none
    is within ``SPOT_RADII``."""
    pts = np.asarray(points, dtype=np.float64)
    a = np.linspace(0.0, 2.0 * math.pi, SPOT_HEADINGS, endpoint=False)
    ring = np.stack([np.cos(a), np.sin(a)], axis=-1)                     # (A, 2)
    out = np.full(len(pts), np.inf)
    todo = np.arange(len(pts))
    for r in SPOT_RADII:
        if todo.size == 0:
            break
        spots = pts[todo, None, :2] + r * ring[None]                     # (n, A, 2)
        free = ctx.stand_map(spots.reshape(-1, 2)).reshape(spots.shape[:2]) > ctx.stand_room
        s = np.linspace(0.0, 1.0, max(math.ceil(r / LINE_STEP), 1) + 1)
        line = pts[todo, None, None, :2] + s[None, None, :, None] * (
            spots[:, :, None, :] - pts[todo, None, None, :2])            # (n, A, S, 2)
        z = np.broadcast_to(pts[todo, 2][:, None, None, None], (*line.shape[:3], 1))
        seen = ctx.obstacle_field.distance(np.concatenate([line, z], axis=-1)) \
            > LINE_CLEARANCE
        ok = (free & seen.all(axis=2)).any(axis=1)
        out[todo[ok]] = r
        todo = todo[~ok]
    return out


def region_point(ctx: PlanContext, region, part_room: float, height: float,
                 reach: float) -> np.ndarray | None:
    """The point (3,) at ``height`` to put a part's centre in ``region`` instead of its
    centre, or None to keep the centre: where the centre is further than ``reach`` (m)
    from every free standing spot, the point of the region (``part_room`` inside its
    sides, clear of obstacles by the obstacle field) nearest one, if it is
    ``NEARER_BY`` nearer; of equally near points, the one nearest the centre."""
    lo = np.asarray(region.lo, dtype=np.float64)
    hi = np.asarray(region.hi, dtype=np.float64)
    centre = (lo + hi) / 2.0
    centre[2] = float(height)
    here = float(spot_distance(ctx, centre[None])[0])
    if here <= reach:
        return None
    axes = [np.arange(lo[k] + part_room, hi[k] - part_room + 1e-9, POINT_STEP)
            for k in range(2)]
    if any(len(ax) == 0 for ax in axes):
        return None
    xy = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
    pts = np.concatenate([xy, np.full((len(xy), 1), float(height))], axis=1)
    pts = pts[ctx.obstacle_field.distance(pts) > part_room]
    if len(pts) == 0:
        return None
    near = spot_distance(ctx, pts)
    best = near.min()
    if not best < here - NEARER_BY:
        return None
    tied = pts[near <= best + 1e-9]
    return tied[np.argmin(np.linalg.norm(tied[:, :2] - centre[:2], axis=1))]
