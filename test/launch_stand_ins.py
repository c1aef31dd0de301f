"""Running a ROS 2 launch file without ``launch``/``launch_ros`` (absent from the PyPI
wheels): recording stand-ins of the few classes our launch files use."""

from __future__ import annotations

import runpy
import sys
import types
from pathlib import Path
from typing import Any

import pytest
import yaml


class LaunchConfiguration:
    def __init__(self, name: str) -> None:
        self.name = name

    def perform(self, context: dict[str, str]) -> str:
        return context[self.name]


class OpaqueFunction:
    def __init__(self, function: Any) -> None:
        self.function = function


def launch_description(monkeypatch: pytest.MonkeyPatch, launch_file: Path) -> list:
    """``generate_launch_description()`` of ``launch_file`` with the stand-ins in place.

    Declared arguments come back as ``("arg", name, kwargs)`` tuples, ``Node`` actions as
    their keyword arguments, ``OpaqueFunction`` as :class:`OpaqueFunction`.
    """
    def module(name: str, **attrs: Any) -> None:
        mod = types.ModuleType(name)
        mod.__dict__.update(attrs)
        monkeypatch.setitem(sys.modules, name, mod)

    module("launch", LaunchDescription=list)
    module("launch.actions", OpaqueFunction=OpaqueFunction,
           DeclareLaunchArgument=lambda name, **kw: ("arg", name, kw))
    module("launch.substitutions", LaunchConfiguration=LaunchConfiguration)
    module("launch_ros")
    module("launch_ros.actions", Node=lambda **kw: kw)
    return runpy.run_path(str(launch_file))["generate_launch_description"]()


def launched_nodes(description: list, context: dict[str, str]) -> list[dict[str, Any]]:
    """Keyword arguments of every Node the description's OpaqueFunction creates, with the
    launch arguments of ``context`` and the declared defaults of the others."""
    defaults = {a[1]: a[2]["default_value"] for a in description if isinstance(a, tuple)}
    opaque = next(a for a in description if isinstance(a, OpaqueFunction))
    return opaque.function({**defaults, **context})


def launch_ros_command(node: dict[str, Any], folder: Path) -> list[str]:
    """The ``--ros-args`` a launch_ros ``Node`` with these keyword arguments puts on the
    command line of its process (launch_ros 0.19+ semantics, reproduced here because
    launch_ros itself cannot be installed):

    * ``name`` -> ``-r __node:=<name>``, ``namespace`` -> ``-r __ns:=/<namespace>``;
    * a ``str`` entry of ``parameters`` -> ``--params-file <path>``;
    * a ``dict`` entry -> a params file that launch_ros writes itself, under the node's
      full name when both name and namespace are given, else under ``/**``.
    """
    args = ["--ros-args", "-r", f"__node:={node['name']}"]
    namespace = node.get("namespace")
    if namespace:
        args += ["-r", f"__ns:=/{namespace.strip('/')}"]
    for i, entry in enumerate(node.get("parameters") or []):
        if isinstance(entry, dict):
            key = f"/{namespace.strip('/')}/{node['name']}" if namespace else "/**"
            path = folder / f"launch_params_{node['name']}_{i}.yaml"
            path.write_text(yaml.safe_dump({key: {"ros__parameters": entry}}))
            args += ["--params-file", str(path)]
        else:
            args += ["--params-file", str(entry)]
    return args
