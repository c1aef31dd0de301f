"""Looping joint-space pick-and-place trajectories for the simulated controller.

A trajectory is a closed list of waypoints. The arm moves from waypoint ``i`` to ``i + 1``
(and from the last back to the first) in ``move_time`` seconds along a minimum-jerk
profile (zero velocity and acceleration at every waypoint), then dwells ``dwell`` seconds.
Time here is *trajectory time*: the controller advances it at the speed-slider rate.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["JointTrajectory", "Waypoint", "default_pick_and_place", "load_robot_config"]


@dataclass(frozen=True)
class Waypoint:
    """A named joint configuration ``q`` (6,) rad, reached after ``move_time`` s, held
    ``dwell`` s."""

    name: str
    q: tuple[float, ...]
    move_time: float
    dwell: float = 0.0


class JointTrajectory:
    """Smooth, looping interpolation through waypoints.

    Parameters
    ----------
    waypoints : sequence of Waypoint
        At least two. ``waypoints[i].move_time`` is the time to move *into* waypoint ``i``
        from its predecessor (waypoint 0 is entered from the last one).
    """

    def __init__(self, waypoints: Sequence[Waypoint]) -> None:
        if len(waypoints) < 2:
            raise ValueError(f"a trajectory needs at least 2 waypoints, got {len(waypoints)}")
        q = np.array([w.q for w in waypoints], dtype=np.float64)
        if q.shape != (len(waypoints), 6) or not np.all(np.isfinite(q)):
            raise ValueError(f"waypoints: expected finite joint vectors of 6, got {q.shape}")
        for w in waypoints:
            if not (math.isfinite(w.move_time) and w.move_time > 0):
                raise ValueError(f"waypoint {w.name!r}: move_time must be > 0, got "
                                 f"{w.move_time}")
            if not (math.isfinite(w.dwell) and w.dwell >= 0):
                raise ValueError(f"waypoint {w.name!r}: dwell must be >= 0, got {w.dwell}")
        self.waypoints = tuple(waypoints)
        self._q = q
        n = len(waypoints)
        # Segment k: from waypoint k-1 (cyclically) to k, moving then dwelling.
        self._move = np.array([w.move_time for w in waypoints])
        self._dwell = np.array([w.dwell for w in waypoints])
        self._start = np.concatenate([[0.0], np.cumsum(self._move + self._dwell)[:-1]])
        self._from = q[np.arange(n) - 1]
        self.cycle_time = float(np.sum(self._move + self._dwell))

    def _locate(self, t: float) -> tuple[int, float]:
        if not math.isfinite(t):
            raise ValueError(f"trajectory time must be finite, got {t}")
        tc = t % self.cycle_time
        k = int(np.searchsorted(self._start, tc, side="right") - 1)
        return k, tc - self._start[k]

    def sample(self, t: float) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                        NDArray[np.float64]]:
        """Joint position, velocity and acceleration at trajectory time ``t``.

        Returns
        -------
        q, qd, qdd : ndarray, shape (6,)
            Per unit of trajectory time (multiply ``qd`` by the time rate for real speed).
        """
        k, local = self._locate(t)
        T = self._move[k]
        q0, q1 = self._from[k], self._q[k]
        if local >= T:
            return q1.copy(), np.zeros(6), np.zeros(6)
        tau = local / T
        s = tau ** 3 * (10 - 15 * tau + 6 * tau ** 2)
        ds = 30 * tau ** 2 * (1 - tau) ** 2 / T
        dds = 60 * tau * (1 - tau) * (1 - 2 * tau) / T ** 2
        dq = q1 - q0
        return q0 + s * dq, ds * dq, dds * dq

    def position(self, t: float) -> NDArray[np.float64]:
        """Joint position (6,) at trajectory time ``t``."""
        return self.sample(t)[0]

    def segment_arrays(self) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                      NDArray[np.float64], NDArray[np.float64]]:
        """The segments as arrays: start times (W,), move times (W,), and the joints each
        one moves from and to (W, 6); segment ``k`` starts at ``start[k]`` (s of the cycle)."""
        return self._start, self._move, self._from, self._q

    def positions(self, times: Sequence[float]) -> NDArray[np.float64]:
        """Joint positions (T, 6) at many trajectory times (vectorized :meth:`position`)."""
        t = np.asarray(times, dtype=np.float64).reshape(-1)
        if not np.all(np.isfinite(t)):
            raise ValueError("trajectory times must be finite")
        tc = t % self.cycle_time
        k = np.searchsorted(self._start, tc, side="right") - 1
        tau = np.minimum((tc - self._start[k]) / self._move[k], 1.0)
        s = tau ** 3 * (10 - 15 * tau + 6 * tau ** 2)
        return self._from[k] + s[:, None] * (self._q[k] - self._from[k])


def default_pick_and_place() -> JointTrajectory:
    """A UR5e pick-and-place cycle of 6.2 s: home, above pick, pick, lift, above place, place."""
    deg = math.radians
    w = [
        ("home", (0, -90, -90, -90, 90, 0), 1.2, 0.2),
        ("above_pick", (-40, -100, -100, -70, 90, 0), 1.0, 0.0),
        ("pick", (-40, -112, -104, -54, 90, 0), 0.6, 0.4),
        ("lift", (-40, -100, -100, -70, 90, 0), 0.6, 0.0),
        ("above_place", (45, -95, -105, -70, 90, 0), 1.2, 0.0),
        ("place", (45, -108, -108, -54, 90, 0), 0.6, 0.4),
    ]
    return JointTrajectory([Waypoint(n, tuple(deg(v) for v in q), mt, dw) for n, q, mt, dw in w])


def _waypoints_from(items: Any, units: str, where: str) -> list[Waypoint]:
    if not isinstance(items, list):
        raise ValueError(f"{where}: 'waypoints' must be a list")
    scale = {"deg": math.pi / 180.0, "rad": 1.0}.get(units)
    if scale is None:
        raise ValueError(f"{where}: units must be 'deg' or 'rad', got {units!r}")
    out = []
    for i, item in enumerate(items):
        if not isinstance(item, Mapping) or "q" not in item:
            raise ValueError(f"{where}: waypoint {i} needs a mapping with 'q'")
        try:
            q = tuple(float(v) * scale for v in item["q"])
            out.append(Waypoint(str(item.get("name", f"wp{i}")), q,
                                float(item.get("move_time", 1.0)), float(item.get("dwell", 0.0))))
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{where}: waypoint {i}: {exc}") from exc
    return out


def load_robot_config(path: str | Path | None) -> dict[str, Any]:
    """Read a robot/trajectory YAML (see ``config/ur_pick_place.yaml``).

    Returns
    -------
    dict
        ``model`` (str), ``base_xyz`` (3,), ``base_rpy`` (3,), ``tool_length``,
        ``tool_radius`` (float or None), ``trajectory`` (:class:`JointTrajectory`).
        With ``path=None``, the defaults (UR5e at the origin, :func:`default_pick_and_place`).
    """
    cfg: dict[str, Any] = {"model": "ur5e", "base_xyz": (0.0, 0.0, 0.0),
                           "base_rpy": (0.0, 0.0, 0.0), "tool_length": None,
                           "tool_radius": None, "trajectory": default_pick_and_place()}
    if path is None:
        return cfg
    import yaml

    from ltl_human_motion.yaml_limits import read_text_file

    where = str(path)
    text = read_text_file(path, "robot config")       # TextFileError, a ValueError
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ValueError(f"{where}: cannot read robot config: {exc}") from exc
    if not isinstance(data, Mapping):
        raise ValueError(f"{where}: expected a mapping at the top level")
    cfg["model"] = str(data.get("model", "ur5e"))
    base = data.get("base", {}) or {}
    if not isinstance(base, Mapping):
        raise ValueError(f"{where}: 'base' must be a mapping with xyz and rpy")
    cfg["base_xyz"] = tuple(float(v) for v in base.get("xyz", (0, 0, 0)))
    cfg["base_rpy"] = tuple(float(v) for v in base.get("rpy", (0, 0, 0)))
    tool = data.get("tool", {}) or {}
    if tool:
        cfg["tool_length"] = float(tool.get("length", 0.15))
        cfg["tool_radius"] = float(tool.get("radius", 0.05))
    traj = data.get("trajectory")
    if traj is not None:
        if not isinstance(traj, Mapping):
            raise ValueError(f"{where}: 'trajectory' must be a mapping")
        cfg["trajectory"] = JointTrajectory(
            _waypoints_from(traj.get("waypoints"), str(traj.get("units", "deg")), where))
    return cfg
