"""A* over the gait primitives of the motion automaton (Sec. III-B of the paper).

Nodes are gait primitives placed on the floor. Cost is time; the heuristic is
``dist(occ, R) / v`` with a relaxed (lower than maximal) speed ``v``, so the search is
greedy but fast, as the paper found. The closed set is a grid over (x, y, heading), so
near-identical placements are expanded once (whichever primitive led there first).
"""

from __future__ import annotations

import heapq
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ltl_human_motion.deadline import checkpoint
from ltl_human_motion.planning.gait_index import GaitIndex
from ltl_human_motion.planning.navigation import ClearanceMap

Pose = tuple[float, float, float]

#: How much nearer the goal (metres of the heuristic's distance) the closest approach
#: must come to count as progress for ``stall_nodes``.
STALL_PROGRESS = 0.05
#: A search stuck closer than this to the goal (metres of the heuristic's distance) does
#: not stall: it is finding a way to stand there, not a way around an obstacle.
STALL_FAR = 0.5
#: Nodes the final adjusting walk to a reach's spot (a goal a few centimetres wide) may
#: expand after it first reached the goal's floor cells (heuristic distance 0) without
#: ending: there it only looks for a place to stop that the goal and the body tests
#: accept. Next to a table edge no stop may fit (a 1.95 m worker's 5 cm final adjustment
#: used all 8000 nodes of its budget for nothing); then the other placements are tried.
#: Only that walk ends early: an approach walk that needs more nodes at its goal still
#: finds its stop (an S2 study item needed over 4000).
AT_GOAL_NODES = 4000


@dataclass(frozen=True)
class SearchOptions:
    """The settings of every gait search (one home for their defaults; the planner's
    :class:`~ltl_human_motion.planning.planner.PlannerOptions` builds one).

    Attributes
    ----------
    body_radius : float
        Clearance the walking root keeps from obstacle footprints, metres.
    heuristic_speed : float
        Relaxed walking speed of the heuristic, m/s (paper Sec. III-B): below the gait's
        speed, so the search stays greedy but fast.
    turn_rate : float
        Relaxed turning speed of the heuristic's heading term, rad/s.
    cost_noise : float
        Seeded relative noise on primitive costs: different seeds, different paths.
    near_radius : float
        Primitives whose root path comes this close to an obstacle get the whole-body
        test, metres.
    grid : float
        Closed-set lattice in x and y, metres.
    yaw_bins : int
        Closed-set heading bins.
    """

    body_radius: float = 0.15
    heuristic_speed: float = 0.25
    turn_rate: float = 0.8
    cost_noise: float = 0.15
    near_radius: float = 0.6
    grid: float = 0.08
    yaw_bins: int = 24


@dataclass(frozen=True)
class SearchBudget:
    """Limits of one search: expanded nodes, and optionally wall-clock seconds; and the
    nodes expanded after the search first reached the goal's floor cells
    (``at_goal_nodes``, None: no limit), beyond which it ends as ``"no_stop"``; and
    the nodes expanded without coming ``STALL_PROGRESS`` nearer the goal
    (``idle_nodes``, None: no limit), beyond which it ends as ``"budget"``.

    Only the node limit is on by default, so a result never depends on the machine's
    load (the same inputs give the same motion or the same error).
    """

    max_nodes: int = 8000
    max_seconds: float | None = None
    at_goal_nodes: int | None = None
    idle_nodes: int | None = None

    def within(self, limit: SearchBudget) -> SearchBudget:
        """This budget with its node and time limits no larger than ``limit``'s (a
        search the planner sizes itself, an alternative's walk, keeps to the plan's
        budget)."""
        seconds = self.max_seconds if limit.max_seconds is None else (
            limit.max_seconds if self.max_seconds is None
            else min(self.max_seconds, limit.max_seconds))
        return replace(self, max_nodes=min(self.max_nodes, limit.max_nodes),
                       max_seconds=seconds)


