"""Early infeasibility analysis: refuse a task sequence no worker can do, before any search.

For every step of a task sequence the targets it acts on (the part it has to touch, the
region a hand or the body has to get into, the bin a part goes into, the seat) are
checked against a worker of the given stature:

``reach``
    the target lies above the highest point a palm can reach (:class:`ReachEnvelope`);
``seat_height``
    a sitting surface above the standing pelvis (nobody sits there without climbing);
``no_floor``
    no free floor to stand on within horizontal reach of the target;
``enclosed``
    there is floor within reach, but none of it is connected to the start region;
``inside_obstacle``
    the target region lies entirely inside solid obstacles;
``size``
    a part that cannot fit into the region or container it is to be put in, in any
    orientation (its smallest width or its volume exceeds the container's).

Every bound is generous (the envelope of a flexible adult of that stature, a body that
may turn sideways through a gap), so a refusal means the pair is infeasible for a real
worker, not only for the planner. A refusal raises
:class:`~ltl_human_motion.errors.PlanningError` with ``reason`` set to the check's name
and a message naming the task, the target, the numbers and the limit.
"""

from __future__ import annotations

import hashlib
import math
import pickle
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.sparse.csgraph import connected_components

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.planning.navigation import FloorGrid, layout_key

__all__ = ["FloorMap", "ReachEnvelope", "check_steps", "floor_components", "floor_map",
           "reach_envelope", "step_problems"]

#: The shoulder girdle rises in an overhead reach: about 0.04 H above the rest pose's
#: shoulder joint, which brings the skeleton's overhead reach (1.21 H) to the 1.2-1.25 H
#: of overhead grip reach in anthropometric tables (Pheasant & Haslegrave, Bodyspace).
SHOULDER_ELEVATION_FRACTION = 0.04
#: Half the width of the narrowest gap a worker gets through turned sideways: half the
#: chest depth, about 0.07 H (0.12 m at 1.75 m; Drillis & Contini proportions).
PASSAGE_HALF_WIDTH_FRACTION = 0.07
#: Obstacle parts whose underside is above knee height (0.285 H, the skeleton's rest
#: knee) do not take floor away: feet and shins fit under a table top or a high board.
FLOOR_BLOCK_FRACTION = 0.285
#: A seat above the standing pelvis (0.53 H, the skeleton's rest pelvis) needs a climb.
SEAT_MAX_FRACTION = 0.53
#: Table I's B(eps): a grasp holds with the palm within eps of the part (metres).
GRASP_EPS = 0.05
#: Cell size of the floor map, metres.
FLOOR_RESOLUTION = 0.05
#: Least room (m) a box part needs inside a box container or region along each axis: a
#: part exactly as large as its container along an axis has no clearance to be put in
#: (and a placed part then holds Table I's enclose only up to rounding: 3e-8 m was seen).
FIT_CLEARANCE = 0.002


@dataclass(frozen=True)
class ReachEnvelope:
    """Where a palm can get for a worker standing (or kneeling) on one floor spot.

    Attributes
    ----------
    stature : float
    vertical : float
        Highest palm height, metres above the floor.
    heights : ndarray, shape (K,)
        Heights at which ``radius`` is sampled, 0 to ``vertical``.
    radius : ndarray, shape (K,)
        Largest horizontal distance from the standing spot to a palm at that height,
        with the trunk bent forward up to 90 degrees and the hips lowered to kneeling.
    """

    stature: float
    vertical: float
    heights: np.ndarray
    radius: np.ndarray

    def horizontal(self, lo_z: float, hi_z: float) -> float:
        """Largest horizontal reach at any height in ``[lo_z, hi_z]``; -inf if none."""
        lo, hi = max(float(lo_z), 0.0), min(float(hi_z), self.vertical)
        if lo > hi:
            return -math.inf
        inside = (self.heights >= lo) & (self.heights <= hi)
        near = [float(np.interp(lo, self.heights, self.radius)),
                float(np.interp(hi, self.heights, self.radius))]
        return max(near + ([float(self.radius[inside].max())] if inside.any() else []))


