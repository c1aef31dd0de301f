"""A periodic callback on an absolute wall schedule, on its own thread (no rclpy).

Tick ``k`` is due at ``t0 + k * period`` on ``time.monotonic()``: a late tick does not
delay the ones after it (no drift, unlike sleeping a period after the work). A tick that
starts one period or more late skips the slots it overran (the stream keeps its phase
instead of bursting to catch up).

Missed deadlines are counted as a subscriber expecting one message per period sees them
(issue 34): a tick that starts ``gap`` >= 1.5 periods after the previous one misses
``round(gap / period) - 1`` deadlines. Counting only the skipped slots hid the late
ticks: on a loaded machine (2 cores, ``stress-ng --cpu 2``) a 15 s stream had 236 gaps of
15 ms or more at a subscriber and 251 between the node's own ticks, while the skipped
slots were fewer and the old count rose by a few. :meth:`WallSchedule.record` keeps each
recent tick's slot and start time, the stream's own timing record.

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
from collections import deque
from collections.abc import Callable

import numpy as np

#: Ticks kept in :meth:`WallSchedule.record` (20 s at 100 Hz).
RECORD_TICKS = 2000


def missed_deadlines(gap: float, period: float) -> int:
    """Deadlines a subscriber expecting one message per ``period`` misses when two come
    ``gap`` seconds apart: ``round(gap / period) - 1`` from 1.5 periods on, else 0."""
    return max(int(gap / period + 0.5) - 1, 0)


class WallSchedule:
    """Call ``on_tick()`` every ``period`` seconds on a daemon thread.

    Parameters
    ----------
    period : float
        Seconds between ticks (> 0).
    on_tick : callable
        The work of one tick; exceptions go to ``on_error`` (the schedule keeps going).
    on_miss : callable, optional
        Called with ``(missed, late)`` before a tick that missed ``missed`` >= 1
        deadlines (see the module docstring); it started ``late`` seconds after its first
        due slot.
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
        #: Deadlines missed as a subscriber sees them (see the module docstring).
        self.missed = 0
        #: Slots without a tick.
        self.skipped = 0
        self.max_late = 0.0
        self._record: deque[tuple[float, float]] = deque(maxlen=RECORD_TICKS)
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

    def record(self) -> np.ndarray:
        """The recent ticks (at most :data:`RECORD_TICKS`), oldest first: array (n, 2) of
        the slot each tick ran for (its due time) and its start time, monotonic seconds."""
        return np.array(list(self._record), dtype=np.float64).reshape(-1, 2)

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
        previous: float | None = None
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
                    previous = None
                    continue
                if due - time.monotonic() > 0:
                    continue
            start = time.monotonic()
            late = start - due
            period = self._period
            skipped = int(late // period)
            due += skipped * period
            missed = 0 if previous is None else missed_deadlines(start - previous, period)
            previous = start
            self._record.append((due, start))
            self.skipped += skipped
            self.max_late = max(self.max_late, late)
            if missed:
                self.missed += missed
                if self._on_miss is not None:
                    self._on_miss(missed, late)
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
    this real-time priority (threads started later inherit it) no other process preempts
    them; threads already at a higher ``SCHED_FIFO`` priority (the stream's, one above:
    threads of equal FIFO priority do not preempt each other) keep theirs. Returns "" on
    success, else why it was refused (nothing changed then).
    """
    if priority <= 0:
        return "priority 0: normal scheduling"
    try:
        tids = [int(t) for t in os.listdir("/proc/self/task")]
        param = os.sched_param(int(priority))
        os.sched_setscheduler(0, os.SCHED_FIFO, param)
        for tid in tids:
            try:
                if os.sched_getscheduler(tid) == os.SCHED_FIFO \
                        and os.sched_getparam(tid).sched_priority >= priority:
                    continue                          # keep a thread that has more
                os.sched_setscheduler(tid, os.SCHED_FIFO, param)
            except ProcessLookupError:
                pass                                  # a thread that ended meanwhile
    except (AttributeError, OSError, ValueError) as exc:
        return f"SCHED_FIFO priority {priority} refused ({type(exc).__name__}: {exc})"
    return ""
