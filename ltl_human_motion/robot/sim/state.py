"""State of the simulated UR controller: trajectory execution, speed slider, safety.

:class:`SimulatedUR` is plain Python with an injected clock; the RTDE and dashboard servers
(:mod:`.rtde_server`) read and write it. Codes follow UR's RTDE guide.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ltl_human_motion.robot.kinematics import URModel, tcp_pose, ur_model
from ltl_human_motion.robot.sim.trajectory import JointTrajectory, default_pick_and_place

__all__ = [
    "ROBOT_MODE_RUNNING",
    "RUNTIME_PAUSED",
    "RUNTIME_PLAYING",
    "SAFETY_NORMAL",
    "SAFETY_PROTECTIVE_STOP",
    "SimulatedUR",
    "SimulatorEvent",
]

ROBOT_MODE_RUNNING = 7
SAFETY_NORMAL = 1
SAFETY_PROTECTIVE_STOP = 3
RUNTIME_PLAYING = 2
RUNTIME_PAUSED = 4
#: A slider at or below this counts as zero (see :meth:`SimulatedUR.set_speed_slider`).
ZERO_SLIDER = 1e-6


@dataclass(frozen=True)
class SimulatorEvent:
    """Something the controller did: ``kind`` is e.g. ``"protective_stop"``."""

    time: float
    kind: str
    detail: str = ""


class SimulatedUR:
    """A UR arm looping a joint trajectory, scaled by the speed slider.

    Parameters
    ----------
    model : str or URModel
    trajectory : JointTrajectory, optional
        Default :func:`~ltl_human_motion.robot.sim.trajectory.default_pick_and_place`.
    clock : callable
        Monotonic seconds.
    zero_slider_protective_stop : bool
        Model the controller's behaviour that a speed slider set to 0 raises a protective
        stop at the next slider change (so clients keep the slider at >= 1 %).
    base : array-like, shape (4, 4), optional
        World-from-base pose of the arm in the cell (reported by :meth:`status`; the RTDE
        outputs are in the base frame, as on a real controller).

    Notes
    -----
    The trajectory time advances at ``speed_slider`` times wall time while the robot runs
    (normal safety mode, program playing); a protective stop freezes it. ``speed_scaling``
    reports that effective rate (0 while stopped); ``target_speed_fraction`` the slider.
    A real controller reports the slider only in ``target_speed_fraction`` (its
    ``speed_scaling`` is the trajectory limiter's), so ur_rtde's
    ``getSpeedScalingCombined()`` (their product) reads slider squared here; clients should
    read the slider with ``getTargetSpeedFraction()``.
    """

    def __init__(self, model: str | URModel = "ur5e", trajectory: JointTrajectory | None = None,
                 clock: Callable[[], float] | None = None,
                 zero_slider_protective_stop: bool = True,
                 base: ArrayLike | None = None) -> None:
        import time

        self.model = ur_model(model)
        self.base = np.eye(4) if base is None else np.asarray(base, dtype=np.float64)
        if self.base.shape != (4, 4) or not np.all(np.isfinite(self.base)):
            raise ValueError(f"base: expected a finite (4, 4) transform, got {self.base.shape}")
        self.trajectory = trajectory if trajectory is not None else default_pick_and_place()
        self.clock = clock if clock is not None else time.monotonic
        self.zero_slider_protective_stop = zero_slider_protective_stop
        self.start_time = self.clock()
        self.speed_slider = 1.0
        self.safety_mode = SAFETY_NORMAL
        self.robot_mode = ROBOT_MODE_RUNNING
        self.runtime_state = RUNTIME_PLAYING
        self.trajectory_time = 0.0
        self.cycle_times: list[float] = []
        self.events: list[SimulatorEvent] = []
        self.digital_outputs = 0
        self.input_registers: dict[str, float | int] = {}
        self._last = self.start_time
        self._cycle_index = 0
        self._cycle_start = self.start_time
        self.q, self.qd, self.qdd = self.trajectory.sample(0.0)
        self.tcp = tcp_pose(self.q, self.model)
        self.tcp_speed = np.zeros(6)

    @property
    def running(self) -> bool:
        """True when the trajectory advances (normal safety mode, program playing)."""
        return self.safety_mode == SAFETY_NORMAL and self.runtime_state == RUNTIME_PLAYING

    @property
    def speed_scaling(self) -> float:
        """Effective rate of trajectory time: the slider while running, else 0."""
        return self.speed_slider if self.running else 0.0

    def _event(self, kind: str, detail: str = "") -> None:
        self.events.append(SimulatorEvent(self.clock() - self.start_time, kind, detail))
        del self.events[:-100]

    def step(self, now: float | None = None) -> None:
        """Advance the simulation to ``now`` (default: the clock)."""
        now = self.clock() if now is None else now
        dt = max(0.0, now - self._last)
        self._last = now
        rate = self.speed_scaling
        old_tcp = self.tcp
        if rate > 0.0 and dt > 0.0:
            self.trajectory_time += dt * rate
            q, qd, qdd = self.trajectory.sample(self.trajectory_time)
            self.q, self.qd, self.qdd = q, qd * rate, qdd * rate * rate
            self.tcp = tcp_pose(self.q, self.model)
            self.tcp_speed = (self.tcp - old_tcp) / dt
            index = int(self.trajectory_time // self.trajectory.cycle_time)
            if index > self._cycle_index:
                self.cycle_times.append(now - self._cycle_start)
                del self.cycle_times[:-1000]
                self._cycle_start = now
                self._cycle_index = index
        else:
            self.qd = np.zeros(6)
            self.qdd = np.zeros(6)
            self.tcp_speed = np.zeros(6)

    def set_speed_slider(self, fraction: float) -> bool:
        """Set the slider (clamped to [0, 1]); NaN is refused. Returns True if applied."""
        if not math.isfinite(fraction):
            return False
        fraction = min(1.0, max(0.0, float(fraction)))
        if (self.zero_slider_protective_stop and self.speed_slider <= ZERO_SLIDER
                and abs(fraction - self.speed_slider) > ZERO_SLIDER):
            self.protective_stop("speed slider changed from 0")
        self.speed_slider = fraction
        return True

    def protective_stop(self, reason: str = "requested") -> None:
        """Enter a protective stop: the arm halts until :meth:`unlock_protective_stop`."""
        if self.safety_mode != SAFETY_PROTECTIVE_STOP:
            self.step()
            self.safety_mode = SAFETY_PROTECTIVE_STOP
            self._event("protective_stop", reason)

    def unlock_protective_stop(self) -> bool:
        """Leave a protective stop (the dashboard's ``unlock protective stop``)."""
        if self.safety_mode != SAFETY_PROTECTIVE_STOP:
            return False
        self.step()
        self.safety_mode = SAFETY_NORMAL
        self._last = self.clock()
        self._event("unlock_protective_stop")
        return True

    def set_program_running(self, playing: bool) -> None:
        """Play or pause the program (the dashboard's ``play`` / ``pause``)."""
        self.step()
        self.runtime_state = RUNTIME_PLAYING if playing else RUNTIME_PAUSED
        self._last = self.clock()

    def status(self) -> dict[str, object]:
        """JSON-friendly snapshot of the state."""
        return {
            "time": self.clock() - self.start_time,
            "model": self.model.name,
            "base_pose": self.base.tolist(),
            "q": [float(v) for v in self.q],
            "tcp_pose": [float(v) for v in self.tcp],
            "speed_slider": self.speed_slider,
            "speed_scaling": self.speed_scaling,
            "safety_mode": self.safety_mode,
            "robot_mode": self.robot_mode,
            "runtime_state": self.runtime_state,
            "trajectory_time": self.trajectory_time,
            "nominal_cycle_time": self.trajectory.cycle_time,
            "cycles_completed": self._cycle_index,
            "cycle_times": list(self.cycle_times),
            "events": [e.__dict__ for e in self.events],
        }

    def joint_positions(self) -> NDArray[np.float64]:
        """Current joint positions (6,) rad."""
        return self.q.copy()
