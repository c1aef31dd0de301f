"""The node set of a bringup configuration -- one source for ``bringup`` and launch files.

Plain Python (no rclpy, so ``launch/bringup.launch.py`` can import it). A bringup file is
a standard ROS 2 params file (``config/bringup.yaml``): the ``/**``, per-node and
``/**/<node>`` sections hold node parameters and are handed to every node as
``--params-file`` (by ``ros2 launch`` and by ``ltl-human-motion bringup`` alike); the
``bringup`` section says which nodes to start::

    bringup:
      ros__parameters:
        nodes: [synthesis_node, skeleton_publisher, occupancy_node]
        humans: ["1", "2"]        # one skeleton publisher + occupancy node per human
        executor_threads: 16

The synthesis node runs in the root namespace (service ``/synthesize_motion``); each
human's nodes run in namespace ``human_<id>`` with parameter ``human_id: <id>``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

PACKAGE = "ltl_human_motion"
#: Node kinds a bringup can start, in start order.
NODE_KINDS = ("synthesis_node", "skeleton_publisher", "occupancy_node", "ergonomics_node",
              "coexistence_node")
PER_HUMAN = ("skeleton_publisher", "occupancy_node", "ergonomics_node")
DEFAULT_CONFIG = Path(__file__).resolve().parents[2] / "config" / "bringup.yaml"


@dataclass(frozen=True)
class NodeSpec:
    """One node to start: the ``ros2 run`` executable, its name, namespace and the
    parameters given on top of the params file."""

    executable: str
    name: str
    namespace: str = ""
    parameters: dict[str, Any] = field(default_factory=dict)

    @property
    def fully_qualified_name(self) -> str:
        return f"/{self.namespace}/{self.name}" if self.namespace else f"/{self.name}"


@dataclass(frozen=True)
class BringupConfig:
    """A parsed bringup file."""

    path: Path
    nodes: tuple[str, ...]
    humans: tuple[str, ...]
    executor_threads: int
    params: dict[str, Any]

    def node_specs(self) -> list[NodeSpec]:
        """The nodes to start, in order."""
        specs = [NodeSpec("synthesis_node", "synthesis_node")] \
            if "synthesis_node" in self.nodes else []
        specs += [NodeSpec(kind, kind, f"human_{h}", {"human_id": h})
                  for h in self.humans for kind in PER_HUMAN if kind in self.nodes]
        if "coexistence_node" in self.nodes:
            specs.append(NodeSpec("coexistence_node", "coexistence_node"))
        return specs

    def parameter(self, node: NodeSpec, name: str, default: Any = None) -> Any:
        """The value the params file gives ``name`` for ``node`` (rcl precedence, roughly:
        ``/**`` < ``/**/<name>`` < ``<name>`` / ``/<ns>/<name>``; spec parameters win)."""
        value = default
        keys = ["/**", f"/**/{node.name}", node.name, node.fully_qualified_name,
                node.fully_qualified_name.lstrip("/")]
        for key in keys:
            section = self.params.get(key)
            if isinstance(section, dict):
                values = section.get("ros__parameters") or {}
                if name in values:
                    value = values[name]
        return node.parameters.get(name, value)

    def ros_args(self) -> list[str]:
        """Command-line arguments that hand this file to every node of a context."""
        return ["--ros-args", "--params-file", str(self.path)]

    def topics(self) -> dict[str, str]:
        """The topics the node set publishes, name -> type (for recording)."""
        out: dict[str, str] = {}
        specs = self.node_specs()
        if any(s.executable == "synthesis_node" for s in specs):
            out["/motion_catalog"] = f"{PACKAGE}/msg/MotionCatalog"
        for spec in specs:
            ns = f"/{spec.namespace}" if spec.namespace else ""
            if spec.executable == "skeleton_publisher":
                out["/tf"] = "tf2_msgs/msg/TFMessage"
                out["/tf_static"] = "tf2_msgs/msg/TFMessage"
                out[self.parameter(spec, "markers_topic", "/markers")] = \
                    "visualization_msgs/msg/MarkerArray"
                out[f"{ns}/task_state"] = f"{PACKAGE}/msg/TaskState"
            elif spec.executable == "occupancy_node":
                out[f"{ns}/occupancy"] = f"{PACKAGE}/msg/HumanOccupancy"
                if float(self.parameter(spec, "marker_rate", 10.0)) > 0:
                    out[self.parameter(spec, "markers_topic", "/occupancy_markers")] = \
                        "visualization_msgs/msg/MarkerArray"
            elif spec.executable == "ergonomics_node":
                out[f"{ns}/ergonomics"] = f"{PACKAGE}/msg/ErgonomicsState"
                out[self.parameter(spec, "markers_topic", "/ergonomics_markers")] = \
                    "visualization_msgs/msg/MarkerArray"
            elif spec.executable == "coexistence_node":
                out["/tf"] = out["/tf_static"] = "tf2_msgs/msg/TFMessage"
                out["/joint_states"] = "sensor_msgs/msg/JointState"
                out["/safety_status"] = f"{PACKAGE}/msg/SafetyStatus"
                if float(self.parameter(spec, "marker_rate", 10.0)) > 0:
                    out[self.parameter(spec, "markers_topic", "/robot_markers")] = \
                        "visualization_msgs/msg/MarkerArray"
        return out


def load_bringup_config(path: str | Path | None = None) -> BringupConfig:
    """Read and check a bringup file (default ``config/bringup.yaml``).

    Raises
    ------
    ValueError
        Naming the file and the key when the file is malformed.
    """
    path = Path(path) if path is not None else DEFAULT_CONFIG
    if not path.is_file():
        raise FileNotFoundError(f"bringup configuration {path} does not exist")
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except yaml.YAMLError as exc:
        raise ValueError(f"{path}: not valid YAML: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a params file (a mapping of node names)")
    section = data.get("bringup", {})
    values = section.get("ros__parameters", {}) if isinstance(section, dict) else None
    if not isinstance(values, dict):
        raise ValueError(f"{path}: 'bringup' must hold 'ros__parameters'")
    nodes = values.get("nodes", ["synthesis_node", "skeleton_publisher", "occupancy_node"])
    if not isinstance(nodes, list) or not nodes or any(n not in NODE_KINDS for n in nodes):
        raise ValueError(f"{path}: bringup.nodes must be a non-empty list of "
                         f"{', '.join(NODE_KINDS)}; got {nodes!r}")
    humans = [str(h) for h in values.get("humans", ["1"])]
    if len(set(humans)) != len(humans) or any(not h.replace("_", "").isalnum()
                                               for h in humans):
        raise ValueError(f"{path}: bringup.humans must be unique ids of letters, digits or "
                         f"'_'; got {humans!r}")
    if any(n in PER_HUMAN for n in nodes) and not humans:
        raise ValueError(f"{path}: bringup.humans is empty but {nodes} need a human")
    threads = values.get("executor_threads", 16)
    if not isinstance(threads, int) or threads < 2:
        raise ValueError(f"{path}: bringup.executor_threads must be an integer >= 2")
    ordered = tuple(k for k in NODE_KINDS if k in nodes)
    return BringupConfig(path.resolve(), ordered, tuple(humans), threads, data)
