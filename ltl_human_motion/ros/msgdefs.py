"""Full ROS 2 message definitions (with dependencies), as rosbag2 stores them in MCAP.

Plain Python (no rclpy). ``message_definition("visualization_msgs/msg/MarkerArray")``
returns the type's ``.msg`` text followed, for every type it uses (depth first, each
once), by a line of 80 ``=``, ``MSG: <pkg>/<Type>`` and that type's text -- the
``ros2msg`` schema encoding of MCAP. The ``.msg`` files are found in
``<prefix>/share/<pkg>/msg/`` for every prefix on ``AMENT_PREFIX_PATH``.
"""

from __future__ import annotations

import os
import re
from functools import lru_cache
from pathlib import Path

SEPARATOR = "=" * 80
PRIMITIVES = frozenset({
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
    "int32", "uint32", "int64", "uint64", "string", "wstring", "time", "duration",
})
_ARRAY = re.compile(r"\[[^\]]*\]$")
_BOUNDED = re.compile(r"^(w?string)<=\d+$")


def _split_type(name: str) -> tuple[str, str]:
    """``pkg/msg/Type`` or ``pkg/Type`` -> (pkg, Type)."""
    parts = name.split("/")
    if len(parts) == 3 and parts[1] == "msg":
        return parts[0], parts[2]
    if len(parts) == 2:
        return parts[0], parts[1]
    raise ValueError(f"message type must look like 'pkg/msg/Type', got {name!r}")


def find_msg_file(package: str, type_name: str, prefixes: tuple[str, ...] | None = None) -> Path:
    """The ``.msg`` file of ``package/type_name`` under the ament prefixes."""
    if prefixes is None:
        prefixes = tuple(p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)
                         if p)
    for prefix in prefixes:
        path = Path(prefix) / "share" / package / "msg" / f"{type_name}.msg"
        if path.is_file():
            return path
    raise FileNotFoundError(
        f"no definition of {package}/msg/{type_name} in share/{package}/msg under "
        f"AMENT_PREFIX_PATH ({os.pathsep.join(prefixes) or 'empty'})")


def field_types(text: str, package: str) -> list[str]:
    """The non-primitive field types of a ``.msg`` text, as ``pkg/Type``, in order."""
    out: list[str] = []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.split()
        if len(parts) < 2 or "=" in parts[1]:      # constants: "int32 NAME=1"
            continue
        base = _ARRAY.sub("", parts[0])
        if _BOUNDED.match(base) or base in PRIMITIVES:
            continue
        if base == "Header":
            base = "std_msgs/Header"
        elif "/" not in base:
            base = f"{package}/{base}"
        out.append(base)
    return out


@lru_cache(maxsize=256)
def message_definition(full_type: str) -> str:
    """The concatenated definition of ``full_type`` (``pkg/msg/Type``) and its dependencies."""
    package, type_name = _split_type(full_type)
    root = find_msg_file(package, type_name).read_text(encoding="utf-8")
    sections = [root.rstrip("\n")]
    seen = {f"{package}/{type_name}"}
    stack = list(reversed(field_types(root, package)))
    while stack:
        dep = stack.pop()
        if dep in seen:
            continue
        seen.add(dep)
        dep_pkg, dep_type = _split_type(dep)
        text = find_msg_file(dep_pkg, dep_type).read_text(encoding="utf-8")
        sections.append(f"{SEPARATOR}\nMSG: {dep}\n{text.rstrip(chr(10))}")
        stack.extend(reversed(field_types(text, dep_pkg)))
    return "\n".join(sections) + "\n"
