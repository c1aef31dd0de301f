"""Input propositions of a reactive specification from a robot's own trajectory
(docs/reactive.md): ``robot_in(R)`` and ``robot_moving`` at trajectory time t.

``robot_in(R)`` holds when some capsule of the arm (base to tool,
:func:`~ltl_human_motion.robot.kinematics.robot_capsules`) meets region R's box: a point
of its axis, sampled every :data:`AXIS_SAMPLES`-th of its length (about 2 cm on a UR5e
link), lies within the capsule's radius of the box. ``robot_moving`` holds when the
fastest joint turns faster than ``moving_threshold`` (rad/s).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ltl_human_motion.robot.kinematics import URModel, pose_from_xyz_rpy, robot_capsules, ur_model
from ltl_human_motion.robot.sim.trajectory import JointTrajectory, load_robot_config

__all__ = ["AXIS_SAMPLES", "DEFAULT_MOVING_THRESHOLD", "RobotEvents", "robot_events",
           "robot_inputs"]

#: Points per capsule axis in the region test.
AXIS_SAMPLES = 21

#: Joint speed (rad/s) above which ``robot_moving`` holds.
DEFAULT_MOVING_THRESHOLD = 0.05


@dataclass(frozen=True)
class RobotEvents:
    """The built-in robot inputs along a looping joint trajectory.

    Attributes
    ----------
    trajectory : JointTrajectory
    model : URModel
    base : ndarray, shape (4, 4)
        World-from-base transform.
    regions : mapping of str to (ndarray (3,), ndarray (3,))
        Region name -> (lo, hi) corners of its box, m.
    inputs : tuple of str
        Keys to report (``"robot_in(R1)"``, ``"robot_moving"``); others are left out.
    moving_threshold : float
        rad/s.
    """

    trajectory: JointTrajectory
    model: URModel
    base: np.ndarray
    regions: Mapping[str, tuple[np.ndarray, np.ndarray]]
    inputs: tuple[str, ...]
    moving_threshold: float = DEFAULT_MOVING_THRESHOLD

    @property
    def period(self) -> float:
        """Seconds of one trajectory cycle."""
        return float(self.trajectory.cycle_time)

    def at(self, t: float) -> dict[str, bool]:
        """The inputs at trajectory time ``t`` (s), keyed as in :attr:`inputs`."""
        q, qd, _ = self.trajectory.sample(t)
        return robot_inputs(q, qd, self.model, self.base, self.regions, self.inputs,
                            self.moving_threshold)

    def stopped(self, t: float) -> dict[str, bool]:
        """The inputs of the robot stopped where it is at trajectory time ``t``."""
        return {k: (False if k == "robot_moving" else v) for k, v in self.at(t).items()}


def robot_inputs(q: np.ndarray, qd: np.ndarray | None, model: URModel, base: np.ndarray,
                 regions: Mapping[str, tuple[np.ndarray, np.ndarray]], inputs: Sequence[str],
                 moving_threshold: float = DEFAULT_MOVING_THRESHOLD) -> dict[str, bool]:
    """The built-in robot inputs at joint positions ``q`` (6,) rad and joint speeds
    ``qd`` (6,) rad/s (None: ``robot_moving`` is left out); ``model``, ``base``,
    ``regions``, ``inputs`` and ``moving_threshold`` as the attributes of
    :class:`RobotEvents`."""
    seg, radii = robot_capsules(np.asarray(q, dtype=np.float64), model, base)  # (7, 2, 3)
    s = np.linspace(0.0, 1.0, AXIS_SAMPLES)[None, :, None]
    points = seg[:, :1, :] + s * (seg[:, 1:, :] - seg[:, :1, :])              # (7, S, 3)
    out: dict[str, bool] = {}
    for key in inputs:
        if key == "robot_moving":
            if qd is not None:
                out[key] = bool(np.max(np.abs(qd)) > moving_threshold)
        elif key.startswith("robot_in(") and key[9:-1] in regions:
            lo, hi = regions[key[9:-1]]
            gap = np.maximum(np.maximum(lo - points, points - hi), 0.0)
            dist = np.sqrt((gap * gap).sum(-1))                                  # (7, S)
            out[key] = bool(np.any(dist <= radii[:, None]))
    return out


def robot_events(path: str | Path, cell, inputs: Sequence[str],
                 moving_threshold: float = DEFAULT_MOVING_THRESHOLD) -> RobotEvents:
    """:class:`RobotEvents` of the robot YAML ``path`` (``config/ur_pick_place.yaml``) in
    ``cell`` (its regions' boxes), for the built-in inputs among ``inputs``.

    Raises
    ------
    ValueError
        A malformed robot file (the message names it), or a threshold that is not a
        finite number >= 0.
    """
    if not (np.isfinite(moving_threshold) and moving_threshold >= 0):
        raise ValueError(f"moving_threshold must be a finite speed >= 0 rad/s, got "
                         f"{moving_threshold}")
    cfg = load_robot_config(path)
    model = ur_model(cfg["model"])
    if cfg["tool_length"] is not None:
        model = model.with_tool(float(cfg["tool_length"]), float(cfg["tool_radius"]))
    regions = {name: (np.asarray(r.lo, dtype=np.float64), np.asarray(r.hi, dtype=np.float64))
               for name, r in cell.regions.items()}
    keys = tuple(k for k in inputs if k == "robot_moving" or k.startswith("robot_in("))
    return RobotEvents(cfg["trajectory"], model, pose_from_xyz_rpy(cfg["base_xyz"],
                                                                   cfg["base_rpy"]),
                       regions, keys, float(moving_threshold))
