"""Goal steps: make, check and place the goal primitive of a task, with the walk to it.

:class:`GoalSteps` walks the worker to where a goal primitive reaches its target
(:mod:`.walk_goals`, :mod:`.standing`), makes the primitive for the exact target with
the motion library's goal models (:mod:`ltl_human_motion.motion.goals`), checks it as
the verifier does (body, parts in hand, the part being lifted; an extract must bring
its part out) and places it. When every seeded primitive runs into an obstacle it
tries the alternatives in order: other places to let a part go, a roomier spot, other
sides of the target and a step further back.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.motion.goals import (
    HAND_PATHS,
    LEVEL_PATH_TASKS,
    LEVEL_REGION_TASKS,
    PUSH_LEVEL_TASKS,
)
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.motion.types import MotionPrimitive, world_positions
from ltl_human_motion.planning.astar import AT_GOAL_NODES, Goal, SearchBudget
from ltl_human_motion.planning.lift_in import (
    lift_for_grasp,
    lift_in,
    needs_lift,
    needs_lift_out,
    settle,
)
from ltl_human_motion.planning.open_sides import (
    OPEN_SIDE_BUDGET,
    SIDES,
    Arc,
    SideReach,
    open_arc,
    side_blocked,
)
from ltl_human_motion.planning.plan_state import (
    OTHER_HAND,
    PlanContext,
    Pose,
    StartArms,
    WorkerState,
    acting_hand,
    grip_frame,
    holding_joint,
    in_start_frame,
    lift_frame,
    object_position,
)
from ltl_human_motion.planning.stance_search import (
    Stance,
    StanceTries,
    candidate_stances,
    clear_stances,
)
from ltl_human_motion.planning.standing import (
    SQUARE_BOARD_HEIGHT,
    board_local,
    ceiling_local,
    low_board,
    posture_clearance,
    pull_length,
    release_targets,
    standing_offset,
    support_local,
)
from ltl_human_motion.planning.steps import StepExecutor
from ltl_human_motion.planning.walk_goals import WalkGoals
from ltl_human_motion.vocabulary import HAND_TASKS

#: Frames a wait lasts beyond the blends at both ends (2 x overlap), so that the
#: stillness the verifier checks lasts as long as asked.
WAIT_EXTRA_FRAMES = 6
#: How long a seated wait without a duration lasts, seconds (the wait model's default).
SEATED_WAIT_SECONDS = 2.0

if TYPE_CHECKING:
    from ltl_human_motion.motion.goals.kinematics import HeldPart

#: Blocked goal primitives of a step that the whole-body program remakes, at most.
WHOLE_BODY_TRIES = 1
#: Placements at which the whole-body program remakes a blocked goal primitive, once
#: every try has failed without it: the first ones, in the order tried, where a goal
#: primitive was made and an obstacle blocked it (where the walk ended out of reach, or
#: no walk got there, there is nothing to remake).
WHOLE_BODY_PLACEMENTS = 2
#: Whole-body programs one plan runs at most (about 0.25 s each): a step that every
#: placement blocks would otherwise run one per placement.
WHOLE_BODY_BUDGET = 4

#: Seeded primitives tried at each alternative (release place, approach) after the first
#: (the first gets ``PlannerOptions.goal_attempts``).
ALTERNATIVE_ATTEMPTS = 2

#: Other ways to stand for a reach whose motions all hit an obstacle, in order: (turn of
#: the approach direction about the target, rad; extra distance from the target, m;
#: whether the other hand reaches). First a step further back (a knee or thigh at a desk
#: or low shelf front), then the other hand from the placement mirrored across the
#: target (the body beside the target on its other side: a floor part next to a cart
#: the stooping head and shoulder hit), then the target's other sides (an arm hitting a
#: crate beside it).
ALTERNATE_APPROACHES: tuple[tuple[float, float, bool], ...] = (
    (0.0, 0.08, False), (0.0, 0.0, True), (math.pi / 3, 0.0, False),
    (-math.pi / 3, 0.0, False))

#: Walks to the nearest stances where the goal model's motion is clear
#: (:mod:`.stance_search`) a blocked step tries, at most.
STANCE_WALKS = 3

#: Node budget of the walk to a clear stance (the walk from the front of a cart round to
#: the 30 degree side beside it took 816 nodes).
STANCE_NODES = 1000
#: ... and the nodes it may expand after it first came to the goal's floor cells
#: without a place to stop (a spot that a search found took 212 after it came there).
STANCE_AT_GOAL_NODES = 300
STANCE_BUDGET = SearchBudget(STANCE_NODES, at_goal_nodes=STANCE_AT_GOAL_NODES)

#: Node budget of the walk to an alternative approach (most are a few steps round the
#: target; a side that needs a long way round is not worth the search).
ALTERNATIVE_NODES = 500
#: Nodes such a walk may expand after it first came to the goal's floor cells without a
#: place to stop there (a side whose spots are all in the furniture: the search floods
#: them); where it ends so, the model-made steps into the goal are tried as after its
#: budget (:meth:`GoalSteps._walk_or_step_into`).
ALTERNATIVE_AT_GOAL_NODES = 100
ALTERNATIVE_BUDGET = SearchBudget(ALTERNATIVE_NODES, at_goal_nodes=ALTERNATIVE_AT_GOAL_NODES)

#: Node budget of the walk to the side of a seat that faces the seated work (without
#: it the worker sits facing whichever way the walk arrives).
FACING_NODES = 600

#: Half width of the side a worker reaching under a low board stands on, rad: nearly
#: square to the edge (the knees of a deep crouch come up close to it).
BOARD_FACING = math.pi / 12

#: Half width of the side of the target an alternative approach walks to, rad.
APPROACH_HALF_WIDTH = math.pi / 6

#: Step left to the standing adjustment when the first one from where a walk ended was
#: not clear: the walk goes on to a spot that needs almost none, metres.
FINAL_ADJUST_RADIUS = 0.05

#: Node budget of that final walk. It starts at the reach spot's ring, so it stops
#: within a few primitives or not at all: over the corpus at 1.75 and 1.95 m and 10
#: generated cells it ran 25 times and stopped 3 times, each after 1 node; the other 22
#: spent 4000 nodes at the goal (``AT_GOAL_NODES``) or the first approach's whole 8000
#: (1-4 s each) before the other placements were tried.
FINAL_WALK_NODES = 400

#: Tasks done where the worker stands (no target); when furniture there blocks them,
#: the worker first walks to a spot with ``IN_PLACE_ROOM`` of floor clearance.
IN_PLACE_TASKS = ("bend", "stoop", "kneel", "wait")

#: Floor clearance around the root a kneel or stoop needs, metres (the knee goes about
#: 0.5 m ahead of the root and the head as far when stooping, plus a hand's width).
IN_PLACE_ROOM = 0.6

#: Tasks whose goal primitive reaches with whichever hand the target is on the side of
#: (the planner's placement decides; both hands or a named hand otherwise).
ONE_HAND_AUTO_TASKS = ("grasp", "release", "move", "insert", "extract")

#: Stride of the frames on which the planner checks that an extract takes its part out.
EXTRACT_CHECK_STRIDE = 4


@dataclass
class ProgramBudget:
    """Whole-body programs a plan may still run (:data:`WHOLE_BODY_BUDGET`)."""

    left: int


class GoalSteps:
    """Makes the goal segments of one plan.

    Parameters
    ----------
    ctx : PlanContext
    state : WorkerState
    executor : StepExecutor
        Places the walks, steps and primitives.
    goals : WalkGoals
        Makes the walks' goals.
    """

    def __init__(self, ctx: PlanContext, state: WorkerState, executor: StepExecutor,
                 goals: WalkGoals) -> None:
        self.ctx = ctx
        self.state = state
        self.executor = executor
        self.goals = goals
        self.programs = ProgramBudget(WHOLE_BODY_BUDGET)

    def where(self, name: str) -> np.ndarray:
        """Where part ``name`` rests now (3,) (:func:`.plan_state.object_position`)."""
        return object_position(self.ctx.cell, self.state, name)

    def segment(self, kind: str, target: np.ndarray | None, label: int,
                text: str, *, carry_stance: bool = False, seconds: float | None = None,
                grasped: str | None = None, attempts: int | None = None,
                part: str | None = None, container: str | None = None,
                program: bool = False) -> tuple[int, MotionPrimitive]:
        """Make, check and place the goal primitive of ``kind`` for ``target``.

        ``carry_stance``: the arms are already in the carry stance; ``seconds``: how long
        a wait lasts; ``grasped``: the part a grasp picks up (checked from contact on);
        ``attempts``: seeded primitives tried (default ``options.goal_attempts``);
        ``program``: a step every placement blocked: remake a blocked primitive with the
        whole-body program (:meth:`whole_body`);
        ``part``: the part a move, insert or release puts down (done by the hand holding
        it; for extract, the part taken out of ``container``). A grasp or extract while
        one hand holds a part is done by the other hand.
        """
        local, kwargs, board = self.goal_kwargs(kind, target, carry_stance, seconds,
                                                grasped, part, container,
                                                pose=self.state.pose)
        seated = self.state.seat is not None and kind != "standUp"
        hand_fixed = "hand" in kwargs
        mp = None
        kept_in = self_hits = 0
        blocked: list[MotionPrimitive] = []
        switched = None          # the hand tried first, after switching to the other one
        attempts = self.ctx.options.goal_attempts if attempts is None else attempts
        for attempt in range(attempts):
            if kind in LEVEL_PATH_TASKS + LEVEL_REGION_TASKS \
                    or (kind in PUSH_LEVEL_TASKS and "support" in kwargs):
                # Every other try comes in level (over a shelf board, under the one above;
                # over a bench top into the region above it; a push or pull in front of
                # the furniture under the target).
                kwargs["path"] = HAND_PATHS[attempt % len(HAND_PATHS)]
            try:
                candidate = self.executor.sit_still(kwargs.get("duration", SEATED_WAIT_SECONDS)) \
                    if seated and kind == "wait" else self.ctx.library.goal(kind, local, **kwargs)
            except ValueError as exc:
                if switched:
                    # The placement put the target within the first hand's reach, not
                    # necessarily the other's (a low part to the right): keep the first.
                    kwargs["hand"], switched = switched, None
                    continue
                raise PlanningError(f"task {text}: cannot make a {kind} motion for the "
                                    f"target: {exc}", task=text, reason="unreachable") from None
            clear = self.goal_clear(candidate, self.state.pose, grasped,
                                    part if kind == "extract" else None)
            through_body = clear and self.ctx.options.refuse_self_penetration \
                and bool(candidate.meta.get("self_penetrating"))
            if through_body:
                # a limb through the body (the verifier's self-penetration check)
                self_hits += 1
                clear = False
            if clear and kind == "extract" and part is not None and container is not None \
                    and not self.pulls_out(candidate, part, container):
                kept_in += 1
                clear = False
            if clear:
                mp = candidate
                break
            if not through_body:
                blocked.append(candidate)
            if attempt == 1 and kind in ("grasp", "release") and not hand_fixed \
                    and board is None:
                other = OTHER_HAND.get(candidate.meta.get("hand"))
                if other:
                    kwargs["hand"], switched = other, candidate.meta.get("hand")
        note = None
        if mp is None and blocked and program:
            mp, note = self.whole_body(blocked, kind, grasped, part, container)
        if mp is None:
            raise self.refusal(text, kind, attempts, blocked, grasped, (kept_in, self_hits),
                               part, container, note)
        seg = self.executor.advance(mp, label)
        self.state.gait_state = None
        if kind == "standUp" and not np.array_equal(kwargs["start_pose"],
                                                    self.ctx.stance(self.state.carrying)):
            # Sat down holding a part that a seated task used up (or the other way round).
            self.executor.arm_transition(not self.state.carrying, label)
        return seg, mp

    def furniture(self, kind: str, target: np.ndarray | None, local: np.ndarray | None,
                  yaw: float) -> dict:
        """The furniture the goal primitive of ``kind`` for ``target`` (world (3,);
        ``local``: in the start frame of a worker facing ``yaw``, rad) keeps the body clear
        of, as its keyword arguments:
        a low board over the target (``board``, :func:`.standing.board_local`), else any
        board over it (``ceiling``, :func:`.standing.ceiling_local`), and what the target
        rests on or in (``support``, :func:`.standing.support_local`)."""
        out: dict = {}
        if local is None:
            return out
        if kind in LEVEL_PATH_TASKS:
            board = board_local(self.ctx.cell, target, local, yaw, self.ctx.stature)
            if board is not None:
                out["board"] = board
        if kind in HAND_TASKS:
            support = support_local(self.ctx.cell, target, local, yaw)
            if support is not None:
                out["support"] = support
            if "board" not in out:
                ceiling = ceiling_local(self.ctx.cell, target, local, yaw)
                if ceiling is not None:
                    out["ceiling"] = ceiling
        return out

    def goal_kwargs(self, kind: str, target: np.ndarray | None, carry_stance: bool,
                    seconds: float | None, grasped: str | None, part: str | None,
                    container: str | None, *, pose: Pose
                    ) -> tuple[np.ndarray | None, dict, tuple[float, float, float] | None]:
        """What :meth:`segment` makes its primitives from for a worker standing at
        ``pose``: the target in the start frame (3,) (None without one), the goal model's
        keyword arguments (start pose, hand, extract travel, furniture, obstacles around,
        wait duration) and the low board (edge, underside, top) over the target, or
        None."""
        local = None if target is None else in_start_frame(pose, target)
        seated = self.state.seat is not None and kind != "standUp"
        if kind == "standUp" and self.state.seat is not None:
            # Stand up with the arms as they are on the seat (:meth:`segment` brings them
            # to the stance of what the hands hold afterwards).
            carry_stance = self.executor.seated_in_carry_stance()
        kwargs = {"rng": self.ctx.rng,
                  "start_pose": self.executor.seated_pose(pose) if seated
                  else self.state.start_arms.stance if self.state.start_arms is not None
                  else self.ctx.stance(self.state.carrying or carry_stance)}
        hand = acting_hand(self.state, kind, part if kind != "grasp" else grasped)
        if hand is not None:
            kwargs["hand"] = hand
        if kind == "extract" and part is not None and container is not None:
            kwargs["travel"] = self.pull_length(part, container)
        furniture = self.furniture(kind, target, local, pose[2]) if not seated else {}
        kwargs.update(furniture)
        if kind in HAND_TASKS and not seated and self.ctx.cell.obstacles:   # the body clear
            kwargs["obstacles"] = posture_clearance(self.ctx, pose)
        if kind == "wait" and target is None and seconds is not None:
            # Longer than asked by the blends at both ends, so the stillness lasts.
            kwargs["duration"] = (seconds + (2 * self.ctx.overlap + WAIT_EXTRA_FRAMES)
                                  / self.ctx.library.fps)
        return local, kwargs, furniture.get("board")

    def first_clear_try(self, i: int, text: str, kind: str, args: tuple[str, ...],
                        tries: list, carrying_before: bool,
                        failure: PlanningError | None = None
                        ) -> tuple[int, MotionPrimitive, np.ndarray | None, int]:
        """Make the goal primitive of step ``i`` from the first of ``tries`` (see
        :meth:`alternatives`; a target may be a function of where the preparation left the
        worker) that works; returns (segment, primitive, the target it reached, gait
        primitives its preparation walked). Raises the first failure (``failure`` if
        given: the blocked walk to the first placement), with how many other placements
        were tried."""
        first = failure
        blocked_at: list[int] = []         # placements whose motions an obstacle blocked
        for program in (False, True):
            if program and not (self.ctx.options.whole_body and failure is not None
                                and self.programs.left > 0 and blocked_at
                                and (failure.reason == "blocked"
                                     or failure.reason == "unreachable")):
                break
            order = [k for k in blocked_at[:WHOLE_BODY_PLACEMENTS] if k != 0] if program \
                else range(len(tries))
            for k in order:
                target, prepare = tries[k]
                mark = self.state.mark()
                made = False
                try:
                    walked = prepare() if prepare is not None else 0
                    if callable(target):
                        target = target()          # where the preparation left the worker
                    made = True
                    seg, mp = self.segment(
                        kind, target, i, text, carry_stance=carrying_before,
                        seconds=float(args[0]) if kind == "wait" and args else None,
                        grasped=args[0] if kind == "grasp" else None,
                        part=args[0] if kind in ("move", "insert", "release", "extract")
                        and args else None,
                        container=args[1] if kind == "extract" else None,
                        attempts=None if k == 0 or target is None
                        or self.state.start_arms is not None   # (a try's own stance)
                        else ALTERNATIVE_ATTEMPTS,
                        program=program or (k == 0 and self.ctx.options.whole_body))
                    lifted = self.state.start_arms
                    if lifted is not None and lifted.rise > 0.0 and kind != "grasp":
                        settle(self, lifted, i, text,
                               args[0] if kind in ("move", "insert") else None)
                        self.state.start_arms = None
                    return seg, mp, target, walked
                except PlanningError as exc:
                    # Blocked, or out of reach from where the walk ended (it came from
                    # the side of a machine): the other placements may do; an
                    # alternative may fail in any way.
                    if k == 0 and exc.reason not in ("blocked", "unreachable"):
                        raise
                    if made and exc.reason == "blocked" and not program:
                        blocked_at.append(k)
                    if failure is None or (program and first is None
                                           and k == blocked_at[0]):
                        failure = exc       # the program's try at the first placement
                    # What a failed try placed (a walk, an arm transition) is taken back.
                    self.state.restore(mark)
        if len(tries) == 1:
            raise failure
        raise PlanningError(f"{failure}; so did {len(tries) - 1} other placements tried",
                            task=text, reason=failure.reason)

    def alternatives(self, kind: str, args: tuple[str, ...], target: np.ndarray | None,
                     placement: tuple[float, float] | None, text: str, raised: bool,
                     raise_back: bool = False
                     ) -> list[tuple[np.ndarray | Callable[[], np.ndarray] | None,
                                     Callable[[], int] | None]]:
        """What to try when the goal primitive is blocked, in order: (target, prepare),
        where ``prepare()`` moves the worker first and returns the primitives walked.
        release: other places to let go, then ahead from a roomy spot; bend/stoop/kneel/
        wait: a roomier spot; tasks with a target: :meth:`lift_tries`, the open arc of the
        target, ``ALTERNATE_APPROACHES`` (further back, other sides), a step back from
        where the first try stood, then the nearest stances where the goal model's own
        motion is clear (:mod:`.stance_search`, ``STANCE_WALKS`` of them); with
        ``raise_back`` the arms are raised at each of those spots (they stayed down at the
        first)."""
        if kind == "release":
            # Last, where every place around the worker is in the furniture (a short
            # worker at a shelf it took the part from): from a roomy spot, straight ahead.
            return [(t, None) for t in self.release_targets(args[0])] + [
                (lambda: self.release_targets(args[0])[0], lambda: self.walk_to_room(text))]
        if target is None:
            return [(None, None)] + ([(None, lambda: self.walk_to_room(text))]
                                     if kind in IN_PLACE_TASKS else [])
        if placement is None:
            return [(target, None)]
        x, y, yaw = self.state.pose
        first = math.atan2(y - target[1], x - target[0])
        # Asked only when the try comes (most first tries succeed): where the other hand
        # stands, and whether the goal model reaches from a step back from where the
        # first try stood (when furniture in front kept the worker further back than the
        # placement already, the step back from the placement comes to the same spot).
        mirrored = functools.cache(
            lambda: self.other_hand_placement(kind, args, target, placement, text))
        ahead = float(math.cos(yaw) * (target[0] - x) + math.sin(yaw) * (target[1] - y))
        back = max(b for _, b, _ in ALTERNATE_APPROACHES)
        walk_there = functools.partial(self.walk_there, target, text, raised, raise_back)

        def further() -> bool:
            return ahead > placement[0] + back and self.reaches(
                kind, args, (ahead + back, placement[1], target[2]), raised)

        def approach(turn: float, back: float, other: bool, stand: float | None = None
                     ) -> int:
            if (other and mirrored() is None) or (stand is not None and not further()):
                raise PlanningError(f"task {text}: no reach clear of the obstacles from "
                                    "that side", task=text, reason="blocked")
            d, lat = mirrored() if other else placement
            return walk_there((d + back if stand is None else stand, lat),
                              (first + turn, APPROACH_HALF_WIDTH), ALTERNATIVE_BUDGET)

        walk_to_stance = self.stance_walks(kind, args, target, placement, text, raised,
                                           walk_there, mirrored)

        return [(target, None)] + self.lift_tries(kind, args, target, placement, text,
                                                  raised, raise_back) + [
            (target, functools.partial(self.walk_to_open_arc, text, first, walk_there,
                                       self.side_reach(kind, args, target, placement,
                                                       raised)))] + [
            (target, functools.partial(approach, turn, back, other))
            for turn, back, other in ALTERNATE_APPROACHES
        ] + [(target, functools.partial(approach, 0.0, 0.0, False, ahead + back))] + [
            (target, walk_to_stance) for _ in range(STANCE_WALKS)]

    def stance_walks(self, kind: str, args: tuple[str, ...], target: np.ndarray,
                     placement: tuple[float, float], text: str, raised: bool,
                     walk_there: Callable[..., int],
                     mirrored: Callable[[], tuple[float, float] | None]
                     ) -> Callable[[], int]:
        """A try's preparation that walks to the next stance of :mod:`.stance_search`
        for ``target`` (3,) (from ``placement`` and the other hand's, ``mirrored()``)
        where the goal model's motion is clear, the first found when it is first called;
        returns the gait primitives walked, or raises PlanningError (``blocked``)."""
        stood = self.state.pose
        first = math.atan2(stood[1] - target[1], stood[0] - target[0])

        def find() -> Iterator[Stance]:
            spots = [placement] + ([mirrored()] if mirrored() is not None else [])
            candidates = candidate_stances(self.ctx, target, stood, first, spots)
            model = functools.lru_cache(maxsize=1)(
                functools.partial(self.stance_model, kind, args, target, raised))
            return clear_stances(
                candidates, lambda pose: self.posture_clear_at(kind, model(pose)),
                lambda pose: self.motion_clear_at(kind, args, model(pose), pose))

        stances = StanceTries(find)

        def walk_to_stance() -> int:
            stance = stances.next()
            if stance is None:
                raise PlanningError(f"task {text}: no other stance where the motion keeps "
                                    "clear of the obstacles", task=text, reason="blocked")
            try:
                return walk_there(stance.spot, (stance.side, APPROACH_HALF_WIDTH),
                                  STANCE_BUDGET, stance.pose[2])
            except PlanningError:
                stances.walk_failed(stance)
                raise

        return walk_to_stance

    def walk_there(self, target: np.ndarray, text: str, raised: bool, raise_back: bool,
                   spot: tuple[float, float], sector: tuple[float, float],
                   budget: SearchBudget, stand_yaw: float | None = None) -> int:
        """An alternative's walk (:meth:`approach`) to ``spot`` (ahead, left, m) from
        ``target`` (3,) within ``sector`` and ``budget`` (facing ``stand_yaw``), out of the
        first try's place; the arms ``raised`` come down for the walk and go up again
        after it, as with ``raise_back`` (there they stayed down at the first try).
        Returns the gait primitives walked."""
        lowered = raised and not self.state.held
        if lowered:
            self.executor.arm_transition(True, -1, text)
        self.executor.step_out()            # the first try may have left the worker at a rack
        walked = self.approach(target, spot, text, sector=sector, budget=budget,
                               stand_yaw=stand_yaw)
        if lowered or (raise_back and not self.state.held):
            self.executor.arm_transition(False, -1, text)
            if not lowered:
                self.state.start_arms = StartArms(self.ctx.stance(True), 0.0)
        return walked

    def side_reach(self, kind: str, args: tuple[str, ...], target: np.ndarray,
                   placement: tuple[float, float], raised: bool) -> SideReach:
        """Task ``kind`` (``args``) at ``target`` (3,) from ``placement`` as the side tests
        of :mod:`.open_sides` see it: the acting hand, from the carry stance if ``raised``
        or a part is held."""
        return SideReach(kind, target, placement,
                         acting_hand(self.state, kind, args[0] if args else None),
                         self.ctx.stance(self.state.carrying or raised))

    def walk_to_open_arc(self, text: str, first: float,
                         walk_there: Callable[[tuple[float, float], tuple[float, float],
                                               SearchBudget], int],
                         reach: SideReach) -> int:
        """``walk_there`` (a spot, a side, a budget) to the arc of sides open to ``reach``
        (:func:`.open_sides.open_arc`) nearest the side ``first`` (rad, from the target)
        the first try stood at, other than it (a rack's aisle, not its back); returns
        the gait primitives walked. Only where the first try's side is closed (the level
        line from the target to it passes an obstacle, :func:`.open_sides.side_blocked`):
        elsewhere the other alternatives come first, as they did."""
        if not side_blocked(self.ctx, reach.target, self.state.pose):
            raise PlanningError(f"task {text}: the first side of the target is open to it",
                                task=text, reason="blocked")
        arc = open_arc(self.ctx, reach, first, skip=math.pi / SIDES)
        if arc is None:
            raise PlanningError(f"task {text}: no other side of the target open to it",
                                task=text, reason="blocked")
        return walk_there(reach.placement, (arc.centre, arc.half_width), STANCE_BUDGET)

    def approach_arc(self, target: np.ndarray, placement: tuple[float, float], text: str,
                     arc: Arc | None) -> int:
        """:meth:`approach` from ``arc`` (within ``OPEN_SIDE_BUDGET``), or from any side."""
        if arc is None:
            return self.approach(target, placement, text)
        return self.approach(target, placement, text, sector=(arc.centre, arc.half_width),
                             budget=OPEN_SIDE_BUDGET)

    def lift_tries(self, kind: str, args: tuple[str, ...], target: np.ndarray,
                   placement: tuple[float, float], text: str, raised: bool,
                   raise_back: bool) -> list[tuple[np.ndarray, Callable[[], int]]]:
        """The tries that start the goal motion from raised arms
        (``WorkerState.start_arms``) after the first: with ``raise_back`` (the arms stayed
        down because the step back their raise needed put the target out of the goal
        model's reach), that step back and raise all the same (the whole-body program may
        still reach from there); where the part in hand, carried or about to be, would
        meet the furniture at the first placement (:mod:`.lift_in`), a move or insert
        lifts it over the furniture and steps in, a grasp raises the arms (``raised``:
        they are up already) and lifts it off."""
        def raise_arms() -> int:
            self.executor.arm_transition(False, -1)
            self.state.start_arms = StartArms(self.ctx.stance(True), 0.0)
            return 0

        def lift() -> int:
            walked, self.state.start_arms = lift_in(self, args[0], target, placement, text,
                                                APPROACH_HALF_WIDTH, ALTERNATIVE_BUDGET)
            return walked

        def lift_off() -> int:
            if not raised:                  # (a step back where the furniture is in the way)
                self.executor.arm_transition(False, -1)
            self.state.start_arms = lift_for_grasp(self, args[0], target, placement, text)
            return 0

        tries = [(target, raise_arms)] if raise_back else []
        if kind in ("move", "insert") and args and args[0] in self.state.held \
                and needs_lift(self, args[0], target, placement):
            tries.append((target, lift))
        if kind == "grasp" and needs_lift_out(self, args[0], target, placement):
            tries.append((target, lift_off))
        return tries

    def stance_model(self, kind: str, args: tuple[str, ...], target: np.ndarray,
                     raised: bool, pose: Pose) -> tuple[np.ndarray, dict]:
        """What the goal primitive of ``kind`` for ``target`` (3,) is made from for a worker
        standing at ``pose`` (:meth:`goal_kwargs` with the task's parts: the hand holding
        a part moves it), with a fixed seed: the plan's random stream stays as it was."""
        grasped = args[0] if kind == "grasp" and args else None
        part = args[0] if kind in ("move", "insert", "release", "extract") and args else None
        container = args[1] if kind == "extract" and len(args) > 1 else None
        local, kwargs, _ = self.goal_kwargs(kind, target, self.state.carrying or raised,
                                            None, grasped, part, container, pose=pose)
        return local, {**kwargs, "rng": np.random.default_rng(0)}

    def posture_clear_at(self, kind: str, model: tuple[np.ndarray, dict]) -> bool:
        """Whether the goal model's posture search finds a posture clear of the obstacles
        (:func:`.motion.goals.posture_clear`) for the goal primitive made from ``model``
        (:meth:`stance_model`), with its hand, start stance and low board."""
        from ltl_human_motion.motion.goals import posture_clear
        local, kwargs = model
        obstacles = kwargs.get("obstacles")
        # (no obstacles around, or seated: no posture to rule out)
        return obstacles is None or posture_clear(
            kind, local, self.ctx.library.skeleton, obstacles,
            start_pose=kwargs["start_pose"], hand=kwargs.get("hand", "auto"),
            board=kwargs.get("board"))

    def motion_clear_at(self, kind: str, args: tuple[str, ...],
                        model: tuple[np.ndarray, dict], pose: Pose) -> bool | None:
        """Whether the goal primitive made from ``model`` (:meth:`stance_model`) placed at
        ``pose`` keeps clear (:meth:`goal_clear`); None where the goal model does not
        reach the target from there."""
        local, kwargs = model
        try:
            mp = self.ctx.library.goal(kind, local, **kwargs)
        except ValueError:
            return None
        return self.goal_clear(mp, pose, args[0] if kind == "grasp" and args else None,
                               args[0] if kind == "extract" and args else None)

    def reaches(self, kind: str, args: tuple[str, ...], local: tuple[float, float, float],
                raised: bool) -> bool:
        """Whether the goal model of ``kind`` reaches ``local`` (ahead, left, height) in the
        start frame from the stance the reach starts in (the carry stance if ``raised``
        or a part is held)."""
        hand = acting_hand(self.state, kind, args[0] if kind != "grasp" and args else None)
        try:
            # The model's own reach test (its seeds only vary the timing: a fixed one
            # keeps the plan's random stream as it was).
            self.ctx.library.goal(kind, np.asarray(local, dtype=np.float64),
                                  rng=np.random.default_rng(0),
                                  start_pose=self.ctx.stance(self.state.carrying or raised),
                                  **({"hand": hand} if hand else {}))
        except ValueError:
            return False
        return True

    def other_hand_placement(self, kind: str, args: tuple[str, ...], target: np.ndarray,
                             placement: tuple[float, float], text: str
                             ) -> tuple[float, float] | None:
        """Where ``target`` (3,) is in the standing root's frame for the other hand than
        the one ``placement`` (ahead, left) is for (:func:`.standing.standing_offset`, the
        goal model's reach for that hand), if the task leaves the hand free; else None."""
        if placement[1] == 0.0 or kind not in ONE_HAND_AUTO_TASKS \
                or acting_hand(self.state, kind, args[0] if args else None) is not None:
            return None
        hand = "l_hand" if placement[1] < 0.0 else "r_hand"
        try:
            return standing_offset(self.ctx, kind, target, text, hand,
                                   carry_stance=self.state.carrying)
        except PlanningError:
            return None

    def approach(self, target: np.ndarray, placement: tuple[float, float], text: str,
                 sector: tuple[float, float] | None = None,
                 budget: SearchBudget | None = None, stand_yaw: float | None = None) -> int:
        """Walk to where the goal primitive reaches ``target`` (from ``sector``, facing
        ``stand_yaw`` if given, see :meth:`.walk_goals.WalkGoals.reach`; within
        ``budget``) and take the standing step there; returns the gait primitives walked."""
        desc = f"reach {text} at ({target[0]:.2f}, {target[1]:.2f}, {target[2]:.2f})"
        goal, back = self.goals.reach(target, placement, desc, text, sector=sector,
                                      stand_yaw=stand_yaw)
        self._possible(goal, text, desc)
        expanded0 = self.state.expanded
        if self.state.seat is None and sector is None and stand_yaw is None:
            self.executor.step_towards(target, placement, back, goal=goal)
        walked = self._walk_or_step_into(goal, text, budget, sector is not None
                                         or stand_yaw is not None)
        if not self.executor.adjust_to(target, placement, text, back, stand_yaw):
            # No clear step from where the walk ended: walk on to a spot that needs
            # (almost) none.
            goal, back = self.goals.reach(target, placement, desc, text,
                                          adjust=FINAL_ADJUST_RADIUS, sector=sector,
                                          stand_yaw=stand_yaw)
            self._possible(goal, text, desc)
            final = budget or self.ctx.options.budget
            # (a given budget is the whole walk's: what the first walk left of it)
            left = final.max_nodes - (self.state.expanded - expanded0 if budget is not None
                                      else 0)
            final = replace(final, max_nodes=min(left, FINAL_WALK_NODES),
                            at_goal_nodes=min(final.at_goal_nodes or AT_GOAL_NODES,
                                              FINAL_WALK_NODES))
            # Next to the spot and no stop there keeps the body clear: a blocked spot (the
            # caller tries the other placements).
            no_stop = PlanningError(
                f"task {text}: {desc}: no place to stop within {FINAL_ADJUST_RADIUS:.2f} m "
                "of the reach spot keeps the body clear ("
                + (f"{final.max_nodes} nodes searched)" if final.max_nodes > 0
                   else f"the walk's {budget.max_nodes} nodes spent)"),
                task=text, reason="blocked")
            if final.max_nodes <= 0:
                raise no_stop
            if self.state.seat is None:
                self.executor.step_into(goal)
            try:
                # (an alternative's spot, where the squeeze search ran out next to it:
                # squaring up to the gap and searching again did not find one either)
                walked += self.executor.walk(goal, text, -1, carry=self.state.carrying,
                                             budget=final, square_up=budget is None)
            except PlanningError as exc:
                if exc.reason != "budget":
                    raise
                raise no_stop from exc
            self.executor.adjust_to(target, placement, text, back, stand_yaw)
        return walked

    def _possible(self, goal: Goal, text: str, desc: str) -> None:
        """Raise a blocked :class:`PlanningError` where no floor pose passes ``goal``'s
        test (:attr:`.astar.Goal.possible`): no search could end there."""
        if goal.possible is not None and not goal.possible():
            raise PlanningError(f"task {text}: {desc}: no place to stand there keeps the "
                                "body clear", task=text, reason="blocked")

    def _walk_or_step_into(self, goal: Goal, text: str, budget: SearchBudget | None,
                           step_after: bool) -> int:
        """The walk to ``goal``; with ``step_after``, where its search ends without a
        place to stop, model-made steps into the goal instead if it is that near
        (:meth:`.steps.StepExecutor.step_into`; a side next to furniture can be smaller
        than a tall worker's stop stride). Returns the gait primitives walked."""
        mark = self.state.mark()
        try:
            return self.executor.walk(goal, text, -1, carry=self.state.carrying, budget=budget)
        except PlanningError as exc:
            if not step_after or self.state.seat is not None \
                    or exc.search not in ("budget", "no_stop"):
                raise
            self.state.restore(mark)
            if not self.executor.step_into(goal):
                raise
            return 0

    def approach_under(self, target: np.ndarray, placement: tuple[float, float],
                       text: str) -> int | None:
        """:meth:`approach` to the standing place in front of the nearest edge of a board
        over ``target`` lower than ``SQUARE_BOARD_HEIGHT`` of the stature, square to the
        edge (the walk ends within ``BOARD_FACING`` of it and the standing step squares
        up: the reach under the board is planned square,
        :func:`.standing.standing_offset`); None if there is no such board or no way
        there."""
        low = low_board(self.ctx.cell, target, self.ctx.stature, below=SQUARE_BOARD_HEIGHT)
        if low is None:
            return None
        yaw = math.atan2(-low[3][1], -low[3][0])
        c, s = math.cos(yaw), math.sin(yaw)
        d, lat = placement
        side = math.atan2(-(s * d + c * lat), -(c * d - s * lat))
        mark = self.state.mark()
        try:
            return self.approach(target, placement, text, sector=(side, BOARD_FACING),
                                 budget=SearchBudget(FACING_NODES), stand_yaw=yaw)
        except PlanningError:
            self.state.restore(mark)                 # what the walk placed is taken back
            return None

    def approach_facing(self, target: np.ndarray, placement: tuple[float, float],
                        text: str, facing: np.ndarray | None) -> int:
        """:meth:`approach`; with ``facing`` (3,), from the side of the target that makes
        the worker face it (a seat: sit facing the desk), else from any side."""
        if facing is not None:
            ahead = math.atan2(facing[1] - target[1], facing[0] - target[0])
            # The worker stands ``placement`` from the target: with the target behind
            # (a seat), the standing spot lies towards what the worker will face.
            side = ahead if placement[0] < 0 else ahead + math.pi
            mark = self.state.mark()
            try:
                return self.approach(target, placement, text,
                                     sector=(side, APPROACH_HALF_WIDTH),
                                     budget=SearchBudget(FACING_NODES))
            except PlanningError:
                self.state.restore(mark)
        return self.approach(target, placement, text)

    def walk_to_room(self, text: str) -> int:
        """Walk to the nearest spot with ``IN_PLACE_ROOM`` of floor clearance (a task done
        where the worker stands hit the furniture there); returns the primitives walked."""
        room = IN_PLACE_ROOM

        def roomy(x: np.ndarray, y: np.ndarray, yaw: np.ndarray | None = None) -> np.ndarray:
            return self.ctx.clearance(np.stack([x, y], axis=-1)) > room

        field = self.goals.field(lambda xy, clearance: roomy(xy[:, 0], xy[:, 1]), ("room", room))
        goal = self.goals.from_field(field, roomy, f"find room for {text}", text)
        return self.executor.walk(goal, text, -1, carry=self.state.carrying)

    def release_targets(self, obj: str) -> list[np.ndarray]:
        """Where the hand holding ``obj`` may let it go, palm positions (3,), in order
        (:func:`.standing.release_targets`)."""
        height = float(np.ptp(self.ctx.cell.object(obj).occupancy.aabb(), axis=0)[2])
        return release_targets(self.ctx.cell, self.state.pose, self.ctx.stature, height,
                               self.state.held_offset(obj))

    def pull_length(self, part: str, container: str) -> float:
        """How far an extract pulls ``part`` out of ``container``, metres
        (:func:`.standing.pull_length`)."""
        cell = self.ctx.cell
        return pull_length(cell.object(container).occupancy_at(self.where(container)).aabb(),
                           cell.object(part).occupancy_at(self.where(part)).aabb())

    def pulls_out(self, mp: MotionPrimitive, part: str, container: str) -> bool:
        """Whether the hand of an extract primitive brings ``part`` (carried from the
        contact frame on) out of ``container`` on some frame: Table I's condition, which
        the verifier checks (a worker standing close keeps the part in a deep fixture)."""
        from ltl_human_motion.scene.predicates import enter_object
        joint = holding_joint(mp.meta.get("hand"))
        hand = world_positions(mp, *self.state.pose)[:, JOINT_INDEX[joint]]
        contact = min(grip_frame(mp), len(hand) - 1)
        obj, box = self.ctx.cell.object(part), self.ctx.cell.object(container)
        around = box.occupancy_at(self.where(container))
        offset = self.where(part) - hand[contact]
        return any(not enter_object(obj.occupancy_at(p + offset), around)
                   for p in hand[contact::EXTRACT_CHECK_STRIDE])

    def refusal(self, text: str, kind: str, attempts: int, blocked: list[MotionPrimitive],
                grasped: str | None, counts: tuple[int, int], part: str | None,
                container: str | None, note: str | None = None) -> PlanningError:
        """The error of a goal primitive none of whose ``attempts`` tries was clear;
        ``counts``: how many kept the part in its container, and how many took a limb
        through the body, of those clear of obstacles; ``note``: what the whole-body
        program reached, where it ran."""
        kept_in, self_hits = counts
        if self_hits and not blocked:
            return PlanningError(f"task {text}: every {kind} motion tried ({attempts}) "
                                 "takes a limb through the body from where the worker "
                                 "stands", task=text, reason="blocked")
        if kept_in:
            return PlanningError(f"task {text}: {kept_in} of the {attempts} {kind} motions "
                                 f"tried keep {part} in {container} (the hand does not take "
                                 "it out far enough from where the worker stands), the "
                                 "others run into an obstacle", task=text, reason="blocked")
        into = (f"{len(blocked)} of the {kind} motions tried ({attempts}) run into an "
                f"obstacle, {self_hits} take a limb through the body" if self_hits
                else f"every {kind} motion tried ({attempts}) runs into an obstacle")
        program = "" if note is None else \
            f"; the whole-body program, kept clear of every obstacle: {note}"
        return PlanningError(f"task {text}: {into}; {self.what_blocks(blocked, grasped)}"
                             f"{program}", task=text, reason="blocked")

    def what_blocks(self, blocked: list[MotionPrimitive], grasped: str | None) -> str:
        """In words, what blocks the least blocked of ``blocked`` (goal primitives at the
        current pose that :meth:`goal_clear` refused): the body part, the obstacle, how
        deep and when, or the part in hand or being grasped that meets an obstacle."""
        from ltl_human_motion.scene.contacts import deepest_contact
        contacts = [deepest_contact(world_positions(mp, *self.state.pose), self.ctx.cell,
                                    stature=self.ctx.stature) for mp in blocked]
        found = [c for c in contacts if c is not None]
        if len(found) < len(contacts):
            held = ", ".join(sorted({*self.state.held, *([grasped] if grasped else [])}))
            return f"the part in hand ({held}) meets an obstacle" if held \
                else "an obstacle blocks the reach"
        least = min(found, key=lambda c: c.depth)
        return f"closest try: {least.describe(self.ctx.library.fps)}"

    def whole_body(self, blocked: list[MotionPrimitive], kind: str, grasped: str | None,
                   part: str | None, container: str | None
                   ) -> tuple[MotionPrimitive | None, str | None]:
        """The first of ``blocked`` (hand goal primitives that met an obstacle) that the
        whole-body program (:mod:`.constrained_goals`) remakes clear of every obstacle,
        still reaching the target and passing the checks of :meth:`segment`, or None;
        and where none does, what the program reached, for the refusal."""
        from ltl_human_motion.planning.constrained_goals import (
            constrained_primitive,
            contact_tolerance,
        )
        note = None
        for candidate in blocked[:WHOLE_BODY_TRIES]:
            if candidate.meta.get("hand") in (None, "none") or self.programs.left <= 0 \
                    or not self.palm_clear(candidate):
                continue
            self.programs.left -= 1
            held, held_from = self.held_part(candidate, kind, grasped, part)
            made, miss, result = constrained_primitive(
                candidate, self.ctx.cell.part_set, self.state.pose, self.ctx.stature, held,
                held_from)
            failed = body_failures(made, kind, self.ctx.stature) \
                if made is not None and self.ctx.options.refuse_self_penetration else []
            if made is None:
                note = (
                    f"its palm stops {100 * miss:.1f} cm from the target"
                    if miss > contact_tolerance(kind) else "it cannot keep every part clear"
                    if result.least_clearance < 0.0 else
                    f"it ends {100 * result.end_miss:.1f} cm from the pose it must end in")
            elif not self.goal_clear(made, self.state.pose, grasped,
                                     part if kind == "extract" else None):
                note = "a part in hand still meets an obstacle"
            elif failed:
                note = f"its motion fails the {', '.join(failed)} check"
            elif kind == "extract" and part is not None and container is not None \
                    and not self.pulls_out(made, part, container):
                note = f"it does not take {part} out of {container}"
            else:
                return made, None
        return None, note

    def palm_clear(self, mp: MotionPrimitive) -> bool:
        """Whether the acting palms of goal primitive ``mp`` keep clear of the obstacles
        where the task holds them (contact and hold frames): the whole-body program
        tracks them there, so it cannot help where they are inside an obstacle."""
        from ltl_human_motion.scene.occupancy import capsules_from_positions
        frames = sorted({int(mp.meta.get("contact_frame", 0)),
                         *(int(f) for f in mp.meta.get("hold_frames", []))})
        world = world_positions(mp, *self.state.pose, frames=np.array(frames))
        hand = mp.meta.get("hand")
        palms = ("l_palm", "r_palm") if hand == "both" else (f"{hand[0]}_palm",)
        seg, rad = capsules_from_positions(world, self.ctx.stature, palms)
        return bool(np.all(self.ctx.cell.part_set.capsule_clearance(seg, rad) > 0.0))

    def held_part(self, mp: MotionPrimitive, kind: str, grasped: str | None,
                  part: str | None) -> tuple[HeldPart | None, int]:
        """The part the acting hand of ``mp`` carries, as the whole-body program keeps it
        clear (edges relative to the hand joint, start frame), and the frame from which
        it is carried: a held part from the start, the part being grasped or extracted
        from the frame the hand lifts it; (None, 0) for an empty hand."""
        from ltl_human_motion.motion.goals.kinematics import HeldPart
        taken = grasped if grasped is not None else part if kind == "extract" else None
        name = taken if taken is not None else part if part in self.state.held else None
        if name is None:
            return None, 0
        joint = holding_joint(mp.meta.get("hand"))
        hand = world_positions(mp, *self.state.pose)[:, JOINT_INDEX[joint]]
        obj = self.ctx.cell.objects[name]
        lo, hi = obj.shape.aabb()
        if taken is not None:
            contact = int(mp.meta.get("contact_frame", 0))
            start, offset = lift_frame(mp, hand), self.where(name) - hand[contact]
        else:
            start, offset = 0, self.state.held_offset(name)
        centre = offset + (lo + hi) / 2 - obj.position
        yaw = float(self.state.pose[2])
        c, s = math.cos(yaw), math.sin(yaw)
        to_local = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
        return HeldPart.box(JOINT_INDEX[joint], to_local @ centre, (hi - lo) / 2,
                            rotation=to_local), start

    def goal_clear(self, mp: MotionPrimitive, pose: Pose, grasped: str | None,
                   taken: str | None = None) -> bool:
        """Whether, placed at ``pose``, the body, the objects already in the hands and the
        part being grasped (``grasped``, from the frame the hand lifts it,
        :func:`lift_frame`) or taken out of its container (``taken``, an extract's part,
        from the frame the hand holds it, as the object tracks carry it) keep clear of
        obstacles."""
        world = world_positions(mp, *pose)
        if not self.executor.placed_clear(mp, pose, samples=None, world=world):
            return False
        grasped = grasped or taken
        if grasped is None:
            return True
        from ltl_human_motion.scene.predicates import object_collides
        joint = holding_joint(mp.meta.get("hand"))
        hand = world[:, JOINT_INDEX[joint]]
        contact = grip_frame(mp) if taken is not None else int(mp.meta.get("contact_frame", 0))
        lift = contact if taken is not None else lift_frame(mp, hand)
        if lift >= len(hand):
            return True
        # The part rests on its support until the hand lifts it; carried from then on.
        centre = hand[lift:] + (self.where(grasped) - hand[contact])
        return not np.any(object_collides(self.ctx.cell, grasped, centre))


def body_failures(mp: MotionPrimitive, kind: str, stature: float) -> list[str]:
    """The verifier's biomechanical checks (speeds, ranges of motion, self-penetration,
    balance, planted feet) that goal primitive ``mp`` of task ``kind`` fails on its own."""
    from ltl_human_motion.motion.biomechanics import check_biomechanics
    world = world_positions(mp)
    checks = check_biomechanics(world, mp.fps, stature=stature, labels=[kind] * len(world))
    return [name for name, entry in checks.items() if not entry["passed"]]

