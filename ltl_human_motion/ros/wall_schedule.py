"""A periodic callback on an absolute wall schedule, on its own thread (no rclpy).

Tick ``k`` is due at ``t0 + k * period`` on ``time.monotonic()``: a late tick does not
delay the ones after it (no drift, unlike sleeping a period after the work). A tick that
starts one period or more late has missed its deadline; the slots it overran are skipped
(the stream keeps its phase instead of bursting to catch up) and counted.

On a loaded machine the thread's wake-up can wait for a CPU longer than a period. With
``priority`` > 0 the thread asks for the real-time policy ``SCHED_FIFO`` at that priority
(Linux; needs CAP_SYS_NICE or an ``rtprio`` limit, as ros2_control's real-time threads
do); when that is refused it keeps normal scheduling and says why in
:attr:`WallSchedule.priority_error`. A tick's work is short and the thread sleeps in
between, so the policy costs the rest of the machine little.
"""

from __future__ import annotations

import math
import os
import threading
import time
from collections.abc import Callable


class WallSchedule:
    """Call ``on_tick()`` every ``period`` seconds on a daemon thread.

    Parameters
    ----------
    period : float
        Seconds between ticks (> 0).
    on_tick : callable
        The work of one tick; exceptions go to ``on_error`` (the schedule keeps going).
    on_miss : callable, optional
        Called with ``(skipped, late)`` after a tick that was ``late`` seconds behind its
        slot and so skipped ``skipped`` >= 1 slots.
    on_error : callable, optional
        Called with the exception of a failed tick (default: re-raise, ending the thread).
    name : str
        Thread name.
    priority : int
        ``SCHED_FIFO`` priority of the thread (1-99); 0 keeps normal scheduling.
    """

    def __init__(self, period: float, on_tick: Callable[[], None], *,
                 on_miss: Callable[[int, float], None] | None = None,
                 on_error: Callable[[BaseException], None] | None = None,
                 name: str = "wall-schedule", priority: int = 0) -> None:
        self._check(period)
        self._period = float(period)
        self._on_tick, self._on_miss, self._on_error = on_tick, on_miss, on_error
        self._stop = threading.Event()
        self._reset = threading.Event()
        self._wake = threading.Event()
        self.ticks = 0
        self.missed = 0
        self.max_late = 0.0
        self.priority = int(priority)
        self.realtime = False
        self.priority_error = ""
        self._started = threading.Event()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()
        self._started.wait(timeout=5.0)

    @staticmethod
    def _check(period: float) -> None:
        if not (math.isfinite(period) and period > 0):
            raise ValueError(f"schedule period must be a positive number of seconds, "
                             f"got {period!r}")

    @property
    def period(self) -> float:
        return self._period

    def set_period(self, period: float) -> None:
        """Change the period; the new schedule starts one new period from now."""
        self._check(period)
        self._period = float(period)
        self._reset.set()
        self._wake.set()

    def _set_priority(self) -> None:
        if self.priority <= 0:
            return
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(self.priority))
            self.realtime = True
        except (AttributeError, OSError, ValueError) as exc:
            self.priority_error = (f"SCHED_FIFO priority {self.priority} refused "
                                   f"({type(exc).__name__}: {exc}); normal scheduling")

    def _run(self) -> None:
        self._set_priority()
        self._started.set()
        due = time.monotonic() + self._period
        while not self._stop.is_set():
            delay = due - time.monotonic()
            if delay > 0:
                self._wake.wait(delay)
                self._wake.clear()
                if self._stop.is_set():
                    break
                if self._reset.is_set():
                    self._reset.clear()
                    due = time.monotonic() + self._period
                    continue
                if due - time.monotonic() > 0:
                    continue
            late = time.monotonic() - due
            period = self._period
            if late >= period:
                skipped = int(late // period)
                due += skipped * period
                self.missed += skipped
                self.max_late = max(self.max_late, late)
                if self._on_miss is not None:
                    self._on_miss(skipped, late)
            try:
                self._on_tick()
            except Exception as exc:
                if self._on_error is None:
                    raise
                self._on_error(exc)
            self.ticks += 1
            due += period

    def stop(self, timeout: float = 2.0) -> None:
        """End the thread (after the running tick) and wait for it."""
        self._stop.set()
        self._wake.set()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout=timeout)


def realtime_process(priority: int) -> str:
    """Give every thread of this process ``SCHED_FIFO`` at ``priority`` (Linux).

    For a process that runs one time-critical stream and little else (the occupancy node
    alone): its stream thread needs the GIL after each wake-up, and a GIL holder at normal
    priority can lose its CPU to other processes while holding it. With all threads at
    the same real-time priority (threads started later inherit it) no other process
    preempts them. Returns "" on success, else why it was refused (nothing changed then).
    """
    if priority <= 0:
        return "priority 0: normal scheduling"
    try:
        tids = [int(t) for t in os.listdir("/proc/self/task")]
        param = os.sched_param(int(priority))
        os.sched_setscheduler(0, os.SCHED_FIFO, param)
        for tid in tids:
            try:
                os.sched_setscheduler(tid, os.SCHED_FIFO, param)
            except ProcessLookupError:
                pass                                  # a thread that ended meanwhile
    except (AttributeError, OSError, ValueError) as exc:
        return f"SCHED_FIFO priority {priority} refused ({type(exc).__name__}: {exc})"
    return ""
