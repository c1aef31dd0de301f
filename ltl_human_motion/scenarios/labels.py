"""Feasibility labels from geometry alone: reach envelope, free floor, openings, sizes.

A generated task is labelled by what a worker of a stature can do in the cell's geometry,
never by what the planner manages. The worker model is a plain anthropometric one
(proportions of stature H, after Pheasant & Haslegrave, *Bodyspace*, and Winter's
segment table), independent of the planner's:

* vertical grip reach ``VERTICAL_REACH_FRACTION * H`` (1.94 m at 1.55 m, 2.44 m at
  1.95 m); a target whose bottom lies :data:`REACH_MARGIN` above it is out of reach;
* a comfortable horizontal reach from the edge of the free floor: the arm
  (``ARM_FRACTION * H`` from the shoulder at ``SHOULDER_FRACTION * H``, the shoulder
  allowed to lean :data:`LEAN` forward; above the shoulder the arm's horizontal reach
  shrinks), and a generous bound ``GENEROUS_REACH_FRACTION * H`` beyond which nobody
  reaches, however far the trunk bends;
* two floor maps: *strict* floor keeps a standing body (:data:`STRICT_BODY_RADIUS`)
  clear of every obstacle part below :data:`STRICT_BLOCK_HEIGHT` (reach is measured from
  in front of a table, not from under it), *loose* floor only keeps a body turned
  sideways (:data:`LOOSE_BODY_RADIUS`) clear of what reaches below the shins
  (:data:`LOOSE_BLOCK_HEIGHT`); both count only floor connected to the start region;
* an opening (a machine's door) lets a part through if the part's cross-section leaves
  room for the hand (:data:`OPENING_SIDE_ROOM`, :data:`OPENING_TOP_ROOM`); a part whose
  smallest width exceeds the opening's smaller side passes in no orientation;
* a part fits a container or region if it fits with :data:`FIT_ROOM` to spare along
  every axis (parts only translate); its smallest width or volume exceeding the
  container's means never.

A task is *feasible* when every target passes the comfortable tests, *infeasible* (with
the reason the planner's early analysis uses: ``reach``, ``no_floor``, ``enclosed``,
``size``, ``seat_height``) when one fails the generous test, and *ambiguous* otherwise:
ambiguous tasks are not generated. Openings are not a key of the cell format (a machine
is an obstacle of boxes); the generator passes them as :class:`Opening` beside the cell.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ltl_human_motion.scene.cell import Cell
from ltl_human_motion.scene.shapes import Box, Cylinder
from ltl_human_motion.scene.termination import parse_task

__all__ = ["Label", "Labeller", "Opening", "Worker", "label_task"]

VERTICAL_REACH_FRACTION = 1.25
REACH_MARGIN = 0.10
SHOULDER_FRACTION = 0.82
ARM_FRACTION = 0.39
LEAN = 0.10
#: Fraction of the arm's reach counted as comfortable (the palm, not the fingertips).
COMFORT_FACTOR = 0.9
GENEROUS_REACH_FRACTION = 0.80
#: Highest target centre labelled feasible, metres (the corpus's overhead shelf).
MAX_COMFORT_HEIGHT = 1.70
STRICT_BODY_RADIUS = 0.18
STRICT_BLOCK_HEIGHT = 1.20
LOOSE_BODY_RADIUS = 0.10
LOOSE_BLOCK_HEIGHT = 0.30
FLOOR_RESOLUTION = 0.05
OPENING_SIDE_ROOM = 0.10
OPENING_TOP_ROOM = 0.25
FIT_ROOM = 0.01
#: A seat above this fraction of stature needs a climb (the standing pelvis is 0.53 H).
SEAT_FRACTION = 0.50

_IN_PLACE = {"wait", "standUp", "bend", "stoop", "kneel"}


@dataclass(frozen=True)
class Worker:
    """The geometric worker of one stature (metres)."""

    stature: float

    @property
    def vertical(self) -> float:
        return VERTICAL_REACH_FRACTION * self.stature

    @property
    def generous(self) -> float:
        return GENEROUS_REACH_FRACTION * self.stature

    def comfortable(self, z: float) -> float:
        """Comfortable horizontal reach from the floor's edge to a target at height z."""
        arm = ARM_FRACTION * self.stature
        dz = max(float(z) - SHOULDER_FRACTION * self.stature, 0.0)
        if dz >= arm:
            return 0.0
        return COMFORT_FACTOR * math.sqrt(arm * arm - dz * dz) + LEAN


