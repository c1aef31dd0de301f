"""Declare node parameters with defaults and validate every change in one place.

Each node lists its parameters as :class:`ParamSpec` entries; :func:`declare_parameters`
declares them (with a description and, for the numeric checks :func:`positive`,
:func:`non_negative` and :func:`in_range`, the range ``ros2 param describe`` shows),
checks the initial values (a bad value in a params file stops the node with a clear
message) and registers an on-set-parameters callback that rejects bad values later
(``ros2 param set``) with the same message.
"""

from __future__ import annotations

import math
import re
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    SetParametersResult,
)
from rclpy.exceptions import InvalidParameterValueException
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
        try:
            node.declare_parameter(spec.name, spec.default, descriptor(spec))
        except InvalidParameterValueException:
            # Out of the declared range: declared without it, so that the check below
            # names the parameter and the expected values.
            node.declare_parameter(spec.name, spec.default, descriptor(spec, ranges=False))
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


#: The largest integer a parameter holds (int64).
_INT_MAX = 2 ** 63 - 1


def descriptor(spec: ParamSpec, ranges: bool = True) -> ParameterDescriptor:
    """The ParameterDescriptor of ``spec``: description, read-only flag and, when its
    check bounds a number, that range (``floating_point_range`` or ``integer_range``, as
    the default's type; inclusive, so ``positive`` gives [0, max] and says ``> 0`` in
    ``additional_constraints``)."""
    out = ParameterDescriptor(description=spec.description, read_only=spec.read_only,
                              dynamic_typing=spec.dynamic_typing)
    bounds = getattr(spec.check, "bounds", None)
    if bounds is None or isinstance(spec.default, bool) or spec.dynamic_typing:
        return out
    lo, hi, text = bounds
    out.additional_constraints = text
    if not ranges:
        return out
    if isinstance(spec.default, int):
        out.integer_range = [IntegerRange(
            from_value=math.ceil(lo) if math.isfinite(lo) else -_INT_MAX - 1,
            to_value=math.floor(hi) if math.isfinite(hi) else _INT_MAX, step=0)]
    elif isinstance(spec.default, float):
        out.floating_point_range = [FloatingPointRange(
            from_value=float(lo) if math.isfinite(lo) else -sys.float_info.max,
            to_value=float(hi) if math.isfinite(hi) else sys.float_info.max, step=0.0)]
    return out


def bounded(lo: float, hi: float, text: str) -> Callable[[Check], Check]:
    """Mark a numeric check with the range it accepts (closed; ``text`` says it)."""
    def mark(check: Check) -> Check:
        check.bounds = (lo, hi, text)  # type: ignore[attr-defined]
        return check
    return mark


def _error(spec: ParamSpec, value: Any) -> str | None:
    if spec.check is None:
        return None
    msg = spec.check(value)
    return f"{spec.name}: {msg}" if msg else None


@bounded(0.0, math.inf, "> 0")
def positive(value: Any) -> str | None:
    """Check: a finite number > 0."""
    ok = isinstance(value, int | float) and math.isfinite(value) and value > 0
    return None if ok else f"expected a positive number, got {value!r}"


@bounded(0.0, math.inf, ">= 0")
def non_negative(value: Any) -> str | None:
    """Check: a finite number >= 0."""
    ok = isinstance(value, int | float) and math.isfinite(value) and value >= 0
    return None if ok else f"expected a number >= 0, got {value!r}"


def in_range(lo: float, hi: float) -> Check:
    """Check: a number in [lo, hi]."""
    @bounded(lo, hi, f"in [{lo}, {hi}]")
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
