"""The REP 155 (ROS4HRI) body interface of one synthesized worker.

HRI software written for tracked humans (ROS4HRI's ``hri`` listeners, RViz's humans
plugins) reads bodies from these topics; the skeleton publisher offers them for its
worker, alongside its own ``/tf`` frames and markers:

Body ids are the human ids, prefixed with ``h`` when they start with a digit (a ROS name
token cannot): human ``1`` is body ``h1`` (topics ``/humans/bodies/h1/...``, frames
``body_h1``, ``head_h1``, ...).

* ``/humans/bodies/tracked`` (``hri_msgs/IdsList``): the ids of the bodies shown now.
  Every skeleton publisher publishes the whole list: its own id while it plays, plus the
  ids of the other bodies whose ``joint_states`` arrived within :data:`TRACKED_TIMEOUT`
  (found by topic discovery every :data:`DISCOVERY_PERIOD`), so the publishers of
  several humans, in one process or several, agree.
* ``/humans/bodies/<id>/joint_states`` (``sensor_msgs/JointState``): the 66 revolute
  joints of the worker's REP 155 URDF (:mod:`ltl_human_motion.motion.urdf` with
  ``rep155``: REP 155's joint names, ``l_p_shoulder_<id>``, ``l_elbow_<id>``, ...),
  radians.
* ``/humans/bodies/<id>/urdf`` (``std_msgs/String``, transient local): that URDF, for the
  stature of the motion played (republished when it changes); the same text is the
  node's parameter ``human_description_<id>`` (REP 155's ``/human_description_<bodyID>``).
* ``/humans/bodies/<id>/position`` (``geometry_msgs/PointStamped``) and ``/velocity``
  (``geometry_msgs/TwistStamped``): the body frame's origin and velocity in the world
  frame.
* TF: ``<world> -> body_<id>`` (REP 155's body frame: origin at the midpoint of the hips,
  x forward, z up) and, with ``link_frames``, every other link of the URDF as
  robot_state_publisher would put it (``body_<id> -> pelvis_<id>``, each bone's three
  rotations ``<parent>_<id> -> <child>_bone_<axis>_<id> -> ... -> <child>_bone_<id>``,
  then ``<child>_<id>`` at the joint's position), so RViz's RobotModel finds every link.
  Turn ``link_frames`` off when ``robot_state_publisher`` turns the URDF and
  ``joint_states`` into TF itself.

Per-frame link rotations and velocities are computed once per motion (:meth:`BodyInterface.prepare`,
before the playback clock starts);
a tick blends the rotations of the two frames around the playback time and takes the
interpolated joint positions, so the link frames sit exactly on the ``human_<id>/...``
joint frames of the same stamp, and joint angles come from the blended rotations.
"""

from __future__ import annotations

import re
import time
from typing import Any

import numpy as np
from geometry_msgs.msg import PointStamped, TransformStamped, TwistStamped
from hri_msgs.msg import IdsList
from rclpy.node import Node
from scipy.spatial.transform import Rotation
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion import urdf
from ltl_human_motion.motion.skeleton import JOINT_NAMES, PARENTS, Skeleton
from ltl_human_motion.planning.playback import Frame, Playback
from ltl_human_motion.ros.common import LATCHED_QOS, STREAM_QOS
from ltl_human_motion.ros.params import declare_or_set_string

BODIES = "/humans/bodies"
TRACKED_TOPIC = f"{BODIES}/tracked"
#: Seconds after its last joint_states message that another body still counts as tracked
#: (a 30 Hz publisher misses ~15 messages before it drops out).
TRACKED_TIMEOUT = 0.5
#: Seconds between two looks for other bodies' joint_states topics.
DISCOVERY_PERIOD = 2.0
#: Motions whose tables are kept (a player shows one at a time; a few for switching back).
MAX_TABLES = 4
_JOINT_STATES = re.compile(rf"^{BODIES}/([^/]+)/joint_states$")