@dataclass
class Goal:
    """What ends a walk, as vectorized tests on root floor poses.

    Attributes
    ----------
    reached : callable
        ``reached(x (M,), y (M,), yaw (M,)) -> bool (M,)``.
    distance : callable
        ``distance(x (M,), y (M,)) -> (M,)``: metres left to walk (0 at the goal), used
        by the heuristic.
    heading : callable or None
        ``heading(x (M,), y (M,)) -> (M,)``: direction the walk should head; the
        heuristic adds the time to turn towards it.
    description : str
    clearance : callable or None
        ``clearance(xy (M, 2)) -> (M,)``: the floor clearance map the walk to this goal
        keeps ``body_radius`` on, when not the caller's default (a squeeze through a
        narrow aisle keeps it on the obstacles' footprints).
    stop_clearance : callable or None
        Where no step into a stop keeps ``body_radius`` on ``clearance``, the floor map
        it may keep it on instead: the footprint map where the search checks the whole
        body, as the body stands still there with its arms at its sides (the walking
        map, widened for swinging arms at shelves, held stops in a 0.83 m aisle to its
        middle line, and the search spent its budget there).
    reroute : callable or None
        ``reroute((x, y)) -> Goal | None``: the same goal with a heuristic that avoids the
        floor around (x, y), where a search stalled (None: no other way).
    possible : callable or None
        ``possible() -> bool``: False where no floor pose at all passes ``reached`` (a
        test on a grid fine enough not to miss the goal's spots), so no search can end
        there; None where the goal does not say.
    """

    reached: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    distance: Callable[[np.ndarray, np.ndarray], np.ndarray]
    heading: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None
    description: str = ""
    clearance: Callable[[np.ndarray], np.ndarray] | None = None
    stop_clearance: Callable[[np.ndarray], np.ndarray] | None = None
    reroute: Callable[[tuple[float, float]], Goal | None] | None = None
    possible: Callable[[], bool] | None = None


@dataclass
class SearchResult:
    """Outcome of one A* search.

    Attributes
    ----------
    primitives : list of int
        Gait primitive indices from the start to the goal (empty if already there).
    poses : list of (x, y, yaw)
        Floor pose at which each primitive starts.
    end_pose : (x, y, yaw)
        Pose after the last primitive's hand-over frame.
    expanded : int
    seconds : float
    """

    primitives: list[int]
    poses: list[Pose]
    end_pose: Pose
    expanded: int
    seconds: float


@dataclass
class SearchFailure:
    """Why a search ended without reaching the goal: ``"blocked"``, ``"budget"``,
    ``"stalled"`` (no progress for ``stall_nodes``) or ``"no_stop"`` (at the goal's
    floor cells for ``SearchBudget.at_goal_nodes`` without a place to stop there that
    the goal and body tests accept); ``closest_at``: the floor point (x, y) of the
    closest approach."""

    reason: str
    expanded: int
    seconds: float
    closest: float = field(default=float("inf"))
    closest_at: tuple[float, float] | None = None


def placement_key(x: float, y: float, yaw: float, grid: float = 0.08, yaw_bins: int = 24
                  ) -> tuple[int, int, int]:
    """The closed-set cell of a floor pose: (x, y) on a ``grid`` m lattice, the heading in
    ``yaw_bins`` bins."""
    return (round(x / grid), round(y / grid),
            round(yaw * yaw_bins / (2.0 * np.pi)) % yaw_bins)


def _place(index: GaitIndex, ids: np.ndarray, x: float | np.ndarray, y: float | np.ndarray,
           yaw: float | np.ndarray) -> np.ndarray:
    """End poses of primitives ``ids`` (M,) started at (x, y, yaw) (each a float, or (M,)
    per primitive), shape (M, 3)."""
    c, s = np.cos(yaw), np.sin(yaw)
    d = index.disp[ids]
    return np.stack([x + c * d[:, 0] - s * d[:, 1], y + s * d[:, 0] + c * d[:, 1],
                     yaw + d[:, 2]], axis=-1)


def _path_points(index: GaitIndex, ids: np.ndarray, x: float | np.ndarray,
                 y: float | np.ndarray, yaw: float | np.ndarray) -> np.ndarray:
    """World floor points of the root paths of primitives ``ids`` (M,) started at
    (x, y, yaw) (each a float, or (M, 1) per primitive), shape (M, S, 2)."""
    c, s = np.cos(yaw), np.sin(yaw)
    p = index.path[ids]                                    # (M, S, 2)
    wx = x + c * p[..., 0] - s * p[..., 1]
    wy = y + s * p[..., 0] + c * p[..., 1]
    return np.stack([wx, wy], axis=-1)


