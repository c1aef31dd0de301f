"""What launch files, ``bringup`` and scripts need before any ROS context: plain Python,
no rclpy import.

* :mod:`.bringup_config` -- the node set of a bringup file, one source for ``bringup``
  and the launch files;
* :mod:`.launch_description` -- the launch description both launch files return
  (``launch``/``launch_ros`` imported only when called);
* :mod:`.middleware` -- loopback discovery and the Fast DDS profile
  (``ros/fastdds_profiles.xml``, installed with the ``ros`` package) set before a
  context starts.
"""