@lru_cache(maxsize=16)
def reach_envelope(stature: float) -> ReachEnvelope:
    """The reach envelope of a worker of ``stature`` metres, from the skeleton's
    proportions (Winter's table, :mod:`ltl_human_motion.motion.skeleton`)."""
    skel = Skeleton(float(stature))
    rest = skel.rest_positions()
    H = float(stature)
    j = JOINT_INDEX
    shoulder = rest[j["l_shoulder"]]
    arm = float(np.linalg.norm(rest[j["l_elbow"]] - shoulder)
                + np.linalg.norm(rest[j["l_wrist"]] - rest[j["l_elbow"]])
                + np.linalg.norm(rest[j["l_hand"]] - rest[j["l_wrist"]]))
    hip_z = float(rest[j["l_hip"], 2])
    trunk = float(shoulder[2]) - hip_z
    thigh = hip_z - float(rest[j["l_knee"], 2])
    lateral = float(abs(shoulder[1]))
    elevation = SHOULDER_ELEVATION_FRACTION * H
    vertical = float(shoulder[2]) + elevation + arm
    heights = np.linspace(0.0, vertical, 160)
    theta = np.linspace(0.0, np.pi / 2, 31)[:, None]                  # trunk flexion
    hips = np.linspace(thigh, hip_z, 12)[None, :]                    # kneeling to standing
    fwd = (trunk * np.sin(theta) + 0.0 * hips).ravel()
    sz = (hips + trunk * np.cos(theta) + elevation * np.cos(theta)).ravel()
    dz = heights[:, None] - sz[None, :]
    reach = np.sqrt(np.maximum(arm ** 2 - dz ** 2, 0.0))
    horiz = np.hypot(fwd[None, :] + reach, lateral)
    horiz = np.where(np.abs(dz) <= arm, horiz, -np.inf)
    radius = horiz.max(axis=1)
    heights.flags.writeable = False
    radius.flags.writeable = False
    return ReachEnvelope(H, vertical, heights, radius)


@dataclass(frozen=True)
class FloorMap:
    """Floor a worker can stand on, and which of it is connected to the start.

    Attributes
    ----------
    grid : FloorGrid
        Free cells keep ``PASSAGE_HALF_WIDTH_FRACTION * H`` from every obstacle part that
        reaches below knee height, inside the workspace.
    free_xy : ndarray, shape (F, 2)
        Centres of the free cells.
    connected : ndarray of bool, shape (F,)
        Free cells reachable on the floor from the start region.
    start_found : bool
        Whether the start region has free floor at all.
    tree : scipy.spatial.cKDTree or None
        Of ``free_xy``, for the cells near a target.
    """

    grid: FloorGrid
    free_xy: np.ndarray
    connected: np.ndarray
    start_found: bool
    tree: object = None


_FLOOR_CACHE: BoundedCache[FloorMap] = BoundedCache(32)
#: Answers per cell content, stature and task sequence (cells repeat across calls).
_ANSWER_CACHE: BoundedCache[list[PlanningError]] = BoundedCache(512)
#: Content digests of the Cell objects seen (a cell is immutable).
_DIGESTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _digest(cell) -> str:
    """A digest of everything the analysis reads from ``cell`` (once per Cell object)."""
    hit = _DIGESTS.get(cell)
    if hit is None:
        hit = hashlib.sha1(pickle.dumps((
            cell.floor_z, np.asarray(cell.workspace_lo), np.asarray(cell.workspace_hi),
            cell.obstacles, cell.objects, cell.regions, cell.start_region.name,
            cell.shorthands))).hexdigest()
        _DIGESTS[cell] = hit
    return hit


def _layout_key(cell, stature: float) -> tuple:
    return _digest(cell), round(float(stature), 4)


#: Free floor and its components per obstacle layout and stature (objects, regions and
#: the start region may change from call to call, e.g. in batches, without a rebuild).
_GRID_CACHE: BoundedCache[tuple] = BoundedCache(32)