def _path_clearance(index: GaitIndex, ids: np.ndarray, x: float, y: float, yaw: float,
                    clearance: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Smallest obstacle clearance along the root path of primitives ``ids``, shape (M,)."""
    pts = _path_points(index, ids, x, y, yaw)
    return clearance(pts.reshape(-1, 2)).reshape(pts.shape[:2]).min(axis=1)


def _clear_successors(index: GaitIndex, prim: int, pose: Pose, allowed: np.ndarray,
                      clearance: Callable[[np.ndarray], np.ndarray],
                      body_clear: Callable[[np.ndarray, np.ndarray], np.ndarray] | None,
                      forbidden: frozenset[tuple[int, int, int, int]],
                      options: SearchOptions) -> tuple[np.ndarray, np.ndarray] | None:
    """The primitives that may follow ``prim`` (-1: standing) at ``pose`` and keep clear:
    their ids (M,) and end poses (M, 3), or None."""
    px, py, pyaw = pose
    succ = index.starts if prim < 0 else index.successors(prim)
    succ = succ[allowed[succ]]
    if forbidden:
        here = placement_key(px, py, pyaw, options.grid, options.yaw_bins)
        succ = succ[[(int(p), *here) not in forbidden for p in succ.tolist()]]
    if succ.size == 0:
        return None
    placed = (clearance.placed_paths(index.disp, index.path, succ, pose)
              if isinstance(clearance, ClearanceMap) else None)
    if placed is None:
        ends = _place(index, succ, px, py, pyaw)
        gap = _path_clearance(index, succ, px, py, pyaw, clearance)
    else:
        ends, gap = placed
    clear = gap > options.body_radius
    if not np.count_nonzero(clear):
        return None
    succ, ends, gap = succ[clear], ends[clear], gap[clear]
    if body_clear is not None and index.body.size:
        exact = index.standing[succ] | (gap < options.near_radius)
        if np.count_nonzero(exact):
            ok = np.ones(len(succ), dtype=bool)
            ok[exact] = body_clear(_body_at(index, succ[exact], px, py, pyaw),
                                   index.standing[succ[exact]])
            if not np.count_nonzero(ok):
                return None
            succ, ends = succ[ok], ends[ok]
    return succ, ends


def _arrivals(index: GaitIndex, succ: np.ndarray, ends: np.ndarray, goal: Goal,
              allowed: np.ndarray, clearance: Callable[[np.ndarray], np.ndarray],
              body_clear: Callable[[np.ndarray, np.ndarray], np.ndarray] | None,
              forbidden: frozenset[tuple[int, int, int, int]], options: SearchOptions
              ) -> tuple[np.ndarray, list[tuple[int, Pose]]]:
    """Which successors (M,) end the search: a stop primitive in the goal, or a walking
    one in the goal that a stop primitive can finish (the first such, keeping
    ``body_radius`` on ``clearance``, else on ``goal.stop_clearance``; its end pose in
    ``ends`` becomes the stop's, and the stop is returned as the tail to append)."""
    near = goal.reached(ends[:, 0], ends[:, 1], ends[:, 2])
    done = near & index.stops[succ]
    tail: list[tuple[int, Pose]] = []
    if not np.count_nonzero(done) and np.count_nonzero(near):
        at = np.flatnonzero(near)
        found = _first_stop(index, succ, ends, at, goal, allowed, clearance, body_clear,
                            forbidden, options)
        if found is None and goal.stop_clearance is not None:
            found = _first_stop(index, succ, ends, at, goal, allowed, goal.stop_clearance,
                                body_clear, forbidden, options)
        if found is not None:
            m, stop, end = found
            tail = [(stop, (float(ends[m, 0]), float(ends[m, 1]), float(ends[m, 2])))]
            done[m] = True
            ends[m] = end
    return done, tail


def _placed_from(index: GaitIndex, ids: np.ndarray, at: np.ndarray,
                 clearance: Callable[[np.ndarray], np.ndarray]
                 ) -> tuple[np.ndarray, np.ndarray]:
    """End poses (M, 3) of primitives ``ids`` (M,) started at ``at`` (M, 3) and the least
    ``clearance`` along their root paths (M,); in one compiled call on a
    :class:`ClearanceMap` where the compiled kernel is in use (the same numbers)."""
    placed = (clearance.placed_paths_from(index.disp, index.path, ids, at)
              if isinstance(clearance, ClearanceMap) else None)
    if placed is not None:
        return placed
    ends = _place(index, ids, at[:, 0], at[:, 1], at[:, 2])
    path = _path_points(index, ids, at[:, 0, None], at[:, 1, None], at[:, 2, None])
    return ends, clearance(path.reshape(-1, 2)).reshape(path.shape[:2]).min(axis=1)


def _first_stop(index: GaitIndex, succ: np.ndarray, ends: np.ndarray, near: np.ndarray,
                goal: Goal, allowed: np.ndarray,
                clearance: Callable[[np.ndarray], np.ndarray],
                body_clear: Callable[[np.ndarray, np.ndarray], np.ndarray] | None,
                forbidden: frozenset[tuple[int, int, int, int]], options: SearchOptions
                ) -> tuple[int, int, np.ndarray] | None:
    """The first successor ``m`` of ``near`` (indices into ``succ`` (M,) and ``ends``
    (M, 3), in order) after which a stop primitive may follow, is not ``forbidden``
    there, keeps clear and ends in the goal, with the first such stop: (m, the stop, its
    end pose (3,)); None if there is none. The floor, goal and body tests of all the
    candidates left run in one call each."""
    prims = succ[near]
    first = index.indptr[prims]
    counts = index.indptr[prims + 1] - first
    total = int(counts.sum())
    if total == 0:
        return None
    offsets = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    cand = index.indices[np.repeat(first, counts) + offsets]
    owner = np.repeat(near, counts)
    keep = index.stops[cand] & allowed[cand]
    if forbidden and np.count_nonzero(keep):
        for k in np.flatnonzero(keep).tolist():
            at = ends[owner[k]]
            there = placement_key(float(at[0]), float(at[1]), float(at[2]), options.grid,
                                  options.yaw_bins)
            keep[k] = (int(cand[k]), *there) not in forbidden
    if not np.count_nonzero(keep):
        return None
    owner, cand = owner[keep], cand[keep]
    cand_ends, gap = _placed_from(index, cand, ends[owner], clearance)
    ok = gap > options.body_radius
    if np.count_nonzero(ok):
        ok[ok] = goal.reached(cand_ends[ok, 0], cand_ends[ok, 1], cand_ends[ok, 2])
    if np.count_nonzero(ok) and body_clear is not None and index.body.size:
        # The arms swing as the worker stops: check the whole body, as for every move.
        sel = np.flatnonzero(ok)
        groups = np.split(sel, np.flatnonzero(np.diff(owner[sel])) + 1)   # per successor
        body = np.concatenate([_body_at(index, cand[g], *(float(v) for v in ends[owner[g[0]]]))
                               for g in groups])
        ok[sel] = body_clear(body, index.standing[cand[sel]])
    if not np.count_nonzero(ok):
        return None
    k = int(np.flatnonzero(ok)[0])
    return int(owner[k]), int(cand[k]), cand_ends[k]


def _heuristic(goal: Goal, options: SearchOptions, x: np.ndarray, y: np.ndarray,
               yaw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Relaxed time (M,) to the goal from poses (M,): distance at the heuristic speed plus
    the heading error at the turn rate; and that distance, metres (M,)."""
    left = goal.distance(x, y)
    h = left * (1.0 / options.heuristic_speed)
    if goal.heading is not None:
        off = np.abs((goal.heading(x, y) - yaw + np.pi) % (2.0 * np.pi) - np.pi)
        h = h + off / options.turn_rate
    return h, left


def _over_budget(budget: SearchBudget, t0: float, expanded: int, stall_nodes: int | None,
                 near: _Closest) -> str:
    """``"budget"``, ``"no_stop"`` or ``"stalled"`` when the search must end, else
    ``""``."""
    if expanded > budget.max_nodes or (budget.max_seconds is not None
                                       and time.perf_counter() - t0 > budget.max_seconds):
        return "budget"
    if budget.idle_nodes is not None and expanded - near.progress_at > budget.idle_nodes:
        return "budget"
    if budget.at_goal_nodes is not None and near.at_goal_since is not None \
            and expanded - near.at_goal_since > budget.at_goal_nodes:
        return "no_stop"
    if stall_nodes is not None and expanded - near.progress_at > stall_nodes \
            and near.distance > STALL_FAR:
        return "stalled"
    return ""


def _chain(node: int, last: int, parents: list[int], prims: list[int], poses: list[Pose],
           tail: list[tuple[int, Pose]]) -> tuple[list[int], list[Pose]]:
    """The primitives from the start to ``node``, then ``last`` and ``tail``, with the
    pose each starts from."""
    chain, chain_poses = [last], [poses[node]]
    n = node
    while parents[n] >= 0:
        chain.append(prims[n])
        chain_poses.append(poses[parents[n]])
        n = parents[n]
    chain.reverse()
    chain_poses.reverse()
    for prim_id, pose in tail:
        chain.append(prim_id)
        chain_poses.append(pose)
    return chain, chain_poses


def _body_at(index: GaitIndex, ids: np.ndarray, x: float, y: float, yaw: float
             ) -> np.ndarray:
    """Sampled body poses of primitives ``ids`` placed at (x, y, yaw), shape (M, B, J, 3)."""
    c, s = np.cos(yaw), np.sin(yaw)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    local = index.body[ids]
    body = (local.reshape(-1, 3) @ rot.T).reshape(local.shape)
    body[..., 0] += x
    body[..., 1] += y
    return body


def _step_costs(index: GaitIndex, options: SearchOptions, carry: bool,
                rng: np.random.Generator | None) -> tuple[np.ndarray, np.ndarray]:
    """The primitives a search may take (carry or walk ones; all if the library has none
    of that kind), bool (P,), and their costs with the seeded noise, (P,)."""
    allowed = index.carry == carry
    if not np.count_nonzero(allowed):
        allowed = np.ones_like(allowed)
    noise = (1.0 + options.cost_noise * rng.random(len(index.cost))
             if (rng is not None and options.cost_noise) else np.ones(len(index.cost)))
    return allowed, index.cost * noise


class _Tree:
    """The search tree and its open list: per node the parent, the primitive that led
    there, the pose it ends at (where the next primitive starts) and the cost so far."""

    def __init__(self, start: Pose, start_primitive: int, h0: float) -> None:
        self.parents: list[int] = [-1]
        self.prims: list[int] = [start_primitive]
        self.poses: list[Pose] = [start]
        self.g_cost: list[float] = [0.0]
        self.heap: list[tuple[float, int]] = [(h0, 0)]
        self.closed: set[tuple[int, int, int, int]] = set()

    def close(self, node: int, options: SearchOptions) -> bool:
        """Add ``node`` to the closed set (its pose on the ``options.grid`` /
        ``options.yaw_bins`` lattice and its primitive); False if it was closed."""
        px, py, pyaw = self.poses[node]
        key = (round(px / options.grid), round(py / options.grid),
               round(pyaw * (options.yaw_bins / (2.0 * np.pi))) % options.yaw_bins,
               self.prims[node])
        if key in self.closed:
            return False
        self.closed.add(key)
        return True

    def push(self, node: int, succ: np.ndarray, ends: np.ndarray, g: np.ndarray,
             f: np.ndarray) -> None:
        """Add the successors ``succ`` (M,) of ``node`` ending at ``ends`` (M, 3), with
        costs ``g`` and priorities ``f`` (M,)."""
        first = len(self.prims)
        self.parents.extend([node] * len(succ))
        self.prims.extend(succ.tolist())
        self.poses.extend(map(tuple, ends.tolist()))
        self.g_cost.extend(g.tolist())
        heap, push = self.heap, heapq.heappush
        for k, f_k in enumerate(f.tolist(), first):
            push(heap, (f_k, k))

    def chain(self, node: int, last: int, tail: list[tuple[int, Pose]]
              ) -> tuple[list[int], list[Pose]]:
        """The primitives from the start to ``node``, then ``last`` and ``tail``, with the
        pose each starts from (:func:`_chain`)."""
        return _chain(node, last, self.parents, self.prims, self.poses, tail)


class _Closest:
    """The search's closest approach to the goal (field distance, metres), where it was,
    when it last came ``STALL_PROGRESS`` nearer (for the stall test) and when it first
    reached the goal's floor cells (distance 0; None before)."""

    def __init__(self, distance: float, at: tuple[float, float]) -> None:
        self.distance, self.at = distance, at
        self.progress, self.progress_at = distance, 0
        self.at_goal_since: int | None = 0 if distance <= 0.0 else None

    def update(self, left: np.ndarray, ends: np.ndarray, expanded: int) -> None:
        """Take the successors' distances to the goal ``left`` (M,) at ``ends`` (M, 3)."""
        m = int(np.argmin(left))
        if left[m] < self.distance:
            self.distance, self.at = float(left[m]), (float(ends[m, 0]), float(ends[m, 1]))
            if self.distance < self.progress - STALL_PROGRESS:
                self.progress, self.progress_at = self.distance, expanded
            if self.distance <= 0.0 and self.at_goal_since is None:
                self.at_goal_since = expanded

    def failure(self, reason: str, expanded: int, t0: float) -> SearchFailure:
        """The search's end for ``reason``, started at ``t0`` (``time.perf_counter``)."""
        return SearchFailure(reason, expanded, time.perf_counter() - t0, self.distance,
                             self.at)



def astar(index: GaitIndex, start: Pose, goal: Goal, *, start_primitive: int | None = None,
          clearance: Callable[[np.ndarray], np.ndarray],
          options: SearchOptions = SearchOptions(), carry: bool = False,
          budget: SearchBudget = SearchBudget(), rng: np.random.Generator | None = None,
          body_clear: Callable[[np.ndarray], np.ndarray] | None = None,
          forbidden: frozenset[tuple[int, int, int, int]] = frozenset(),
          stall_nodes: int | None = None
          ) -> SearchResult | SearchFailure:
    """Search a sequence of gait primitives from ``start`` until ``goal.reached``; returns
    a :class:`SearchResult`, or a :class:`SearchFailure` that says why it ended.

    Parameters
    ----------
    index : GaitIndex
    start : (x, y, yaw)
        Floor pose of the root where walking begins.
    goal : Goal
    start_primitive : int or None
        The gait primitive being executed at ``start``; None when standing.
    clearance : callable
        ``clearance(xy (M, 2)) -> (M,)`` signed distance of floor points from the
        obstacles' footprints.
    options : SearchOptions
        Clearance, heuristic speeds, cost noise and the closed-set lattice.
    carry : bool
        Use carry primitives (arms holding an object) instead of walk primitives.
    budget : SearchBudget
    rng : numpy.random.Generator, optional
        Draws the seeded cost noise (``options.cost_noise``): varied but valid paths.
    body_clear : callable, optional
        ``body_clear(poses (M, S, J, 3), standing (M,)) -> bool (M,)``: whole-body obstacle
        test (``standing``: the primitive starts where the last one ended), run on
        standing primitives (turns, steps) and on primitives whose root path comes within
        ``options.near_radius`` of an obstacle.
    forbidden : frozenset of (primitive, i, j, k)
        Primitives never taken from a pose, keyed by :func:`placement_key` of that pose
        (the caller found them colliding on a closer look).
    stall_nodes : int or None
        End with ``"stalled"`` after this many nodes without coming ``STALL_PROGRESS``
        nearer, further than ``STALL_FAR`` from the goal (the heuristic leads into a gap
        the body does not pass, and the search floods the floor before it).
    """
    t0 = time.perf_counter()
    sx, sy, syaw = start
    if bool(goal.reached(np.array([sx]), np.array([sy]), np.array([syaw]))[0]):
        return SearchResult([], [], start, 0, time.perf_counter() - t0)
    allowed, step_cost = _step_costs(index, options, carry, rng)
    h0 = float(_heuristic(goal, options, np.array([sx]), np.array([sy]), np.array([syaw]))[0][0])
    tree = _Tree(start, -1 if start_primitive is None else start_primitive, h0)
    expanded = 0
    near = _Closest(float(goal.distance(np.array([sx]), np.array([sy]))[0]), (sx, sy))
    while tree.heap:
        checkpoint("planning")
        _, node = heapq.heappop(tree.heap)
        if not tree.close(node, options):
            continue
        expanded += 1
        over = _over_budget(budget, t0, expanded, stall_nodes, near)
        if over:
            return near.failure(over, expanded, t0)
        found = _clear_successors(index, tree.prims[node], tree.poses[node], allowed,
                                  clearance, body_clear, forbidden, options)
        if found is None:
            continue
        succ, ends = found
        done, tail = _arrivals(index, succ, ends, goal, allowed, clearance, body_clear,
                               forbidden, options)
        g_new = tree.g_cost[node] + step_cost[succ]
        if np.count_nonzero(done):
            best = int(np.argmin(np.where(done, g_new, np.inf)))
            chain, chain_poses = tree.chain(node, int(succ[best]), tail)
            return SearchResult(chain, chain_poses, tuple(float(v) for v in ends[best]),
                                expanded, time.perf_counter() - t0)
        h_new, left = _heuristic(goal, options, ends[:, 0], ends[:, 1], ends[:, 2])
        keep = np.isfinite(h_new)
        if not np.count_nonzero(keep):
            continue
        near.update(left[keep], ends[keep], expanded)
        tree.push(node, succ[keep], ends[keep], g_new[keep], g_new[keep] + h_new[keep])
    return near.failure("blocked", expanded, t0)
