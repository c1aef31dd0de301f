"""A playback clock for one synthesized motion, shared by the nodes that show one human.

Plain Python (no rclpy): times are seconds on whatever clock the caller uses (the node
clock, so ``use_sim_time`` works). The skeleton publisher and the occupancy node of one
human share a :class:`Playback` object when they run in one process, so TF, markers and
occupancy always show the same pose. Across processes, a follower calls :meth:`sync`
with each ``TaskState`` message of the player (motion id, motion time at the stamp, rate,
loop, state) and extrapolates from there; see ``docs/ros.md``.

States: ``"stopped"`` (no human shown), ``"playing"``, ``"paused"`` and ``"finished"``
(a motion played once stays at its last frame: the worker is still in the cell).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ltl_human_motion.planning.result import SynthesizedMotion

STOPPED = "stopped"
PLAYING = "playing"
PAUSED = "paused"
FINISHED = "finished"
STATES = (STOPPED, PLAYING, PAUSED, FINISHED)


@dataclass(frozen=True)
class TaskProgress:
    """Where the worker is in the task timeline at one frame."""

    current_task: str
    next_task: str
    task_index: int
    task_count: int
    progress: float


@dataclass(frozen=True)
class Frame:
    """The pose of the played motion at one instant.

    Attributes
    ----------
    motion_id : str
    time : float
        Motion time in seconds (0 .. duration).
    index : int
        Index of the frame at or before ``time``.
    positions : ndarray, shape (J, 3)
        Joint positions, world frame, linearly interpolated between frames.
    yaw : float
        Body heading about +z (radians).
    objects : dict of str to ndarray, shape (3,)
        Object positions (they move while carried).
    task : TaskProgress
    state : str
    """

    motion_id: str
    time: float
    index: int
    positions: np.ndarray
    yaw: float
    objects: dict[str, np.ndarray] = field(default_factory=dict)
    task: TaskProgress = TaskProgress("", "", -1, 0, 0.0)
    state: str = PLAYING


def task_sequence_text(motion: SynthesizedMotion) -> str:
    """The tasks of a synthesized motion, separated by ``" ; "`` (from its timeline, else
    from its task sequence)."""
    if motion.timeline:
        return " ; ".join(str(seg.task) for seg in motion.timeline)
    return " ; ".join(str(t) for t in motion.sequence)


class _MotionArrays:
    """The arrays of a SynthesizedMotion that playback needs, checked once."""

    def __init__(self, motion: SynthesizedMotion) -> None:
        body = motion.motion
        self.positions = np.asarray(body.positions, dtype=np.float64)
        if self.positions.ndim != 3 or self.positions.shape[2] != 3 or len(self.positions) < 1:
            raise ValueError(
                f"motion positions must have shape (T, J, 3) with T >= 1, got "
                f"{self.positions.shape}")
        self.fps = float(body.fps)
        self.n_frames = int(self.positions.shape[0])
        self.duration = (self.n_frames - 1) / self.fps
        self.stature = float(body.skeleton.stature)
        yaw = np.asarray(motion.root_yaw, dtype=np.float64)
        self.yaw = np.unwrap(yaw) if yaw.shape == (self.n_frames,) else np.zeros(self.n_frames)
        index = np.asarray(motion.task_index, dtype=np.int64)
        self.task_index = (index if index.shape == (self.n_frames,)
                           else np.full(self.n_frames, -1, dtype=np.int64))
        self.objects = {str(k): np.asarray(v, dtype=np.float64)
                        for k, v in motion.objects.items()}
        timeline = motion.timeline
        self.task_names = [str(seg.task) for seg in timeline]
        self.starts = np.array([int(seg.start_frame) for seg in timeline], dtype=np.int64)
        self.ends = np.array([int(seg.end_frame) for seg in timeline], dtype=np.int64)

    def interpolate(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions (N, J, 3), yaw (N,) and frame indices (N,) at motion times (N,)."""
        f = np.clip(np.asarray(times, dtype=np.float64) * self.fps, 0.0, self.n_frames - 1)
        i0 = np.floor(f).astype(np.int64)
        i1 = np.minimum(i0 + 1, self.n_frames - 1)
        w = (f - i0)
        pos = self.positions[i0] * (1.0 - w)[:, None, None] + self.positions[i1] * w[:, None, None]
        yaw = self.yaw[i0] * (1.0 - w) + self.yaw[i1] * w
        return pos, yaw, i0

    def table(self, key: str, per_frame: Any) -> np.ndarray:
        """``per_frame(positions)`` (T, ...) for this motion, computed once and kept."""
        cache = self.__dict__.setdefault("_tables", {})
        if key not in cache:
            values = np.ascontiguousarray(per_frame(self.positions), dtype=np.float64)
            if len(values) != self.n_frames:
                raise ValueError(f"per-frame table {key!r} has {len(values)} rows, the "
                                 f"motion {self.n_frames} frames")
            cache[key] = values
        return cache[key]

    def interpolate_table(self, table: np.ndarray, times: np.ndarray) -> np.ndarray:
        """Rows of a per-frame ``table`` (T, ...) at motion times (N,): (N, ...)."""
        f = np.clip(np.asarray(times, dtype=np.float64) * self.fps, 0.0, self.n_frames - 1)
        i0 = np.floor(f).astype(np.int64)
        i1 = np.minimum(i0 + 1, self.n_frames - 1)
        w = (f - i0).reshape((-1,) + (1,) * (table.ndim - 1))
        return table[i0] * (1.0 - w) + table[i1] * w

    def objects_at(self, index: int, w: float) -> dict[str, np.ndarray]:
        i1 = min(index + 1, self.n_frames - 1)
        out = {}
        for name, traj in self.objects.items():
            if traj.ndim == 2 and len(traj) == self.n_frames:
                out[name] = traj[index] * (1.0 - w) + traj[i1] * w
            else:
                out[name] = np.asarray(traj, dtype=np.float64).reshape(-1)[:3]
        return out

    def task_at(self, index: int) -> TaskProgress:
        count = len(self.task_names)
        if count == 0:
            return TaskProgress("", "", -1, 0, 0.0)
        current = int(self.task_index[index])
        if 0 <= current < count:
            start, end = self.starts[current], self.ends[current]
            progress = (index - start) / max(end - start, 1)
            nxt = self.task_names[current + 1] if current + 1 < count else ""
            return TaskProgress(self.task_names[current], nxt, current, count,
                                float(np.clip(progress, 0.0, 1.0)))
        # Walking between tasks: report the task walked towards.
        later = np.nonzero(self.starts > index)[0]
        if len(later) == 0:
            return TaskProgress("", "", -1, count, 1.0)
        nxt = int(later[0])
        prev_end = self.ends[nxt - 1] if nxt > 0 else 0
        progress = (index - prev_end) / max(self.starts[nxt] - prev_end, 1)
        return TaskProgress("", self.task_names[nxt], nxt, count,
                            float(np.clip(progress, 0.0, 1.0)))


