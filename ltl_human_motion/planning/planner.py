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

The parts: :mod:`.plan_state` (the context, the worker's state, the parts' book-keeping),
:mod:`.standing` (placement geometry: where to stand, how to face), :mod:`.walk_goals`
(the walks' goals and navigation fields), :mod:`.steps` (the step executor: walks,
standing steps, arm transitions, every-frame checks) and :mod:`.goal_steps` (the goal
primitive of a task, its approach and alternatives). This module dispatches each task
step to them and records what it made (:class:`StepPlan`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, replace

import numpy as np

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.motion.goals import LEVEL_PATH_TASKS
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.planning.blend import PlacedSegment
from ltl_human_motion.planning.feasibility import reach_envelope
from ltl_human_motion.planning.goal_steps import GoalSteps
from ltl_human_motion.planning.lift_in import settle
from ltl_human_motion.planning.open_sides import approach_open_side
from ltl_human_motion.planning.plan_state import (
    Effects,
    PlanContext,
    PlannerOptions,
    Pose,
    WorkerState,
    acting_hand,
    apply_effects,
    grip_frame,
    in_start_frame,
    lift_frame,
    track_objects,
)
from ltl_human_motion.planning.stand_distance import farther_placement
from ltl_human_motion.planning.standing import (
    low_board,
    palm_clear_of_support,
    standing_offset,
)
from ltl_human_motion.planning.steps import StepExecutor
from ltl_human_motion.planning.walk_goals import WalkGoals
from ltl_human_motion.vocabulary import HAND_TASKS, TaskStep

#: How long ``standUp`` by a worker already standing stands still, seconds (a short,
#: visible pause; the blends at both ends take 2 x overlap frames of it).
STAND_UP_IN_PLACE_SECONDS = 0.4

#: How long the worker stands (or sits) still at the start and the end of a motion,
#: seconds: the blends at both ends need 2 x overlap frames, and the still start
#: makes the start region's check hold on frame 0.
END_STILL_SECONDS = 0.3
#: How long the worker stands still after a walk task, seconds (the stop primitive
#: ends with the feet planted; this makes the arrival visible and blends the next task).
WALK_END_STILL_SECONDS = 0.25
#: A sit on a seat no further than this from the one the worker sits on stays seated,
#: metres (a seat point is exact to the cell model; 5 cm is a buttock's settling).
SAME_SEAT_DISTANCE = 0.05

#: Hand tasks a seated worker does from the seat (others make the worker stand up).
SEATED_HAND_TASKS = ("leftHand", "rightHand", "assemble")
#: How far inside a move's (or carry's) region, beyond the part's half-diagonal, the
#: point in front of a worker already there must lie to be used instead of its centre,
#: metres.
REGION_POINT_MARGIN = 0.05
#: How far from the point in front of the worker that region point may lie (a step
#: adjusts the stance), metres.
REGION_POINT_REACH = 0.25


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
    objects_effect : Effects
        What the step does to the parts (attached, detached, consumed, respawned).
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
    objects_effect: Effects = field(default_factory=Effects)
    sub_steps: list[StepPlan] = field(default_factory=list)


@dataclass
class Plan:
    """Placed segments and the step plans that produced them."""

    segments: list[PlacedSegment]
    steps: list[StepPlan]
    start_pose: Pose
    expanded: int


class SequencePlanner:
    """Plans one task sequence in one cell with one motion library.

    Parameters
    ----------
    cell : Cell
    library : MotionLibrary
    rng : numpy.random.Generator
    options : PlannerOptions
    failed_before : dict, optional
        Steps that failed in an earlier order of the tasks (:attr:`failed_before`).
    """

    def __init__(self, cell, library, rng: np.random.Generator,
                 options: PlannerOptions = PlannerOptions(),
                 failed_before: dict[tuple, PlanningError] | None = None) -> None:
        self.ctx = PlanContext.build(cell, library, rng, options)
        self.state = WorkerState()
        self.executor = StepExecutor(self.ctx, self.state)
        self.goals = WalkGoals(self.ctx, self.state, turn_clear=self.executor.turn_clear)
        self.goal_steps = GoalSteps(self.ctx, self.state, self.executor, self.goals)
        self.steps: list[StepPlan] = []
        #: Steps that failed in an earlier order of the tasks, by :meth:`situation`: the
        #: same step in the same situation fails the same way here, without a search.
        self.failed_before: dict[tuple, PlanningError] = failed_before or {}

    def situation(self, text: str, after: str | None) -> tuple:
        """Step ``text`` done after step ``after`` (None: first) in what the tasks so far
        left: which hand holds which part, where parts were put down, the parts used up
        and, seated, the seat and how the worker sits on it (the hands work from there).
        (A walk from another place to the same reach can end elsewhere: in an aisle,
        coming from its far end or from the other rack.)"""
        st = self.state
        return (text, after, frozenset(st.held.items()),
                frozenset((k, tuple(np.round(v, 4).tolist())) for k, v in st.object_at.items()),
                frozenset(st.consumed),
                None if st.seat is None
                else (*np.round(st.seat, 4).tolist(), *np.round(st.pose, 4).tolist()))

    def target_of(self, kind: str, args: tuple[str, ...]) -> np.ndarray | None:
        """Where a step acts, shape (3,): grasp point, region or object centre, seat; the
        region's centre for walk/carry; None for tasks in place (wait, bend, ...)."""
        cell = self.ctx.cell
        if kind in ("walk", "carry"):
            return np.asarray(cell.region(args[-1]).center, dtype=np.float64)
        if kind in ("grasp",):
            obj = cell.object(args[0])
            at = self.goal_steps.where(args[0])
            point = np.asarray(obj.grasp_points_at(at)[0], dtype=np.float64)
            return palm_clear_of_support(cell, self.ctx.stature, point, obj.occupancy_at(at))
        if kind in ("move",):
            return np.asarray(cell.region(args[1]).center, dtype=np.float64)
        if kind == "extract":
            # The hand takes the part as a grasp does: off the support under it.
            obj = cell.object(args[0])
            return palm_clear_of_support(cell, self.ctx.stature, self.goal_steps.where(args[1]),
                                         obj.occupancy_at(self.goal_steps.where(args[0])))
        if kind == "insert":
            return self.goal_steps.where(args[1])
        if kind in ("leftHand", "rightHand", "assemble"):
            return np.asarray(cell.region(args[0]).center, dtype=np.float64)
        if kind == "sit":
            obj = cell.object(args[0])
            return np.asarray(obj.sitting_surface_at(obj.position).center, dtype=np.float64)
        return None

    def plan(self, tasks: list[TaskStep], start: Pose) -> Plan:
        """Plan every step (:func:`~ltl_human_motion.vocabulary.task_step` makes them)."""
        self.state.start_at(start)
        self.executor.stand_still(-1, END_STILL_SECONDS)
        for i, task in enumerate(tasks):
            first = len(self.state.segments)
            facing = self._seated_work(tasks[i + 1:]) if task.kind == "sit" else None
            situation = self.situation(task.text, tasks[i - 1].text if i else None)
            try:
                known = self.failed_before.get(situation)
                if known is not None:
                    raise PlanningError(str(known), task=known.task, reason=known.reason,
                                        search=known.search)
                step = self._plan_step(i, task.text, task.kind, task.args, facing=facing)
            except PlanningError as exc:
                exc.step_index = i              # where the order of the tasks failed
                if task.kind not in ("walk", "carry"):   # (a walk depends on where from)
                    exc.situation = situation
                raise
            step.first_segment = first
            step.last_segment = len(self.state.segments) - 1
            self.steps.append(step)
        if self.state.seat is None:
            self.executor.stand_still(-1, END_STILL_SECONDS)
        else:                                # the motion ends seated: stay on the seat
            still = self.executor.sit_still(END_STILL_SECONDS)
            self.executor.add(still, self.state.pose, -1, self.ctx.overlap)
        return Plan(self.state.segments, self.steps, start, self.state.expanded)

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
        expanded0 = self.state.expanded
        if self.state.seat is None:
            self.executor.step_out()
        if self.state.seat is not None and (
                kind not in ("standUp", "wait", "sit", *SEATED_HAND_TASKS)
                or (kind in SEATED_HAND_TASKS and self._beyond_seated_reach(kind, args))):
            self.goal_steps.segment("standUp", self.state.seat, -1, text)
            self.state.seat = None
        if kind == "sit" and self.state.seat is not None:
            seat = self.target_of(kind, args)
            if seat is not None and \
                    float(np.linalg.norm(seat - self.state.seat)) <= SAME_SEAT_DISTANCE:
                # Already on this seat: sit holds while the worker stays seated (standing
                # up to sit down again would be a needless double transition).
                still = self.executor.sit_still(STAND_UP_IN_PLACE_SECONDS)
                seg = self.executor.add(still, self.state.pose, i, self.ctx.overlap)
                return StepPlan(text, "sit (seated)", self.state.seat, goal_segment=seg,
                                contact_frame=0, primitive=self.state.segments[seg].name)
            # To sit on another seat, stand up first.
            self.goal_steps.segment("standUp", self.state.seat, -1, text)
            self.state.seat = None
        if kind == "carry":
            # carry(O, R) holds when the body enters R with O inside it: the held part is
            # put into R by hand (so the palm enters R too), and it stays in hand.
            step = self._plan_step(i, text, "move", args, keep_hold=True)
            return replace(step, kind="carry (by move)")
        if kind == "walk":
            region = self.ctx.cell.region(args[-1])
            subs: list[StepPlan] = []
            try:
                goal = self.goals.region(region, f"walk into {region.name}", text)
            except PlanningError as exc:
                if exc.reason != "unreachable":
                    raise
                # Nowhere to stand in the region (e.g. a box above a bench). Its entry,
                # enter(x, R), holds once any body part is in it: reach in with a hand.
                return self._reach_into(i, text, args, exc)
            n = self.executor.walk(goal, text, i, carry=self.state.carrying)
            self.executor.stand_still(i, WALK_END_STILL_SECONDS)
            return StepPlan(text, kind, np.asarray(region.center, dtype=float), walk_segments=n,
                            expanded=self.state.expanded - expanded0,
                            primitive=f"{n} gait primitives", sub_steps=subs)
        if kind == "standUp" and self.state.seat is None:
            # Already standing (every bend, stoop and kneel ends upright): standUp holds
            # once the worker stands still for a moment.
            self.executor.stand_still(i, STAND_UP_IN_PLACE_SECONDS)
            return StepPlan(text, "standUp (standing)", None, expanded=0, primitive="stand")
        return self._goal_step(i, text, kind, args, keep_hold, facing, expanded0)

    def _beyond_seated_reach(self, kind: str, args: tuple[str, ...]) -> bool:
        """Whether the target of a hand task lies further from the seat than even a
        standing worker reaches at its height, or than the goal model reaches from the
        seated pose (the worker stands up and walks to it)."""
        target = self.target_of(kind, args)
        if target is None or self.state.seat is None:
            return False
        envelope = reach_envelope(self.ctx.stature)
        away = float(np.hypot(*(np.asarray(target[:2]) - np.asarray(self.state.seat[:2]))))
        if away > envelope.horizontal(float(target[2]), float(target[2])):
            return True
        local = in_start_frame(self.state.pose, target)
        hand = acting_hand(self.state, kind, args[0] if kind != "grasp" and args else None)
        try:
            # The model's own reach test (its seeds only vary the timing: a fixed one
            # keeps the plan's random stream as it was).
            self.ctx.library.goal(kind, local, rng=np.random.default_rng(0),
                                  start_pose=self.executor.seated_pose(self.state.pose),
                                  **({"hand": hand} if hand else {}))
        except ValueError:
            return True
        return False

    def _goal_step(self, i: int, text: str, kind: str, args: tuple[str, ...],
                   keep_hold: bool, facing: np.ndarray | None, expanded0: int) -> StepPlan:
        """A step done with a goal primitive (hand tasks, postures, sit): fetch the part
        if needed, walk to the placement, make the primitive (trying the alternatives
        when it is blocked) and follow its effect on the parts (see :meth:`_plan_step`;
        ``expanded0``: nodes expanded before the step)."""
        subs = []
        if kind in ("move", "insert", "release") and args[0] not in self.state.held:
            # The part is fetched first, as for carry(O, R).
            subs.append(self._fetch(i, args[0]))
        respawn = kind == "grasp" and args[0] in self.state.consumed
        if respawn:
            self.state.consumed.discard(args[0])           # a fresh part from the supply
            self.state.object_at.pop(args[0], None)
        target = self.state.seat if kind == "standUp" else self.target_of(kind, args)
        if kind in ("move", "insert") and args[0] in self.state.held_offsets:
            # The hand puts the part's centre (held at its offset) on the target.
            target = target - self.state.held_offsets[args[0]]
        walked, approach_failed = 0, None
        placement, arms_up = None, True
        if target is not None and kind not in ("release", "standUp") and self.state.seat is None:
            # (Seated, the hands work from the seat.)
            placement, arms_up = self._placement(kind, target, text, args)
            here = self._region_point_here(kind, args, target, placement)
            if here is None:
                here = self._region_point_in_reach(kind, args, target, placement)
            if here is not None:
                target = here
                placement, arms_up = self._placement(kind, target, text, args)
            placement = farther_placement(
                self.ctx, target, placement,
                lambda local: self.goal_steps.reaches(kind, args, local, arms_up)) or placement
            walked, approach_failed = self._first_approach(kind, args, target, placement, text,
                                                           facing)
        carrying_before = self.state.carrying
        raised = kind in HAND_TASKS and not carrying_before and self.state.seat is None \
            and arms_up
        out_of_reach = False
        if raised:
            # Raise the arms to the carry stance first: hands then reach from the chest
            # (and a grasped part comes up to it) instead of swinging up from the thighs
            # past the edge of the surface in front. Where the raise needs a step back
            # that puts the target out of reach (a vise 0.35 m behind a machine's sill),
            # or is blocked even so, the reach starts from the arms down instead.
            raised, out_of_reach = self._raise_arms(kind, args, target)
            carrying_before = raised
        tries = self.goal_steps.alternatives(kind, args, target, placement, text, raised,
                                             raise_back=out_of_reach)
        seg, mp, target, prepared = self.goal_steps.first_clear_try(
            i, text, kind, args, tries, carrying_before, approach_failed)
        walked += prepared
        hand = mp.meta.get("hand")
        joints = dict(self.state.held)
        effect = apply_effects(self.state, kind, args, hand, keep_hold)
        if respawn:
            effect = replace(effect, respawn=(args[0],))
        track_objects(self.ctx.cell, self.state, effect, joints,
                      self.state.segments[seg].positions, mp)
        if self.state.start_arms is not None:
            # Made from raised arms: a grasp lifted off (a carton off a stand) steps back
            # and lowers them to the carry stance, where the others already are.
            arms, self.state.start_arms = self.state.start_arms, None
            if arms.rise > 0.0:
                settle(self.goal_steps, arms, i, text)
            carrying_before = True
        if self.state.carrying != carrying_before and self.state.seat is None:
            self.executor.arm_transition(carrying_before, i, text)
        if kind in ("sit", "standUp"):
            self.state.seat = target if kind == "sit" else None
        lift = None
        if kind == "grasp" and effect.attach:
            joint = effect.attach[0][1]
            lift = lift_frame(mp, self.state.segments[seg].positions[:, JOINT_INDEX[joint]])
        return StepPlan(text, kind, target, walk_segments=walked, goal_segment=seg,
                        contact_frame=grip_frame(mp),
                        lift_frame=lift, hand=hand, expanded=self.state.expanded - expanded0,
                        primitive=mp.name,
                        objects_effect=effect, sub_steps=subs)

    def _region_point_here(self, kind: str, args: tuple[str, ...], target: np.ndarray,
                           placement: tuple[float, float]) -> np.ndarray | None:
        """For a move (or carry) into a region, the hand's point (3,) that puts the part
        at the point of the region nearest the one in front of the worker (``placement``
        from where they stand, at the height of ``target``: the region's centre less the
        part's held offset), ``REGION_POINT_MARGIN`` inside it and clear of obstacles,
        when that is within ``REGION_POINT_REACH`` of it: a worker already at the region
        puts the part down in front of them instead of walking to a spot facing its centre
        (in an aisle 0.8 m wide, a turn with the part in hand). None otherwise."""
        if kind != "move" or self.state.seat is not None \
                or args[0] not in self.state.held_offsets:
            return None
        region = self.ctx.cell.region(args[1])
        x, y, yaw = self.state.pose
        c, s = np.cos(yaw), np.sin(yaw)
        d, lat = placement
        here = np.array([x + c * d - s * lat, y + s * d + c * lat, float(target[2])])
        point = here + self.state.held_offsets[args[0]]
        lo, hi = self.ctx.cell.object(args[0]).shape.aabb()
        room = float(np.linalg.norm((np.asarray(hi) - np.asarray(lo))[:2]) / 2.0) \
            + REGION_POINT_MARGIN
        lo, hi = np.asarray(region.lo, dtype=float), np.asarray(region.hi, dtype=float)
        if np.any(lo[:2] + room > hi[:2] - room):
            return None
        inside = point.copy()
        inside[:2] = np.clip(point[:2], lo[:2] + room, hi[:2] - room)
        if np.linalg.norm(inside[:2] - point[:2]) > REGION_POINT_REACH \
                or np.linalg.norm(inside[:2] - (lo[:2] + hi[:2]) / 2.0) < REGION_POINT_MARGIN:
            return None
        if float(self.ctx.obstacle_field.distance(inside[None])[0]) <= room:
            return None
        return here + (inside - point)

    def _raise_arms(self, kind: str, args: tuple[str, ...], target: np.ndarray | None
                    ) -> tuple[bool, bool]:
        """Raise the arms to the carry stance for a hand task at ``target`` (3,), stepping
        back first where the furniture in front is in the way. Returns (raised, out of
        reach): where the raise is blocked even after the step back, or the step back
        leaves the target out of the goal model's reach (the second flag), nothing is
        placed and the arms stay down."""
        mark = self.state.mark()
        try:
            self.executor.arm_transition(False, -1)
        except PlanningError:
            self.state.restore(mark)
            return False, False
        if target is None or self.state.pose == mark[1]:
            return True, False
        if self.goal_steps.reaches(kind, args, tuple(in_start_frame(self.state.pose, target)),
                                   True):
            return True, False
        self.state.restore(mark)
        return False, True

    def _region_point_in_reach(self, kind: str, args: tuple[str, ...], target: np.ndarray,
                               placement: tuple[float, float]) -> np.ndarray | None:
        """For a move into a region whose centre no free standing spot is within reach of
        (``placement`` and the reach tolerance), the hand's point (3,) that puts the part
        at the region's point nearest such a spot (:func:`.region_point.region_point`);
        None otherwise."""
        from ltl_human_motion.planning.region_point import region_point
        if kind != "move" or self.state.seat is not None \
                or args[0] not in self.state.held_offsets:
            return None
        offset = self.state.held_offsets[args[0]]
        lo, hi = self.ctx.cell.object(args[0]).shape.aabb()
        room = float(np.linalg.norm((np.asarray(hi) - np.asarray(lo))[:2]) / 2.0) \
            + REGION_POINT_MARGIN
        reach = float(np.hypot(*placement)) + self.ctx.options.reach_tolerance
        point = region_point(self.ctx, self.ctx.cell.region(args[1]), room,
                             float(target[2] + offset[2]), reach)
        return None if point is None else point - offset

    def _first_approach(self, kind: str, args: tuple[str, ...], target: np.ndarray,
                        placement: tuple[float, float], text: str, facing: np.ndarray | None
                        ) -> tuple[int, PlanningError | None]:
        """Walk to the placement for ``target`` (3,) (under a low board, or facing
        ``facing``; then to a side open to the target if it ended at a closed one,
        :func:`.open_sides.approach_open_side`); returns the gait primitives walked and
        None. Where that walk is blocked (no place to stop there keeps the body clear),
        what it placed is taken back and (0, the error) returned: the goal step's alternatives
        (:meth:`.goal_steps.GoalSteps.alternatives`, from other sides and further back)
        are tried from where the worker stood, and the error is what a refusal names."""
        mark = self.state.mark()
        try:
            walked = self.goal_steps.approach_under(target, placement, text) \
                if kind in LEVEL_PATH_TASKS and facing is None else None
            if walked is None:
                walked = self.goal_steps.approach_facing(target, placement, text, facing)
            if facing is None and kind in HAND_TASKS:
                walked = approach_open_side(
                    self.ctx, self.state,
                    self.goal_steps.side_reach(kind, args, target, placement, True),
                    functools.partial(self.goal_steps.approach_arc, target, placement, text),
                    walked, mark)
        except PlanningError as exc:
            if exc.reason != "blocked":
                raise
            self.state.restore(mark)
            return 0, exc
        return walked, None

    def _placement(self, kind: str, target: np.ndarray, text: str, args: tuple[str, ...]
                   ) -> tuple[tuple[float, float], bool]:
        """Where the target should be in the standing root's frame
        (:func:`.standing.standing_offset`), and whether the arms come up to the carry
        stance before the goal primitive. They do, except under a low board that no
        place reaches from the carry stance while the hands are free (a short worker's
        floor grasp under a board at knee height reaches from the arms down). Under a low
        board a place whose posture keeps the hips in their range of motion (a crouch
        with the pelvis's tilt capped, or kneeling) comes first, from either stance; one
        that needs the pelvis tilted in full only after."""
        hand = acting_hand(self.state, kind, args[0] if args else None)
        low = kind in LEVEL_PATH_TASKS \
            and low_board(self.ctx.cell, target, self.ctx.stature) is not None
        stances = (True, False) if low and not self.state.carrying else (True,)
        error = None
        for full_tilt in (False, True) if low else (True,):
            for carry in stances:
                try:
                    return standing_offset(self.ctx, kind, target, text, hand,
                                           carry_stance=carry, full_tilt=full_tilt), carry
                except PlanningError as exc:
                    error = exc
        raise error

    def _fetch(self, i: int, obj: str) -> StepPlan:
        """Grasp ``obj`` as part of step ``i`` (which needs it in hand)."""
        first = len(self.state.segments)
        step = self._plan_step(i, f"grasp({obj})", "grasp", (obj,))
        step.first_segment, step.last_segment = first, len(self.state.segments) - 1
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
