"""The coexistence node as a lifecycle node, driven over its lifecycle services by a plain
rclpy client (as ``ros2 lifecycle set`` or nav2's lifecycle manager drive it), against the
simulated UR controller through the real ur_rtde client (issue 38 item 5).

What the arm is left at when the monitor is deactivated is read back the way any client of
the controller sees it: a separate ``RTDEReceiveInterface`` reads the speed slider, the
simulator's status how fast the arm's program advances, and this process's TCP table
which RTDE connections the node holds.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

rclpy = pytest.importorskip("rclpy")
rtde_receive = pytest.importorskip("rtde_receive")
pytest.importorskip("rtde_io")
psutil = pytest.importorskip("psutil")

from lifecycle_msgs.msg import State, Transition  # noqa: E402
from lifecycle_msgs.srv import ChangeState, GetState  # noqa: E402
from ltl_human_motion.msg import HumanOccupancy, SafetyStatus  # noqa: E402
from rclpy.context import Context  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402

from ltl_human_motion.robot.sim.port_lock import RTDE_PORT  # noqa: E402
from ltl_human_motion.robot.sim.process import URSimHandle  # noqa: E402
from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402
from ltl_human_motion.ros.coexistence_demo import (  # noqa: E402
    node_parameters_from_robot_config,
    rtde_port_lock,
    start_sim_when_free,
)
from ltl_human_motion.ros.coexistence_node import CoexistenceNode  # noqa: E402
from ltl_human_motion.ros.common import SpinThread  # noqa: E402
from ltl_human_motion.ros.diagnostics import WARN  # noqa: E402
from ltl_human_motion.ros.occupancy_cdr import encode_human_occupancy  # noqa: E402

pytestmark = pytest.mark.ros

NS = "/coexistence_lifecycle"          # each test's node and worker under a namespace of
                                       # its own, so no graph entry of another one matches
HOST = "127.0.0.1"
MIN, MAX = 0.01, 1.0                 # the node's default slider range
FAR = np.array([[[4.5, 2.5, 0.0], [4.5, 2.5, 1.6]]])   # a worker about 5 m from the arm

REACHES = {Transition.TRANSITION_CONFIGURE: State.PRIMARY_STATE_INACTIVE,
           Transition.TRANSITION_ACTIVATE: State.PRIMARY_STATE_ACTIVE,
           Transition.TRANSITION_DEACTIVATE: State.PRIMARY_STATE_INACTIVE,
           Transition.TRANSITION_CLEANUP: State.PRIMARY_STATE_UNCONFIGURED}


@pytest.fixture(scope="module")
def sim() -> Iterator[URSimHandle]:
    """The simulated UR5e of config/ur_pick_place.yaml on 127.0.0.1:30004 (one per
    machine: other sessions' runs are waited for)."""
    with rtde_port_lock(timeout=150.0):
        handle = start_sim_when_free(timeout=60.0)
        try:
            yield handle
        finally:
            handle.stop()


@pytest.fixture
def context() -> Iterator[Context]:
    context = Context()
    rclpy.init(context=context)
    yield context
    rclpy.try_shutdown(context=context)


def _node(context: Context, ns: str, host: str = HOST, **params: Any) -> CoexistenceNode:
    values = {**node_parameters_from_robot_config(), "robot_host": host,
              "occupancy_topic": f"{ns}/far_worker/occupancy", "autostart": False, **params}
    return CoexistenceNode(namespace=ns, context=context, record=True,
                           parameter_overrides=[Parameter(k, value=v)
                                                for k, v in values.items()])


def _change(session: ClientSession, ns: str, transition: int) -> bool:
    """Whether ``transition`` took the node to its state (a lost reply is sent for again;
    a repeated transition is refused, so the state then tells)."""
    response = session.call(ChangeState, f"{ns}/coexistence_node/change_state",
                            ChangeState.Request(transition=Transition(id=transition)),
                            timeout=30.0, resend_after=3.0)
    return response.success or _state(session, ns) == REACHES[transition]


def _state(session: ClientSession, ns: str) -> int:
    return session.call(GetState, f"{ns}/coexistence_node/get_state", GetState.Request(),
                        timeout=30.0, resend_after=3.0).current_state.id


def _rtde_connections() -> int:
    """TCP connections of this process to the controller's RTDE port."""
    return sum(1 for c in psutil.Process().net_connections(kind="tcp")
               if c.raddr and c.raddr.port == RTDE_PORT and c.status == "ESTABLISHED")


def _program_rate(sim: URSimHandle, seconds: float = 1.0) -> float:
    """How fast the arm's program advances (trajectory seconds per wall second)."""
    start, t0 = sim.status()["trajectory_time"], time.monotonic()
    time.sleep(seconds)
    return (sim.status()["trajectory_time"] - start) / (time.monotonic() - t0)


class _FarWorker:
    """A worker's occupancy, 5 m from the arm, streamed at 50 Hz from the client while
    :attr:`sending` is set."""

    def __init__(self, session: ClientSession, ns: str) -> None:
        self._publisher = session.node.create_publisher(HumanOccupancy,
                                                        f"{ns}/far_worker/occupancy", 10)
        self._clock = session.node.get_clock()
        self._stop = threading.Event()
        self.sending = threading.Event()
        self.sending.set()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.02):
            if not self.sending.is_set():
                continue
            sec, nanosec = divmod(self._clock.now().nanoseconds, 1_000_000_000)
            self._publisher.publish(encode_human_occupancy(
                sec, nanosec, "world", "far", ["torso"], FAR[None], np.array([0.2]),
                np.zeros(1)))

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()


