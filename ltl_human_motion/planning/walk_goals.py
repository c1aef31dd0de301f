"""Walk goals: where a walk may end and the navigation field that leads there.

A walk goal (:class:`~ltl_human_motion.planning.astar.Goal`) tests floor poses of the
root and carries the heuristic's distance and heading. :class:`WalkGoals` makes them for
the three kinds of walk: into a region (the verifier's own ``enter`` predicate,
:class:`~.placement.RegionEntry`), to a reach placement for a goal task (a ring around
the target, :func:`.standing.ideal_placement`), and to any spot with some floor
clearance. Fields are solved on the walking map, or where it leaves no way through, on
the footprint map (the squeeze through a narrow aisle).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.planning.astar import Goal
from ltl_human_motion.planning.blend import wrap_angle
from ltl_human_motion.planning.navigation import (
    NARROW_COST,
    TALL_EXTRA,
    FloorGrid,
    NavigationField,
    floor_grid,
)
from ltl_human_motion.planning.placement import RegionEntry
from ltl_human_motion.planning.plan_state import PlanContext, WorkerState
from ltl_human_motion.planning.standing import ideal_placement

#: Floor clearance below which the navigation field counts the floor longer, metres:
#: about half the hip and shoulder width of a 1.75 m worker (0.2 m) plus the gait's
#: sway, more than ``PlannerOptions.body_radius`` (the least a walk needs).
PASSAGE_RADIUS = 0.25

#: Extra cost of a metre through floor with less than ``PASSAGE_RADIUS`` of clearance
#: on the walking map's field (:func:`.navigation.floor_grid`, linear down to
#: ``PlannerOptions.body_radius``, where it is 11 metres a metre): the field keeps to
#: roomy lanes wherever they lead, and still leads from and to the floor beside them.
#: It replaced a field on the lanes alone, which was infinite off them: the search,
#: which drops poses where the field is infinite, was held on the lane's one-cell edge
#: when the worker or the reach spot stood just beside a lane (a 1.95 m worker at a
#: table: 7,000 nodes, 8 s), and where a goal lay off every lane the field fell back to
#: one that counted a gap the gait does not pass only twice its length (the cluttered
#: cell: 5,600 nodes stalled in front of the gap between the crates). 10 over 30 on
#: the corpus's slowest runs; the full corpus went from 42 runs over 2 s to 34.
LANE_NARROW_COST = 10.0

#: The same on the footprint map of a squeeze (:meth:`WalkGoals.field`): half
#: the 0.8 m aisle of the corpus, whose walls the walking map counts ``TALL_EXTRA``
#: closer; the field leads along the middle of such a gap.
SQUEEZE_PASSAGE = PASSAGE_RADIUS + TALL_EXTRA

#: Radius of the floor blocked around a stalled search's closest approach when its goal
#: reroutes, metres (:data:`.steps.STALL_NODES` says when a search stalls).
STALL_BLOCK_RADIUS = 0.3

#: Radii and directions sampled on the ring of standing spots within the reach tolerance
#: (:meth:`WalkGoals.reach`) to tell whether any of them has a free spot for the goal
#: test: 8 radii over the 0.3 m band (4 cm apart, half the 0.08 m search grid) and
#: 72 directions (5 degrees, 2-3 cm apart at the 0.25-0.4 m ring).
RING_SAMPLES = (8, 72)

#: ``turn_clear(x, y, yaw, to_yaw) -> bool`` (all (M,)): whether the standing body turned
#: on the spot at (x, y) from ``yaw`` to ``to_yaw`` keeps clear
#: (:meth:`.steps.StepExecutor.turn_clear`).
TurnClear = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]

#: Navigation fields by floor grid and goal (see :meth:`WalkGoals.field`).
_FIELD_CACHE: BoundedCache[NavigationField] = BoundedCache(16)


def _in_sector(x: np.ndarray, y: np.ndarray, target: tuple[float, float],
               sector: tuple[float, float] | None) -> np.ndarray:
    """Whether floor points (x, y) lie within ``sector`` (direction from ``target``, half
    width, rad) of the target (all of them without a sector); bool, shaped like x."""
    if sector is None:
        return np.ones(np.shape(x), dtype=bool)
    tx, ty = target
    return np.abs(wrap_angle(np.arctan2(y - ty, x - tx) - sector[0])) <= sector[1]


def _ring_stands(ctx: PlanContext, target: np.ndarray, placement: tuple[float, float],
                 side: Callable[[np.ndarray, np.ndarray], np.ndarray],
                 stand_yaw: float | None) -> bool:
    """Whether any spot (sampled, ``RING_SAMPLES``) of the ring of :meth:`WalkGoals.reach`
    within the reach tolerance, on its ``side`` and with floor room, has a free standing
    spot for the goal test (:func:`.standing.ideal_placement`, ``target`` (3,) at
    ``placement`` (ahead, left)). Beside a bench at a wall every spot the tolerance allows
    lies in the bench's room (further back and turned by the lateral offset): no walk
    passed the goal test and the search gave up at the bench, where ``max_step_back``
    finds a spot."""
    tol = ctx.options.reach_tolerance
    dist = float(np.hypot(*placement))
    r = np.linspace(max(dist - tol, 0.0), dist + tol, RING_SAMPLES[0])
    a = np.linspace(-np.pi, np.pi, RING_SAMPLES[1], endpoint=False)
    x = (float(target[0]) + np.outer(r, np.cos(a))).ravel()
    y = (float(target[1]) + np.outer(r, np.sin(a))).ravel()
    on = side(x, y) & (ctx.stand_map(np.stack([x, y], axis=-1)) > ctx.stand_room)
    return bool(on.any()) and bool(ideal_placement(ctx, target, placement, x[on], y[on], tol,
                                                   stand_yaw=stand_yaw)[3].any())


#: Largest spacing, metres, of the grid on which a reach goal tells whether any floor
#: point passes its test (:attr:`.astar.Goal.possible`).
POSSIBLE_SPACING = 0.04
#: Points of that grid tested at a time (the test stops at the first chunk that passes).
POSSIBLE_CHUNK = 256

#: Metres the band of :func:`_spot_band` is widened by (rounding only).
_BAND_SLACK = 1e-6


def _spot_band(placement: tuple[float, float], back: float, adjust: float
               ) -> tuple[float, float]:
    """The distances from the target within which a root may pass a reach goal: every
    spot :func:`.standing.ideal_placement` picks lies ``hypot(d + b, lat)`` from the
    target for a ``b`` in [0, ``back``] (``placement`` = (d, lat)), and the goal needs
    the root within ``adjust`` of it. A prefilter: the goal test of the search's many
    far poses is skipped."""
    d, lat = float(placement[0]), float(placement[1])
    lo_b, hi_b = min(0.0, back), max(0.0, back)
    nearest = min(max(-d, lo_b), hi_b)
    inner = math.hypot(d + nearest, lat)
    outer = max(math.hypot(d + lo_b, lat), math.hypot(d + hi_b, lat))
    return inner - adjust - _BAND_SLACK, outer + adjust + _BAND_SLACK


def _stands_to_reach(ctx: PlanContext, target: np.ndarray, placement: tuple[float, float],
                     back: float, adjust: float,
                     side: Callable[[np.ndarray, np.ndarray], np.ndarray],
                     walk_map: Callable[[np.ndarray], np.ndarray], stand_yaw: float | None,
                     inner: float, turn_clear: TurnClear | None, x: np.ndarray,
                     y: np.ndarray, yaw: np.ndarray | None) -> np.ndarray:
    """The goal test of :meth:`WalkGoals.reach` for root poses (x, y, yaw) (M,) in its
    band: the ideal spot (:func:`.standing.ideal_placement`, up to ``back`` further back;
    room on ``walk_map``) is free, within ``adjust`` and on ``side``, and the worker
    faces its way or has room to turn there: ``turn_room`` of floor, or where there is
    less, the body turned on the spot keeps clear (``turn_clear``); any heading where
    ``yaw`` is None. With ``stand_yaw``, the root at least ``inner`` from the target.
    Bool (M,)."""
    px, py, pyaw, free, here = ideal_placement(ctx, target, placement, x, y, back, room=True,
                                               walk_map=walk_map, stand_yaw=stand_yaw)
    out = free & (np.hypot(px - x, py - y) <= adjust) & side(x, y)
    if yaw is not None:
        # Turning on the spot needs room for the hips; facing nearly right needs none.
        turn = (here <= ctx.turn_room) \
            & (np.abs(wrap_angle(pyaw - yaw)) > ctx.options.heading_tolerance)
        if turn_clear is not None and (out & turn).any():
            k = np.flatnonzero(out & turn)
            turn[k] = ~turn_clear(x[k], y[k], yaw[k], pyaw[k])
        out &= ~turn
    if stand_yaw is not None:
        # The spot is fixed: a walk must still end on the ring, not nearer (under the
        # board the standing step would have to back out of).
        out &= np.hypot(target[0] - x, target[1] - y) >= inner
    return out


def _band_points(target: np.ndarray, band: tuple[float, float],
                 sector: tuple[float, float] | None, step: float, toward: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Floor points (x, y), each (N,), of the ring ``band`` (metres from ``target``) within
    ``sector`` (all round without one) on a polar grid no coarser than ``step`` (a disc
    of radius ``step / 0.7`` in it holds one), those nearest the direction ``toward``
    (rad, from the target) first."""
    r = np.arange(max(band[0], 0.0), band[1] + step, step)
    da = step / max(band[1], step)
    a = np.arange(-np.pi, np.pi, da) if sector is None \
        else sector[0] + np.arange(-sector[1], sector[1] + 1e-9, da)
    a = a[np.argsort(np.abs(wrap_angle(a - toward)), kind="stable")]
    return ((float(target[0]) + np.outer(np.cos(a), r)).ravel(),
            (float(target[1]) + np.outer(np.sin(a), r)).ravel())


