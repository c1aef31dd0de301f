"""The coexistence controller survives a controller crash: REAL ur_rtde client, simulated
controller in its own process on 127.0.0.1:30004 (killed, then restarted)."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest
from robot_sim import feed_and_step, human_at, start_sim

from ltl_human_motion.robot import (
    CoexistenceConfig,
    CoexistenceController,
    SSMParameters,
    URSimHandle,
    ur_rtde_factories,
)

pytest.importorskip("rtde_receive")
pytest.importorskip("rtde_io")

HOST = "127.0.0.1"
PARAMS = SSMParameters()
MIN = PARAMS.min_slider
#: Worker's x (m): beyond S_p (1.06 m) of every pose of the simulator's pick-and-place
#: cycle (at 1.9 m the home pose is 0.998 m away: "stop", and the test passed only when
#: the arm had left home before it connected).
FAR = 3.0


@pytest.fixture
def sim() -> Iterator[URSimHandle]:
    handle = start_sim()
    yield handle
    handle.stop()


def test_dropped_connection_goes_to_minimum_and_reconnects(sim: URSimHandle) -> None:
    receive_factory, io_factory = ur_rtde_factories(HOST)
    config = CoexistenceConfig(stale_after=0.5, backoff_initial=0.02, backoff_max=0.2)
    ctl = CoexistenceController(receive_factory, io_factory, "ur5e", params=PARAMS,
                                config=config)
    new_sim = None
    try:
        d = feed_and_step(ctl, human_at(FAR), steps=10)[-1]
        assert d.connected and d.mode in ("reduced", "full")
        sim.kill()                                        # controller crash / cable pulled
        # Detected when the socket closes or robot data freeze for robot_stale_after
        # (0.5 s): wait in real time (bounded), not a number of steps, which a loaded
        # machine stretches or squeezes.
        deadline = time.monotonic() + 5.0
        modes = [d.mode for d in feed_and_step(ctl, human_at(FAR), steps=40)]
        while modes[-1] != "disconnected" and time.monotonic() < deadline:
            modes = [d.mode for d in feed_and_step(ctl, human_at(FAR), steps=5)]
        assert modes[-1] == "disconnected"
        lost = [d for d in feed_and_step(ctl, human_at(FAR), steps=5)]
        assert all(x.slider == MIN and not x.connected for x in lost)
        new_sim = start_sim()                     # the controller comes back
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline:
            d = feed_and_step(ctl, human_at(FAR), steps=1)[0]
            if d.connected and d.mode != "disconnected":
                break
        assert d.connected and d.mode in ("reduced", "full"), d
        assert ctl.reconnects == 2
        time.sleep(0.05)
        d = feed_and_step(ctl, human_at(FAR), steps=1)[0]
        time.sleep(0.05)
        assert new_sim.status()["speed_slider"] == pytest.approx(d.slider, abs=0.05)
    finally:
        ctl.close()
        if new_sim is not None:
            new_sim.stop()
