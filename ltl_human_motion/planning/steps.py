"""The step executor: places motion segments and keeps the worker's state.

:class:`StepExecutor` appends placed segments to the shared
:class:`~.plan_state.WorkerState` and returns what it made (segment indices, gait
primitives walked, whether a step was clear): walks found by A* (:mod:`.astar`) and
checked on every frame, standing steps and turns (:mod:`.turns`), arm transitions,
stand-stills and seated waits. Its collision checks are the verifier's (exact capsule
distances on every frame, parts in hand included), so a plan it accepts does not fail
collision afterwards.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion.capsules import part_indices
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.motion.types import MotionPrimitive, world_positions
from ltl_human_motion.planning.astar import (
    Goal,
    SearchBudget,
    SearchFailure,
    astar,
    placement_key,
)
from ltl_human_motion.planning.blend import PlacedSegment, wrap_angle
from ltl_human_motion.planning.plan_state import PlanContext, Pose, WorkerState
from ltl_human_motion.planning.standing import ideal_placement
from ltl_human_motion.planning.walk_goals import walk_grid

#: Clearance (m) the planner keeps between the body and obstacles on the frames it
#: checks exactly: the verifier allows none below 0; blends between segments move
#: joints by a few millimetres.
PLACED_MARGIN = 0.003

#: Stride of the measured frames of an every-frame check, and the clearance below which
#: those measurements are exact, metres (:func:`body_clear_every_frame`).
CLEAR_STRIDE = 4

CLEAR_EXACT = 0.1
#: The clearance below which the planner's other checks measure exactly, metres (only
#: clearances near ``PLACED_MARGIN`` decide a check; farther ones may be bounds).
EXACT_BELOW = 0.01

#: Clearance (m) the search asks of a part in hand at points on its box on its gait
#: samples, beyond the obstacle field's interpolation allowance: the points are not
#: inside an obstacle. A shallow corner between them is left to the exact check of the
#: path (:meth:`StepExecutor.first_collision`), which decides; a margin for their
#: spacing kept a part in hand from every stop at a table. Without the check a carton
#: carried at hip height was walked over a packing table's top on every path found.
HELD_SEARCH_MARGIN = 0.0
#: Largest spacing (m) of the points a part in hand is read at by the search.
HELD_POINT_SPACING = 0.05


def held_surface(cell, name: str) -> tuple[np.ndarray, float]:
    """Points on the surface of object ``name``'s bounding box, relative to its centre
    (P, 3), no further apart than ``HELD_POINT_SPACING`` along each face, and that
    spacing."""
    def build() -> tuple[np.ndarray, float]:
        obj = cell.object(name)
        lo, hi = obj.shape.aabb()
        lo, hi = lo - obj.position, hi - obj.position
        n = np.maximum(np.ceil((hi - lo) / HELD_POINT_SPACING).astype(int), 1) + 1
        axes = [np.linspace(lo[k], hi[k], n[k]) for k in range(3)]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        on_face = np.any(np.isclose(grid, lo) | np.isclose(grid, hi), axis=1)
        return np.ascontiguousarray(grid[on_face]), float(np.max((hi - lo) / (n - 1)))

    return _HELD_SURFACES.get_or_build(name, build, owner=cell)


_HELD_SURFACES: BoundedCache[tuple[np.ndarray, float]] = BoundedCache(64)


#: Clearance the search asks of the body on the gait samples between those it keeps
#: 1 cm on (``gait_index.BODY_SAMPLES``), in units of the obstacle field's resolution
#: and counted from the field's own interpolation allowance (0.4 resolution): -0.4, the
#: capsules only must not be inside an obstacle by the field. That catches a hand
#: swinging 1-7 cm into a crate between the 1 cm samples; with the allowance (or a
#: margin) these samples turned away steps along an aisle's boards that the exact check
#: of the path passes (4 aisle runs that verified failed).
SWEEP_MARGIN = -0.4
#: The body parts checked on those samples: the arms, which swing across the body's
#: path between the samples (every collision the 5 samples missed in cluttered was a
#: hand, palm or forearm); the trunk and legs move with the root path the search checks.
SWEEP_PARTS: tuple[str, ...] = ("l_upper_arm", "r_upper_arm", "l_lower_arm", "r_lower_arm",
                                "l_hand", "r_hand", "l_palm", "r_palm")
_SWEEP_INDICES = part_indices(SWEEP_PARTS)

#: Headings at which :meth:`StepExecutor.turn_clear` checks the body (odd, as
#: :meth:`StepExecutor.body_clear` reads even and odd samples): 0.4 rad apart in a
#: half turn.
TURN_SAMPLES = 9

#: A failed search that came no further than this from its start (m) got nowhere from
#: there: the worker steps away first and it searches again, once per start in a plan
#: (:meth:`StepExecutor.walk`: the corpus aisle's 1.95 m worker, whom no step gets
#: in, stepped back and forth at its entrance for every placement tried).
STUCK_RADIUS = 0.4

#: Whole-body programs of arm transitions that may fail in one plan before no more are
#: run (:meth:`StepExecutor.transition_clear`).
TRANSITION_PROGRAMS = 3

#: Searches run again after the path found collided on a frame the search did not
#: sample (each forbids the colliding primitive at its pose).
WALK_REPAIRS = 4

#: Backward steps tried (m) to leave a spot closer to an obstacle than walking allows,
#: and the clearance beyond ``PlannerOptions.body_radius`` the step must reach (m).
STEP_OUT_DISTANCES: tuple[float, ...] = (0.1, 0.2, 0.3)

STEP_OUT_MARGIN = 0.02

#: Steps aside (m, left positive) tried when no backward step clears what follows.
SIDE_STEPS: tuple[float, ...] = (0.1, -0.1, 0.2, -0.2)

#: Model-made standing steps (ahead, left), m, tried in order to get room: back, aside,
#: then both at once (an open machine door beside the worker reaches further back than
#: a step).
STEP_MOVES: tuple[tuple[float, float], ...] = tuple(
    [(-back, 0.0) for back in STEP_OUT_DISTANCES] + [(0.0, side) for side in SIDE_STEPS]
    + [(-back, side) for back in STEP_OUT_DISTANCES for side in SIDE_STEPS])

#: A squeezing walk whose search ran out of budget in a gap whose middle has less floor
#: clearance (footprint map) than this, metres, squares up to the gap's axis, steps to
#: that middle and searches again: half the corpus aisle's 0.8 m width and 5 cm, the
#: widest gap whose walls a tall worker's swinging hands (0.91 m board) and elbows
#: (1.2 m board) reach when walking a few degrees off its axis or a few centimetres
#: off its middle (aisle at 1.95 m: 126 of 300 gait
#: candidates rejected for the left hand at the 0.91 m board, 58 for the right forearm
#: at the 1.2 m board, from a start 7 cm off the middle turned 33 deg).
SQUARE_UP_GAP = 0.45

#: Side offsets tried for the middle of the gap when squaring up (metres, across the
#: walk's heading): the spot with the most floor clearance among them, if not at either
#: end (a gap, not a single wall the clearance grows away from); 2.5 cm steps up to a
#: short side step (a quarter step more than ``SIDE_STEPS``' 0.2 m).
SQUARE_UP_OFFSETS = np.linspace(-0.25, 0.25, 21)

#: Axis directions tried for a gap (rad, 5 deg apart over a half turn), and how far the
#: line along each is followed either way (metres, about one gait step).
SQUARE_UP_AXES = np.radians(np.arange(0.0, 180.0, 5.0))
SQUARE_UP_REACH = 0.5

#: Node budget of a squeezing walk without getting ``astar.STALL_PROGRESS`` nearer
#: its goal (``SearchBudget.idle_nodes``): along a gap the body barely fits the search
#: gets on at once or not at all (the aisle's walks take under 20 nodes; a goal the
#: body cannot stand at took the whole 8000 and the pair's time limit). It was the
#: whole budget; a tall worker's walk out of the aisle from a task inside it, whose
#: first steps must find the few gait starts that keep the hands off the 0.91 m board
#: and the elbows off the 1.2 m board, needed more (aisle, 1.95 m: 5 walks to R1).
SQUEEZE_NODES = 1000

#: A walk's search that expands this many nodes without getting nearer the goal stalls
#: (in front of a gap the walking body does not pass: the cell with crates floods 7000
#: nodes there; searches that get through a tight spot went up to about 2500 nodes
#: without progress there); its goal then reroutes around a disc of
#: ``STALL_BLOCK_RADIUS`` (m) at the closest approach, up to ``MAX_REROUTES`` times.
STALL_NODES = 3500

MAX_REROUTES = 2

#: Arm transitions by (stances, stature, rate, blend, carrying before) (see
#: :meth:`StepExecutor.arm_poses`).
_ARM_POSES: BoundedCache[np.ndarray] = BoundedCache(32)

#: How much further back than the ideal spot a standing adjustment may stand when the
#: step there would touch an obstacle, metres, tried in order (up to a short step).
ADJUST_BACKS: tuple[float, ...] = (0.0, 0.05, 0.1, 0.15)
#: A standing adjustment shorter than this (metres, radians) is not made: the worker
#: already stands where the goal primitive reaches from.
ADJUST_STILL = (0.02, 0.05)
#: How far from the ideal placement (in adjust radii) a worker standing still takes a
#: model-made step towards it before walking (:meth:`StepExecutor.step_towards`): two
#: steps reach it, where a 1.95 m worker's gait start and stop (0.5 m each) overshoot.
STEP_TOWARDS_REACH = 2.0
#: Spacing (m) of the spots a worker standing near a walk's goal tries to step into when
#: no gait start and stop fits (:meth:`StepExecutor.step_into`), and how many of the
#: nearest are tried.
STEP_INTO_GRID = 0.05
STEP_INTO_TRIES = 8
#: The gait index's step straight back (metres ahead, left), the first step tried to
#: get room in front (:meth:`StepExecutor.step_back`).
GAIT_STEP_BACK = [-0.3, 0.0]


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
                                      exact_below=EXACT_BELOW)) > PLACED_MARGIN)


@functools.lru_cache(maxsize=8)
def _sample_sets(n_samples: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The samples :meth:`StepExecutor.body_clear` reads of ``n_samples``: the even ones,
    the odd ones, and the first with the odd ones (shared: callers must not write; left
    writeable, as the compiled loops take them)."""
    return np.arange(0, n_samples, 2), np.arange(1, n_samples, 2), np.r_[0, 1:n_samples:2]


