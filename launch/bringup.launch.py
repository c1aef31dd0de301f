"""Launch the ltl_human_motion node set from a bringup file (full ROS 2 installs).

    ros2 launch ltl_human_motion bringup.launch.py
    ros2 launch ltl_human_motion bringup.launch.py config:=/path/to/bringup_two_humans.yaml

The node set comes from the same file and the same function as
``ltl-human-motion bringup`` (``ltl_human_motion.ros.bringup_config.node_specs``): the
synthesis node in the root namespace, one skeleton publisher and one occupancy node per
human in ``human_<id>``. Every node gets the file as its params file, plus ``human_id``.
Started as separate processes here, the occupancy node follows its skeleton publisher's
``task_state`` (in ``ltl-human-motion bringup`` they share one playback clock instead).
"""

from pathlib import Path


def _default_config() -> str:
    try:
        from ament_index_python.packages import get_package_share_directory

        return str(Path(get_package_share_directory("ltl_human_motion")) / "config"
                   / "bringup.yaml")
    except (ImportError, LookupError):
        return str(Path(__file__).resolve().parents[1] / "config" / "bringup.yaml")


def generate_launch_description():
    """The node set of the bringup file given as ``config:=`` (default bringup.yaml)."""
    from launch.actions import DeclareLaunchArgument, OpaqueFunction
    from launch.substitutions import LaunchConfiguration
    from launch_ros.actions import Node

    from launch import LaunchDescription
    from ltl_human_motion.ros.bringup_config import load_bringup_config

    def nodes(context):
        config = load_bringup_config(LaunchConfiguration("config").perform(context))
        return [
            Node(package="ltl_human_motion", executable=spec.executable, name=spec.name,
                 namespace=spec.namespace or None, output="screen", emulate_tty=True,
                 parameters=[str(config.path), spec.parameters] if spec.parameters
                 else [str(config.path)])
            for spec in config.node_specs()
        ]

    return LaunchDescription([
        DeclareLaunchArgument("config", default_value=_default_config(),
                              description="bringup file (ROS 2 params layout)"),
        OpaqueFunction(function=nodes),
    ])
