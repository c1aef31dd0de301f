"""The human-robot coexistence loop end to end, as one function (the README demo).

:func:`run_coexistence_demo`:

1. starts the simulated UR5e of ``config/ur_pick_place.yaml`` in its own process
   (RTDE on 127.0.0.1:30004; skipped when ``robot_host`` names URSim or a real arm);
2. brings up the synthesis node and one worker's skeleton publisher and occupancy node
   (with a 1 s prediction) in this process (``config/bringup.yaml``);
3. measures the **baseline**: the robot's cycle time at full speed with no human (the arm
   runs alone while the worker's motion is synthesized);
4. from a client node in its own context (every call crosses DDS) calls
   ``/synthesize_motion`` for the spec (default: the paper's S1 in ``paper_cell``, which
   takes the worker to R1 on the robot's workbench) and, once per mode (**reactive**, then
   **predictive**), starts a coexistence node, plays the motion on
   ``/human_1/play_motion`` and runs the loop while the worker works;
5. writes per mode ``coexistence_<mode>.json`` and ``.png`` (commissioning metrics: minimum
   separation over time, time at reduced speed and at the minimum, protective-distance
   violations, robot cycle time against the baseline) and ``coexistence_summary.json``.

With the simulated controller, the robot's progress comes from the controller itself
(trajectory time and completed cycles); against another controller the effective cycle
time is estimated from the commanded slider (trajectory time advances at slider x wall
time) and needs ``baseline_cycle_time``.
"""

from __future__ import annotations

import contextlib
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from rclpy.parameter import Parameter

from ltl_human_motion.atomic import atomic_write_text
from ltl_human_motion.msg import SafetyStatus
from ltl_human_motion.robot.coexistence import ControlDecision
from ltl_human_motion.robot.metrics import write_commissioning_report
from ltl_human_motion.robot.sim.port_lock import RTDE_PORT, rtde_port_lock, wait_port_free
from ltl_human_motion.robot.sim.process import URSimHandle, start_ur_sim_process
from ltl_human_motion.robot.sim.trajectory import load_robot_config
from ltl_human_motion.ros.bringup import Bringup
from ltl_human_motion.ros.client import ClientSession, wait_until
from ltl_human_motion.ros.coexistence_node import CONTROL_SWITCH_INTERVAL, CoexistenceNode
from ltl_human_motion.ros.common import SpinThread
from ltl_human_motion.srv import PlayMotion, SynthesizeMotion

__all__ = [
    "ROBOT_CONFIG",
    "RTDE_PORT",
    "node_parameters_from_robot_config",
    "rtde_port_lock",
    "run_coexistence_demo",
    "start_sim_when_free",
    "wait_port_free",
]

ROOT = Path(__file__).resolve().parents[2]
ROBOT_CONFIG = ROOT / "config" / "ur_pick_place.yaml"
#: ur_rtde always connects to this port: only one simulated controller per machine.


def start_sim_when_free(robot_config: str | Path | None = ROBOT_CONFIG, timeout: float = 60.0,
                        **kwargs: Any) -> URSimHandle:
    """Start the simulated controller on 127.0.0.1:30004 as soon as the port is free.

    The dashboard server is off unless ``dashboard_port`` is given. Retries when another
    program takes the port between the check and the start; TimeoutError after
    ``timeout`` s.
    """
    kwargs.setdefault("dashboard_port", -1)
    end = time.monotonic() + timeout
    while True:
        wait_port_free("127.0.0.1", RTDE_PORT, max(end - time.monotonic(), 0.1))
        try:
            return start_ur_sim_process(trajectory=robot_config, host="127.0.0.1",
                                        rtde_port=RTDE_PORT, **kwargs)
        except OSError:
            if time.monotonic() > end:
                raise
            time.sleep(0.2)


