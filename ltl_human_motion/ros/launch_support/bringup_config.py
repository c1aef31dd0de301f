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

import hashlib
import re
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ltl_human_motion.atomic import atomic_write_text
from ltl_human_motion.yaml_limits import read_text_file

PACKAGE = "ltl_human_motion"
#: Node kinds a bringup can start, in start order.
NODE_KINDS = ("synthesis_node", "skeleton_publisher", "reactive_player", "occupancy_node",
              "ergonomics_node", "coexistence_node")
PER_HUMAN = ("skeleton_publisher", "reactive_player", "occupancy_node", "ergonomics_node")
DEFAULT_CONFIG = Path(__file__).resolve().parents[3] / "config" / "bringup.yaml"
#: Topic parameters whose absolute defaults wire a node set together, by node kind: the
#: ``namespace:=`` launch argument moves them into the namespace (:func:`namespace_overrides`).
SET_TOPICS: dict[str, dict[str, str]] = {
    "skeleton_publisher": {"markers_topic": "/markers", "catalog_topic": "/motion_catalog"},
    "occupancy_node": {"markers_topic": "/occupancy_markers",
                       "catalog_topic": "/motion_catalog"},
    "ergonomics_node": {"markers_topic": "/ergonomics_markers",
                        "catalog_topic": "/motion_catalog"},
    "coexistence_node": {"markers_topic": "/robot_markers"},
    "reactive_player": {"markers_topic": "/markers"},
}
_NAMESPACE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*$")


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

    def matching_sections(self, node: NodeSpec) -> list[str]:
        """Keys of the file's sections that apply to ``node`` (as written in the file),
        plus ``/**`` and the node's fully qualified name."""
        keys = ["/**", f"/**/{node.name}", node.name, node.fully_qualified_name,
                node.fully_qualified_name.lstrip("/")]
        found = [k for k in keys if isinstance(self.params.get(k), dict)]
        return list(dict.fromkeys(["/**", *found, node.fully_qualified_name]))

    def ros_args(self) -> list[str]:
        """Command-line arguments that hand this file to every node of a context."""
        return ["--ros-args", "--params-file", str(self.path)]

    def topics(self, namespace: str = "") -> dict[str, str]:
        """The topics the node set publishes, name -> type (for recording), run under
        ``namespace`` ('' = none; see :func:`namespace_overrides`)."""
        root = check_namespace(namespace)
        out: dict[str, str] = {"/diagnostics": "diagnostic_msgs/msg/DiagnosticArray"}
        specs = self.node_specs()
        if any(s.executable == "synthesis_node" for s in specs):
            out[f"/{root}/motion_catalog" if root else "/motion_catalog"] = \
                f"{PACKAGE}/msg/MotionCatalog"
        for spec in specs:
            node_ns = node_namespace(root, spec)
            ns = f"/{node_ns}" if node_ns else ""
            markers = namespace_overrides(self, spec, root).get("markers_topic") or \
                self.parameter(spec, "markers_topic",
                               SET_TOPICS.get(spec.executable, {}).get("markers_topic"))
            if spec.executable == "skeleton_publisher":
                out["/tf"] = "tf2_msgs/msg/TFMessage"
                out["/tf_static"] = "tf2_msgs/msg/TFMessage"
                out[markers] = "visualization_msgs/msg/MarkerArray"
                out[f"{ns}/task_state"] = f"{PACKAGE}/msg/TaskState"
                if self.parameter(spec, "rep155", True):
                    from ltl_human_motion.motion.urdf import body_id

                    body = f"/humans/bodies/{body_id(spec.parameters.get('human_id', '1'))}"
                    out["/humans/bodies/tracked"] = "hri_msgs/msg/IdsList"
                    out[f"{body}/joint_states"] = "sensor_msgs/msg/JointState"
                    out[f"{body}/urdf"] = "std_msgs/msg/String"
                    out[f"{body}/position"] = "geometry_msgs/msg/PointStamped"
                    out[f"{body}/velocity"] = "geometry_msgs/msg/TwistStamped"
            elif spec.executable == "reactive_player":
                out["/tf"] = "tf2_msgs/msg/TFMessage"
                out[markers] = "visualization_msgs/msg/MarkerArray"
                out[f"{ns}/task_state"] = f"{PACKAGE}/msg/TaskState"
            elif spec.executable == "occupancy_node":
                out[f"{ns}/occupancy"] = f"{PACKAGE}/msg/HumanOccupancy"
                if float(self.parameter(spec, "marker_rate", 10.0)) > 0:
                    out[markers] = "visualization_msgs/msg/MarkerArray"
            elif spec.executable == "ergonomics_node":
                out[f"{ns}/ergonomics"] = f"{PACKAGE}/msg/ErgonomicsState"
                out[markers] = "visualization_msgs/msg/MarkerArray"
            elif spec.executable == "coexistence_node":
                out["/tf"] = out["/tf_static"] = "tf2_msgs/msg/TFMessage"
                out["/joint_states"] = "sensor_msgs/msg/JointState"
                out[f"{ns}/safety_status"] = f"{PACKAGE}/msg/SafetyStatus"
                if float(self.parameter(spec, "marker_rate", 10.0)) > 0:
                    out[markers] = "visualization_msgs/msg/MarkerArray"
        return out


