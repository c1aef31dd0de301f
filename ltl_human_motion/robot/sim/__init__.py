"""The simulated UR controller that users run as ``ltl-human-motion ur-sim``.

It serves the real RTDE protocol (TCP 30004) and the dashboard (TCP 29999) on 127.0.0.1,
so the real ``ur_rtde`` client talks to it as to a robot:

- :mod:`.process`: run it in the foreground (:func:`run_ur_sim`) or in its own process
  (:func:`start_ur_sim_process`, a :class:`URSimHandle`);
- :mod:`.server`: the RTDE and dashboard servers; :mod:`.rtde_protocol`: the wire format;
- :mod:`.state`: the arm (trajectory execution, speed slider, safety);
  :mod:`.trajectory`: looping pick-and-place trajectories;
- :mod:`.port_lock`: one simulator at a time (``ur_rtde`` always connects to 30004).
"""

from ltl_human_motion.robot.sim.port_lock import RTDE_PORT, rtde_port_lock, wait_port_free
from ltl_human_motion.robot.sim.process import (
    URSimConfig,
    URSimHandle,
    build_controller,
    run_ur_sim,
    start_ur_sim_process,
)
from ltl_human_motion.robot.sim.server import ControllerServer
from ltl_human_motion.robot.sim.state import SimulatedUR
from ltl_human_motion.robot.sim.trajectory import (
    JointTrajectory,
    Waypoint,
    default_pick_and_place,
    load_robot_config,
)

__all__ = [
    "RTDE_PORT",
    "ControllerServer",
    "JointTrajectory",
    "SimulatedUR",
    "URSimConfig",
    "URSimHandle",
    "Waypoint",
    "build_controller",
    "default_pick_and_place",
    "load_robot_config",
    "rtde_port_lock",
    "run_ur_sim",
    "start_ur_sim_process",
    "wait_port_free",
]
