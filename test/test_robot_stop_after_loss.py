"""Issue 34, item 2: stopping the coexistence node after the robot controller is gone.

After the controller died, SIGTERM to the bringup aborted the process (exit 134, no
report): a wrapper around the broken ``RTDEIOInterface`` was dropped at close, and
ur_rtde's destructor wrote to the closed socket ("write: Broken pipe", std::terminate).
A frozen controller (SIGSTOP: socket open, no answers) made the stop hang in ur_rtde's
disconnect. Real processes: the simulated controller, the bringup with the real ur_rtde
client, a SIGKILL or SIGSTOP of the controller and a SIGTERM of the bringup, in either
order and with delays; and a live controller, whose stop logs no loss.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from robot_sim import start_sim

pytest.importorskip("rclpy")
pytest.importorskip("rtde_io")

pytestmark = [pytest.mark.ros, pytest.mark.slow]

MIN_SLIDER = 0.01
BRINGUP = textwrap.dedent("""
    /**:
      ros__parameters:
        world_frame: world
        cell: paper_cell
    bringup:
      ros__parameters:
        nodes: [coexistence_node]
        humans: []
    coexistence_node:
      ros__parameters:
        robot_host: 127.0.0.1
        model: ur5e
        rate: 125.0
        min_slider: {min_slider}
        metrics_out: {out}
""")


def _wait_for(predicate, timeout: float, what: str) -> None:
    end = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < end, f"timed out waiting for {what}"
        time.sleep(0.1)


#: What happens to the controller around the SIGTERM: (action, seconds between them).
ORDERS = {"killed, stop 3 s later": ("kill", 3.0), "killed, stop at once": ("kill", 0.0),
          "stop, then killed": ("kill_after", 0.0), "frozen, stop at once": ("freeze", 0.0),
          "frozen, stop 1 s later": ("freeze", 1.0), "alive": ("none", 0.0)}


@pytest.mark.parametrize("order", list(ORDERS))
def test_bringup_stops_cleanly_whatever_the_order(tmp_path: Path, order: str) -> None:
    action, delay = ORDERS[order]
    out = tmp_path / "report"
    config = tmp_path / "bringup.yaml"
    config.write_text(BRINGUP.format(min_slider=MIN_SLIDER, out=out))
    sim = start_sim(initial_speed_slider=1.0)
    log = tmp_path / "bringup.log"
    proc = None
    try:
        with open(log, "wb") as fh:
            proc = subprocess.Popen([sys.executable, "-m", "ltl_human_motion", "bringup",
                                     str(config)], stdout=fh, stderr=subprocess.STDOUT,
                                    env=dict(os.environ, PYTHONUNBUFFERED="1"))
        # Connected and commanding: no occupancy, so the minimum reaches the controller.
        _wait_for(lambda: sim.status()["speed_slider"] == pytest.approx(MIN_SLIDER), 90.0,
                  "the node to command the minimum speed")
        _wait_for(lambda: "bringup: /coexistence_node" in log.read_text(errors="replace"),
                  30.0, "the end of start-up (a signal before it exits 130)")
        if action == "kill":
            sim.kill()                                   # controller switched off
        elif action == "freeze":
            os.kill(sim.process.pid, signal.SIGSTOP)     # hung: socket open, silent
        time.sleep(delay)
        proc.send_signal(signal.SIGTERM)
        if action == "kill_after":
            sim.kill()
        stopping = time.monotonic()
        rc = proc.wait(timeout=30.0)
        stop_seconds = time.monotonic() - stopping
    finally:
        if proc is not None and proc.poll() is None:
            proc.kill()
        if action == "freeze":
            sim.kill()
        sim.stop()
    text = log.read_text(errors="replace")
    assert rc == 0, text[-3000:]
    assert "terminate called" not in text and "Traceback" not in text, text[-3000:]
    assert stop_seconds < 15.0, f"the stop took {stop_seconds:.1f} s"
    report = json.loads((out / "coexistence.json").read_text())
    assert report
    assert (out / "coexistence.png").stat().st_size > 0
    lost = "robot connection lost before the stop" in text
    assert lost == (action in ("kill", "freeze")) or action == "kill_after", text[-3000:]