def check_namespace(namespace: str, what: str = "launch argument namespace") -> str:
    """``namespace`` without its slashes at either end ('' for none).

    Raises
    ------
    ValueError
        If it is no ROS namespace (tokens of letters, digits and '_', not starting with
        a digit, separated by '/'); the message starts with ``what`` (when not '').
    """
    ns = namespace.strip().strip("/")
    if ns and not _NAMESPACE.match(ns):
        raise ValueError(f"{what}: " * bool(what) + f"expected a ROS namespace such as "
                         f"'cell_a', got {namespace!r}")
    return ns


def node_namespace(namespace: str, node: NodeSpec) -> str:
    """The namespace of ``node`` when its node set runs under ``namespace``."""
    return "/".join(x for x in (check_namespace(namespace), node.namespace) if x)


def namespace_overrides(config: BringupConfig, node: NodeSpec, namespace: str
                        ) -> dict[str, Any]:
    """What ``node`` needs on top of ``config`` to run under ``namespace``.

    Its topic parameters moved under ``namespace`` (those of :data:`SET_TOPICS` whose
    value in ``config`` is absolute), so that node sets in different namespaces keep
    their catalogs and markers apart; TF, REP 155's ``/humans/...``, ``/joint_states``
    and ``/diagnostics`` stay global. And the parameters of the file's sections named
    after the node's own full name (``synthesis_node:``, ``coexistence_node:``,
    ``/human_1/skeleton_publisher:``): rcl matches such a section only to the node
    outside the namespace, so under it they would be lost (the ``/**`` and
    ``/**/<name>`` sections still apply)."""
    ns = check_namespace(namespace)
    if not ns:
        return {}
    out: dict[str, Any] = {}
    fqn = node.fully_qualified_name
    for key in dict.fromkeys((fqn.lstrip("/"), fqn)):
        section = config.params.get(key)
        if isinstance(section, dict):
            out.update(section.get("ros__parameters") or {})
    for param, default in SET_TOPICS.get(node.executable, {}).items():
        value = config.parameter(node, param, default)
        if isinstance(value, str) and value.startswith("/"):
            out[param] = f"/{ns}{value}"
    return out


def load_bringup_config(path: str | Path | None = None) -> BringupConfig:
    """Read and check a bringup file (default ``config/bringup.yaml``).

    Raises
    ------
    ValueError
        Naming the file and the key when the file is malformed.
    """
    path = Path(path) if path is not None else DEFAULT_CONFIG
    if not path.exists():
        raise FileNotFoundError(f"bringup configuration {path} does not exist")
    text = read_text_file(path, "bringup configuration")   # TextFileError: a ValueError
    try:
        data = yaml.safe_load(text)
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
    if "reactive_player" in nodes and ("skeleton_publisher" in nodes
                                       or "ergonomics_node" in nodes):
        raise ValueError(f"{path}: bringup.nodes: reactive_player plays the worker instead "
                         "of skeleton_publisher (both would serve play_motion and publish "
                         "the worker on /tf), and ergonomics_node cannot follow it yet; "
                         f"got {nodes!r}")
    if any(n in PER_HUMAN for n in nodes) and not humans:
        raise ValueError(f"{path}: bringup.humans is empty but {nodes} need a human")
    threads = values.get("executor_threads", 16)
    if not isinstance(threads, int) or threads < 2:
        raise ValueError(f"{path}: bringup.executor_threads must be an integer >= 2")
    ordered = tuple(k for k in NODE_KINDS if k in nodes)
    return BringupConfig(path.resolve(), ordered, tuple(humans), threads, data)


