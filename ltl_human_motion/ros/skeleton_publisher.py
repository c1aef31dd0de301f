"""The skeleton publisher: plays a synthesized motion in real time on TF and markers.

Publishes, at ``publish_rate`` (stamps and playback time come from the node clock, so
``use_sim_time`` works):

* ``/tf`` (tf2_msgs/TFMessage): ``<world_frame>`` -> ``human_<id>/pelvis`` ->
  ``human_<id>/<joint>`` for the 23 joints of ``motion.skeleton``, following ``PARENTS``.
  The pelvis frame carries the body heading (yaw about +z, x forward, y left, z up);
  every other joint frame has the identity rotation relative to its parent (so it is
  oriented like the pelvis frame) and the bone vector as translation. Frames are not
  bone-aligned (see :mod:`ltl_human_motion.ros.conversions`).
* ``/tf_static``: ``<world_frame>`` -> ``cell/<region>`` at the centre of each region of
  ``cell`` (transient-local, as tf2's static broadcaster).
* ``markers_topic`` (visualization_msgs/MarkerArray, default ``/markers``), namespaces
  ``human_<id>/bones`` (LINE_LIST), ``/joints`` (SPHERE_LIST), ``/capsules`` (a CYLINDER
  and two SPHEREs per body capsule), ``/objects`` (CUBEs; they move while carried),
  ``/task`` (TEXT_VIEW_FACING over the head), and every ``scene_period`` seconds the cell:
  ``cell/regions`` (translucent CUBEs), ``cell/region_labels``, ``cell/obstacles``
  (TRIANGLE_LIST of the obstacle meshes).
* ``task_state`` (ltl_human_motion/msg/TaskState): the current task, progress and the
  playback state (``playing``/``paused``/``finished``/``stopped``, rate, loop), which lets
  an occupancy node in another process follow this playback.
* With ``rep155`` (default true), the REP 155 (ROS4HRI) body interface of
  :mod:`ltl_human_motion.ros.hri`: ``/humans/bodies/tracked``, ``/humans/bodies/<id>/``
  ``joint_states``, ``urdf``, ``position``, ``velocity``, and the frames ``body_<id>``,
  ``head_<id>``, ... (all URDF joint links unless ``rep155_link_frames`` is false), at
  ``rep155_rate`` (10 Hz; every n-th tick).

Service ``play_motion`` (ltl_human_motion/srv/PlayMotion): ``play`` (motion_id, loop,
rate), ``stop``, ``pause``, ``resume``. Motions come from the shared
:class:`~ltl_human_motion.planning.motion_store.MotionStore` (same process) or from the
folder announced on ``catalog_topic`` (``/motion_catalog``) by the synthesis node.

Parameters: ``human_id`` ("1"), ``world_frame`` ("world"), ``publish_rate`` (30.0 Hz),
``cell`` ("paper_cell"; "" for no cell markers), ``scene_period`` (2.0 s), ``motion_id``
("" ; played as soon as it is known), ``autoplay`` (false; play every newly announced
motion), ``loop`` (false), ``playback_rate`` (1.0), ``marker_lifetime`` (1.0 s),
``store_dir`` (""), ``catalog_topic`` ("/motion_catalog"), ``markers_topic``
("/markers").
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from geometry_msgs.msg import TransformStamped
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.node import Node
from rclpy.parameter import Parameter
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from ltl_human_motion.motion.skeleton import JOINT_INDEX, PARENTS
from ltl_human_motion.msg import MotionCatalog, TaskState
from ltl_human_motion.planning.motion_store import MotionSource, MotionStore, check_motion_id
from ltl_human_motion.planning.playback import PLAYING, STOPPED, Frame, Playback
from ltl_human_motion.ros import conversions as cv
from ltl_human_motion.ros.common import (
    LATCHED_QOS,
    STREAM_QOS,
    TF_QOS,
    TF_STATIC_QOS,
    now_seconds,
    resolve_cell,
)
from ltl_human_motion.ros.diagnostics import OK, Status, attach_diagnostics
from ltl_human_motion.ros.hri import BodyInterface
from ltl_human_motion.ros.params import (
    ParamSpec,
    declare_parameters,
    frame_id,
    identifier,
    non_negative,
    positive,
    topic_name,
)
from ltl_human_motion.srv import PlayMotion

_BONE_PAIRS = np.array([(p, j) for j, p in enumerate(PARENTS) if p >= 0])


def skeleton_parameters() -> list[ParamSpec]:
    """The skeleton publisher's parameters."""
    return [
        ParamSpec("human_id", "1", "Id of the human (frames human_<id>/...)", identifier,
                  read_only=True, dynamic_typing=True),
        ParamSpec("world_frame", "world", "Fixed frame of the cell", frame_id, read_only=True),
        ParamSpec("publish_rate", 30.0, "TF, marker and task state rate (Hz)", positive),
        ParamSpec("cell", "paper_cell", "Cell shown as markers ('' for none)", read_only=True),
        ParamSpec("scene_period", 2.0, "Seconds between cell marker messages", positive,
                  read_only=True),
        ParamSpec("motion_id", "", "Motion played as soon as it is known ('' for none)",
                  lambda v: None if v == "" else _id_error(v)),
        ParamSpec("autoplay", False, "Play every newly announced motion"),
        ParamSpec("loop", False, "Loop playback"),
        ParamSpec("playback_rate", 1.0, "Playback rate (1.0 is real time)", positive),
        ParamSpec("marker_lifetime", 1.0, "Lifetime of moving markers (s; 0 = forever)",
                  non_negative),
        ParamSpec("store_dir", "", "Folder of <motion_id>.npz ('' = use the catalog's)",
                  read_only=True),
        ParamSpec("catalog_topic", "/motion_catalog", "Latched MotionCatalog topic",
                  topic_name, read_only=True),
        ParamSpec("markers_topic", "/markers", "MarkerArray topic", topic_name, read_only=True),
        ParamSpec("rep155", True, "Publish the REP 155 body interface (/humans/bodies/...)",
                  read_only=True),
        ParamSpec("rep155_rate", 10.0, "Rate (Hz) of the REP 155 topics and frames (at most "
                  "publish_rate)", positive, read_only=True),
        ParamSpec("rep155_link_frames", True, "Put every URDF joint link (body_<id>, "
                  "head_<id>, ...) on TF; false: only world -> body_<id> (when "
                  "robot_state_publisher runs with the URDF)", read_only=True),
    ]