def node_parameters_from_robot_config(path: str | Path | None = ROBOT_CONFIG
                                      ) -> dict[str, Any]:
    """Coexistence-node parameters (model, tool, base pose) of a robot YAML file."""
    cfg = load_robot_config(path)
    roll, pitch, yaw = cfg["base_rpy"]
    if abs(roll) > 1e-9 or abs(pitch) > 1e-9:
        raise ValueError(f"{path}: the coexistence node supports a base rotated about z only "
                         f"(rpy [0, 0, yaw]); got {cfg['base_rpy']}")
    out: dict[str, Any] = {"model": cfg["model"], "base_x": cfg["base_xyz"][0],
                           "base_y": cfg["base_xyz"][1], "base_z": cfg["base_xyz"][2],
                           "base_yaw": float(yaw)}
    if cfg["tool_length"] is not None:
        out["tool_length"] = float(cfg["tool_length"])
        out["tool_radius"] = float(cfg["tool_radius"])
    return out


def _measure_baseline(sim: URSimHandle, cycles: int) -> dict[str, Any]:
    """Cycle time of the robot running alone at full speed (waits for ``cycles``)."""
    status = sim.status()
    nominal = float(status["nominal_cycle_time"])
    timeout = nominal * (cycles + 1) / max(status["speed_slider"], 0.05) + 10.0
    wait_until(lambda: sim.status()["cycles_completed"] >= cycles, timeout,
               f"{cycles} robot cycle(s) at full speed")
    status = sim.status()
    times = [float(t) for t in status["cycle_times"][:cycles]]
    return {"cycle_times": times, "cycle_time": float(np.mean(times)),
            "nominal_cycle_time": nominal, "source": "simulated controller, no human, 100 %"}


def _run_mode(session: ClientSession, context: Any, *, mode: str, motion_id: str,
              motion_duration: float, playback_rate: float, duration: float | None,
              node_params: dict[str, Any], sim: URSimHandle | None,
              baseline: float | None, out: Path, human_ns: str,
              extra: dict[str, Any]) -> dict[str, Any]:
    """One coexistence run: a fresh node, the worker's motion played once, the metrics."""
    params = {**node_params, "use_prediction": mode == "predictive"}
    node = CoexistenceNode(node_name=f"coexistence_{mode}", record=True, context=context,
                           parameter_overrides=[Parameter(k, value=v)
                                                for k, v in params.items()])
    spinner = SpinThread([node], context, 2)
    try:
        wait_until(lambda: node.latest is not None and node.latest.connected, 15.0,
                   f"the coexistence node to connect to {params['robot_host']}:30004")
        before = sim.status() if sim is not None else None
        t_play = node.controller.clock()
        played = session.call(PlayMotion, f"{human_ns}/play_motion", PlayMotion.Request(
            command="play", motion_id=motion_id, loop=False, rate=playback_rate))
        if not played.success:
            raise RuntimeError(f"play_motion: {played.message}")
        run_for = duration if duration is not None else motion_duration / playback_rate + 0.5
        time.sleep(run_for)
        t_end = node.controller.clock()
        after = sim.status() if sim is not None else None
        session.call(PlayMotion, f"{human_ns}/play_motion", PlayMotion.Request(command="stop"))
    finally:
        spinner.stop()
        node.stop_control()
    decisions: list[ControlDecision] = [d for d in node.recorder.decisions
                                        if t_play <= d.time <= t_end]
    node.destroy_node()
    if not decisions:
        raise RuntimeError(f"{mode}: the coexistence node made no control decision")
    wall = decisions[-1].time - decisions[0].time
    sliders = np.array([d.slider for d in decisions])
    dt = np.diff([d.time for d in decisions], append=decisions[-1].time)
    progress: dict[str, Any] = {"slider_integral_s": float(np.sum(sliders * dt)),
                                "wall_s": float(wall)}
    cycle_times: list[float] = []
    if before is not None and after is not None:
        progress["trajectory_time_s"] = after["trajectory_time"] - before["trajectory_time"]
        cycle_times = [float(c) for c in after["cycle_times"][before["cycles_completed"]:]]
        nominal = float(after["nominal_cycle_time"])
    else:
        progress["trajectory_time_s"] = progress["slider_integral_s"]
        nominal = baseline
    ratio = progress["trajectory_time_s"] / max(wall, 1e-9)
    progress["throughput_ratio"] = ratio
    progress["effective_cycle_time"] = (nominal / ratio) if nominal and ratio > 0 else None
    if baseline and progress["effective_cycle_time"]:
        progress["effective_cycle_time_ratio"] = progress["effective_cycle_time"] / baseline
    progress.update(_approach(decisions, node.params.min_slider))
    statuses = session.watcher.logs.get("/safety_status")
    info = {"mode": mode, "progress": progress, "ssm_terms": node.params.terms(),
            "safety_status_messages": statuses.count if statuses else 0, **extra}
    json_path, png_path = write_commissioning_report(
        decisions, out, f"coexistence_{mode}", cycle_times, baseline,
        node.params.max_slider, node.params.min_slider, info)
    metrics = json.loads(json_path.read_text())
    metrics["json"], metrics["png"] = str(json_path), str(png_path)
    return metrics


