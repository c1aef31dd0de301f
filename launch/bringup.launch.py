"""Launch the ltl_human_motion node set from a bringup file (full ROS 2 installs).

    ros2 launch ltl_human_motion bringup.launch.py
    ros2 launch ltl_human_motion bringup.launch.py config:=/path/to/bringup_two_humans.yaml
    ros2 launch ltl_human_motion bringup.launch.py store_dir:=/data/motions

The node set comes from the same file and the same function as
``ltl-human-motion bringup``
(``ltl_human_motion.ros.launch_support.bringup_config.node_specs``): the synthesis node
in the root namespace, one skeleton publisher and one occupancy node per human in
``human_<id>``. Every node gets the file as its params file, then one with
``human_id`` and the launch arguments (``bringup_config.LAUNCH_ARGUMENTS["bringup.launch"]``;
empty = the file's value), written so that they override the file.
Started as separate processes here, the occupancy node follows its skeleton publisher's
``task_state`` (in ``ltl-human-motion bringup`` they share one playback clock instead).
"""


def generate_launch_description():
    """The node set of the bringup file given as ``config:=`` (default bringup.yaml)."""
    from ltl_human_motion.ros.launch_support.launch_description import node_set_description

    return node_set_description("bringup.launch", "bringup.yaml")
