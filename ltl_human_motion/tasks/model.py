"""A cell model for task planning: what a worker can do next, and what it costs.

The state (:class:`CellState`) holds where the worker is (the start, or the target of
the last task), what each hand holds, where every movable part is and the posture.
Preconditions and effects follow Table I of the paper and what the planner does:

* ``grasp(O)`` needs a free hand (both for a ``two_handed`` part) and O not held; O is
  picked up where it lies (out of the open container it lies in, as the planner does).
* ``release(O)`` needs O in hand, or fetches it first (as the planner does); O is put
  down where the worker stands. A part that starts inside a fixed object (a bin) is
  inside it.
* ``move(O, R)``, ``insert(O, C)`` and ``carry(O, R)`` need O in hand, or fetch it
  first (walk to O and grasp it, which needs a free hand), as the planner does.
  ``move`` sets O down in R and ``insert`` inside C, with the hand free (as the
  planner does); ``carry`` keeps O in hand and puts the worker in R.
* ``extract(O, C)`` needs O inside C and a free hand; O ends in hand.
* ``assemble(R)`` (the shorthand ``leftHand(R) & rightHand(R)``) uses up the parts in
  hand; a later grasp takes a fresh one from its supply position (paper Fig. 3).
* ``walk(R)`` where the worker already is holds once it stands still there (a carry
  into R, then ``F walk(R)``); it costs :data:`IN_PLACE_WALK_PENALTY` more, so that a
  search takes it only where the specification asks for it.
* ``sit(O)`` needs to be standing, or seated already (the worker stays seated);
  ``standUp`` stands up (a no-op when standing); ``kneel`` kneels. Tasks that walk or
  work away from a seat stand up first, as the planner does.

The cost of a step, which the search minimizes, is the straight-line walking distance on
the floor over :data:`WALK_SPEED`, plus the task's nominal duration
(:data:`NOMINAL_DURATION`). It orders sequences; it is not the length of the motion.
:func:`estimated_duration` estimates that length with constants fitted to synthesized
motions (:data:`TIME_CALIBRATION`, ``bench/time_estimate.py``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.ltl.formula import Atom
from ltl_human_motion.vocabulary import two_hand_region

__all__ = ["DONE", "IMPLICIT_FETCH_PENALTY", "IN_PLACE_WALK_PENALTY", "NOMINAL_DURATION",
           "TIME_CALIBRATION", "WALK_SPEED", "CellModel", "CellState", "Limits",
           "TimeCalibration", "estimated_duration"]

#: Walking speed of the cost estimate, m/s. Slower than free walking (about 1.3 m/s,
#: Bohannon 1997) because walks in a cell are short and start and stop.
WALK_SPEED = 1.0

#: Nominal task durations, s: the typical lengths of the motion library's goal
#: primitives of each kind (reach, act and return to the carry stance), rounded.
NOMINAL_DURATION: Mapping[str, float] = {
    "grasp": 1.6, "release": 1.2, "move": 1.8, "insert": 2.2, "extract": 2.2,
    "leftHand": 1.4, "rightHand": 1.4, "assemble": 2.0, "walk": 0.4, "carry": 0.4,
    "sit": 2.0, "standUp": 1.8, "kneel": 2.0, "bend": 1.8, "stoop": 1.8, "wait": 0.0,
}


@dataclass(frozen=True)
class TimeCalibration:
    """Constants of the motion-length estimate (:func:`estimated_duration`), fitted by
    least squares (non-negative) to synthesized motions.

    Attributes
    ----------
    walk_speed : float
        m/s over the straight-line distance between the model's locations.
    walk_overhead : float
        s per walk of non-zero length (starting, stopping, turning, the adjusting step).
    start : float
        s once per motion (the first stance and the last stop).
    durations : mapping
        Task name -> s of its goal primitive (``wait(t)`` adds t on top).
    motions : int
        Motions the constants were fitted to.
    median_error, p90_error, max_error : float
        Relative error |estimate - motion| / motion on motions not used for the fit
        (other statures and seeds): median, 90th percentile, largest.
    """

    walk_speed: float
    walk_overhead: float
    start: float
    durations: Mapping[str, float]
    motions: int = 0
    median_error: float = 0.0
    p90_error: float = 0.0
    max_error: float = 0.0

    def describe(self) -> str:
        """The estimate's error in words, for reports and the CLI."""
        return (f"fitted to {self.motions} synthesized motions; on others off by "
                f"{self.median_error:.0%} (median), {self.p90_error:.0%} (9 in 10), "
                f"at most {self.max_error:.0%}")


