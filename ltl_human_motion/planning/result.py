"""The result of motion synthesis: a verified full-body motion and its task timeline.

Frame conventions: ``task_index[t] = i >= 0`` means frame ``t`` executes task step
``sequence[i]`` (described by ``timeline[i]``); ``-1`` marks the approach gait between
tasks. ``TaskSegment.end_frame`` is exclusive (``positions[start_frame:end_frame]``).
Exports live in :mod:`ltl_human_motion.planning.exports`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from ltl_human_motion.motion.types import Motion

__all__ = ["SynthesisStats", "SynthesizedMotion", "TaskSegment"]


@dataclass(frozen=True, eq=False)
class TaskSegment:
    """One task step of a synthesized motion.

    Attributes
    ----------
    task : str
        The task as written in the sequence, e.g. ``"grasp(O1)"``.
    start_frame, end_frame : int
        Frame range ``[start_frame, end_frame)``.
    primitive : str
        Name of the goal (or gait) primitive that realised the task.
    target : ndarray, shape (3,) or None
        Goal point of the task (region centre, grasp point), world frame.
    """

    task: str
    start_frame: int
    end_frame: int
    primitive: str = ""
    target: np.ndarray | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.task, str) or not self.task:
            raise ValueError(f"task must be a non-empty string, got {self.task!r}")
        start, end = int(self.start_frame), int(self.end_frame)
        if start < 0 or end < start:
            raise ValueError(f"need 0 <= start_frame <= end_frame, got {start}, {end}")
        object.__setattr__(self, "start_frame", start)
        object.__setattr__(self, "end_frame", end)
        if self.target is not None:
            target = np.asarray(self.target, dtype=np.float64)
            if target.shape != (3,):
                raise ValueError(f"target must have shape (3,), got {target.shape}")
            object.__setattr__(self, "target", target)

    @property
    def n_frames(self) -> int:
        return self.end_frame - self.start_frame

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python form (for JSON)."""
        return {"task": self.task, "start_frame": self.start_frame,
                "end_frame": self.end_frame, "primitive": self.primitive,
                "target": None if self.target is None else [float(v) for v in self.target]}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TaskSegment:
        """Inverse of :meth:`to_dict`."""
        return cls(task=data["task"], start_frame=data["start_frame"],
                   end_frame=data["end_frame"], primitive=data.get("primitive", ""),
                   target=data.get("target"))


@dataclass(frozen=True)
class SynthesisStats:
    """What making one motion took and what its plan was.

    Attributes
    ----------
    automaton_time, sequence_time, library_time : float
        Seconds spent on the specification's automaton, the task sequences and the motion
        library (0 where a cache had them).
    planning_time, blending_time, verification_time : float
        Seconds of the motion planner, of blending the segments and of the checks.
    total_time : float
        Seconds to make this motion, the automaton and the sequences included.
    nodes_expanded : int
        Search nodes the planner expanded.
    duration : float
        The motion's length, seconds.
    real_time_factor : float
        ``duration / total_time``.
    variant : int
        Which motion of the call.
    lasso : str
        The task sequence as the product search found it.
    goal_primitives : list of dict
        Per task step: ``task``, ``primitive``, ``target`` (3,) or None, ``frames``
        [start, end), ``walk_primitives``, ``expanded``.
    start_pose : list of float
        ``[x, y, yaw]`` the worker starts from (m, m, rad).
    steps : list of dict
        Every goal step with its frames (``goal``, ``contact``, ``lift``).
    segments : list of list
        ``[primitive name, start frame, end frame]`` of every placed segment.
    realism : dict
        :func:`~ltl_human_motion.motion.realism.realism_summary` of the motion.
    foot_locking : bool
        Whether the feet were locked (else the motion was blended without it).
    orders_failed : int or None
        Orders of the tasks that failed before this motion's own (None: it is the first).
    first_failure : str or None
        Why the first of them failed.
    batch_total_time : float or None
        Seconds of the whole :func:`~ltl_human_motion.planning.pipeline.synthesize` call.
    """

    automaton_time: float = 0.0
    sequence_time: float = 0.0
    library_time: float = 0.0
    planning_time: float = 0.0
    blending_time: float = 0.0
    verification_time: float = 0.0
    total_time: float = 0.0
    nodes_expanded: int = 0
    duration: float = 0.0
    real_time_factor: float = 0.0
    variant: int = 0
    lasso: str = ""
    goal_primitives: list[dict[str, Any]] = field(default_factory=list)
    start_pose: list[float] = field(default_factory=list)
    steps: list[dict[str, Any]] = field(default_factory=list)
    segments: list[list] = field(default_factory=list)
    realism: dict[str, Any] = field(default_factory=dict)
    foot_locking: bool = False
    orders_failed: int | None = None
    first_failure: str | None = None
    batch_total_time: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """Plain form, in field order; the fields that are None are left out."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if getattr(self, f.name) is not None}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SynthesisStats:
        """Inverse of :meth:`to_dict`; missing fields take their defaults, a key that is
        not a field is a ``ValueError`` naming it."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"unknown stats field(s) {unknown}; expected some of "
                             f"{sorted(known)}")
        return cls(**data)


