"""``ltl-human-motion coexist``: the human-robot coexistence loop end to end.

Starts the simulated UR (unless ``--robot-host``), the synthesis, worker and coexistence
nodes, synthesizes the worker's motion from an LTL spec, plays it next to the robot and
writes commissioning metrics (JSON + PNG) for a reactive and a predictive run, compared
with the robot's cycle time without a human. A thin layer over
:func:`ltl_human_motion.ros.coexistence_demo.run_coexistence_demo`.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

NAME = "coexist"
HELP = ("run the coexistence loop end to end (simulated UR or --robot-host, worker from an "
        "LTL spec, SSM node) and write commissioning metrics")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``coexist``."""
    parser.add_argument("--spec", default="S1",
                        help="worker's LTL spec: a paper name (S1..) or formula (default S1)")
    parser.add_argument("--cell", default="paper_cell",
                        help="cell name or YAML path (default paper_cell)")
    parser.add_argument("--out", type=Path, default=Path("out/coexist"),
                        help="output folder (default out/coexist)")
    parser.add_argument("--robot-host", default=None, metavar="IP",
                        help="URSim or a real UR controller (default: start the simulated "
                             "UR on 127.0.0.1:30004)")
    parser.add_argument("--robot-config", type=Path, default=None, metavar="YAML",
                        help="robot model, base pose and trajectory "
                             "(default config/ur_pick_place.yaml)")
    parser.add_argument("--duration", type=float, default=None,
                        help="seconds per run (default: the motion's duration)")
    parser.add_argument("--rate", type=float, default=1.0,
                        help="worker playback rate (default 1.0 = real time)")
    parser.add_argument("--baseline-cycle-time", type=float, default=None,
                        help="robot cycle time without a human (s); measured on the "
                             "simulated UR when omitted")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--compare-prediction", dest="compare", action="store_true",
                      default=True, help="run reactive and predictive SSM (default)")
    mode.add_argument("--predictive-only", dest="compare", action="store_false",
                      help="run predictive SSM only")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")


def _fmt(value: object, unit: str = "", digits: int = 2) -> str:
    return "n/a" if value is None else f"{value:.{digits}f}{unit}"


def run(args: argparse.Namespace) -> int:
    """Run the loop; prints a short summary; returns the exit code."""
    from ltl_human_motion.ros.coexistence_demo import ROBOT_CONFIG, run_coexistence_demo

    try:
        summary = run_coexistence_demo(
            args.out, spec=args.spec, duration=args.duration,
            compare_prediction=args.compare, robot_host=args.robot_host, cell=args.cell,
            playback_rate=args.rate, robot_config=args.robot_config or ROBOT_CONFIG,
            baseline_cycle_time=args.baseline_cycle_time)
    except (ValueError, TimeoutError, RuntimeError, OSError) as exc:
        print(f"coexist: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(summary, indent=2))
    if not summary["success"]:
        print(f"coexist: {summary['error']}", file=sys.stderr)
        return 1
    base = summary["baseline"].get("cycle_time")
    print(f"worker: {summary['spec']} -> {summary['task_sequence']} "
          f"({summary['motion_duration']:.1f} s of motion at rate {summary['playback_rate']:g})")
    print(f"robot: {summary['robot_host']}; cycle time without a human {_fmt(base, ' s')}")
    for mode, r in summary["runs"].items():
        print(f"{mode:>10}: min separation {_fmt(r['min_separation'], ' m')} "
              f"(S_p {r['protective_distance']:.2f} m), reduced speed "
              f"{r['time_reduced_speed']:.1f} s, at minimum {r['time_min_speed']:.1f} s, mean "
              f"slider {_fmt(r['mean_slider_1s_before'])} in the 1 s before S_p, effective "
              f"cycle {_fmt(r['effective_cycle_time'], ' s')}, loop "
              f"{_fmt(r['loop_rate_hz'], ' Hz', 1)}")
        for line in _breaches(r):
            print(f"{'':>12}{line}")
    print(f"metrics: {args.out}/coexistence_*.json, .png; total {summary['wall_time']:.0f} s")
    return 0


def _breaches(r: dict) -> list[str]:
    """The times the worker came closer than the protective separation distance S_p, in a
    commissioning engineer's words: when, how close, and what the robot did meanwhile."""
    sp = r["protective_distance"]
    intervals = r.get("violation_intervals") or []
    if not intervals:
        return [f"the worker never came closer than S_p = {sp:.2f} m"]
    out = [f"the worker was closer than S_p = {sp:.2f} m {len(intervals)} time(s), "
           f"{r['violation_time']:.1f} s in all:"]
    for v in intervals:
        if v["slowed_to_min"]:
            did = ("the robot stood still throughout (speed slider at its "
                   f"{v['max_slider']:.0%} minimum, which stands for stop: docs/robot.md)")
        else:
            did = (f"the robot was not stopped: it moved at up to {v['max_slider']:.0%} of "
                   "its programmed speed")
        out.append(f"  t = {v['start']:.1f}-{v['end']:.1f} s: down to "
                   f"{v['min_separation']:.2f} m from the arm; {did}")
    return out
