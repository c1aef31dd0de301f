"""Issue 2's foundation over real DDS between two processes.

(a) a message generated from msg/ (HumanOccupancy) and (b) tf2_msgs/msg/TFMessage go from
a publisher in a subprocess to a subscriber here; (c) a node here calls a service of
this package (PlayMotion, on a skeleton publisher started with its own entry point in a
subprocess) using the generated interface.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

rclpy = pytest.importorskip("rclpy")

from ltl_human_motion.msg import HumanOccupancy  # noqa: E402
from ltl_human_motion.srv import PlayMotion  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402

from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402

pytestmark = pytest.mark.ros

PUBLISHER_CODE = textwrap.dedent("""\
    import time
    import rclpy
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage
    from ltl_human_motion.msg import Capsule, HumanOccupancy, PredictedOccupancy
    rclpy.init()
    node = rclpy.create_node("foundation_publisher")
    occ_pub = node.create_publisher(HumanOccupancy, "/foundation/occupancy", 10)
    tf_pub = node.create_publisher(TFMessage, "/foundation/tf", 10)
    end = time.monotonic() + 30.0
    seq = 0
    while time.monotonic() < end:
        occ = HumanOccupancy()
        occ.header.stamp = node.get_clock().now().to_msg()
        occ.header.frame_id = "world"
        occ.human_id = "7"
        occ.part_names = ["head", "l_hand"]
        occ.capsules = [Capsule(radius=0.105), Capsule(radius=0.045)]
        occ.capsules[0].a.z, occ.capsules[0].b.z = 1.47, 1.63
        occ.prediction_horizon = 0.5
        occ.predicted = [PredictedOccupancy(time_from_now=0.5, capsules=[Capsule(radius=0.1)])]
        occ_pub.publish(occ)
        tf = TransformStamped()
        tf.header.frame_id, tf.child_frame_id = "world", "human_7/pelvis"
        tf.transform.translation.x = float(seq)
        tf.transform.rotation.w = 1.0
        tf_pub.publish(TFMessage(transforms=[tf]))
        seq += 1
        time.sleep(0.05)
    node.destroy_node()
    rclpy.shutdown()
    """)


def _env() -> dict[str, str]:
    return {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}


@pytest.fixture(scope="module")
def publisher_process():
    proc = subprocess.Popen([sys.executable, "-c", PUBLISHER_CODE], env=_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    yield proc
    proc.terminate()
    proc.communicate(timeout=10)


@pytest.fixture(scope="module")
def session():
    with ClientSession("foundation_subscriber") as s:
        yield s


def _wait_for_messages(session: ClientSession, log: object, proc: subprocess.Popen,
                       what: str) -> None:
    wait_until(lambda: log.count >= 3 or proc.poll() is not None, 20.0, what)
    if proc.poll() is not None:
        pytest.fail(f"publisher process exited: {proc.communicate()[1][-2000:]}")


def test_human_occupancy_between_processes(publisher_process: subprocess.Popen,
                                           session: ClientSession) -> None:
    log = session.watch(HumanOccupancy, "/foundation/occupancy", keep=3)
    _wait_for_messages(session, log, publisher_process, "HumanOccupancy from the subprocess")
    msg = log.last
    assert msg.header.frame_id == "world" and msg.human_id == "7"
    assert list(msg.part_names) == ["head", "l_hand"]
    assert [c.radius for c in msg.capsules] == [0.105, 0.045]
    assert (msg.capsules[0].a.z, msg.capsules[0].b.z) == (1.47, 1.63)
    assert msg.prediction_horizon == 0.5 and msg.predicted[0].time_from_now == 0.5
    assert msg.header.stamp.sec > 0


def test_tf_message_between_processes(publisher_process: subprocess.Popen,
                                      session: ClientSession) -> None:
    log = session.watch(TFMessage, "/foundation/tf", keep=5)
    _wait_for_messages(session, log, publisher_process, "TFMessage from the subprocess")
    msgs = log.messages
    assert all(m.transforms[0].child_frame_id == "human_7/pelvis" for m in msgs)
    xs = [m.transforms[0].transform.translation.x for m in msgs]
    assert xs == sorted(xs) and len(set(xs)) == len(xs)


def test_service_of_this_package_between_processes(session: ClientSession) -> None:
    code = ("import sys; from ltl_human_motion.ros.entry_points import skeleton_publisher; "
            "sys.exit(skeleton_publisher())")
    proc = subprocess.Popen(
        [sys.executable, "-X", "faulthandler", "-c", code, "--ros-args", "-r",
         "__ns:=/foundation_human",
         "-p", "human_id:=9", "-p", "cell:=''"],
        env=_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        service = "/foundation_human/play_motion"
        reply = session.call(PlayMotion, service, PlayMotion.Request(command="pause"),
                             timeout=10.0)
        assert not reply.success and "cannot pause: playback is stopped" in reply.message
        reply = session.call(PlayMotion, service, PlayMotion.Request(
            command="play", motion_id="motion_that_was_never_made"), timeout=10.0)
        assert not reply.success and "motion_that_was_never_made" in reply.message
        assert proc.poll() is None
    finally:
        proc.send_signal(2)            # Ctrl-C: the entry point shuts down cleanly
        try:
            out, _ = proc.communicate(timeout=15)
        except subprocess.TimeoutExpired:
            proc.send_signal(6)        # SIGABRT: faulthandler prints every thread's stack
            out, _ = proc.communicate(timeout=15)
            pytest.fail(f"the node ran on 15 s after Ctrl-C:\n{out[-6000:]}")
    assert proc.returncode == 0, out[-2000:]
    assert "Traceback" not in out