@dataclass(eq=False)
class SynthesizedMotion:
    """A synthesized full-body motion with its tasks and the objects it moves.

    Attributes
    ----------
    motion : Motion
        Joint positions (T, J, 3), world frame, z up.
    root_yaw : ndarray, shape (T,)
        Heading of the root (pelvis) about +z, radians.
    task_index : ndarray of int, shape (T,)
        Task step executed at each frame, -1 while walking between tasks.
    timeline : list of TaskSegment
        One segment per task step, in order.
    objects : dict of str to ndarray, shape (T, 3)
        Object positions per frame (they move while carried).
    spec : str
        The LTL specification.
    sequence : list of str
        The task sequence, e.g. ``["grasp(O1)", "assemble(R1)"]``.
    seed : int
    stats : SynthesisStats
        What making the motion took (times, expanded nodes, the plan's steps).
    verification : dict
        Results of the verification checks.
    """

    motion: Motion
    root_yaw: np.ndarray
    task_index: np.ndarray
    timeline: list[TaskSegment] = field(default_factory=list)
    objects: dict[str, np.ndarray] = field(default_factory=dict)
    spec: str = ""
    sequence: list[str] = field(default_factory=list)
    seed: int = 0
    stats: SynthesisStats = field(default_factory=SynthesisStats)
    verification: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.motion, Motion):
            raise ValueError(f"motion must be a Motion, got {type(self.motion).__name__}")
        T = self.motion.n_frames
        yaw = np.asarray(self.root_yaw, dtype=np.float64)
        if yaw.shape != (T,):
            raise ValueError(f"root_yaw must have shape ({T},), got {yaw.shape}")
        idx = np.asarray(self.task_index)
        if idx.shape != (T,) or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
            raise ValueError(f"task_index must be an int array of shape ({T},), got "
                             f"{idx.dtype} {idx.shape}")
        idx = idx.astype(np.int64)
        self.sequence = [str(s) for s in self.sequence]
        self.timeline = list(self.timeline)
        n_steps = len(self.sequence) if self.sequence else len(self.timeline)
        if idx.size and (idx.min() < -1 or idx.max() >= n_steps):
            raise ValueError(f"task_index values must lie in [-1, {n_steps - 1}], got "
                             f"[{idx.min()}, {idx.max()}]")
        for seg in self.timeline:
            if not isinstance(seg, TaskSegment):
                raise ValueError(f"timeline entries must be TaskSegment, got {type(seg).__name__}")
            if seg.end_frame > T:
                raise ValueError(f"segment {seg.task!r} ends at frame {seg.end_frame} > {T}")
        objects: dict[str, np.ndarray] = {}
        for name, traj in self.objects.items():
            arr = np.asarray(traj, dtype=np.float64)
            if arr.shape != (T, 3):
                raise ValueError(f"objects[{name!r}] must have shape ({T}, 3), got {arr.shape}")
            objects[str(name)] = arr
        self.root_yaw = yaw
        self.task_index = idx
        self.objects = objects
        self.seed = int(self.seed)

    # ------------------------------------------------------------------ accessors
    @property
    def n_frames(self) -> int:
        return self.motion.n_frames

    @property
    def fps(self) -> float:
        return self.motion.fps

    @property
    def duration(self) -> float:
        return self.motion.duration

    @property
    def positions(self) -> np.ndarray:
        """Joint positions, shape (T, J, 3)."""
        return self.motion.positions

    @property
    def timestamps(self) -> np.ndarray:
        """Frame times in seconds, shape (T,)."""
        return self.motion.timestamps

    def _check_frame(self, frame: int) -> int:
        f = int(frame)
        if f != frame or not 0 <= f < self.n_frames:
            raise ValueError(f"frame must be an integer in [0, {self.n_frames - 1}], got {frame!r}")
        return f

    def task_label(self, index: int) -> str:
        """Name of task step ``index`` (from ``sequence``, else the timeline)."""
        if self.sequence:
            return self.sequence[index]
        return self.timeline[index].task

    def active_task(self, frame: int) -> str | None:
        """The task executed at ``frame``, or None while walking between tasks."""
        i = int(self.task_index[self._check_frame(frame)])
        return None if i < 0 else self.task_label(i)

    def active_segment(self, frame: int) -> TaskSegment | None:
        """The timeline segment that contains ``frame`` (None between tasks)."""
        f = self._check_frame(frame)
        for seg in self.timeline:
            if seg.start_frame <= f < seg.end_frame:
                return seg
        return None

    def frame_at(self, time: float) -> int:
        """Index of the frame nearest to ``time`` seconds (clipped to the motion)."""
        return int(np.clip(round(float(time) * self.fps), 0, self.n_frames - 1))

    def objects_at(self, frame: int) -> dict[str, np.ndarray]:
        """Object positions at ``frame``: name -> (3,)."""
        f = self._check_frame(frame)
        return {name: traj[f] for name, traj in self.objects.items()}
