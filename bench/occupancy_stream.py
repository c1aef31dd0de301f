"""Benchmark: sustained HumanOccupancy rate, gaps and latency over DDS, per layout.

Layouts (``--layout``, default ``all``):

* ``single``: a publisher process runs one occupancy node (100 Hz, 1 s of prediction in
  0.1 s steps, as in config/bringup.yaml) playing a looped test motion (topic
  ``/bench_human/occupancy``).
* ``launch``: the node set of config/bringup.yaml as ``ros2 launch`` starts it, one
  process per node (synthesis node, skeleton publisher, occupancy node following
  ``task_state``), with the same command lines (``bringup_config.launch_parameters``).
  The synthesis node synthesizes the paper's S1 and the skeleton publisher loops it.
* ``bringup``: the same node set in one process (``ltl-human-motion bringup``).

This process subscribes (rclpy, SingleThreadedExecutor; ``SCHED_FIFO`` 10 where allowed,
as a controller that needs the stream on time runs; ``--subscriber-priority 0`` for
normal scheduling) and, for every message, takes the receive time and the header stamp
(both the system clock of this machine).
Latency = receive time - stamp; gap = time between two received messages.

    python bench/occupancy_stream.py [--layout all] [--duration 10] [--rate 100]

Prints the medians and p99 and writes bench/results/occupancy_stream.json (one entry per
layout, with the machine's load average). Targets: >= 99 Hz sustained and p99 gap
<= 15 ms in every layout (issue 14); p99 latency < 5 ms.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULT = ROOT / "bench" / "results" / "occupancy_stream.json"
TOPIC = "/bench_human/occupancy"
LAYOUT_TOPIC = "/human_1/occupancy"
LAYOUTS = ("single", "launch", "bringup")
CONFIG = ROOT / "config" / "bringup.yaml"
#: Issue 14's targets for every layout.
TARGET_RATE_HZ = 99.0
TARGET_GAP_P99_MS = 15.0


def run_publisher(args: argparse.Namespace) -> int:
    """The publisher process: one occupancy node with its own looped playback."""
    import rclpy

    from ltl_human_motion.planning.playback import Playback
    from ltl_human_motion.ros.common import now_seconds, spin_nodes
    from ltl_human_motion.ros.occupancy_node import OccupancyNode
    sys.path.insert(0, str(ROOT / "test"))   # the hand-made test motion (test/ros_fakes.py)
    from ros_fakes import make_test_motion

    rclpy.init(args=["--ros-args", "-r", "__ns:=/bench_human", "-p", f"rate:={args.rate}",
                     "-p", f"prediction_horizon:={args.horizon}", "-p", "marker_rate:=0.0"])
    playback = Playback()
    node = OccupancyNode(playback=playback)
    playback.play("bench", make_test_motion(duration=5.0), now_seconds(node), loop=True)
    try:
        spin_nodes([node], num_threads=4, timeout=args.duration + 10.0)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


def _node_command(spec: object, config: object, store_dir: str) -> list[str]:
    """The process ``ros2 launch`` starts for one node of the bringup file (same
    ``--ros-args`` as launch_ros builds from launch/bringup.launch.py)."""
    from ltl_human_motion.ros.launch_support.bringup_config import launch_parameters

    code = (f"import sys; from ltl_human_motion.ros.entry_points import {spec.executable} "
            f"as main; sys.exit(main(sys.argv))")
    args = [sys.executable, "-c", code, "--ros-args", "-r", f"__node:={spec.name}"]
    if spec.namespace:
        args += ["-r", f"__ns:=/{spec.namespace}"]
    for path in launch_parameters(config, spec, {"store_dir": store_dir}, folder=store_dir):
        args += ["--params-file", path]
    return args


def start_layout(layout: str, args: argparse.Namespace, store_dir: str
                 ) -> list[subprocess.Popen]:
    """Start the publishing processes of ``layout``."""
    env = {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    if layout == "single":
        return [subprocess.Popen(
            [sys.executable, str(Path(__file__).resolve()), "--publisher", "--duration",
             str(args.duration), "--rate", str(args.rate), "--horizon", str(args.horizon)],
            env=env)]
    if layout == "bringup":
        return [subprocess.Popen([sys.executable, "-m", "ltl_human_motion", "bringup",
                                  str(CONFIG), "--store-dir", store_dir], env=env)]
    from ltl_human_motion.ros.launch_support.bringup_config import load_bringup_config

    config = load_bringup_config(CONFIG)
    return [subprocess.Popen(_node_command(spec, config, store_dir), env=env)
            for spec in config.node_specs()]


def play_s1(timeout: float = 600.0) -> str:
    """Synthesize S1 on the running synthesis node and loop it on human 1; its id."""
    from ltl_human_motion.srv import PlayMotion, SynthesizeMotion

    from ltl_human_motion.ros.client import ClientSession

    with ClientSession("bench_client") as session:
        response = session.call(SynthesizeMotion, "/synthesize_motion",
                                SynthesizeMotion.Request(spec="S1", cell="paper_cell", seed=3),
                                timeout=timeout, resend_after=30.0)
        if not response.success:
            raise RuntimeError(f"S1 synthesis failed: {response.error_message}")
        played = session.call(PlayMotion, "/human_1/play_motion", PlayMotion.Request(
            command="play", motion_id=response.motion_ids[0], loop=True, rate=1.0),
            timeout=60.0, resend_after=5.0)
        if not played.success:
            raise RuntimeError(f"play_motion failed: {played.message}")
        return str(response.motion_ids[0])


def run_benchmark(args: argparse.Namespace, layout: str = "single") -> dict:
    """Start ``layout``'s processes, receive for ``duration`` s, compute the statistics."""
    import tempfile

    import rclpy
    from ltl_human_motion.msg import HumanOccupancy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    from ltl_human_motion.ros.common import STREAM_QOS

    store = tempfile.TemporaryDirectory(prefix="ltl_hm_bench_")
    processes = start_layout(layout, args, store.name)
    refused = ""
    if args.subscriber_priority > 0:
        from ltl_human_motion.ros.wall_schedule import realtime_process

        refused = realtime_process(args.subscriber_priority)
    topic = TOPIC if layout == "single" else LAYOUT_TOPIC
    load_start = os.getloadavg()
    context = Context()
    rclpy.init(context=context)
    node = Node("bench_subscriber", context=context)
    received: list[tuple[int, int, int]] = []     # (receive ns, stamp ns, bytes)

    def on_message(data: bytes) -> None:
        now = time.time_ns()
        sec, nanosec = struct.unpack_from("<iI", data, 4)
        received.append((now, sec * 1_000_000_000 + nanosec, len(data)))

    node.create_subscription(HumanOccupancy, topic, on_message, STREAM_QOS, raw=True)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    motion_id = ""
    try:
        if layout != "single":
            motion_id = play_s1()
        deadline = time.monotonic() + 30.0
        while not received and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1)
        if not received:
            raise RuntimeError("no occupancy message within 30 s (is the publisher up?)")
        warmup_end = time.monotonic() + args.warmup
        while time.monotonic() < warmup_end:
            executor.spin_once(timeout_sec=0.05)
        received.clear()
        end = time.monotonic() + args.duration
        while time.monotonic() < end:
            executor.spin_once(timeout_sec=0.05)
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        for proc in processes:
            proc.terminate()
        for proc in processes:
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        store.cleanup()
    data = np.array(received, dtype=np.int64)
    gaps_ms = np.diff(data[:, 0]) * 1e-6
    recv_s = (data[:, 0] - data[0, 0]) * 1e-9
    latency_ms = (data[:, 0] - data[:, 1]) * 1e-6
    periods_ms = np.diff(data[:, 1]) * 1e-6
    per_second = np.bincount(np.floor(recv_s).astype(int))[:int(args.duration)]
    return {
        "benchmark": "occupancy_stream",
        "layout": layout,
        "motion": motion_id or "test motion (5 s, looped)",
        "description": "HumanOccupancy between processes over Fast DDS on loopback",
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "host": {"machine": platform.machine(), "python": platform.python_version(),
                 "cpus": os.cpu_count(), "load_avg_1min_start": round(load_start[0], 2),
                 "load_avg_1min_end": round(os.getloadavg()[0], 2)},
        "settings": {"rate_hz": args.rate, "prediction_horizon_s": args.horizon,
                     "prediction_step_s": 0.1, "duration_s": args.duration,
                     "warmup_s": args.warmup, "rmw": os.environ.get("RMW_IMPLEMENTATION", ""),
                     "subscriber_sched_fifo": 0 if refused else args.subscriber_priority,
                     "discovery_range": "LOCALHOST"},
        "messages": len(data),
        "message_bytes": int(np.median(data[:, 2])),
        "sustained_rate_hz": round(len(data) / args.duration, 2),
        "rate_per_second_hz": {"median": float(np.median(per_second)),
                               "min": int(per_second.min())},
        "gap_ms": {"median": round(float(np.median(gaps_ms)), 3),
                   "p99": round(float(np.percentile(gaps_ms, 99)), 3),
                   "max": round(float(gaps_ms.max()), 3)},
        "stamp_period_ms": {"median": round(float(np.median(periods_ms)), 3),
                            "p99": round(float(np.percentile(periods_ms, 99)), 3),
                            "max": round(float(periods_ms.max()), 3)},
        "latency_ms": {"median": round(float(np.median(latency_ms)), 3),
                       "p90": round(float(np.percentile(latency_ms, 90)), 3),
                       "p99": round(float(np.percentile(latency_ms, 99)), 3),
                       "max": round(float(latency_ms.max()), 3)},
        "targets": {"rate_hz_min": TARGET_RATE_HZ, "gap_p99_ms_max": TARGET_GAP_P99_MS,
                    "latency_p99_ms_max": 5.0},
        "meets_targets": bool(len(data) / args.duration >= TARGET_RATE_HZ
                              and np.percentile(gaps_ms, 99) <= TARGET_GAP_P99_MS),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--layout", choices=(*LAYOUTS, "all"), default="all")
    parser.add_argument("--duration", type=float, default=10.0, help="seconds measured")
    parser.add_argument("--warmup", type=float, default=1.0, help="seconds ignored first")
    parser.add_argument("--rate", type=float, default=100.0, help="occupancy rate (Hz)")
    parser.add_argument("--horizon", type=float, default=1.0, help="prediction horizon (s)")
    parser.add_argument("--subscriber-priority", type=int, default=10,
                        help="SCHED_FIFO priority of this (receiving) process, as a robot "
                             "controller that needs the stream on time would run; 0 = normal")
    parser.add_argument("--publisher", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randint(100, 200)))
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    if args.publisher:
        return run_publisher(args)
    from ltl_human_motion.atomic import atomic_write_text

    layouts = LAYOUTS if args.layout == "all" else (args.layout,)
    results = {}
    for layout in layouts:
        result = results[layout] = run_benchmark(args, layout)
        lat, gap = result["latency_ms"], result["gap_ms"]
        print(f"[{layout}] occupancy stream ({result['message_bytes']} B/msg, "
              f"{result['messages']} msgs in {args.duration:g} s, load "
              f"{result['host']['load_avg_1min_start']:.1f}-"
              f"{result['host']['load_avg_1min_end']:.1f} on {result['host']['cpus']} CPUs): "
              f"sustained {result['sustained_rate_hz']:.1f} Hz (min per second "
              f"{result['rate_per_second_hz']['min']})")
        print(f"  gap median {gap['median']:.2f} ms, p99 {gap['p99']:.2f} ms, max "
              f"{gap['max']:.2f} ms; latency median {lat['median']:.3f} ms, "
              f"p99 {lat['p99']:.3f} ms; targets met: {result['meets_targets']}")
    previous = json.loads(RESULT.read_text()) if RESULT.is_file() else {}
    merged = previous.get("layouts", {}) if isinstance(previous, dict) else {}
    merged.update(results)
    atomic_write_text(RESULT, json.dumps({"benchmark": "occupancy_stream",
                                          "layouts": merged}, indent=2) + "\n")
    print(f"  wrote {RESULT.relative_to(ROOT)}")
    return 0 if all(r["meets_targets"] for r in results.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
