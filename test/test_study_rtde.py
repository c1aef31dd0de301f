"""Offline SSM against the live loop: the real ``ur_rtde`` client and the simulated UR
controller over TCP, the worker's S1 motion played in real time (about 15 s).

Tolerances (the live loop runs on wall-clock time over sockets; the offline one on
simulated time):

* :data:`SEPARATION_TOL`: the live loop sees the worker's frame of its wall-clock time
  and the arm's last RTDE sample (the simulator publishes at 500 Hz), each up to a few ms
  late; at the worker's and arm's speeds (< 1.5 m/s together) that moves the minimum by
  at most a centimetre or two.
* :data:`TIME_TOL`: time spent at reduced speed or at the minimum: a decision switching
  a few control periods (8 ms each) earlier or later, plus late steps under load.
* :data:`RATIO_TOL`: the arm's progress (trajectory time over wall time).
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from robot_sim import HOST, start_sim

from ltl_human_motion.robot.coexistence import CoexistenceController, ur_rtde_factories
from ltl_human_motion.robot.kinematics import pose_from_xyz_rpy, ur_model
from ltl_human_motion.robot.metrics import DecisionRecorder, commissioning_metrics
from ltl_human_motion.robot.offline_ssm import run_offline_ssm
from ltl_human_motion.robot.sim.trajectory import load_robot_config
from ltl_human_motion.scene.occupancy import capsules_from_positions

pytest.importorskip("rtde_receive")

ROBOT = "config/ur_pick_place.yaml"
SEPARATION_TOL = 0.03     # m
TIME_TOL = 0.35           # s
RATIO_TOL = 0.03          # trajectory seconds per wall second


def test_offline_agrees_with_the_live_rtde_loop():
    from ltl_human_motion.planning import synthesize
    motion = synthesize("S1", "paper_cell", variants=1, seed=1)[0]
    cfg = load_robot_config(ROBOT)
    model = ur_model(cfg["model"]).with_tool(cfg["tool_length"], cfg["tool_radius"])
    base = pose_from_xyz_rpy(cfg["base_xyz"], cfg["base_rpy"])
    hseg, hrad = capsules_from_positions(motion.positions, 1.75)
    T = motion.n_frames
    sim = start_sim(model=cfg["model"], trajectory=ROBOT)
    try:
        recorder = DecisionRecorder()
        ctl = CoexistenceController(*ur_rtde_factories(HOST), model, base,
                                    on_decision=recorder)
        try:
            deadline = time.monotonic() + 15.0
            while not ctl.step().connected and time.monotonic() < deadline:
                time.sleep(0.01)
            ctl.update_occupancy(hseg[0], hrad, time.monotonic())
            ctl.step()                                   # full speed before the worker moves
            recorder.decisions.clear()
            before = sim.status()

            def feed(t: float) -> None:
                f = min(round(t * motion.fps), T - 1)
                ctl.update_occupancy(hseg[f], hrad, time.monotonic())

            ctl.run(rate=125.0, duration=motion.duration, before_step=feed)
            after = sim.status()
        finally:
            ctl.close()
    finally:
        sim.stop()
    live = recorder.decisions
    wall = live[-1].time - live[0].time
    m_live = commissioning_metrics(live)
    live_ratio = (after["trajectory_time"] - before["trajectory_time"]) / wall
    off = run_offline_ssm(motion.positions, motion.fps, cfg["trajectory"], model, base,
                          trajectory_start=float(before["trajectory_time"]))
    m_off = off.metrics
    print(f"live vs offline: min separation {m_live['min_separation']:.4f} / "
          f"{m_off['min_separation']:.4f} m, at minimum {m_live['time_min_speed']:.3f} / "
          f"{m_off['time_min_speed']:.3f} s, reduced {m_live['time_reduced_speed']:.3f} / "
          f"{m_off['time_reduced_speed']:.3f} s, progress {live_ratio:.4f} / "
          f"{m_off['throughput_ratio']:.4f}, loop {m_live['rate_hz']:.1f} Hz")
    assert m_live["rate_hz"] > 100, "the live loop fell far behind 125 Hz"
    assert m_off["min_separation"] == pytest.approx(m_live["min_separation"],
                                                    abs=SEPARATION_TOL)
    assert m_off["time_min_speed"] == pytest.approx(m_live["time_min_speed"], abs=TIME_TOL)
    assert m_off["time_reduced_speed"] == pytest.approx(m_live["time_reduced_speed"],
                                                        abs=TIME_TOL)
    assert m_off["throughput_ratio"] == pytest.approx(live_ratio, abs=RATIO_TOL)
    below_live = sum(v["end"] - v["start"] for v in m_live["violations"])
    assert m_off["time_below_sp"] == pytest.approx(below_live, abs=TIME_TOL)
    assert np.isfinite(m_off["effective_cycle_time"])
