"""The executor the nodes spin in (ros/executors.py), with real rclpy.

- A callback waiting in the pool's queue is handed to the pool once, not on every
  ``spin_once`` while a long callback holds the only pool thread (rclpy's own executor
  does, ros2/rclpy#1452, and its list of tracked tasks grows), and every queued callback
  still runs.
- Publishers destroyed while the executor waits do not end the spinning thread: a service
  call through the same node is still answered afterwards.
"""

from __future__ import annotations

import threading
import time

import pytest

rclpy = pytest.importorskip("rclpy")

from ltl_human_motion.srv import PlayMotion  # noqa: E402
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup  # noqa: E402
from rclpy.context import Context  # noqa: E402
from rclpy.executors import MultiThreadedExecutor  # noqa: E402
from rclpy.node import Node  # noqa: E402
from std_msgs.msg import String  # noqa: E402

from ltl_human_motion.ros.client import call_service  # noqa: E402
from ltl_human_motion.ros.common import SpinThread  # noqa: E402
from ltl_human_motion.ros.executors import PoolExecutor  # noqa: E402

pytestmark = pytest.mark.ros

BLOCK_SECONDS = 1.0
ROUNDS = 40


def _submissions_while_blocked(executor_type: type) -> tuple[int, int, int]:
    """Spin a node whose one pool thread is held by a long callback while a 200 Hz timer
    of another group queues behind it. Returns (tasks submitted to the pool more than once
    while they waited, the most entries the executor tracked at once, fast ticks run)."""
    context = Context()
    rclpy.init(context=context)
    node = Node("executor_probe", context=context)
    started, fast_ticks = threading.Event(), [0]

    def long_callback() -> None:
        started.set()
        time.sleep(BLOCK_SECONDS)                      # releases the GIL, holds the thread

    slow = node.create_timer(0.01, long_callback, callback_group=MutuallyExclusiveCallbackGroup())
    node.create_timer(0.005, lambda: fast_ticks.__setitem__(0, fast_ticks[0] + 1),
                      callback_group=MutuallyExclusiveCallbackGroup())
    executor = executor_type(num_threads=1, context=context)
    executor.add_node(node)
    submitted: dict[int, int] = {}
    alive: list = []                  # every task seen stays alive: its id is never reused
    pool_submit = executor._executor.submit

    def counting_submit(fn, *args):                    # the real pool, counted
        task = args[0] if args else fn
        alive.append(task)
        submitted[id(task)] = submitted.get(id(task), 0) + 1
        return pool_submit(fn, *args)

    executor._executor.submit = counting_submit
    most_tracked = 0
    try:
        end = time.monotonic() + BLOCK_SECONDS + 2.0
        while time.monotonic() < end and not (started.is_set() and fast_ticks[0] >= 5):
            executor.spin_once(timeout_sec=0.1)
            if started.is_set():
                slow.cancel()
            most_tracked = max(most_tracked, len(executor._futures))
        return sum(n > 1 for n in submitted.values()), most_tracked, fast_ticks[0]
    finally:
        executor.shutdown(timeout_sec=5.0)
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def test_a_queued_callback_is_submitted_once() -> None:
    stock_twice, stock_tracked, _ = _submissions_while_blocked(MultiThreadedExecutor)
    assert stock_twice > 0, "rclpy's executor resubmitted nothing: the case did not arise"
    twice, tracked, ticks = _submissions_while_blocked(PoolExecutor)
    assert twice == 0, f"{twice} task(s) submitted again while queued"
    assert tracked <= 3, (f"the executor tracked {tracked} entries at once "
                          f"(rclpy's MultiThreadedExecutor: {stock_tracked})")
    assert ticks >= 5, f"queued timer callbacks did not run after the block ({ticks})"


def test_publishers_destroyed_while_spinning_do_not_end_the_spin_thread() -> None:
    context = Context()
    rclpy.init(context=context)
    server = Node("executor_server", context=context)
    server.create_service(PlayMotion, "executor_probe_trigger",
                          lambda _req, res: setattr(res, "success", True) or res)
    client_node = Node("executor_client", context=context)
    client = client_node.create_client(PlayMotion, "executor_probe_trigger")
    client_node.create_timer(0.0005, lambda: None)     # wait sets built without pause
    spinner = SpinThread([server, client_node], context, num_threads=1)
    try:
        for _ in range(ROUNDS):              # seen to interrupt a few of 2000 waits here
            publishers = [client_node.create_publisher(String, f"executor_probe_{i}", 10)
                          for i in range(50)]
            time.sleep(0.01)                 # the executor waits on their event handlers
            for publisher in publishers:
                client_node.destroy_publisher(publisher)
        assert spinner._thread.is_alive(), "the spin thread died"
        assert call_service(client, PlayMotion.Request(command="stop"), timeout=10.0).success
    finally:
        spinner.stop()
        client_node.destroy_node()
        server.destroy_node()
        rclpy.try_shutdown(context=context)