class StepExecutor:
    """Places the segments of one plan.

    Parameters
    ----------
    ctx : PlanContext
    state : WorkerState
        Changed by every method that places a segment.
    """

    def __init__(self, ctx: PlanContext, state: WorkerState) -> None:
        self.ctx = ctx
        self.state = state
        # Arm transitions the whole-body program remade, or failed to, by pose and name
        # (:meth:`transition_clear`; placements tried one after another come back to the
        # same spot), and how many programs failed.
        self._transitions: dict[tuple, MotionPrimitive | None] = {}
        self._transition_failures = 0
        # Walk starts where stepping away did not get a search any further.
        self._stuck: set[tuple] = set()

    def add(self, mp: MotionPrimitive, pose: Pose, label: int, blend: int,
            end: Pose | None = None) -> int:
        """Place ``mp`` at ``pose`` as the next segment (task label ``label``, blended over
        ``blend`` frames with the one before); the worker then stands at ``end`` if given,
        else where it stood (a motion in place). Returns the segment's index."""
        segment = PlacedSegment(world_positions(mp, *pose), pose[2] + mp.root[:, 3], label,
                                blend if self.state.segments else 0, mp.name)
        return self.state.place(segment, end)

    def advance(self, mp: MotionPrimitive, label: int = -1) -> int:
        """Place ``mp`` where the worker stands and move the worker to its hand-over pose
        (:meth:`hand_over_pose`); returns the segment's index."""
        pose = self.state.pose
        return self.add(mp, pose, label, self.ctx.overlap, self.hand_over_pose(mp, pose))

    def hand_over_pose(self, mp: MotionPrimitive, pose: Pose) -> Pose:
        """The floor pose where ``mp`` placed at ``pose`` hands over to the next segment
        (its root ``overlap`` frames before its end)."""
        k = max(mp.n_frames - self.ctx.overlap, 0)
        r = mp.root[k]
        c, s = math.cos(pose[2]), math.sin(pose[2])
        return (pose[0] + c * r[0] - s * r[1], pose[1] + s * r[0] + c * r[1], pose[2] + r[3])

    def stand_still(self, label: int, seconds: float) -> None:
        """A short standing segment (start of the motion, end of a walk task)."""
        n = max(round(seconds * self.ctx.library.fps), self.ctx.overlap + 2)
        rel = np.repeat(self.ctx.stance(self.state.carrying)[None], n, axis=0)
        root = np.zeros((n, 4))
        root[:, 2] = self.ctx.library.standing_height
        mp = MotionPrimitive("stand", "wait", rel, root, self.ctx.library.fps, "planner: stand")
        self.add(mp, self.state.pose, label, self.ctx.overlap)

    def body_clear(self, poses: np.ndarray, standing: np.ndarray) -> np.ndarray:
        """Whether sampled poses (M, S, J, 3) (S odd: ``gait_index.BODY_SAMPLES``) keep
        1 cm from every obstacle on the even samples and whose arms do not enter one
        (``SWEEP_MARGIN``, ``SWEEP_PARTS``) on the odd ones between them, shape (M,);
        standing primitives (``standing`` (M,)) need only not come closer."""
        out = np.ones(len(poses), dtype=bool)
        stature = self.ctx.stature
        field = self.ctx.obstacle_field
        even, odd, first_odd = _sample_sets(poses.shape[1])
        stand = standing.nonzero()[0]
        groups = ((False, np.arange(len(poses))),) if not stand.size else \
            ((False, (~standing).nonzero()[0]), (True, stand))
        for rel, sel in groups:
            if sel.size:
                ok = field.clear_samples(poses, sel, even, stature, relative=rel)
                if ok.any():
                    keep = sel[ok]
                    # (with ``relative``, after the start they are measured from)
                    ok[ok] = field.clear_samples(poses, keep, first_odd if rel else odd,
                                                 stature, margin=SWEEP_MARGIN * field.res,
                                                 relative=rel, parts=_SWEEP_INDICES)
                out[sel] = ok
        if self.state.held and out.any():
            keep = out.nonzero()[0]
            out[keep] = self.held_clear(poses[keep], standing[keep])
        return out

    def turn_clear(self, x: np.ndarray, y: np.ndarray, yaw: np.ndarray, to_yaw: np.ndarray
                   ) -> np.ndarray:
        """Whether the standing body (and the parts in hand) turned on the spot at floor
        points (x, y) from ``yaw`` to ``to_yaw`` keeps clear (:meth:`body_clear` of the
        stance at ``TURN_SAMPLES`` headings between; a standing primitive's rule: no
        part gets closer than it starts). All (M,); bool (M,). The room a walk needs to
        end turned away from its goal, asked of the body instead of a disc on the floor:
        in an aisle 0.8 m wide the hips turn, while the walking map, widened for the arms
        at tall parts, has no disc of that radius."""
        lib = self.ctx.library
        stance = self.ctx.stance(self.state.carrying)                         # (J, 3)
        a = yaw[:, None] + wrap_angle(to_yaw - yaw)[:, None] \
            * np.linspace(0.0, 1.0, TURN_SAMPLES)                              # (M, K)
        c, s = np.cos(a)[..., None], np.sin(a)[..., None]
        poses = np.empty(a.shape + stance.shape)
        poses[..., 0] = c * stance[:, 0] - s * stance[:, 1] + x[:, None, None]
        poses[..., 1] = s * stance[:, 0] + c * stance[:, 1] + y[:, None, None]
        poses[..., 2] = stance[:, 2] + lib.standing_height
        return self.body_clear(poses, np.ones(len(poses), dtype=bool))

    def search_options(self):
        """The search's options, with the body's exact checks (``near_radius``) begun far
        enough from an obstacle for the parts in hand to be checked too: a carton held
        0.5 m ahead of the hips reaches past the body's radius."""
        options = self.ctx.options.search
        if not self.state.held:
            return options
        stance = self.ctx.stance(True)
        reach = 0.0
        for name, joint in self.state.held.items():
            pts, _ = held_surface(self.ctx.cell, name)
            at = stance[JOINT_INDEX[joint]] + self.state.held_offset(name) + pts
            reach = max(reach, float(np.hypot(at[:, 0], at[:, 1]).max()))
        return replace(options, near_radius=max(options.near_radius,
                                                reach + options.body_radius))

    def held_clear(self, poses: np.ndarray, standing: np.ndarray) -> np.ndarray:
        """Whether the parts in hand keep ``HELD_SEARCH_MARGIN`` from every obstacle at
        the sampled poses (M, S, J, 3), by the obstacle field at points on each part's
        box (:func:`held_surface`); standing primitives (``standing`` (M,)) need only not
        come closer than at their first sample. Shape (M,)."""
        field = self.ctx.obstacle_field
        out = np.ones(len(poses), dtype=bool)
        if field.empty:
            return out
        for name, joint in self.state.held.items():
            pts, _ = held_surface(self.ctx.cell, name)
            centre = poses[:, :, JOINT_INDEX[joint]] + self.state.held_offset(name)
            out &= field.points_clear(centre, pts, HELD_SEARCH_MARGIN + field.res * 0.4,
                                      standing)
        return out

    def sit_still(self, seconds: float) -> MotionPrimitive:
        """A wait on the seat: the seated pose held (the standing wait model would rebuild
        the legs for standing)."""
        pose = self.seated_pose(self.state.pose)
        n = max(round(seconds * self.ctx.library.fps), self.ctx.overlap + 2)
        root = np.zeros((n, 4))
        root[:, :3] = pose[0]
        rel = np.repeat((pose - pose[0])[None], n, axis=0)
        return MotionPrimitive(f"sit_still_{seconds:.2f}s", "wait", rel, root,
                               self.ctx.library.fps, "planner: seated wait",
                               meta={"contact_frame": n - 1, "hand": "none"})

    def seated_pose(self, pose: Pose) -> np.ndarray:
        """The last frame placed (the worker seated), in the start frame of ``pose``
        (root floor point at the origin, facing +x; heights above the floor), (J, 3)."""
        x, y, yaw = pose
        last = self.state.segments[-1].positions[-1]
        c, s = math.cos(-yaw), math.sin(-yaw)
        dx, dy = last[:, 0] - x, last[:, 1] - y
        return np.stack([c * dx - s * dy, s * dx + c * dy, last[:, 2]], axis=-1)

    def seated_in_carry_stance(self) -> bool:
        """Whether the seated worker's arms are in the carry stance (the stance nearer the
        last frame's hands relative to the shoulders; the seat keeps the stance the worker
        sat down in, also after a seated task took the part out of the hands)."""
        last = self.state.segments[-1].positions[-1]
        hands = [JOINT_INDEX[n] for n in ("l_hand", "r_hand")]
        shoulders = [JOINT_INDEX[n] for n in ("l_shoulder", "r_shoulder")]

        def offset(pose: np.ndarray) -> np.ndarray:
            return np.linalg.norm(pose[hands] - pose[shoulders], axis=-1)

        seated = offset(np.asarray(last))
        return bool(np.sum(np.abs(offset(self.ctx.stance(True)) - seated))
                    < np.sum(np.abs(offset(self.ctx.stance(False)) - seated)))

    def arm_transition(self, carrying_before: bool, label: int, task: str | None = None
                       ) -> None:
        """Bring the arms from the walk stance to the carry stance or back (for ``task``,
        named in the error where it is blocked).

        The palms move beside the body on a smooth curve, timed by Fitts' law with a
        bounded peak speed (:func:`~ltl_human_motion.motion.arm_transition.
        arm_transition_poses`). Where the transition would hit an obstacle, the worker
        steps back first, or where no step clears it the whole-body program remakes it
        (:meth:`transition_clear`).
        """
        rel = self.arm_poses(carrying_before)
        root = np.zeros((len(rel), 4))
        root[:, 2] = self.ctx.library.standing_height
        mp = MotionPrimitive("arms_to_carry" if not carrying_before else "arms_to_walk", "wait",
                             rel, root, self.ctx.library.fps, "planner: arm transition")
        if not self.placed_clear(mp, self.state.pose) and not self.step_back(carrying_before,
                                                                           label, mp):
            mp = self.transition_clear(mp)
        if mp is None:
            raise PlanningError(("" if task is None else f"task {task}: ")
                                + f"bringing the arms {'down' if carrying_before else 'up'} at "
                                f"({self.state.pose[0]:.2f}, {self.state.pose[1]:.2f}) hits an "
                                "obstacle, also after a step back", task=task, reason="blocked")
        self.add(mp, self.state.pose, label, self.ctx.overlap)

    def transition_clear(self, mp: MotionPrimitive) -> MotionPrimitive | None:
        """Arm transition ``mp`` at the current pose remade by the whole-body program
        (:func:`.constrained_goals.constrained_transition`) where the hands are empty and
        the program is on, if it keeps the body clear on every frame and passes the
        verifier's biomechanical checks; else None. Asked once per pose; after
        ``TRANSITION_PROGRAMS`` programs that failed, no more are run (about 0.3 s each:
        a tall worker's arms in an aisle, tried at every placement)."""
        from ltl_human_motion.motion.biomechanics import check_biomechanics
        from ltl_human_motion.planning.constrained_goals import constrained_transition
        if self.state.held or not self.ctx.options.whole_body:
            return None
        key = (*map(float, self.state.pose), mp.name)
        if key in self._transitions:
            return self._transitions[key]
        if self._transition_failures >= TRANSITION_PROGRAMS:
            return None
        made = constrained_transition(mp, self.ctx.cell.part_set, self.state.pose,
                                      self.ctx.stature)
        if made is not None and self.placed_clear(made, self.state.pose):
            checks = check_biomechanics(world_positions(made), made.fps,
                                        stature=self.ctx.stature,
                                        labels=[made.task] * made.n_frames)
            made = made if all(entry["passed"] for entry in checks.values()) else None
        else:
            made = None
        self._transitions[key] = made
        self._transition_failures += made is None
        return made

    def arm_poses(self, carrying_before: bool) -> np.ndarray:
        """Root-relative poses (T, J, 3) of the arm transition (made once per library and
        direction: it depends on nothing else)."""
        from ltl_human_motion.motion.arm_transition import arm_transition_poses
        from ltl_human_motion.motion.retarget import enforce_bone_lengths
        key = (self.ctx.stance(False).tobytes(), self.ctx.stance(True).tobytes(),
               self.ctx.stature, self.ctx.library.fps, self.ctx.overlap,
               bool(carrying_before))

        def build() -> np.ndarray:
            a, b = self.ctx.stance(carrying_before), self.ctx.stance(not carrying_before)
            rel = arm_transition_poses(a, b, self.ctx.library.skeleton, self.ctx.library.fps)
            if len(rel) < self.ctx.overlap + 2:
                rel = np.concatenate([rel, np.repeat(rel[-1:], self.ctx.overlap + 2 - len(rel),
                                                     0)])
            # The pipeline restores bone lengths after blending, so the transition is
            # checked as it will be played.
            rel = enforce_bone_lengths(rel, self.ctx.library.skeleton, rigid_hips=False)
            rel.flags.writeable = False
            return rel

        return _ARM_POSES.get_or_build(key, build)

    def placed_clear(self, mp: MotionPrimitive, pose: Pose, samples: int | None = None,
                     world: np.ndarray | None = None, put_down: str | None = None) -> bool:
        """Whether ``mp`` placed at ``pose`` keeps the body and the objects held (at their
        hand offsets) clear of every obstacle, checked with the exact distances on
        ``samples`` frames (None: every frame, as the verifier checks). ``world``:
        ``world_positions(mp, *pose)`` if already made; ``put_down``: a held part the
        motion before put down (not moved with the hand)."""
        from ltl_human_motion.scene.predicates import body_clearance, object_collides
        if not self.ctx.cell.obstacles:
            return True
        stature = self.ctx.stature
        if samples is None:
            world = world_positions(mp, *pose) if world is None else world
            if not body_clear_every_frame(world, self.ctx.cell, stature):
                return False
        else:
            frames = np.linspace(0, mp.n_frames - 1, samples).round().astype(int)
            if world is None and self.state.held:
                world = world_positions(mp, *pose)
            body = world_positions(mp, *pose, frames=frames) if world is None else world[frames]
            # Only clearances up to the PLACED_MARGIN limit matter: those are exact.
            d = body_clearance(body, self.ctx.cell, stature=stature, exact_below=EXACT_BELOW)
            if np.min(d) <= PLACED_MARGIN:
                return False
        for name, joint in self.state.held.items():
            if name == put_down:
                continue
            step = 1 if samples is None else 2
            centre = world[::step, JOINT_INDEX[joint]] + self.state.held_offset(name)
            if np.any(object_collides(self.ctx.cell, name, centre)):
                return False
        return True

    def step_out(self) -> None:
        """Step back onto walkable floor if the worker stands closer to an obstacle than a
        walk may start (at a rack, where reaching allowed it): the search could not
        leave the spot otherwise."""
        from ltl_human_motion.planning.turns import make_step_primitive
        x, y, yaw = self.state.pose
        if self.walkable(x, y):
            return
        carrying = self.state.carrying
        lib = self.ctx.library
        c, s = math.cos(yaw), math.sin(yaw)
        for back in STEP_OUT_DISTANCES:
            if not self.walkable(x - back * c, y - back * s):
                continue
            mp = make_step_primitive(self.ctx.stance(carrying), lib.standing_height, -back, 0.0,
                                     0.0, lib.skeleton, lib.fps,
                                     "carry" if carrying else "walk")
            if self.placed_clear(mp, self.state.pose, samples=None):
                self.advance(mp)
                return

    def step_away(self, clearance: Callable[[np.ndarray], np.ndarray]) -> bool:
        """A model-made standing step of ``STEP_MOVES`` onto floor with more ``clearance``
        (the search's map, of (M, 2) points) than where the worker stands, clear on every
        frame (:meth:`take_steps`): where the first move of every walk from here, a turn
        on the spot, swings a leg into the furniture in front, or no search gets away
        from here. Returns whether it stepped."""
        x, y, yaw = self.state.pose
        c, s = math.cos(yaw), math.sin(yaw)
        here = float(clearance(np.array([[x, y]]))[0])
        to = np.array([[x + c * dx - s * dy, y + s * dx + c * dy] for dx, dy in STEP_MOVES])
        roomier = clearance(to) > here
        if not self.take_steps([((dx, dy, 0.0),) for (dx, dy), ok in zip(STEP_MOVES, roomier)
                                if ok]):
            return False
        self.state.gait_state = None
        return True

    def square_up(self, goal: Goal, carrying: bool) -> bool:
        """In a narrow gap (its middle has less floor clearance on the footprint map than
        ``SQUARE_UP_GAP``): turn on the spot to the gap's axis, the way towards ``goal``,
        and step sideways to its middle (``SQUARE_UP_OFFSETS``), in one standing step, if
        that keeps the body clear on every frame and is not shorter than
        ``ADJUST_STILL``. A gait cycle started turned or off the middle there swings a
        hand or elbow into a rack's board (a tall worker's hands at the 0.91 m board,
        elbows at the 1.2 m board) and the search floods the spot until its budget runs
        out; square to the gap it may walk out. Returns whether the step was added."""
        x, y, yaw = self.state.pose
        axis = self.gap_axis(goal)
        if axis is None:
            return False
        side = np.array([-math.sin(axis), math.cos(axis)])
        spots = np.array([x, y]) + SQUARE_UP_OFFSETS[:, None] * side
        gap = self.ctx.stand_map(spots)
        k = int(np.argmax(gap))
        if not 0 < k < len(spots) - 1 or gap[k] >= SQUARE_UP_GAP:
            return False                    # open floor, or a single wall
        # The body's middle: where the most gait starts keep clear (a gait's arms swing
        # out further on one side), nearest the footprint's middle among those.
        room = self.gait_room(spots, axis, carrying)
        k = int(np.argmax(room * 1e3 - np.abs(np.arange(len(spots)) - k)))
        c, s = math.cos(yaw), math.sin(yaw)
        dxw, dyw = spots[k, 0] - x, spots[k, 1] - y
        if math.hypot(dxw, dyw) < ADJUST_STILL[0] and \
                abs(float(wrap_angle(axis - yaw))) < ADJUST_STILL[1]:
            return False                    # square already
        if not self.take_steps([((c * dxw + s * dyw, -s * dxw + c * dyw,
                                  float(wrap_angle(axis - yaw))),)]):
            return False
        self.state.gait_state = None
        return True

    def gait_room(self, spots: np.ndarray, yaw: float, carrying: bool) -> np.ndarray:
        """How many of the gait's starts from standing (walk or carry ones) keep the body
        clear (:meth:`body_clear`) from each of ``spots`` (N, 2) facing ``yaw``, (N,)."""
        index = self.ctx.index
        starts = index.starts[index.carry[index.starts] == carrying]
        if not starts.size or not index.body.size:
            return np.zeros(len(spots))
        c, s = math.cos(yaw), math.sin(yaw)
        body = index.body[starts] @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
        out = np.zeros(len(spots))
        for n, (x, y) in enumerate(spots):
            placed = body + np.array([x, y, 0.0])
            out[n] = np.count_nonzero(self.body_clear(placed, index.standing[starts]))
        return out

    def gap_axis(self, goal: Goal) -> float | None:
        """The heading (rad) along the floor around the worker: of the lines through its
        spot (``SQUARE_UP_AXES``, ``SQUARE_UP_REACH`` either way) the one keeping the most
        footprint clearance (a gap's axis), pointing the way ``goal`` is nearer; None
        where the goal's distance is infinite both ways."""
        x, y, _ = self.state.pose
        t = np.linspace(-SQUARE_UP_REACH, SQUARE_UP_REACH, 11)
        u = np.stack([np.cos(SQUARE_UP_AXES), np.sin(SQUARE_UP_AXES)], axis=-1)     # (A, 2)
        pts = np.array([x, y]) + t[None, :, None] * u[:, None, :]                 # (A, 11, 2)
        keep = self.ctx.stand_map(pts.reshape(-1, 2)).reshape(pts.shape[:2]).min(axis=1)
        a = int(np.argmax(keep))
        ends = np.array([x, y]) + SQUARE_UP_REACH * np.array([u[a], -u[a]])
        left = goal.distance(ends[:, 0], ends[:, 1])
        if not np.isfinite(left).any():
            return None
        return float(SQUARE_UP_AXES[a] + (0.0 if left[0] <= left[1] else np.pi))

    def walkable(self, x: float, y: float) -> bool:
        """Whether a walk may start at (x, y): ``STEP_OUT_MARGIN`` more floor clearance
        than ``options.body_radius``, and the navigation grid's cell there is free (the
        searches start from that cell)."""
        if float(self.ctx.clearance(np.array([[x, y]]))[0]) <= (self.ctx.options.body_radius
                                                               + STEP_OUT_MARGIN):
            return False
        grid = walk_grid(self.ctx)
        i = int(np.clip(np.rint((x - grid.lo[0]) / grid.res), 0, grid.shape[0] - 1))
        j = int(np.clip(np.rint((y - grid.lo[1]) / grid.res), 0, grid.shape[1] - 1))
        return bool(grid.free[i, j])

    def first_collision(self, primitives: list[int], poses: list[Pose]) -> int | None:
        """Index of the first gait primitive of a path that comes within the planner's
        margin of an obstacle on any frame (body or held parts), or None; what
        :meth:`placed_clear` checks on every frame, in one pass over the whole path."""
        from ltl_human_motion.scene.predicates import body_clearance, object_collides
        if not self.ctx.cell.obstacles or not primitives:
            return None
        worlds = [world_positions(self.ctx.index.primitives[p], *pose)
                  for p, pose in zip(primitives, poses)]
        ends = np.cumsum([len(w) for w in worlds])
        world = np.concatenate(worlds)
        bad = body_clearance(world, self.ctx.cell, stature=self.ctx.stature,
                             exact_below=EXACT_BELOW) <= PLACED_MARGIN
        for name, joint in self.state.held.items():
            centre = world[:, JOINT_INDEX[joint]] + self.state.held_offset(name)
            bad |= object_collides(self.ctx.cell, name, centre)
        if not bad.any():
            return None
        return int(np.searchsorted(ends, int(np.argmax(bad)), side="right"))

    def step_back(self, carrying: bool, label: int, then: MotionPrimitive) -> bool:
        """Step back from an obstacle in front so that ``then`` is clear afterwards: the
        gait index's 0.3 m step back, else a model-made step of ``STEP_OUT_DISTANCES``,
        else a step aside of ``SIDE_STEPS`` (a board at elbow height beside the worker,
        in an aisle), else both at once (an open machine door beside the worker at a
        chamber, reaching back further than a step). Returns False (nothing added) when
        no step and ``then`` are both clear."""
        from ltl_human_motion.planning.turns import make_step_primitive
        task = "carry" if carrying else "walk"
        lib = self.ctx.library

        def steps():
            yield from [mp for mp in self.ctx.index.primitives
                        if mp.task == task and mp.meta.get("step") == GAIT_STEP_BACK
                        and not mp.meta.get("turn")][:1]
            for dx, dy in STEP_MOVES:                  # made when tried
                yield make_step_primitive(self.ctx.stance(carrying), lib.standing_height, dx, dy,
                                          0.0, lib.skeleton, lib.fps, task)

        for mp in steps():
            pose = self.hand_over_pose(mp, self.state.pose)
            if self.placed_clear(mp, self.state.pose) and self.placed_clear(then, pose):
                self.add(mp, self.state.pose, label, self.ctx.overlap, pose)
                return True
        return False

    def walk(self, goal: Goal, task: str, label: int, carry: bool,
             budget: SearchBudget | None = None, square_up: bool = True) -> int:
        """A* from the current pose; appends the gait segments; returns their count.

        The search checks the body on sampled frames of a distance grid; every frame of
        the path it returns is then checked as the verifier does (exact capsules, held
        parts). A primitive that collides is forbidden from its pose and the search runs
        again (at most ``WALK_REPAIRS`` times). A squeeze search (on the footprint map)
        out of budget in a narrow gap squares up to it and searches again
        (:meth:`square_up`), unless not ``square_up``."""
        # A step of the same task (a grasp at a rack, then the step back its arms needed)
        # may have left the worker where no walk may start.
        if self.state.seat is None:
            self.step_out()
        forbidden: set[tuple[int, int, int, int]] = set()
        noise_state = self.ctx.rng.bit_generator.state
        budget = self.ctx.options.budget if budget is None \
            else budget.within(self.ctx.options.budget)
        if goal.clearance is self.ctx.stand_map:
            budget = replace(budget, idle_nodes=SQUEEZE_NODES)
        used, repairs, reroutes, stepped = 0, 0, 0, False
        start = (*map(float, self.state.pose), carry)
        while True:
            self.ctx.rng.bit_generator.state = noise_state      # the same costs every time
            stall = STALL_NODES if goal.reroute is not None and reroutes < MAX_REROUTES \
                else None
            res = astar(self.ctx.index, self.state.pose, goal,
                        start_primitive=self.state.gait_state,
                        clearance=goal.clearance or self.ctx.clearance,
                        options=self.search_options(), carry=carry,
                        budget=replace(budget, max_nodes=budget.max_nodes - used),
                        rng=self.ctx.rng, body_clear=self.body_clear,
                        forbidden=frozenset(forbidden), stall_nodes=stall)
            self.state.expanded += res.expanded
            used += res.expanded
            if isinstance(res, SearchFailure) and res.reason == "stalled":
                # Walk around the spot the search could not get past, or search on.
                reroutes += 1
                goal = goal.reroute(res.closest_at) or replace(goal, reroute=None)
                continue
            if isinstance(res, SearchFailure):
                if not stepped and used < budget.max_nodes and self._got_nowhere(res, start) \
                        and self.step_away(goal.clearance or self.ctx.clearance):
                    # No way on from where it stands (facing a rack in an aisle with a
                    # part in hand, too close to turn): step away first.
                    stepped, forbidden = True, set()
                    continue
                if stepped:
                    self._stuck.add(start)
                break
            bad = self.first_collision(res.primitives, res.poses)
            if bad is None:
                break
            if bad == 0 and not stepped and self.ctx.index.standing[res.primitives[0]] \
                    and self.step_away(goal.clearance or self.ctx.clearance):
                # Too tight a place to turn (a thigh into a conveyor): step away first.
                stepped, forbidden = True, set()
                continue
            forbidden |= self.forbid(res.primitives, res.poses, bad)
            repairs += 1
            if repairs > WALK_REPAIRS:
                raise PlanningError(f"task {task}: {goal.description}: every path found "
                                    f"({WALK_REPAIRS + 1}) collides on a frame the search "
                                    "did not sample", task=task, reason="blocked")
        if isinstance(res, SearchFailure) and res.reason == "budget" and square_up and \
                goal.clearance is self.ctx.stand_map and self.square_up(goal, carry):
            return self.walk(goal, task, label, carry, budget)    # square to the gap
        if isinstance(res, SearchFailure):
            raise _search_refusal(task, goal, res, used)
        for prim_id, pose, end in zip(res.primitives, res.poses, [*res.poses[1:], res.end_pose]):
            self.add(self.ctx.index.primitives[prim_id], pose, label, self.ctx.overlap, end)
        if res.primitives:
            self.state.gait_state = None  # every walk ends with a stop primitive
        return len(res.primitives)

    def _got_nowhere(self, res: SearchFailure, start: tuple) -> bool:
        """Whether failed search ``res`` from ``start`` (floor pose and carry) came no
        further than ``STUCK_RADIUS`` from it, and stepping away from there has not been
        tried in vain in this plan."""
        return res.reason in ("budget", "blocked") and res.closest_at is not None \
            and math.dist(res.closest_at, start[:2]) < STUCK_RADIUS \
            and start not in self._stuck

    def forbid(self, primitives: list[int], poses: list[Pose], bad: int
               ) -> set[tuple[int, int, int, int]]:
        """What a search must not take again after primitive ``bad`` of its path collided:
        that primitive from its pose; where it is a turn on the spot, every such turn
        from there; and where it is a stop (the arms swing forward as the worker stops
        at furniture) that ends a walk, every gait stop from there and from the
        neighbouring closed-set cells: the stops from one spot sweep nearly the same
        space, and forbidding them one at a time, one cell at a time, used up the
        ``WALK_REPAIRS`` (so did the turns of a worker facing a conveyor, his thigh
        swinging into it, each turn tried in turn)."""
        i, j, k = placement_key(*poses[bad])
        prim = primitives[bad]
        index = self.ctx.index
        if index.standing[prim] and index.primitives[prim].meta.get("turn"):
            # A turn on the spot (the first move from a tight place): every turn from
            # there sweeps the legs through nearly the same space.
            turns = [p for p in np.flatnonzero(index.standing).tolist()
                     if index.primitives[p].meta.get("turn")]
            return {(int(p), i, j, k) for p in turns}
        if bad == 0 or not index.stops[prim] or index.standing[prim]:
            return {(prim, i, j, k)}               # the first move, a step on the spot
        stops = np.flatnonzero(self.ctx.index.stops & ~self.ctx.index.standing).tolist()
        return {(int(p), i + di, j + dj, k) for p in stops
                for di in (-1, 0, 1) for dj in (-1, 0, 1)}

    def step_towards(self, target: np.ndarray, placement: tuple[float, float],
                     back_limit: float, stand_yaw: float | None = None,
                     goal: Goal | None = None) -> bool:
        """Where the ideal placement for ``target`` (:func:`.standing.ideal_placement`) is
        further than ``options.adjust_radius`` but within ``STEP_TOWARDS_REACH`` of it, a
        model-made step of ``adjust_radius`` straight towards it (no turn), if clear: the
        gait's shortest start and stop overshoot a spot this near (a 1.95 m worker's
        stop strides 0.5 m). Where that spot is blocked or the step is not clear, the
        steps into ``goal`` (if given, :meth:`step_into`). Returns whether it stepped."""
        if self._step_towards(target, placement, back_limit, stand_yaw):
            return True
        return goal is not None and self.step_into(goal, turn=True)

    def step_into(self, goal: Goal, turn: bool = False) -> bool:
        """Up to ``STEP_TOWARDS_REACH`` model-made steps of at most
        ``options.adjust_radius`` each, without turning, to the nearest spot within their
        reach where ``goal.reached`` holds, if the worker is not there yet and every step
        is clear (the nearest ``STEP_INTO_TRIES`` spots tried). A walk's goal next to
        furniture may be smaller than the gait's shortest start and stop: a search from
        close by floods the floor around it. With ``turn``, where no such steps are clear,
        the worker turns on the spot to the goal's heading (``goal.heading``) and then
        steps (where the goal needs the worker facing its target, e.g. in an aisle too
        narrow to turn in at the spot, the gait's turns take a search of thousands of
        nodes). Returns whether it stepped."""
        x, y, yaw = self.state.pose
        if bool(goal.reached(np.array([x]), np.array([y]), np.array([yaw]))[0]):
            return False
        reach = self.ctx.options.adjust_radius
        most = STEP_TOWARDS_REACH * reach
        left = float(goal.distance(np.array([x]), np.array([y]))[0])
        if np.isfinite(left) and left > most + reach + 2.0 * self.ctx.options.grid_resolution:
            # The spots the goal accepts stand within ``reach`` of its floor cells (the
            # ideal placements): none within the steps' reach (the walk's own field,
            # path lengths at least the straight distance, a cell off).
            return False
        g = np.arange(-most, most + 1e-9, STEP_INTO_GRID)
        dx, dy = (v.ravel() for v in np.meshgrid(g, g))
        far = np.hypot(dx, dy)
        c, s = math.cos(yaw), math.sin(yaw)
        wx, wy = x + c * dx - s * dy, y + s * dx + c * dy
        near = far <= most
        plain = near & (far > 0.0)
        plain[plain] = goal.reached(wx[plain], wy[plain], np.full(int(plain.sum()), yaw))
        if self._steps_into(plain, dx, dy, far, None):
            return True
        if not turn or goal.heading is None:
            return False
        heading = np.full(len(far), yaw)
        heading[near] = goal.heading(wx[near], wy[near])
        turns = wrap_angle(heading - yaw)
        turned = near & (np.abs(turns) > self.ctx.options.heading_tolerance)
        turned[turned] = goal.reached(wx[turned], wy[turned], heading[turned])
        return self._steps_into(turned, dx, dy, far, turns)

    def _steps_into(self, spots: np.ndarray, dx: np.ndarray, dy: np.ndarray,
                    far: np.ndarray, turns: np.ndarray | None) -> bool:
        """:meth:`step_into`'s steps to the nearest of ``spots`` (bool (G,) over the grid
        offsets ``dx``, ``dy`` (G,) in the worker's frame, ``far`` (G,) their lengths),
        after a turn on the spot by ``turns`` (G,) radians if given, the first
        ``STEP_INTO_TRIES`` tried; the first whose moves are all clear is taken."""
        from ltl_human_motion.planning.turns import make_step_primitive
        lib = self.ctx.library
        stance = self.ctx.stance(self.state.carrying)
        task = "carry" if self.state.carrying else "walk"
        reach = self.ctx.options.adjust_radius

        def step(ddx: float, ddy: float, dyaw: float) -> MotionPrimitive:
            return make_step_primitive(stance, lib.standing_height, ddx, ddy, dyaw,
                                       lib.skeleton, lib.fps, task)

        for k in np.flatnonzero(spots)[np.argsort(far[spots], kind="stable")][:STEP_INTO_TRIES]:
            moves: list[MotionPrimitive] = []
            ddx, ddy = float(dx[k]), float(dy[k])
            if turns is not None:
                dyaw = float(turns[k])
                moves.append(step(0.0, 0.0, dyaw))
                cy, sy = math.cos(dyaw), math.sin(dyaw)
                ddx, ddy = cy * ddx + sy * ddy, -sy * ddx + cy * ddy
            n = math.ceil(far[k] / reach - 1e-9)
            if n:                                    # (none for a turn where it stands)
                moves += [step(ddx / n, ddy / n, 0.0)] * n
            poses = [self.state.pose]
            for mp in moves[:-1]:
                poses.append(self.hand_over_pose(mp, poses[-1]))
            if all(self.placed_clear(mp, pose) for mp, pose in zip(moves, poses)):
                for mp in moves:
                    self.advance(mp)
                return True
        return False

    def _step_towards(self, target: np.ndarray, placement: tuple[float, float],
                      back_limit: float, stand_yaw: float | None) -> bool:
        """:meth:`step_towards`'s step towards the ideal placement."""
        from ltl_human_motion.planning.turns import make_step_primitive
        x, y, yaw = self.state.pose
        px, py, _, free = (float(v[0]) for v in ideal_placement(
            self.ctx, target, placement, np.array([x]), np.array([y]), back_limit,
            stand_yaw=stand_yaw))
        reach = self.ctx.options.adjust_radius
        far = math.hypot(px - x, py - y)
        if not free or not reach < far <= STEP_TOWARDS_REACH * reach:
            return False
        c, s = math.cos(yaw), math.sin(yaw)
        k = reach / far
        dx, dy = k * (c * (px - x) + s * (py - y)), k * (-s * (px - x) + c * (py - y))
        lib = self.ctx.library
        mp = make_step_primitive(self.ctx.stance(self.state.carrying), lib.standing_height,
                                 dx, dy, 0.0, lib.skeleton, lib.fps,
                                 "carry" if self.state.carrying else "walk")
        if not self.placed_clear(mp, self.state.pose):
            return False
        self.advance(mp)
        return True

    def adjust_to(self, target: np.ndarray, placement: tuple[float, float], task: str,
                  back_limit: float, stand_yaw: float | None = None) -> bool:
        """Step and turn on the spot to the ideal placement for ``target`` (if needed;
        :func:`.standing.ideal_placement`, facing ``stand_yaw`` if given).

        If that step would touch an obstacle, stand a little further back (up to 15 cm).
        Returns False if no adjustment is clear (the worker stays where the walk ended).
        """
        x, y, yaw = self.state.pose
        px, py, pyaw, _ = (float(v[0]) for v in ideal_placement(
            self.ctx, target, placement, np.array([x]), np.array([y]), back_limit,
            stand_yaw=stand_yaw))
        back_dir = np.array([math.cos(pyaw), math.sin(pyaw)])
        c, s = math.cos(yaw), math.sin(yaw)
        for back in ADJUST_BACKS:
            qx, qy = px - back * back_dir[0], py - back * back_dir[1]
            dx, dy = c * (qx - x) + s * (qy - y), -s * (qx - x) + c * (qy - y)
            dyaw = float(wrap_angle(pyaw - yaw))
            if math.hypot(dx, dy) < ADJUST_STILL[0] and abs(dyaw) < ADJUST_STILL[1]:
                return True
            # Step and turn at once; or turn where the walk ended, then step in.
            cp, sp = math.cos(dyaw), math.sin(dyaw)
            if self.take_steps([((dx, dy, dyaw),),
                                ((0.0, 0.0, dyaw), (cp * dx + sp * dy, -sp * dx + cp * dy,
                                                    0.0))]):
                return True
        return False

    def take_steps(self, plans: list[tuple[tuple[float, float, float], ...]]) -> bool:
        """Add the first of ``plans`` whose standing steps all keep the body and the
        parts in hand clear on every frame (:meth:`placed_clear`); each plan is a
        sequence of moves (dx, dy, dyaw) (m, m, rad) in the frame of the pose the move
        starts from (:func:`.turns.make_step_primitive`). The primitives are made when
        tried (the first plan is usually clear). Returns whether a plan was added."""
        from ltl_human_motion.planning.turns import make_step_primitive
        lib = self.ctx.library
        carrying = self.state.carrying
        stance = self.ctx.stance(carrying)
        for moves in plans:
            pose = self.state.pose
            plan = []
            for dx, dy, dyaw in moves:
                mp = make_step_primitive(stance, lib.standing_height, dx, dy, dyaw,
                                         lib.skeleton, lib.fps, "carry" if carrying else "walk")
                if not self.placed_clear(mp, pose):
                    break
                plan.append(mp)
                pose = self.hand_over_pose(mp, pose)
            if len(plan) == len(moves):
                for mp in plan:
                    self.advance(mp)
                return True
        return False


