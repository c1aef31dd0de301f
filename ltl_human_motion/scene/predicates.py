"""The predicates of Sec. II-B: enter, enclose and collision, vectorized over frames.

* ``enter(x, BP, R)``  iff occ(x, BP) ∩ R ≠ ∅: some capsule of the body part meets the
  region, i.e. its segment-to-region distance is at most its radius.
  ``enter(x, BP, occ(O) ⊕ B(eps))`` is ``enter(..., margin=eps)``.
* ``enclose(x, BP, R)`` iff occ(x, BP) ⊆ R: for a convex region (boxes) a capsule lies
  inside iff both end points lie in the region shrunk by the radius, i.e. their signed
  distance is at most ``-radius``. For mesh regions this test is exact when the mesh is
  convex.
* ``enter(O, R)`` / ``enclose(O, R)`` compare an object's solid with a region.
* ``collision(x)`` iff occ(x) ∩ O(t) ≠ ∅, where O(t) holds the static obstacles; a
  carried object counts as part of the body (it must not meet an obstacle either).
  Objects that are not carried are not obstacles (the hands reach for them).
* ``ground(x, BP, h)``: occ(x, BP) ∩ (occ(ground) ⊕ B(h)) ≠ ∅, the ground being the
  half-space below ``floor_z``: the lowest capsule point is at most ``h`` above it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from ltl_human_motion.motion.skeleton import DEFAULT_STATURE
from ltl_human_motion.scene.cell import Cell, Region, SceneObject
from ltl_human_motion.scene.geometry import box_gap, point_bounds
from ltl_human_motion.scene.occupancy import capsules_from_positions
from ltl_human_motion.scene.shapes import (
    EXACT_BELOW,
    Box,
    Shape,
    shape_distance,
    shape_enclosed_in,
)

__all__ = [
    "as_shape",
    "body_clearance",
    "collision",
    "distance_to",
    "enclose",
    "enclose_object",
    "enter",
    "enter_object",
    "ground_enter",
    "object_clearance",
    "object_collides",
]

Target = Region | Shape | SceneObject


def as_shape(target: Target) -> Shape:
    """The solid of a region, shape or object (an object at its initial position)."""
    if isinstance(target, Region):
        return target.shape
    if isinstance(target, SceneObject):
        return target.occupancy
    if isinstance(target, Shape):
        return target
    raise ValueError(f"expected a Region, Shape or SceneObject, got {type(target).__name__}")


def enter(positions: np.ndarray, region: Target, parts: str | Iterable[str] | None = None, *,
          margin: float = 0.0, stature: float = DEFAULT_STATURE) -> np.ndarray:
    """enter(x, BP, R ⊕ B(margin)) for every frame.

    Parameters
    ----------
    positions : array-like, shape (..., J, 3)
    region : Region, Shape or SceneObject
    parts : str or iterable of str, optional
        Body parts (default: the whole body).
    margin : float
        Radius of the ball added to the region (Minkowski sum).
    stature : float

    Returns
    -------
    holds : ndarray of bool, shape (...)
    """
    if margin < 0:
        raise ValueError(f"margin must be non-negative, got {margin!r}")
    seg, rad = capsules_from_positions(positions, stature, parts)
    # Clearances up to the margin are exact; capsules bounded beyond it cannot enter.
    clearance = as_shape(region).capsule_clearance(
        seg, rad, exact_below=float(np.nextafter(margin, np.inf)))
    return np.any(clearance <= margin, axis=-1)


def distance_to(positions: np.ndarray, target: Target,
                parts: str | Iterable[str] | None = None, *,
                stature: float = DEFAULT_STATURE) -> np.ndarray:
    """dist(occ(x, BP), target): the smallest distance between the body and a target.

    The A* heuristic of Sec. III-B uses it. Exact (no far-field bound).

    Parameters
    ----------
    positions : array-like, shape (..., J, 3)
    target : Region, Shape or SceneObject
    parts : str or iterable of str, optional
    stature : float

    Returns
    -------
    distance : ndarray, shape (...)
        0 when the body meets the target.
    """
    seg, rad = capsules_from_positions(positions, stature, parts)
    clearance = as_shape(target).capsule_clearance(seg, rad, exact_below=np.inf)
    return np.maximum(np.min(clearance, axis=-1), 0.0)


def enclose(positions: np.ndarray, region: Target, parts: str | Iterable[str] | None = None, *,
            stature: float = DEFAULT_STATURE) -> np.ndarray:
    """enclose(x, BP, R): every capsule of the parts lies inside the region.

    Parameters
    ----------
    positions : array-like, shape (..., J, 3)
    region : Region, Shape or SceneObject
    parts : str or iterable of str, optional
    stature : float

    Returns
    -------
    holds : ndarray of bool, shape (...)
    """
    seg, rad = capsules_from_positions(positions, stature, parts)
    shape = as_shape(region)
    sd = shape.signed_distance(seg)                               # (..., K, 2)
    return np.all(sd <= -rad[:, None] + 1e-12, axis=(-1, -2))


def enter_object(obj: Shape | SceneObject, region: Target, margin: float = 0.0) -> bool:
    """enter(O, R ⊕ B(margin)): the object's solid meets the region."""
    return shape_distance(as_shape(obj), as_shape(region)) <= margin


def enclose_object(obj: Shape | SceneObject, region: Target) -> bool:
    """enclose(O, R): the object's solid lies inside the region."""
    return shape_enclosed_in(as_shape(obj), as_shape(region))


