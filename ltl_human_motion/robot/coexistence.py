"""Plain-Python coexistence controller: human occupancy in, UR speed slider out.

:class:`CoexistenceController` reads the arm's joint positions through an
``RTDEReceiveInterface``-like object, computes the human-robot separation from the latest
human capsules (optionally a predicted occupancy), maps it to a speed-slider command with
:mod:`.ssm` and writes it through an ``RTDEIOInterface``-like object. The ROS node wraps it;
clocks and connection factories are injected, so tests run it against the real ``ur_rtde``
client and the simulated controller.

Fail-safe behaviour
-------------------
* Occupancy older than ``stale_after``, or none yet: the minimum slider.
* Lost RTDE connection (receive side reports disconnected, robot timestamps freeze, or a
  write fails): the minimum slider is commanded on whatever interface still works, and the
  controller reconnects with exponential backoff, recovering by itself when data returns.
* A human occupancy with NaN/inf, wrong shapes, negative radii, absurd coordinates or a
  stamp in the future is rejected and logged; until the next valid occupancy the command
  cannot rise above the one in force when the rejection happened, and the occupancy in
  force turns stale after ``stale_after`` (the minimum).
* :meth:`CoexistenceController.invalidate_occupancy` (what the ROS node calls when one
  human's stream faults while others' are fine) drops the occupancy at once: the minimum
  from the next step until a valid occupancy arrives.

Usage (what the ROS node does)::

    receive_factory, io_factory = ur_rtde_factories("127.0.0.1")
    ctl = CoexistenceController(receive_factory, io_factory, "ur5e", base=world_from_base)
    ctl.update_occupancy(segments, radii, stamp)    # occupancy callback, any thread
    decision = ctl.step()                           # 125 Hz timer
    ctl.close()                                     # on shutdown

ur_rtde 1.6.5 caveat: an ``RTDEIOInterface`` whose connection broke throws from its
destructor (``std::terminate``). The controller therefore repairs broken interfaces with
``reconnect()`` instead of replacing them, and :meth:`CoexistenceController.close` keeps a
still-broken one alive until the process exits rather than destroying it.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ltl_human_motion.kernel.kept_alive import keep_alive_forever
from ltl_human_motion.kernel.segments import (
    check_capsules,
    compiled,
    group_min_signed_distances,
    min_signed_distance,
)
from ltl_human_motion.robot.kinematics import URModel, robot_capsules, ur_model
from ltl_human_motion.robot.ssm import (
    SSMParameters,
    predictive_separation,
    slider_from_separation,
)

__all__ = [
    "CoexistenceConfig",
    "CoexistenceController",
    "ControlDecision",
    "IOLike",
    "ReceiveLike",
    "ssm_command",
    "ur_rtde_factories",
]

log = logging.getLogger(__name__)


class ReceiveLike(Protocol):
    """The part of ``rtde_receive.RTDEReceiveInterface`` the controller uses."""

    def getActualQ(self) -> list[float]: ...
    def getTimestamp(self) -> float: ...
    def getTargetSpeedFraction(self) -> float: ...
    def isConnected(self) -> bool: ...
    def reconnect(self) -> bool: ...
    def disconnect(self) -> None: ...


class IOLike(Protocol):
    """The part of ``rtde_io.RTDEIOInterface`` the controller uses."""

    def setSpeedSlider(self, speed: float) -> bool: ...
    def reconnect(self) -> bool: ...
    def disconnect(self) -> None: ...


def ur_rtde_factories(host: str = "127.0.0.1", frequency: float = -1.0
                      ) -> tuple[Callable[[], ReceiveLike], Callable[[], IOLike]]:
    """Factories of the real ``ur_rtde`` interfaces (imported lazily).

    The receive interface subscribes only to what the controller needs.
    """
    try:
        import rtde_io
        import rtde_receive
    except ImportError as exc:
        from ltl_human_motion.errors import MissingDependencyError

        raise MissingDependencyError("the UR client is missing: pip install ur-rtde") from exc
    variables = ["timestamp", "actual_q", "speed_scaling", "target_speed_fraction",
                 "safety_mode", "robot_mode"]

    def make_receive() -> ReceiveLike:
        return rtde_receive.RTDEReceiveInterface(host, frequency, variables)

    def make_io() -> IOLike:
        return rtde_io.RTDEIOInterface(host)

    return make_receive, make_io


@dataclass(frozen=True)
class CoexistenceConfig:
    """Timing and robustness settings.

    Attributes
    ----------
    stale_after : float
        Occupancy older than this (s) is stale.
    future_tolerance : float
        Occupancy stamped further than this (s) in the future is rejected.
    robot_stale_after : float
        Robot timestamps frozen for this long (s) count as a lost connection.
    backoff_initial, backoff_max : float
        Reconnection delays (s), doubling after each failure.
    resend_period : float
        An unchanged command is re-sent at least this often (s).
    use_prediction : bool
        Use predicted occupancy when given (else only the current one).
    max_coordinate : float
        Human capsule coordinates beyond this (m) are absurd.
    max_capsules : int
        More human capsules than this per occupancy are rejected.
    """

    stale_after: float = 0.25
    future_tolerance: float = 0.05
    robot_stale_after: float = 0.5
    backoff_initial: float = 0.05
    backoff_max: float = 2.0
    resend_period: float = 0.5
    use_prediction: bool = True
    max_coordinate: float = 50.0
    max_capsules: int = 256

    def __post_init__(self) -> None:
        for name in ("stale_after", "future_tolerance", "robot_stale_after", "backoff_initial",
                     "backoff_max", "resend_period", "max_coordinate"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"CoexistenceConfig.{name}: expected > 0, got {value}")
        if self.backoff_max < self.backoff_initial:
            raise ValueError("CoexistenceConfig: backoff_max < backoff_initial")


def ssm_command(effective_separation: float, params: SSMParameters) -> tuple[float, str]:
    """Speed-slider command and mode (``"full"``, ``"reduced"``, ``"stop"``) for an
    effective separation (m): the decision of one control step, without I/O (the live
    loop and :mod:`.offline_ssm` both use it)."""
    slider = slider_from_separation(effective_separation, params)
    mode = ("full" if slider >= params.max_slider
            else "stop" if slider <= params.min_slider else "reduced")
    return slider, mode


@dataclass(frozen=True)
class ControlDecision:
    """What one control step saw and did.

    Attributes
    ----------
    time : float
        Clock time of the step (s).
    slider : float
        Speed-slider command of this step.
    sent : bool
        Whether it was written to the robot in this step.
    mode : str
        ``"full"``, ``"reduced"``, ``"stop"`` (separation at or below S_p), ``"stale"``
        (no fresh occupancy), ``"disconnected"``.
    separation : float
        Current minimum separation (m), NaN when unknown.
    effective_separation : float
        Separation the command is based on (after prediction), NaN when unknown.
    protective_distance : float
        S_p (m).
    connected : bool
    capped : bool
        True when a rejected occupancy held the command down.
    q : tuple of float or None
        Joint positions read in this step.
    """

    time: float
    slider: float
    sent: bool
    mode: str
    separation: float
    effective_separation: float
    protective_distance: float
    connected: bool
    capped: bool = False
    q: tuple[float, ...] | None = None


@dataclass
class _Occupancy:
    stamp: float
    segments: NDArray[np.float64]
    radii: NDArray[np.float64]
    pred_segments: NDArray[np.float64] | None = None   # (N, 2, 3) all horizons stacked
    pred_radii: NDArray[np.float64] | None = None
    pred_offsets: NDArray[np.intp] | None = None       # start of each horizon
    horizons: NDArray[np.float64] | None = None


#: Seconds :meth:`CoexistenceController.close` waits for one RTDE interface's disconnect
#: (about 1 ms from a live controller).
DISCONNECT_TIMEOUT = 1.0


def _disconnect_within(obj: Any, timeout: float) -> str | None:
    """Call ``obj.disconnect()`` on a daemon thread (ur_rtde releases the GIL while it
    waits); None when it returned within ``timeout`` seconds, else why not."""
    failure: list[str] = ["no answer within " + f"{timeout:g} s"]

    def run() -> None:
        try:
            obj.disconnect()
            failure.clear()
        except Exception as exc:
            failure[:] = [str(exc) or type(exc).__name__]

    thread = threading.Thread(target=run, name="rtde-disconnect", daemon=True)
    thread.start()
    thread.join(timeout)
    return failure[0] if thread.is_alive() or failure else None


class CoexistenceController:
    """Speed and separation monitoring of one UR arm against one human.

    Parameters
    ----------
    receive_factory, io_factory : callable
        Create connected ``RTDEReceiveInterface``/``RTDEIOInterface``-like objects (they
        raise when the robot is unreachable). See :func:`ur_rtde_factories`.
    model : str or URModel
        Arm model (capsules from :func:`~ltl_human_motion.robot.kinematics.robot_capsules`).
    base : array-like, shape (4, 4), optional
        World-from-base transform of the arm in the cell.
    params : SSMParameters
    config : CoexistenceConfig
    clock : callable
        Monotonic seconds; occupancy stamps use the same clock.
    on_decision : callable, optional
        Called with every :class:`ControlDecision` (e.g. a metrics recorder).
    """

    def __init__(self, receive_factory: Callable[[], ReceiveLike],
                 io_factory: Callable[[], IOLike], model: str | URModel = "ur5e",
                 base: ArrayLike | None = None, params: SSMParameters | None = None,
                 config: CoexistenceConfig | None = None,
                 clock: Callable[[], float] = time.monotonic,
                 on_decision: Callable[[ControlDecision], None] | None = None) -> None:
        self.model = ur_model(model)
        self.base = np.eye(4) if base is None else np.asarray(base, dtype=np.float64)
        if self.base.shape != (4, 4) or not np.all(np.isfinite(self.base)):
            raise ValueError(f"base: expected a finite (4, 4) transform, got {self.base.shape}")
        self.params = params if params is not None else SSMParameters()
        self.config = config if config is not None else CoexistenceConfig()
        self.clock = clock
        self.on_decision = on_decision
        self._receive_factory = receive_factory
        self._io_factory = io_factory
        self._recv: Any = None
        self._io: Any = None
        self._recv_ok = False
        self._io_ok = False
        self._next_attempt = -math.inf
        self._backoff = self.config.backoff_initial
        self._occ: _Occupancy | None = None
        self._ceiling: float | None = None
        self._last_command = self.params.min_slider
        self._last_sent: float | None = None
        self._last_sent_time = -math.inf
        self._robot_stamp: float | None = None
        self._robot_stamp_changed = -math.inf
        self._lock = threading.Lock()
        compiled()   # load the distance kernel now, not in the first control cycle
        self.rejections = 0
        self.reconnects = 0
        self.last_rejection: str | None = None

    # ------------------------------------------------------------------ occupancy input
    def update_occupancy(self, segments: ArrayLike, radii: ArrayLike,
                         stamp: float | None = None,
                         predicted: Sequence[tuple[float, ArrayLike, ArrayLike]] | None = None,
                         *, check_order: bool = True) -> bool:
        """Offer the latest human occupancy.

        Parameters
        ----------
        segments : array-like, shape (K, 2, 3)
            Human capsule axes in the world frame (m).
        radii : array-like, shape (K,)
        stamp : float, optional
            Time of the occupancy on the controller's clock (s); default: now (receipt
            time, for sources whose clock differs from the controller's).
        predicted : sequence of (horizon, segments (K_i, 2, 3), radii (K_i,)), optional
            Predicted occupancy ``horizon`` seconds after ``stamp``.
        check_order : bool
            Ignore an occupancy older than the current one (default). A caller merging
            several humans passes False: the merged stamp (the oldest human's) may go back.

        Returns
        -------
        bool
            True if accepted; False if rejected (logged) or older than the current one.

        Notes
        -----
        May be called from another thread than :meth:`step`.
        """
        try:
            occ = self._validated(segments, radii, self.clock() if stamp is None else stamp,
                                  predicted)
        except ValueError as exc:
            with self._lock:
                self.rejections += 1
                self.last_rejection = str(exc)
                cap = self._last_command if self._ceiling is None \
                    else min(self._ceiling, self._last_command)
                self._ceiling = cap
            log.warning("human occupancy rejected (%s); speed held at <= %.3f", exc, cap)
            return False
        with self._lock:
            if check_order and self._occ is not None and occ.stamp < self._occ.stamp:
                log.debug("out-of-order occupancy (%.3f) ignored", occ.stamp)
                return False
            self._occ = occ
            self._ceiling = None
        return True

    def check_occupancy(self, segments: ArrayLike, radii: ArrayLike, stamp: float,
                        predicted: Sequence[tuple[float, ArrayLike, ArrayLike]] | None = None
                        ) -> None:
        """Raise ValueError saying what is wrong with an occupancy (shapes as in
        :meth:`update_occupancy`), without offering it."""
        self._validated(segments, radii, stamp, predicted)

    def invalidate_occupancy(self, reason: str) -> None:
        """Drop the occupancy in force: the minimum slider until a valid one is offered."""
        with self._lock:
            self._occ = None
            self.rejections += 1
            self.last_rejection = reason

    def _validated(self, segments: ArrayLike, radii: ArrayLike, stamp: float,
                   predicted: Sequence[tuple[float, ArrayLike, ArrayLike]] | None
                   ) -> _Occupancy:
        try:
            stamp = float(stamp)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"stamp must be a number, got {stamp!r}") from exc
        if not math.isfinite(stamp):
            raise ValueError(f"stamp must be finite, got {stamp}")
        if stamp > self.clock() + self.config.future_tolerance:
            raise ValueError(f"stamp {stamp:.3f} lies {stamp - self.clock():.3f} s in the "
                             f"future (tolerance {self.config.future_tolerance:g} s)")
        seg, rad = check_capsules(segments, radii, "human capsules", self.config.max_coordinate)
        if len(seg) > self.config.max_capsules:
            raise ValueError(f"{len(seg)} human capsules exceed {self.config.max_capsules}")
        occ = _Occupancy(stamp, seg, rad)
        if predicted:
            segs, rads, offsets, hor = [], [], [], []
            n = 0
            for i, item in enumerate(predicted):
                try:
                    horizon, pseg, prad = item
                    horizon = float(horizon)
                except (TypeError, ValueError) as exc:
                    raise ValueError(f"predicted[{i}]: expected (horizon, segments, radii)") \
                        from exc
                if not (math.isfinite(horizon) and 0.0 <= horizon <= 60.0):
                    raise ValueError(f"predicted[{i}]: horizon must be in [0, 60] s, "
                                     f"got {horizon}")
                ps, pr = check_capsules(pseg, prad, f"predicted[{i}] capsules",
                                        self.config.max_coordinate)
                segs.append(ps)
                rads.append(pr)
                offsets.append(n)
                hor.append(horizon)
                n += len(ps)
            occ.pred_segments = np.concatenate(segs)
            occ.pred_radii = np.concatenate(rads)
            occ.pred_offsets = np.asarray(offsets, dtype=np.intp)
            occ.horizons = np.asarray(hor)
        return occ

    # ------------------------------------------------------------------ connection
    @property
    def connected(self) -> bool:
        """True when both RTDE interfaces work."""
        return self._recv_ok and self._io_ok

    def _connect(self, now: float) -> bool:
        if self.connected:
            return True
        if now < self._next_attempt:
            return False
        try:
            if not self._recv_ok:
                if self._recv is None:
                    self._recv = self._receive_factory()
                else:
                    self._recv.reconnect()
                self._recv_ok = bool(self._recv.isConnected())
                self._robot_stamp = None
            if self._recv_ok and not self._io_ok:
                if self._io is None:
                    self._io = self._io_factory()
                else:
                    self._io.reconnect()
                self._io_ok = True
                self._last_sent = None
        except (RuntimeError, OSError) as exc:
            log.info("RTDE connection attempt failed (%s); retry in %.2f s", exc, self._backoff)
        if self.connected:
            self.reconnects += 1
            self._backoff = self.config.backoff_initial
            log.info("RTDE connected")
            return True
        self._next_attempt = now + self._backoff
        self._backoff = min(2.0 * self._backoff, self.config.backoff_max)
        return False

    def _read_q(self, now: float) -> NDArray[np.float64] | None:
        try:
            if not self._recv.isConnected():
                raise RuntimeError("receive interface disconnected")
            q = np.asarray(self._recv.getActualQ(), dtype=np.float64)
            stamp = float(self._recv.getTimestamp())
        except (RuntimeError, OSError, TypeError, ValueError) as exc:
            self._lost("receive", exc)
            return None
        if stamp != self._robot_stamp:
            self._robot_stamp = stamp
            self._robot_stamp_changed = now
        elif now - self._robot_stamp_changed > self.config.robot_stale_after:
            self._lost("receive", RuntimeError("robot data stopped arriving"))
            return None
        if q.shape != (6,) or not np.all(np.isfinite(q)):
            self._lost("receive", ValueError(f"bad joint positions {q}"))
            return None
        return q

    def _lost(self, which: str, exc: BaseException) -> None:
        if which == "receive":
            if self._recv_ok:
                log.warning("RTDE receive lost: %s", exc)
            self._recv_ok = False
            if self._io_ok:
                # Best effort: slow down through the io side, then reconnect it as well
                # (both talk to the same controller, whose restart would leave it stale).
                try:
                    self._io.setSpeedSlider(float(self.params.min_slider))
                    self._last_sent = None
                except (RuntimeError, OSError):
                    pass
        if self._io_ok:
            if which == "io":
                log.warning("RTDE io lost: %s", exc)
            self._io_ok = False
        self._backoff = self.config.backoff_initial
        self._next_attempt = self.clock() + self._backoff

    def _send(self, slider: float, now: float) -> bool:
        if not self._io_ok:
            return False
        if (self._last_sent is not None and abs(slider - self._last_sent) < 1e-4
                and now - self._last_sent_time < self.config.resend_period):
            return False
        try:
            ok = bool(self._io.setSpeedSlider(float(slider)))
        except (RuntimeError, OSError) as exc:
            self._lost("io", exc)
            return False
        if not ok:
            self._lost("io", RuntimeError("setSpeedSlider returned false"))
            return False
        self._last_sent = slider
        self._last_sent_time = now
        return True

    # ------------------------------------------------------------------ control
    def robot_capsules(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World-frame capsules (7, 2, 3), (7,) of the arm at joint positions ``q``."""
        return robot_capsules(q, self.model, self.base)

    def separations(self, q: ArrayLike) -> tuple[float, float]:
        """Current and effective (prediction-aware) separation (m) for joint positions
        ``q`` (6,) and the latest accepted occupancy; NaN for both without one."""
        with self._lock:
            occ = self._occ
        return self._separations(q, occ)

    def _separations(self, q: ArrayLike, occ: _Occupancy | None) -> tuple[float, float]:
        if occ is None:
            return math.nan, math.nan
        rseg, rrad = self.robot_capsules(q)
        current = min_signed_distance(occ.segments, occ.radii, rseg, rrad)
        if occ.pred_segments is None or not self.config.use_prediction:
            return current, current
        per_horizon = group_min_signed_distances(occ.pred_segments, occ.pred_radii, rseg, rrad,
                                                 occ.pred_offsets)
        return current, predictive_separation(current, per_horizon, occ.horizons, self.params)

    def step(self) -> ControlDecision:
        """One control cycle: read the arm, compute the command, write it."""
        now = self.clock()
        sp = self.params.protective_distance
        q = self._read_q(now) if self._connect(now) else None
        sep = eff = math.nan
        with self._lock:
            occ = self._occ
        if q is None:
            mode, slider = "disconnected", self.params.min_slider
        elif occ is None or now - occ.stamp > self.config.stale_after:
            mode, slider = "stale", self.params.min_slider
        else:
            sep, eff = self._separations(q, occ)
            slider, mode = ssm_command(eff, self.params)
        with self._lock:
            ceiling = self._ceiling
            capped = ceiling is not None and slider > ceiling
            if capped:
                slider = float(ceiling)  # type: ignore[arg-type]
            self._last_command = slider
        sent = self._send(slider, now)
        decision = ControlDecision(now, slider, sent, mode, sep, eff, sp, self.connected,
                                   capped, None if q is None else tuple(float(v) for v in q))
        if self.on_decision is not None:
            self.on_decision(decision)
        return decision

    def run(self, rate: float = 125.0, duration: float | None = None,
            should_stop: Callable[[], bool] | None = None,
            before_step: Callable[[float], None] | None = None) -> int:
        """Step at ``rate`` Hz until ``duration`` s pass or ``should_stop()`` is true.

        ``before_step(t)`` (t = seconds since start) may feed occupancy. Returns the number
        of steps. Uses wall-clock sleeping, so it needs the real monotonic clock.
        """
        if not (math.isfinite(rate) and rate > 0):
            raise ValueError(f"rate must be > 0, got {rate}")
        period = 1.0 / rate
        start = time.monotonic()
        next_time = start
        steps = 0
        while True:
            now = time.monotonic()
            if duration is not None and now - start >= duration:
                break
            if should_stop is not None and should_stop():
                break
            if before_step is not None:
                before_step(now - start)
            self.step()
            steps += 1
            next_time += period
            delay = next_time - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            elif delay < -10 * period:
                next_time = time.monotonic()
        return steps

    def hold_minimum(self, timeout: float = 0.5) -> str | None:
        """Command the minimum slider and wait until the controller reports it.

        What a monitor that stops leaves the arm at (the ROS node's deactivate and
        shutdown); call it with the control loop stopped. Returns None once the receive side
        reads ``target_speed_fraction`` within 1e-3 of ``params.min_slider`` in a package
        the controller sent after the write (a newer ``timestamp``: a frozen controller's
        last package confirms nothing) within ``timeout`` s, else why not."""
        target = float(self.params.min_slider)
        if not self._io_ok:
            return "not connected to the robot controller"
        try:
            written_at = float(self._recv.getTimestamp()) if self._recv_ok else math.nan
            if not self._io.setSpeedSlider(target):
                raise RuntimeError("setSpeedSlider returned false")
        except Exception as exc:            # best effort, whatever ur_rtde raises
            self._lost("io", exc)
            return f"the minimum slider was not written ({exc})"
        with self._lock:
            self._last_command = target
        self._last_sent, self._last_sent_time = target, self.clock()
        if not self._recv_ok:
            return "written, but the receive side is not connected to confirm it"
        end = time.monotonic() + timeout
        stamp, reported = written_at, math.nan
        while time.monotonic() < end:
            try:
                stamp = float(self._recv.getTimestamp())
                reported = float(self._recv.getTargetSpeedFraction())
            except Exception as exc:
                return f"written, but not confirmed ({exc})"
            if stamp != written_at and abs(reported - target) < 1e-3:
                return None
            time.sleep(0.002)
        frozen = ", its data frozen" if stamp == written_at else ""
        return (f"written, but not confirmed within {timeout:g} s (the controller reports "
                f"{reported:.3f}{frozen})")

    def close(self) -> None:
        """Disconnect the working interfaces; a broken one is neither disconnected nor
        destroyed but kept alive (see the module docstring), and the loss is logged.

        Issue 34: after the controller went away, destroying the broken
        ``RTDEIOInterface`` (held by a wrapper, so not recognised by its type) made its
        destructor write to the closed socket: "write: Broken pipe", std::terminate. A
        frozen controller (process stopped, socket open) never answers a disconnect: the
        controller's timestamp must move first, and each disconnect gets
        :data:`DISCONNECT_TIMEOUT` seconds."""
        if self._recv is not None and self.connected and not self._controller_answers():
            self._recv_ok = self._io_ok = False
        lost = []
        for attr, ok in (("_io", self._io_ok), ("_recv", self._recv_ok)):
            obj = getattr(self, attr)
            if obj is None:
                continue
            setattr(self, attr, None)
            if ok:
                failure = _disconnect_within(obj, DISCONNECT_TIMEOUT)
                if failure is None:
                    continue
                log.warning("RTDE %s: disconnect failed (%s)", attr[1:], failure)
            lost.append(attr[1:])
            keep_alive_forever(obj)
        if lost:
            log.warning("robot connection lost before the stop (RTDE %s); not disconnected",
                        " and ".join(lost))
        self._recv_ok = self._io_ok = False

    def _controller_answers(self) -> bool:
        """True when the receive side is connected and the controller's timestamp moves
        within ``robot_stale_after`` (a killed controller closes the socket, a frozen one
        leaves it open and silent; either never answers a disconnect)."""
        end = time.monotonic() + self.config.robot_stale_after
        try:
            first = self._recv.getTimestamp()
            while self._recv.isConnected():
                if self._recv.getTimestamp() != first:
                    return True
                if time.monotonic() > end:
                    return False
                time.sleep(0.002)
        except (RuntimeError, OSError):
            pass
        return False

    def __enter__(self) -> CoexistenceController:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