def _towards(led: NavigationField, target: tuple[float, float], near: float, offset: float
             ) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """The heuristic's heading for a reach: the field's way, and within ``near`` of the
    target, straight at it less ``offset`` (the target is off the root's axis)."""
    tx, ty = target

    def towards(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        close = np.hypot(tx - x, ty - y) <= near
        return np.where(close, np.arctan2(ty - y, tx - x) - offset, led.heading(x, y))
    return towards


def walk_grid(ctx: PlanContext, squeeze: bool = False) -> FloorGrid:
    """The floor grid the walk fields of :meth:`WalkGoals.field` are solved on: free
    cells keep ``body_radius`` of clearance on the walking map, floor with less than
    ``PASSAGE_RADIUS`` counting up to ``1 + LANE_NARROW_COST`` metres a metre; with
    ``squeeze``, on the footprint map (``stand_map``, ``SQUEEZE_PASSAGE``,
    ``NARROW_COST``). Shared by every field on that floor (:func:`.navigation.floor_grid`)."""
    clearance = ctx.stand_map if squeeze else ctx.clearance
    radius = ctx.options.body_radius
    passage = SQUEEZE_PASSAGE if squeeze else PASSAGE_RADIUS
    return floor_grid(clearance, ctx.cell.workspace_lo[:2], ctx.cell.workspace_hi[:2],
                      radius, ctx.options.grid_resolution,
                      passage=passage if radius < passage else None,
                      narrow_cost=NARROW_COST if squeeze else LANE_NARROW_COST)


class WalkGoals:
    """Makes the walk goals of one plan.

    Parameters
    ----------
    ctx : PlanContext
    state : WorkerState
        Read for where the worker stands now and whether it carries a part.
    turn_clear : TurnClear, optional
        Whether the body turns on the spot clear where the floor has less than
        ``turn_room`` (without it, such spots end a walk only facing the goal's way).
    """

    def __init__(self, ctx: PlanContext, state: WorkerState,
                 turn_clear: TurnClear | None = None) -> None:
        self.ctx = ctx
        self.state = state
        self.turn_clear = turn_clear

    def field(self, goal_cells, key: tuple | None = None, squeeze: bool = False
              ) -> NavigationField:
        """The navigation field of ``goal_cells`` on the floor grid. ``goal_cells(xy (N, 2),
        clearance) -> bool (N,)`` gets the clearance map of the grid it is solved on.
        ``key``: numbers that determine the goal cells on this floor; fields with a key
        are kept (a target that does not move between items, e.g. an assembly region,
        reuses its field).

        The field counts a metre of floor with less than ``PASSAGE_RADIUS`` of clearance
        up to ``1 + LANE_NARROW_COST`` metres, so it keeps to roomy lanes where they lead
        and does not send the search through a gap the body barely fits (to exhaust its
        budget there) where a roomier way exists, yet it leads from any floor the walk
        may take. With ``squeeze`` (where the walking map leaves no way at all: a
        narrow aisle between racks, see :meth:`led`) the field is solved on the
        footprint map (:attr:`stand_map`, no allowance for the arms at tall parts),
        whose walks the search keeps clear with the whole-body check. The walk keeps its
        clearance on ``field.grid.clearance``."""
        grid = walk_grid(self.ctx, squeeze)
        cells = functools.partial(goal_cells, clearance=grid.clearance)
        if key is None:
            return NavigationField.on_grid(grid, cells)
        return _FIELD_CACHE.get_or_build(tuple(key), lambda: NavigationField.on_grid(grid, cells),
                                         owner=grid)

    def leads(self, field: NavigationField) -> bool:
        """Whether ``field`` leads from the worker's spot to a goal cell."""
        return field.has_goal and field.reachable_from(*self.state.pose[:2])

    def led(self, solve: Callable[[bool], tuple]) -> tuple:
        """``solve(False)`` (a field on the walking map, and what made it), or where that
        field leads nowhere and ``solve(True)``'s (the squeeze, see :meth:`field`) does,
        the latter."""
        plain = solve(False)
        if self.leads(plain[0]):
            return plain
        squeezed = solve(True)
        return squeezed if self.leads(squeezed[0]) else plain

    def from_field(self, field: NavigationField, reached, desc: str, task: str,
                   heading: Callable[[NavigationField], Callable] | None = None
                   ) -> Goal:
        """The walk's :class:`Goal` led by ``field``; ``heading(field)``: the heuristic's
        direction (default the field's). A search that stalls (in front of a gap the body
        does not pass) may reroute: the same goal on the field with the floor around the
        stall blocked (``STALL_BLOCK_RADIUS``), while it still leads to the goal."""
        if not field.has_goal:
            raise PlanningError(f"task {task}: {desc}: every place to stand there is blocked "
                                "by obstacles; the region is unreachable", task=task,
                                reason="unreachable")
        if not field.reachable_from(*self.state.pose[:2]):
            raise PlanningError(f"task {task}: {desc}: obstacles block every way from "
                                f"({self.state.pose[0]:.2f}, {self.state.pose[1]:.2f})", task=task,
                                reason="blocked")
        slack = 0.5 * self.ctx.options.grid_resolution

        def distance(x: np.ndarray, y: np.ndarray) -> np.ndarray:
            return np.maximum(field.distance(x, y) - slack, 0.0)

        def reroute(at: tuple[float, float]) -> Goal | None:
            around = field.without(at, STALL_BLOCK_RADIUS)
            if not (around.has_goal and around.reachable_from(*self.state.pose[:2])):
                return None
            return self.from_field(around, reached, desc, task, heading)

        return Goal(reached, distance, field.heading if heading is None else heading(field),
                    desc, clearance=field.grid.clearance, stop_clearance=self.stop_floor,
                    reroute=reroute)

    def stop_floor(self, xy: np.ndarray) -> np.ndarray:
        """The floor map a walk's last step into a stop keeps ``body_radius`` on where the
        walking map leaves it none (:attr:`.astar.Goal.stop_clearance`): the footprint
        map less the room a standing body needs beyond that radius (``stand_room``, as
        for a goal primitive's spot), so that the legs stop clear of the furniture.
        ``xy`` (M, 2); (M,)."""
        return self.ctx.stand_map(xy) - (self.ctx.stand_room - self.ctx.options.body_radius)

    def reach(self, target: np.ndarray, placement: tuple[float, float], desc: str,
              task: str, adjust: float | None = None,
              sector: tuple[float, float] | None = None,
              stand_yaw: float | None = None) -> tuple[Goal, float]:
        """Walk until a standing adjustment (a step of at most ``adjust``, default
        ``options.adjust_radius``, and a turn) puts the worker where the goal primitive
        reaches ``target`` (3,) from ``placement`` (:func:`.standing.standing_offset`);
        with ``sector`` (direction from the target, half width, rad) only from that side;
        with ``stand_yaw`` (rad), standing facing that way (:func:`.standing.ideal_placement`).

        Returns the goal and how much further back than the ideal spot it lets the worker
        stand (the reach tolerance, or ``max_step_back`` where an obstacle leaves no
        closer place); :meth:`.steps.StepExecutor.adjust_to` takes the same."""
        tx, ty = float(target[0]), float(target[1])
        side = functools.partial(_in_sector, target=(tx, ty), sector=sector)
        tol = self.ctx.options.reach_tolerance
        dist = float(np.hypot(*placement))
        offset = float(np.arctan2(placement[1], placement[0]))
        adjust = self.ctx.options.adjust_radius if adjust is None else float(adjust)

        def ring(xy: np.ndarray, clearance=None) -> np.ndarray:
            r = np.hypot(tx - xy[:, 0], ty - xy[:, 1])
            out = (r >= dist - tol) & (r <= dist + limit[0]) & side(xy[:, 0], xy[:, 1])
            # The floor clearance only where the distance fits (few of the cells).
            out[out] = self.ctx.stand_map(xy[out]) > self.ctx.stand_room
            return out

        def near_ring(xy: np.ndarray, clearance=None) -> np.ndarray:
            # Where a walk may end to step in (a rack: the walking map keeps tall
            # parts further off than a worker standing at them needs).
            r = np.hypot(tx - xy[:, 0], ty - xy[:, 1])
            return ((r >= dist - tol) & (r <= dist + limit[0] + adjust)
                    & side(xy[:, 0], xy[:, 1]))

        # Stand within the reach tolerance where possible; only where an obstacle leaves
        # no such place (a tall worker at a bench) stand up to max_step_back further.
        def ring_key() -> tuple:
            return ("ring", tx, ty, dist, tol, float(limit[0]),
                    self.ctx.stand_room, sector)

        limit = [tol]                    # how much further back than ideal, per field

        def solve(squeeze: bool) -> tuple[NavigationField, float]:
            limit[0] = tol
            field = self.field(ring, ring_key(), squeeze)
            if not field.has_goal or not _ring_stands(self.ctx, target, placement, side,
                                                      stand_yaw):
                limit[0] = self.ctx.options.max_step_back
                field = self.field(ring, ring_key(), squeeze)
            if not field.has_goal:
                field = self.field(near_ring, ("near", *ring_key(), adjust), squeeze)
            return field, limit[0]

        field, back = self.led(solve)
        band = _spot_band(placement, back, adjust)

        reached_in_band = functools.partial(
            _stands_to_reach, self.ctx, target, placement, back, adjust, side,
            field.grid.clearance, stand_yaw, dist - tol, self.turn_clear)

        def reached(x: np.ndarray, y: np.ndarray, yaw: np.ndarray) -> np.ndarray:
            r = np.hypot(tx - x, ty - y)
            out = (r >= band[0]) & (r <= band[1])
            if out.any():
                out[out] = reached_in_band(x[out], y[out], yaw[out])
            return out

        def possible() -> bool:
            # facing the way each spot does, as a walk may arrive; the side the worker
            # comes from first, in chunks (most goals pass in the first)
            toward = math.atan2(self.state.pose[1] - ty, self.state.pose[0] - tx)
            x, y = _band_points(target, band, sector, min(POSSIBLE_SPACING, 0.7 * adjust),
                                toward)
            return any(reached_in_band(x[k:k + POSSIBLE_CHUNK], y[k:k + POSSIBLE_CHUNK],
                                       None).any() for k in range(0, len(x), POSSIBLE_CHUNK))

        heading = functools.partial(_towards, target=(tx, ty), near=dist + 2 * tol,
                                    offset=offset)
        return replace(self.from_field(field, reached, desc, task, heading),
                       possible=possible), back

    def region(self, region, desc: str, task: str) -> Goal:
        """Walk until the standing body enters ``region`` (the verifier's predicate).

        The goal cells of the heuristic are the spots with room to turn
        (``turn_clearance``) from which the standing body enters the region facing some
        heading; none (a region above a bench, beside a wall) makes the region
        unreachable on foot (the caller reaches into it by hand).
        """
        from ltl_human_motion.motion.capsules import capsule_radii
        stature = self.ctx.stature
        carrying = self.state.carrying
        entry = RegionEntry(region, self.ctx.stance(carrying), self.ctx.library.standing_height,
                            stature, float(capsule_radii(stature).max()))
        room = self.ctx.turn_room

        def cells(xy: np.ndarray, clearance: Callable[[np.ndarray], np.ndarray]
                  ) -> np.ndarray:
            out = entry.cells(xy)
            out[out] = clearance(xy[out]) > room
            return out

        key = ("region", *entry.lo.tolist(), *entry.hi.tolist(), stature, carrying, room)
        field, = self.led(lambda squeeze: (self.field(cells, key, squeeze),))
        return self.from_field(field, entry.enters, desc, task)