def body_topic(human_id: str, name: str) -> str:
    """``/humans/bodies/<body id>/<name>`` (:func:`~ltl_human_motion.motion.urdf.body_id`)."""
    return f"{BODIES}/{urdf.body_id(human_id)}/{name}"


def _skeleton(stature: float) -> Skeleton:
    return Skeleton(stature=stature)


def link_quaternions(positions: np.ndarray, stature: float) -> np.ndarray:
    """Per frame, every joint link's world rotation as a quaternion (x y z w): (T, J, 4),
    each on the same hemisphere as the frame before (so frames can be blended)."""
    R = urdf.link_rotations(np.asarray(positions, dtype=np.float64), _skeleton(stature))
    q = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat().reshape(*R.shape[:2], 4)
    # Same hemisphere as the previous frame: flip where the running sign changes.
    dots = np.sum(q[1:] * q[:-1], axis=-1) < 0                           # (T-1, J)
    signs = np.concatenate([np.ones((1, q.shape[1])),
                            np.cumprod(np.where(dots, -1.0, 1.0), axis=0)])
    return q * signs[..., None]


def blend_quaternions(quats: np.ndarray, time: float, fps: float) -> np.ndarray:
    """World link rotations (J, 4: x y z w) at motion ``time`` (s): the quaternions
    (T, J, 4) of the two frames around it, blended linearly and normalized."""
    f = float(np.clip(time * fps, 0.0, len(quats) - 1))
    i0 = int(np.floor(f))
    i1 = min(i0 + 1, len(quats) - 1)
    q = quats[i0] * (1.0 - (f - i0)) + quats[i1] * (f - i0)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def link_transforms(positions: np.ndarray, quats: np.ndarray) -> np.ndarray:
    """Transforms (J, 7: x y z qx qy qz qw) of every link relative to its skeleton parent
    (the root's: to the world) for one pose: joint positions (J, 3) and world link
    rotations (J, 4). The link origins are the joint positions exactly."""
    pos = np.asarray(positions, dtype=np.float64)
    q = np.asarray(quats, dtype=np.float64)
    parents = np.array(PARENTS[1:])
    parent = Rotation.from_quat(q[parents])
    R_parent = parent.as_matrix()
    out = np.empty((len(JOINT_NAMES), 7))
    out[0, :3], out[0, 3:] = pos[0], q[0]
    out[1:, :3] = np.einsum("kji,kj->ki", R_parent, pos[1:] - pos[parents])
    out[1:, 3:] = (parent.inv() * Rotation.from_quat(q[1:])).as_quat()
    return out


def body_origins(pelvis: np.ndarray, pelvis_quaternions: np.ndarray, stature: float
                 ) -> np.ndarray:
    """REP 155 body frame origins (..., 3): the midpoint of the hips, from the pelvis
    joint's positions (..., 3) and the pelvis link's quaternions (..., 4: x y z w)."""
    offset = urdf.hip_offset(_skeleton(stature))
    R = Rotation.from_quat(np.reshape(pelvis_quaternions, (-1, 4)))
    return np.asarray(pelvis, dtype=np.float64) + R.apply(offset).reshape(np.shape(pelvis))


def body_velocity(origins: np.ndarray, root_quaternions: np.ndarray, fps: float
                  ) -> np.ndarray:
    """Per frame, the body frame's linear and angular velocity in the world frame: (T, 6),
    from its origins (T, 3) and quaternions (T, 4)."""
    origins = np.asarray(origins, dtype=np.float64)
    out = np.zeros((len(origins), 6))
    if len(origins) < 2:
        return out
    out[:, :3] = np.gradient(origins, axis=0) * fps
    R = Rotation.from_quat(root_quaternions)
    step = (R[1:] * R[:-1].inv()).as_rotvec() * fps
    out[1:, 3:] = step
    out[0, 3:] = step[0]
    return out


