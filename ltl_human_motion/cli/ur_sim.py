"""``ltl-human-motion ur-sim``: a simulated UR controller speaking RTDE, in the foreground."""

from __future__ import annotations

import argparse
import logging
import signal
import sys

NAME = "ur-sim"
HELP = ("run a simulated UR e-Series controller (RTDE on TCP 30004, dashboard on 29999) "
        "looping a pick-and-place trajectory until Ctrl-C")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``ur-sim``."""
    parser.add_argument("--model", default=None, choices=["ur3e", "ur5e", "ur10e", "ur16e"],
                        help="arm model (default: the trajectory file's, else ur5e)")
    parser.add_argument("--trajectory", default=None, metavar="YAML",
                        help="robot/trajectory file, e.g. config/ur_pick_place.yaml "
                             "(default: built-in pick-and-place cycle)")
    parser.add_argument("--host", default="127.0.0.1", help="bind address (default loopback)")
    parser.add_argument("--rtde-port", type=int, default=30004,
                        help="RTDE port (default 30004, which ur_rtde clients always use)")
    parser.add_argument("--dashboard-port", type=int, default=29999,
                        help="dashboard port (default 29999; -1 disables the dashboard server)")
    parser.add_argument("--rate", type=float, default=500.0,
                        help="controller rate in Hz (default 500)")
    parser.add_argument("--speed-slider", type=float, default=1.0,
                        help="initial speed slider fraction in [0, 1] (default 1)")
    parser.add_argument("-v", "--verbose", action="store_true", help="log client activity")


def run(args: argparse.Namespace) -> int:
    """Serve until Ctrl-C; returns the exit code."""
    from ltl_human_motion.robot.sim.process import URSimConfig, run_ur_sim
    from ltl_human_motion.robot.sim.server import ControllerServer

    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(asctime)s %(name)s: %(message)s")
    if not 0.0 <= args.speed_slider <= 1.0:
        print(f"ur-sim: --speed-slider must be in [0, 1], got {args.speed_slider}",
              file=sys.stderr)
        return 2
    config = URSimConfig(args.model, args.trajectory, args.host, args.rtde_port,
                         args.dashboard_port, args.rate, args.speed_slider)
    def announce(server: ControllerServer) -> None:
        print(f"ur-sim: simulated {server.sim.model.name} on {args.host}: RTDE port "
              f"{server.rtde_port}, dashboard port {server.dashboard_port}; Ctrl-C to stop",
              flush=True)

    # Ctrl-C stops the server even when this process was started with SIGINT ignored
    # (a background job of a non-interactive shell inherits SIG_IGN).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        return run_ur_sim(config, announce)
    except OSError as exc:
        print(f"ur-sim: cannot serve on {args.host}: {exc}", file=sys.stderr)
        return 2
    except ValueError as exc:   # a malformed trajectory file or option
        print(f"ur-sim: {exc}", file=sys.stderr)
        return 2
