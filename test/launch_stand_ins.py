"""Running a ROS 2 launch file without ``launch``/``launch_ros`` (absent from the PyPI
wheels): recording stand-ins of the few classes our launch files use."""

from __future__ import annotations

import runpy
import sys
import types
from pathlib import Path
from typing import Any

import pytest


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
    """Keyword arguments of every Node the description's OpaqueFunction creates."""
    opaque = next(a for a in description if isinstance(a, OpaqueFunction))
    return opaque.function(context)
