"""Launch arguments override the bringup file (issue 14), checked with real rcl.

``launch``/``launch_ros`` are not on PyPI (tried: ``pip download --no-deps ros-launch
ros-launch-ros launch-ros ros-launch-xml ros-launch-yaml ros-osrf-pycommon``: no
distribution; PyPI's ``launch`` 0.1.3 is an unrelated 2017 application launcher). So the
launch files run against the recording stand-ins of ``test/launch_stand_ins.py``, which
also reproduce how launch_ros turns a ``Node`` into ``--ros-args`` (a dict of parameters
becomes a ``/**`` params file). This is not the real launch service. What is real: the
params files, rcl's merging of them and the nodes that read them -- each node's
parameters are read from a real rclpy context given that command line, and for the
coexistence launch file from the real node processes, by a plain rclpy client
(``rcl_interfaces/srv/GetParameters``).
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

rclpy = pytest.importorskip("rclpy")

from launch_stand_ins import (  # noqa: E402
    launch_description,
    launch_ros_command,
    launched_nodes,
)
from rcl_interfaces.srv import GetParameters  # noqa: E402
from rclpy.context import Context  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import parameter_value_to_python  # noqa: E402

from ltl_human_motion.ros.client import ClientSession, call_service  # noqa: E402
from ltl_human_motion.ros.launch_support.bringup_config import (  # noqa: E402
    LAUNCH_ARGUMENTS,
    load_bringup_config,
)

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
LAUNCH_FILES = {"bringup.launch": ROOT / "config" / "bringup.yaml",
                "coexistence.launch": ROOT / "config" / "bringup_coexistence.yaml"}
#: A value no config file holds, per launch argument. 127.0.0.3: loopback, nothing serves
#: RTDE there, so the coexistence node cannot command another test's simulated arm.
OVERRIDES = {"robot_host": "127.0.0.3", "store_dir": "/tmp/ltl_hm_launch_override_motions",
             "use_sim_time": "true"}


def _launch(monkeypatch: pytest.MonkeyPatch, stem: str, values: dict[str, str]
            ) -> tuple[list[tuple], list[dict[str, Any]]]:
    description = launch_description(monkeypatch, ROOT / "launch" / f"{stem}.py")
    declared = [a for a in description if isinstance(a, tuple)]
    return declared, launched_nodes(description, values)


def _rcl_parameters(args: list[str], name: str, namespace: str | None) -> dict[str, Any]:
    """The parameters rcl hands node ``name`` for this command line (real rclpy)."""
    context = Context()
    rclpy.init(args=args, context=context)
    try:
        node = Node(name, namespace=namespace, context=context,
                    automatically_declare_parameters_from_overrides=True)
        try:
            return {n: p.value for n, p in node._parameters.items()}
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def test_every_launch_argument_is_declared_and_known() -> None:
    for stem in LAUNCH_FILES:
        assert all(a.name in OVERRIDES for a in LAUNCH_ARGUMENTS[stem]), stem


@pytest.mark.parametrize("stem", sorted(LAUNCH_FILES))
def test_each_launch_argument_overrides_the_config_file(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path, stem: str) -> None:
    config = load_bringup_config(LAUNCH_FILES[stem])
    specs = {s.fully_qualified_name: s for s in config.node_specs()}
    declared, _ = _launch(monkeypatch, stem, {})
    names = [name for _, name, _ in declared]
    assert names == ["config"] + [a.name for a in LAUNCH_ARGUMENTS[stem]] + ["namespace"]
    for argument in LAUNCH_ARGUMENTS[stem]:
        value = OVERRIDES[argument.name]
        _, nodes = _launch(monkeypatch, stem, {argument.name: value})
        targets = 0
        for kw in nodes:
            fqn = f"/{kw['namespace']}/{kw['name']}" if kw["namespace"] else f"/{kw['name']}"
            spec = specs[fqn]
            got = _rcl_parameters(launch_ros_command(kw, tmp_path), kw["name"],
                                  kw["namespace"])
            if spec.executable in argument.executables:
                targets += 1
                in_file = config.parameter(spec, argument.parameter)
                assert in_file != argument.convert(value), \
                    f"{argument.name}: pick a value the file lacks"
                assert got[argument.parameter] == argument.convert(value), \
                    (stem, argument.name, fqn)
            for key, expected in spec.parameters.items():
                assert got[key] == expected, (fqn, key)
        assert targets > 0, argument.name


@pytest.mark.parametrize("stem", sorted(LAUNCH_FILES))
def test_without_arguments_the_file_holds(monkeypatch: pytest.MonkeyPatch,
                                          tmp_path: Path, stem: str) -> None:
    config = load_bringup_config(LAUNCH_FILES[stem])
    _, nodes = _launch(monkeypatch, stem, {})
    for kw, spec in zip(nodes, config.node_specs(), strict=True):
        got = _rcl_parameters(launch_ros_command(kw, tmp_path), kw["name"], kw["namespace"])
        for argument in LAUNCH_ARGUMENTS[stem]:
            if spec.executable in argument.executables:
                # use_sim_time, which no shipped file sets, is every node's own (false).
                assert got.get(argument.parameter) == config.parameter(
                    spec, argument.parameter, False if argument.name == "use_sim_time" else None)


def test_a_bad_use_sim_time_names_the_launch_argument(monkeypatch: pytest.MonkeyPatch
                                                      ) -> None:
    with pytest.raises(ValueError, match="launch argument use_sim_time: expected true or "
                                         "false, got 'maybe'"):
        _launch(monkeypatch, "bringup.launch", {"use_sim_time": "maybe"})


def test_a_dict_under_double_star_loses_to_the_file_as_in_issue_14(tmp_path: Path) -> None:
    """What the launch file did before: ``parameters=[file, {"robot_host": ...}]``."""
    config = LAUNCH_FILES["coexistence.launch"]
    kw = {"name": "coexistence_node", "namespace": None,
          "parameters": [str(config), {"robot_host": "127.0.0.3"}]}
    got = _rcl_parameters(launch_ros_command(kw, tmp_path), "coexistence_node", None)
    assert got["robot_host"] == "127.0.0.1"


def _get_parameters(session: ClientSession, fqn: str, names: list[str],
                    timeout: float) -> dict[str, Any]:
    client = session.node.create_client(GetParameters, f"{fqn}/get_parameters")
    response = call_service(client, GetParameters.Request(names=names), timeout=timeout,
                            wait_for_service=timeout, resend_after=5.0)
    return {n: parameter_value_to_python(v) for n, v in zip(names, response.values)}


def _start(nodes: list[dict[str, Any]], folder: Path) -> list[subprocess.Popen]:
    """The node executables of ``nodes``, each with launch_ros's command line."""
    procs = []
    for kw in nodes:
        code = (f"import sys; from ltl_human_motion.ros.entry_points import "
                f"{kw['executable']} as main; sys.exit(main(sys.argv))")
        procs.append(subprocess.Popen(
            [sys.executable, "-c", code, *launch_ros_command(kw, folder)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    return procs


def _stop(procs: list[subprocess.Popen]) -> None:
    for proc in procs:
        proc.terminate()
    deadline = time.monotonic() + 15
    for proc in procs:
        try:
            proc.wait(timeout=max(deadline - time.monotonic(), 0.1))
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def test_coexistence_launch_processes_get_the_launch_arguments(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """The real node executables, started with launch_ros's command line, read back by
    a plain rclpy client."""
    stem = "coexistence.launch"
    _, nodes = _launch(monkeypatch, stem, OVERRIDES)
    procs = _start(nodes, tmp_path)
    try:
        with ClientSession("launch_test_client") as session:
            for kw in nodes:
                fqn = f"/{kw['namespace']}/{kw['name']}" if kw["namespace"] \
                    else f"/{kw['name']}"
                wanted = [a.parameter for a in LAUNCH_ARGUMENTS[stem]
                          if kw["executable"] in a.executables]
                if not wanted:
                    continue
                got = _get_parameters(session, fqn, wanted, timeout=90.0)
                for argument in LAUNCH_ARGUMENTS[stem]:
                    if kw["executable"] in argument.executables:
                        assert got[argument.parameter] == argument.convert(
                            OVERRIDES[argument.name]), (fqn, argument.name)
    finally:
        _stop(procs)


def test_a_bad_namespace_names_the_launch_argument(monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.raises(ValueError, match="launch argument namespace: expected a ROS "
                                         "namespace such as 'cell_a', got '9 lives'"):
        _launch(monkeypatch, "bringup.launch", {"namespace": "9 lives"})


def test_bringup_launch_under_a_namespace_keeps_its_wiring_inside(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """``namespace:=cell_a``: the real node processes (launch_ros's command lines) run
    under /cell_a, and their catalog and marker topics move there with them; a plain
    rclpy client reads the graph."""
    _, nodes = _launch(monkeypatch, "bringup.launch",
                       {"namespace": "/cell_a/", "store_dir": str(tmp_path / "m")})
    assert {kw["namespace"] for kw in nodes} == {"cell_a", "cell_a/human_1"}
    procs = _start(nodes, tmp_path)
    try:
        with ClientSession("launch_ns_client") as session:
            node = session.node
            wanted = {("/cell_a", "synthesis_node"), ("/cell_a/human_1", "skeleton_publisher"),
                      ("/cell_a/human_1", "occupancy_node"),
                      ("/cell_a/human_1", "ergonomics_node")}

            def ready() -> bool:
                names = {(ns, n) for n, ns in node.get_node_names_and_namespaces()}
                return wanted <= names and node.count_subscribers(
                    "/cell_a/motion_catalog") >= 3 and node.count_publishers(
                    "/cell_a/markers") >= 1
            deadline = time.monotonic() + 90.0
            while not ready() and time.monotonic() < deadline:
                time.sleep(0.2)
            assert ready(), sorted(node.get_node_names_and_namespaces())
            assert node.count_publishers("/cell_a/motion_catalog") == 1
            for topic in ("/cell_a/occupancy_markers", "/cell_a/ergonomics_markers",
                          "/cell_a/human_1/occupancy"):
                assert node.count_publishers(topic) == 1, topic
            for topic in ("/motion_catalog", "/markers", "/occupancy_markers"):
                assert node.count_publishers(topic) == 0, topic
            assert node.count_publishers("/humans/bodies/h1/joint_states") == 1
    finally:
        _stop(procs)


def test_launch_file_and_bringup_agree_under_a_namespace_on_sim_time(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """The in-process bringup's ``namespace`` and ``use_sim_time`` are the launch
    arguments: the same nodes under the same names, every parameter as rcl hands it to
    the launched node. The file's ``synthesis_node:`` and ``coexistence_node:`` sections
    match only a node outside the namespace (rcl), so both carry them over (the
    synthesis node's ``max_concurrent: 2``, default 4)."""
    from ltl_human_motion.ros.bringup import Bringup

    stem = "coexistence.launch"
    config = load_bringup_config(LAUNCH_FILES[stem])
    values = {"namespace": "cell_b", "use_sim_time": "true", "robot_host": "127.0.0.3",
              "store_dir": str(tmp_path / "m")}
    _, nodes = _launch(monkeypatch, stem, values)
    bringup = Bringup(config, namespace="/cell_b/", use_sim_time=True, overrides={
        "robot_host": "127.0.0.3", "store_dir": str(tmp_path / "m")})
    try:
        started = {n.get_fully_qualified_name(): n for n in bringup.nodes}
        launched = {f"/{kw['namespace']}/{kw['name']}": kw for kw in nodes}
        assert set(started) == set(launched) == {
            "/cell_b/synthesis_node", "/cell_b/human_1/skeleton_publisher",
            "/cell_b/human_1/occupancy_node", "/cell_b/coexistence_node"}
        rcl = {fqn: _rcl_parameters(launch_ros_command(kw, tmp_path), kw["name"],
                                    kw["namespace"]) for fqn, kw in launched.items()}
        for fqn, got in rcl.items():
            node = started[fqn]
            shared = [n for n in got if node.has_parameter(n)]
            assert len(shared) >= 5, (fqn, shared)
            assert {n: node.get_parameter(n).value for n in shared} == \
                {n: got[n] for n in shared}, fqn
            assert got["use_sim_time"] is True, fqn
        assert rcl["/cell_b/synthesis_node"]["max_concurrent"] == 2
        assert rcl["/cell_b/coexistence_node"]["human_speed"] == 1.6
        coexistence = started["/cell_b/coexistence_node"]
        assert coexistence.get_parameter("robot_host").value == "127.0.0.3"
        assert coexistence.get_parameter("markers_topic").value == "/cell_b/robot_markers"
    finally:
        bringup.shutdown()


def test_a_bad_bringup_namespace_is_refused_before_any_node_starts() -> None:
    from ltl_human_motion.ros.bringup import Bringup

    with pytest.raises(ValueError, match="bringup namespace: expected a ROS namespace such "
                                         "as 'cell_a', got '9 lives'"):
        Bringup(LAUNCH_FILES["bringup.launch"], namespace="9 lives")