def _layout_digest(cell) -> tuple[float, str]:
    """The cell's floor height and the digest of its workspace and obstacles
    (:func:`.navigation.layout_key`, computed once per obstacles tuple)."""
    return float(cell.floor_z), layout_key(cell)


#: The smallest signed distance of the floor grid's points to the footprints of the
#: obstacle parts taken (N,), per layout, parts and grid: workers of every stature share
#: it (only the radius they keep and the parts low enough to block differ).
_FOOTPRINT_DISTANCES: BoundedCache[np.ndarray] = BoundedCache(16)


def floor_components(cell, radius: float, resolution: float, block: float = math.inf
                     ) -> tuple[FloorGrid, np.ndarray]:
    """The floor grid where a body of ``radius`` (m) keeps clear of the workspace's walls
    and of every obstacle part whose underside is less than ``block`` (m) above the floor,
    and the connected component of each grid cell: ``(FloorGrid, labels (nx * ny,))``."""
    floor = float(cell.floor_z)
    parts = [part for ob in cell.obstacles for part in ob.parts]
    taken = tuple(k for k, part in enumerate(parts) if part.aabb()[0][2] - floor < block)
    lo = np.asarray(cell.workspace_lo[:2], dtype=np.float64)
    hi = np.asarray(cell.workspace_hi[:2], dtype=np.float64)

    def nearest(xy: np.ndarray) -> np.ndarray:
        out = np.full(len(xy), np.inf)
        for k in taken:
            np.minimum(out, parts[k].footprint().signed_distance(xy), out=out)
        out.flags.writeable = False
        return out

    def free(xy: np.ndarray) -> np.ndarray:
        ok = np.all((xy >= lo + radius) & (xy <= hi - radius), axis=-1)
        key = (_layout_digest(cell), taken, lo.tobytes(), hi.tobytes(), float(resolution),
               xy.shape)
        return ok & (_FOOTPRINT_DISTANCES.get_or_build(key, lambda: nearest(xy)) > radius)

    grid = FloorGrid(lo, hi, free, resolution)
    _, labels = connected_components(grid.graph, directed=False)
    return grid, labels


def _floor_grid(cell, stature: float) -> tuple:
    """``(grid, free_xy (F, 2), free_labels (F,), tree)`` for the cell's obstacle layout."""
    from scipy.spatial import cKDTree
    key = (_layout_digest(cell), round(float(stature), 4))
    hit = _GRID_CACHE.get(key)
    if hit is not None:
        return hit
    H = float(stature)
    grid, labels = floor_components(cell, PASSAGE_HALF_WIDTH_FRACTION * H, FLOOR_RESOLUTION,
                                    FLOOR_BLOCK_FRACTION * H)
    flat_free = grid.free.ravel()
    free_xy = grid.centres[flat_free]
    return _GRID_CACHE.put(key, (grid, free_xy, labels[flat_free],
                                 cKDTree(free_xy) if len(free_xy) else None))


def floor_map(cell, stature: float) -> FloorMap:
    """The :class:`FloorMap` of ``cell`` for a worker of ``stature`` (cached per layout)."""
    key = _layout_key(cell, stature)
    hit = _FLOOR_CACHE.get(key)
    if hit is not None:
        return hit
    grid, free_xy, free_labels, tree = _floor_grid(cell, stature)
    r0 = cell.start_region
    in_start = (np.all(free_xy >= np.asarray(r0.lo[:2]) - 1e-9, axis=-1)
                & np.all(free_xy <= np.asarray(r0.hi[:2]) + 1e-9, axis=-1))
    if not in_start.any() and len(free_xy):      # a start patch smaller than a cell
        d = np.hypot(*(free_xy - np.asarray(r0.center[:2])).T)
        in_start = d <= max(FLOOR_RESOLUTION, float(d.min()))
    connected = np.isin(free_labels, np.unique(free_labels[in_start]))
    return _FLOOR_CACHE.put(key, FloorMap(grid, free_xy, connected, bool(in_start.any()), tree))


