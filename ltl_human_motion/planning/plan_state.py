"""What a plan works in and what its steps change: the planning context, the worker's
state, and the book-keeping of the parts (which hand holds what, where parts rest).

:class:`PlanContext` holds what one plan does not change (the cell, the motion library,
the gait index, the clearance maps, the seeded generator). :class:`WorkerState` holds
what the steps change: the segments placed so far, the root pose, the seat, the parts
in hand. The planner's parts (:mod:`.steps`, :mod:`.walk_goals`, :mod:`.goal_steps`)
share one of each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.motion.automaton import REFERENCE_STATURE
from ltl_human_motion.motion.library import MotionLibrary
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.motion.types import MotionPrimitive
from ltl_human_motion.planning.astar import SearchBudget, SearchOptions
from ltl_human_motion.planning.blend import PlacedSegment
from ltl_human_motion.planning.gait_index import GaitIndex, gait_index
from ltl_human_motion.planning.navigation import (
    ClearanceMap,
    ObstacleField,
    clearance_maps,
    stand_clearance_map,
)
from ltl_human_motion.scene.cell import Cell

Pose = tuple[float, float, float]

#: How far the gripping hand rises before a grasped part counts as lifted off its
#: support (a part resting on a table touches it until then), metres.
LIFT_RISE = 0.001

#: The other hand of each hand joint.
OTHER_HAND = {"l_hand": "r_hand", "r_hand": "l_hand"}

#: The joint that holds a part for a goal primitive's ``meta["hand"]`` (both hands and an
#: unnamed hand: the right hand, the planner's convention since the first grasp).
HOLDING_JOINT = {"l_hand": "l_hand", "r_hand": "r_hand", "both": "r_hand", None: "r_hand"}


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
        tolerance, metres, for the 1.75 m reference worker (a taller one needs
        proportionally more: :attr:`.plan_state.PlanContext.turn_room`).
    stand_clearance : float
        Floor clearance of the spot a goal primitive starts from (hips and a slight
        forward lean need more room than the walking legs), metres, for the 1.75 m
        reference worker (:attr:`.plan_state.PlanContext.stand_room`).
    max_step_back : float
        How much further from the target than the preferred reach the worker may stand
        when an obstacle (a bench) is in the way; the goal primitive leans further.
    refuse_self_penetration : bool
        Take a goal primitive that takes a limb through the body (the biomechanical
        self-penetration check) as blocked, so that other placements are tried.
        Synthesis sets it from ``VerificationOptions.biomechanics``.
    whole_body : bool
        Where every seeded goal primitive of a hand task meets an obstacle, remake the
        first of them with the whole-body program (clearance, range of motion and
        planted feet as constraints of every frame; :mod:`.constrained_goals`) before
        other placements are tried.
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
    refuse_self_penetration: bool = True
    whole_body: bool = True

    @property
    def search(self) -> SearchOptions:
        """The gait-search settings these options give."""
        return SearchOptions(body_radius=self.body_radius,
                             heuristic_speed=self.heuristic_speed,
                             turn_rate=self.turn_rate, cost_noise=self.cost_noise)


@dataclass(frozen=True)
class PlanContext:
    """What one plan does not change.

    Attributes
    ----------
    cell : Cell
    library : MotionLibrary
    index : GaitIndex
        The library's gait primitives as arrays for the search.
    rng : numpy.random.Generator
        The plan's seeded generator (cost noise, goal primitives).
    options : PlannerOptions
    clearance : ClearanceMap
        Floor clearance of the walking map, ``(N, 2) -> (N,)`` metres.
    obstacle_field : ObstacleField
        Distance grid for the search's sampled body checks.
    stand_map : ClearanceMap
        Floor clearance of the obstacles' footprints (no allowance for the arms).
    """

    cell: Cell
    library: MotionLibrary
    index: GaitIndex
    rng: np.random.Generator
    options: PlannerOptions
    clearance: ClearanceMap
    obstacle_field: ObstacleField
    stand_map: ClearanceMap

    @classmethod
    def build(cls, cell: Cell, library: MotionLibrary, rng: np.random.Generator,
              options: PlannerOptions) -> PlanContext:
        """The context of a plan in ``cell`` with ``library`` (the maps are cached per cell)."""
        clearance, obstacle_field = clearance_maps(cell)
        return cls(cell, library, gait_index(library), rng, options, clearance,
                   obstacle_field, stand_clearance_map(cell))

    @property
    def overlap(self) -> int:
        """Frames two placed segments blend over."""
        return int(self.library.overlap)

    @property
    def stature(self) -> float:
        """The worker's stature, metres."""
        return float(self.library.skeleton.stature)

    @property
    def body_scale(self) -> float:
        """How much more floor room the worker's body needs than the reference worker's
        (``REFERENCE_STATURE``, for whom ``PlannerOptions.stand_clearance`` and
        ``turn_clearance`` were set): ``stature / REFERENCE_STATURE``, at least 1. A tall
        worker's knees come further forward as it turns or steps and its hanging hands
        reach bench height (a 1.95 m worker turning 87 degrees 0.27 m from a table put
        its thigh 5 cm into the top); a short worker keeps the reference room."""
        return max(1.0, self.stature / REFERENCE_STATURE)

    @property
    def stand_room(self) -> float:
        """Floor clearance of the spot a goal primitive starts from for this worker,
        metres (``options.stand_clearance`` scaled by :attr:`body_scale`)."""
        return float(self.options.stand_clearance) * self.body_scale

    @property
    def turn_room(self) -> float:
        """Floor clearance a walk must end with to turn there by more than the heading
        tolerance for this worker, metres (``options.turn_clearance`` scaled by
        :attr:`body_scale`)."""
        return float(self.options.turn_clearance) * self.body_scale

    def stance(self, carrying: bool) -> np.ndarray:
        """The standing pose (J, 3), root-relative: arms down, or in the carry stance."""
        lib = self.library
        return np.asarray(lib.carry_standing_pose if carrying else lib.standing_pose)


