"""The occupancy stream's wall schedule: absolute deadlines, missed ones counted."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from ltl_human_motion.ros.wall_schedule import WallSchedule, missed_deadlines


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
    assert schedule.skipped >= int((block - period) / period) - 1
    assert any(missed >= 1 and late >= period for missed, late in misses), misses
    assert schedule.max_late >= period
    assert schedule.ticks >= 8


def test_missed_deadlines_are_the_gaps_a_subscriber_sees() -> None:
    """Issue 34: a tick 7 ms into its 10 ms slot skips nothing, but its message comes
    17 ms after the previous one: a subscriber misses a deadline, and so does the count."""
    period = 0.01
    assert [missed_deadlines(g, period) for g in (0.002, 0.01, 0.0149, 0.015, 0.017, 0.0249,
                                                  0.03, 0.061)] == [0, 0, 0, 1, 1, 1, 2, 5]


def test_the_count_and_the_record_agree_whatever_the_load() -> None:
    period = 0.01
    ticks: list[float] = []
    done = threading.Event()

    def on_tick() -> None:
        ticks.append(time.monotonic())
        if len(ticks) in (3, 7):
            time.sleep(0.017 if len(ticks) == 3 else 0.043)
        if len(ticks) == 12:
            done.set()

    schedule = WallSchedule(period, on_tick)
    try:
        assert done.wait(10.0)
    finally:
        schedule.stop()
    record = schedule.record()
    assert record.shape == (schedule.ticks, 2)
    steps = np.diff(record[:, 0]) / period                         # slots on the grid
    assert np.allclose(steps, np.round(steps), atol=1e-6) and np.all(steps > 0.5)
    assert np.all(record[:, 1] >= record[:, 0])                    # never early
    gaps = np.diff(record[:, 1])
    assert schedule.missed == sum(missed_deadlines(g, period) for g in gaps) >= 4
    assert schedule.skipped >= round(steps.sum()) - len(steps)     # + any before the first


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
