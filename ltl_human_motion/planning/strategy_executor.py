"""Live execution of a reactive worker's strategy (docs/reactive.md, "Live in ROS").

Plain Python (no rclpy): times are seconds on the caller's clock. A
:class:`StrategyExecutor` plays the clips of a
:class:`~ltl_human_motion.planning.strategy_motion.StrategyProgram` one move after the
other. At the end of each move it hands the strategy the inputs as they are then (the
Moore reading of docs/reactive.md) and starts the clip of the move the strategy picks. A
waiting worker is interruptible: when an input changes during a ``wait`` step, the wait
ends at once and the next move starts at the time of the change. Tasks under way finish.

Consecutive clips were planned from the same worker state but through different
histories, so a clip's first pose differs from the pose the worker is in (its heading by
up to 2 rad where the worker reached a part from the other side); the difference is
blended out over the clip's first :func:`blend_seconds`: its rigid part (a turn about the
vertical through the clip's first pelvis, and a shift) as a turn and a shift, what is left
of the posture as an offset (offset blending, as at the junctions of the pipeline).
The executor is duck-compatible with :class:`~ltl_human_motion.planning.playback.Playback`
where an occupancy stream reads it
(``state``, ``stature``, ``motion_id``, ``positions_ahead``, ``sample_ahead``).
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from ltl_human_motion.errors import SpecError
from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion.biomechanics import SPEED_WINDOW, check_biomechanics
from ltl_human_motion.motion.quality import QualityThresholds
from ltl_human_motion.motion.retarget import enforce_bone_lengths
from ltl_human_motion.motion.skeleton import JOINT_INDEX, PARENTS, Skeleton
from ltl_human_motion.planning.strategy_motion import START, StepClip, StrategyProgram
from ltl_human_motion.planning.verify import FOOT_JOINTS, VerificationOptions

__all__ = ["BLEND_MAX", "BLEND_MIN", "BLEND_SPEED", "JUNCTION_BIOMECHANICS",
           "JUNCTION_STRETCHES", "JunctionCheck",
           "LiveFrame", "StrategyExecutor", "StrategyStatus", "blend_seconds",
           "check_junction"]

#: Shortest and longest blend of a junction, s.
BLEND_MIN = 0.3
BLEND_MAX = 1.0
#: Speed (m/s) at which a joint's junction offset is blended out.
BLEND_SPEED = 1.5

#: Factors on a junction's blend tried in turn until its frames pass the checks.
JUNCTION_STRETCHES = (1.0, 2.0, 4.0)
#: The biomechanical checks of the verifier run on a junction's frames (balance and foot
#: skate are not: docs/reactive.md).
JUNCTION_BIOMECHANICS = ("joint_speed", "range_of_motion", "self_penetration")
#: Junctions whose check is remembered (the same pose into the same move is checked once).
JUNCTION_CACHE_SIZE = 256

PELVIS = JOINT_INDEX["pelvis"]
_BONES = np.array([(j, q) for j, q in enumerate(PARENTS) if q >= 0])
_FEET = [JOINT_INDEX[j] for j in FOOT_JOINTS]
PLAYING = "playing"
STOPPED = "stopped"


def blend_seconds(offset: float) -> float:
    """Blend of a junction whose largest joint offset is ``offset`` m."""
    return float(np.clip(offset / BLEND_SPEED, BLEND_MIN, BLEND_MAX))


@dataclass(frozen=True)
class JunctionCheck:
    """What the checks said of one junction's frames.

    Attributes
    ----------
    step : int
        Index of the move the junction leads into.
    task : str
        Its task key.
    blend : float
        Seconds of the blend played.
    passed : bool
    failed : tuple of str
        The checks that failed (of the blend played).
    detail : str
    frames : int
        Frames checked.
    tried : tuple of (float, tuple of str)
        Each blend tried (s) and the checks it failed, in order.
    """

    step: int
    task: str
    blend: float
    passed: bool
    failed: tuple[str, ...]
    detail: str
    frames: int
    tried: tuple[tuple[float, tuple[str, ...]], ...] = ()


def check_junction(positions: np.ndarray, fps: float, labels: list[str], cell,
                   skeleton: Skeleton, options: VerificationOptions | None = None
                   ) -> tuple[tuple[str, ...], str]:
    """The verifier's checks on a junction's frames: :data:`JUNCTION_BIOMECHANICS` (joint
    speeds by each frame's activity in ``labels``, range of motion, no body part through
    another), ``smoothness`` (no jump between frames), bone lengths (within
    :class:`~ltl_human_motion.motion.quality.QualityThresholds`' ``bone_length`` of
    ``skeleton``'s), collisions of the body with ``cell``'s obstacles, and the feet (none
    below the floor by more than ``options.floor_tolerance``, no flight longer than
    ``options.max_flight``). Balance and foot skate are not checked (docs/reactive.md).

    Parameters
    ----------
    positions : ndarray, shape (T, J, 3)
        Frames at ``fps``, world frame, m.
    fps : float
    labels : list of str
        Activity (task key) of each frame.
    cell : Cell
    skeleton : Skeleton
    options : VerificationOptions, optional
        The verifier's limits (default ones).

    Returns
    -------
    failed : tuple of str
        Names of the failed checks (empty: all passed).
    detail : str
    """
    from ltl_human_motion.scene.predicates import collision

    options = options or VerificationOptions()
    pos = np.asarray(positions, dtype=np.float64)
    failed: list[str] = []
    notes: list[str] = []
    body = check_biomechanics(pos, fps, stature=skeleton.stature, labels=labels,
                              floor_z=cell.floor_z, limits=options.limits)
    for name in JUNCTION_BIOMECHANICS:
        if not body[name]["passed"]:
            failed.append(name)
            notes.append(f"{name}: {body[name]['detail']}")
    step = np.linalg.norm(np.diff(pos, axis=0), axis=-1) * fps
    if step.size and float(step.max()) > options.max_joint_speed:
        failed.append("smoothness")
        notes.append(f"smoothness: a joint at {float(step.max()):.2f} m/s between frames")
    lengths = np.linalg.norm(pos[:, _BONES[:, 0]] - pos[:, _BONES[:, 1]], axis=-1)
    stretch = float(np.max(np.abs(lengths - skeleton.bone_lengths()[_BONES[:, 0]])))
    if stretch > QualityThresholds().bone_length:
        failed.append("bone_length")
        notes.append(f"bone_length: a bone {1e3 * stretch:.1f} mm off its length")
    hits = collision(pos, cell, stature=skeleton.stature) if cell.obstacles \
        else np.zeros(len(pos), bool)
    if hits.any():
        failed.append("collision")
        notes.append(f"collision: {int(hits.sum())} frames collide, first "
                     f"{int(np.argmax(hits))}")
    feet = pos[:, _FEET, 2] - cell.floor_z
    flying = np.concatenate([[0], (feet.min(axis=1) > options.flight_height).astype(np.int8),
                             [0]])
    edges = np.flatnonzero(np.diff(flying))
    flight = int(np.max(edges[1::2] - edges[::2])) / fps if edges.size else 0.0
    if float(feet.min()) < -options.floor_tolerance or flight > options.max_flight:
        failed.append("feet")
        notes.append(f"feet: lowest foot joint {float(feet.min()):+.3f} m, flight "
                     f"{flight:.2f} s")
    return tuple(failed), "; ".join(notes)


@dataclass(frozen=True)
class StrategyStatus:
    """What the strategy does now.

    Attributes
    ----------
    strategy_id : str
    step : int
        Index of the move under way (0 first).
    task : str
        Its task key.
    worker_state : int
        Worker model state the move started from (-1: the start).
    goal : int
        Index of the goal (``G F``) the strategy pursues.
    goals : int
        Number of goals.
    inputs : dict of str to bool
        The inputs as read last.
    inputs_stamp : float
        Stamp (s) of the newest input message among them (0: none yet).
    step_start : float
        Clock time (s) the move started.
    reacted_at : float or None
        Clock time (s) of the latest wait ended by an input change.
    """

    strategy_id: str
    step: int
    task: str
    worker_state: int
    goal: int
    goals: int
    inputs: dict[str, bool]
    inputs_stamp: float
    step_start: float
    reacted_at: float | None

    def state_text(self) -> str:
        """The strategy's state in words, e.g. ``"worker state 3, goal 1 of 2"``."""
        where = "start" if self.worker_state == START else f"worker state {self.worker_state}"
        return f"{where}, goal {self.goal + 1} of {self.goals}"


@dataclass(frozen=True)
class LiveFrame:
    """The worker's pose at one instant.

    Attributes
    ----------
    positions : ndarray, shape (J, 3)
        Joint positions, world frame, m.
    yaw : float
        Body heading about +z, rad.
    objects : dict of str to ndarray, shape (3,)
    step_time : float
        Seconds of motion into the current move.
    step_duration : float
        Seconds of the current move's motion.
    status : StrategyStatus
    """

    positions: np.ndarray
    yaw: float
    objects: dict[str, np.ndarray]
    step_time: float
    step_duration: float
    status: StrategyStatus


class StrategyExecutor:
    """Thread-safe live run of a strategy.

    Parameters
    ----------
    program : StrategyProgram
    start : float
        Clock time (s) of the first move's first frame.
    inputs : mapping of str to bool, optional
        Input values before any message (missing ones are false).
    on_step : callable, optional
        Called with each new :class:`StrategyStatus` (under the executor's lock).
    rate : float
        Playback rate (1.0 is real time; 2.0 plays each move in half its time).
    cell : Cell, optional
        The resolved cell the junctions are checked in (default: resolve ``program.cell``).
    options : VerificationOptions, optional
        Limits of the junction checks (default: the verifier's).
    """

    def __init__(self, program: StrategyProgram, start: float,
                 inputs: Mapping[str, bool] | None = None,
                 on_step: Callable[[StrategyStatus], None] | None = None,
                 rate: float = 1.0, cell=None,
                 options: VerificationOptions | None = None) -> None:
        if not (np.isfinite(rate) and rate > 0):
            raise ValueError(f"playback rate must be a positive number, got {rate!r}")
        if cell is None:
            from ltl_human_motion.scene.cell_yaml import resolve_cell
            cell = resolve_cell(program.cell)
        self.program = program
        self.rate = float(rate)
        self.cell = cell
        self.options = options or VerificationOptions()
        self.skeleton = Skeleton(program.stature)
        self._checked: BoundedCache[tuple] = BoundedCache(JUNCTION_CACHE_SIZE)
        #: The check of each junction played (at most 1000), and how many failed.
        self.junctions: deque[JunctionCheck] = deque(maxlen=1000)
        self.junctions_failed = 0
        first = next(iter(program.clips.values()))
        # The collision test compiles on its first call: here, not in a reaction.
        check_junction(first.positions[:2], first.fps, [first.task] * 2, cell, self.skeleton,
                       self.options)
        self._lock = threading.RLock()
        self._inputs = {k: bool((inputs or {}).get(k, False)) for k in program.inputs}
        self._inputs_stamp = 0.0
        self._on_step = on_step
        self._strategy = program.worker.strategy
        self._strategy.reset()
        self._wait = next((i for i, t in enumerate(program.worker.tasks) if t.name == "wait"),
                          -1)
        self._step = -1
        self._source = START
        self._clip: StepClip | None = None
        self._start = float(start)
        self._residual = np.zeros((0, 3))
        self._pivot = np.zeros(3)
        self._shift = np.zeros(3)
        self._yaw_offset = 0.0
        self._blend = BLEND_MIN
        self._reacted_at: float | None = None
        self._stopped = False
        #: Why the run stopped by itself (the inputs broke an assumption), else None.
        self.error: str | None = None
        #: Tasks of the latest moves started (at most 1000).
        self.steps_done: deque[str] = deque(maxlen=1000)
        self._begin(float(start), None, 0.0)

    # -- inputs ----------------------------------------------------------------------
    @property
    def motion_id(self) -> str:
        return self.program.strategy_id

    @property
    def stature(self) -> float:
        return self.program.stature

    def set_inputs(self, values: Mapping[str, bool], stamp: float, now: float) -> bool:
        """Take input values (keys of the specification's inputs; others are ignored)
        from a message stamped ``stamp`` received at clock time ``now``.

        Returns True when this ended a wait: the next move starts at ``now``.
        """
        with self._lock:
            self._advance(now)
            changed = False
            for key, value in values.items():
                if key in self._inputs and self._inputs[key] != bool(value):
                    self._inputs[key] = bool(value)
                    changed = True
            if any(k in self._inputs for k in values):
                self._inputs_stamp = max(self._inputs_stamp, float(stamp))
            if changed and not self._stopped and self._clip is not None \
                    and self._clip.move.task == self._wait and now >= self._start:
                self._reacted_at = float(now)
                self._next(float(now))
                return True
            return False

    def stop(self) -> None:
        """Stop: no frames any more."""
        with self._lock:
            self._stopped = True

    # -- queries ---------------------------------------------------------------------
    def state(self, now: float) -> str:
        """``"playing"``, or ``"stopped"`` after :meth:`stop` or when the inputs broke an
        assumption (:attr:`error` says how)."""
        return STOPPED if self._stopped else PLAYING

    def status(self, now: float) -> StrategyStatus:
        """The strategy's status at clock time ``now``."""
        with self._lock:
            self._advance(now)
            return self._status()

    def frame_at(self, now: float) -> LiveFrame | None:
        """The pose at clock time ``now`` (None when stopped)."""
        with self._lock:
            if self._stopped:
                return None
            self._advance(now)
            t = max(float(now) - self._start, 0.0) * self.rate
            positions, yaw = self._pose(np.array([t]))
            clip = self._clip
            f = min(t * clip.fps, len(clip.positions) - 1)
            i0 = int(np.floor(f))
            i1 = min(i0 + 1, len(clip.positions) - 1)
            w = f - i0
            objects = {k: v[i0] * (1 - w) + v[i1] * w for k, v in clip.objects.items()}
            return LiveFrame(positions[0], float(yaw[0]), objects, t, clip.duration,
                             self._status())

    def positions_ahead(self, now: float, offsets: np.ndarray) -> np.ndarray | None:
        """Joint positions (N, J, 3) ``offsets`` (N,) s after ``now`` if the current move
        runs on (it holds its last pose after its end); None when stopped."""
        with self._lock:
            if self._stopped:
                return None
            self._advance(now)
            t = (max(float(now) - self._start, 0.0)
                 + np.asarray(offsets, dtype=np.float64)) * self.rate
            return self._pose(t)[0]

    def sample_ahead(self, now: float, offsets: np.ndarray, key: str,
                     per_frame: Callable[[np.ndarray], np.ndarray]) -> np.ndarray | None:
        """``per_frame`` (T, J, 3) -> (T, ...) of :meth:`positions_ahead` (``key`` is
        accepted for compatibility with Playback; nothing is cached)."""
        positions = self.positions_ahead(now, offsets)
        return None if positions is None else per_frame(positions)

    # -- internals -------------------------------------------------------------------
    def _status(self) -> StrategyStatus:
        state = self._strategy._chosen or self._strategy.state
        goals = len(self._strategy.game.aut.win["[]<>"])
        return StrategyStatus(self.program.strategy_id, self._step,
                              self._clip.task if self._clip is not None else "",
                              self._source, int(state.get("_goal", 0)), goals,
                              dict(self._inputs), self._inputs_stamp, self._start,
                              self._reacted_at)

    def _pose(self, t: np.ndarray, blend: float | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
        """Positions (N, J, 3) and yaw (N,) of the current clip at step times ``t`` (N,),
        the junction offset blended out over ``blend`` s (default: the junction's)."""
        clip = self._clip
        n = len(clip.positions)
        f = np.clip(t * clip.fps, 0.0, n - 1)
        i0 = np.floor(f).astype(np.int64)
        i1 = np.minimum(i0 + 1, n - 1)
        w = f - i0
        pos = clip.positions[i0] * (1 - w)[:, None, None] + clip.positions[i1] * w[:, None, None]
        yaw = clip.yaw[i0] * (1 - w) + clip.yaw[i1] * w
        u = np.clip(t / (self._blend if blend is None else blend), 0.0, 1.0)
        fade = 1.0 - u * u * (3.0 - 2.0 * u)                          # smoothstep down
        if self._residual.shape == pos.shape[1:]:
            # The junction's rigid part (a turn about z through the clip's first pelvis and
            # a shift), then what is left of the posture, both faded out.
            a = fade * self._yaw_offset
            c, sn = np.cos(a)[:, None], np.sin(a)[:, None]
            rel = pos - self._pivot
            pos = np.stack([c * rel[..., 0] - sn * rel[..., 1],
                            sn * rel[..., 0] + c * rel[..., 1], rel[..., 2]], axis=-1)
            pos = pos + self._pivot + fade[:, None, None] * (self._shift + self._residual)
            blended = fade > 0.0
            if blended.any():
                pos[blended] = enforce_bone_lengths(pos[blended], self.skeleton,
                                                    rigid_hips=False)
        return pos, yaw + fade * self._yaw_offset

    def _advance(self, now: float) -> None:
        """Finish every move that ended by ``now`` (each at its own end time)."""
        while not self._stopped and self._clip is not None \
                and float(now) >= self._start + self._length():
            self._next(self._start + self._length())

    def _length(self) -> float:
        """Clock seconds of the current move."""
        return max(self._clip.duration, 1.0 / self._clip.fps) / self.rate

    def _next(self, at: float) -> None:
        """End the current move at clock time ``at``: observe the inputs, start the next."""
        t = (at - self._start) * self.rate
        fps = self._clip.fps
        w = max(1, round(SPEED_WINDOW * fps))
        # The pose at ``at`` and the frames played before it that the speed window reaches.
        positions, yaw = self._pose(np.concatenate([t - np.arange(w, 0, -1) / fps, [t]]))
        self._strategy.observe(self._inputs)
        previous = self._clip.task
        self._source = self._clip.move.target
        try:
            self._begin(at, positions[-1], float(yaw[-1]), positions[:-1], previous)
        except SpecError as exc:
            self._stopped = True
            self.error = (f"step {self._step + 1}: {exc} (inputs "
                          + ", ".join(f"{k}={v}" for k, v in self._inputs.items()) + ")")

    def _begin(self, at: float, pose: np.ndarray | None, yaw: float,
               before: np.ndarray | None = None, previous: str = "") -> None:
        task = self._strategy.choose()
        clip = self.program.clips.get((self._source, task))
        if clip is None:
            raise KeyError(f"the strategy's move {self.program.worker.tasks[task].key} from "
                           f"worker state {self._source} has no motion in the program")
        self._clip, self._start, self._step = clip, float(at), self._step + 1
        if pose is None:
            self._residual, self._yaw_offset, self._blend = np.zeros((0, 3)), 0.0, BLEND_MIN
        else:
            first = clip.positions[0]
            self._yaw_offset = float(np.angle(np.exp(1j * (yaw - clip.yaw[0]))))
            self._pivot = np.array([*first[PELVIS, :2], 0.0])
            self._shift = pose[PELVIS] - first[PELVIS]
            c, sn = np.cos(self._yaw_offset), np.sin(self._yaw_offset)
            rel = first - self._pivot
            turned = np.stack([c * rel[:, 0] - sn * rel[:, 1], sn * rel[:, 0] + c * rel[:, 1],
                               rel[:, 2]], axis=-1) + self._pivot + self._shift
            self._residual = pose - turned
            # The farthest a joint travels in the blend: the turn, the shift, the posture.
            travel = np.linalg.norm(pose - first, axis=1)
            self._verify_junction(blend_seconds(float(np.max(travel))), pose, yaw,
                                  np.zeros((0, *pose.shape)) if before is None else before,
                                  previous)
        self.steps_done.append(clip.task)
        if self._on_step is not None:
            self._on_step(self._status())

    def junction_frames(self, blend: float) -> np.ndarray:
        """The current move's first frames (n, J, 3) as played with its junction blended
        out over ``blend`` s: through the blend and the speed window after it (at most
        the clip), at the clip's frame rate."""
        with self._lock:
            clip = self._clip
            w = max(1, round(SPEED_WINDOW * clip.fps))
            n = min(int(np.ceil(blend * clip.fps)) + w, len(clip.positions) - 1)
            return self._pose(np.arange(n + 1) / clip.fps, float(blend))[0]

    def _verify_junction(self, blend: float, pose: np.ndarray, yaw: float,
                         before: np.ndarray, previous: str) -> None:
        """Set the blend of the junction just begun to the first of ``blend`` times
        :data:`JUNCTION_STRETCHES` whose frames pass :func:`check_junction` (else the
        longest), and record the check. ``before`` (w, J, 3): the frames played before
        the junction's pose ``pose`` (J, 3); ``previous``: their move's task."""
        clip = self._clip
        key = (clip.move.source, clip.move.task, pose.tobytes(), float(yaw), before.tobytes())
        hit = self._checked.get(key)
        if hit is None:
            tried = []
            for factor in JUNCTION_STRETCHES:
                ahead = self.junction_frames(blend * factor)
                frames = np.concatenate([before, ahead])
                labels = [previous] * len(before) + [clip.task] * len(ahead)
                failed, detail = check_junction(frames, clip.fps, labels, self.cell,
                                                self.skeleton, self.options)
                tried.append((blend * factor, failed))
                if not failed:
                    break
            hit = self._checked.put(key, (blend * factor, failed, detail, len(frames),
                                          tuple(tried)))
        self._blend, failed, detail, n_frames, tried = hit
        self.junctions.append(JunctionCheck(self._step, clip.task, self._blend, not failed,
                                            failed, detail, n_frames, tried))
        self.junctions_failed += bool(failed)
