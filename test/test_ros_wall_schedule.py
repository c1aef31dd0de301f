"""The occupancy stream's wall schedule: absolute deadlines, missed ones counted."""

from __future__ import annotations

import threading
import time

import pytest

from ltl_human_motion.ros.wall_schedule import WallSchedule


def test_a_slow_tick_skips_and_counts_the_slots_it_overran() -> None:
    period, block = 0.01, 0.06
    ticks: list[float] = []
    misses: list[tuple[int, float]] = []
    done = threading.Event()

    def on_tick() -> None:
        ticks.append(time.monotonic())
        if len(ticks) == 3:
            time.sleep(block)
        if len(ticks) == 8:
            done.set()

    schedule = WallSchedule(period, on_tick, on_miss=lambda s, late: misses.append((s, late)))
    try:
        assert done.wait(10.0)
    finally:
        schedule.stop()
    # The tick after the slow one started >= block - period late: that many slots skipped.
    assert schedule.missed >= int((block - period) / period) - 1
    assert misses and misses[0][0] >= 1 and misses[0][1] >= period
    assert schedule.max_late >= period
    assert schedule.ticks >= 8


def test_errors_go_to_on_error_and_the_schedule_keeps_going() -> None:
    errors: list[BaseException] = []
    calls = threading.Semaphore(0)

    def on_tick() -> None:
        calls.release()
        raise RuntimeError("boom")

    schedule = WallSchedule(0.005, on_tick, on_error=errors.append)
    try:
        for _ in range(3):
            assert calls.acquire(timeout=10.0)
    finally:
        schedule.stop()
    assert len(errors) >= 2 and all(isinstance(e, RuntimeError) for e in errors)


def test_bad_periods_are_refused() -> None:
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="period"):
            WallSchedule(bad, lambda: None)
