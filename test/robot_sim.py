"""Shared robot test helpers: the simulated UR controller (one at a time on
127.0.0.1:30004), a capsule worker and a feed-and-step loop. The fixtures are in conftest.py."""

from __future__ import annotations

import time

import numpy as np

from ltl_human_motion.robot import CoexistenceController, URSimHandle, start_ur_sim_process
from ltl_human_motion.robot.sim.port_lock import wait_port_free

HOST = "127.0.0.1"


def start_sim(**kwargs: object) -> URSimHandle:
    """Wait (up to 60 s) until ports 30004 and 29999 are free, then start a simulator."""
    wait_port_free(HOST, 30004, timeout=60.0)
    wait_port_free(HOST, 29999, timeout=60.0)
    return start_ur_sim_process(host=HOST, **kwargs)  # type: ignore[arg-type]


def human_at(x: float, y: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """A standing worker (legs, torso, head, one arm reaching towards -x) at (x, y):
    capsules (4, 2, 3) and radii (4,)."""
    segments = np.array([
        [[x, y, 0.1], [x, y, 0.9]],
        [[x, y, 0.9], [x, y, 1.5]],
        [[x, y, 1.6], [x, y, 1.75]],
        [[x, y, 1.4], [x - 0.5, y, 1.2]],
    ])
    return segments, np.array([0.15, 0.2, 0.12, 0.06])


def feed_and_step(ctl: CoexistenceController, occupancy: tuple[np.ndarray, np.ndarray],
                  steps: int = 5, period: float = 0.008) -> list:
    """Offer ``occupancy`` and run one control cycle, ``steps`` times; the decisions."""
    decisions = []
    for _ in range(steps):
        ctl.update_occupancy(*occupancy, stamp=time.monotonic())
        decisions.append(ctl.step())
        time.sleep(period)
    return decisions
