"""The figures of one study item: ergonomics, cycle time and waste, offline SSM.

Runs in batch workers (:attr:`ltl_human_motion.batch.worker.BatchJob.assess`); the
settings are plain JSON (:func:`assess_settings`) so they enter the batch fingerprint and
travel to Dask workers.
"""

from __future__ import annotations

import functools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ltl_human_motion.assess.cycle import cycle_breakdown
from ltl_human_motion.assess.ergonomics import ErgonomicsSettings, assess_motion

__all__ = ["assess_item", "assess_settings", "robot_settings"]


def robot_settings(path: str | Path | None) -> dict[str, Any] | None:
    """A robot YAML (``config/ur_pick_place.yaml``) as plain JSON, or None."""
    if path is None:
        return None
    from ltl_human_motion.robot.sim.trajectory import load_robot_config
    cfg = load_robot_config(path)
    traj = cfg["trajectory"]
    return {"source": str(path), "model": cfg["model"], "base_xyz": list(cfg["base_xyz"]),
            "base_rpy": list(cfg["base_rpy"]), "tool_length": cfg["tool_length"],
            "tool_radius": cfg["tool_radius"],
            "waypoints": [[w.name, list(w.q), w.move_time, w.dwell] for w in traj.waypoints]}


def assess_settings(robot: str | Path | None = None, prediction_horizon: float = 0.0,
                    ergonomics: ErgonomicsSettings | None = None) -> dict[str, Any]:
    """Settings of :func:`assess_item` (JSON-ready)."""
    e = ergonomics or ErgonomicsSettings()
    if not (math.isfinite(prediction_horizon) and prediction_horizon >= 0):
        raise ValueError(f"prediction_horizon must be >= 0 s, got {prediction_horizon}")
    return {"robot": robot_settings(robot), "prediction_horizon": float(prediction_horizon),
            "ergonomics": {"reba_coupling": e.reba_coupling,
                           "niosh_coupling": e.niosh_coupling, "duration": e.duration}}


@functools.lru_cache(maxsize=4)
def _robot(text: str) -> tuple[Any, Any, Any]:
    from ltl_human_motion.robot.kinematics import pose_from_xyz_rpy, ur_model
    from ltl_human_motion.robot.sim.trajectory import JointTrajectory, Waypoint
    r = json.loads(text)
    model = ur_model(r["model"])
    if r.get("tool_length") is not None:
        model = model.with_tool(float(r["tool_length"]), float(r["tool_radius"]))
    traj = JointTrajectory([Waypoint(str(n), tuple(q), float(mt), float(dw))
                            for n, q, mt, dw in r["waypoints"]])
    return traj, model, pose_from_xyz_rpy(r["base_xyz"], r["base_rpy"])


def assess_item(synth: Any, cell: Any, item: Any, settings: dict[str, Any]) -> dict[str, Any]:
    """Ergonomics, cycle time and (with a robot) offline SSM figures of one motion.

    Parameters
    ----------
    synth : SynthesizedMotion
    cell : Cell
        The item's cell (part masses).
    item : ItemParams
        For the cycle count and stature.
    settings : dict
        From :func:`assess_settings`.

    Returns
    -------
    dict
        ``ergonomics`` (summary and per task, lifts), ``cycle`` (breakdown) and ``ssm``
        (offline SSM metrics, or None without a robot).
    """
    masses = {name: float(obj.mass) for name, obj in cell.objects.items()}
    ergo = assess_motion(synth, masses, ErgonomicsSettings(**settings["ergonomics"]),
                         cycles=int(item.cycles))
    out: dict[str, Any] = {"ergonomics": ergo.to_dict(),
                           "cycle": cycle_breakdown(synth, cycles=int(item.cycles)),
                           "ssm": None}
    if settings.get("robot"):
        from ltl_human_motion.robot.offline_ssm import run_offline_ssm
        traj, model, base = _robot(json.dumps(settings["robot"], sort_keys=True))
        res = run_offline_ssm(synth.positions, synth.fps, traj, model, base,
                              stature=float(item.stature),
                              prediction_horizon=float(settings.get("prediction_horizon", 0)))
        m = res.metrics
        out["ssm"] = {k: m[k] for k in (
            "min_separation", "min_separation_time", "protective_distance",
            "time_reduced_speed", "time_min_speed", "time_below_sp", "effective_cycle_time",
            "nominal_cycle_time", "throughput_ratio", "duration")}
        out["ssm"]["violations"] = len(m["violations"])
        out["ssm"]["frames_below_sp"] = len(m["frames_below_sp"])
    out["ergonomics"]["reba_frames"] = np.bincount(ergo.reba, minlength=16)[1:].tolist()
    return out