@dataclass(frozen=True)
class StartArms:
    """Arms raised above the carry stance to lift a part over or off furniture
    (:mod:`.lift_in`): the stance (J, 3) the next goal motion starts and ends in, and the
    lift (m) it was made with."""

    stance: np.ndarray
    rise: float


@dataclass
class WorkerState:
    """What the steps of a plan change.

    Attributes
    ----------
    segments : list of PlacedSegment
        The motion placed so far.
    pose : (x, y, yaw)
        Where the next segment starts (the hand-over pose of the last one).
    gait_state : int or None
        The gait primitive the worker is in; None when standing.
    seat : ndarray, shape (3,), or None
        The seat point sat on; None when standing.
    held : dict
        Part name -> the hand joint holding it.
    held_offsets : dict
        Part name -> its centre's world offset from the holding hand, (3,).
    object_at : dict
        Part name -> where a step put it down, (3,).
    consumed : set
        Parts assembled (a new one comes from the supply when grasped again).
    expanded : int
        A* nodes expanded so far.
    start_arms : StartArms or None
        The arms the next goal motion starts from where a try chose them, else None (the
        walk or carry stance).
    """

    segments: list[PlacedSegment] = field(default_factory=list)
    pose: Pose = (0.0, 0.0, 0.0)
    gait_state: int | None = None
    seat: np.ndarray | None = None
    held: dict[str, str] = field(default_factory=dict)
    held_offsets: dict[str, np.ndarray] = field(default_factory=dict)
    object_at: dict[str, np.ndarray] = field(default_factory=dict)
    consumed: set[str] = field(default_factory=set)
    expanded: int = 0
    start_arms: StartArms | None = None

    @property
    def carrying(self) -> bool:
        """Whether a hand holds a part (the arms are in the carry stance)."""
        return bool(self.held)

    def start_at(self, pose: Pose) -> None:
        """Begin the plan with the worker standing at ``pose`` (x, y, yaw)."""
        self.pose = pose

    def place(self, segment: PlacedSegment, end: Pose | None = None) -> int:
        """Append ``segment`` to the motion; returns its index. With ``end`` (its hand-over
        pose) the next segment starts there; without, the segment was made in place (a
        stand-still, an arm motion) and the next starts where it did. With
        :meth:`start_at` and :meth:`restore`, the only writer of :attr:`pose`."""
        self.segments.append(segment)
        if end is not None:
            self.pose = end
        return len(self.segments) - 1

    def mark(self) -> tuple[int, Pose, int | None, StartArms | None]:
        """Where the plan stands now, for :meth:`restore`: (segments, pose, gait state,
        start arms)."""
        return len(self.segments), self.pose, self.gait_state, self.start_arms

    def restore(self, mark: tuple[int, Pose, int | None, StartArms | None]) -> None:
        """Take back every segment placed since ``mark`` (a try that failed); the parts
        in hand are not changed by walks, steps and arm transitions."""
        del self.segments[mark[0]:]
        self.pose, self.gait_state, self.start_arms = mark[1], mark[2], mark[3]

    def held_offset(self, name: str) -> np.ndarray:
        """The held part's offset from its hand (3,); zero for a part not held."""
        return self.held_offsets.get(name, np.zeros(3))