def _id_error(value: Any) -> str | None:
    try:
        check_motion_id(value)
    except ValueError as exc:
        return str(exc)
    return None


class SkeletonPublisher(Node):
    """Plays one human's motion on TF, markers and ``task_state``.

    Parameters
    ----------
    store : MotionStore, optional
        The synthesis node's store when in the same process.
    playback : Playback, optional
        Share the playback clock with an occupancy node in the same process.
    """

    def __init__(self, *, store: MotionStore | None = None, playback: Playback | None = None,
                 node_name: str = "skeleton_publisher", **node_kwargs: Any) -> None:
        super().__init__(node_name, **node_kwargs)
        declare_parameters(self, skeleton_parameters())
        self.human_id = str(self.param("human_id"))
        self.world_frame: str = self.param("world_frame")
        store_dir = self.param("store_dir")
        self.source = MotionSource(store if store is not None
                                   else MotionStore(store_dir) if store_dir else None)
        self.playback = playback if playback is not None else Playback()
        self.cell = self._load_cell(self.param("cell"))
        self._capsules_ok = True
        self._published_keys: set[tuple[str, int]] = set()
        self.frames_published = 0

        self._tf_pub = self.create_publisher(TFMessage, "/tf", TF_QOS)
        self._tf_static_pub = self.create_publisher(TFMessage, "/tf_static", TF_STATIC_QOS)
        self._marker_pub = self.create_publisher(MarkerArray, self.param("markers_topic"),
                                                 STREAM_QOS)
        self._state_pub = self.create_publisher(TaskState, "task_state", STREAM_QOS)
        self.create_subscription(MotionCatalog, self.param("catalog_topic"), self._on_catalog,
                                 LATCHED_QOS)
        self._service = self.create_service(PlayMotion, "play_motion", self._on_play,
                                            callback_group=MutuallyExclusiveCallbackGroup())
        self._timer_group = MutuallyExclusiveCallbackGroup()
        self._timer = self.create_timer(1.0 / self.param("publish_rate"), self._tick,
                                        callback_group=self._timer_group)
        # The cell goes out from the tick (not a timer of its own in the same group, which a
        # tick that is always due, on a loaded machine, would starve).
        self._scene_period = float(self.param("scene_period"))
        self._scene_due = 0.0
        self.body = BodyInterface(self, self.human_id, self.world_frame,
                                  self.param("rep155_link_frames")) \
            if self.param("rep155") else None
        self._ticks = 0
        self._body_every = 1
        self._set_body_every(self.param("publish_rate"))
        self.add_post_set_parameters_callback(self._on_parameters_set)
        attach_diagnostics(self, self.diagnostics)
        self._publish_static_frames()
        self._publish_scene()
        wanted = self.param("motion_id")
        if wanted and wanted in self.source.known():
            try:
                self._play(wanted, self.param("loop"), self.param("playback_rate"))
            except (KeyError, ValueError, OSError) as exc:
                self.get_logger().error(f"cannot play {wanted!r}: {exc}")

    def param(self, name: str) -> Any:
        return self.get_parameter(name).value

    def diagnostics(self) -> list[Status]:
        """The playback state for ``/diagnostics`` (always OK: stopped is a state)."""
        state = self.playback.state(now_seconds(self))
        motion = self.playback.motion_id if state != STOPPED else ""
        return [Status("playback", OK, f"{state} {motion}".strip(), {
            "state": state, "motion_id": motion, "rate": f"{self.playback.rate:g}",
            "loop": str(self.playback.loop).lower()})]

    # -- inputs ---------------------------------------------------------------------------
    def _load_cell(self, name: str) -> Any:
        if not name:
            return None
        try:
            return resolve_cell(name)
        except Exception as exc:   # the scene is optional for playback
            self.get_logger().warning(f"cell {name!r} not shown: {exc}")
            return None

    def _on_catalog(self, msg: MotionCatalog) -> None:
        new = self.source.on_catalog(msg)
        wanted = self.param("motion_id")
        now = now_seconds(self)
        idle = self.playback.state(now) == STOPPED
        target = None
        if wanted and wanted in new and (idle or self.playback.motion_id != wanted):
            target = wanted
        elif self.param("autoplay") and new:
            target = new[-1]
        if target is not None:
            try:
                self._play(target, self.param("loop"), self.param("playback_rate"))
            except (KeyError, ValueError, OSError) as exc:
                self.get_logger().error(f"cannot play {target!r}: {exc}")

    def _on_play(self, request: PlayMotion.Request,
                 response: PlayMotion.Response) -> PlayMotion.Response:
        command = request.command.strip().lower()
        now = now_seconds(self)
        try:
            if command == "play":
                motion_id = request.motion_id or self.playback.motion_id
                if not motion_id:
                    raise ValueError("no motion_id given and none played before")
                rate = request.rate if request.rate > 0 else 1.0
                self._play(motion_id, request.loop, rate)
                response.message = (f"playing {motion_id} ({self.playback.duration:.2f} s, "
                                    f"rate {rate:g}{', looped' if request.loop else ''})")
            elif command == "stop":
                self.playback.stop()
                response.message = "stopped"
            elif command == "pause":
                self.playback.pause(now)
                response.message = f"paused at {self.playback.motion_time(now):.2f} s"
            elif command == "resume":
                self.playback.resume(now)
                response.message = "resumed"
            else:
                raise ValueError(f"unknown command {request.command!r}; expected play, stop, "
                                 f"pause or resume")
            response.success = True
        except (KeyError, ValueError, OSError) as exc:
            response.success = False
            response.message = str(exc.args[0]) if isinstance(exc, KeyError) else str(exc)
            self.get_logger().warning(f"play_motion {command}: {response.message}")
        return response

    def _play(self, motion_id: str, loop: bool, rate: float) -> None:
        motion = self.source.get(motion_id)
        if self.body is not None:
            self.body.prepare(motion_id, motion)    # before the clock starts: may take a while
        self.playback.play(motion_id, motion, now_seconds(self), rate=rate, loop=loop)
        self.get_logger().info(f"playing {motion_id} ({self.playback.duration:.2f} s)")

    def _set_body_every(self, publish_rate: float) -> None:
        """REP 155 output on every n-th tick: ``rep155_rate`` out of ``publish_rate``."""
        self._body_every = max(1, round(publish_rate / self.param("rep155_rate")))

    def _on_parameters_set(self, params: list[Parameter]) -> None:
        for p in params:
            if p.name == "publish_rate":
                self._set_body_every(p.value)
                self._timer.cancel()
                self.destroy_timer(self._timer)
                self._timer = self.create_timer(1.0 / p.value, self._tick,
                                                callback_group=self._timer_group)
            elif p.name == "playback_rate" and self.playback.state(now_seconds(self)) != STOPPED:
                self.playback.set_rate(now_seconds(self), p.value)
            elif p.name == "motion_id" and p.value and p.value in self.source.known():
                try:
                    self._play(p.value, self.param("loop"), self.param("playback_rate"))
                except (KeyError, ValueError, OSError) as exc:
                    self.get_logger().error(f"cannot play {p.value!r}: {exc}")

    # -- outputs --------------------------------------------------------------------------
    def _tick(self) -> None:
        stamp_time = self.get_clock().now()
        stamp = stamp_time.to_msg()
        frame = self.playback.frame_at(stamp_time.nanoseconds * 1e-9)
        body_frames: list = []
        self._ticks += 1
        if self.body is not None and self._ticks % self._body_every == 0:
            body_frames = self.body.publish(frame, self.playback, stamp)
        if frame is None:
            self._clear_markers(stamp)
        else:
            self._tf_pub.publish(TFMessage(transforms=cv.skeleton_transforms(
                frame.positions, frame.yaw, self.human_id, self.world_frame, stamp)
                + body_frames))
            self._publish_markers(frame, stamp)
            self.frames_published += 1
        self._state_pub.publish(self._task_state(frame, stamp))
        if time.monotonic() >= self._scene_due:
            self._publish_scene()

    def _task_state(self, frame: Frame | None, stamp: Any) -> TaskState:
        msg = TaskState()
        msg.header.stamp = stamp
        msg.header.frame_id = self.world_frame
        msg.human_id = self.human_id
        msg.rate = self.playback.rate
        msg.loop = self.playback.loop
        if frame is None:
            msg.playback_state = STOPPED
            msg.task_index = -1
            return msg
        msg.motion_id = frame.motion_id
        msg.current_task = frame.task.current_task
        msg.next_task = frame.task.next_task
        msg.progress = frame.task.progress
        msg.task_index = frame.task.task_index
        msg.task_count = frame.task.task_count
        msg.motion_time = frame.time
        msg.motion_duration = self.playback.duration
        msg.playback_state = frame.state
        return msg

    def _publish_markers(self, frame: Frame, stamp: Any) -> None:
        ns = cv.human_prefix(self.human_id)
        f = cv.MarkerFactory(self.world_frame, stamp, self.param("marker_lifetime"))
        pos = frame.positions
        markers = [
            f.line_list(f"{ns}/bones", 0, pos[_BONE_PAIRS], cv.color(0.9, 0.9, 0.9), 0.02),
            f.sphere_list(f"{ns}/joints", 0, pos, cv.color(0.2, 0.4, 1.0), 0.05),
        ]
        if self._capsules_ok:
            try:
                segments, radii, _ = cv.body_capsules(pos, self.playback.stature)
                markers += f.capsules(f"{ns}/capsules", segments, radii,
                                      cv.color(0.3, 0.5, 0.9, 0.35))
            except ImportError as exc:
                self._capsules_ok = False
                self.get_logger().warning(f"no capsule markers: {exc}")
        for k, name in enumerate(sorted(frame.objects)):
            markers.append(f.cube(f"{ns}/objects", k, frame.objects[name],
                                  cv.object_size(self.cell, name), cv.color(0.95, 0.6, 0.1)))
        head = pos[JOINT_INDEX["head"]] + np.array([0.0, 0.0, 0.35])
        task = frame.task.current_task or (f"-> {frame.task.next_task}"
                                           if frame.task.next_task else "done")
        label = f"human {self.human_id}: {task}"
        if frame.state != PLAYING:
            label += f" [{frame.state}]"
        markers.append(f.text(f"{ns}/task", 0, head, label, 0.15, cv.color(1.0, 1.0, 1.0)))
        self._marker_pub.publish(MarkerArray(markers=markers))
        self._published_keys.update((m.ns, m.id) for m in markers)

    def _clear_markers(self, stamp: Any) -> None:
        if not self._published_keys:
            return
        keys = sorted(self._published_keys)
        self._published_keys.clear()
        self._marker_pub.publish(MarkerArray(
            markers=cv.delete_markers(keys, self.world_frame, stamp)))

    def _publish_scene(self) -> None:
        self._scene_due = time.monotonic() + self._scene_period
        if self.cell is None:
            return
        f = cv.MarkerFactory(self.world_frame, self.get_clock().now().to_msg())
        markers = cv.cell_markers(self.cell, f)
        if markers:
            self._marker_pub.publish(MarkerArray(markers=markers))

    def _publish_static_frames(self) -> None:
        if self.cell is None:
            return
        stamp = self.get_clock().now().to_msg()
        transforms = []
        for name, region in sorted(self.cell.regions.items()):
            centre = (region.lo + region.hi) / 2
            tf = TransformStamped()
            tf.header.stamp, tf.header.frame_id = stamp, self.world_frame
            tf.child_frame_id = f"cell/{name}"
            tf.transform.translation.x, tf.transform.translation.y, \
                tf.transform.translation.z = (float(v) for v in centre)
            tf.transform.rotation.w = 1.0
            transforms.append(tf)
        if transforms:
            self._tf_static_pub.publish(TFMessage(transforms=transforms))
