"""Benchmark: sustained HumanOccupancy rate and publish-to-receive latency over DDS.

Two processes on loopback: a publisher process runs one occupancy node (100 Hz, 1 s of
prediction in 0.1 s steps, as in config/bringup.yaml) playing a looped test motion; this
process subscribes (rclpy, SingleThreadedExecutor) and, for every message, takes the
receive time and the header stamp (both the system clock of this machine). Latency =
receive time - stamp: publish, DDS over loopback and the subscriber's executor.

    python bench/occupancy_stream.py [--duration 10] [--rate 100] [--horizon 1.0]

Prints the medians and p99 and writes bench/results/occupancy_stream.json.
Targets: >= 100 Hz sustained, p99 latency < 5 ms.
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


def run_publisher(args: argparse.Namespace) -> int:
    """The publisher process: one occupancy node with its own looped playback."""
    import rclpy

    from ltl_human_motion.ros.common import now_seconds, spin_nodes
    from ltl_human_motion.ros.occupancy_node import OccupancyNode
    from ltl_human_motion.ros.playback import Playback
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


def run_benchmark(args: argparse.Namespace) -> dict:
    """Start the publisher process, receive for ``duration`` s, compute the statistics."""
    import rclpy
    from ltl_human_motion.msg import HumanOccupancy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    from ltl_human_motion.ros.common import STREAM_QOS

    env = {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    publisher = subprocess.Popen(
        [sys.executable, str(Path(__file__).resolve()), "--publisher", "--duration",
         str(args.duration), "--rate", str(args.rate), "--horizon", str(args.horizon)],
        env=env)
    context = Context()
    rclpy.init(context=context)
    node = Node("bench_subscriber", context=context)
    received: list[tuple[int, int, int]] = []     # (receive ns, stamp ns, bytes)

    def on_message(data: bytes) -> None:
        now = time.time_ns()
        sec, nanosec = struct.unpack_from("<iI", data, 4)
        received.append((now, sec * 1_000_000_000 + nanosec, len(data)))

    node.create_subscription(HumanOccupancy, TOPIC, on_message, STREAM_QOS, raw=True)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    try:
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
        publisher.terminate()
        publisher.wait(timeout=15)
    data = np.array(received, dtype=np.int64)
    recv_s = (data[:, 0] - data[0, 0]) * 1e-9
    latency_ms = (data[:, 0] - data[:, 1]) * 1e-6
    periods_ms = np.diff(data[:, 1]) * 1e-6
    per_second = np.bincount(np.floor(recv_s).astype(int))[:int(args.duration)]
    return {
        "benchmark": "occupancy_stream",
        "description": "HumanOccupancy between two processes over Fast DDS on loopback",
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "host": {"machine": platform.machine(), "python": platform.python_version(),
                 "cpus": os.cpu_count(), "load_avg_1min": os.getloadavg()[0]},
        "settings": {"rate_hz": args.rate, "prediction_horizon_s": args.horizon,
                     "prediction_step_s": 0.1, "duration_s": args.duration,
                     "warmup_s": args.warmup, "rmw": os.environ.get("RMW_IMPLEMENTATION", ""),
                     "discovery_range": "LOCALHOST"},
        "messages": len(data),
        "message_bytes": int(np.median(data[:, 2])),
        "sustained_rate_hz": round(len(data) / args.duration, 2),
        "rate_per_second_hz": {"median": float(np.median(per_second)),
                               "min": int(per_second.min())},
        "stamp_period_ms": {"median": round(float(np.median(periods_ms)), 3),
                            "p99": round(float(np.percentile(periods_ms, 99)), 3),
                            "max": round(float(periods_ms.max()), 3)},
        "latency_ms": {"median": round(float(np.median(latency_ms)), 3),
                       "p90": round(float(np.percentile(latency_ms, 90)), 3),
                       "p99": round(float(np.percentile(latency_ms, 99)), 3),
                       "max": round(float(latency_ms.max()), 3)},
        "targets": {"rate_hz_min": 100.0, "latency_p99_ms_max": 5.0},
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=10.0, help="seconds measured")
    parser.add_argument("--warmup", type=float, default=1.0, help="seconds ignored first")
    parser.add_argument("--rate", type=float, default=100.0, help="occupancy rate (Hz)")
    parser.add_argument("--horizon", type=float, default=1.0, help="prediction horizon (s)")
    parser.add_argument("--publisher", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randint(100, 200)))
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    if args.publisher:
        return run_publisher(args)
    result = run_benchmark(args)
    from ltl_human_motion.atomic import atomic_write_text

    atomic_write_text(RESULT, json.dumps(result, indent=2) + "\n")
    lat, per = result["latency_ms"], result["stamp_period_ms"]
    print(f"occupancy stream ({result['message_bytes']} B/msg, {result['messages']} msgs in "
          f"{args.duration:g} s): sustained {result['sustained_rate_hz']:.1f} Hz "
          f"(median per second {result['rate_per_second_hz']['median']:.0f}, min "
          f"{result['rate_per_second_hz']['min']})")
    print(f"  stamp period median {per['median']:.2f} ms, p99 {per['p99']:.2f} ms")
    print(f"  latency median {lat['median']:.3f} ms, p90 {lat['p90']:.3f} ms, "
          f"p99 {lat['p99']:.3f} ms, max {lat['max']:.3f} ms")
    print(f"  wrote {RESULT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