#: The estimate's constants, fitted by ``python bench/time_estimate.py`` (which writes
#: ``bench/results/time_estimate.json``; 2026-12-07, commit 6ea2cf8): see
#: :class:`TimeCalibration`. Walks are slow against the straight line between locations
#: (starting, stopping, turning and going round furniture at short gait steps); insert and
#: extract keep their nominal values (no motion of the fit had them).
TIME_CALIBRATION = TimeCalibration(
    walk_speed=0.292, walk_overhead=0.0, start=1.02,
    durations={"grasp": 2.04, "release": 2.04, "move": 1.95, "insert": 2.2, "extract": 2.2,
               "leftHand": 2.00, "rightHand": 1.02, "assemble": 3.01, "walk": 0.54,
               "carry": 1.89, "sit": 1.13, "standUp": 0.04, "kneel": 4.89, "bend": 4.72,
               "stoop": 4.80, "wait": 0.0},
    motions=98, median_error=0.106, p90_error=0.257, max_error=0.743)


#: Posture codes of :class:`CellState`.
STANDING, SITTING, KNEELING = 0, 1, 2
POSTURES = ("standing", "sitting", "kneeling")

#: Where a part is: at a location index >= 0, in hand, or inside container ``c``
#: (encoded as ``INSIDE - c``).
HELD = -1
#: Extra cost (s) of a ``release`` that fetches its part first, so that a search prefers
#: an explicit ``grasp`` wherever the specification allows one (a choice, not a measure).
IMPLICIT_FETCH_PENALTY = 0.5
#: Extra cost (s) of a ``walk(R)`` where the worker already is (see the module
#: docstring): more than the small differences between real options, so the search
#: never prefers such a step to one the specification does not force (a choice).
IN_PLACE_WALK_PENALTY = 1.0
INSIDE = -2

#: Where a part is once the specification no longer mentions it and no hand holds it:
#: handling it again would be pointless, so the search forgets its place.
DONE = -(1 << 30)

#: Tasks the planner performs while seated; any other task stands up first.
_SEATED_TASKS = frozenset({"standUp", "wait", "leftHand", "rightHand", "assemble", "sit"})


@dataclass(frozen=True)
class CellState:
    """One state of the cell model (hashable).

    Attributes
    ----------
    location : int
        Index into :attr:`CellModel.points` where the worker is.
    held : tuple of int
        Parts in hand (part indices, sorted).
    parts : tuple of int
        Per part: a location index, :data:`HELD`, or ``INSIDE - c`` for container c.
    posture : int
        :data:`STANDING`, :data:`SITTING` or :data:`KNEELING`.
    """

    location: int
    held: tuple[int, ...]
    parts: tuple[int, ...]
    posture: int = STANDING


@dataclass(frozen=True)
class Limits:
    """Physical limits of the model; relaxing one tells which limit blocks a plan.

    Attributes
    ----------
    hands : int
        Hands of the worker (a ``two_handed`` part takes two).
    posture : bool
        Whether posture preconditions (``sit`` needs standing) are enforced.
    """

    hands: int = 2
    posture: bool = True


