"""The demo's reactive stage end to end: real DDS (loopback) and real RTDE (ur_rtde).

The simulated UR5e of config/ur_react_r1.yaml runs in its own process; the coexistence
node drives it with the real ur_rtde client and publishes the joint state it reads; the
reactive player computes robot_in(R1) from it and the arm's capsules. The synthesis
service is called from a client node in its own context. No mocks of ROS or ur_rtde; the
simulated controller's port 30004 is taken under the machine-wide lock.
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("rclpy")
pytest.importorskip("rtde_receive")
pytest.importorskip("rtde_io")

from ltl_human_motion.ros.react_demo import run_react_demo

pytestmark = pytest.mark.ros


def test_worker_waits_at_the_bench_while_the_ur_works_in_r1_then_assembles(tmp_path: Path):
    summary = run_react_demo(tmp_path, timeout=60.0)
    assert summary["success"], summary["error"]
    tasks = [s["task"] for s in summary["steps"]]
    assert tasks[:3] == ["grasp(O1)", "walk(R1)", "wait(0.15)"]
    assert tasks[-1] == "assemble(R1)"
    wait = next(s for s in summary["steps"] if s["task"] == "wait(0.15)")
    assert wait["inputs"] == {"robot_in(R1)": True}       # the arm in R1, over RTDE and ROS
    assert wait.get("repeats", 1) > 1                     # the worker waited, step after step
    assert summary["steps"][-1]["inputs"] == {"robot_in(R1)": False}
    assert summary["waited_s"] > 0.0 and summary["reaction_s"] >= 0.0
    assert (tmp_path / "react_demo.json").is_file()