def _approach(decisions: list[ControlDecision], min_slider: float) -> dict[str, float | None]:
    """How the arm met the worker's first approach within S_p lasting over 0.5 s:
    ``stop_lead_time``, seconds the arm was already at the slider minimum when the
    separation fell below S_p (0 for a purely reactive reaction), and
    ``mean_slider_1s_before``, the mean command in the second before (lower = slowed
    earlier). None without such an approach."""
    t = np.array([d.time for d in decisions])
    sliders = np.array([d.slider for d in decisions])
    below = np.array([d.separation < d.protective_distance for d in decisions])
    at_min = np.array([d.slider <= min_slider + 1e-9 for d in decisions])
    starts = np.flatnonzero(below & ~np.concatenate([[False], below[:-1]]))
    for i in starts:
        j = i
        while j < len(below) and below[j]:
            j += 1
        if t[j - 1] - t[i] < 0.5:
            continue
        k = i
        while k > 0 and at_min[k - 1]:
            k -= 1
        window = (t >= t[i] - 1.0) & (t < t[i])
        return {"stop_lead_time": float(t[i] - t[k]) if at_min[i] else 0.0,
                "mean_slider_1s_before": float(sliders[window].mean()) if window.any()
                else None}
    return {"stop_lead_time": None, "mean_slider_1s_before": None}


def _mode_summary(m: dict[str, Any]) -> dict[str, Any]:
    violations = m["violations"]
    return {
        "min_separation": m["min_separation"],
        "protective_distance": m["protective_distance"],
        "time_reduced_speed": m["time_reduced_speed"],
        "time_min_speed": m["time_min_speed"],
        "time_by_mode": m["time_by_mode"],
        "violations": len(violations),
        "violation_time": float(sum(v["end"] - v["start"] for v in violations)),
        "violations_not_slowed_to_min": sum(not v["slowed_to_min"] for v in violations),
        "violation_intervals": violations,
        "effective_cycle_time": m["extra"]["progress"]["effective_cycle_time"],
        "stop_lead_time": m["extra"]["progress"]["stop_lead_time"],
        "mean_slider_1s_before": m["extra"]["progress"]["mean_slider_1s_before"],
        "cycle_times": m["cycle_times"],
        "loop_rate_hz": m["rate_hz"],
        "json": m["json"], "png": m["png"],
    }


