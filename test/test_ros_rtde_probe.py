"""Without a robot, the coexistence node says so through ROS logging (host and port),
not through ur_rtde's bare ``connect: Connection refused`` on stdout/stderr."""

from __future__ import annotations

import os
import socket
import time

import pytest

rclpy = pytest.importorskip("rclpy")
pytest.importorskip("rtde_receive")

from rclpy.context import Context  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402

from ltl_human_motion.robot.rtde_probe import RTDE_PORT, probed_factories, refusal  # noqa: E402
from ltl_human_motion.ros.coexistence_node import CoexistenceNode  # noqa: E402

pytestmark = pytest.mark.ros

#: Loopback, but nothing serves RTDE there (simulators of other tests bind 127.0.0.1).
NO_ROBOT = "127.0.0.4"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_refusal_names_host_and_port_and_is_empty_when_the_controller_answers() -> None:
    """Refused, and listening but silent (a controller whose process is stopped: the
    kernel accepts, nobody answers RTDE), are both named; the simulated controller, which
    speaks RTDE, answers."""
    import signal

    from robot_sim import start_sim
    port = _free_port()
    message = refusal("127.0.0.1", port)
    assert f"127.0.0.1:{port}" in message and "refused" in message.lower()
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(1)
        silent = refusal("127.0.0.1", server.getsockname()[1], timeout=0.3)
        assert "does not answer" in silent and str(server.getsockname()[1]) in silent
    sim = start_sim()
    try:
        assert refusal("127.0.0.1") == ""
        os.kill(sim.process.pid, signal.SIGSTOP)           # frozen: socket open, silent
        assert "does not answer" in refusal("127.0.0.1", timeout=0.3)
    finally:
        sim.kill()
        sim.stop()


def test_probed_factories_do_not_call_ur_rtde_when_refused() -> None:
    calls: list[str] = []
    reports: list[str] = []
    port = _free_port()
    make_receive, make_io = probed_factories(
        (lambda: calls.append("receive"), lambda: calls.append("io")), "127.0.0.1",
        reports.append, port=port)
    for make in (make_receive, make_io):
        with pytest.raises(ConnectionRefusedError, match=f"127.0.0.1:{port}"):
            make()
    assert calls == [] and len(reports) == 2


def test_the_node_logs_the_refusal_and_ur_rtde_prints_nothing(
        capfd: pytest.CaptureFixture[str]) -> None:
    context = Context()
    rclpy.init(context=context)
    node = None
    seen = ""
    try:
        node = CoexistenceNode(context=context, parameter_overrides=[
            Parameter("robot_host", value=NO_ROBOT), Parameter("marker_rate", value=0.0)])
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline:
            time.sleep(0.2)
            out = capfd.readouterr()
            seen += out.out + out.err
            if f"{NO_ROBOT}:{RTDE_PORT}" in seen:
                break
        else:
            pytest.fail(f"no log line naming {NO_ROBOT}:{RTDE_PORT}")
        assert node.controller.connected is False
        time.sleep(3.0)                         # several reconnection attempts
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown(context=context)
    out = capfd.readouterr()
    seen += out.out + out.err
    assert "not reachable" in seen
    assert "connect: Connection refused" not in seen
