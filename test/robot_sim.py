"""Starting the simulated UR controller for tests: one at a time on 127.0.0.1:30004."""

from __future__ import annotations

from ltl_human_motion.robot import URSimHandle, start_ur_sim_process
from ltl_human_motion.robot.port_lock import wait_port_free

HOST = "127.0.0.1"


def start_sim(**kwargs: object) -> URSimHandle:
    """Wait (up to 60 s) until ports 30004 and 29999 are free, then start a simulator."""
    wait_port_free(HOST, 30004, timeout=60.0)
    wait_port_free(HOST, 29999, timeout=60.0)
    return start_ur_sim_process(host=HOST, **kwargs)  # type: ignore[arg-type]
