"""Placement geometry: where the worker stands for a task and whether the body gets there.

The planner's walk goals are tests on floor poses (x, y, yaw) of the root. For a task
whose condition is ``enter(x, R)`` (``walk(R)``, ``carry(O, R)`` and the always-on final
region) the test here is the verifier's own predicate: the standing body, placed at the
pose, enters R (:func:`ltl_human_motion.scene.predicates.enter`, the exact capsule test).
A region whose floor projection has no such spot with room to turn (a box above a bench)
is entered by a hand instead (the planner's hand reach).
"""

from __future__ import annotations

import numpy as np

#: Headings tried when deciding whether a floor cell is a place from which the standing
#: body enters a region (every 45 degrees: the body's extent varies slowly with yaw).
ENTRY_HEADINGS = 8
#: Headings of those from which a goal cell of a walk into a region must enter it: a
#: place that enters facing one heading only is met by the walk's arrival from one
#: side only (a 1.95 m worker coming to a region over a bench from the side searched
#: 8,000 poses in front of the bench; from a place it enters facing half the headings,
#: 1,000).
ENTRY_HEADINGS_NEEDED = 4


def standing_bodies(stance: np.ndarray, height: float, x: np.ndarray, y: np.ndarray,
                    yaw: np.ndarray) -> np.ndarray:
    """World joint positions of a standing pose at many floor poses.

    Parameters
    ----------
    stance : ndarray, shape (J, 3)
        Root-relative standing pose in the heading frame.
    height : float
        Root height of the standing pose, metres.
    x, y, yaw : ndarray, shape (M,)

    Returns
    -------
    positions : ndarray, shape (M, J, 3)
    """
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    out = np.empty((len(x), *stance.shape))
    out[..., 0] = c * stance[:, 0] - s * stance[:, 1] + np.asarray(x)[:, None]
    out[..., 1] = s * stance[:, 0] + c * stance[:, 1] + np.asarray(y)[:, None]
    out[..., 2] = stance[:, 2] + height
    return out


def footprint_gap(lo: np.ndarray, hi: np.ndarray, x: np.ndarray, y: np.ndarray
                  ) -> np.ndarray:
    """Horizontal distance of floor points from the box footprint [lo, hi], shape like x."""
    gx = np.maximum(np.maximum(lo[0] - x, x - hi[0]), 0.0)
    gy = np.maximum(np.maximum(lo[1] - y, y - hi[1]), 0.0)
    return np.hypot(gx, gy)


def standing_extent(stance: np.ndarray, max_radius: float) -> float:
    """How far from the root (horizontally) any capsule of the standing pose reaches, m."""
    return float(np.max(np.hypot(stance[:, 0], stance[:, 1]))) + float(max_radius)


class RegionEntry:
    """Floor poses from which the standing body enters a region (the exact predicate).

    Parameters
    ----------
    region : Region
    stance : ndarray, shape (J, 3)
        The standing pose the walk ends in (walk or carry stance).
    height : float
        Its root height, metres.
    stature : float
    max_radius : float
        Largest capsule radius at this stature, metres.
    """

    def __init__(self, region, stance: np.ndarray, height: float, stature: float,
                 max_radius: float) -> None:
        self.region = region
        self.lo = np.asarray(region.lo, dtype=np.float64)
        self.hi = np.asarray(region.hi, dtype=np.float64)
        self.stance = np.asarray(stance, dtype=np.float64)
        self.height = float(height)
        self.stature = float(stature)
        self.extent = standing_extent(self.stance, max_radius)

    def enters(self, x: np.ndarray, y: np.ndarray, yaw: np.ndarray) -> np.ndarray:
        """Whether the standing body at each pose enters the region, bool shape (M,)."""
        from ltl_human_motion.scene.predicates import enter
        x, y, yaw = (np.asarray(v, dtype=np.float64) for v in (x, y, yaw))
        out = footprint_gap(self.lo, self.hi, x, y) <= self.extent
        if out.any():
            bodies = standing_bodies(self.stance, self.height, x[out], y[out], yaw[out])
            out[out] = enter(bodies, self.region, stature=self.stature)
        return out

    def cells(self, xy: np.ndarray) -> np.ndarray:
        """Floor points from which the standing body enters the region facing at least
        :data:`ENTRY_HEADINGS_NEEDED` of the :data:`ENTRY_HEADINGS` headings, or, where
        no point does, facing some heading; bool shape (N,)."""
        xy = np.asarray(xy, dtype=np.float64)
        out = footprint_gap(self.lo, self.hi, xy[:, 0], xy[:, 1]) <= self.extent
        idx = np.flatnonzero(out)
        if idx.size:
            count = np.zeros(idx.size, dtype=np.int64)
            for yaw in np.arange(ENTRY_HEADINGS) * (2.0 * np.pi / ENTRY_HEADINGS):
                count += self.enters(xy[idx, 0], xy[idx, 1], np.full(idx.size, yaw))
            hit = count >= ENTRY_HEADINGS_NEEDED
            out[idx] = hit if hit.any() else count > 0
        return out
