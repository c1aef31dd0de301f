"""The executor our nodes spin in, and a spin loop that outlives destroyed entities.

rclpy 9.1's ``MultiThreadedExecutor`` hands a callback to its thread pool and, until a pool
thread has started it, yields the same task again on every ``spin_once`` (ros2/rclpy#1452;
fixed upstream by ros2/rclpy#1547, after the 9.1.2 wheels this package pins). The spinning
thread then loops without waiting, holding the GIL most of the time, and the pool threads
that would start the task barely run: on a loaded machine a node stalls for seconds (a
service that no longer answers, a stream that misses hundreds of deadlines). Seen here: an
occupancy node and an ergonomics node each at 95 % CPU for 12 minutes, the stream thread
708 s late.

:class:`PoolExecutor` submits every task once and, when it is handed a task still waiting
in the pool's queue, sleeps :data:`QUEUED_TASK_BACKOFF` instead, which lets a pool thread
take the GIL and start it.

A publisher, subscription or client destroyed while an executor builds its wait set makes
that ``spin_once`` raise ``InvalidHandle`` ("destruction was requested"). The entity is gone
from the node by then, so the next ``spin_once`` is fine: :func:`spin_once_tolerant` goes
on instead of letting the spinning thread die (a client's thread that died leaves every
later service call unanswered).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

from rclpy.exceptions import InvalidHandle
from rclpy.executors import (
    ConditionReachedException,
    Executor,
    ExternalShutdownException,
    MultiThreadedExecutor,
    ShutdownException,
    TimeoutException,
)

#: Seconds the spinning thread sleeps when handed a task that is already queued (a GIL
#: hand-over takes a switch interval, 5 ms by default; 1 ms lets a waiting pool thread in
#: without delaying the next wait noticeably).
QUEUED_TASK_BACKOFF = 0.001


class PoolExecutor(MultiThreadedExecutor):
    """A ``MultiThreadedExecutor`` that submits each callback to its pool once.

    Parameters are those of ``MultiThreadedExecutor`` (``num_threads``, ``context``).
    """

    def __init__(self, num_threads: int | None = None, *, context: Any = None) -> None:
        super().__init__(num_threads=num_threads, context=context)
        self._queued: set[int] = set()
        self._queued_lock = threading.Lock()
        self.resubmissions_skipped = 0

    def _spin_once_impl(self, timeout_sec: Any = None,
                        wait_condition: Callable[[], bool] = lambda: False) -> None:
        try:
            handler, _entity, _node = self.wait_for_ready_callbacks(
                timeout_sec, None, wait_condition)
        except (ExternalShutdownException, ShutdownException, TimeoutException,
                ConditionReachedException):
            return
        key = id(handler)
        with self._queued_lock:
            queued = key in self._queued
            if not queued:
                self._queued.add(key)
        if queued:
            self.resubmissions_skipped += 1
            time.sleep(QUEUED_TASK_BACKOFF)
            return
        self._executor.submit(self._run, handler, key)
        self._futures.append(handler)
        for future in self._futures[:]:
            if future.done():
                self._futures.remove(future)
                future.result()                      # raise the callback's exception

    def _run(self, handler: Callable[[], Any], key: int) -> None:
        with self._queued_lock:
            self._queued.discard(key)
        handler()


def spin_once_tolerant(executor: Executor, timeout_sec: float) -> bool:
    """One ``spin_once``; False (instead of raising) when an entity destroyed meanwhile
    made the wait fail with ``InvalidHandle``."""
    try:
        executor.spin_once(timeout_sec=timeout_sec)
    except InvalidHandle:
        return False
    return True
