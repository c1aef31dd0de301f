"""Robot coexistence: UR kinematics, a simulated UR controller speaking RTDE, human-robot
separation, ISO/TS 15066 speed and separation monitoring, and commissioning metrics.

Core package: no ROS imports. The simulated controller is the sub-package
:mod:`ltl_human_motion.robot.sim` (``ltl-human-motion ur-sim``); it runs in its own process
(:func:`start_ur_sim_process`) because the ``ur_rtde`` client holds the GIL while it
connects.
"""

from ltl_human_motion.kernel.rotations import (
    compact_axis_angle_from_matrix,
    matrix_from_compact_axis_angle,
)
from ltl_human_motion.robot.coexistence import (
    CoexistenceConfig,
    CoexistenceController,
    ControlDecision,
    IOLike,
    ReceiveLike,
    ur_rtde_factories,
)
from ltl_human_motion.robot.kinematics import (
    UR_MODELS,
    URModel,
    forward_kinematics,
    pose_from_xyz_rpy,
    robot_capsules,
    tcp_pose,
    ur_model,
)
from ltl_human_motion.robot.metrics import (
    DecisionRecorder,
    commissioning_metrics,
    plot_commissioning,
    write_commissioning_report,
)
from ltl_human_motion.robot.separation import (
    Separation,
    check_capsules,
    min_distance,
    pair_distances,
    segment_distances,
    separation,
    signed_distances,
)
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
from ltl_human_motion.robot.ssm import (
    SLIDER_MIN,
    SSMParameters,
    predictive_separation,
    slider_from_separation,
)

#: The name :func:`compact_axis_angle_from_matrix` had here before the rotations moved to
#: :mod:`ltl_human_motion.kernel.rotations` (kept for importers of the package).
axis_angle_from_matrix = compact_axis_angle_from_matrix

__all__ = [
    "SLIDER_MIN",
    "UR_MODELS",
    "CoexistenceConfig",
    "CoexistenceController",
    "ControlDecision",
    "ControllerServer",
    "DecisionRecorder",
    "IOLike",
    "JointTrajectory",
    "ReceiveLike",
    "SSMParameters",
    "Separation",
    "SimulatedUR",
    "URModel",
    "URSimConfig",
    "URSimHandle",
    "Waypoint",
    "build_controller",
    "check_capsules",
    "commissioning_metrics",
    "compact_axis_angle_from_matrix",
    "default_pick_and_place",
    "forward_kinematics",
    "load_robot_config",
    "matrix_from_compact_axis_angle",
    "min_distance",
    "pair_distances",
    "plot_commissioning",
    "pose_from_xyz_rpy",
    "predictive_separation",
    "robot_capsules",
    "run_ur_sim",
    "segment_distances",
    "separation",
    "signed_distances",
    "slider_from_separation",
    "start_ur_sim_process",
    "tcp_pose",
    "ur_model",
    "ur_rtde_factories",
    "write_commissioning_report",
]