def launch_bool(text: str) -> bool:
    """A launch argument's ``true``/``false`` (any case; also 1/0, yes/no) as a bool.

    Raises
    ------
    ValueError
        Naming the text when it is none of these.
    """
    value = text.strip().lower()
    if value in ("true", "1", "yes", "on"):
        return True
    if value in ("false", "0", "no", "off"):
        return False
    raise ValueError(f"expected true or false, got {text!r}")


@dataclass(frozen=True)
class LaunchArgument:
    """A ``ros2 launch`` argument that sets one node parameter on top of the file;
    ``convert`` turns its text into the parameter's type.

    An empty value (the default) keeps the file's value.
    """

    name: str
    parameter: str
    executables: tuple[str, ...]
    description: str
    convert: Callable[[str], Any] = str


_USE_SIM_TIME = LaunchArgument(
    "use_sim_time", "use_sim_time", NODE_KINDS,
    "true: every node runs on /clock (ROS time), e.g. replaying a bag ('' = the file's)",
    launch_bool)
#: The launch arguments of each launch file (besides ``config:=``), by file stem.
LAUNCH_ARGUMENTS: dict[str, tuple[LaunchArgument, ...]] = {
    "bringup.launch": (
        LaunchArgument("store_dir", "store_dir",
                       ("synthesis_node", "skeleton_publisher", "occupancy_node"),
                       "folder of <motion_id>.npz ('' = the file's)"),
        _USE_SIM_TIME,
    ),
    "coexistence.launch": (
        LaunchArgument("robot_host", "robot_host", ("coexistence_node",),
                       "robot controller address ('' = the file's)"),
        LaunchArgument("store_dir", "store_dir",
                       ("synthesis_node", "skeleton_publisher", "occupancy_node"),
                       "folder of <motion_id>.npz ('' = the file's)"),
        _USE_SIM_TIME,
    ),
}


def launch_overrides(arguments: tuple[LaunchArgument, ...], values: Mapping[str, str],
                     node: NodeSpec) -> dict[str, Any]:
    """The parameters the launch ``values`` (argument name -> text) set on ``node``.

    Raises
    ------
    ValueError
        Naming the launch argument when its text does not convert.
    """
    out = {}
    for arg in arguments:
        if node.executable in arg.executables and values.get(arg.name, "") != "":
            try:
                out[arg.parameter] = arg.convert(values[arg.name])
            except ValueError as exc:
                raise ValueError(f"launch argument {arg.name}: {exc}") from None
    return out


def write_override_params(config: BringupConfig, node: NodeSpec,
                          overrides: Mapping[str, Any], folder: str | Path | None = None
                          ) -> Path | None:
    """A params file that makes ``node.parameters`` and ``overrides`` beat ``config``.

    rcl merges the ``--params-file`` files of a node in order (a later file replaces a
    value of the same section and name) and then lets a node-specific section win over
    ``/**``. A dict handed to launch_ros lands in a ``/**`` section of its own, so the
    file's ``<node>:`` section would still win (issue 14). This file instead repeats the
    values under every section of ``config`` that applies to the node (and under
    ``/**`` and the node's full name), so given after ``config`` they win whatever the
    precedence between sections. Returns None when there is nothing to override.
    """
    values = {**node.parameters, **overrides}
    if not values:
        return None
    data = {key: {"ros__parameters": dict(values)} for key in config.matching_sections(node)}
    folder = Path(folder) if folder is not None else Path(tempfile.gettempdir())
    tag = node.fully_qualified_name.strip("/").replace("/", "__")
    text = yaml.safe_dump(data, sort_keys=False)
    digest = hashlib.sha256(f"{config.path}\n{text}".encode()).hexdigest()[:16]
    path = folder / f"ltl_human_motion_launch_{tag}_{digest}.yaml"
    atomic_write_text(path, text)
    return path


def launch_parameters(config: BringupConfig, node: NodeSpec, overrides: Mapping[str, Any],
                      folder: str | Path | None = None) -> list[str]:
    """``parameters=`` of a launch_ros Node: the config file, then the override file."""
    extra = write_override_params(config, node, overrides, folder)
    return [str(config.path)] + ([str(extra)] if extra is not None else [])