def _wait(predicate: Callable[[], Any], timeout: float, what: str) -> None:
    wait_until(lambda: bool(predicate()), timeout, what)


def _far_worker_until_full_speed(ns: str, readback: Any, timeout: float = 60.0) -> None:
    """Stream a far worker (from a client session of its own) until the controller reports
    the full slider."""
    with ClientSession(f"far_worker{ns.replace('/', '_')}") as session:
        worker = _FarWorker(session, ns)
        try:
            _wait(lambda: readback.getTargetSpeedFraction() == pytest.approx(MAX), timeout,
                  f"the full slider (a far worker on {ns})")
        finally:
            worker.stop()


def test_commissioning_and_deactivation_leave_the_arm_at_the_minimum(
        sim: URSimHandle, context: Context) -> None:
    readback = rtde_receive.RTDEReceiveInterface(HOST)
    baseline = _rtde_connections()                 # the read-back client's own
    ns = f"{NS}_commissioning"
    node = _node(context, ns)
    spinner = SpinThread([node], context, 4)
    try:
        with ClientSession("coexistence_lifecycle_client") as session:
            status = session.watch(SafetyStatus, f"{ns}/safety_status", keep=1)
            joints = session.watch(JointState, "/joint_states", keep=1)
            worker = _FarWorker(session, ns)
            try:
                _commission(sim, session, ns, node, readback, baseline, status, joints,
                            worker)
            finally:
                worker.stop()
    finally:
        spinner.stop()
        node.destroy_node()
        readback.disconnect()


def _commission(sim: URSimHandle, session: ClientSession, ns: str, node: CoexistenceNode,
                readback: Any, baseline: int, status: Any, joints: Any,
                worker: _FarWorker) -> None:
    """Configure, activate, deactivate, activate, deactivate, clean up: what each
    connects, publishes and leaves the arm at."""
    assert _state(session, ns) == State.PRIMARY_STATE_UNCONFIGURED

    # configure: the model is loaded, nothing is connected or published
    assert _change(session, ns, Transition.TRANSITION_CONFIGURE)
    assert _state(session, ns) == State.PRIMARY_STATE_INACTIVE
    assert node.model is not None and node.model.name == "ur5e"
    time.sleep(1.0)
    assert node.controller is None and _rtde_connections() == baseline
    assert status.count == 0 and joints.count == 0
    assert readback.getTargetSpeedFraction() == pytest.approx(MAX)   # untouched

    # activate: connects over RTDE, publishes, the far worker lets the arm run
    assert _change(session, ns, Transition.TRANSITION_ACTIVATE)
    assert _state(session, ns) == State.PRIMARY_STATE_ACTIVE
    _wait(lambda: status.count > 0 and joints.count > 0, 15.0,
          "safety_status and joint_states once active")
    assert _rtde_connections() > baseline
    _wait(lambda: node.latest is not None and node.latest.mode == "full", 15.0,
          "full speed with the only worker 5 m away")
    _wait(lambda: readback.getTargetSpeedFraction() == pytest.approx(MAX), 5.0,
          "the full slider over RTDE")
    running = _program_rate(sim)
    assert running == pytest.approx(MAX, abs=0.15)

    # deactivate: publishing stops, the arm is left at the minimum slider (the
    # controller confirms it) and the node disconnects
    assert _change(session, ns, Transition.TRANSITION_DEACTIVATE)
    assert _state(session, ns) == State.PRIMARY_STATE_INACTIVE
    assert node.held is not None and "confirmed by the controller" in node.held
    assert readback.getTargetSpeedFraction() == pytest.approx(MIN)
    _wait(lambda: _rtde_connections() == baseline, 5.0, "the node's RTDE clients "
          "closed")
    counts = (status.count, joints.count)
    held = _program_rate(sim, 2.0)             # the worker's stream goes on
    assert (status.count, joints.count) == counts
    assert held == pytest.approx(MIN, abs=0.005) and held < running / 20
    assert readback.getTargetSpeedFraction() == pytest.approx(MIN)
    [diag] = node.diagnostics()
    assert diag.level == WARN and "not active" in diag.message \
        and "minimum slider" in diag.message

    # activate again with the worker silent: the occupancy seen before deactivation (far:
    # full speed) is not used again, the arm stays at the minimum until the worker's
    # stream returns, then runs at full speed
    worker.sending.clear()
    time.sleep(0.5)
    reactivated = time.monotonic()
    assert _change(session, ns, Transition.TRANSITION_ACTIVATE)
    _wait(lambda: status.count > counts[0], 15.0, "safety_status again")
    _wait(lambda: node.latest is not None and node.latest.connected, 15.0,
          "the node connected again")
    time.sleep(1.0)
    assert node.recorder is not None
    since = [d for d in node.recorder.decisions if d.time >= reactivated]
    assert len(since) > 50 and all(d.slider == pytest.approx(MIN) for d in since)
    assert {d.mode for d in since} <= {"stale", "disconnected"}
    assert readback.getTargetSpeedFraction() == pytest.approx(MIN)
    worker.sending.set()
    _wait(lambda: readback.getTargetSpeedFraction() == pytest.approx(MAX), 15.0,
          "the full slider again")

    # cleanup after deactivate: back to unconfigured, the model forgotten
    assert _change(session, ns, Transition.TRANSITION_DEACTIVATE)
    assert _change(session, ns, Transition.TRANSITION_CLEANUP)
    assert _state(session, ns) == State.PRIMARY_STATE_UNCONFIGURED
    assert node.model is None
    assert readback.getTargetSpeedFraction() == pytest.approx(MIN)