def in_start_frame(pose: Pose, target: np.ndarray) -> np.ndarray:
    """``target`` (3,) in the start frame of a worker standing at ``pose`` (x, y, yaw):
    (ahead, left, height), shape (3,)."""
    x, y, yaw = pose
    c, s = math.cos(-yaw), math.sin(-yaw)
    dx, dy = target[0] - x, target[1] - y
    return np.array([c * dx - s * dy, s * dx + c * dy, target[2]], dtype=np.float64)


def holding_joint(hand: str | None) -> str:
    """The joint that holds a part for a goal primitive's ``meta["hand"]``
    (``HOLDING_JOINT``; any other value: the right hand)."""
    return HOLDING_JOINT.get(hand, "r_hand")


def object_position(cell, state: WorkerState, name: str) -> np.ndarray:
    """Where object ``name`` rests now (3,): where the last step put it down, else its
    supply position in the cell."""
    at = state.object_at.get(name)
    return np.asarray(cell.object(name).position if at is None else at, dtype=np.float64)


def acting_hand(state: WorkerState, kind: str, part: str | None) -> str | None:
    """The hand a goal task must use, or None (either): a move, insert or release of a
    held ``part`` uses the hand holding it; a grasp or extract while one hand holds a
    part uses the other hand."""
    if part is not None and part in state.held and kind in ("move", "insert", "release"):
        return state.held[part]
    busy = set(state.held.values())
    if kind in ("grasp", "extract") and len(busy) == 1:
        return OTHER_HAND[next(iter(busy))]
    return None


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


@dataclass(frozen=True)
class Effects:
    """What a goal step does to the parts, as the object tracks follow it.

    Attributes
    ----------
    attach : tuple of (str, str)
        (part, hand joint): the parts the hand takes, held from the grip frame on.
    detach : tuple of str
        The parts the hand lets go at the grip frame.
    consume : tuple of str
        The parts assembled (gone from the cell).
    respawn : tuple of str
        Attached parts that are fresh ones from their supply (one was assembled before).
    """

    attach: tuple[tuple[str, str], ...] = ()
    detach: tuple[str, ...] = ()
    consume: tuple[str, ...] = ()
    respawn: tuple[str, ...] = ()


def apply_effects(state: WorkerState, kind: str, args: tuple[str, ...], hand: str | None,
                  keep_hold: bool = False) -> Effects:
    """Update which parts ``state`` holds after a goal task; returns the effect for the
    object tracks. ``keep_hold``: a held part that a move puts into its region stays in
    hand (carry)."""
    hand_joint = holding_joint(hand)
    if kind == "grasp":
        state.held[args[0]] = hand_joint
        return Effects(attach=((args[0], hand_joint),))
    if kind == "release":
        state.held.pop(args[0], None)
        return Effects(detach=(args[0],))
    if kind in ("move", "insert", "extract"):
        if args[0] not in state.held:
            # extract takes the part out of its container and keeps it in hand (move
            # and insert fetch the part first).
            state.held[args[0]] = hand_joint
            return Effects(attach=((args[0], hand_joint),))
        if kind == "extract" or keep_hold:
            return Effects()
        state.held.pop(args[0], None)
        return Effects(detach=(args[0],))
    if kind == "assemble":
        parts = tuple(state.held)
        state.consumed.update(parts)
        state.held.clear()
        return Effects(detach=parts, consume=parts)
    return Effects()


def track_objects(cell, state: WorkerState, effect: Effects, joints: dict[str, str],
                  positions: np.ndarray, mp: MotionPrimitive) -> None:
    """Follow a step's effect on the parts as the object tracks will: a part keeps its
    world offset from the hand from the grip frame on, and rests where the hand let it
    go.

    Parameters
    ----------
    joints : dict
        The hands holding parts before the step (updated).
    positions : ndarray, shape (T, J, 3)
        The placed goal segment.
    mp : MotionPrimitive
        Its primitive (grip frame, length).
    """
    contact = min(grip_frame(mp), mp.n_frames - 1)
    for name, joint in effect.attach:
        joints[name] = joint
        state.held_offsets[name] = (object_position(cell, state, name)
                                    - positions[contact, JOINT_INDEX[joint]])
    for name in effect.detach:
        offset = state.held_offsets.pop(name, np.zeros(3))
        if name in joints:
            state.object_at[name] = positions[contact, JOINT_INDEX[joints[name]]] + offset
    for name in effect.consume:
        state.object_at.pop(name, None)


__all__ = ["LIFT_RISE", "OTHER_HAND", "Effects", "PlanContext", "Pose",
           "WorkerState", "acting_hand", "apply_effects", "grip_frame", "holding_joint",
           "lift_frame",
           "object_position", "track_objects"]
