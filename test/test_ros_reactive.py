"""The reactive worker live in ROS over real DDS (loopback).

The synthesis node and the reactive player run in this process (ReactiveStack, one rclpy
context); requests, the robot's joint states and the Bool inputs go through a client node
in its own context, so every message crosses DDS. The joint states come from a stand-in
publishing what the coexistence node publishes; test_ros_reactive_demo.py reads them from
the real coexistence node and the simulated UR over RTDE. No mocks of ROS.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

rclpy = pytest.importorskip("rclpy")

from ltl_human_motion.msg import TaskState  # noqa: E402
from ltl_human_motion.srv import PlayMotion, SynthesizeMotion  # noqa: E402
from std_msgs.msg import Bool  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402

from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402
from ltl_human_motion.ros.common import STREAM_QOS, stamp_seconds  # noqa: E402
from ltl_human_motion.ros.react_demo import (  # noqa: E402
    Q_IN,
    Q_OUT,
    JointStateStandIn,
    ReactiveStack,
)
from ltl_human_motion.ros.reactive_player import strategy_path  # noqa: E402
from ltl_human_motion.tasks.reactive import DEMO_SPEC  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
DOOR_CELL = (ROOT / "config" / "paper_cell.yaml").read_text() \
    + "\ninputs:\n  door_open: /cell/door_open\n"
DOOR_SPEC = ("(G F !door_open & G F offered(O1)) -> (G(door_open -> X !assemble(R1)) & "
             "G(!offered(O1) -> X !grasp(O1)) & G F grasp(O1) & G F assemble(R1))")


def wait_for(predicate: Callable[[], Any], timeout: float, what: str) -> Any:
    """``predicate()`` once truthy (polled); fails naming ``what`` after ``timeout`` s."""
    found: list[Any] = []
    try:
        wait_until(lambda: bool(found.append(predicate()) or found[-1]), timeout, what, 0.01)
    except TimeoutError as exc:
        pytest.fail(str(exc))
    return found[-1]


@pytest.fixture(scope="module")
def live(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[ReactiveStack,
                                                                     ClientSession]]:
    stack = ReactiveStack(tmp_path_factory.mktemp("reactive"), playback_rate=4.0)
    session = ClientSession("reactive_test_client")
    try:
        yield stack, session
    finally:
        session.close()
        stack.close()


def synthesize(session: ClientSession, spec: str, cell: str = "paper_cell"
               ) -> SynthesizeMotion.Response:
    return session.call(SynthesizeMotion, "/synthesize_motion",
                        SynthesizeMotion.Request(spec=spec, cell=cell), timeout=300.0,
                        resend_after=60.0)


def play(session: ClientSession, strategy_id: str, command: str = "play") -> PlayMotion.Response:
    return session.call(PlayMotion, "/human_1/play_motion",
                        PlayMotion.Request(command=command, motion_id=strategy_id),
                        timeout=30.0, resend_after=5.0)


def test_the_service_answers_a_reactive_spec_with_a_strategy_id(live):
    stack, session = live
    response = synthesize(session, DEMO_SPEC)
    assert response.success, response.error_message
    assert response.strategy_id.startswith("strategy_")
    assert list(response.motion_ids) == []
    assert "wait(0.15)" in response.task_sequences[0]
    assert strategy_path(stack.synthesis.store.directory, response.strategy_id).is_file()


def test_an_unrealizable_reactive_spec_is_refused_with_the_explanation(live):
    _, session = live
    response = synthesize(session, "G(robot_in(R1) -> X !assemble(R1)) & G F assemble(R1)")
    assert not response.success
    assert "unrealizable" in response.error_message
    assert "G F !robot_in(R1)" in response.error_message
    assert response.strategy_id == ""


def test_an_unknown_strategy_id_is_refused_by_name(live):
    _, session = live
    response = play(session, "strategy_000000000000")
    assert not response.success and "strategy_000000000000" in response.message


def test_the_waiting_worker_reacts_to_the_robot_leaving_r1(live):
    stack, session = live
    states = session.watch(TaskState, "/human_1/task_state", keep=400)
    tf = session.watch(TFMessage, "/tf", keep=400)
    robot = JointStateStandIn(session.node, Q_IN)
    try:
        response = synthesize(session, DEMO_SPEC)
        assert response.success, response.error_message
        sid = response.strategy_id
        assert play(session, sid).success

        def waiting() -> TaskState | None:
            msg = states.last
            ok = msg is not None and msg.strategy_id == sid and \
                msg.current_task == "wait(0.15)" and list(msg.input_values) == [True]
            return msg if ok else None

        msg = wait_for(waiting, 30.0, "the worker to wait at the bench with the arm in R1")
        assert list(msg.input_names) == ["robot_in(R1)"]
        assert msg.strategy_state.startswith("worker state")
        time.sleep(0.5)
        assert states.last.current_task == "wait(0.15)"      # still waiting
        robot.move(Q_OUT)
        event = wait_for(lambda: robot.changed, 2.0, "the robot's first joint state out of R1")

        def assembling() -> TaskState | None:
            return next((m for m in states.messages if m.strategy_id == sid
                         and m.current_task == "assemble(R1)"), None)

        first = wait_for(assembling, 5.0, "the worker to assemble once the arm left R1")
        assert list(first.input_values) == [False]
        assert stamp_seconds(first.inputs_stamp) == pytest.approx(event, abs=1e-6)
        reacted = stamp_seconds(first.header.stamp)
        assert reacted >= event
        # The first frame of the reaction is on TF with the same stamp.
        stamps = {stamp_seconds(t.header.stamp) for m in tf.messages for t in m.transforms
                  if t.child_frame_id == "human_1/pelvis"}
        assert reacted in stamps
        assert any(r[0] == pytest.approx(event, abs=1e-6) for r in stack.player.reactions)
        # A task under way finishes: the arm coming back does not stop the assembly.
        robot.move(Q_IN)
        time.sleep(0.3)
        assert states.last.current_task == "assemble(R1)"
        assert play(session, sid, "stop").success
    finally:
        robot.close()


class BoolInputs:
    """Publishes Bool inputs at 20 Hz (the values can change at any time)."""

    def __init__(self, session: ClientSession, topics: dict[str, str]) -> None:
        self.pubs = {k: session.node.create_publisher(Bool, t, STREAM_QOS)
                     for k, t in topics.items()}
        self.values = dict.fromkeys(topics, False)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            for k, pub in self.pubs.items():
                pub.publish(Bool(data=self.values[k]))
            time.sleep(0.05)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2.0)


def test_offered_and_cell_inputs_are_read_from_their_bool_topics(live):
    _, session = live
    states = session.watch(TaskState, "/human_1/task_state", keep=1)
    inputs = BoolInputs(session, {"door_open": "/cell/door_open",
                                  "offered(O1)": "/cell/offered/O1"})
    try:
        inputs.values["door_open"] = True
        response = synthesize(session, DOOR_SPEC, DOOR_CELL)
        assert response.success, response.error_message
        sid = response.strategy_id
        assert play(session, sid).success

        def now(task: str, door: bool, offered: bool) -> bool:
            msg = states.last
            return msg is not None and msg.strategy_id == sid and msg.current_task == task \
                and dict(zip(msg.input_names, msg.input_values)) == {
                    "door_open": door, "offered(O1)": offered}

        # Holding O1 with the door open: no assembly (G(door_open -> X !assemble(R1))).
        wait_for(lambda: now("wait(0.15)", True, False), 20.0,
                 "a wait with the door open (read from /cell/door_open)")
        assert states.last.strategy_state.startswith("worker state 1")
        inputs.values["door_open"] = False
        wait_for(lambda: now("assemble(R1)", False, False), 5.0,
                 "the assembly once the door is closed")
        inputs.values["door_open"] = True
        # Hands free, door open, O1 not offered: neither assembly nor grasp; it waits.
        wait_for(lambda: now("wait(0.15)", True, False), 10.0, "a wait for O1 to be offered")
        inputs.values["offered(O1)"] = True
        wait_for(lambda: now("grasp(O1)", True, True), 5.0,
                 "the grasp once O1 is offered (read from /cell/offered/O1)")
        assert play(session, sid, "stop").success
    finally:
        inputs.close()


def test_a_player_in_its_own_process_plays_a_strategy_from_its_file(live):
    stack, session = live
    response = synthesize(session, DEMO_SPEC)
    assert response.success, response.error_message
    states = session.watch(TaskState, "/human_2/task_state", keep=1)
    code = ("import sys; from ltl_human_motion.ros.entry_points import reactive_player; "
            "sys.exit(reactive_player(sys.argv))")
    proc = subprocess.Popen(
        [sys.executable, "-c", code, "--ros-args", "-r", "__ns:=/human_2",
         "-p", "human_id:=2", "-p", f"store_dir:={stack.synthesis.store.directory}",
         "-p", f"strategy_id:={response.strategy_id}"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        msg = wait_for(lambda: (m := states.last) is not None
                       and m.strategy_id == response.strategy_id and m, 60.0,
                       "the player process's task state")
        assert msg.human_id == "2" and msg.current_task == "grasp(O1)"
        assert list(msg.input_names) == ["robot_in(R1)"]
        time.sleep(1.5)                  # nobody publishes /joint_states here: a warning
    finally:
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=20.0)
    assert proc.returncode == 0, out
    assert f"playing strategy {response.strategy_id}" in out
    assert "no joint state on /joint_states for over 1 s: robot_in(R1) keep" in out
