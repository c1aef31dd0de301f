"""Launch the coexistence loop (full ROS 2 installs): synthesis, worker, coexistence node.

    ros2 launch ltl_human_motion coexistence.launch.py
    ros2 launch ltl_human_motion coexistence.launch.py robot_host:=192.168.1.10

The node set is the one of ``config/bringup_coexistence.yaml`` (or ``config:=``), built by
the same function as ``ltl-human-motion bringup config/bringup_coexistence.yaml``
(``ltl_human_motion.ros.launch_support.bringup_config.node_specs``). ``robot_host:=`` overrides the
coexistence node's ``robot_host``, ``store_dir:=`` the motion folder of the other nodes
(empty = the file's value; ``bringup_config.LAUNCH_ARGUMENTS["coexistence.launch"]``).
"""


def generate_launch_description():
    """The node set of ``config:=`` (default bringup_coexistence.yaml)."""
    from ltl_human_motion.ros.launch_support.launch_description import node_set_description

    return node_set_description("coexistence.launch", "bringup_coexistence.yaml")
