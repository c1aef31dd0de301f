"""``ros2 run`` / console-script entry points: one function per node (``bringup`` is the
CLI's, :func:`ltl_human_motion.cli.bringup.ros_entry_point`: the ROS layer imports no CLI).

Each node entry point follows ros2/examples: ``rclpy.init(args=args)`` (so ``--ros-args
-p name:=value --params-file f.yaml -r __ns:=/human_2`` work), spin in a
PoolExecutor (ros/executors.py), shut down cleanly on Ctrl-C, and return the exit code (2 for
invalid parameters, with the message on stderr). This module imports rclpy and the nodes only
inside the entry points, so a Ctrl-C while they load (about a second) also ends the process
quietly with exit code 0, as one while spinning does.
"""

from __future__ import annotations

import atexit
import functools
import gc
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from ltl_human_motion.kernel.kept_alive import end_if_kept

if TYPE_CHECKING:
    from rclpy.node import Node


@functools.cache
def exit_without_final_collection() -> None:
    """At interpreter exit, skip the collector's final pass over every object.

    That pass (``gc_collect_main`` during finalization) took 1-2 s for a synthesis node
    with its motion library on a loaded machine: most of its 2 s budget after SIGINT
    (issue 17). Everything that must outlive the process is written before (atomically);
    the objects are still freed as the modules are torn down. Registered once.
    """
    atexit.register(gc.freeze)


def quiet_on_interrupt(entry: Callable[..., int]) -> Callable[..., int]:
    """An entry point that returns 0 on Ctrl-C, wherever it comes (while the node's
    modules load, or before rclpy installs its own signal handler), with no traceback."""
    @functools.wraps(entry)
    def run(*args: object, **kwargs: object) -> int:
        try:
            code = entry(*args, **kwargs)
        except KeyboardInterrupt:
            code = 0
        end_if_kept(code)
        return code
    return run


def _run_node(factory: Callable[[], Node], args: list[str] | None,
              num_threads: int | None = None) -> int:
    import rclpy
    from rclpy.executors import ExternalShutdownException

    from ltl_human_motion.ros.common import DEFAULT_EXECUTOR_THREADS, spin_nodes
    from ltl_human_motion.ros.launch_support.middleware import apply_middleware_defaults

    exit_without_final_collection()
    apply_middleware_defaults()
    rclpy.init(args=args)
    node: Node | None = None
    try:
        node = factory()
        spin_nodes([node], num_threads=num_threads or DEFAULT_EXECUTOR_THREADS)
        return 0
    except (KeyboardInterrupt, ExternalShutdownException):
        return 0
    except Exception as exc:
        if not rclpy.ok():
            return 0        # Ctrl-C (rclpy's handler shut the context down) mid-construction
        if isinstance(exc, ValueError):
            print(f"error: {exc}", file=sys.stderr)
            return 2
        raise
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


#: Executor threads of a standalone occupancy node: its callbacks (task_state, markers,
#: parameter services) are short, and two threads let a marker message not delay them.
OCCUPANCY_EXECUTOR_THREADS = 2


@quiet_on_interrupt
def synthesis_node(args: list[str] | None = None) -> int:
    """Serve ``synthesize_motion``."""
    from ltl_human_motion.ros.synthesis_node import SynthesisNode

    return _run_node(SynthesisNode, args)


@quiet_on_interrupt
def skeleton_publisher(args: list[str] | None = None) -> int:
    """Play motions on TF, markers and ``task_state``."""
    from ltl_human_motion.ros.skeleton_publisher import SkeletonPublisher

    return _run_node(SkeletonPublisher, args)


@quiet_on_interrupt
def occupancy_node(args: list[str] | None = None) -> int:
    """Stream ``occupancy``, following the skeleton publisher's ``task_state``."""
    from ltl_human_motion.ros.occupancy_node import STREAM_SWITCH_INTERVAL, OccupancyNode
    from ltl_human_motion.ros.wall_schedule import realtime_process

    sys.setswitchinterval(STREAM_SWITCH_INTERVAL)    # the stream thread waits less for the GIL

    def make() -> OccupancyNode:
        node = OccupancyNode()
        # What exists now lives as long as the process: keep it out of the collector's
        # full passes, which hold the GIL (and so stall the stream) for their duration.
        gc.freeze()
        priority = node.get_parameter("stream_priority").value
        refused = realtime_process(priority) if priority > 0 else ""
        if refused:
            node.get_logger().info(f"process: {refused}; normal scheduling")
        elif priority > 0:
            node.get_logger().info(f"process: all threads SCHED_FIFO {priority}")
        return node

    # Few executor threads: each one that wakes competes with the stream thread for the
    # GIL, which CPython hands over without regard to thread priority.
    return _run_node(make, args, num_threads=OCCUPANCY_EXECUTOR_THREADS)


@quiet_on_interrupt
def ergonomics_node(args: list[str] | None = None) -> int:
    """Publish ``ergonomics`` (REBA/RULA now) during playback, following ``task_state``."""
    from ltl_human_motion.ros.ergonomics import ErgonomicsNode

    return _run_node(ErgonomicsNode, args)


@quiet_on_interrupt
def coexistence_node(args: list[str] | None = None) -> int:
    """Speed and separation monitoring of a UR arm (``robot_host``) against every human's
    ``occupancy``: reads the arm over RTDE, writes its speed slider."""
    from ltl_human_motion.ros.coexistence_node import CONTROL_SWITCH_INTERVAL, CoexistenceNode

    sys.setswitchinterval(CONTROL_SWITCH_INTERVAL)   # the 125 Hz loop waits less for the GIL
    return _run_node(CoexistenceNode, args)


@quiet_on_interrupt
def reactive_player(args: list[str] | None = None) -> int:
    """Play a reactive worker's strategy live (``play_motion`` with a strategy id, or the
    ``strategy_id`` parameter), reading the robot's events from their topics."""
    from ltl_human_motion.ros.reactive_player import ReactivePlayer

    return _run_node(ReactivePlayer, args)
