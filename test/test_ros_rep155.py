"""The REP 155 (ROS4HRI) body interface over real DDS, read back by a plain rclpy client.

One in-process bringup of two humans (config/bringup_two_humans.yaml) plays two looped
motions; a client in its own rclpy context (its own DDS participant) reads
``/humans/bodies/tracked``, each body's ``joint_states``, ``urdf`` (latched), ``position``
and ``velocity``, and the REP 155 frames on ``/tf``.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np
import pytest

rclpy = pytest.importorskip("rclpy")
urdf_parser = pytest.importorskip("urdf_parser_py.urdf")

from geometry_msgs.msg import PointStamped, TwistStamped  # noqa: E402
from hri_msgs.msg import IdsList  # noqa: E402
from ltl_human_motion.srv import PlayMotion, SynthesizeMotion  # noqa: E402
from rcl_interfaces.srv import GetParameters  # noqa: E402
from ros_fakes import scripted_synthesize  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from test_motion_urdf import forward_kinematics  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402

from ltl_human_motion.motion import urdf  # noqa: E402
from ltl_human_motion.motion.skeleton import JOINT_NAMES  # noqa: E402
from ltl_human_motion.ros.bringup import Bringup  # noqa: E402
from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402
from ltl_human_motion.ros.common import LATCHED_QOS  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
TWO_HUMANS = ROOT / "config" / "bringup_two_humans.yaml"


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory):
    store = tmp_path_factory.mktemp("motions")
    bringup = Bringup(TWO_HUMANS, overrides={"store_dir": str(store)},
                      synthesize_fn=partial(scripted_synthesize, duration=3.0))
    bringup.start()
    client = ClientSession("test_rep155_client")
    try:
        client.tracked = client.watch(IdsList, "/humans/bodies/tracked", keep=20)
        client.joints = client.watch(JointState, "/humans/bodies/h1/joint_states", keep=50)
        client.urdf = client.watch(String, "/humans/bodies/h1/urdf", keep=1, qos=LATCHED_QOS)
        client.position = client.watch(PointStamped, "/humans/bodies/h1/position", keep=50)
        client.velocity = client.watch(TwistStamped, "/humans/bodies/h1/velocity", keep=50)
        client.tf = client.watch(TFMessage, "/tf", keep=200)
        response = client.call(SynthesizeMotion, "/synthesize_motion",
                               SynthesizeMotion.Request(spec="S2", cell="paper_cell",
                                                        variants=2))
        assert response.success, response.error_message
        for human, motion_id in zip(("1", "2"), response.motion_ids, strict=True):
            played = client.call(PlayMotion, f"/human_{human}/play_motion", PlayMotion.Request(
                command="play", motion_id=motion_id, loop=True, rate=1.0))
            assert played.success, played.message
        wait_until(lambda: client.joints.count > 20 and client.position.count > 20
                   and client.velocity.count > 20 and client.urdf.count > 0,
                   20.0, "REP 155 topics of body 1")
        wait_until(lambda: (m := client.tracked.last) is not None and list(m.ids) == ["h1", "h2"],
                   20.0, "both bodies on /humans/bodies/tracked")
        yield client
    finally:
        client.close()
        bringup.shutdown()


def _world_poses(messages: list[TFMessage]) -> dict[tuple[int, str], np.ndarray]:
    """World positions of every frame, per stamp, composed from the TF messages."""
    edges: dict[int, dict[str, tuple[str, np.ndarray]]] = {}
    for msg in messages:
        for t in msg.transforms:
            stamp = t.header.stamp.sec * 1_000_000_000 + t.header.stamp.nanosec
            T = np.eye(4)
            q, p = t.transform.rotation, t.transform.translation
            T[:3, :3] = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()
            T[:3, 3] = [p.x, p.y, p.z]
            edges.setdefault(stamp, {})[t.child_frame_id] = (t.header.frame_id, T)
    out = {}
    for stamp, tree in edges.items():
        def pose(frame: str, tree: dict = tree) -> np.ndarray:
            if frame == "world":
                return np.eye(4)
            parent, T = tree[frame]
            return pose(parent) @ T
        for frame in tree:
            try:
                out[(stamp, frame)] = pose(frame)
            except KeyError:
                pass                                     # a chain not complete at this stamp
    return out


def test_tracked_lists_both_bodies(session) -> None:
    last = session.tracked.last
    assert list(last.ids) == ["h1", "h2"] and last.header.frame_id == "world"


def test_joint_states_name_the_urdf_joints(session) -> None:
    msg = session.joints.last
    assert list(msg.name) == urdf.joint_names("h1", rep155=True)
    assert {"l_p_shoulder_h1", "l_elbow_h1", "r_knee_h1", "y_head_h1"} <= set(msg.name)
    assert len(msg.position) == 66 and np.isfinite(msg.position).all()
    assert msg.header.stamp.sec > 0


def test_the_latched_urdf_loads_and_reproduces_the_tf_frames(session) -> None:
    robot = urdf_parser.URDF.from_xml_string(session.urdf.last.data)
    assert robot.get_root() == "body_h1"
    poses = _world_poses(session.tf.messages)
    # A joint_states message and the TF of the same stamp: FK of the URDF from the root
    # frame body_1 and the joint angles gives every REP 155 link frame's position.
    checked = 0
    for msg in session.joints.messages:
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        if (stamp, "body_h1") not in poses or (stamp, "human_1/l_hand") not in poses:
            continue
        root = poses[(stamp, "body_h1")][None]
        fk = forward_kinematics(robot, root, {n: np.array([q]) for n, q in
                                              zip(msg.name, msg.position, strict=True)})
        hips = (poses[(stamp, "l_hip_h1")][:3, 3] + poses[(stamp, "r_hip_h1")][:3, 3]) / 2
        # REP 155: the body frame's origin at the hips' midpoint (the played motion keeps
        # its pelvis -> hip bones rigid; test_rep155_urdf bounds the slack of others).
        np.testing.assert_allclose(poses[(stamp, "body_h1")][:3, 3], hips, atol=1e-3)
        for name in JOINT_NAMES:
            link = urdf.link_name(name, "h1", rep155=True)
            np.testing.assert_allclose(fk[link][0, :3, 3], poses[(stamp, link)][:3, 3],
                                       atol=1e-3, err_msg=link)
            # ... which sit on today's human_1/<joint> frames of the same stamp.
            np.testing.assert_allclose(poses[(stamp, link)][:3, 3],
                                       poses[(stamp, f"human_1/{name}")][:3, 3], atol=1e-6)
        checked += 1
    assert checked >= 3


def test_position_and_velocity_follow_the_body_frame(session) -> None:
    poses = _world_poses(session.tf.messages)
    matched = 0
    for msg in session.position.messages:
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        assert msg.header.frame_id == "world"
        if (stamp, "body_h1") in poses:
            np.testing.assert_allclose([msg.point.x, msg.point.y, msg.point.z],
                                       poses[(stamp, "body_h1")][:3, 3], atol=1e-9)
            matched += 1
    assert matched >= 3
    speeds = [np.linalg.norm([m.twist.linear.x, m.twist.linear.y, m.twist.linear.z])
              for m in session.velocity.messages]
    assert all(np.isfinite(speeds)) and max(speeds) < 3.0     # a walking worker
    assert session.velocity.last.header.frame_id == "world"


def test_rep155_frames_form_one_tree_under_body(session) -> None:
    parents = {}
    for msg in session.tf.messages:
        for t in msg.transforms:
            parents[t.child_frame_id] = t.header.frame_id
    assert parents["body_h1"] == "world"
    # Every URDF link is on TF under the same parent as in the URDF (what
    # robot_state_publisher would publish), so RViz's RobotModel finds all of them.
    robot = urdf_parser.URDF.from_xml_string(session.urdf.last.data)
    for joint in robot.joints:
        assert parents[joint.child] == joint.parent, joint.name
    for j, name in enumerate(JOINT_NAMES):
        link = urdf.link_name(name, "h1", rep155=True)
        expected = "body_h1" if j == 0 else urdf.bone_chain(name, "h1")[-1]
        assert parents[link] == expected
    assert "head_h1" in parents and "body_h2" in parents
    assert all(f.endswith(("_h1", "_h2")) for f in parents if not f.startswith("human_"))


def test_human_description_parameter_holds_the_urdf(session) -> None:
    """REP 155: the URDF of body <id> is the parameter ``human_description_<id>``."""
    response = session.call(GetParameters, "/human_1/skeleton_publisher/get_parameters",
                            GetParameters.Request(names=["human_description_h1"]),
                            timeout=30.0, resend_after=3.0)
    assert response.values[0].string_value == session.urdf.last.data
