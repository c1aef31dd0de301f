"""Soak benchmark: the coexistence bringup under bad luck for ``--minutes`` (default 10).

The node set of config/bringup_coexistence.yaml runs in its own process
(``ltl-human-motion bringup``), the simulated UR5e in another (127.0.0.1:30004). This
process, a plain rclpy client over DDS, meanwhile:

* every ``--burst-period`` s sends 20 concurrent synthesis requests, a quarter of them
  malformed (bad syntax, absurd variants, bad options), and later counts the answers;
* publishes a second worker's occupancy (far from the arm, so the arm may run at full
  speed) at 50 Hz, and every ``--fault-period`` s injects one fault for 1 s, in turn:
  the stream stops (stale), stamps 30 s in the future, NaN capsules;
* every ``--sim-period`` s kills the simulated controller and starts it again;
* samples the bringup's RSS every 2 s.

It reports answered/sent, RSS over time (and its change after the first minute), the
slider during each fault (from ``/safety_status``: the highest slider after the fail-safe
took hold) and the time to the minimum slider: from the first faulty message, and for a
silent stream from the moment its data is stale (``stale_after`` of the config). Prints a
summary and writes ``bench/results/soak.json``. Not a test: ``python bench/soak.py
--minutes 3`` after ``. scripts/env.sh``. Takes the machine-wide lock of port 30004.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402

CONFIG = ROOT / "config" / "bringup_coexistence.yaml"
FAR = np.array([[[4.5, 2.5, 0.0], [4.5, 2.5, 1.6]]])      # ~5 m from the arm
REQUESTS_PER_BURST = 20
FAULTS = ("stale", "future", "nan")
#: The minimum slider within this long of a fault counts as a timely fail-safe (issue 17).
FAIL_SAFE_BOUND = 0.3


def _requests(burst: int) -> list[Any]:
    from ltl_human_motion.srv import SynthesizeMotion as S

    out = []
    for i in range(REQUESTS_PER_BURST):
        seed = burst * 100 + i
        kind = i % 8
        if kind == 0:
            out.append(S.Request(spec="grasp(O1) & (F", cell="paper_cell", seed=seed))
        elif kind == 1:
            out.append(S.Request(spec="S1", cell="paper_cell", variants=4294967295))
        elif kind == 2:
            out.append(S.Request(spec="S1", cell="paper_cell", options_json="{bad json"))
        elif kind == 3:
            out.append(S.Request(spec="X " * 300 + "grasp(O1)", cell="paper_cell"))
        else:
            out.append(S.Request(spec="S1" if kind % 2 else "S2", cell="paper_cell",
                                 seed=seed))
    return out


def _rss_mb(pid: int) -> float:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


class Soak:
    """The client side: requests, a second worker's occupancy, faults, observations."""

    def __init__(self, args: argparse.Namespace) -> None:
        from ltl_human_motion.msg import HumanOccupancy, SafetyStatus
        from ltl_human_motion.srv import SynthesizeMotion
        from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

        from ltl_human_motion.ros.client import ClientSession

        self.args = args
        self.session = ClientSession("soak_client")
        node = self.session.node
        deep = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                          reliability=ReliabilityPolicy.RELIABLE)
        self.client = node.create_client(SynthesizeMotion, "/synthesize_motion",
                                         qos_profile=deep)
        self.publisher = node.create_publisher(HumanOccupancy, "/human_9/occupancy", 10)
        self.status: list[tuple[float, float, str, bool]] = []   # t, slider, mode, connected
        self._status_lock = threading.Lock()
        node.create_subscription(SafetyStatus, "/safety_status", self._on_status, 50)
        self.clock = node.get_clock()
        self.futures: list[Any] = []
        self.lost = 0                          # requests pending when the bringup died
        self.mode = "good"

    def _on_status(self, msg: Any) -> None:
        with self._status_lock:
            self.status.append((time.monotonic(), float(msg.slider), msg.mode,
                                bool(msg.connected)))

    def publish_occupancy(self) -> None:
        from ltl_human_motion.ros.occupancy_cdr import encode_human_occupancy

        if self.mode == "stale":
            return
        offset = 30.0 if self.mode == "future" else 0.0
        segments = np.full_like(FAR, np.nan) if self.mode == "nan" else FAR
        ns = self.clock.now().nanoseconds + int(offset * 1e9)
        sec, nanosec = divmod(ns, 1_000_000_000)
        self.publisher.publish(encode_human_occupancy(sec, nanosec, "world", "9", ["torso"],
                                                      segments[None], np.array([0.2]),
                                                      np.zeros(1)))

    def burst(self, index: int) -> None:
        self.futures += [self.client.call_async(r) for r in _requests(index)]

    def statuses_since(self, t0: float, t1: float) -> list[tuple[float, float, str, bool]]:
        with self._status_lock:
            return [s for s in self.status if t0 <= s[0] <= t1]

    def close(self) -> None:
        self.session.close()


