"""CoexistenceController with the REAL ur_rtde client against the simulated controller.

No mocks of ur_rtde here: every test that claims RTDE behaviour starts the simulated
controller in its own process on 127.0.0.1:30004 (ur_rtde cannot use another port),
waiting until no other simulator holds that port (test/robot_sim.py).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from robot_sim import feed_and_step, human_at

from ltl_human_motion.robot import (
    CoexistenceConfig,
    CoexistenceController,
    DecisionRecorder,
    SSMParameters,
    URSimHandle,
    min_distance,
    slider_from_separation,
    ur_rtde_factories,
    write_commissioning_report,
)

rtde_receive = pytest.importorskip("rtde_receive")
pytest.importorskip("rtde_io")

HOST = "127.0.0.1"
PARAMS = SSMParameters()
MIN = PARAMS.min_slider


class FakeClock:
    def __init__(self) -> None:
        self.t = time.monotonic()

    def __call__(self) -> float:
        return self.t


@pytest.fixture
def controller(sim: URSimHandle) -> Iterator[CoexistenceController]:
    receive_factory, io_factory = ur_rtde_factories(HOST)
    config = CoexistenceConfig(stale_after=0.15, backoff_initial=0.02, backoff_max=0.2)
    ctl = CoexistenceController(receive_factory, io_factory, "ur5e", params=PARAMS,
                                config=config)
    yield ctl
    ctl.close()


def settle(receive: object, value: float, timeout: float = 2.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if abs(receive.getTargetSpeedFraction() - value) < 1e-9:
            return True
        time.sleep(0.005)
    return False


def test_speed_follows_separation(controller: CoexistenceController, receive: object) -> None:
    far = feed_and_step(controller, human_at(4.0))
    assert far[-1].mode == "full" and far[-1].slider == 1.0 and far[-1].connected
    assert settle(receive, 1.0)
    assert receive.getSpeedScaling() == pytest.approx(1.0)
    near = feed_and_step(controller, human_at(0.6))
    assert near[-1].mode == "stop" and near[-1].slider == MIN
    assert near[-1].separation <= PARAMS.protective_distance
    assert settle(receive, MIN)
    assert receive.getSpeedScaling() == pytest.approx(MIN)
    # Inside the band the command is the linear map of the separation.
    band = feed_and_step(controller, human_at(1.9), steps=10)
    reduced = [d for d in band if d.mode == "reduced"]
    assert reduced, [d.separation for d in band]
    for d in reduced:
        assert d.slider == pytest.approx(slider_from_separation(d.separation, PARAMS))
    assert settle(receive, band[-1].slider)


def test_stale_occupancy_commands_the_minimum(sim: URSimHandle, receive: object) -> None:
    clock = FakeClock()                               # injected: staleness is deterministic
    receive_factory, io_factory = ur_rtde_factories(HOST)
    ctl = CoexistenceController(receive_factory, io_factory, "ur5e", params=PARAMS,
                                config=CoexistenceConfig(stale_after=0.15), clock=clock)
    try:
        # The test is about staleness, so first wait (real time, bounded) for the RTDE
        # connection it assumes; the frozen clock moves on so that reconnection backoff
        # expires. On a loaded machine the first connection can take a while.
        deadline = time.monotonic() + 20.0
        while not ctl.connected and time.monotonic() < deadline:
            clock.t += 0.05
            ctl.step()
            time.sleep(0.02)
        assert ctl.connected, "no RTDE connection to the simulated controller within 20 s"
        assert ctl.step().mode == "stale"             # nothing received yet
        ctl.update_occupancy(*human_at(4.0), stamp=clock())
        assert ctl.step().mode == "full"
        assert settle(receive, 1.0)
        clock.t += 0.1
        assert ctl.step().mode == "full"              # 0.1 s old: still fresh
        clock.t += 0.1
        d = ctl.step()                                # 0.2 s old: stale
        assert d.mode == "stale" and d.slider == MIN and d.sent
        assert settle(receive, MIN)
        ctl.update_occupancy(*human_at(4.0))          # data returns (stamped on receipt)
        assert ctl.step().mode == "full"              # and it recovers by itself
        assert settle(receive, 1.0)
    finally:
        ctl.close()


def test_rejected_occupancy_never_raises_speed(controller: CoexistenceController,
                                               receive: object) -> None:
    feed_and_step(controller, human_at(0.6))
    assert settle(receive, MIN)
    segs, radii = human_at(4.0)
    bad_inputs = [
        (np.where(np.arange(12).reshape(4, 1, 3) == 5, np.nan, segs), radii),
        (segs, -radii),
        (segs[:, :1], radii),
        (segs + 1e6, radii),
        (segs, radii[:2]),
    ]
    for bad in bad_inputs:
        assert not controller.update_occupancy(*bad, stamp=time.monotonic())
        d = controller.step()
        assert d.slider == MIN
    assert controller.rejections == len(bad_inputs)
    nan_prediction = [(0.5, np.full_like(segs, np.nan), radii)]
    assert not controller.update_occupancy(segs, radii, time.monotonic(), nan_prediction)
    assert not controller.update_occupancy(segs, radii, time.monotonic(),
                                           [(-1.0, segs, radii)])
    assert controller.step().slider == MIN
    assert not controller.update_occupancy(segs, radii, stamp=math.inf)
    assert not controller.update_occupancy(segs, radii, stamp=time.monotonic() + 10.0)
    # A reduced command is a ceiling while only rejected data arrives, even though the
    # robot moves and the (still fresh) last valid occupancy would allow more.
    mid = feed_and_step(controller, human_at(1.9), steps=3)[-1]
    ceiling = mid.slider
    controller.update_occupancy(np.full((4, 2, 3), np.nan), radii, stamp=time.monotonic())
    for _ in range(15):
        d = controller.step()
        assert d.slider <= ceiling + 1e-12
        time.sleep(0.008)
    assert receive.getTargetSpeedFraction() <= ceiling + 1e-12
    assert feed_and_step(controller, human_at(4.0))[-1].slider == 1.0


def test_prediction_slows_down_earlier(controller: CoexistenceController) -> None:
    q = np.zeros(6)
    segs, radii = human_at(2.2)
    # The worker walks towards the robot at 1.2 m/s: predicted 0.5 s and 1 s ahead.
    step = np.array([0.6, 0.0, 0.0])
    predicted = [(0.5, segs - step, radii), (1.0, segs - 2 * step, radii)]
    now = time.monotonic()
    assert controller.update_occupancy(segs, radii, now, predicted)
    current, effective = controller.separations(q)
    assert effective < current
    rseg, rrad = controller.robot_capsules(q)
    expected = min(current, *(min_distance(s, r, rseg, rrad)
                              + PARAMS.prediction_discount_speed * h for h, s, r in predicted))
    assert effective == pytest.approx(expected, abs=1e-9)
    reactive = CoexistenceController(lambda: None, lambda: None, "ur5e", params=PARAMS,
                                     config=CoexistenceConfig(use_prediction=False))
    reactive.update_occupancy(segs, radii, now, predicted)
    assert reactive.separations(q) == (current, current)
    assert slider_from_separation(effective, PARAMS) < slider_from_separation(current, PARAMS)
    # Walking away: the prediction never raises the command above the reactive one.
    away = [(1.0, segs + np.array([1.0, 0, 0]), radii)]
    controller.update_occupancy(segs, radii, time.monotonic(), away)
    assert controller.separations(q)[1] == pytest.approx(current)


def test_control_loop_rate_and_commissioning_report(sim: URSimHandle,
                                                    controller: CoexistenceController,
                                                    tmp_path: Path) -> None:
    recorder = DecisionRecorder()
    controller.on_decision = recorder

    def walk(t: float) -> None:      # approach from 4 m to 0.6 m and back within 1.5 s
        x = 0.6 + 3.4 * abs(1.0 - t / 0.75)
        controller.update_occupancy(*human_at(x), stamp=time.monotonic())

    steps = controller.run(rate=125.0, duration=1.5, before_step=walk)
    assert steps >= 0.8 * 125 * 1.5
    times = np.array([d.time for d in recorder.decisions])
    assert np.median(np.diff(times)) == pytest.approx(1 / 125, rel=0.2)
    status = sim.status()
    json_path, png_path = write_commissioning_report(
        recorder.decisions, tmp_path, "run", status["cycle_times"],
        status["nominal_cycle_time"])
    metrics = json.loads(json_path.read_text())
    assert png_path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert metrics["steps"] == steps
    assert metrics["min_separation"] < PARAMS.protective_distance
    assert metrics["time_reduced_speed"] > 0.2
    assert metrics["time_by_mode"]["stop"] > 0
    assert all(v["slowed_to_min"] for v in metrics["violations"][1:])
    assert metrics["baseline_cycle_time"] == pytest.approx(6.2)
