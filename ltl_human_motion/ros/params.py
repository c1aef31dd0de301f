"""Declare node parameters with defaults and validate every change in one place.

Each node lists its parameters as :class:`ParamSpec` entries; :func:`declare_parameters`
declares them (with a description), checks the initial values (a bad value in a params
file stops the node with a clear message) and registers an on-set-parameters callback
that rejects bad values later (``ros2 param set``) with the same message.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

Check = Callable[[Any], str | None]


@dataclass(frozen=True)
class ParamSpec:
    """One parameter: name, default (its type is the parameter's type), description."""

    name: str
    default: Any
    description: str
    check: Check | None = None
    read_only: bool = False
    dynamic_typing: bool = False


def declare_parameters(node: Node, specs: Sequence[ParamSpec]) -> None:
    """Declare ``specs`` on ``node``, validate initial values, keep validating changes.

    Raises
    ------
    ValueError
        If an initial value (from a params file or overrides) is invalid.
    """
    by_name = {spec.name: spec for spec in specs}
    for spec in specs:
        node.declare_parameter(spec.name, spec.default, ParameterDescriptor(
            description=spec.description, read_only=spec.read_only,
            dynamic_typing=spec.dynamic_typing))
    errors = [msg for spec in specs
              if (msg := _error(spec, node.get_parameter(spec.name).value))]
    if errors:
        raise ValueError(f"{node.get_fully_qualified_name()}: invalid parameters: "
                         + "; ".join(errors))

    def on_set(params: list[Parameter]) -> SetParametersResult:
        problems = [msg for p in params if p.name in by_name
                    and (msg := _error(by_name[p.name], p.value))]
        return SetParametersResult(successful=not problems, reason="; ".join(problems))

    node.add_on_set_parameters_callback(on_set)


def _error(spec: ParamSpec, value: Any) -> str | None:
    if spec.check is None:
        return None
    msg = spec.check(value)
    return f"{spec.name}: {msg}" if msg else None


def positive(value: Any) -> str | None:
    """Check: a finite number > 0."""
    ok = isinstance(value, int | float) and math.isfinite(value) and value > 0
    return None if ok else f"expected a positive number, got {value!r}"


def non_negative(value: Any) -> str | None:
    """Check: a finite number >= 0."""
    ok = isinstance(value, int | float) and math.isfinite(value) and value >= 0
    return None if ok else f"expected a number >= 0, got {value!r}"


def in_range(lo: float, hi: float) -> Check:
    """Check: a number in [lo, hi]."""
    def check(value: Any) -> str | None:
        ok = isinstance(value, int | float) and lo <= value <= hi
        return None if ok else f"expected a number in [{lo}, {hi}], got {value!r}"
    return check


_NAME = re.compile(r"^[A-Za-z0-9_]+$")
_FRAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_/]*$")


def identifier(value: Any) -> str | None:
    """Check: letters, digits and underscores (a human id, a name); an integer is fine
    too (``-p human_id:=1`` arrives as one)."""
    ok = (isinstance(value, int) and not isinstance(value, bool) and value >= 0) or (
        isinstance(value, str) and bool(_NAME.match(value)))
    return None if ok else f"expected letters, digits or '_', got {value!r}"


def frame_id(value: Any) -> str | None:
    """Check: a TF frame id (no leading slash)."""
    ok = isinstance(value, str) and bool(_FRAME.match(value))
    return None if ok else f"expected a TF frame id such as 'world', got {value!r}"


def topic_name(value: Any) -> str | None:
    """Check: a non-empty ROS topic name."""
    ok = isinstance(value, str) and bool(re.match(r"^[~/A-Za-z_][A-Za-z0-9_/{}~]*$", value))
    return None if ok else f"expected a ROS topic name, got {value!r}"


def declare_or_set_string(node: Node, name: str, value: str, description: str) -> None:
    """Give the string parameter ``name`` of ``node`` the value ``value`` (declared with
    ``description`` on first use; the node keeps it up to date, not its users)."""
    if node.has_parameter(name):
        node.set_parameters([Parameter(name, Parameter.Type.STRING, value)])
    else:
        node.declare_parameter(name, value, ParameterDescriptor(description=description))
