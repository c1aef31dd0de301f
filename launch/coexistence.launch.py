"""Launch the coexistence loop (full ROS 2 installs): synthesis, worker, coexistence node.

    ros2 launch ltl_human_motion coexistence.launch.py
    ros2 launch ltl_human_motion coexistence.launch.py robot_host:=192.168.1.10

The node set is the one of ``config/bringup_coexistence.yaml`` (or ``config:=``), built by
the same function as ``ltl-human-motion bringup config/bringup_coexistence.yaml``
(``ltl_human_motion.ros.bringup_config.node_specs``). ``robot_host:=`` overrides the
coexistence node's ``robot_host`` parameter (default: the file's, 127.0.0.1).
"""

from pathlib import Path


def _default_config() -> str:
    try:
        from ament_index_python.packages import get_package_share_directory

        return str(Path(get_package_share_directory("ltl_human_motion")) / "config"
                   / "bringup_coexistence.yaml")
    except (ImportError, LookupError):
        return str(Path(__file__).resolve().parents[1] / "config" / "bringup_coexistence.yaml")


def generate_launch_description():
    """The node set of ``config:=`` (default bringup_coexistence.yaml)."""
    from launch.actions import DeclareLaunchArgument, OpaqueFunction
    from launch.substitutions import LaunchConfiguration
    from launch_ros.actions import Node

    from launch import LaunchDescription
    from ltl_human_motion.ros.bringup_config import load_bringup_config

    def nodes(context):
        config = load_bringup_config(LaunchConfiguration("config").perform(context))
        host = LaunchConfiguration("robot_host").perform(context)
        out = []
        for spec in config.node_specs():
            extra = dict(spec.parameters)
            if spec.executable == "coexistence_node" and host:
                extra["robot_host"] = host
            out.append(Node(package="ltl_human_motion", executable=spec.executable,
                            name=spec.name, namespace=spec.namespace or None, output="screen",
                            emulate_tty=True,
                            parameters=[str(config.path), extra] if extra
                            else [str(config.path)]))
        return out

    return LaunchDescription([
        DeclareLaunchArgument("config", default_value=_default_config(),
                              description="bringup file (ROS 2 params layout)"),
        DeclareLaunchArgument("robot_host", default_value="",
                              description="robot controller address ('' = the file's)"),
        OpaqueFunction(function=nodes),
    ])
