"""Small pieces the nodes share: QoS profiles, clock seconds, cell lookup, spinning."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import rclpy
from rclpy.executors import (
    Executor,
    ExternalShutdownException,
    SingleThreadedExecutor,
)
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from ltl_human_motion.ros.executors import PoolExecutor, spin_once_tolerant

if TYPE_CHECKING:
    from ltl_human_motion.scene.cell import Cell

#: /tf as tf2_ros.TransformBroadcaster publishes it.
TF_QOS = QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST,
                    reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
#: /tf_static as tf2_ros.StaticTransformBroadcaster publishes it (latched).
TF_STATIC_QOS = QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST,
                           reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)
#: Latched state such as the motion catalog: a late subscriber gets the last message.
LATCHED_QOS = TF_STATIC_QOS
#: Streams (markers, task state, occupancy).
STREAM_QOS = QoSProfile(depth=10, history=HistoryPolicy.KEEP_LAST,
                        reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.VOLATILE)

DEFAULT_EXECUTOR_THREADS = 16


def now_seconds(node: Node) -> float:
    """The node clock (ROS time when use_sim_time is set) in seconds."""
    return node.get_clock().now().nanoseconds * 1e-9


def stamp_seconds(stamp: Any) -> float:
    """A builtin_interfaces/Time in seconds."""
    return stamp.sec + stamp.nanosec * 1e-9


def resolve_cell(cell: str) -> Cell:
    """:func:`ltl_human_motion.scene.cell_yaml.resolve_cell`, with shipped cells and YAML
    files loaded once per process (inline YAML is parsed on every call)."""
    from ltl_human_motion.scene.cell_yaml import looks_like_yaml
    from ltl_human_motion.scene.cell_yaml import resolve_cell as load

    return load(cell) if looks_like_yaml(cell) else _named_cell(cell.strip())


@lru_cache(maxsize=32)
def _named_cell(name: str) -> Cell:
    from ltl_human_motion.scene.cell_yaml import resolve_cell as load

    return load(name)


def spin_nodes(nodes: Sequence[Node], num_threads: int = DEFAULT_EXECUTOR_THREADS,
               context: Any = None, until: Callable[[], bool] | None = None,
               timeout: float | None = None) -> None:
    """Spin ``nodes`` in one :class:`~ltl_human_motion.ros.executors.PoolExecutor` until
    Ctrl-C, shutdown, ``until()`` or ``timeout`` seconds; always removes the nodes from the
    executor and shuts it down."""
    executor = PoolExecutor(num_threads=num_threads, context=context)
    for node in nodes:
        executor.add_node(node)
    stop_at = None if timeout is None else time.monotonic() + timeout
    try:
        while (context or rclpy.get_default_context()).ok():
            spin_once_tolerant(executor, 0.1)
            if until is not None and until():
                break
            if stop_at is not None and time.monotonic() >= stop_at:
                break
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except Exception:
        # Ctrl-C shuts the context down from rclpy's signal handler; a wait that was under
        # way then fails ("context is not valid"). Anything else is a real error.
        if (context or rclpy.get_default_context()).ok():
            raise
    finally:
        shutdown_executor(executor)


def shutdown_executor(executor: Executor, timeout: float = 5.0) -> None:
    """Remove the nodes and shut ``executor`` down after its queued callbacks ran.

    ``Executor.shutdown()`` destroys its guard condition before the callbacks queued on a
    MultiThreadedExecutor's pool have run (rclpy 9.1), and they then fail on it ("cannot
    use Destroyable"); so the pool is drained first.
    """
    pool = getattr(executor, "_executor", None)
    if pool is not None:
        pool.shutdown(wait=True)
    for node in list(executor.get_nodes()):
        executor.remove_node(node)
    executor.shutdown(timeout_sec=timeout)


class SpinThread:
    """Spin nodes on a background thread (for in-process use).

    ``num_threads`` > 1 uses a :class:`~ltl_human_motion.ros.executors.PoolExecutor`; 1 a
    SingleThreadedExecutor, which runs callbacks inline (best for many short callbacks,
    such as a recorder's). An entity destroyed while the executor waits does not end the
    thread (see :func:`~ltl_human_motion.ros.executors.spin_once_tolerant`).
    """

    def __init__(self, nodes: Sequence[Node], context: Any,
                 num_threads: int = DEFAULT_EXECUTOR_THREADS) -> None:
        self.context = context
        self.executor: Executor = (
            PoolExecutor(num_threads=num_threads, context=context) if num_threads > 1
            else SingleThreadedExecutor(context=context))
        for node in nodes:
            self.executor.add_node(node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, name="ltl-hm-executor", daemon=True)
        self._thread.start()

    def add_node(self, node: Node) -> None:
        self.executor.add_node(node)

    def _spin(self) -> None:
        try:
            while not self._stop.is_set() and self.context.ok():
                spin_once_tolerant(self.executor, 0.05)
        except ExternalShutdownException:
            pass

    def stop(self, timeout: float = 5.0) -> None:
        """Stop spinning, wait for the thread and the running callbacks."""
        self._stop.set()
        self._thread.join(timeout=timeout)
        shutdown_executor(self.executor, timeout)