# ------------------------------------------------------------------------ targets
def _box_xy_distance(xy: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Floor-plane distance from points (N, 2) to the box footprint [lo, hi] (2,), (N,)."""
    d = np.maximum(np.maximum(lo - xy, 0.0), np.maximum(xy - hi, 0.0))
    return np.hypot(d[:, 0], d[:, 1])


def _support(cell, lo: np.ndarray, hi: np.ndarray) -> str:
    """`` on top of the <obstacle>`` when an obstacle's top is just below the box."""
    for ob in cell.obstacles:
        for part in ob.parts:
            plo, phi = part.aabb()
            if (-1e-6 <= lo[2] - phi[2] <= 0.06 and np.all(plo[:2] <= hi[:2])
                    and np.all(phi[:2] >= lo[:2])):
                return f" on top of the {ob.name}"
    return ""


def _min_width(shape) -> float | None:
    """Smallest width of a primitive shape (None for meshes: not bounded here)."""
    from ltl_human_motion.scene.shapes import Box, Cylinder, Sphere
    if isinstance(shape, Box):
        return float(np.min(shape.extents))
    if isinstance(shape, Cylinder):
        return float(min(2 * shape.radius, shape.height))
    if isinstance(shape, Sphere):
        return 2.0 * float(shape.radius)
    return None


def _volume(shape) -> float | None:
    from ltl_human_motion.scene.shapes import Box, Cylinder, Sphere
    if isinstance(shape, Box):
        return float(np.prod(shape.extents))
    if isinstance(shape, Cylinder):
        return float(math.pi * shape.radius ** 2 * shape.height)
    if isinstance(shape, Sphere):
        return float(4.0 / 3.0 * math.pi * shape.radius ** 3)
    return None


def _inside_obstacles(cell, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether a 5x5x5 lattice of the box [lo, hi] lies entirely inside obstacles."""
    if not cell.obstacles:
        return False
    axes = [np.linspace(lo[i], hi[i], 5) for i in range(3)]
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    inside = np.zeros(len(pts), dtype=bool)
    for ob in cell.obstacles:
        inside |= ob.contains(pts)
    return bool(inside.all())


class _Checker:
    """The checks of one cell and stature; ``problem`` returns a PlanningError or None."""

    def __init__(self, cell, stature: float) -> None:
        self.cell = cell
        self.H = float(stature)
        self.env = reach_envelope(round(self.H, 4))
        self.floor = floor_map(cell, self.H)
        self.start = cell.start_region.name

    def reach(self, task: str, what: str, lo: np.ndarray, hi: np.ndarray,
              margin: float = 0.0) -> PlanningError | None:
        """Can a palm get within ``margin`` of the box [lo, hi] (3,) from floor connected
        to the start?"""
        env, H = self.env, self.H
        floor_z = float(self.cell.floor_z)
        where = _support(self.cell, lo, hi)
        shown = f"{float(lo[2]) - floor_z:.2f}-{float(hi[2]) - floor_z:.2f} m"
        lo, hi = lo - margin, hi + margin
        zlo, zhi = float(lo[2]) - floor_z, float(hi[2]) - floor_z
        if zlo > env.vertical:
            return PlanningError(
                f"task {task}: {what} at {shown}{where} is above the reach of a {H:.2f} m "
                f"worker ({env.vertical:.2f} m)", task=task, reason="reach")
        radius = env.horizontal(zlo, zhi) + FLOOR_RESOLUTION * math.sqrt(0.5)
        fl = self.floor
        if fl.tree is None:
            idx = np.zeros(0, dtype=np.intp)
        else:                                   # cells near the box, then the exact test
            half = float(np.hypot(*(np.asarray(hi[:2]) - np.asarray(lo[:2])))) / 2
            idx = np.asarray(fl.tree.query_ball_point((np.asarray(lo[:2]) + hi[:2]) / 2,
                                                      radius + half), dtype=np.intp)
        d = _box_xy_distance(fl.free_xy[idx], np.asarray(lo[:2]), np.asarray(hi[:2]))
        near = np.zeros(len(fl.free_xy), dtype=bool)
        near[idx[d <= radius]] = True
        if np.any(near & fl.connected):
            return None
        if np.any(near):
            return PlanningError(
                f"task {task}: {what} is enclosed by obstacles: no floor within "
                f"{radius:.2f} m of it is connected to {self.start}", task=task,
                reason="enclosed")
        return PlanningError(
            f"task {task}: no floor to stand on within {radius:.2f} m of {what}"
            f"{where} (a {H:.2f} m worker's reach at that height): "
            "obstacles cover it", task=task, reason="no_floor")

    def region(self, task: str, name: str) -> PlanningError | None:
        reg = self.cell.region(name)
        lo, hi = np.asarray(reg.lo, dtype=float), np.asarray(reg.hi, dtype=float)
        if _inside_obstacles(self.cell, lo, hi):
            return PlanningError(f"task {task}: region {name} lies inside solid obstacles: "
                                 "no body part or part can get into it", task=task,
                                 reason="inside_obstacle")
        return self.reach(task, f"region {name}", lo, hi)

    def part(self, task: str, name: str) -> PlanningError | None:
        lo, hi = self.cell.object(name).shape.aabb()
        return self.reach(task, name, lo, hi, margin=GRASP_EPS)

    def fits(self, task: str, part: str, container: str, is_region: bool
             ) -> PlanningError | None:
        obj = self.cell.object(part)
        cshape = self.cell.region(container).shape if is_region \
            else self.cell.object(container).shape
        pw, cw = _min_width(obj.shape), _min_width(cshape)
        pv, cv = _volume(obj.shape), _volume(cshape)
        kind = "region" if is_region else "container"
        if pw is not None and cw is not None and pw > cw + 1e-9:
            return PlanningError(
                f"task {task}: {kind} {container} is smaller than {part} ({part}'s smallest "
                f"width {pw:.3f} m exceeds {container}'s {cw:.3f} m): {task} can never hold",
                task=task, reason="size")
        if pv is not None and cv is not None and pv > cv + 1e-12:
            return PlanningError(
                f"task {task}: {kind} {container} ({cv * 1e3:.2f} l) is smaller than {part} "
                f"({pv * 1e3:.2f} l): {task} can never hold", task=task, reason="size")
        room = _box_room(obj.shape, cshape)
        if room is not None and room.min() < FIT_CLEARANCE:
            axis = "xyz"[int(np.argmin(room))]
            return PlanningError(
                f"task {task}: {kind} {container} leaves {part} {max(room.min(), 0.0):.3f} m "
                f"of room along {axis} (at least {FIT_CLEARANCE:.3f} m, FIT_CLEARANCE; "
                f"parts only translate): {part} cannot be put in", task=task, reason="size")
        return None

    def passage(self, task: str, part: str, target: str, is_region: bool
                ) -> PlanningError | None:
        """Can ``part`` be brought from where it lies into region or container
        ``target`` at all, translating among the obstacles (:mod:`.passage`)?"""
        from ltl_human_motion.planning.passage import can_pass
        shape = self.cell.region(target).shape if is_region \
            else self.cell.object(target).shape
        lo, hi = shape.aabb()
        if can_pass(self.cell, part, np.asarray(lo), np.asarray(hi)):
            return None
        lo_p, hi_p = self.cell.object(part).shape.aabb()
        size = " x ".join(f"{v:.2f}" for v in np.asarray(hi_p) - np.asarray(lo_p))
        return PlanningError(
            f"task {task}: no way from where {part} lies into {target} is wide enough for "
            f"it ({size} m; parts only translate): {task} can never hold", task=task,
            reason="size")

    def seat(self, task: str, name: str) -> PlanningError | None:
        obj = self.cell.object(name)
        surface = obj.sitting_surface_at(obj.position)
        lo, hi = surface.aabb()
        z = float(lo[2]) - float(self.cell.floor_z)
        limit = SEAT_MAX_FRACTION * self.H
        if z > limit:
            return PlanningError(
                f"task {task}: the sitting surface of {name} at {z:.2f} m is above the "
                f"standing pelvis of a {self.H:.2f} m worker ({limit:.2f} m): nobody sits "
                "there without climbing", task=task, reason="seat_height")
        return self.reach(task, f"the seat of {name}", lo, hi)


def step_problems(cell, steps: Sequence[tuple[str, Sequence[str]]], stature: float
                  ) -> list[PlanningError]:
    """Every infeasibility found in a task sequence, in step order.

    Parameters
    ----------
    cell : Cell
    steps : sequence of (task name, args)
        Table I tasks or shorthand instances, e.g. ``("carry", ("O1", "R1"))``.
    stature : float
        Body height, metres.
    """
    key = (*_layout_key(cell, stature), tuple((n, tuple(a)) for n, a in steps))
    hit = _ANSWER_CACHE.get(key)
    if hit is not None:
        return list(hit)
    return list(_ANSWER_CACHE.put(key, _problems(cell, steps, stature)))


def _problems(cell, steps: Sequence[tuple[str, Sequence[str]]], stature: float
              ) -> list[PlanningError]:
    from ltl_human_motion.scene.termination import expand_task
    check = _Checker(cell, stature)
    out: list[PlanningError] = []
    touched: set[str] = set()
    if not check.floor.start_found:
        out.append(PlanningError(f"start region {check.start}: no free floor to stand on",
                                 task=None, reason="no_floor"))
        return out
    for name, args in steps:
        text = f"{name}({', '.join(args)})" if args else name
        try:
            conjuncts = expand_task(name, tuple(args), cell)
        except ValueError:
            continue                      # not a task this analysis knows: planner's call
        for task, a in conjuncts:
            found: list[PlanningError | None] = []
            if task in ("grasp", "release", "carry", "move", "insert", "extract") \
                    and a[0] not in touched:
                # The part is touched where it lies (carry/move/insert/release fetch it).
                touched.add(a[0])
                found.append(check.part(text, a[0]))
            if task in ("carry", "move"):
                found.append(check.fits(text, a[0], a[1], is_region=True))
                found.append(check.region(text, a[1]))
                found.append(check.passage(text, a[0], a[1], is_region=True))
            elif task == "insert":
                found.append(check.fits(text, a[0], a[1], is_region=False))
                found.append(check.part(text, a[1]))
                found.append(check.passage(text, a[0], a[1], is_region=False))
            elif task in ("walk", "leftHand", "rightHand"):
                found.append(check.region(text, a[0]))
            elif task == "sit":
                found.append(check.seat(text, a[0]))
            for p in found:
                if p is not None and all(str(p) != str(q) for q in out):
                    out.append(p)
    return out


def check_steps(cell, steps: Sequence[tuple[str, Sequence[str]]], stature: float) -> None:
    """Raise the first :func:`step_problems` problem as a PlanningError, if any."""
    problems = step_problems(cell, steps, stature)
    if problems:
        first = problems[0]
        raise PlanningError(str(first), task=first.task, reason=first.reason)


def _box_room(part: object, container: object) -> np.ndarray | None:
    """Spare length (3,) of box ``container`` over box ``part`` along the container's axes,
    for parts that only translate (their yaws equal, or a quarter turn apart); None for
    other shapes or yaws."""
    from ltl_human_motion.scene.shapes import Box
    if not (isinstance(part, Box) and isinstance(container, Box)):
        return None
    turn = (part.yaw - container.yaw) / (math.pi / 2)
    if abs(turn - round(turn)) > 1e-6:
        return None
    extents = np.asarray(part.extents, dtype=np.float64)
    if round(turn) % 2:
        extents = extents[[1, 0, 2]]
    return np.asarray(container.extents, dtype=np.float64) - extents