class BodyInterface:
    """The REP 155 publishers of one worker, driven by its skeleton publisher's ticks.

    Parameters
    ----------
    node : Node
        The skeleton publisher.
    human_id, world_frame : str
    link_frames : bool
        Also put every joint's link frame on TF (see the module docstring).
    """

    def __init__(self, node: Node, human_id: str, world_frame: str,
                 link_frames: bool) -> None:
        self.node, self.human_id, self.world_frame = node, human_id, world_frame
        self.body_id = urdf.body_id(human_id)
        self.link_frames = link_frames
        self._tracked_pub = node.create_publisher(IdsList, TRACKED_TOPIC, STREAM_QOS)
        self._joint_pub = node.create_publisher(JointState, body_topic(human_id,
                                                                       "joint_states"),
                                                STREAM_QOS)
        self._urdf_pub = node.create_publisher(String, body_topic(human_id, "urdf"),
                                               LATCHED_QOS)
        self._position_pub = node.create_publisher(PointStamped,
                                                   body_topic(human_id, "position"),
                                                   STREAM_QOS)
        self._velocity_pub = node.create_publisher(TwistStamped,
                                                   body_topic(human_id, "velocity"),
                                                   STREAM_QOS)
        self.joint_names = urdf.joint_names(self.body_id, rep155=True)
        self.link_names = [urdf.link_name(j, self.body_id, rep155=True) for j in JOINT_NAMES]
        self.body_frame = f"body_{self.body_id}"
        #: Per bone: its three revolute joints' links (urdf.bone_chain) and unit axes.
        self._chains = [urdf.bone_chain(JOINT_NAMES[j], self.body_id)
                        for j in range(1, len(JOINT_NAMES))]
        self._axes = np.array([np.eye(3)["xyz".index(a)] for j in range(1, len(JOINT_NAMES))
                               for a in urdf.bone_joint(JOINT_NAMES[j]).axes])
        self.description_parameter = f"human_description_{self.body_id}"
        self._urdf_stature: float | None = None
        self._tables: BoundedCache[tuple[float, np.ndarray, np.ndarray]] = \
            BoundedCache(MAX_TABLES)
        self._last_seen: dict[str, float] = {}
        self._subscribed: set[str] = set()
        self.publish_urdf(1.75)
        node.create_timer(DISCOVERY_PERIOD, self._discover)

    def publish_urdf(self, stature: float) -> None:
        """Latch the URDF for ``stature`` (only when it changes)."""
        if self._urdf_stature is not None and abs(self._urdf_stature - stature) < 1e-9:
            return
        self._urdf_stature = stature
        text = urdf.worker_urdf(stature, self.body_id, rep155=True)
        declare_or_set_string(self.node, self.description_parameter, text,
                              "REP 155 URDF of this body (as on its urdf topic)")
        self._urdf_pub.publish(String(data=text))

    def prepare(self, motion_id: str, motion: Any) -> tuple[float, np.ndarray, np.ndarray]:
        """Per-frame tables of ``motion`` (a SynthesizedMotion): stature, link quaternions
        (T, J, 4) and body velocity (T, 6); computed once per motion id and kept (the
        skeleton publisher calls this before it starts the playback clock)."""
        def build() -> tuple[float, np.ndarray, np.ndarray]:
            body = motion.motion
            stature = float(body.skeleton.stature)
            positions = np.asarray(body.positions, dtype=np.float64)
            quats = link_quaternions(positions, stature)
            origins = body_origins(positions[:, 0], quats[:, 0], stature)
            return stature, quats, body_velocity(origins, quats[:, 0], float(body.fps))
        return self._tables.get_or_build(motion_id, build)

    def _discover(self) -> None:
        for topic, _ in self.node.get_topic_names_and_types():
            match = _JOINT_STATES.match(topic)
            if match is None or topic in self._subscribed or match[1] == self.body_id:
                continue
            other = match[1]
            self._subscribed.add(topic)
            self.node.create_subscription(
                JointState, topic, lambda _msg, who=other: self._seen(who), STREAM_QOS,
                raw=True)

    def _seen(self, other: str) -> None:
        self._last_seen[other] = time.monotonic()

    def tracked(self, playing: bool) -> list[str]:
        """The body ids shown now (this one while ``playing``), sorted."""
        now = time.monotonic()
        ids = {k for k, t in self._last_seen.items() if now - t <= TRACKED_TIMEOUT}
        if playing:
            ids.add(self.body_id)
        return sorted(ids)

    def _link_edges(self, rows: np.ndarray, angles: np.ndarray, stature: float
                    ) -> list[tuple[str, str, np.ndarray]]:
        """(parent, child, x y z qx qy qz qw) of every URDF link below ``body_<id>``, as
        robot_state_publisher would give them from the URDF and ``angles`` (66,), except
        that each joint link sits at the joint's position (``rows``: (J, 7) of
        :func:`link_transforms`)."""
        pelvis = np.concatenate([-urdf.hip_offset(_skeleton(stature)), [0, 0, 0, 1.0]])
        edges = [(self.body_frame, self.link_names[0], pelvis)]
        rotations = Rotation.from_rotvec(
            (self._axes * angles[:, None]).reshape(-1, 3)).as_quat().reshape(-1, 3, 4)
        for j in range(1, len(JOINT_NAMES)):
            chain = [self.link_names[PARENTS[j]], *self._chains[j - 1]]
            for k in range(3):
                edges.append((chain[k], chain[k + 1],
                              np.concatenate([np.zeros(3), rotations[j - 1, k]])))
            offset = Rotation.from_quat(rows[j, 3:]).inv().apply(rows[j, :3])
            edges.append((chain[-1], self.link_names[j],
                          np.concatenate([offset, [0.0, 0.0, 0.0, 1.0]])))
        return edges

    def publish(self, frame: Frame | None, playback: Playback, stamp: Any
                ) -> list[TransformStamped]:
        """One tick: ``tracked`` always, the body's topics while shown; returns the body's
        TF transforms (the skeleton publisher sends them with its own, in one message)."""
        tracked = IdsList(ids=self.tracked(frame is not None))
        tracked.header.stamp = stamp
        tracked.header.frame_id = self.world_frame
        self._tracked_pub.publish(tracked)
        if frame is None:
            return []
        tables = self._tables.get(frame.motion_id)
        if tables is None and playback.motion is not None:  # played by another node
            tables = self.prepare(frame.motion_id, playback.motion)
        if tables is None:
            return []
        stature, quats, velocity = tables
        self.publish_urdf(stature)
        rotations = blend_quaternions(quats, frame.time, playback.fps)
        rows = link_transforms(frame.positions, rotations)
        joints = JointState(name=self.joint_names, position=urdf.angles_from_local_quaternions(
            rows[None, 1:, 3:])[0].tolist())
        joints.header.stamp = stamp
        self._joint_pub.publish(joints)
        i = min(frame.index, len(velocity) - 1)
        origin = body_origins(rows[0, :3], rows[0, 3:], stature)
        position = PointStamped()
        position.header.stamp, position.header.frame_id = stamp, self.world_frame
        x, y, z = (float(v) for v in origin)
        position.point.x, position.point.y, position.point.z = x, y, z
        self._position_pub.publish(position)
        twist = TwistStamped()
        twist.header.stamp, twist.header.frame_id = stamp, self.world_frame
        v = velocity[i]
        twist.twist.linear.x, twist.twist.linear.y, twist.twist.linear.z = map(float, v[:3])
        twist.twist.angular.x, twist.twist.angular.y, twist.twist.angular.z = map(float,
                                                                                 v[3:])
        self._velocity_pub.publish(twist)
        edges = [(self.world_frame, self.body_frame, np.concatenate([origin, rows[0, 3:]]))]
        if self.link_frames:
            edges += self._link_edges(rows, np.asarray(joints.position), stature)
        transforms = []
        for parent, child, row in edges:
            t = TransformStamped()
            t.header.stamp = stamp
            t.header.frame_id, t.child_frame_id = parent, child
            tr, q = t.transform.translation, t.transform.rotation
            tr.x, tr.y, tr.z = (float(a) for a in row[:3])
            q.x, q.y, q.z, q.w = (float(a) for a in row[3:])
            transforms.append(t)
        return transforms
