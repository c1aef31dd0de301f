"""From a task sequence to placed motion segments (Sec. III-B of the paper).

For each task step the planner

1. works out the target point (object grasp point, region centre, ...);
2. searches gait primitives, turns and steps on the spot with A* (:mod:`.astar`) until
   the worker stands within a short step of a place from which a goal primitive
   reaches the target (walk/carry tasks: until the body enters the region), then takes
   that step (a model-made step and turn, :mod:`.turns`);
3. raises the arms for hand tasks, makes the goal primitive for the exact target
   (:mod:`ltl_human_motion.motion.goals`), checks it against the obstacles (other seeds,
   the other hand) and places it at the pose where the walk hands over.

Objects follow the hand that grasped them until they are released, placed (move,
insert, extract) or assembled. A part that was assembled is replenished at its supply
position (its pose in the cell) when it is grasped again, as in the paper's Fig. 3,
where every grasp picks a new part from the floor.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.motion.goals import HAND_PATHS, LEVEL_PATH_TASKS, LOW_BOARD_HEIGHT
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.motion.types import MotionPrimitive, world_positions
from ltl_human_motion.planning.astar import (
    Goal,
    SearchBudget,
    SearchFailure,
    SearchOptions,
    astar,
    placement_key,
)
from ltl_human_motion.planning.blend import PlacedSegment, wrap_angle
from ltl_human_motion.planning.feasibility import reach_envelope
from ltl_human_motion.planning.gait_index import gait_index
from ltl_human_motion.planning.navigation import (
    TALL_EXTRA,
    NavigationField,
    clearance_maps,
    floor_grid,
    stand_clearance_map,
)
from ltl_human_motion.planning.placement import RegionEntry
from ltl_human_motion.vocabulary import HAND_TASKS, TaskStep

Pose = tuple[float, float, float]

#: How long ``standUp`` by a worker already standing stands still, seconds (a short,
#: visible pause; the blends at both ends take 2 x overlap frames of it).
STAND_UP_IN_PLACE_SECONDS = 0.4
#: A sit on a seat no further than this from the one the worker sits on stays seated,
#: metres (a seat point is exact to the cell model; 5 cm is a buttock's settling).
SAME_SEAT_DISTANCE = 0.05

#: Height of the hand where a held part is let go, as a fraction of the stature (waist
#: height: 0.75 m for a 1.75 m worker, the planner's value since the first release).
RELEASE_HEIGHT = 0.75 / 1.75

#: Places a part is let go at, (metres ahead of the root, turn from the heading in
#: radians), tried in order: straight ahead at a forearm's length, then to either side
#: and nearer the body when furniture stands in front.
RELEASE_PLACES: tuple[tuple[float, float], ...] = (
    (0.45, 0.0), (0.45, math.pi / 4), (0.45, -math.pi / 4), (0.4, math.pi / 2),
    (0.4, -math.pi / 2), (0.3, 0.0))

#: Seeded primitives tried at each alternative (release place, approach) after the first
#: (the first gets ``PlannerOptions.goal_attempts``).
ALTERNATIVE_ATTEMPTS = 2

#: Other ways to stand for a reach whose motions all hit an obstacle, in order: (turn of
#: the approach direction about the target, rad; extra distance from the target, m).
#: First a step further back (a knee or thigh at a desk or low shelf front), then the
#: target's other sides (an arm hitting a crate beside it).
ALTERNATE_APPROACHES: tuple[tuple[float, float], ...] = (
    (0.0, 0.08), (math.pi / 3, 0.0), (-math.pi / 3, 0.0))

#: Node budget of the walk to an alternative approach (most are a few steps round the
#: target; a side that needs a long way round is not worth the search).
ALTERNATIVE_NODES = 500

#: Node budget of the walk to the side of a seat that faces the seated work (without
#: it the worker sits facing whichever way the walk arrives).
FACING_NODES = 600

#: Half length of a low board's front edge either side of the target that the reach
#: under it keeps clear of, metres (about a shoulder width: the arm and the head).
BOARD_EDGE_SPAN = 0.25

#: Half width of the side a worker reaching under a low board stands on, rad: nearly
#: square to the edge (the knees of a deep crouch come up close to it).
BOARD_FACING = math.pi / 12

#: Half width of the side of the target an alternative approach walks to, rad.
APPROACH_HALF_WIDTH = math.pi / 6

#: Step left to the standing adjustment when the first one from where a walk ended was
#: not clear: the walk goes on to a spot that needs almost none, metres.
FINAL_ADJUST_RADIUS = 0.05

#: Clearance (m) the planner keeps between the body and obstacles on the frames it
#: checks exactly: the verifier allows none below 0; blends between segments move
#: joints by a few millimetres.
PLACED_MARGIN = 0.003

#: Stride of the measured frames of an every-frame check, and the clearance below which
#: those measurements are exact, metres (:func:`body_clear_every_frame`).
CLEAR_STRIDE = 4
CLEAR_EXACT = 0.1

#: Searches run again after the path found collided on a frame the search did not
#: sample (each forbids the colliding primitive at its pose).
WALK_REPAIRS = 4

#: Backward steps tried (m) to leave a spot closer to an obstacle than walking allows,
#: and the clearance beyond ``PlannerOptions.body_radius`` the step must reach (m).
STEP_OUT_DISTANCES: tuple[float, ...] = (0.1, 0.2, 0.3)
STEP_OUT_MARGIN = 0.02
#: Steps aside (m, left positive) tried when no backward step clears what follows.
SIDE_STEPS: tuple[float, ...] = (0.1, -0.1, 0.2, -0.2)

#: Hand tasks a seated worker does from the seat (others make the worker stand up).
SEATED_HAND_TASKS = ("leftHand", "rightHand", "assemble")

#: How far the gripping hand rises before a grasped part counts as lifted off its
#: support (a part resting on a table touches it until then), metres.
LIFT_RISE = 0.001

#: Tasks done where the worker stands (no target); when furniture there blocks them,
#: the worker first walks to a spot with ``IN_PLACE_ROOM`` of floor clearance.
IN_PLACE_TASKS = ("bend", "stoop", "kneel", "wait")

#: Floor clearance around the root a kneel or stoop needs, metres (the knee goes about
#: 0.5 m ahead of the root and the head as far when stooping, plus a hand's width).
IN_PLACE_ROOM = 0.6

#: Tops of furniture a released part is set down on: up to this fraction of the stature
#: (1.2 m at 1.75 m, about chest height: higher tops are shelves out of a natural
#: put-down).
RELEASE_SURFACE_MAX = 1.2 / 1.75

#: Gap between a part set down and the surface under it when it is let go, metres (the
#: cells' parts rest 1 cm above their tables).
RELEASE_GAP = 0.01

#: Raising a grasp's palm target off the part's support (:meth:`SequencePlanner.
#: _palm_clear_of_support`): step and the gap kept to the support (the planner's goal
#: checks need PLACED_MARGIN; blends move the palm a few mm), and how deep the palm
#: sphere stays in the part (grasp holds when it enters), metres.
PALM_RISE_STEP = 0.005
PALM_SUPPORT_GAP = 0.01
PALM_IN_PART = 0.01

#: Floor clearance below which the navigation field counts the floor longer, metres:
#: about half the hip and shoulder width of a 1.75 m worker (0.2 m) plus the gait's
#: sway, more than ``PlannerOptions.body_radius`` (the least a walk needs).
PASSAGE_RADIUS = 0.25
#: The same on the footprint map of a squeeze (:meth:`SequencePlanner._field`): half
#: the 0.8 m aisle of the corpus, whose walls the walking map counts ``TALL_EXTRA``
#: closer; the field leads along the middle of such a gap.
SQUEEZE_PASSAGE = PASSAGE_RADIUS + TALL_EXTRA
#: Node budget of a squeezing walk: along a gap the body barely fits the search gets
#: through at once or not at all (the aisle's walks take under 20 nodes; a goal the
#: body cannot stand at took the whole 8000 and the pair's time limit).
SQUEEZE_NODES = 1000

#: How far beyond its container an extract pulls the part, metres.
PULL_MARGIN = 0.03

#: Stride of the frames on which the planner checks that an extract takes its part out.
EXTRACT_CHECK_STRIDE = 4

#: The other hand of each hand joint.
OTHER_HAND = {"l_hand": "r_hand", "r_hand": "l_hand"}

#: A walk's search that expands this many nodes without getting nearer the goal stalls
#: (in front of a gap the walking body does not pass: the cell with crates floods 7000
#: nodes there; searches that get through a tight spot went up to about 2500 nodes
#: without progress there); its goal then reroutes around a disc of
#: ``STALL_BLOCK_RADIUS`` (m) at the closest approach, up to ``MAX_REROUTES`` times.
STALL_NODES = 3500
STALL_BLOCK_RADIUS = 0.3
MAX_REROUTES = 2

#: Navigation fields by floor grid and goal (see :meth:`SequencePlanner._field`).
_FIELD_CACHE: dict[tuple, tuple[object, NavigationField]] = {}

#: Arm transitions by (stances, stature, rate, blend, carrying before) (see
#: :meth:`SequencePlanner._arm_poses`).
_ARM_POSES: dict[tuple, np.ndarray] = {}



@dataclass(frozen=True)
class PlannerOptions:
    """Tunable planner settings.

    Attributes
    ----------
    heuristic_speed : float
        Relaxed speed of the A* heuristic, m/s (paper Sec. III-B).
    turn_rate : float
        Relaxed turning speed of the heuristic's heading term, rad/s.
    budget : SearchBudget
        Node and time limits of each search.
    cost_noise : float
        Seeded relative noise on primitive costs: different seeds, different paths.
    reach_tolerance : float
        Accepted error of the standing distance to the target, metres.
    heading_tolerance : float
        Accepted heading error towards the target, radians.
    body_radius : float
        Clearance the walking root keeps from obstacle footprints, metres.
    grid_resolution : float
        Cell size of the navigation field behind the heuristic, metres.
    goal_attempts : int
        Seeded goal primitives tried before a reach blocked by obstacles fails.
    adjust_radius : float
        A walk may end this far from the ideal placement; a model-made step and turn on
        the spot covers the rest (like the analytic expansion of hybrid A*).
    turn_clearance : float
        Floor clearance a walk must end with to turn there by more than the heading
        tolerance, metres.
    stand_clearance : float
        Floor clearance of the spot a goal primitive starts from (hips and a slight
        forward lean need more room than the walking legs), metres.
    max_step_back : float
        How much further from the target than the preferred reach the worker may stand
        when an obstacle (a bench) is in the way; the goal primitive leans further.
    """

    heuristic_speed: float = SearchOptions.heuristic_speed
    turn_rate: float = SearchOptions.turn_rate
    budget: SearchBudget = field(default_factory=SearchBudget)
    cost_noise: float = SearchOptions.cost_noise
    reach_tolerance: float = 0.15
    heading_tolerance: float = 0.35
    body_radius: float = SearchOptions.body_radius
    goal_attempts: int = 6
    adjust_radius: float = 0.3
    turn_clearance: float = 0.26
    stand_clearance: float = 0.22
    max_step_back: float = 0.35
    grid_resolution: float = 0.05

    @property
    def search(self) -> SearchOptions:
        """The gait-search settings these options give."""
        return SearchOptions(body_radius=self.body_radius,
                             heuristic_speed=self.heuristic_speed,
                             turn_rate=self.turn_rate, cost_noise=self.cost_noise)


@dataclass
class StepPlan:
    """What the planner made for one task step.

    Attributes
    ----------
    task : str
        The step as written, e.g. ``"assemble(R1)"``.
    kind : str
        Goal-primitive task used (``"grasp"``, ``"assemble"``, ...) or ``"walk"``.
    target : ndarray, shape (3,) or None
    walk_segments : int
        Number of gait primitives walked before the task.
    goal_segment : int or None
        Index of the goal segment in the segment list.
    contact_frame : int or None
        Frame of the goal primitive where the task condition first holds.
    lift_frame : int or None
        For a grasp: the frame of the goal primitive from which the part is carried (it
        rests on its support until the hand lifts it, :func:`lift_frame`).
    hand : str or None
    expanded : int
        A* nodes expanded for this step.
    primitive : str
        Name of the goal primitive (or of the last gait primitive for walks).
    objects_effect : dict
        What the step does to the objects (``attach``, ``detach``, ...).
    sub_steps : list of StepPlan
        Steps the planner added before this one, e.g. the grasp of a part that
        carry/move/insert needs in hand; their effects come first.
    """

    task: str
    kind: str
    target: np.ndarray | None
    walk_segments: int = 0
    goal_segment: int | None = None
    first_segment: int = 0
    last_segment: int = 0
    contact_frame: int | None = None
    lift_frame: int | None = None
    hand: str | None = None
    expanded: int = 0
    primitive: str = ""
    objects_effect: dict = field(default_factory=dict)
    sub_steps: list[StepPlan] = field(default_factory=list)


@dataclass
class Plan:
    """Placed segments and the step plans that produced them."""

    segments: list[PlacedSegment]
    steps: list[StepPlan]
    start_pose: Pose
    expanded: int


def body_clear_every_frame(world: np.ndarray, cell, stature: float) -> bool:
    """Whether every frame of ``world`` (T, J, 3) keeps ``PLACED_MARGIN`` from the
    obstacles, with exact capsule distances: every ``CLEAR_STRIDE``-th frame is measured
    (exact up to ``CLEAR_EXACT``); the frames between two measured ones are measured too
    unless the joints' travel between them proves them clear (a capsule's distance to an
    obstacle changes by at most the largest joint displacement)."""
    from ltl_human_motion.scene.predicates import body_clearance
    T = len(world)
    idx = np.unique(np.r_[np.arange(0, T, CLEAR_STRIDE), T - 1])
    d = body_clearance(world[idx], cell, stature=stature, exact_below=CLEAR_EXACT)
    if np.min(d) <= PLACED_MARGIN:
        return False
    step = np.sqrt(np.max(np.sum(np.diff(world, axis=0) ** 2, axis=-1), axis=-1))   # (T-1,)
    travel = np.add.reduceat(step, idx[:-1]) if len(idx) > 1 else np.zeros(0)
    # Within a gap, every frame is within the gap's travel of both ends.
    safe = 0.5 * (d[:-1] + d[1:] - travel) > PLACED_MARGIN
    todo = [np.arange(idx[k] + 1, idx[k + 1]) for k in np.flatnonzero(~safe)]
    todo = np.concatenate(todo) if todo else np.zeros(0, dtype=int)
    if not todo.size:
        return True
    return bool(np.min(body_clearance(world[todo], cell, stature=stature,
                                      exact_below=0.01)) > PLACED_MARGIN)


def lift_frame(mp: MotionPrimitive, hand: np.ndarray) -> int:
    """The frame of a grasp primitive from which the part is carried: the first frame
    after the hold where the hand has risen ``LIFT_RISE`` above its contact height (the
    part rests on its support until then). The contact frame if the hand never rises.

    Parameters
    ----------
    mp : MotionPrimitive
        With ``meta["contact_frame"]`` and ``meta["hold_frames"]``.
    hand : ndarray, shape (T, 3)
        The gripping hand joint over the primitive's frames.
    """
    contact = int(mp.meta.get("contact_frame", 0))
    if contact >= len(hand):
        return contact
    hold_end = max(int(mp.meta.get("hold_frames", [contact, contact])[1]), contact)
    rose = np.flatnonzero(hand[hold_end:, 2] >= hand[contact, 2] + LIFT_RISE)
    return hold_end + int(rose[0]) if rose.size else contact


def grip_frame(mp: MotionPrimitive) -> int:
    """The frame of a goal primitive from which the hand holds the part it acts on: the
    contact frame, except for extract, where the hand takes the part when it reaches it
    (the start of the hold) and then pulls it out (its contact frame, where the part is
    out, is the end of the pull)."""
    if mp.task == "extract" and "hold_frames" in mp.meta:
        return int(mp.meta["hold_frames"][0])
    return int(mp.meta.get("contact_frame", mp.n_frames - 1))


class SequencePlanner:
    """Plans one task sequence in one cell with one motion library.

    Parameters
    ----------
    cell : Cell
    library : MotionLibrary
    rng : numpy.random.Generator
    options : PlannerOptions
    """

    def __init__(self, cell, library, rng: np.random.Generator,
                 options: PlannerOptions = PlannerOptions()) -> None:
        self.cell = cell
        self.library = library
        self.index = gait_index(library)
        self.rng = rng
        self.options = options
        self.clearance, self.obstacle_field = clearance_maps(cell)
        self.stand_map = stand_clearance_map(cell)
        self.overlap = int(library.overlap)
        self.segments: list[PlacedSegment] = []
        self.steps: list[StepPlan] = []
        self.pose: Pose = (0.0, 0.0, 0.0)
        self.gait_state: int | None = None          # None = standing
        self.seat: np.ndarray | None = None          # the seat sat on (3,); None: standing
        self.held: dict[str, str] = {}               # object -> hand joint
        self.consumed: set[str] = set()
        self.object_at: dict[str, np.ndarray] = {}   # where parts were put down (3,)
        self.held_offsets: dict[str, np.ndarray] = {}
        self._back_limit = options.reach_tolerance
        self._backs: dict[float, np.ndarray] = {}     # step-back distances per limit
        self.expanded = 0

    # ---------------------------------------------------------------- geometry
    def target_of(self, kind: str, args: tuple[str, ...]) -> np.ndarray | None:
        """Where a step acts, shape (3,): grasp point, region or object centre, seat; the
        region's centre for walk/carry; None for tasks in place (wait, bend, ...)."""
        cell = self.cell
        if kind in ("walk", "carry"):
            return np.asarray(cell.region(args[-1]).center, dtype=np.float64)
        if kind in ("grasp",):
            obj = cell.object(args[0])
            point = np.asarray(obj.grasp_points_at(self.object_position(args[0]))[0],
                               dtype=np.float64)
            return self._palm_clear_of_support(point, args[0])
        if kind in ("move",):
            return np.asarray(cell.region(args[1]).center, dtype=np.float64)
        if kind in ("insert", "extract"):
            return self.object_position(args[1])
        if kind in ("leftHand", "rightHand", "assemble"):
            return np.asarray(cell.region(args[0]).center, dtype=np.float64)
        if kind == "sit":
            obj = cell.object(args[0])
            return np.asarray(obj.sitting_surface_at(obj.position).center, dtype=np.float64)
        return None

    def _palm_clear_of_support(self, point: np.ndarray, obj: str) -> np.ndarray:
        """The palm target (3,) for a grasp at ``point`` (3,): the grasp point, raised by
        up to the palm's radius where the palm sphere there would touch the support (a
        flat part on a board): grasp holds while the palm still enters the part."""
        cell = self.cell
        if not cell.obstacles:
            return point
        from ltl_human_motion.scene.occupancy import BODY_PARTS, capsule_radii
        radius = float(capsule_radii(self.library.skeleton.stature)[BODY_PARTS.index("r_palm")])
        part = cell.object(obj).occupancy_at(self.object_position(obj))
        for rise in np.arange(0.0, radius, PALM_RISE_STEP):
            palm = point + np.array([0.0, 0.0, rise])
            clear = float(cell.part_set.capsule_clearance(np.stack([palm, palm])[None],
                                                          radius)[0])
            if clear > PALM_SUPPORT_GAP:
                inside = float(part.signed_distance(palm[None])[0])
                return palm if inside <= radius - PALM_IN_PART else point
        return point

    def object_position(self, name: str) -> np.ndarray:
        """Where object ``name`` rests now (3,): where the last step put it down, else its
        supply position in the cell."""
        at = self.object_at.get(name)
        return np.asarray(self.cell.object(name).position if at is None else at,
                          dtype=np.float64)

    def _acting_hand(self, kind: str, part: str | None) -> str | None:
        """The hand a goal task must use, or None (either): a move, insert or release of
        a held ``part`` uses the hand holding it; a grasp or extract while one hand holds
        a part uses the other hand."""
        if part is not None and part in self.held and kind in ("move", "insert", "release"):
            return self.held[part]
        busy = set(self.held.values())
        if kind in ("grasp", "extract") and len(busy) == 1:
            return OTHER_HAND[next(iter(busy))]
        return None

    def _placement(self, kind: str, target: np.ndarray, task: str,
                   hand: str | None = None) -> tuple[float, float]:
        """Where the target should be in the standing root's frame: (ahead, left), metres
        (for ``hand``, if given: the left hand reaches a target on the left)."""
        from ltl_human_motion.motion import goals
        low = self._low_board(target) if kind in LEVEL_PATH_TASKS else None
        try:
            d, lat = goals.reach_placement(kind, float(target[2]), self.library.skeleton,
                                           hand=hand or "auto",
                                           board=None if low is None else low[:3])
            return float(d), float(lat)
        except ValueError as exc:
            raise PlanningError(f"task {task}: the target at height {target[2]:.2f} m is "
                                f"unreachable: {exc}", task=task, reason="unreachable") from None

    def _low_board(self, target: np.ndarray
                   ) -> tuple[float, float, float, np.ndarray] | None:
        """The lowest obstacle part over ``target`` (3,) with its underside above it and
        below ``LOW_BOARD_HEIGHT`` of the stature: (depth of the target behind the
        part's nearest edge, underside, top in metres, the edge's outward normal (2,));
        None if there is none."""
        highest = LOW_BOARD_HEIGHT * self.library.skeleton.stature
        best = None
        xy = np.asarray(target[:2], dtype=np.float64)
        probe = xy + np.array([[0.0, 0.0], [1e-3, 0.0], [0.0, 1e-3]])
        for ob in self.cell.obstacles:
            for part in ob.parts:
                lo, hi = part.aabb()
                if not (float(target[2]) < float(lo[2]) <= highest
                        and (best is None or float(lo[2]) < best[1])):
                    continue
                sd = part.footprint().signed_distance(probe)
                if sd[0] <= 0.0:
                    grad = sd[1:] - sd[0]
                    normal = grad / max(float(np.linalg.norm(grad)), 1e-12)
                    best = (-float(sd[0]), float(lo[2]), float(hi[2]), normal)
        return best

    def _board_local(self, target: np.ndarray, local: np.ndarray
                     ) -> tuple[float, float, float] | None:
        """The low board over ``target`` (world (3,); ``local``: it in the start frame of
        the goal primitive) as the goal primitive takes it: (edge x, underside, top),
        the edge's nearest x within ``BOARD_EDGE_SPAN`` either side of the target."""
        low = self._low_board(target)
        if low is None:
            return None
        c, s = math.cos(-self.pose[2]), math.sin(-self.pose[2])
        n = np.array([c * low[3][0] - s * low[3][1], s * low[3][0] + c * low[3][1]])
        edge = float(local[0]) + low[0] * n[0] - BOARD_EDGE_SPAN * abs(n[1])
        return edge, low[1], low[2]

    def _clearance(self, xy: np.ndarray) -> np.ndarray:
        return self.clearance(xy)

    def _field(self, goal_cells, key: tuple | None = None, squeeze: bool = False
               ) -> NavigationField:
        """The navigation field of ``goal_cells`` on the floor grid. ``goal_cells(xy (N, 2),
        clearance) -> bool (N,)`` gets the clearance map of the grid it is solved on.
        ``key``: numbers that determine the goal cells on this floor; fields with a key
        are kept (a target that does not move between items, e.g. an assembly region,
        reuses its field).

        The field keeps to lanes with ``PASSAGE_RADIUS`` of clearance where they lead from
        the worker to a goal; else it uses all floor the walk may take, counting floor
        with less clearance longer. Either way the search does not squeeze the gait
        through a gap the body barely fits (and exhaust its budget there) where a roomier
        way exists. With ``squeeze`` (where the walking map leaves no way at all: a
        narrow aisle between racks, see :meth:`_led`) the field is solved on the
        footprint map (:attr:`stand_map`, no allowance for the arms at tall parts),
        whose walks the search keeps clear with the whole-body check. The walk keeps its
        clearance on ``field.grid.clearance``."""
        if squeeze:
            return self._field_with(self.stand_map, self.options.body_radius, goal_cells, key)
        roomy = self._field_with(self.clearance, PASSAGE_RADIUS, goal_cells, key)
        if self._leads(roomy):
            return roomy
        return self._field_with(self.clearance, self.options.body_radius, goal_cells, key)

    def _leads(self, field: NavigationField) -> bool:
        """Whether ``field`` leads from the worker's spot to a goal cell."""
        return field.has_goal and field.reachable_from(self.pose[0], self.pose[1])

    def _led(self, solve: Callable[[bool], tuple]) -> tuple:
        """``solve(False)`` (a field on the walking map, and what made it), or where that
        field leads nowhere and ``solve(True)``'s (the squeeze, see :meth:`_field`) does,
        the latter."""
        plain = solve(False)
        if self._leads(plain[0]):
            return plain
        squeezed = solve(True)
        return squeezed if self._leads(squeezed[0]) else plain

    def _field_with(self, clearance, radius: float, goal_cells, key: tuple | None
                    ) -> NavigationField:
        """:meth:`_field` on the floor grid of map ``clearance`` whose free cells keep
        ``radius``."""
        passage = SQUEEZE_PASSAGE if clearance is self.stand_map else PASSAGE_RADIUS
        grid = floor_grid(clearance, self.cell.workspace_lo[:2],
                          self.cell.workspace_hi[:2], radius, self.options.grid_resolution,
                          passage=passage if radius < passage else None)
        cells = functools.partial(goal_cells, clearance=clearance)
        if key is None:
            return NavigationField.on_grid(grid, cells)
        full = (id(grid), *key)
        hit = _FIELD_CACHE.get(full)
        if hit is not None and hit[0] is grid:         # the grid is held, its id unique
            return hit[1]
        field = NavigationField.on_grid(grid, cells)
        if len(_FIELD_CACHE) >= 16:
            _FIELD_CACHE.pop(next(iter(_FIELD_CACHE)))
        _FIELD_CACHE[full] = (grid, field)
        return field

    def _goal_from_field(self, field: NavigationField, reached, desc: str, task: str,
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
        if not field.reachable_from(self.pose[0], self.pose[1]):
            raise PlanningError(f"task {task}: {desc}: obstacles block every way from "
                                f"({self.pose[0]:.2f}, {self.pose[1]:.2f})", task=task,
                                reason="blocked")
        slack = 0.5 * self.options.grid_resolution

        def distance(x: np.ndarray, y: np.ndarray) -> np.ndarray:
            return np.maximum(field.distance(x, y) - slack, 0.0)

        def reroute(at: tuple[float, float]) -> Goal | None:
            around = field.without(at, STALL_BLOCK_RADIUS)
            if not (around.has_goal and around.reachable_from(self.pose[0], self.pose[1])):
                return None
            return self._goal_from_field(around, reached, desc, task, heading)

        return Goal(reached, distance, field.heading if heading is None else heading(field),
                    desc, clearance=field.grid.clearance, reroute=reroute)

    def _ideal_placement(self, target: np.ndarray, placement: tuple[float, float],
                         x: np.ndarray, y: np.ndarray, room: bool = False,
                         walk_map: Callable[[np.ndarray], np.ndarray] | None = None
                         ) -> tuple[np.ndarray, ...]:
        """Root pose (x*, y*, yaw*) from which the goal primitive reaches ``target``,
        facing it from the side of (x, y), and whether that spot is free.

        Where the ideal spot is too close to an obstacle (a bench in front), the worker
        stands up to ``max_step_back`` further back. Arrays shaped like ``x``. With
        ``room``, also the floor clearance at (x, y) itself on ``walk_map`` (default the
        walking map).
        """
        d, lat = placement
        yaw = np.arctan2(target[1] - y, target[0] - x) - np.arctan2(lat, d)
        c, s = np.cos(yaw), np.sin(yaw)
        back = self._backs.get(self._back_limit)
        if back is None:
            back = self._backs[self._back_limit] = np.linspace(0.0, self._back_limit, 8)
        px = target[0] - (c[..., None] * (d + back) - s[..., None] * lat)
        py = target[1] - (s[..., None] * (d + back) + c[..., None] * lat)
        pts = np.stack([px, py], axis=-1).reshape(-1, 2)
        free = self.stand_map(pts).reshape(px.shape) > self.options.stand_clearance
        k = np.argmax(free, axis=-1)
        pick = np.take_along_axis
        out = (pick(px, k[..., None], -1)[..., 0], pick(py, k[..., None], -1)[..., 0], yaw,
               free.any(axis=-1))
        if not room:
            return out
        walk_map = self._clearance if walk_map is None else walk_map
        return (*out, walk_map(np.stack([x, y], axis=-1).reshape(-1, 2)).reshape(np.shape(x)))

    def _reach_goal(self, target: np.ndarray, placement: tuple[float, float], desc: str,
                    task: str, adjust: float | None = None,
                    sector: tuple[float, float] | None = None) -> Goal:
        """Walk until a standing adjustment (a step of at most ``adjust``, default
        ``options.adjust_radius``, and a turn) puts the worker where the goal primitive
        reaches the target; with ``sector`` (direction from the target, half width, rad)
        only from that side."""
        tx, ty = float(target[0]), float(target[1])

        def side(x: np.ndarray, y: np.ndarray) -> np.ndarray:
            if sector is None:
                return np.ones(np.shape(x), dtype=bool)
            return np.abs(wrap_angle(np.arctan2(y - ty, x - tx) - sector[0])) <= sector[1]

        tol = self.options.reach_tolerance
        dist = float(np.hypot(*placement))
        offset = float(np.arctan2(placement[1], placement[0]))
        adjust = self.options.adjust_radius if adjust is None else float(adjust)

        def ring(xy: np.ndarray, clearance=None) -> np.ndarray:
            r = np.hypot(tx - xy[:, 0], ty - xy[:, 1])
            out = (r >= dist - tol) & (r <= dist + self._back_limit) & side(xy[:, 0], xy[:, 1])
            # The floor clearance only where the distance fits (few of the cells).
            out[out] = self.stand_map(xy[out]) > self.options.stand_clearance
            return out

        def near_ring(xy: np.ndarray, clearance=None) -> np.ndarray:
            # Where a walk may end to step in (a rack: the walking map keeps tall
            # parts further off than a worker standing at them needs).
            r = np.hypot(tx - xy[:, 0], ty - xy[:, 1])
            return ((r >= dist - tol) & (r <= dist + self._back_limit + adjust)
                    & side(xy[:, 0], xy[:, 1]))

        def reached(x: np.ndarray, y: np.ndarray, yaw: np.ndarray) -> np.ndarray:
            px, py, pyaw, free, here = self._ideal_placement(target, placement, x, y,
                                                             room=True, walk_map=walk_map)
            # Turning on the spot needs room for the hips; facing nearly right needs none.
            room = here > self.options.turn_clearance
            facing = np.abs(wrap_angle(pyaw - yaw)) <= self.options.heading_tolerance
            return free & (np.hypot(px - x, py - y) <= adjust) & (room | facing) & side(x, y)

        # Stand within the reach tolerance where possible; only where an obstacle leaves
        # no such place (a tall worker at a bench) stand up to max_step_back further.
        def ring_key() -> tuple:
            return ("ring", tx, ty, dist, tol, float(self._back_limit),
                    float(self.options.stand_clearance), sector)

        def solve(squeeze: bool) -> tuple[NavigationField, float]:
            self._back_limit = tol
            field = self._field(ring, ring_key(), squeeze)
            if not field.has_goal:
                self._back_limit = self.options.max_step_back
                field = self._field(ring, ring_key(), squeeze)
            if not field.has_goal:
                field = self._field(near_ring, ("near", *ring_key(), adjust), squeeze)
            return field, self._back_limit

        field, self._back_limit = self._led(solve)
        walk_map = field.grid.clearance                # read by reached()

        def heading(led: NavigationField) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
            def towards(x: np.ndarray, y: np.ndarray) -> np.ndarray:
                near = np.hypot(tx - x, ty - y) <= dist + 2 * tol
                return np.where(near, np.arctan2(ty - y, tx - x) - offset, led.heading(x, y))
            return towards

        return self._goal_from_field(field, reached, desc, task, heading)

    def _adjust_to(self, target: np.ndarray, placement: tuple[float, float], task: str) -> bool:
        """Step and turn on the spot to the ideal placement for ``target`` (if needed).

        If that step would touch an obstacle, stand a little further back (up to 15 cm).
        Returns False if no adjustment is clear (the worker stays where the walk ended).
        """
        from ltl_human_motion.planning.turns import make_step_primitive
        x, y, yaw = self.pose
        px, py, pyaw, _ = (float(v[0]) for v in self._ideal_placement(
            target, placement, np.array([x]), np.array([y])))
        carrying = bool(self.held)
        back_dir = np.array([math.cos(pyaw), math.sin(pyaw)])
        c, s = math.cos(yaw), math.sin(yaw)
        stance = self._stance(carrying)
        task_name = "carry" if carrying else "walk"
        lib = self.library

        def step(dx: float, dy: float, dyaw: float) -> MotionPrimitive:
            return make_step_primitive(stance, lib.standing_height, dx, dy, dyaw, lib.skeleton,
                                       lib.fps, task_name)

        for back in (0.0, 0.05, 0.1, 0.15):
            qx, qy = px - back * back_dir[0], py - back * back_dir[1]
            dx, dy = c * (qx - x) + s * (qy - y), -s * (qx - x) + c * (qy - y)
            dyaw = float(wrap_angle(pyaw - yaw))
            if math.hypot(dx, dy) < 0.02 and abs(dyaw) < 0.05:
                return True
            # Step and turn at once; or turn where the walk ended, then step in. The
            # primitives are made when tried (the first plan is usually clear).
            cp, sp = math.cos(dyaw), math.sin(dyaw)
            plans = [((dx, dy, dyaw),),
                     ((0.0, 0.0, dyaw), (cp * dx + sp * dy, -sp * dx + cp * dy, 0.0))]
            for moves in plans:
                pose = self.pose
                plan = []
                for move in moves:
                    mp = step(*move)
                    if not self._placed_clear(mp, pose):
                        break
                    plan.append(mp)
                    pose = self._hand_over_pose(mp, pose)
                if len(plan) == len(moves):
                    for mp in plan:
                        self._add(mp, self.pose, -1, self.overlap)
                        self.pose = self._hand_over_pose(mp, self.pose)
                    return True
        return False

    def _region_goal(self, region, desc: str, task: str) -> Goal:
        """Walk until the standing body enters ``region`` (the verifier's predicate).

        The goal cells of the heuristic are the spots with room to turn
        (``turn_clearance``) from which the standing body enters the region facing some
        heading; none (a region above a bench, beside a wall) makes the region
        unreachable on foot (the caller reaches into it by hand).
        """
        from ltl_human_motion.scene.occupancy import capsule_radii
        stature = self.library.skeleton.stature
        carrying = bool(self.held)
        entry = RegionEntry(region, self._stance(carrying), self.library.standing_height,
                            stature, float(capsule_radii(stature).max()))
        room = self.options.turn_clearance

        def cells(xy: np.ndarray, clearance: Callable[[np.ndarray], np.ndarray]
                  ) -> np.ndarray:
            out = entry.cells(xy)
            out[out] = clearance(xy[out]) > room
            return out

        key = ("region", *entry.lo.tolist(), *entry.hi.tolist(), stature, carrying, room)
        field, = self._led(lambda squeeze: (self._field(cells, key, squeeze),))
        return self._goal_from_field(field, entry.enters, desc, task)

    # ---------------------------------------------------------------- segments
    def _add(self, mp: MotionPrimitive, pose: Pose, label: int, blend: int) -> int:
        pos = world_positions(mp, *pose)
        yaw = pose[2] + mp.root[:, 3]
        self.segments.append(PlacedSegment(pos, yaw, label, blend if self.segments else 0,
                                           mp.name))
        return len(self.segments) - 1

    def _hand_over_pose(self, mp: MotionPrimitive, pose: Pose) -> Pose:
        k = max(mp.n_frames - self.overlap, 0)
        r = mp.root[k]
        c, s = math.cos(pose[2]), math.sin(pose[2])
        return (pose[0] + c * r[0] - s * r[1], pose[1] + s * r[0] + c * r[1], pose[2] + r[3])

    def _stand_still(self, label: int, seconds: float) -> None:
        """A short standing segment (start of the motion, end of a walk task)."""
        n = max(round(seconds * self.library.fps), self.overlap + 2)
        rel = np.repeat(self._stance(bool(self.held))[None], n, axis=0)
        root = np.zeros((n, 4))
        root[:, 2] = self.library.standing_height
        mp = MotionPrimitive("stand", "wait", rel, root, self.library.fps, "planner: stand")
        self._add(mp, self.pose, label, self.overlap)

    def _body_clear(self, poses: np.ndarray, standing: np.ndarray) -> np.ndarray:
        """Whether sampled poses (M, S, J, 3) keep 1 cm from every obstacle, shape (M,);
        standing primitives (``standing`` (M,)) need only not come closer."""
        out = np.ones(len(poses), dtype=bool)
        stature = self.library.skeleton.stature
        for rel in (False, True):
            sel = standing == rel
            if sel.any():
                out[sel] = self.obstacle_field.clear(poses[sel], stature, relative=rel)
        return out

    def _sit_still(self, seconds: float) -> MotionPrimitive:
        """A wait on the seat: the seated pose held (the standing wait model would rebuild
        the legs for standing)."""
        pose = self._seated_pose()
        n = max(round(seconds * self.library.fps), self.overlap + 2)
        root = np.zeros((n, 4))
        root[:, :3] = pose[0]
        rel = np.repeat((pose - pose[0])[None], n, axis=0)
        return MotionPrimitive(f"sit_still_{seconds:.2f}s", "wait", rel, root,
                               self.library.fps, "planner: seated wait",
                               meta={"contact_frame": n - 1, "hand": "none"})

    def _seated_pose(self) -> np.ndarray:
        """The last frame placed (the worker seated), in the start frame of the current
        pose (root floor point at the origin, facing +x; heights above the floor), (J, 3)."""
        x, y, yaw = self.pose
        last = self.segments[-1].positions[-1]
        c, s = math.cos(-yaw), math.sin(-yaw)
        dx, dy = last[:, 0] - x, last[:, 1] - y
        return np.stack([c * dx - s * dy, s * dx + c * dy, last[:, 2]], axis=-1)

    def _stance(self, carrying: bool) -> np.ndarray:
        lib = self.library
        return np.asarray(lib.carry_standing_pose if carrying else lib.standing_pose)

    def _arm_transition(self, carrying_before: bool, label: int) -> None:
        """Bring the arms from the walk stance to the carry stance or back.

        The palms move beside the body on a smooth curve, timed by Fitts' law with a
        bounded peak speed (:func:`~ltl_human_motion.motion.arm_transition.
        arm_transition_poses`).
        """
        rel = self._arm_poses(carrying_before)
        root = np.zeros((len(rel), 4))
        root[:, 2] = self.library.standing_height
        mp = MotionPrimitive("arms_to_carry" if not carrying_before else "arms_to_walk", "wait",
                             rel, root, self.library.fps, "planner: arm transition")
        if not self._placed_clear(mp, self.pose) and not self._step_back(carrying_before,
                                                                           label, mp):
            raise PlanningError(f"bringing the arms {'down' if carrying_before else 'up'} at "
                                f"({self.pose[0]:.2f}, {self.pose[1]:.2f}) hits an obstacle, "
                                "also after a step back", reason="blocked")
        self._add(mp, self.pose, label, self.overlap)

    def _arm_poses(self, carrying_before: bool) -> np.ndarray:
        """Root-relative poses (T, J, 3) of the arm transition (made once per library and
        direction: it depends on nothing else)."""
        from ltl_human_motion.motion.arm_transition import arm_transition_poses
        from ltl_human_motion.motion.retarget import enforce_bone_lengths
        key = (self._stance(False).tobytes(), self._stance(True).tobytes(),
               self.library.skeleton.stature, self.library.fps, self.overlap,
               bool(carrying_before))
        hit = _ARM_POSES.get(key)
        if hit is not None:
            return hit
        a, b = self._stance(carrying_before), self._stance(not carrying_before)
        rel = arm_transition_poses(a, b, self.library.skeleton, self.library.fps)
        if len(rel) < self.overlap + 2:
            rel = np.concatenate([rel, np.repeat(rel[-1:], self.overlap + 2 - len(rel), 0)])
        # The pipeline restores bone lengths after blending, so the transition is checked
        # as it will be played.
        rel = enforce_bone_lengths(rel, self.library.skeleton)
        rel.flags.writeable = False
        if len(_ARM_POSES) >= 32:
            _ARM_POSES.clear()
        _ARM_POSES[key] = rel
        return rel

    def _placed_clear(self, mp: MotionPrimitive, pose: Pose, samples: int | None = None,
                      world: np.ndarray | None = None) -> bool:
        """Whether ``mp`` placed at ``pose`` keeps the body and the objects held (at their
        hand offsets) clear of every obstacle, checked with the exact distances on
        ``samples`` frames (None: every frame, as the verifier checks). ``world``:
        ``world_positions(mp, *pose)`` if already made."""
        from ltl_human_motion.scene.predicates import body_clearance, object_clearance
        if not self.cell.obstacles:
            return True
        stature = self.library.skeleton.stature
        if samples is None:
            world = world_positions(mp, *pose) if world is None else world
            if not body_clear_every_frame(world, self.cell, stature):
                return False
        else:
            frames = np.linspace(0, mp.n_frames - 1, samples).round().astype(int)
            if world is None and self.held:
                world = world_positions(mp, *pose)
            body = world_positions(mp, *pose, frames=frames) if world is None else world[frames]
            # Only clearances up to the PLACED_MARGIN limit matter: those are exact.
            d = body_clearance(body, self.cell, stature=stature, exact_below=0.01)
            if np.min(d) <= PLACED_MARGIN:
                return False
        for name, joint in self.held.items():
            step = 1 if samples is None else 2
            centre = world[::step, JOINT_INDEX[joint]] + self.held_offsets.get(name, np.zeros(3))
            if np.any(object_clearance(self.cell, name, centre) <= 0.0):
                return False
        return True

    def _step_out(self) -> None:
        """Step back onto walkable floor if the worker stands closer to an obstacle than a
        walk may start (at a rack, where reaching allowed it): the search could not
        leave the spot otherwise."""
        from ltl_human_motion.planning.turns import make_step_primitive
        x, y, yaw = self.pose
        if self._walkable(x, y):
            return
        carrying = bool(self.held)
        lib = self.library
        c, s = math.cos(yaw), math.sin(yaw)
        for back in STEP_OUT_DISTANCES:
            if not self._walkable(x - back * c, y - back * s):
                continue
            mp = make_step_primitive(self._stance(carrying), lib.standing_height, -back, 0.0,
                                     0.0, lib.skeleton, lib.fps,
                                     "carry" if carrying else "walk")
            if self._placed_clear(mp, self.pose, samples=None):
                self._add(mp, self.pose, -1, self.overlap)
                self.pose = self._hand_over_pose(mp, self.pose)
                return

    def _walkable(self, x: float, y: float) -> bool:
        """Whether a walk may start at (x, y): ``STEP_OUT_MARGIN`` more floor clearance
        than ``options.body_radius``, and the navigation grid's cell there is free (the
        searches start from that cell)."""
        if float(self._clearance(np.array([[x, y]]))[0]) <= (self.options.body_radius
                                                               + STEP_OUT_MARGIN):
            return False
        grid = floor_grid(self.clearance, self.cell.workspace_lo[:2],
                          self.cell.workspace_hi[:2], self.options.body_radius,
                          self.options.grid_resolution, passage=PASSAGE_RADIUS)
        i = int(np.clip(np.rint((x - grid.lo[0]) / grid.res), 0, grid.shape[0] - 1))
        j = int(np.clip(np.rint((y - grid.lo[1]) / grid.res), 0, grid.shape[1] - 1))
        return bool(grid.free[i, j])

    def _first_collision(self, primitives: list[int], poses: list[Pose]) -> int | None:
        """Index of the first gait primitive of a path that comes within the planner's
        margin of an obstacle on any frame (body or held parts), or None; what
        :meth:`_placed_clear` checks on every frame, in one pass over the whole path."""
        from ltl_human_motion.scene.predicates import body_clearance, object_clearance
        if not self.cell.obstacles or not primitives:
            return None
        worlds = [world_positions(self.index.primitives[p], *pose)
                  for p, pose in zip(primitives, poses)]
        ends = np.cumsum([len(w) for w in worlds])
        world = np.concatenate(worlds)
        bad = body_clearance(world, self.cell, stature=self.library.skeleton.stature,
                             exact_below=0.01) <= PLACED_MARGIN
        for name, joint in self.held.items():
            centre = world[:, JOINT_INDEX[joint]] + self.held_offsets.get(name, np.zeros(3))
            bad |= object_clearance(self.cell, name, centre) <= 0.0
        if not bad.any():
            return None
        return int(np.searchsorted(ends, int(np.argmax(bad)), side="right"))

    def _step_back(self, carrying: bool, label: int, then: MotionPrimitive) -> bool:
        """Step back from an obstacle in front so that ``then`` is clear afterwards: the
        gait index's 0.3 m step back, else a model-made step of ``STEP_OUT_DISTANCES``,
        else a step aside of ``SIDE_STEPS`` (a board at elbow height beside the worker,
        in an aisle). Returns False (nothing added) when no step and ``then`` are both
        clear."""
        from ltl_human_motion.planning.turns import make_step_primitive
        task = "carry" if carrying else "walk"
        lib = self.library

        def steps():
            yield from [mp for mp in self.index.primitives
                        if mp.task == task and mp.meta.get("step") == [-0.3, 0.0]
                        and not mp.meta.get("turn")][:1]
            moves = [(-back, 0.0) for back in STEP_OUT_DISTANCES] + [(0.0, side)
                                                                     for side in SIDE_STEPS]
            for dx, dy in moves:                       # made when tried
                yield make_step_primitive(self._stance(carrying), lib.standing_height, dx, dy,
                                          0.0, lib.skeleton, lib.fps, task)

        for mp in steps():
            pose = self._hand_over_pose(mp, self.pose)
            if self._placed_clear(mp, self.pose) and self._placed_clear(then, pose):
                self._add(mp, self.pose, label, self.overlap)
                self.pose = pose
                return True
        return False

    def _walk(self, goal: Goal, task: str, label: int, carry: bool,
              budget: SearchBudget | None = None) -> int:
        """A* from the current pose; appends the gait segments; returns their count.

        The search checks the body on sampled frames of a distance grid; every frame of
        the path it returns is then checked as the verifier does (exact capsules, held
        parts). A primitive that collides is forbidden from its pose and the search runs
        again (at most ``WALK_REPAIRS`` times)."""
        forbidden: set[tuple[int, int, int, int]] = set()
        noise_state = self.rng.bit_generator.state
        budget = budget or self.options.budget
        if goal.clearance is self.stand_map:
            budget = replace(budget, max_nodes=min(budget.max_nodes, SQUEEZE_NODES))
        used, repairs, reroutes = 0, 0, 0
        while True:
            self.rng.bit_generator.state = noise_state      # the same costs every time
            stall = STALL_NODES if goal.reroute is not None and reroutes < MAX_REROUTES \
                else None
            res = astar(self.index, self.pose, goal, start_primitive=self.gait_state,
                        clearance=goal.clearance or self._clearance,
                        options=self.options.search, carry=carry,
                        budget=replace(budget, max_nodes=budget.max_nodes - used),
                        rng=self.rng, body_clear=self._body_clear, forbidden=frozenset(forbidden),
                        stall_nodes=stall)
            self.expanded += res.expanded
            used += res.expanded
            if isinstance(res, SearchFailure) and res.reason == "stalled":
                # Walk around the spot the search could not get past, or search on.
                reroutes += 1
                goal = goal.reroute(res.closest_at) or replace(goal, reroute=None)
                continue
            if isinstance(res, SearchFailure):
                break
            bad = self._first_collision(res.primitives, res.poses)
            if bad is None:
                break
            forbidden |= self._forbid(res.primitives, res.poses, bad)
            repairs += 1
            if repairs > WALK_REPAIRS:
                raise PlanningError(f"task {task}: {goal.description}: every path found "
                                    f"({WALK_REPAIRS + 1}) collides on a frame the search "
                                    "did not sample", task=task, reason="blocked")
        if isinstance(res, SearchFailure):
            if res.reason == "budget":
                why = (f"the search budget ran out ({used} nodes; closest approach "
                       f"{res.closest:.2f} m)")
            else:
                why = (f"obstacles block every way to the target (searched {res.expanded} "
                       f"placements; closest approach {res.closest:.2f} m)")
            raise PlanningError(f"task {task}: {goal.description}: {why}", task=task,
                                reason=res.reason)
        for prim_id, pose in zip(res.primitives, res.poses):
            self._add(self.index.primitives[prim_id], pose, label, self.overlap)
        if res.primitives:
            self.pose = res.end_pose
            self.gait_state = None  # every walk ends with a stop primitive
        return len(res.primitives)

    def _forbid(self, primitives: list[int], poses: list[Pose], bad: int
                ) -> set[tuple[int, int, int, int]]:
        """What a search must not take again after primitive ``bad`` of its path collided:
        that primitive from its pose, and where it is a stop (the arms swing forward as
        the worker stops at furniture) that ends a walk, every gait stop from there and
        from the neighbouring closed-set cells: the stops from one spot sweep nearly the
        same space, and forbidding them one at a time, one cell at a time, used up the
        ``WALK_REPAIRS``."""
        i, j, k = placement_key(*poses[bad])
        prim = primitives[bad]
        if bad == 0 or not self.index.stops[prim] or self.index.standing[prim]:
            return {(prim, i, j, k)}               # the first move, a turn on the spot
        stops = np.flatnonzero(self.index.stops & ~self.index.standing).tolist()
        return {(int(p), i + di, j + dj, k) for p in stops
                for di in (-1, 0, 1) for dj in (-1, 0, 1)}

    # ---------------------------------------------------------------- tasks
    def plan(self, tasks: list[TaskStep], start: Pose) -> Plan:
        """Plan every step (:func:`~ltl_human_motion.vocabulary.task_step` makes them)."""
        self.pose = start
        self._stand_still(-1, 0.3)
        for i, task in enumerate(tasks):
            first = len(self.segments)
            facing = self._seated_work(tasks[i + 1:]) if task.kind == "sit" else None
            step = self._plan_step(i, task.text, task.kind, task.args, facing=facing)
            step.first_segment = first
            step.last_segment = len(self.segments) - 1
            self.steps.append(step)
        if self.seat is None:
            self._stand_still(-1, 0.3)
        else:                                # the motion ends seated: stay on the seat
            self._add(self._sit_still(0.3), self.pose, -1, self.overlap)
        return Plan(self.segments, self.steps, start, self.expanded)

    def _seated_work(self, rest: list[TaskStep]) -> np.ndarray | None:
        """Target (3,) of the first hand task done seated after a sit (the tasks in
        ``rest``, up to the first that needs standing), or None."""
        for task in rest:
            if task.kind in SEATED_HAND_TASKS:
                return self.target_of(task.kind, task.args)
            if task.kind != "wait":
                return None
        return None

    def _plan_step(self, i: int, text: str, kind: str, args: tuple[str, ...],
                   keep_hold: bool = False, facing: np.ndarray | None = None) -> StepPlan:
        """Plan step ``i`` (``text``) as the goal task ``kind``; ``keep_hold``: a part a
        move puts into its region stays in hand (carry); ``facing``: for sit, where the
        seated worker will work (sit facing it)."""
        expanded0 = self.expanded
        if self.seat is None:
            self._step_out()
        if self.seat is not None and (
                kind not in ("standUp", "wait", "sit", *SEATED_HAND_TASKS)
                or (kind in SEATED_HAND_TASKS and self._beyond_seated_reach(kind, args))):
            self._goal_segment("standUp", self.seat, -1, text)
            self.seat = None
        if kind == "sit" and self.seat is not None:
            seat = self.target_of(kind, args)
            if seat is not None and float(np.linalg.norm(seat - self.seat)) <= SAME_SEAT_DISTANCE:
                # Already on this seat: sit holds while the worker stays seated (standing
                # up to sit down again would be a needless double transition).
                seg = self._add(self._sit_still(STAND_UP_IN_PLACE_SECONDS), self.pose, i,
                                self.overlap)
                return StepPlan(text, "sit (seated)", self.seat, goal_segment=seg,
                                contact_frame=0, primitive=self.segments[seg].name)
            self._goal_segment("standUp", self.seat, -1, text)     # to sit on another seat
            self.seat = None
        if kind == "carry":
            # carry(O, R) holds when the body enters R with O inside it: the held part is
            # put into R by hand (so the palm enters R too), and it stays in hand.
            step = self._plan_step(i, text, "move", args, keep_hold=True)
            return replace(step, kind="carry (by move)")
        if kind == "walk":
            region = self.cell.region(args[-1])
            subs: list[StepPlan] = []
            try:
                goal = self._region_goal(region, f"walk into {region.name}", text)
            except PlanningError as exc:
                if exc.reason != "unreachable":
                    raise
                # Nowhere to stand in the region (e.g. a box above a bench). Its entry,
                # enter(x, R), holds once any body part is in it: reach in with a hand.
                return self._reach_into(i, text, args, exc)
            n = self._walk(goal, text, i, carry=bool(self.held))
            self._stand_still(i, 0.25)
            return StepPlan(text, kind, np.asarray(region.center, dtype=float), walk_segments=n,
                            expanded=self.expanded - expanded0,
                            primitive=f"{n} gait primitives", sub_steps=subs)
        if kind == "standUp" and self.seat is None:
            # Already standing (every bend, stoop and kneel ends upright): standUp holds
            # once the worker stands still for a moment.
            self._stand_still(i, STAND_UP_IN_PLACE_SECONDS)
            return StepPlan(text, "standUp (standing)", None, expanded=0, primitive="stand")
        return self._goal_step(i, text, kind, args, keep_hold, facing, expanded0)

    def _beyond_seated_reach(self, kind: str, args: tuple[str, ...]) -> bool:
        """Whether the target of a hand task lies further from the seat than even a
        standing worker reaches at its height (the worker stands up and walks to it)."""
        target = self.target_of(kind, args)
        if target is None or self.seat is None:
            return False
        envelope = reach_envelope(self.library.skeleton.stature)
        away = float(np.hypot(*(np.asarray(target[:2]) - np.asarray(self.seat[:2]))))
        return away > envelope.horizontal(float(target[2]), float(target[2]))

    def _goal_step(self, i: int, text: str, kind: str, args: tuple[str, ...],
                   keep_hold: bool, facing: np.ndarray | None, expanded0: int) -> StepPlan:
        """A step done with a goal primitive (hand tasks, postures, sit): fetch the part
        if needed, walk to the placement, make the primitive (trying the alternatives
        when it is blocked) and follow its effect on the parts (see :meth:`_plan_step`;
        ``expanded0``: nodes expanded before the step)."""
        subs = []
        if kind in ("move", "insert", "release") and args[0] not in self.held:
            # The part is fetched first, as for carry(O, R).
            subs.append(self._fetch(i, args[0]))
        respawn = kind == "grasp" and args[0] in self.consumed
        if respawn:
            self.consumed.discard(args[0])           # a fresh part from the supply
            self.object_at.pop(args[0], None)
        target = self.seat if kind == "standUp" else self.target_of(kind, args)
        if kind in ("move", "insert") and args[0] in self.held_offsets:
            # The hand puts the part's centre (held at its offset) on the target.
            target = target - self.held_offsets[args[0]]
        walked = 0
        placement = None
        if target is not None and kind not in ("release", "standUp") and self.seat is None:
            # (Seated, the hands work from the seat.)
            placement = self._placement(kind, target, text,
                                        self._acting_hand(kind, args[0] if args else None))
            walked = self._approach_under(target, placement, text) \
                if kind in LEVEL_PATH_TASKS and facing is None else None
            if walked is None:
                walked = self._approach_facing(target, placement, text, facing)
        carrying_before = bool(self.held)
        raised = kind in HAND_TASKS and not carrying_before and self.seat is None
        if raised:
            # Raise the arms to the carry stance first: hands then reach from the chest
            # (and a grasped part comes up to it) instead of swinging up from the thighs
            # past the edge of the surface in front.
            self._arm_transition(False, -1)
            carrying_before = True
        tries = self._alternatives(kind, args, target, placement, text, raised)
        seg, mp, target, prepared = self._first_clear_try(i, text, kind, args, tries,
                                                          carrying_before)
        walked += prepared
        hand = mp.meta.get("hand")
        joints = dict(self.held)
        effect = self._apply_effects(kind, args, hand, keep_hold)
        if respawn:
            effect["respawn"] = [args[0]]
        self._track_objects(effect, joints, seg, mp)
        if bool(self.held) != carrying_before and self.seat is None:
            self._arm_transition(carrying_before, i)
        if kind in ("sit", "standUp"):
            self.seat = target if kind == "sit" else None
        lift = None
        if kind == "grasp" and effect.get("attach"):
            joint = next(iter(effect["attach"].values()))
            lift = lift_frame(mp, self.segments[seg].positions[:, JOINT_INDEX[joint]])
        return StepPlan(text, kind, target, walk_segments=walked, goal_segment=seg,
                        contact_frame=grip_frame(mp),
                        lift_frame=lift, hand=hand, expanded=self.expanded - expanded0,
                        primitive=mp.name,
                        objects_effect=effect, sub_steps=subs)

    def _first_clear_try(self, i: int, text: str, kind: str, args: tuple[str, ...],
                         tries: list, carrying_before: bool
                         ) -> tuple[int, MotionPrimitive, np.ndarray | None, int]:
        """Make the goal primitive of step ``i`` from the first of ``tries`` (see
        :meth:`_alternatives`) that works; returns (segment, primitive, the target it
        reached, gait primitives its preparation walked). Raises the first failure, with
        how many other placements were tried."""
        failure = None
        for k, (target, prepare) in enumerate(tries):
            mark = (len(self.segments), self.pose, self.gait_state)
            try:
                walked = prepare() if prepare is not None else 0
                seg, mp = self._goal_segment(
                    kind, target, i, text, carry_stance=carrying_before,
                    seconds=float(args[0]) if kind == "wait" and args else None,
                    grasped=args[0] if kind == "grasp" else None,
                    part=args[0] if kind in ("move", "insert", "release", "extract") and args
                    else None, container=args[1] if kind == "extract" else None,
                    attempts=None if k == 0 or target is None else ALTERNATIVE_ATTEMPTS)
                return seg, mp, target, walked
            except PlanningError as exc:
                # Blocked, or out of reach from where the walk ended (it came from the
                # side of a machine): the other placements may do; an alternative may
                # fail in any way.
                if k == 0 and exc.reason not in ("blocked", "unreachable"):
                    raise
                failure = failure or exc
                # What a failed try placed (a walk, an arm transition) is taken back.
                del self.segments[mark[0]:]
                self.pose, self.gait_state = mark[1], mark[2]
        if len(tries) == 1:
            raise failure
        raise PlanningError(f"{failure}; so did {len(tries) - 1} other placements tried",
                            task=text, reason=failure.reason)

    def _track_objects(self, effect: dict, joints: dict[str, str], seg: int,
                       mp: MotionPrimitive) -> None:
        """Follow a step's effect on the parts as the object tracks will: a part keeps
        its world offset from the hand from the contact frame on, and rests where the
        hand let it go (``joints``: the hands holding parts before the step)."""
        contact = min(grip_frame(mp), mp.n_frames - 1)
        positions = self.segments[seg].positions
        for name, joint in effect.get("attach", {}).items():
            joints[name] = joint
            self.held_offsets[name] = (self.object_position(name)
                                       - positions[contact, JOINT_INDEX[joint]])
        for names, frame in ((effect.get("detach", ()), contact),
                             (effect.get("detach_after", ()),
                              min(max(mp.n_frames - self.overlap, 0), mp.n_frames - 1))):
            for name in names:
                offset = self.held_offsets.pop(name, np.zeros(3))
                if name in joints:
                    self.object_at[name] = positions[frame, JOINT_INDEX[joints[name]]] + offset
        for name in effect.get("consume", ()):
            self.object_at.pop(name, None)

    def _fetch(self, i: int, obj: str) -> StepPlan:
        """Grasp ``obj`` as part of step ``i`` (which needs it in hand)."""
        first = len(self.segments)
        step = self._plan_step(i, f"grasp({obj})", "grasp", (obj,))
        step.first_segment, step.last_segment = first, len(self.segments) - 1
        return step

    def _reach_into(self, i: int, text: str, args: tuple[str, ...],
                    cause: PlanningError) -> StepPlan:
        """walk(R) for a region nobody can stand in: rightHand(R) (the palm in R makes
        enter(x, R) hold). Raises ``cause`` if that fails too."""
        try:
            step = self._plan_step(i, text, "rightHand", (args[-1],))
        except PlanningError as exc:
            raise PlanningError(f"{cause}; reaching into it instead failed too: {exc}",
                                task=text, reason=cause.reason) from None
        return replace(step, kind="walk (by rightHand)")

    def _approach(self, target: np.ndarray, placement: tuple[float, float], text: str,
                  sector: tuple[float, float] | None = None,
                  budget: SearchBudget | None = None) -> int:
        """Walk to where the goal primitive reaches ``target`` (from ``sector``, see
        :meth:`_reach_goal`; within ``budget``) and take the standing step there; returns
        the gait primitives walked."""
        desc = f"reach {text} at ({target[0]:.2f}, {target[1]:.2f}, {target[2]:.2f})"
        goal = self._reach_goal(target, placement, desc, text, sector=sector)
        walked = self._walk(goal, text, -1, carry=bool(self.held), budget=budget)
        if not self._adjust_to(target, placement, text):
            # No clear step from where the walk ended: walk on to a spot that needs
            # (almost) none.
            goal = self._reach_goal(target, placement, desc, text, adjust=FINAL_ADJUST_RADIUS,
                                    sector=sector)
            walked += self._walk(goal, text, -1, carry=bool(self.held), budget=budget)
            self._adjust_to(target, placement, text)
        return walked

    def _approach_under(self, target: np.ndarray, placement: tuple[float, float],
                        text: str) -> int | None:
        """:meth:`_approach` to the standing place in front of the nearest edge of a low
        board over ``target``, facing in across the edge (within ``BOARD_FACING``); None
        if there is no such board or no way there."""
        low = self._low_board(target)
        if low is None:
            return None
        yaw = math.atan2(-low[3][1], -low[3][0])
        c, s = math.cos(yaw), math.sin(yaw)
        d, lat = placement
        side = math.atan2(-(s * d + c * lat), -(c * d - s * lat))
        try:
            return self._approach(target, placement, text, sector=(side, BOARD_FACING),
                                  budget=SearchBudget(FACING_NODES))
        except PlanningError:
            return None

    def _approach_facing(self, target: np.ndarray, placement: tuple[float, float],
                         text: str, facing: np.ndarray | None) -> int:
        """:meth:`_approach`; with ``facing`` (3,), from the side of the target that makes
        the worker face it (a seat: sit facing the desk), else from any side."""
        if facing is not None:
            ahead = math.atan2(facing[1] - target[1], facing[0] - target[0])
            # The worker stands ``placement`` from the target: with the target behind
            # (a seat), the standing spot lies towards what the worker will face.
            side = ahead if placement[0] < 0 else ahead + math.pi
            try:
                return self._approach(target, placement, text,
                                      sector=(side, APPROACH_HALF_WIDTH),
                                      budget=SearchBudget(FACING_NODES))
            except PlanningError:
                pass
        return self._approach(target, placement, text)

    def _alternatives(self, kind: str, args: tuple[str, ...], target: np.ndarray | None,
                      placement: tuple[float, float] | None, text: str, raised: bool
                      ) -> list[tuple[np.ndarray | None, Callable[[], int] | None]]:
        """What to try when the goal primitive is blocked, in order: (target, prepare),
        where ``prepare()`` moves the worker first and returns the primitives walked.

        release: other places to let go; bend/stoop/kneel/wait: a roomier spot; tasks
        with a target: the other ``ALTERNATE_APPROACHES`` (further back, other sides).
        """
        if kind == "release":
            return [(t, None) for t in self._release_targets(args[0])]
        if target is None:
            return [(None, None)] + ([(None, lambda: self._walk_to_room(text))]
                                     if kind in IN_PLACE_TASKS else [])
        if placement is None:
            return [(target, None)]
        first = math.atan2(self.pose[1] - target[1], self.pose[0] - target[0])

        def approach(turn: float, back: float) -> int:
            lowered = raised and not self.held
            if lowered:
                self._arm_transition(True, -1)
            self._step_out()            # the first try may have left the worker at a rack
            walked = self._approach(target, (placement[0] + back, placement[1]), text,
                                    sector=(first + turn, APPROACH_HALF_WIDTH),
                                    budget=SearchBudget(ALTERNATIVE_NODES))
            if lowered:
                self._arm_transition(False, -1)
            return walked

        return [(target, None)] + [
            (target, functools.partial(approach, turn, back))
            for turn, back in ALTERNATE_APPROACHES]

    def _walk_to_room(self, text: str) -> int:
        """Walk to the nearest spot with ``IN_PLACE_ROOM`` of floor clearance (a task done
        where the worker stands hit the furniture there); returns the primitives walked."""
        room = IN_PLACE_ROOM

        def roomy(x: np.ndarray, y: np.ndarray, yaw: np.ndarray | None = None) -> np.ndarray:
            return self._clearance(np.stack([x, y], axis=-1)) > room

        field = self._field(lambda xy, clearance: roomy(xy[:, 0], xy[:, 1]), ("room", room))
        goal = self._goal_from_field(field, roomy, f"find room for {text}", text)
        return self._walk(goal, text, -1, carry=bool(self.held))

    def _release_targets(self, obj: str) -> list[np.ndarray]:
        """Where the hand holding ``obj`` may let it go, palm positions (3,), in order:
        ahead of the worker, then turned to either side, then nearer
        (``RELEASE_PLACES``). Over a table or bench the part is set down on its top;
        elsewhere it is let go at ``RELEASE_HEIGHT`` of the stature."""
        x, y, yaw = self.pose
        stature = self.library.skeleton.stature
        offset = self.held_offsets.get(obj, np.zeros(3))
        half = 0.5 * float(np.ptp(self.cell.object(obj).occupancy.aabb(), axis=0)[2])
        out = []
        for dist, turn in RELEASE_PLACES:
            c, s = math.cos(yaw + turn), math.sin(yaw + turn)
            palm = np.array([x + dist * c, y + dist * s, RELEASE_HEIGHT * stature])
            top = self._surface_below(palm[:2], RELEASE_SURFACE_MAX * stature)
            if top is not None:
                # The part (held at ``offset`` from the palm) comes to rest on the top.
                palm[2] = max(palm[2], top + half + RELEASE_GAP - float(offset[2]))
            out.append(palm)
        return out

    def _surface_below(self, xy: np.ndarray, highest: float) -> float | None:
        """Height of the highest obstacle top under the floor point ``xy`` (2,) that is
        no higher than ``highest``, metres; None if none."""
        tops = [float(part.aabb()[1][2]) for ob in self.cell.obstacles for part in ob.parts
                if float(part.aabb()[1][2]) <= highest
                and float(part.footprint().signed_distance(xy[None])[0]) <= 0.0]
        return max(tops) if tops else None

    def _goal_segment(self, kind: str, target: np.ndarray | None, label: int,
                      text: str, *, carry_stance: bool = False, seconds: float | None = None,
                      grasped: str | None = None, attempts: int | None = None,
                      part: str | None = None, container: str | None = None
                      ) -> tuple[int, MotionPrimitive]:
        """Make, check and place the goal primitive of ``kind`` for ``target``.

        ``carry_stance``: the arms are already in the carry stance; ``seconds``: how long
        a wait lasts; ``grasped``: the part a grasp picks up (checked from contact on);
        ``attempts``: seeded primitives tried (default ``options.goal_attempts``);
        ``part``: the part a move, insert or release puts down (done by the hand holding
        it; for extract, the part taken out of ``container``). A grasp or extract while
        one hand holds a part is done by the other hand.
        """
        x, y, yaw = self.pose
        local = None
        if target is not None:
            c, s = math.cos(-yaw), math.sin(-yaw)
            dx, dy = target[0] - x, target[1] - y
            local = np.array([c * dx - s * dy, s * dx + c * dy, target[2]])
        seated = self.seat is not None and kind != "standUp"
        kwargs = {"rng": self.rng,
                  "start_pose": self._seated_pose() if seated
                  else self._stance(bool(self.held) or carry_stance)}
        hand = self._acting_hand(kind, part if kind != "grasp" else grasped)
        if hand is not None:
            kwargs["hand"] = hand
        if kind == "extract" and part is not None and container is not None:
            kwargs["travel"] = self._pull_length(part, container)
        board = self._board_local(target, local) if local is not None \
            and kind in LEVEL_PATH_TASKS and not seated else None
        if board is not None:
            kwargs["board"] = board
        hand_fixed = "hand" in kwargs
        if kind == "wait" and target is None and seconds is not None:
            # Longer than asked by the blends at both ends, so the stillness lasts.
            kwargs["duration"] = seconds + (2 * self.overlap + 6) / self.library.fps
        mp = None
        kept_in = 0
        attempts = self.options.goal_attempts if attempts is None else attempts
        for attempt in range(attempts):
            if kind in LEVEL_PATH_TASKS:
                # Every other try comes in level (over a shelf board, under the one above).
                kwargs["path"] = HAND_PATHS[attempt % len(HAND_PATHS)]
            try:
                candidate = self._sit_still(kwargs.get("duration", 2.0)) \
                    if seated and kind == "wait" else self.library.goal(kind, local, **kwargs)
            except ValueError as exc:
                raise PlanningError(f"task {text}: cannot make a {kind} motion for the "
                                    f"target: {exc}", task=text, reason="unreachable") from None
            clear = self._goal_clear(candidate, grasped)
            if clear and kind == "extract" and part is not None and container is not None \
                    and not self._pulls_out(candidate, part, container):
                kept_in += 1
                clear = False
            if clear:
                mp = candidate
                break
            if attempt == 1 and kind in ("grasp", "release") and not hand_fixed \
                    and board is None:
                other = OTHER_HAND.get(candidate.meta.get("hand"))
                if other:
                    kwargs["hand"] = other
        if mp is None and kept_in:
            raise PlanningError(f"task {text}: {kept_in} of the {attempts} {kind} motions "
                                f"tried keep {part} in {container} (the hand does not take "
                                "it out far enough from where the worker stands), the others "
                                "run into an obstacle", task=text, reason="blocked")
        if mp is None:
            raise PlanningError(f"task {text}: every {kind} motion tried "
                                f"({attempts}) runs into an obstacle; "
                                "an obstacle blocks the reach", task=text, reason="blocked")
        seg = self._add(mp, self.pose, label, self.overlap)
        self.pose = self._hand_over_pose(mp, self.pose)
        self.gait_state = None
        return seg, mp

    def _pull_length(self, part: str, container: str) -> float:
        """How far an extract pulls ``part`` (m): out of ``container`` horizontally from
        where it lies (the container's half extent beyond the part's centre plus the
        part's half size and ``PULL_MARGIN``), at least the model's 8 cm, at most 0.3 m."""
        lo, hi = self.cell.object(container).occupancy_at(
            self.object_position(container)).aabb()
        plo, phi = self.cell.object(part).occupancy_at(self.object_position(part)).aabb()
        centre = 0.5 * (plo + phi)
        out = min(float(np.min(np.r_[hi[:2] - centre[:2], centre[:2] - lo[:2]])),
                  0.5 * float(np.max(hi[:2] - lo[:2])))
        need = out + 0.5 * float(np.max(phi[:2] - plo[:2])) + PULL_MARGIN
        return float(np.clip(need, 0.08, 0.3))

    def _pulls_out(self, mp: MotionPrimitive, part: str, container: str) -> bool:
        """Whether the hand of an extract primitive brings ``part`` (carried from the
        contact frame on) out of ``container`` on some frame: Table I's condition, which
        the verifier checks (a worker standing close keeps the part in a deep fixture)."""
        from ltl_human_motion.scene.predicates import enter_object
        joint = {"l_hand": "l_hand"}.get(mp.meta.get("hand"), "r_hand")
        hand = world_positions(mp, *self.pose)[:, JOINT_INDEX[joint]]
        contact = min(grip_frame(mp), len(hand) - 1)
        obj, box = self.cell.object(part), self.cell.object(container)
        around = box.occupancy_at(self.object_position(container))
        offset = self.object_position(part) - hand[contact]
        return any(not enter_object(obj.occupancy_at(p + offset), around)
                   for p in hand[contact::EXTRACT_CHECK_STRIDE])

    def _goal_clear(self, mp: MotionPrimitive, grasped: str | None) -> bool:
        """Whether the body, the objects already in the hands and the part being grasped
        (``grasped``, from the frame the hand lifts it, :func:`lift_frame`) keep clear of
        obstacles."""
        world = world_positions(mp, *self.pose)
        if not self._placed_clear(mp, self.pose, samples=None, world=world):
            return False
        if grasped is None:
            return True
        from ltl_human_motion.scene.predicates import object_clearance
        joint = {"l_hand": "l_hand", "r_hand": "r_hand"}.get(mp.meta.get("hand"), "r_hand")
        hand = world[:, JOINT_INDEX[joint]]
        contact = int(mp.meta.get("contact_frame", 0))
        lift = lift_frame(mp, hand)
        if lift >= len(hand):
            return True
        # The part rests on its support until the hand lifts it; carried from then on.
        centre = hand[lift:] + (self.object_position(grasped) - hand[contact])
        return not np.any(object_clearance(self.cell, grasped, centre) <= 0.0)

    def _apply_effects(self, kind: str, args: tuple[str, ...], hand: str | None,
                       keep_hold: bool = False) -> dict:
        """Update which objects are held; return the effect for the object tracks
        (``keep_hold``: a held part that a move puts into its region stays in hand)."""
        hand_joint = {"l_hand": "l_hand", "r_hand": "r_hand", "both": "r_hand",
                      None: "r_hand"}.get(hand, "r_hand")
        if kind == "grasp":
            self.held[args[0]] = hand_joint
            return {"attach": {args[0]: hand_joint}}
        if kind == "release":
            self.held.pop(args[0], None)
            return {"detach": [args[0]]}
        if kind in ("move", "insert", "extract"):
            if args[0] not in self.held:
                # extract takes the part out of its container and keeps it in hand (move
                # and insert fetch the part first).
                self.held[args[0]] = hand_joint
                return {"attach": {args[0]: hand_joint}}
            if kind == "extract" or keep_hold:
                return {}
            # move / insert of a held part: it stays where the hand put it.
            self.held.pop(args[0], None)
            return {"detach": [args[0]]}
        if kind == "assemble":
            parts = list(self.held)
            self.consumed.update(parts)
            self.held.clear()
            return {"detach": parts, "consume": parts}
        return {}
