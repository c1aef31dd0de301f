"""A periodic callback on an absolute wall schedule, on its own thread (no rclpy).

Tick ``k`` is due at ``t0 + k * period`` on ``time.monotonic()``: a late tick does not
delay the ones after it (no drift, unlike sleeping a period after the work). A tick that
starts one period or more late has missed its deadline; the slots it overran are skipped
(the stream keeps its phase instead of bursting to catch up) and counted.
"""

from __future__ import annotations

import math
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
    """

    def __init__(self, period: float, on_tick: Callable[[], None], *,
                 on_miss: Callable[[int, float], None] | None = None,
                 on_error: Callable[[BaseException], None] | None = None,
                 name: str = "wall-schedule") -> None:
        self._check(period)
        self._period = float(period)
        self._on_tick, self._on_miss, self._on_error = on_tick, on_miss, on_error
        self._stop = threading.Event()
        self._reset = threading.Event()
        self._wake = threading.Event()
        self.ticks = 0
        self.missed = 0
        self.max_late = 0.0
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

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

    def _run(self) -> None:
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