@dataclass(frozen=True)
class Opening:
    """A door opening in the front of a machine, in the cell's z-up frame.

    Attributes
    ----------
    machine : str
        The obstacle it opens.
    lo, hi : ndarray, shape (3,)
        The cavity behind it (the free box inside the machine).
    width, height : float
        Of the opening, metres (width along the front, height up).
    axis : int
        Floor axis (0 for x, 1 for y) that the opening's normal lies along.
    """

    machine: str
    lo: np.ndarray
    hi: np.ndarray
    width: float
    height: float
    axis: int

    def holds(self, point: np.ndarray) -> bool:
        return bool(np.all(point >= self.lo - 1e-9) and np.all(point <= self.hi + 1e-9))


@dataclass(frozen=True)
class Label:
    """A task's label: ``expect`` in {"feasible", "infeasible", "ambiguous"}."""

    expect: str
    reason: str | None = None
    why: str = ""


_OK = Label("feasible")


def _extents(shape) -> np.ndarray:
    """Axis-aligned extents (3,) of a box or cylinder part (translation only)."""
    if isinstance(shape, Box):
        lo, hi = shape.aabb()
        return np.asarray(hi - lo, dtype=float)
    if isinstance(shape, Cylinder):
        return np.array([2 * shape.radius, 2 * shape.radius, shape.height])
    lo, hi = shape.aabb()
    return np.asarray(hi - lo, dtype=float)


@dataclass
class _Floor:
    """Free floor cells connected to the start: centres (F, 2)."""

    connected: np.ndarray
    any_free: np.ndarray

    def distance(self, lo: np.ndarray, hi: np.ndarray, cells: np.ndarray) -> float:
        if not len(cells):
            return math.inf
        d = np.maximum(np.maximum(lo[:2] - cells, 0.0), np.maximum(cells - hi[:2], 0.0))
        return float(np.hypot(d[:, 0], d[:, 1]).min())


def _floor(cell: Cell, radius: float, block: float) -> _Floor:
    from ltl_human_motion.planning.feasibility import floor_components
    grid, labels = floor_components(cell, radius, FLOOR_RESOLUTION, block)
    flat = grid.free.ravel()
    r0 = cell.start_region
    start = flat & np.all((grid.centres >= r0.lo[:2] - FLOOR_RESOLUTION)
                          & (grid.centres <= r0.hi[:2] + FLOOR_RESOLUTION), axis=-1)
    ok = np.isin(labels, np.unique(labels[start])) & flat if start.any() else flat & False
    return _Floor(grid.centres[ok], grid.centres[flat])


class _Floors:
    """The strict and loose floor of a cell (built on first use)."""

    def __init__(self, cell: Cell) -> None:
        self.cell = cell

    @cached_property
    def strict(self) -> _Floor:
        return _floor(self.cell, STRICT_BODY_RADIUS, STRICT_BLOCK_HEIGHT)

    @cached_property
    def loose(self) -> _Floor:
        return _floor(self.cell, LOOSE_BODY_RADIUS, LOOSE_BLOCK_HEIGHT)


