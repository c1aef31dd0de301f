"""ROS 2 layer of ltl_human_motion: a thin set of rclpy nodes over the core.

This package is the only place in ``ltl_human_motion`` that imports ``rclpy``. Modules:

* :mod:`~ltl_human_motion.ros.synthesis_node` -- the ``synthesize_motion`` service.
* :mod:`~ltl_human_motion.ros.skeleton_publisher` -- playback on TF, markers, task state.
* :mod:`~ltl_human_motion.ros.occupancy_node` -- the ``occupancy`` stream (+ prediction).
* :mod:`~ltl_human_motion.ros.bringup` -- the whole node set in one process, recording.
* :mod:`~ltl_human_motion.ros.playback`, :mod:`~ltl_human_motion.ros.motion_store` and
  :mod:`~ltl_human_motion.ros.bringup_config` are plain Python (no rclpy import), so
  launch files and tools can use them without a ROS context.

Importing this package itself imports nothing from ROS.
"""
