"""Benchmark: event-to-motion latency of the reactive worker in the live ROS loop
(issue 36, target: median <= 0.3 s, p99 <= 0.5 s).

The synthesis node and the worker's reactive player run in this process (one rclpy
context, as ``ReactiveStack``); the benchmark's client node, in its own context, calls the
synthesis service for the demo's specification
(:data:`~ltl_human_motion.tasks.reactive.DEMO_SPEC`) and publishes the UR's joint state on
``/joint_states`` at 50 Hz, stamped when published, as the coexistence node does with what
it reads over RTDE. Every message crosses DDS (loopback).

One sample: the arm is in R1 while the worker fetches O1 and walks to the bench, where it
waits; after a random 0.1-0.6 s of waiting the arm's joint state jumps out of R1 (the
event: the stamp of the first message showing it). The latency is from that stamp to the
stamp of the first ``task_state`` of the assembly, which the player publishes in the same
tick and with the same stamp as the first frame of the reaction on ``/tf`` (checked: the
frame with that stamp must be on /tf). The arm then goes back into R1 for the next sample.
The worker's motion plays at ``--rate`` (default 4x) so that samples come every few
seconds; the reaction path does not depend on it.

With ``--rtde-seconds`` (default 180; 0 skips it) it then measures the same latency with
the real robot loop for that long: the simulated UR5e of ``config/ur_react_r1.yaml`` (its
own process) driven by the coexistence node's real ur_rtde client, whose ``/joint_states``
the player reads (``RobotInR1Run``, the demo's stage); the arm leaves R1 once per cycle,
and each assembly that follows a wait at the bench is one sample: from the
``inputs_stamp`` of its first ``task_state`` (the stamp of the joint state that showed the
arm out of R1) to that message's stamp (the reaction's first frame on /tf).

Prints the numbers and writes ``bench/results/react_latency.json``. Not a test: run
``python bench/react_latency.py`` (after ``. scripts/env.sh``).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402


def measure(samples: int, rate: float, seed: int, timeout: float) -> dict:
    from ltl_human_motion.msg import TaskState
    from ltl_human_motion.srv import PlayMotion, SynthesizeMotion
    from tf2_msgs.msg import TFMessage

    from ltl_human_motion.ros.client import ClientSession, wait_until
    from ltl_human_motion.ros.common import stamp_seconds
    from ltl_human_motion.ros.react_demo import Q_IN, Q_OUT, JointStateStandIn, ReactiveStack
    from ltl_human_motion.tasks.reactive import DEMO_SPEC

    rng = random.Random(seed)
    store = tempfile.mkdtemp(prefix="react-latency-")
    stack = ReactiveStack(store, playback_rate=rate)
    session = ClientSession("react_latency_client")
    robot = JointStateStandIn(session.node, Q_IN)
    latencies: list[float] = []
    missing_tf = 0
    try:
        states = session.watch(TaskState, "/human_1/task_state", keep=200)
        tf = session.watch(TFMessage, "/tf", keep=200)
        t0 = time.monotonic()
        response = session.call(SynthesizeMotion, "/synthesize_motion",
                                SynthesizeMotion.Request(spec=DEMO_SPEC, cell="paper_cell"),
                                timeout=600.0, resend_after=60.0)
        if not response.success:
            raise RuntimeError(f"synthesis failed: {response.error_message}")
        synthesis = time.monotonic() - t0
        sid = response.strategy_id
        played = session.call(PlayMotion, "/human_1/play_motion",
                              PlayMotion.Request(command="play", motion_id=sid), timeout=30.0,
                              resend_after=5.0)
        if not played.success:
            raise RuntimeError(f"play_motion: {played.message}")

        def waiting() -> bool:
            m = states.last
            return m is not None and m.strategy_id == sid and m.current_task == "wait(0.15)" \
                and list(m.input_values) == [True]

        for _ in range(samples):
            wait_until(waiting, timeout, "the worker to wait at the bench with the arm in R1")
            time.sleep(rng.uniform(0.1, 0.6))
            robot.move(Q_OUT)
            wait_until(lambda: robot.changed is not None, 2.0, "the event's joint state")
            event = robot.changed

            def reaction(after: float) -> TaskState | None:
                return next((m for m in states.messages if m.strategy_id == sid
                             and m.current_task == "assemble(R1)"
                             and stamp_seconds(m.header.stamp) >= after), None)

            wait_until(lambda e=event: reaction(e) is not None, timeout, "the assembly")
            first = reaction(event)
            reacted = stamp_seconds(first.header.stamp)
            time.sleep(0.1)                       # the TF message of that tick
            on_tf = any(stamp_seconds(t.header.stamp) == reacted for m in tf.messages
                        for t in m.transforms if t.child_frame_id == "human_1/pelvis")
            missing_tf += not on_tf
            latencies.append(reacted - event)
            robot.move(Q_IN)
            print(f"sample {len(latencies)}: {1e3 * latencies[-1]:.1f} ms"
                  + ("" if on_tf else " (frame not seen on /tf)"), flush=True)
    finally:
        robot.close()
        session.close()
        stack.close()
    lat = np.array(latencies)
    return {**_summary(lat), "playback_rate": rate, "synthesis_seconds": synthesis,
            "mean_s": float(statistics.fmean(lat)), "frames_missing_on_tf": missing_tf,
            "target": {"median_s": 0.3, "p99_s": 0.5}}


def _summary(lat: np.ndarray) -> dict:
    return {"samples": len(lat), "median_s": float(np.median(lat)),
            "p99_s": float(np.percentile(lat, 99)), "max_s": float(lat.max()),
            "min_s": float(lat.min()), "latencies_s": [float(v) for v in lat],
            "met": bool(np.median(lat) <= 0.3 and np.percentile(lat, 99) <= 0.5)}


def measure_rtde(seconds: float, rate: float) -> dict:
    """Samples of the real robot loop (simulated UR over RTDE) during ``seconds``."""
    from ltl_human_motion.msg import TaskState

    from ltl_human_motion.ros.common import stamp_seconds
    from ltl_human_motion.ros.react_demo import REACT_ROBOT_CONFIG, RobotInR1Run
    from ltl_human_motion.tasks.reactive import DEMO_SPEC

    firsts: dict[int, TaskState] = {}
    with RobotInR1Run(tempfile.mkdtemp(prefix="react-latency-rtde-"), playback_rate=rate,
                      client_name="react_latency_rtde") as run:
        states = run.session.watch(TaskState, "/human_1/task_state", keep=300)
        response = run.synthesize(DEMO_SPEC)
        if not response.success:
            raise RuntimeError(f"synthesis failed: {response.error_message}")
        sid = response.strategy_id
        run.start_robot()
        if not run.play(sid).success:
            raise RuntimeError("play_motion failed")
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            time.sleep(1.0)
            for m in states.messages:
                if m.strategy_id == sid:
                    firsts.setdefault(m.strategy_step, m)
    lat = []
    for step, m in sorted(firsts.items()):
        before = firsts.get(step - 1)
        if m.current_task == "assemble(R1)" and before is not None \
                and before.current_task == "wait(0.15)":
            lat.append(stamp_seconds(m.header.stamp) - stamp_seconds(m.inputs_stamp))
    result = {"seconds": seconds, "playback_rate": rate,
              "robot": str(REACT_ROBOT_CONFIG.relative_to(ROOT)), "steps_seen": len(firsts)}
    if lat:
        result.update(_summary(np.array(lat)))
    else:
        result["samples"] = 0
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=40)
    parser.add_argument("--rate", type=float, default=4.0,
                        help="playback rate of the worker's motion (default 4)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=60.0,
                        help="seconds to wait for each stage of a sample (default 60)")
    parser.add_argument("--rtde-seconds", type=float, default=180.0,
                        help="seconds of the real robot loop over RTDE (default 180; 0 skips)")
    args = parser.parse_args()
    load_before = os.getloadavg()
    result = measure(args.samples, args.rate, args.seed, args.timeout)
    if args.rtde_seconds > 0:
        result["rtde"] = measure_rtde(args.rtde_seconds, args.rate)
    result["machine"] = {"cpus": os.cpu_count(), "load_before": load_before,
                         "load_after": os.getloadavg()}
    print(f"event-to-motion latency over {result['samples']} events: median "
          f"{1e3 * result['median_s']:.1f} ms, p99 {1e3 * result['p99_s']:.1f} ms, max "
          f"{1e3 * result['max_s']:.1f} ms (target: median <= 300 ms, p99 <= 500 ms: "
          f"{'met' if result['met'] else 'NOT met'}); frames not seen on /tf: "
          f"{result['frames_missing_on_tf']}")
    rtde = result.get("rtde")
    if rtde is not None:
        print(f"with the simulated UR over RTDE ({rtde['seconds']:.0f} s): "
              + (f"{rtde['samples']} events, median {1e3 * rtde['median_s']:.1f} ms, p99 "
                 f"{1e3 * rtde['p99_s']:.1f} ms, max {1e3 * rtde['max_s']:.1f} ms"
                 if rtde["samples"] else "no event (the worker never waited as the arm left)"))
    atomic_write_text(ROOT / "bench" / "results" / "react_latency.json",
                      json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