@dataclass
class _Judge:
    """The checks of one cell and stature."""

    cell: Cell
    worker: Worker
    openings: tuple[Opening, ...]
    floors: _Floors

    @property
    def strict(self) -> _Floor:
        return self.floors.strict

    @property
    def loose(self) -> _Floor:
        return self.floors.loose

    def box(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        lo, hi = self.cell.lookup(name).shape.aabb()
        return np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)

    def reach(self, name: str) -> Label:
        lo, hi = self.box(name)
        w, floor = self.worker, float(self.cell.floor_z)
        zlo, zc = lo[2] - floor, (lo[2] + hi[2]) / 2 - floor
        if zlo > w.vertical + REACH_MARGIN:
            return Label("infeasible", "reach", f"{name} at {zlo:.2f} m is above the "
                         f"{w.stature:.2f} m worker's grip reach ({w.vertical:.2f} m)")
        d_strict = self.strict.distance(lo, hi, self.strict.connected)
        if zc <= MAX_COMFORT_HEIGHT and d_strict <= w.comfortable(zc):
            return _OK
        d_loose = self.loose.distance(lo, hi, self.loose.connected)
        if d_loose > w.generous:
            if self.loose.distance(lo, hi, self.loose.any_free) <= w.generous:
                return Label("infeasible", "enclosed", f"the floor near {name} is cut off "
                             "from the start")
            return Label("infeasible", "no_floor", f"{name} is {d_loose:.2f} m from the "
                         f"nearest floor, beyond any reach ({w.generous:.2f} m)")
        return Label("ambiguous", None, f"{name}: {d_strict:.2f} m from the floor at "
                     f"{zc:.2f} m")

    def stand_in(self, name: str) -> Label:
        lo, hi = self.box(name)
        cells = self.strict.connected
        inside = np.all((cells >= lo[:2]) & (cells <= hi[:2]), axis=-1)
        if inside.any():
            return _OK
        return Label("ambiguous", None, f"no comfortable floor inside {name}")

    def fits(self, part: str, into: str) -> Label:
        p = _extents(self.cell.object(part).shape)
        c = self.box(into)
        c = c[1] - c[0]
        if np.all(p + FIT_ROOM <= c):
            return _OK
        if p.min() > c.min() + 1e-6 or np.prod(p) > np.prod(c):
            return Label("infeasible", "size", f"{part} ({_dims(p)}) does not fit {into} "
                         f"({_dims(c)})")
        return Label("ambiguous", None, f"{part} fits {into} only turned")

    def through(self, part: str, where: str) -> Label:
        """Whether ``part`` passes the opening of the machine that ``where`` lies in."""
        lo, hi = self.box(where)
        op = next((o for o in self.openings if o.holds((lo + hi) / 2)), None)
        if op is None:
            return _OK
        p = _extents(self.cell.object(part).shape)
        side = p[1 - op.axis]
        if side + 2 * OPENING_SIDE_ROOM <= op.width and p[2] + OPENING_TOP_ROOM <= op.height:
            return _OK
        if p.min() > min(op.width, op.height):
            return Label("infeasible", "size", f"{part} ({_dims(p)}) is wider than the "
                         f"{op.width:.2f} x {op.height:.2f} m opening of {op.machine}")
        return Label("ambiguous", None, f"{part} passes {op.machine}'s opening only tightly")

    def seat(self, name: str) -> Label:
        obj = self.cell.object(name)
        z = float(obj.sitting_surface_at().aabb()[1][2]) - float(self.cell.floor_z)
        if z > SEAT_FRACTION * self.worker.stature:
            return Label("infeasible", "seat_height", f"the seat of {name} at {z:.2f} m "
                         "is above the standing pelvis")
        return self.reach(name)

    def task(self, text: str) -> Label:
        kind, args = parse_task(text)
        if kind in _IN_PLACE:
            return _OK
        if kind in ("grasp", "release"):
            checks = [lambda: self.reach(args[0])]
        elif kind == "extract":
            checks = [lambda: self.reach(args[0]), lambda: self.through(args[0], args[0])]
        elif kind in ("insert", "move"):
            checks = [lambda: self.reach(args[0]), lambda: self.through(args[0], args[0]),
                      lambda: self.fits(args[0], args[1]), lambda: self.reach(args[1]),
                      lambda: self.through(args[0], args[1])]
        elif kind == "carry":
            checks = [lambda: self.reach(args[0]), lambda: self.through(args[0], args[0]),
                      lambda: self.fits(args[0], args[1]), lambda: self.stand_in(args[1])]
        elif kind in ("walk", "enter"):
            checks = [lambda: self.stand_in(args[0])]
        elif kind == "sit":
            checks = [lambda: self.seat(args[0])]
        else:                                   # leftHand, rightHand, assemble
            checks = [lambda: self.reach(args[0])]
        worst = _OK
        for check in checks:
            label = check()
            if label.expect == "infeasible":
                return label
            if label.expect == "ambiguous":
                worst = label
        return worst


def _dims(v: np.ndarray) -> str:
    return " x ".join(f"{x:.2f}" for x in v) + " m"


class Labeller:
    """Labels tasks in one cell (its floor maps built once, for every stature)."""

    def __init__(self, cell: Cell, openings: tuple[Opening, ...] = ()) -> None:
        self.cell = cell
        self.openings = tuple(openings)
        self._floors = _Floors(cell)

    def label(self, tasks: list[str] | tuple[str, ...], stature: float) -> Label:
        """The label of a specification that needs every one of ``tasks``
        (``"extract(P1, vise_a)"``, ...): infeasible if one is, else ambiguous if one
        is, else feasible."""
        judge = _Judge(self.cell, Worker(float(stature)), self.openings, self._floors)
        worst = _OK
        for t in tasks:
            label = judge.task(t)
            if label.expect == "infeasible":
                return label
            if label.expect == "ambiguous":
                worst = label
        return worst


def label_task(cell: Cell, task: str, stature: float,
               openings: tuple[Opening, ...] = ()) -> Label:
    """The geometric label of one task for a worker of ``stature``."""
    return Labeller(cell, openings).label([task], stature)
