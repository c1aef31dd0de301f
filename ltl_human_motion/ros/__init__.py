"""ROS 2 layer of ltl_human_motion: a thin set of rclpy nodes over the core.

This package is the only place in ``ltl_human_motion`` that imports ``rclpy``. Modules:

* :mod:`~ltl_human_motion.ros.synthesis_node` -- the ``synthesize_motion`` service.
* :mod:`~ltl_human_motion.ros.skeleton_publisher` -- playback on TF, markers, task state.
* :mod:`~ltl_human_motion.ros.occupancy_node` -- the ``occupancy`` stream (+ prediction).
* :mod:`~ltl_human_motion.ros.bringup` -- the whole node set in one process, recording
  (:mod:`~ltl_human_motion.ros.recorder`, MCAP in rosbag2's layout).
* :mod:`~ltl_human_motion.ros.demo_loop` -- ``run_ros_demo``: bring-up, service call,
  playback and recording in one call; :mod:`~ltl_human_motion.ros.client` -- service calls
  with bounded waits and topic watchers (the hand-made test motions and the scripted
  synthesizer live in ``test/ros_fakes.py``, outside the package).
* :mod:`~ltl_human_motion.ros.hri` -- the REP 155 body interface;
  :mod:`~ltl_human_motion.ros.diagnostics` -- ``/diagnostics`` of the nodes;
  :mod:`~ltl_human_motion.ros.ur_frames` -- the arm's TF frames as ur_description has them.
* :mod:`~ltl_human_motion.ros.launch_support` -- plain Python (no rclpy import) for launch
  files and tools: the bringup file's node set, the launch description, middleware
  defaults. The playback clock and the motion store the nodes share are core modules
  (:mod:`~ltl_human_motion.planning.playback`, :mod:`~ltl_human_motion.planning.motion_store`).
* Plain-Python support of the nodes: :mod:`~ltl_human_motion.ros.occupancy_cdr` (the
  HumanOccupancy wire format), :mod:`~ltl_human_motion.ros.msgdefs` (message definitions
  for the recorder), :mod:`~ltl_human_motion.ros.wall_schedule` (the stream thread's clock).

Importing this package itself imports nothing from ROS.
"""