@dataclass
class CellModel:
    """Locations, parts and costs of one cell (see the module docstring).

    Parameters
    ----------
    points : ndarray, shape (L, 2)
        Floor positions of the locations: 0 is the start, then the parts' supply
        positions, then the regions' centres.
    part_names : tuple of str
    region_names : tuple of str
    two_handed : tuple of bool
        Per part.
    movable : tuple of bool
        Per part (default all): a fixed object is a container or a seat, never held.
    shorthands : mapping
        Shorthand name -> (params, body) of the cell.
    limits : Limits
    durations : mapping
        Task name -> nominal duration, s (default :data:`NOMINAL_DURATION`).
    inside : tuple of (int or None)
        Per part (default none): the index of the container part it starts inside.
    timing : TimeCalibration, optional
        When given, step costs are the calibrated estimate of the motion's length (walks
        and durations from it, no search penalties) instead of the search's cost.
    """

    points: np.ndarray
    part_names: tuple[str, ...]
    region_names: tuple[str, ...]
    two_handed: tuple[bool, ...]
    movable: tuple[bool, ...] = ()
    shorthands: Mapping[str, tuple[tuple[str, ...], str]] = field(default_factory=dict)
    limits: Limits = field(default_factory=Limits)
    durations: Mapping[str, float] = field(default_factory=lambda: dict(NOMINAL_DURATION))
    inside: tuple[int | None, ...] = ()
    timing: TimeCalibration | None = None

    def __post_init__(self) -> None:
        pts = np.asarray(self.points, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] != 1 + len(self.part_names) \
                + len(self.region_names):
            raise ValueError(f"points must have shape (1 + parts + regions, 2) = "
                             f"({1 + len(self.part_names) + len(self.region_names)}, 2), "
                             f"got {pts.shape}")
        self.points = pts
        self.part_index = {n: i for i, n in enumerate(self.part_names)}
        self.region_index = {n: i for i, n in enumerate(self.region_names)}
        diff = pts[:, None, :] - pts[None, :, :]
        dist = np.sqrt((diff ** 2).sum(-1))
        self.walk_time = dist / WALK_SPEED
        self._fetch_penalty, self._in_place_penalty = IMPLICIT_FETCH_PENALTY, IN_PLACE_WALK_PENALTY
        if self.timing is not None:
            self.walk_time = dist / self.timing.walk_speed \
                + np.where(dist > 1e-9, self.timing.walk_overhead, 0.0)
            self.durations = dict(self.timing.durations)
            self._fetch_penalty = self._in_place_penalty = 0.0
        self._walk = self.walk_time.tolist()
        if not self.movable:
            self.movable = (True,) * len(self.part_names)
        if not self.inside:
            self.inside = (None,) * len(self.part_names)
        # a fixed object never fits in the hands
        self._width = tuple(2 if t else 1 if m else self.limits.hands + 1
                            for t, m in zip(self.two_handed, self.movable))
        self._kinds: dict[str, tuple[str, tuple[str, ...]]] = {}

    # ---------------------------------------------------------------- building
    @classmethod
    def from_cell(cls, cell: object, limits: Limits | None = None,
                  durations: Mapping[str, float] | None = None) -> CellModel:
        """The model of a scene :class:`~ltl_human_motion.scene.cell.Cell` (or any object
        with ``objects`` (name -> .position (3,), .two_handed, .movable), ``regions``
        (name -> .center (3,)), ``start_region`` and ``shorthands``)."""
        objects = dict(cell.objects)
        regions = dict(cell.regions)
        start = np.asarray(cell.start_region.center, dtype=np.float64)[:2]
        parts = tuple(objects)
        pts = [start, *(np.asarray(objects[n].position, dtype=np.float64)[:2] for n in parts),
               *(np.asarray(regions[r].center, dtype=np.float64)[:2] for r in regions)]
        return cls(np.array(pts), parts, tuple(regions),
                   tuple(bool(getattr(objects[n], "two_handed", False)) for n in parts),
                   tuple(bool(getattr(objects[n], "movable", True)) for n in parts),
                   dict(getattr(cell, "shorthands", {}) or {}), limits or Limits(),
                   dict(NOMINAL_DURATION if durations is None else durations),
                   _containers(objects, parts))

    def initial_state(self) -> CellState:
        """The worker at the start, hands empty, parts at their supply positions (or
        inside the container they start in)."""
        return CellState(0, (), tuple(1 + i if c is None else INSIDE - c
                                      for i, c in enumerate(self.inside)))

    def with_limits(self, limits: Limits) -> CellModel:
        """The same cell with other physical limits."""
        return CellModel(self.points, self.part_names, self.region_names, self.two_handed,
                         self.movable, self.shorthands, limits, self.durations, self.inside,
                         self.timing)

    def with_timing(self, timing: TimeCalibration) -> CellModel:
        """The same cell whose step costs estimate the motion's length (see ``timing``)."""
        return CellModel(self.points, self.part_names, self.region_names, self.two_handed,
                         self.movable, self.shorthands, self.limits, self.durations,
                         self.inside, timing)

    # ---------------------------------------------------------------- locations
    def supply(self, part: int) -> int:
        """Location index of a part's supply position."""
        return 1 + part

    def region_location(self, name: str) -> int:
        """Location index of a region's centre."""
        return 1 + len(self.part_names) + self.region_index[name]

    def kind(self, task: Atom) -> tuple[str, tuple[str, ...]]:
        """The task kind realising a step: a two-hand shorthand is ``assemble``."""
        hit = self._kinds.get(task.key)
        if hit is None:
            hit = (task.name, tuple(task.args))
            if task.name in self.shorthands:
                params, body = self.shorthands[task.name]
                hit = ("shorthand", tuple(task.args))
                if len(task.args) == 1 and two_hand_region(params, body):
                    hit = ("assemble", tuple(task.args))
            self._kinds[task.key] = hit
        return hit

    def target(self, task: Atom, state: CellState) -> int | None:
        """Location index where ``task`` ends (None: in place)."""
        kind, args = self.kind(task)
        if kind in ("walk", "carry", "leftHand", "rightHand", "assemble", "shorthand"):
            return self._region_or_none(args[-1] if args else None)
        if kind in ("grasp", "sit"):
            return self._part_place(args[0], state)
        if kind == "move":
            return self._region_or_none(args[1])
        if kind in ("insert", "extract"):
            return self._part_place(args[1], state)
        return None

    def _region_or_none(self, name: str | None) -> int | None:
        return None if name is None or name not in self.region_index \
            else self.region_location(name)

    def _part_place(self, name: str, state: CellState) -> int | None:
        p = self.part_index.get(name)
        if p is None:
            return None
        where = state.parts[p]
        if where >= 0:
            return where
        if where == DONE:
            return None
        if where == HELD:
            return state.location
        return self._part_place(self.part_names[INSIDE - where], state)

    # ---------------------------------------------------------------- dynamics
    def _fetch_place(self, p: int, state: CellState, held: Sequence[int]) -> int | None:
        """Where part ``p`` is picked up when a step fetches it first (from its place, or
        out of the container it lies in), or None when it cannot be: no free hand, a
        part no longer mentioned."""
        if self._free_hands(held) < self._width[p]:
            return None
        where = state.parts[p]
        if where >= 0:
            return where
        if where <= INSIDE and where != DONE:
            c = INSIDE - where                  # a fixed container: its place never changes
            place = self._part_place(self.part_names[c], state)
            return self.supply(c) if place is None else place
        return None

    def _free_hands(self, held: Sequence[int]) -> int:
        return self.limits.hands - sum(self._width[p] for p in held)

    def step(self, state: CellState, task: Atom) -> tuple[CellState, float] | None:
        """``(next state, cost in s)`` of doing ``task`` in ``state``, or None when the
        task is physically impossible or pointless there (see the module docstring)."""
        kind, args = self.kind(task)
        cost = 0.0
        posture = state.posture
        if posture != STANDING and kind not in _SEATED_TASKS:
            cost += self.durations["standUp"]
            posture = STANDING
        loc = state.location
        parts = list(state.parts)
        held = list(state.held)
        if kind in ("move", "insert", "carry"):
            p = self.part_index.get(args[0])
            if p is None:
                return None
            if parts[p] != HELD:
                at = self._fetch_place(p, state, held)
                if at is None:
                    return None
                cost += self._walk[loc][at] + self.durations["grasp"]
                loc = at
                parts[p] = HELD
                held.append(p)
            dest = self.target(task, state)
            if dest is not None:
                cost += self._walk[loc][dest]
                loc = dest
            if kind == "move":                  # the planner sets the part down in R
                held.remove(p)
                parts[p] = dest if dest is not None else loc
            elif kind == "insert":
                held.remove(p)
                c = self.part_index.get(args[1])
                if c is None or c == p or state.parts[c] == DONE:
                    return None
                parts[p] = INSIDE - c
        elif kind == "grasp":
            p = self.part_index.get(args[0])
            if p is None or parts[p] == HELD:
                return None
            # A part in an open container (a bin) is picked out of it where it lies.
            at = self._fetch_place(p, state, held)
            if at is None:
                return None
            cost += self._walk[loc][at]
            loc = at
            parts[p] = HELD
            held.append(p)
        elif kind == "release":
            p = self.part_index.get(args[0])
            if p is None:
                return None
            if parts[p] != HELD:                # the planner fetches it first
                at = self._fetch_place(p, state, held)
                if at is None:
                    return None
                cost += self._walk[loc][at] + self.durations["grasp"] + self._fetch_penalty
                loc = at
                held.append(p)
            held.remove(p)
            parts[p] = loc
        elif kind == "extract":
            p, c = self.part_index.get(args[0]), self.part_index.get(args[1])
            if p is None or c is None or parts[p] != INSIDE - c \
                    or self._free_hands(held) < self._width[p]:
                return None
            dest = self.target(task, state)
            if dest is None:
                return None
            cost += self._walk[loc][dest]
            loc = dest
            parts[p] = HELD
            held.append(p)
        elif kind == "assemble":
            dest = self.target(task, state)
            if dest is not None:
                cost += self._walk[loc][dest]
                loc = dest
            for p in held:
                parts[p] = self.supply(p)       # used up; the next grasp takes a new one
            held = []
        elif kind == "sit":
            if self.limits.posture and state.posture == KNEELING:
                return None                     # sitting again while seated: stay seated
            dest = self.target(task, state)
            if dest is not None:
                cost += self._walk[loc][dest]
                loc = dest
            posture = SITTING
        elif kind == "standUp":
            posture = STANDING
        elif kind == "kneel":
            posture = KNEELING
        else:
            dest = self.target(task, state)
            if kind == "walk" and dest == loc:
                cost += self._in_place_penalty   # already there: stands still in R
            if dest is not None:
                cost += self._walk[loc][dest]
                loc = dest
        if kind == "wait":
            cost += float(args[0]) if args else 0.0
        else:
            cost += self.durations.get(kind, self.durations.get("walk", 0.0))
        return CellState(loc, tuple(sorted(held)), tuple(parts), posture), cost

    def forget(self, state: CellState, keep: frozenset[str]) -> CellState:
        """``state`` with the place of every part not in ``keep`` and not held set to
        :data:`DONE` (a product search calls it with the parts its automaton state still
        mentions)."""
        parts = state.parts
        new = tuple(w if w == HELD or self.part_names[p] in keep else DONE
                    for p, w in enumerate(parts))
        return state if new == parts else CellState(state.location, state.held, new,
                                                    state.posture)

    def describe(self, state: CellState) -> str:
        """A one-line text of a state (for explanations)."""
        held = ", ".join(self.part_names[p] for p in state.held) or "nothing"
        return f"holding {held}, {POSTURES[state.posture]}"