class Playback:
    """Thread-safe playback state of one motion: which motion, from when, how fast.

    Parameters
    ----------
    on_change : callable, optional
        Called with no arguments after every state change (play, stop, pause, ...).
    """

    def __init__(self, on_change: Any = None) -> None:
        self._lock = threading.RLock()
        self._motion: Any = None
        self._arrays: _MotionArrays | None = None
        self._motion_id = ""
        self._state = STOPPED
        self._rate = 1.0
        self._loop = False
        self._t0 = 0.0        # clock time at which _offset was the motion time
        self._offset = 0.0    # motion time at _t0
        self._on_change = on_change

    # -- properties ---------------------------------------------------------------------
    @property
    def motion_id(self) -> str:
        return self._motion_id

    @property
    def motion(self) -> Any:
        return self._motion

    @property
    def rate(self) -> float:
        return self._rate

    @property
    def loop(self) -> bool:
        return self._loop

    @property
    def duration(self) -> float:
        return self._arrays.duration if self._arrays is not None else 0.0

    @property
    def stature(self) -> float:
        return self._arrays.stature if self._arrays is not None else 1.75

    @property
    def fps(self) -> float:
        return self._arrays.fps if self._arrays is not None else 0.0

    def state(self, now: float) -> str:
        """The state at clock time ``now`` (a motion played once finishes by itself)."""
        with self._lock:
            self._advance(now)
            return self._state

    # -- commands -----------------------------------------------------------------------
    def play(self, motion_id: str, motion: Any, now: float, rate: float = 1.0,
             loop: bool = False, start_time: float = 0.0) -> None:
        """Start ``motion`` from ``start_time`` at clock time ``now``."""
        _check_rate(rate)
        arrays = _MotionArrays(motion)
        with self._lock:
            self._motion, self._arrays, self._motion_id = motion, arrays, motion_id
            self._rate, self._loop = float(rate), bool(loop)
            self._t0, self._offset = float(now), float(np.clip(start_time, 0, arrays.duration))
            self._state = PLAYING
        self._changed()

    def stop(self) -> None:
        """Stop and forget the motion (the human leaves the scene)."""
        with self._lock:
            self._state = STOPPED
            self._offset = 0.0
        self._changed()

    def pause(self, now: float) -> None:
        """Hold the current pose."""
        with self._lock:
            if self._state != PLAYING:
                raise ValueError(f"cannot pause: playback is {self._state}")
            self._offset = self._motion_time(now)
            self._state = PAUSED
        self._changed()

    def resume(self, now: float) -> None:
        """Continue after :meth:`pause`."""
        with self._lock:
            if self._state != PAUSED:
                raise ValueError(f"cannot resume: playback is {self._state}")
            self._t0 = float(now)
            self._state = PLAYING
        self._changed()

    def set_rate(self, now: float, rate: float) -> None:
        """Change the rate without a jump in motion time."""
        _check_rate(rate)
        with self._lock:
            self._offset = self._motion_time(now) if self._arrays is not None else 0.0
            self._t0 = float(now)
            self._rate = float(rate)
        self._changed()

    def sync(self, motion_id: str, motion: Any, motion_time: float, at: float, rate: float,
             loop: bool, state: str) -> None:
        """Follow another player: it was at ``motion_time`` at clock time ``at``."""
        if state not in STATES:
            raise ValueError(f"state must be one of {', '.join(STATES)}, got {state!r}")
        with self._lock:
            if motion_id != self._motion_id or self._arrays is None:
                if motion is None:
                    raise ValueError(f"motion {motion_id!r} is needed to follow it")
                self._arrays = _MotionArrays(motion)
                self._motion, self._motion_id = motion, motion_id
            self._rate = float(rate) if rate > 0 else 1.0
            self._loop = bool(loop)
            self._t0, self._offset = float(at), float(motion_time)
            self._state = state
        self._changed()

    # -- queries ------------------------------------------------------------------------
    def motion_time(self, now: float) -> float | None:
        """Motion time (s) at clock time ``now``; None when stopped."""
        with self._lock:
            self._advance(now)
            if self._state == STOPPED or self._arrays is None:
                return None
            return self._motion_time(now)

    def frame_at(self, now: float) -> Frame | None:
        """The interpolated pose at clock time ``now``; None when stopped."""
        with self._lock:
            t = self.motion_time(now)
            if t is None:
                return None
            arrays, motion_id, state = self._arrays, self._motion_id, self._state
        pos, yaw, idx = arrays.interpolate(np.array([t]))
        index = int(idx[0])
        w = float(np.clip(t * arrays.fps - index, 0.0, 1.0))
        return Frame(motion_id=motion_id, time=float(t), index=index, positions=pos[0],
                     yaw=float(yaw[0]), objects=arrays.objects_at(index, w),
                     task=arrays.task_at(index), state=state)

    def positions_ahead(self, now: float, offsets: np.ndarray) -> np.ndarray | None:
        """Joint positions (N, J, 3) expected ``offsets`` (N,) clock seconds after ``now``.

        Follows the playback: rate, looping, holding at the end, pausing.
        """
        ahead = self._times_ahead(now, offsets)
        if ahead is None:
            return None
        arrays, times = ahead
        return arrays.interpolate(times)[0]

    def sample_ahead(self, now: float, offsets: np.ndarray, key: str,
                     per_frame: Any) -> np.ndarray | None:
        """Like :meth:`positions_ahead` for a per-frame table of the motion: rows (N, ...)
        of ``per_frame(positions (T, J, 3)) -> (T, ...)``, interpolated between frames.

        The table is computed once per loaded motion (cached under ``key``), so a
        quantity that is linear in the joint positions (capsule end points) costs one
        interpolation per call. None when stopped.
        """
        ahead = self._times_ahead(now, offsets)
        if ahead is None:
            return None
        arrays, times = ahead
        return arrays.interpolate_table(arrays.table(key, per_frame), times)

    def _times_ahead(self, now: float, offsets: np.ndarray
                     ) -> tuple[_MotionArrays, np.ndarray] | None:
        offsets = np.asarray(offsets, dtype=np.float64)
        with self._lock:
            t = self.motion_time(now)
            if t is None:
                return None
            arrays, state, rate, loop = self._arrays, self._state, self._rate, self._loop
        if state == PLAYING:
            times = t + rate * offsets
            if loop and arrays.duration > 0:
                times = np.mod(times, arrays.duration)
        else:
            times = np.full(offsets.shape, t)
        return arrays, np.clip(times, 0.0, arrays.duration)

    # -- internals ----------------------------------------------------------------------
    def _motion_time(self, now: float) -> float:
        duration = self._arrays.duration if self._arrays is not None else 0.0
        if self._state != PLAYING:
            return min(self._offset, duration)
        t = self._offset + (float(now) - self._t0) * self._rate
        if self._loop:
            return float(np.mod(max(t, 0.0), duration)) if duration > 0 else 0.0
        return float(np.clip(t, 0.0, duration))

    def _advance(self, now: float) -> None:
        if self._state == PLAYING and not self._loop and self._arrays is not None:
            t = self._offset + (float(now) - self._t0) * self._rate
            if t >= self._arrays.duration:
                self._state, self._offset = FINISHED, self._arrays.duration

    def _changed(self) -> None:
        if self._on_change is not None:
            self._on_change()


def _check_rate(rate: float) -> None:
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"playback rate must be a positive number, got {rate!r}")
