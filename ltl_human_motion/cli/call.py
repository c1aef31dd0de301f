"""``ltl-human-motion call --spec S2 --cell paper_cell --play``: ask a running bringup.

Calls ``/synthesize_motion`` of a running ``ltl-human-motion bringup`` (or ``ros2 launch
ltl_human_motion bringup.launch.py``) from a client node of its own, prints one line per
motion (id, duration, task sequence) and, with ``--play``, starts the first motion on
``/human_<id>/play_motion`` (TF, markers, occupancy). Exit code 2 with a message if no
bringup answers within ``--wait`` seconds or the service refuses the request.
"""

from __future__ import annotations

import argparse
import json
import sys

NAME = "call"
HELP = "ask a running bringup for motions over ROS 2 (no ros2 command line needed)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion call``."""
    parser.add_argument("--spec", required=True,
                        help='LTL specification, e.g. "F grasp(O1)", or S1/S2')
    parser.add_argument("--cell", default="",
                        help="cell name (config/<name>.yaml) or path to a cell YAML file "
                             "(default: the bringup's default_cell)")
    parser.add_argument("--variants", type=int, default=1,
                        help="number of motions (default 1; the service allows up to 16)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--cycles", type=int, default=1,
                        help="passes through the accepting cycle (default 1; the service "
                             "allows up to 8)")
    parser.add_argument("--play", action="store_true",
                        help="start the first motion on the bringup's skeleton publisher")
    parser.add_argument("--human", default="1", metavar="ID",
                        help="with --play: the worker to play it on, /human_<ID> (default 1)")
    parser.add_argument("--loop", action="store_true", help="with --play: repeat the motion")
    parser.add_argument("--rate", type=float, default=1.0,
                        help="with --play: playback speed, 1.0 = real time (default 1.0)")
    parser.add_argument("--wait", type=float, default=10.0, metavar="S",
                        help="seconds to wait for a bringup to offer the service (default 10)")
    parser.add_argument("--timeout", type=float, default=600.0, metavar="S",
                        help="seconds to wait for the synthesis (default 600)")
    parser.add_argument("--json", action="store_true",
                        help="print the result as JSON instead of one line per motion")


def run(args: argparse.Namespace) -> int:
    """Call the service; print the motion ids and sequences (and what is played)."""
    problems = [msg for bad, msg in (
        (args.variants < 1, f"--variants must be >= 1, got {args.variants}"),
        (args.cycles < 1, f"--cycles must be >= 1, got {args.cycles}"),
        (not args.wait > 0, f"--wait must be positive, got {args.wait:g}"),
        (not args.timeout > 0, f"--timeout must be positive, got {args.timeout:g}"),
        (not 0 < args.rate <= 10, f"--rate must be in (0, 10], got {args.rate:g}")) if bad]
    if problems:
        print(f"ltl-human-motion {NAME}: error: {problems[0]}", file=sys.stderr)
        return 2
    try:
        from ltl_human_motion.ros.motion_client import SynthesisRequest, call_synthesis
    except ImportError as exc:
        from ltl_human_motion.errors import MissingDependencyError
        raise MissingDependencyError(
            f"call needs rclpy and the built interfaces ({exc}); run scripts/setup.sh and "
            f"source scripts/env.sh") from None
    result = call_synthesis(
        SynthesisRequest(spec=args.spec, cell=args.cell, variants=args.variants,
                         seed=args.seed, cycles=args.cycles),
        play=args.play, human_id=args.human, loop=args.loop, rate=args.rate, wait=args.wait,
        timeout=args.timeout)
    if args.json:
        print(json.dumps({"motion_ids": result.motion_ids, "sequences": result.sequences,
                          "durations": result.durations, "cycle_times": result.cycle_times,
                          "reba_max": result.reba_max, "rula_max": result.rula_max,
                          "wall_time": round(result.wall_time, 3), "played": result.played,
                          "strategy_id": result.strategy_id}, indent=1))
        return 0
    for i, (mid, seq, dur) in enumerate(zip(result.motion_ids, result.sequences,
                                            result.durations)):
        print(f"motion {i}: {mid}  ({dur:.1f} s): {seq}")
    if result.strategy_id:
        print(f"strategy: {result.strategy_id} over {result.sequences[0]} (a reactive "
              "specification: play it on a reactive player, docs/ros.md)")
    print(f"answered in {result.wall_time:.1f} s")
    if result.played:
        print(f"playing {result.played} on {result.player.rsplit('/', 1)[0]} "
              f"(rate {args.rate:g}{', looped' if args.loop else ''}): see /tf, /markers, "
              f"{result.player.rsplit('/', 1)[0]}/task_state")
    return 0
