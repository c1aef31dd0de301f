"""The launch description both launch files return (``launch``/``launch_ros`` imported
only when called, so this module imports without them).

Each node gets the bringup file as ``--params-file``, then a params file with its
per-node parameters (``human_id``) and the launch arguments of the file
(:data:`.bringup_config.LAUNCH_ARGUMENTS`), written so that they override the bringup
file (:func:`.bringup_config.launch_parameters`). ``namespace:=`` puts every node under a
namespace (:func:`.bringup_config.node_namespace`) and moves the node set's own topics
with it (:func:`.bringup_config.namespace_overrides`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ltl_human_motion.ros.launch_support.bringup_config import (
    LAUNCH_ARGUMENTS,
    launch_overrides,
    launch_parameters,
    load_bringup_config,
    namespace_overrides,
    node_namespace,
)


def default_config(file_name: str) -> str:
    """``config/<file_name>`` of the installed package, else of this source tree."""
    try:
        from ament_index_python.packages import get_package_share_directory

        return str(Path(get_package_share_directory("ltl_human_motion")) / "config"
                   / file_name)
    except (ImportError, LookupError):
        return str(Path(__file__).resolve().parents[3] / "config" / file_name)


def node_set_description(stem: str, config_file: str) -> Any:
    """A ``LaunchDescription``: ``config:=`` (default ``config/<config_file>``), the launch
    arguments of ``LAUNCH_ARGUMENTS[stem]`` and the node set of the bringup file."""
    from launch.actions import DeclareLaunchArgument, OpaqueFunction
    from launch.substitutions import LaunchConfiguration
    from launch_ros.actions import Node

    from launch import LaunchDescription

    arguments = LAUNCH_ARGUMENTS[stem]

    def nodes(context: Any) -> list[Any]:
        config = load_bringup_config(LaunchConfiguration("config").perform(context))
        values = {a.name: LaunchConfiguration(a.name).perform(context) for a in arguments}
        namespace = LaunchConfiguration("namespace").perform(context)
        return [
            Node(package="ltl_human_motion", executable=spec.executable, name=spec.name,
                 namespace=node_namespace(namespace, spec) or None, output="screen",
                 emulate_tty=True,
                 parameters=launch_parameters(config, spec, {
                     **namespace_overrides(config, spec, namespace),
                     **launch_overrides(arguments, values, spec)}))
            for spec in config.node_specs()
        ]

    return LaunchDescription([
        DeclareLaunchArgument("config", default_value=default_config(config_file),
                              description="bringup file (ROS 2 params layout)"),
        *[DeclareLaunchArgument(a.name, default_value="", description=a.description)
          for a in arguments],
        DeclareLaunchArgument("namespace", default_value="", description=(
            "put the node set under this namespace ('' = none); its catalog and marker "
            "topics move with it, TF, /humans/... and /diagnostics stay global")),
        OpaqueFunction(function=nodes),
    ])