def run_coexistence_demo(out_dir: str | Path, spec: str = "S1", duration: float | None = None,
                         compare_prediction: bool = True, robot_host: str | None = None, *,
                         cell: str = "paper_cell", playback_rate: float = 1.0,
                         robot_config: str | Path = ROBOT_CONFIG,
                         baseline_cycle_time: float | None = None, baseline_cycles: int = 1,
                         seed: int = 0, port_timeout: float = 60.0) -> dict[str, Any]:
    """Run the coexistence loop end to end and write its commissioning metrics.

    Parameters
    ----------
    out_dir : path
        Receives ``coexistence_<mode>.json/.png``, ``coexistence_summary.json`` and
        ``motions/``.
    spec : str
        LTL specification of the worker (a paper name such as ``"S1"`` or formula text).
    duration : float, optional
        Seconds per run; default the motion's duration at ``playback_rate`` + 0.5 s.
    compare_prediction : bool
        Run reactive and predictive SSM (else predictive only).
    robot_host : str, optional
        A URSim or real controller; default: start the simulated UR on 127.0.0.1.
    playback_rate : float
        Worker playback rate (1.0 = real time).
    robot_config : path
        Robot YAML (model, base pose, tool, trajectory of the simulated arm).
    baseline_cycle_time : float, optional
        Cycle time without a human (s); measured on the simulated controller otherwise.

    Returns
    -------
    dict
        ``success``, ``spec``, ``task_sequence``, ``motion_duration``, ``baseline``,
        ``runs`` (per mode: min separation, time at reduced/min speed, violations,
        effective cycle time, loop rate, file paths), ``comparison`` and ``wall_time``.
    """
    started = time.monotonic()
    if not (math.isfinite(playback_rate) and 0.05 <= playback_rate <= 5.0):
        raise ValueError(f"playback_rate must be in [0.05, 5], got {playback_rate}")
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be > 0 s, got {duration}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    node_params = {**node_parameters_from_robot_config(robot_config),
                   "robot_host": robot_host or "127.0.0.1"}
    summary: dict[str, Any] = {"spec": spec, "cell": cell, "robot_host": node_params[
        "robot_host"], "simulated_robot": robot_host is None, "playback_rate": playback_rate,
        "success": False, "error": ""}
    stack = contextlib.ExitStack()
    stack.callback(sys.setswitchinterval, sys.getswitchinterval())
    sys.setswitchinterval(CONTROL_SWITCH_INTERVAL)     # restored at the end
    sim: URSimHandle | None = None
    node_set: Bringup | None = None
    session: ClientSession | None = None
    try:
        if robot_host is None:
            stack.enter_context(rtde_port_lock(port_timeout))
            sim = start_sim_when_free(robot_config, port_timeout)
            stack.callback(sim.stop)
        node_set = Bringup(None, overrides={"store_dir": str(out / "motions"), "cell": cell})
        node_set.start()
        session = ClientSession("coexistence_demo_client")
        session.watch(SafetyStatus, "/safety_status", keep=1)
        t0 = time.monotonic()
        response = session.call(SynthesizeMotion, "/synthesize_motion", SynthesizeMotion.Request(
            spec=spec, cell=cell, seed=seed), timeout=600.0)
        summary["synthesis_wall_time"] = round(time.monotonic() - t0, 3)
        if not response.success:
            summary["error"] = f"synthesis failed: {response.error_message}"
            return summary
        motion_id, motion_duration = response.motion_ids[0], float(response.durations[0])
        summary.update(task_sequence=response.task_sequences[0],
                       motion_duration=motion_duration)
        if sim is not None and baseline_cycle_time is None:
            summary["baseline"] = _measure_baseline(sim, baseline_cycles)
        else:
            summary["baseline"] = {"cycle_time": baseline_cycle_time,
                                   "source": "given" if baseline_cycle_time else "unknown"}
        baseline = summary["baseline"]["cycle_time"]
        modes = ("reactive", "predictive") if compare_prediction else ("predictive",)
        runs: dict[str, Any] = {}
        for mode in modes:
            metrics = _run_mode(session, node_set.context, mode=mode, motion_id=motion_id,
                                motion_duration=motion_duration, playback_rate=playback_rate,
                                duration=duration, node_params=node_params, sim=sim,
                                baseline=baseline, out=out, human_ns="/human_1",
                                extra={"spec": spec, "cell": cell,
                                       "playback_rate": playback_rate})
            runs[mode] = _mode_summary(metrics)
        summary["runs"] = runs
        if len(runs) == 2:
            r, p = runs["reactive"], runs["predictive"]
            summary["comparison"] = {k: {"reactive": r[k], "predictive": p[k]} for k in (
                "min_separation", "time_reduced_speed", "time_min_speed", "violation_time",
                "stop_lead_time", "mean_slider_1s_before", "effective_cycle_time")}
        summary["success"] = True
        return summary
    finally:
        if session is not None:
            session.close()
        if node_set is not None:
            node_set.shutdown()
        stack.close()                             # stops the simulated UR, then unlocks
        summary["wall_time"] = round(time.monotonic() - started, 2)
        atomic_write_text(out / "coexistence_summary.json",
                          json.dumps(summary, indent=2, allow_nan=False, default=_json_default)
                          + "\n")


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")