def test_an_active_node_destroyed_leaves_the_arm_at_the_minimum(
        sim: URSimHandle, context: Context) -> None:
    """Autostart (the default) monitors at once; Ctrl-C (destroy) is a deactivation."""
    readback = rtde_receive.RTDEReceiveInterface(HOST)
    ns = f"{NS}_destroyed"
    node = _node(context, ns, autostart=True)
    spinner = SpinThread([node], context, 4)
    try:
        assert node.active
        with ClientSession("coexistence_lifecycle_auto") as session:
            assert _state(session, ns) == State.PRIMARY_STATE_ACTIVE
        _far_worker_until_full_speed(ns, readback)
    finally:
        spinner.stop()
        node.destroy_node()
    try:
        assert readback.getTargetSpeedFraction() == pytest.approx(MIN)
        assert "confirmed by the controller" in (node.held or "")
    finally:
        readback.disconnect()


def test_deactivation_without_a_robot_says_the_arm_was_not_reached(context: Context) -> None:
    """127.0.0.2: loopback, but nothing serves RTDE there."""
    ns = f"{NS}_no_robot"
    node = _node(context, ns, host="127.0.0.2", marker_rate=0.0)
    spinner = SpinThread([node], context, 4)
    try:
        with ClientSession("coexistence_lifecycle_norobot") as session:
            assert _change(session, ns, Transition.TRANSITION_CONFIGURE)
            assert _change(session, ns, Transition.TRANSITION_ACTIVATE)
            _wait(lambda: node.latest is not None and node.latest.mode == "disconnected",
                  10.0, "a control step without the robot")
            assert _change(session, ns, Transition.TRANSITION_DEACTIVATE)
            assert _state(session, ns) == State.PRIMARY_STATE_INACTIVE
            assert node.held is not None and "not connected" in node.held
            [diag] = node.diagnostics()
            assert diag.level == WARN and "not connected" in diag.message
    finally:
        spinner.stop()
        node.destroy_node()


def test_ctrl_c_leaves_the_arm_at_the_minimum_and_logs_without_rosout(
        sim: URSimHandle) -> None:
    """The node's own process (``ros2 run ltl_human_motion coexistence_node``) at full
    speed for a far worker, then Ctrl-C: exit 0, the arm at the minimum, and the last log
    lines printed without "Failed to publish log message to rosout" (the context is shut
    down before the node is destroyed)."""
    ns = f"{NS}_ctrl_c"
    params = {**node_parameters_from_robot_config(), "robot_host": HOST,
              "occupancy_topic": f"{ns}/far_worker/occupancy"}
    code = ("import sys; from ltl_human_motion.ros.entry_points import coexistence_node as m; "
            "sys.exit(m(sys.argv))")
    proc = subprocess.Popen(
        [sys.executable, "-c", code, "--ros-args", "-r", f"__ns:={ns}",
         *[arg for k, v in params.items() for arg in ("-p", f"{k}:={v}")]],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    readback = rtde_receive.RTDEReceiveInterface(HOST)
    try:
        _wait(lambda: readback.getTargetSpeedFraction() == pytest.approx(MIN), 60.0,
              "the node's process in control (the minimum: no worker yet)")
        _far_worker_until_full_speed(ns, readback)
        proc.send_signal(signal.SIGINT)
        output, _ = proc.communicate(timeout=30.0)
        assert proc.returncode == 0, output[-3000:]
        assert "Failed to publish log message to rosout" not in output, output[-3000:]
        assert "arm left at the minimum slider 0.01 (confirmed by the controller)" in output, \
            output[-3000:]
        assert readback.getTargetSpeedFraction() == pytest.approx(MIN)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
        readback.disconnect()
