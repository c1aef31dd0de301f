"""Benchmark: the control-loop rate the ROS coexistence node actually achieves.

The node runs inside a one-process bringup, as in ``ltl-human-motion coexist``: a worker's
skeleton publisher (TF and markers at 30 Hz) and occupancy node (100 Hz, 1 s prediction =
11 samples of 23 capsules) share the process with the coexistence node (target 125 Hz),
which talks to the simulated UR (own process, 127.0.0.1:30004) through the REAL ur_rtde
client. The worker loops a test motion (``make_test_motion`` of test/ros_fakes.py)
so the occupancy stream never pauses. For the reactive and the predictive mode the
benchmark records every control step for ``--duration`` seconds and reports the achieved
rate, the step period (median, p99, max) and the share of late steps (period > 1.5 x
nominal), plus the RTDE round trip seen by a separate client.

Prints a table and writes ``bench/results/coexistence_loop.json``. Not a test: run
``python bench/coexistence_loop.py`` (after ``. scripts/env.sh``). Takes the machine-wide
lock of port 30004 (see ``coexistence_demo.rtde_port_lock``).
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402


def _periods(times: np.ndarray, rate: float) -> dict[str, float]:
    dt = np.diff(times)
    return {
        "steps": len(times),
        "rate_hz": float((len(times) - 1) / (times[-1] - times[0])),
        "period_median_ms": float(np.median(dt) * 1e3),
        "period_p99_ms": float(np.percentile(dt, 99) * 1e3),
        "period_max_ms": float(dt.max() * 1e3),
        "late_fraction": float(np.mean(dt > 1.5 / rate)),
    }


def run_mode(context: Any, session: Any, mode: str, duration: float, rate: float
             ) -> dict[str, Any]:
    """Run one coexistence node for ``duration`` s; return its loop statistics."""
    from rclpy.parameter import Parameter

    from ltl_human_motion.ros.client import wait_until
    from ltl_human_motion.ros.coexistence_node import CoexistenceNode
    from ltl_human_motion.ros.common import SpinThread

    node = CoexistenceNode(node_name=f"bench_{mode}", record=True, context=context,
                           parameter_overrides=[
                               Parameter("use_prediction", value=mode == "predictive"),
                               Parameter("rate", value=rate)])
    spinner = SpinThread([node], context, 2)
    try:
        wait_until(lambda: node.latest is not None and node.latest.connected
                   and node.latest.mode not in ("stale", "disconnected"), 15.0,
                   "the node to connect and receive occupancy")
        start = node.controller.clock()
        time.sleep(duration)
        end = node.controller.clock()
    finally:
        spinner.stop()
        node.stop_control()
    decisions = [d for d in node.recorder.decisions if start <= d.time <= end]
    node.destroy_node()
    times = np.array([d.time for d in decisions])
    modes = {m: int(sum(d.mode == m for d in decisions)) for m in {d.mode for d in decisions}}
    return {**_periods(times, rate), "modes": modes,
            "occupancy_messages": node.messages_received}


def run_separate_process(mode: str, duration: float, rate: float, out_dir: Path
                         ) -> dict[str, Any]:
    """Run the ``coexistence_node`` entry point in a process of its own (as ``ros2
    launch`` does) for ``duration`` s; its commissioning report (``metrics_out``, written
    on Ctrl-C) gives the achieved rate."""
    import json as _json
    import signal
    import subprocess

    folder = out_dir / mode
    code = ("import sys; from ltl_human_motion.ros.entry_points import coexistence_node; "
            "sys.exit(coexistence_node())")
    proc = subprocess.Popen(
        [sys.executable, "-c", code, "--ros-args", "-r", f"__node:=bench_proc_{mode}",
         "-p", f"use_prediction:={'true' if mode == 'predictive' else 'false'}",
         "-p", f"rate:={rate}", "-p", f"metrics_out:={folder}"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        time.sleep(duration + 3.0)                      # start-up, then the run
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(20.0)
    metrics = _json.loads((folder / "coexistence.json").read_text())
    steps = metrics["steps"]
    return {"steps": steps, "rate_hz": metrics["rate_hz"], "modes": metrics["time_by_mode"],
            "note": "whole run incl. connecting; rate from the node's own report"}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=10.0, help="seconds per mode")
    parser.add_argument("--rate", type=float, default=125.0, help="target loop rate (Hz)")
    parser.add_argument("--switch-interval", type=float, default=None, metavar="S",
                        help="sys.setswitchinterval for the process (default: the node's "
                             "CONTROL_SWITCH_INTERVAL, as its entry point and `coexist` "
                             "set it; Python's is 0.005)")
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results"
                        / "coexistence_loop.json")
    args = parser.parse_args(argv)
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from ltl_human_motion.ros.coexistence_node import CONTROL_SWITCH_INTERVAL
    sys.setswitchinterval(args.switch_interval if args.switch_interval is not None
                          else CONTROL_SWITCH_INTERVAL)

    import rtde_receive
    from ltl_human_motion.srv import PlayMotion, SynthesizeMotion

    from ltl_human_motion.ros.bringup import Bringup
    from ltl_human_motion.ros.client import ClientSession
    from ltl_human_motion.ros.coexistence_demo import rtde_port_lock, start_sim_when_free
    sys.path.insert(0, str(ROOT / "test"))   # the scripted synthesizer (test/ros_fakes.py)
    from ros_fakes import scripted_synthesize

    results: dict[str, Any] = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(),
                    "load_avg_1min": os.getloadavg()[0]},
        "target_rate_hz": args.rate, "duration_s": args.duration,
        "switch_interval_s": sys.getswitchinterval(),
        "setup": "one process: skeleton publisher (30 Hz) + occupancy node (100 Hz, 1 s "
                 "prediction) + coexistence node; simulated UR5e in its own process; "
                 "ur_rtde 1.6.5 over loopback. *_own_process: the coexistence node "
                 "started by its entry point in a separate process (as ros2 launch does)",
    }
    with rtde_port_lock():
        sim = start_sim_when_free()
        node_set = Bringup(None, synthesize_fn=functools.partial(scripted_synthesize,
                                                                 duration=10.0),
                           overrides={"store_dir": ""})
        session = None
        try:
            node_set.start()
            session = ClientSession("bench_client")
            response = session.call(SynthesizeMotion, "/synthesize_motion",
                                    SynthesizeMotion.Request(spec="grasp(O1)",
                                                             cell="paper_cell"))
            played = session.call(PlayMotion, "/human_1/play_motion", PlayMotion.Request(
                command="play", motion_id=response.motion_ids[0], loop=True, rate=1.0))
            assert played.success, played.message
            for mode in ("reactive", "predictive"):
                results[mode] = run_mode(node_set.context, session, mode, args.duration,
                                         args.rate)
            import tempfile

            with tempfile.TemporaryDirectory() as tmp:
                for mode in ("reactive", "predictive"):
                    results[f"{mode}_own_process"] = run_separate_process(
                        mode, args.duration, args.rate, Path(tmp))
            readback = rtde_receive.RTDEReceiveInterface("127.0.0.1")
            stamps = []
            t_end = time.monotonic() + 2.0
            while time.monotonic() < t_end:
                stamps.append(readback.getTimestamp())
                time.sleep(0.001)
            readback.disconnect()
            ts = np.unique(stamps)
            results["rtde_stream_rate_hz"] = float((len(ts) - 1) / (ts[-1] - ts[0]))
        finally:
            if session is not None:
                session.close()
            node_set.shutdown()
            sim.stop()
    results["machine"]["load_avg_1min_end"] = os.getloadavg()[0]
    print(f"{'mode':<11} {'rate Hz':>8} {'median ms':>10} {'p99 ms':>8} {'max ms':>8} "
          f"{'late %':>7}")
    for mode in ("reactive", "predictive"):
        r = results[mode]
        print(f"{mode:<11} {r['rate_hz']:8.1f} {r['period_median_ms']:10.2f} "
              f"{r['period_p99_ms']:8.2f} {r['period_max_ms']:8.1f} "
              f"{100 * r['late_fraction']:7.1f}")
    for mode in ("reactive", "predictive"):
        r = results[f"{mode}_own_process"]
        print(f"{mode + ' (own process)':<26} {r['rate_hz']:8.1f} Hz over {r['steps']} steps")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(args.out, json.dumps(results, indent=2) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
