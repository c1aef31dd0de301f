"""``ltl-human-motion bringup config/bringup.yaml``: the ROS 2 node set in one process.

Starts the nodes a bringup file lists (the same set and parameters as
``ros2 launch ltl_human_motion bringup.launch.py``) in one executor, until
Ctrl-C or ``--duration`` seconds; ``--record out/run.mcap`` writes their topics to an
MCAP file (rosbag2 layout) that is moved into place when the run ends.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ltl_human_motion.cli import interrupts
from ltl_human_motion.kernel.kept_alive import end_if_kept

NAME = "bringup"
HELP = "start the ROS 2 nodes of a bringup file in one process (optionally recording MCAP)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion bringup``."""
    parser.add_argument("config", nargs="?", type=Path, default=None,
                        help="bringup file (ROS 2 params layout; default config/bringup.yaml)")
    parser.add_argument("--record", type=Path, default=None, metavar="OUT.mcap",
                        help="record the node set's topics to this MCAP file")
    parser.add_argument("--duration", type=float, default=None, metavar="S",
                        help="stop after S seconds (default: run until Ctrl-C)")
    parser.add_argument("--store-dir", default=None, metavar="DIR",
                        help="override the store_dir parameter (folder of motion npz files)")
    parser.add_argument("--namespace", default="", metavar="NS",
                        type=_launch_value("namespace"),
                        help="run the node set under this namespace, as the launch argument "
                             "namespace:= (its catalog and marker topics move with it; TF, "
                             "/humans, /joint_states and /diagnostics stay global; default: "
                             "none)")
    parser.add_argument("--use-sim-time", default=None, metavar="true|false",
                        type=_launch_value("use_sim_time"),
                        help="every node on /clock (true) or the system clock (false), as "
                             "the launch argument use_sim_time:= (default: the file's)")


def _launch_value(argument: str) -> Callable[[str], Any]:
    """The argparse type of launch argument ``argument``: its text checked and converted as
    the launch files do (their ValueError is argparse's message)."""
    def convert(text: str) -> Any:
        from ltl_human_motion.ros.launch_support.bringup_config import check_namespace, launch_bool

        try:
            return check_namespace(text, "") if argument == "namespace" else launch_bool(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    return convert


class _StopSignals:
    """Ctrl-C and SIGTERM (e.g. from a process manager) while the node set starts and runs.

    A signal sets :attr:`requested` and stops a running node set through its stop event,
    not by raising KeyboardInterrupt: trimesh imports its optional parts under ``except
    BaseException`` and so swallows a KeyboardInterrupt raised meanwhile (seen: Ctrl-C
    during the bringup's start-up, and the process ran on). During start-up the signal
    also raises KeyboardInterrupt to cut a long start short; if that one is swallowed,
    :attr:`requested` still ends the run once start-up returns. A second Ctrl-C
    interrupts at once.
    """

    def __init__(self) -> None:
        self.requested = interrupts.interrupted()
        self.node_set: Any = None
        self._previous = {s: signal.signal(s, self._on_signal)
                          for s in (signal.SIGINT, signal.SIGTERM)}

    def _on_signal(self, signum: int, frame: Any) -> None:
        if self.requested and signum == signal.SIGINT:
            signal.default_int_handler(signum, frame)
        self.requested = True
        if self.node_set is not None:
            self.node_set.request_stop()
        else:
            raise KeyboardInterrupt

    def restore(self) -> None:
        for s, handler in self._previous.items():
            signal.signal(s, handler)


def run(args: argparse.Namespace) -> int:
    """Run the node set; prints a JSON summary of what was recorded."""
    if args.duration is not None and not args.duration > 0:
        print(f"ltl-human-motion bringup: error: --duration must be positive, got "
              f"{args.duration}", file=sys.stderr)
        return 2
    stop = _StopSignals()
    try:
        return _run(args, stop)
    finally:
        stop.restore()


def _run(args: argparse.Namespace, stop: _StopSignals) -> int:
    try:
        from ltl_human_motion.ros.bringup import Bringup
    except ImportError as exc:
        from ltl_human_motion.errors import MissingDependencyError

        raise MissingDependencyError(
            f"bringup needs rclpy and the built interfaces ({exc}); run scripts/setup.sh "
            f"and source scripts/env.sh") from None
    from ltl_human_motion.ros.entry_points import exit_without_final_collection
    from ltl_human_motion.ros.launch_support.bringup_config import load_bringup_config

    exit_without_final_collection()
    try:
        config = load_bringup_config(args.config)
    except (OSError, ValueError) as exc:           # missing, not a regular file, malformed
        print(f"ltl-human-motion bringup: error: {exc}", file=sys.stderr)
        return 2
    overrides = {"store_dir": str(args.store_dir)} if args.store_dir is not None else None
    node_set = Bringup(config, record=args.record, overrides=overrides,
                       namespace=args.namespace, use_sim_time=args.use_sim_time)
    stop.node_set = node_set
    if stop.requested:                       # a signal during start-up that was swallowed
        node_set.shutdown()
        raise KeyboardInterrupt
    names = ", ".join(n.get_fully_qualified_name() for n in node_set.nodes)
    print(f"bringup: {names}" + (f"; recording to {args.record}" if args.record else ""),
          file=sys.stderr)
    try:
        node_set.spin(args.duration)
    finally:
        path = node_set.shutdown()             # the recording is moved into place
    if path is not None:
        summary = {"mcap": str(path), "topics": node_set.recorder.summary()}
        print(json.dumps(summary, indent=2))
    return 0


def ros_entry_point(args: list[str] | None = None) -> int:
    """``ltl-human-motion bringup`` under another name (``ros2 run ltl_human_motion
    bringup``): the ROS arguments are dropped, the rest parsed as by the CLI. It lives in
    the CLI layer so that the ROS layer never imports the CLI."""
    import rclpy.utilities

    from ltl_human_motion.cli import main

    argv = sys.argv[1:] if args is None else list(args)
    code = main([NAME, *rclpy.utilities.remove_ros_args(argv)])
    end_if_kept(code)
    return code