def _containers(objects: Mapping[str, object], parts: Sequence[str]) -> tuple[int | None, ...]:
    """Per part, the index of the fixed object (a bin) whose box holds its position."""
    boxes = {}
    for i, n in enumerate(parts):
        obj = objects[n]
        if not getattr(obj, "movable", True) and hasattr(obj, "occupancy"):
            boxes[i] = obj.occupancy.aabb()
    out: list[int | None] = []
    for i, n in enumerate(parts):
        pos = np.asarray(objects[n].position, dtype=np.float64)
        hit = next((c for c, (lo, hi) in boxes.items()
                    if c != i and np.all(pos >= lo) and np.all(pos <= hi)), None)
        out.append(hit)
    return tuple(out)


def estimated_duration(model: CellModel, tasks: Sequence[Atom],
                       timing: TimeCalibration | None = None) -> float | None:
    """Estimated length (s) of the motion of ``tasks`` done in order from the start, with
    ``timing`` (default :data:`TIME_CALIBRATION`; its error says how far off it is), or
    None when a step is impossible in the model."""
    timing = timing or TIME_CALIBRATION
    timed = model.with_timing(timing)
    state, total = timed.initial_state(), timing.start
    for task in tasks:
        nxt = timed.step(state, task)
        if nxt is None:
            return None
        state, cost = nxt
        total += cost
    return total