def _stale_after() -> float:
    """The coexistence node's ``stale_after`` (s) in CONFIG."""
    import yaml

    params = yaml.safe_load(CONFIG.read_text())["coexistence_node"]["ros__parameters"]
    return float(params["stale_after"])


def _fault_report(soak: Soak, kind: str, t0: float, t1: float, min_slider: float,
                  stale_after: float) -> dict[str, Any]:
    """The slider during one fault. A silent stream is a fault from ``stale_after`` s after
    its last sample (until then its data is fresh, and the arm may use it), so the time to
    fail-safe of "stale" counts from then; ``time_from_first_fault_s`` counts from the
    first faulty (or missing) message for every kind."""
    onset = t0 + (stale_after if kind == "stale" else 0.0)
    seen = soak.statuses_since(t0 - 0.5, t1)
    before = [s for s in seen if s[0] < t0]
    during = [s for s in seen if s[0] >= t0]
    # The fail-safe holds from the first status after which every status of the fault is
    # at the minimum (a brief minimum before, e.g. worker 1's stream pausing, is not it).
    held = None
    for s in reversed(during):
        if s[1] > min_slider + 1e-9:
            break
        held = s[0]
    reached = None if held is None else held - onset
    return {"fault": kind, "slider_before": before[-1][1] if before else None,
            "mode_before": before[-1][2] if before else None,
            "time_to_fail_safe_s": reached,
            "time_from_first_fault_s": None if held is None else held - t0,
            "statuses": len(during),
            "slider_max_during": max((s[1] for s in during), default=None),
            "modes": sorted({s[2] for s in during}),
            "within_bound": reached is not None and reached <= FAIL_SAFE_BOUND}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--burst-period", type=float, default=5.0)
    parser.add_argument("--fault-period", type=float, default=12.0)
    parser.add_argument("--sim-period", type=float, default=45.0)
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results" / "soak.json")
    args = parser.parse_args(argv)

    from ltl_human_motion.robot.ssm import SSMParameters
    from ltl_human_motion.ros.coexistence_demo import rtde_port_lock, start_sim_when_free

    min_slider = SSMParameters().min_slider
    stale_after = _stale_after()
    duration = 60.0 * args.minutes
    tmp = Path(tempfile.mkdtemp(prefix="lhm-soak-"))
    env = {**os.environ, "ROS_HOME": str(tmp)}
    with rtde_port_lock(timeout=300.0):
        sim = start_sim_when_free(timeout=60.0)
        def start_bringup() -> subprocess.Popen:
            return subprocess.Popen(
                [sys.executable, "-m", "ltl_human_motion", "bringup", str(CONFIG),
                 "--store-dir", str(tmp / "motions")], env=env, stdout=subprocess.DEVNULL,
                stderr=open(tmp / "bringup.log", "a"))

        bringup = start_bringup()
        crashes: list[dict[str, Any]] = []
        soak = Soak(args)
        rss: list[tuple[float, float]] = []
        faults: list[dict[str, Any]] = []
        sim_restarts: list[dict[str, Any]] = []
        sent = 0
        try:
            if not soak.client.wait_for_service(timeout_sec=120.0):
                raise SystemExit("the bringup's synthesis service never came up")
            start = time.monotonic()
            next_burst = next_fault = start + 5.0
            next_sim = start + args.sim_period
            next_rss = start
            fault_index = burst_index = 0
            fault_end: float | None = None
            fault_kind = ""
            while time.monotonic() - start < duration:
                now = time.monotonic()
                if bringup.poll() is not None:      # it died: say so, start it again
                    lost = sum(not f.done() for f in soak.futures)
                    crashes.append({"t": now - start, "exit_code": bringup.returncode,
                                    "requests_lost": lost,
                                    "log_tail": (tmp / "bringup.log").read_text(
                                        errors="replace").splitlines()[-3:]})
                    soak.lost += lost
                    soak.futures = [f for f in soak.futures if f.done()]
                    bringup = start_bringup()
                    soak.client.wait_for_service(timeout_sec=120.0)
                    continue
                soak.publish_occupancy()
                if now >= next_rss:
                    rss.append((now - start, _rss_mb(bringup.pid)))
                    next_rss += 2.0
                if now >= next_burst:
                    soak.burst(burst_index)
                    sent += REQUESTS_PER_BURST
                    burst_index += 1
                    next_burst += args.burst_period
                if fault_end is None and now >= next_fault:
                    fault_kind = FAULTS[fault_index % len(FAULTS)]
                    fault_index += 1
                    soak.mode = fault_kind
                    fault_start, fault_end = now, now + 1.0
                elif fault_end is not None and now >= fault_end:
                    soak.mode = "good"
                    faults.append(_fault_report(soak, fault_kind, fault_start, fault_end,
                                                min_slider, stale_after))
                    fault_end = None
                    next_fault = now + args.fault_period
                if now >= next_sim and fault_end is None:
                    t_kill = time.monotonic()
                    sim.kill()
                    time.sleep(1.0)
                    sim = start_sim_when_free(timeout=60.0)
                    seen = soak.statuses_since(t_kill, time.monotonic())
                    down = [s[0] - t_kill for s in seen if s[2] == "disconnected"]
                    sim_restarts.append({"t": t_kill - start,
                                         "time_to_disconnected_s": down[0] if down else None})
                    next_sim = time.monotonic() + args.sim_period
                time.sleep(0.02)
            # Answers still due: wait for them (bounded).
            end = time.monotonic() + 120.0
            while time.monotonic() < end and not all(f.done() for f in soak.futures):
                soak.publish_occupancy()
                time.sleep(0.05)
        finally:
            bringup.send_signal(signal.SIGINT)
            t_sigint = time.monotonic()
            try:
                bringup.wait(timeout=30.0)
            except subprocess.TimeoutExpired:
                bringup.kill()
            shutdown_s = time.monotonic() - t_sigint
            soak.close()
            sim.stop()
    answers = [f.result() for f in soak.futures if f.done()]
    busy = sum(a.error_message.startswith("busy") for a in answers)
    values = np.array([r for _, r in rss])
    settled = values[[t >= 60.0 for t, _ in rss]] if any(t >= 60.0 for t, _ in rss) else values
    result = {
        "benchmark": "soak", "machine": f"{platform.node()} ({os.cpu_count()} cores, shared)",
        "minutes": args.minutes, "sent": sent, "answered": len(answers),
        "answered_fraction": len(answers) / sent if sent else None,
        "succeeded": sum(a.success for a in answers), "busy": busy,
        "internal_errors": sum("internal error" in a.error_message for a in answers),
        "rss_mb": [[round(t, 1), round(r, 1)] for t, r in rss],
        "rss_after_1min_min_max_mb": [float(settled.min()), float(settled.max())]
        if settled.size else None,
        "rss_change_after_1min": float(settled.max() / settled.min() - 1.0)
        if settled.size else None,
        "lost_to_bringup_crashes": soak.lost, "bringup_crashes": crashes,
        "faults": faults, "sim_restarts": sim_restarts,
        "faults_within_bound": sum(f["within_bound"] for f in faults),
        "fail_safe_bound_s": FAIL_SAFE_BOUND, "stale_after_s": stale_after,
        "sigint_exit_s": shutdown_s, "bringup_exit_code": bringup.returncode,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(args.out, json.dumps(result, indent=1) + "\n")
    times = [f["time_to_fail_safe_s"] for f in faults if f["time_to_fail_safe_s"] is not None]
    print(f"soak {args.minutes:g} min (under load): answered {len(answers)}/{sent} "
          f"({busy} busy, {result['internal_errors']} internal errors, {soak.lost} lost in "
          f"{len(crashes)} bringup crashes); RSS after 1 min "
          f"{result['rss_after_1min_min_max_mb']} MB; faults at the minimum within "
          f"{FAIL_SAFE_BOUND} s: {result['faults_within_bound']}/{len(faults)} (time to "
          f"fail-safe max {max(times) if times else float('nan'):.3f} s); SIGINT exit "
          f"{shutdown_s:.2f} s; wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