def _approach(closest: float) -> str:
    """How near a failed walk came to its goal, in words (``closest``: the search's
    field distance to the goal's floor cells, m; 0 once it stood on them)."""
    if closest <= 0.005:
        return ("it reached the goal's floor area but found no place there to stop at "
                "that the goal test and the body's clearance accept")
    return f"it came no nearer than {closest:.2f} m to the goal's floor area"


def _search_refusal(task: str, goal: Goal, res: SearchFailure, used: int) -> PlanningError:
    """The error of a walk for ``task`` whose search for ``goal`` failed with ``res`` after
    ``used`` nodes in all: out of budget, no stop at the goal (a blocked goal: the caller
    may try other placements) or no way at all."""
    if res.reason == "budget":
        why = f"the search budget ran out ({used} nodes; {_approach(res.closest)})"
    elif res.reason == "no_stop":
        why = (f"the search reached the goal's neighbourhood but no place to stop "
               f"there keeps the body clear and passes the goal test ({used} nodes)")
    else:
        why = (f"obstacles block every way to the target (searched {res.expanded} "
               f"placements; {_approach(res.closest)})")
    return PlanningError(f"task {task}: {goal.description}: {why}", task=task,
                         reason="blocked" if res.reason == "no_stop" else res.reason,
                         search=res.reason)