def ground_enter(positions: np.ndarray, parts: str | Iterable[str] | None, height: float, *,
                 floor_z: float = 0.0, stature: float = DEFAULT_STATURE) -> np.ndarray:
    """enter(x, BP, occ(ground) ⊕ B(height)): the part comes within ``height`` of the floor.

    Returns
    -------
    holds : ndarray of bool, shape (...)
    """
    seg, rad = capsules_from_positions(positions, stature, parts)
    low = np.min(seg[..., 2], axis=-1) - rad                      # (..., K)
    return np.any(low <= floor_z + height, axis=-1)


def body_clearance(positions: np.ndarray, cell: Cell, *,
                   stature: float = DEFAULT_STATURE,
                   exact_below: float = EXACT_BELOW) -> np.ndarray:
    """Smallest distance between the body and any obstacle per frame.

    Parameters
    ----------
    positions : array-like, shape (..., J, 3)
    stature : float
    exact_below : float
        Clearances below this are exact; frames farther from every obstacle get a lower
        bound that is at least ``exact_below`` (a test ``clearance <= m`` with
        ``m < exact_below`` is exact).

    Returns
    -------
    clearance : ndarray, shape (...)
        Negative (or 0) when the body touches an obstacle; ``inf`` without obstacles.
    """
    seg, rad = capsules_from_positions(positions, stature)
    if not cell.obstacles:
        return np.full(seg.shape[:-3], np.inf)
    # Every capsule ends at joints: the joints' box holds the capsules' end points.
    return cell.part_set.body_clearance(seg, rad, exact_below,
                                        bounds=point_bounds(np.asarray(positions)))


def object_clearance(cell: Cell, name: str, trajectory: np.ndarray,
                     exact_below: float = 0.5) -> np.ndarray:
    """Distance between object ``name`` and the obstacles along a trajectory.

    Parameters
    ----------
    cell : Cell
    name : str
    trajectory : array-like, shape (T, 3) or (3,)
        Object positions; rows with NaN are skipped (clearance ``inf``).
    exact_below : float
        Metres: distances are exact up to this, a lower bound (the gap of the bounding
        boxes) beyond. A collision test needs them exact only up to its margin.

    Returns
    -------
    clearance : ndarray, shape (T,) or ()
        0 when touching or overlapping.
    """
    obj = cell.object(name)
    traj = np.asarray(trajectory, dtype=np.float64)
    single = traj.ndim == 1
    traj = np.atleast_2d(traj)
    if traj.shape[-1] != 3:
        raise ValueError(f"trajectory must have shape (T, 3), got {traj.shape}")
    out = np.full(len(traj), np.inf)
    valid = np.all(np.isfinite(traj), axis=-1)
    if valid.any() and cell.obstacles:
        ps = cell.part_set
        lo0, hi0 = obj.shape.aabb()
        rel_lo, rel_hi = lo0 - obj.position, hi0 - obj.position
        tv = traj[valid]
        # Cheap bound for every (frame, part): the gap between the bounding boxes, which is
        # the distance itself for two axis-aligned boxes.
        bound = box_gap((tv + rel_lo)[:, None], (tv + rel_hi)[:, None], ps.lo, ps.hi)
        obj_box = isinstance(obj.shape, Box) and obj.shape.axis_aligned
        need = (bound <= exact_below) & ~(ps.is_box & obj_box)    # exact distance wanted
        best = np.where(need, np.inf, bound).min(axis=1)
        for k in np.flatnonzero(need.any(axis=0)):
            # Exact only where it could be the smallest (it is at least the bound).
            for t in np.flatnonzero(need[:, k] & (bound[:, k] < best)):
                best[t] = min(best[t], shape_distance(obj.occupancy_at(tv[t]), ps.parts[k]))
        out[valid] = best
    return out[0] if single else out


def object_collides(cell: Cell, name: str, trajectory: np.ndarray, margin: float = 0.0
                    ) -> np.ndarray:
    """Whether object ``name`` is within ``margin`` of an obstacle at each position of
    ``trajectory`` (T, 3) (:func:`object_clearance`, exact up to the margin), shape (T,)
    of bool; rows with NaN never collide."""
    exact_below = float(np.nextafter(margin, np.inf))
    return object_clearance(cell, name, trajectory, exact_below=exact_below) <= margin


def collision(positions: np.ndarray, cell: Cell, *, stature: float = DEFAULT_STATURE,
              carried: Mapping[str, np.ndarray] | None = None,
              margin: float = 0.0) -> np.ndarray:
    """collision(x(t)) for every frame: occ(x) (plus carried objects) meets an obstacle.

    Parameters
    ----------
    positions : array-like, shape (T, J, 3) or (J, 3)
    cell : Cell
    stature : float
    carried : mapping of str to array (T, 3), optional
        Positions of carried objects per frame (NaN rows: not carried at that frame).
    margin : float
        Safety margin: count as a collision when the clearance is at most this.

    Returns
    -------
    collides : ndarray of bool, shape (T,) or ()
    """
    pos = np.asarray(positions, dtype=np.float64)
    if margin < 0:
        raise ValueError(f"margin must be non-negative, got {margin!r}")
    # Every capsule-part pair whose bound is at most the margin is computed exactly, so
    # the test is exact; pairs bounded beyond the margin cannot collide.
    exact_below = float(np.nextafter(margin, np.inf))
    hit = body_clearance(pos, cell, stature=stature, exact_below=exact_below) <= margin
    for name, traj in (carried or {}).items():
        traj = np.asarray(traj, dtype=np.float64)
        if traj.shape != (*pos.shape[:-2], 3):
            raise ValueError(f"carried[{name!r}] must have shape {(*pos.shape[:-2], 3)}, "
                             f"got {traj.shape}")
        hit = hit | object_collides(cell, name, traj, margin)
    return hit
