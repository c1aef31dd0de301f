"""``/diagnostics`` and parameter ranges as a plain rclpy client sees them (issue 38 item 5).

The shipped coexistence bringup (synthesis, skeleton publisher, occupancy and coexistence
nodes) runs in-process, its coexistence node pointed at 127.0.0.2 where nothing serves
RTDE; a client in its own rclpy context reads ``/diagnostics`` and asks the nodes'
``describe_parameters`` services.
"""

from __future__ import annotations

from pathlib import Path

import pytest

rclpy = pytest.importorskip("rclpy")

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus  # noqa: E402
from rcl_interfaces.msg import ParameterType  # noqa: E402
from rcl_interfaces.srv import DescribeParameters  # noqa: E402

from ltl_human_motion.ros.bringup import Bringup  # noqa: E402
from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "bringup_coexistence.yaml"
EXPECTED = {"synthesis_node: synthesis queue": "/synthesis_node",
            "skeleton_publisher: playback": "/human_1/skeleton_publisher",
            "occupancy_node: occupancy stream": "/human_1/occupancy_node",
            "coexistence_node: robot connection": "/coexistence_node"}


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory):
    bringup = Bringup(CONFIG, overrides={"store_dir": str(tmp_path_factory.mktemp("m")),
                                         "robot_host": "127.0.0.2"}).start()
    client = ClientSession("test_diagnostics_client")
    try:
        client.diagnostics = client.watch(DiagnosticArray, "/diagnostics", keep=100)

        def statuses() -> dict[str, DiagnosticStatus]:
            return {s.name: s for m in client.diagnostics.messages for s in m.status}
        client.statuses = statuses
        wait_until(lambda: set(EXPECTED) <= set(statuses()), 20.0,
                   "a /diagnostics report of every node")
        yield client
    finally:
        client.close()
        bringup.shutdown()


def test_every_node_reports_on_diagnostics(session) -> None:
    statuses = session.statuses()
    for name, node in EXPECTED.items():
        assert statuses[name].hardware_id == node
    values = {k.key: k.value for k in statuses["synthesis_node: synthesis queue"].values}
    assert values["queued"] == "0" and values["max_queued"].isdigit()
    assert statuses["skeleton_publisher: playback"].message == "stopped"
    stream = {k.key: k.value for k in statuses["occupancy_node: occupancy stream"].values}
    assert float(stream["rate_hz"]) == 100.0 and stream["deadlines_missed"].isdigit()
    robot = statuses["coexistence_node: robot connection"]
    assert robot.level == DiagnosticStatus.ERROR and "127.0.0.2" in robot.message


def _describe(session, node: str, names: list[str]) -> dict:
    response = session.call(DescribeParameters, f"{node}/describe_parameters",
                            DescribeParameters.Request(names=names), timeout=30.0,
                            resend_after=3.0)
    return dict(zip(names, response.descriptors, strict=True))


def test_parameter_descriptors_carry_ranges(session) -> None:
    occupancy = _describe(session, "/human_1/occupancy_node", ["rate", "stream_priority"])
    rate = occupancy["rate"]
    assert rate.type == ParameterType.PARAMETER_DOUBLE
    assert rate.floating_point_range[0].from_value == 0.0
    assert rate.floating_point_range[0].to_value > 1e300
    assert rate.additional_constraints == "> 0"
    priority = occupancy["stream_priority"].integer_range[0]
    assert (priority.from_value, priority.to_value) == (0, 99)
    synthesis = _describe(session, "/synthesis_node", ["max_concurrent"])
    assert synthesis["max_concurrent"].integer_range[0].from_value == 0
    assert synthesis["max_concurrent"].description


def test_an_out_of_range_value_is_refused_with_the_range(session) -> None:
    from rcl_interfaces.msg import Parameter, ParameterValue
    from rcl_interfaces.srv import SetParameters

    value = ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=-5.0)
    response = session.call(SetParameters, "/human_1/occupancy_node/set_parameters",
                            SetParameters.Request(parameters=[
                                Parameter(name="marker_rate", value=value)]),
                            timeout=30.0, resend_after=3.0)
    assert not response.results[0].successful
    assert response.results[0].reason
