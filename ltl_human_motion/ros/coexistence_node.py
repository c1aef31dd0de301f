"""The coexistence node: human occupancy in, UR speed slider out (ISO/TS 15066 SSM).

A thin rclpy layer over :class:`~ltl_human_motion.robot.coexistence.CoexistenceController`.
The control loop runs on a thread of its own at ``rate`` Hz (125 by default, the rate of
a UR e-Series' RTDE interface); it reads the arm's joint positions through ``ur_rtde``,
computes the separation between the arm's capsules and every human's capsules and writes
the speed slider. Running it outside the executor keeps its timing independent of the
other callbacks of the process (a one-process bringup spins a dozen of them).

Subscribes to ``ltl_human_motion/msg/HumanOccupancy``: with ``occupancy_topic: auto``
(default) every topic of that type is found and followed (checked once per second), so
the node guards the arm against all humans at once; otherwise only the named topic. The
separation is the minimum over all humans, and the occupancy counts as fresh only while
every known human's stream is fresh: a human whose stream stops holds the arm at the
slider minimum (until ``forget_after`` s of silence, when set, drop them). Predicted
occupancy is used when ``use_prediction`` is true.

Freshness is judged per human on the node's own clock: a sample's time is its receive time
less its age (never later than its receipt), so no stamp can make a silent stream look
fresh. A sample stamped more than ``future_tolerance`` s in the future, one that does not
decode, or one with NaN, absurd or malformed capsules is a fault of that human: the
occupancy is dropped at once (slider minimum) until the human sends a valid sample again
(or is forgotten). A human seen only through faulty samples counts as well.

Publishes (at ``publish_rate``):

* ``/joint_states`` (sensor_msgs/JointState): the six UR joints
  (``<joint_prefix>shoulder_pan_joint`` ... ``wrist_3_joint``) as read over RTDE.
* ``/tf``: the arm's links as ur_description names and places them
  (:mod:`ltl_human_motion.ros.ur_frames`): ``<tf_prefix>base_link_inertia`` ->
  ``shoulder_link`` -> ``upper_arm_link`` -> ``forearm_link`` -> ``wrist_1_link`` ->
  ``wrist_2_link`` -> ``wrist_3_link``; ``/tf_static``: ``<world_frame>`` ->
  ``<tf_prefix>base_link`` (from the base pose parameters, which place the controller's
  ``base``), ``base_link`` -> ``base`` and ``base_link_inertia``, ``wrist_3_link`` ->
  ``flange`` -> ``tool0`` (the flange, DH frame 6) -> ``tool_tip`` (``tool_length`` along
  z).
* ``safety_status`` (ltl_human_motion/msg/SafetyStatus): separation, effective
  separation, S_p, slider command, mode and connection of the latest control step.
* ``markers_topic`` (``/robot_markers``, at ``marker_rate``): the arm's collision capsules
  (namespace ``robot/capsules``, coloured by mode) and a label with mode and slider.

Fail-safe behaviour comes from the controller: no or stale occupancy, a lost connection
or a rejected occupancy never raise the speed (see :mod:`ltl_human_motion.robot.coexistence`).

A lifecycle (managed) node: with ``autostart`` (the default) it configures and activates
itself at once, with ``autostart: false`` it waits for ``<node>/change_state``.
*Configure* loads the arm's model (with the tool), its base pose and the distance kernel,
and connects nothing. *Activate* connects over RTDE, follows the occupancy, runs the
control loop and publishes (``/tf_static`` once). *Deactivate* (and *shutdown*, an error,
destroying the node) stops following the occupancy and publishing, then leaves the arm
at ``min_slider`` -- the slider the node commands when the occupancy goes stale, since
nothing watches the worker any more -- waits until the controller reports it in
``target_speed_fraction`` (:attr:`CoexistenceNode.held` says whether it did, and why not)
and disconnects. The controller keeps that slider until a client writes another one;
*activate* starts again from the minimum (no occupancy yet). *Cleanup* forgets the model.
With ``metrics_out`` set, the node keeps every control decision and writes the
commissioning report (``coexistence.json`` and ``coexistence.png``) there when destroyed.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import rclpy.logging
from geometry_msgs.msg import TransformStamped
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.impl.rcutils_logger import RcutilsLogger
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from ltl_human_motion.kernel.rotations import quaternion_from_matrix
from ltl_human_motion.kernel.segments import compiled
from ltl_human_motion.msg import HumanOccupancy, SafetyStatus
from ltl_human_motion.robot.coexistence import (
    CoexistenceConfig,
    CoexistenceController,
    ControlDecision,
    IOLike,
    ReceiveLike,
    ur_rtde_factories,
)
from ltl_human_motion.robot.fusion import OccupancySample, fuse_occupancies
from ltl_human_motion.robot.kinematics import (
    UR_MODELS,
    URModel,
    pose_from_xyz_rpy,
    robot_capsules,
    ur_model,
)
from ltl_human_motion.robot.metrics import DecisionRecorder, write_commissioning_report
from ltl_human_motion.robot.rtde_probe import probed_factories
from ltl_human_motion.robot.ssm import SLIDER_MIN, SSMParameters
from ltl_human_motion.ros import conversions as cv
from ltl_human_motion.ros import ur_frames
from ltl_human_motion.ros.common import STREAM_QOS, TF_QOS, TF_STATIC_QOS
from ltl_human_motion.ros.diagnostics import ERROR, OK, WARN, Status, attach_diagnostics
from ltl_human_motion.ros.occupancy_decode import decode_human_occupancy, occupancy_from_message
from ltl_human_motion.ros.params import (
    ParamSpec,
    declare_parameters,
    frame_id,
    in_range,
    non_negative,
    positive,
    topic_name,
)

__all__ = ["CONTROL_SWITCH_INTERVAL", "OCCUPANCY_TYPE", "UR_JOINT_NAMES", "CoexistenceNode",
           "OccupancySample", "coexistence_parameters", "decode_human_occupancy",
           "occupancy_from_message"]

#: Joint names of Universal Robots' ROS 2 driver and description.
UR_JOINT_NAMES = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                  "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
OCCUPANCY_TYPE = "ltl_human_motion/msg/HumanOccupancy"
#: ``sys.setswitchinterval`` for processes running the control loop (Python's default is
#: 5 ms, the longest a thread waiting for the GIL may wait for a busy one). Sharing a
#: process with a player and a predicting occupancy node, the loop held 125 Hz in both
#: modes with 0.2 ms, against 100 / 39 Hz (reactive / predictive) with 1 ms
#: (bench/coexistence_loop.py, 2 cores).
CONTROL_SWITCH_INTERVAL = 0.0002
#: Seconds between two "robot controller not reachable" warnings.
REFUSAL_LOG_PERIOD = 10.0
_MODE_COLORS = {"full": (0.2, 0.8, 0.2), "reduced": (1.0, 0.8, 0.0), "stop": (0.9, 0.1, 0.1),
                "stale": (0.5, 0.5, 0.5), "disconnected": (0.3, 0.3, 0.3)}

# Parameter name -> SSMParameters field.
_SSM_FIELDS = {
    "human_speed": "human_speed", "robot_speed": "robot_speed",
    "reaction_time": "reaction_time", "stopping_time": "stopping_time",
    "stopping_distance": "stopping_distance", "intrusion_distance": "intrusion_distance",
    "sensor_uncertainty": "sensor_uncertainty", "robot_uncertainty": "robot_uncertainty",
    "margin": "margin", "min_slider": "min_slider", "max_slider": "max_slider",
    "prediction_discount_speed": "prediction_discount_speed",
}


def _model_name(value: Any) -> str | None:
    ok = isinstance(value, str) and value.lower() in UR_MODELS
    return None if ok else f"expected one of {sorted(UR_MODELS)}, got {value!r}"


def _host(value: Any) -> str | None:
    ok = isinstance(value, str) and bool(value.strip()) and " " not in value.strip()
    return None if ok else f"expected a host name or IP address, got {value!r}"


def _finite(value: Any) -> str | None:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    return None if ok else f"expected a finite number, got {value!r}"


def _occupancy_topic(value: Any) -> str | None:
    return None if value == "auto" else topic_name(value)


def _tf_prefix(value: Any) -> str | None:
    ok = isinstance(value, str) and (value == "" or frame_id(value + "x") is None)
    return None if ok else f"expected a TF frame prefix such as 'ur/', got {value!r}"


def coexistence_parameters() -> list[ParamSpec]:
    """The coexistence node's parameters (defaults: the UR5e of config/ur_pick_place.yaml
    and the SSM defaults of :class:`~ltl_human_motion.robot.ssm.SSMParameters`)."""
    ssm = SSMParameters()
    spec = ParamSpec
    return [
        spec("robot_host", "127.0.0.1", "Robot controller (or URSim / simulator) address; "
             "ur_rtde uses TCP 30004", _host, read_only=True),
        spec("model", "ur5e", "UR model (ur3e, ur5e, ur10e, ur16e)", _model_name,
             read_only=True),
        spec("tool_length", 0.15, "Tool capsule length along the flange z axis (m)",
             non_negative, read_only=True),
        spec("tool_radius", 0.05, "Tool capsule radius (m)", non_negative, read_only=True),
        spec("base_x", 1.45, "Robot base x in the world frame (m)", _finite, read_only=True),
        spec("base_y", -1.3, "Robot base y in the world frame (m)", _finite, read_only=True),
        spec("base_z", 0.85, "Robot base z in the world frame (m)", _finite, read_only=True),
        spec("base_yaw", 2.62, "Robot base yaw about world z (rad)", _finite, read_only=True),
        spec("rate", 125.0, "Control loop rate (Hz)", in_range(1.0, 1000.0), read_only=True),
        spec("occupancy_topic", "auto", "HumanOccupancy topic, or 'auto' for every topic of "
             "that type (all humans)", _occupancy_topic, read_only=True),
        spec("stale_after", 0.25, "Occupancy older than this (s) is stale: slider minimum",
             positive, read_only=True),
        spec("future_tolerance", CoexistenceConfig().future_tolerance, "Occupancy stamped "
             "further than this (s) in the future is a fault: slider minimum", positive,
             read_only=True),
        spec("forget_after", 0.0, "A human whose stream has been silent this long (s) is "
             "dropped, so the others decide again (0 = never; until then: minimum)",
             non_negative, read_only=True),
        spec("robot_stale_after", 0.5, "Robot data frozen this long (s) = connection lost",
             positive, read_only=True),
        spec("human_speed", ssm.human_speed, "v_h: human approach speed (m/s)",
             non_negative, read_only=True),
        spec("robot_speed", ssm.robot_speed, "v_r: robot speed towards the human (m/s)",
             non_negative, read_only=True),
        spec("reaction_time", ssm.reaction_time, "T_r: sensing+processing latency (s)",
             non_negative, read_only=True),
        spec("stopping_time", ssm.stopping_time, "T_s: robot stopping time (s)",
             non_negative, read_only=True),
        spec("stopping_distance", ssm.stopping_distance, "S_s: robot stopping distance (m)",
             non_negative, read_only=True),
        spec("intrusion_distance", ssm.intrusion_distance, "C: intrusion distance (m)",
             non_negative, read_only=True),
        spec("sensor_uncertainty", ssm.sensor_uncertainty, "Z_d: sensing uncertainty (m)",
             non_negative, read_only=True),
        spec("robot_uncertainty", ssm.robot_uncertainty, "Z_r: robot position uncertainty (m)",
             non_negative, read_only=True),
        spec("margin", ssm.margin, "Band above S_p with linearly reduced speed (m)", positive,
             read_only=True),
        spec("min_slider", ssm.min_slider, "Slider minimum, standing for 'stop' (>= 0.01)",
             in_range(SLIDER_MIN, 1.0), read_only=True),
        spec("max_slider", ssm.max_slider, "Slider at full speed", in_range(SLIDER_MIN, 1.0),
             read_only=True),
        spec("prediction_discount_speed", ssm.prediction_discount_speed,
             "m/s: a predicted separation dt s ahead counts as d + v dt", non_negative,
             read_only=True),
        spec("use_prediction", True, "Use predicted occupancy (predictive SSM)",
             read_only=True),
        spec("metrics_out", "", "Folder for the commissioning report written at shutdown "
             "('' = none)", read_only=True),
        spec("world_frame", "world", "Fixed frame of the cell", frame_id, read_only=True),
        spec("tf_prefix", "ur/", "Prefix of the robot's TF frames", _tf_prefix,
             read_only=True),
        spec("joint_prefix", "", "Prefix of the joint names in /joint_states", read_only=True),
        spec("publish_rate", 50.0, "joint_states, TF and safety_status rate (Hz)",
             in_range(1.0, 500.0), read_only=True),
        spec("marker_rate", 10.0, "Robot marker rate (Hz; 0 = none)", non_negative,
             read_only=True),
        spec("markers_topic", "/robot_markers", "MarkerArray topic", topic_name,
             read_only=True),
        spec("autostart", True, "Configure and activate at once (false: wait for the "
             "lifecycle's change_state)", read_only=True),
    ]


@dataclass
class _Human:
    """What the node holds of one human: times on the controller's clock (s)."""

    received: float                       # receipt of the latest sample, valid or not
    fresh_at: float                       # time of the latest valid data; -inf after a fault
    sample: OccupancySample | None        # None until a valid sample arrives


# ---------------------------------------------------------------------- small helpers
def _transform(parent: str, child: str, T: np.ndarray, stamp: Any) -> TransformStamped:
    tf = TransformStamped()
    tf.header.stamp = stamp
    tf.header.frame_id = parent
    tf.child_frame_id = child
    t = tf.transform.translation
    t.x, t.y, t.z = (float(v) for v in T[:3, 3])
    q = tf.transform.rotation
    q.w, q.x, q.y, q.z = (float(v) for v in quaternion_from_matrix(T[:3, :3]))
    return tf


# ---------------------------------------------------------------------- the node
class CoexistenceNode(LifecycleNode):
    """Speed and separation monitoring of one UR arm against every human in the cell.

    Parameters
    ----------
    receive_factory, io_factory : callable, optional
        Connection factories (default: the real ``ur_rtde`` interfaces to ``robot_host``).
    record : bool, optional
        Keep every control decision in :attr:`recorder` (default: when ``metrics_out`` is
        set).
    on_decision : callable, optional
        Also called with every :class:`~ltl_human_motion.robot.coexistence.ControlDecision`
        (on the control thread).
    """

    def __init__(self, *, receive_factory: Callable[[], ReceiveLike] | None = None,
                 io_factory: Callable[[], IOLike] | None = None, record: bool | None = None,
                 on_decision: Callable[[ControlDecision], None] | None = None,
                 node_name: str = "coexistence_node", **node_kwargs: Any) -> None:
        # What destroy_node needs, even when the parameters below are refused (the
        # context destroys the half-made node at shutdown).
        self._thread: threading.Thread | None = None
        self.controller: CoexistenceController | None = None
        self.metrics_out: Path | None = None
        super().__init__(node_name, **node_kwargs)
        declare_parameters(self, coexistence_parameters())
        p = self.param
        try:
            self.params = SSMParameters(**{f: float(p(n)) for n, f in _SSM_FIELDS.items()})
            self.config = CoexistenceConfig(
                stale_after=float(p("stale_after")),
                future_tolerance=float(p("future_tolerance")),
                robot_stale_after=float(p("robot_stale_after")),
                use_prediction=bool(p("use_prediction")))
        except ValueError as exc:
            raise ValueError(f"{self.get_fully_qualified_name()}: invalid parameters: {exc}") \
                from None
        self.world_frame: str = p("world_frame")
        self.prefix: str = p("tf_prefix")
        self.joint_names = [p("joint_prefix") + name for name in UR_JOINT_NAMES]
        self.use_prediction = bool(p("use_prediction"))
        self.rate = float(p("rate"))
        self.forget_after = float(p("forget_after"))
        self.future_tolerance = float(p("future_tolerance"))
        metrics_out = p("metrics_out")
        self.metrics_out = Path(metrics_out) if metrics_out else None
        self.recorder = DecisionRecorder() \
            if (record if record is not None else self.metrics_out is not None) else None
        self._extra_on_decision = on_decision
        self._factories = (receive_factory, io_factory)
        # Set by configure (model, base, connection factories) and activate (controller).
        self.model: URModel | None = None
        self.base: np.ndarray | None = None
        self._connect_with: tuple[Callable[[], ReceiveLike], Callable[[], IOLike]] | None = None
        self._active = False
        self.held: str | None = None

        self._humans: dict[str, _Human] = {}
        self._topic_keys: dict[str, str] = {}             # topic -> key of its last sample
        self._humans_lock = threading.Lock()
        self._subscribed: set[str] = set()
        self._occupancy_subs: list[Any] = []
        self._active_timers: list[Any] = []
        self._latest: ControlDecision | None = None
        self.steps = 0
        self.messages_received = 0
        self.messages_rejected = 0
        # Controller-clock receipt times of faulty samples and of samples already stale on
        # arrival, and the time of the first step of the current run at the minimum slider:
        # together they give the node's own fault-to-minimum latency.
        self.fault_receipts: deque[float] = deque(maxlen=256)
        self.minimum_since: float | None = None

        publisher = self.create_lifecycle_publisher
        self._joint_pub = publisher(JointState, "/joint_states", STREAM_QOS)
        self._tf_pub = publisher(TFMessage, "/tf", TF_QOS)
        self._tf_static_pub = publisher(TFMessage, "/tf_static", TF_STATIC_QOS)
        self._status_pub = publisher(SafetyStatus, "safety_status", STREAM_QOS)
        self._marker_pub = publisher(MarkerArray, p("markers_topic"), STREAM_QOS)
        self._occ_group = MutuallyExclusiveCallbackGroup()
        self._pub_group = MutuallyExclusiveCallbackGroup()
        self._stop = threading.Event()
        attach_diagnostics(self, self.diagnostics)
        if p("autostart"):
            for name, trigger in (("configure", self.trigger_configure),
                                  ("activate", self.trigger_activate)):
                if trigger() != TransitionCallbackReturn.SUCCESS:
                    raise ValueError(f"{self.get_fully_qualified_name()}: autostart: the "
                                     f"{name} transition failed (see the log)")

    # ------------------------------------------------------------------ lifecycle
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Load the arm's model, its place in the cell and the distance kernel; connect
        nothing yet."""
        p = self.param
        try:
            self.model = ur_model(p("model")).with_tool(float(p("tool_length")),
                                                        float(p("tool_radius")))
            self.base = pose_from_xyz_rpy((p("base_x"), p("base_y"), p("base_z")),
                                          (0.0, 0.0, p("base_yaw")))
            compiled()
        except Exception as exc:     # any failure to load: the transition fails, named
            self.get_logger().error(f"configure failed: {type(exc).__name__}: {exc}")
            return TransitionCallbackReturn.FAILURE
        receive_factory, io_factory = self._factories
        if receive_factory is None or io_factory is None:
            host = p("robot_host")
            default_receive, default_io = probed_factories(
                ur_rtde_factories(host), host, self._report_refusal)
            receive_factory = receive_factory or default_receive
            io_factory = io_factory or default_io
        self._connect_with = (receive_factory, io_factory)
        return super().on_configure(state)

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Connect to the robot, follow the occupancy, run the control loop, publish."""
        if self.model is None or self._connect_with is None:
            return TransitionCallbackReturn.FAILURE       # not configured
        result = super().on_activate(state)
        p = self.param
        self.controller = CoexistenceController(
            *self._connect_with, self.model, self.base, self.params, self.config,
            on_decision=self._on_decision)
        self._latest, self.minimum_since, self.held = None, None, None
        with self._humans_lock:
            self._humans.clear()
            self._topic_keys.clear()
        timers = [(1.0 / p("publish_rate"), self._publish_state, self._pub_group)]
        if p("marker_rate") > 0:
            timers.append((1.0 / p("marker_rate"), self._publish_markers, self._pub_group))
        if p("occupancy_topic") == "auto":
            self._discover()
            timers.append((1.0, self._discover, None))
        else:
            self._subscribe(p("occupancy_topic"))
        self._active_timers = [self.create_timer(period, callback, callback_group=group)
                               for period, callback, group in timers]
        self._publish_static()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._control_loop, name="coexistence-control",
                                        args=(self.controller, self._stop), daemon=True)
        self._active = True
        self._thread.start()
        mode = "predictive" if self.use_prediction else "reactive"
        self.get_logger().info(
            f"{self.model.name} at {p('robot_host')}: {mode} SSM at {self.rate:g} Hz, "
            f"S_p = {self.params.protective_distance:.3f} m, occupancy from "
            f"{p('occupancy_topic')}")
        return result

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop publishing and following the occupancy; leave the arm at the minimum slider
        (see :meth:`stop_control`) and disconnect."""
        result = super().on_deactivate(state)
        self._stand_down()
        return result

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Forget the model and the connection factories (configure loads them again)."""
        self.model = self.base = self._connect_with = None
        return super().on_cleanup(state)

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._stand_down()
        return super().on_shutdown(state)

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._stand_down()
        return super().on_error(state)

    def _stand_down(self) -> None:
        self._active = False
        for timer in self._active_timers:
            self.destroy_timer(timer)
        for subscription in self._occupancy_subs:
            self.destroy_subscription(subscription)
        self._active_timers, self._occupancy_subs = [], []
        self._subscribed.clear()
        self.stop_control()

    @property
    def active(self) -> bool:
        """True while the node monitors the arm (lifecycle state active)."""
        return self._active

    def diagnostics(self) -> list[Status]:
        """The robot connection for ``/diagnostics``: ERROR when the control thread ended
        or the controller is not connected (the robot then gets no speed commands); WARN
        while the node is not active (nothing monitors the arm; what it was left at is
        said)."""
        d = self._latest
        host = self.param("robot_host")
        values = {"robot_host": host, "steps": str(self.steps),
                  "humans": str(len(self.humans))}
        if d is not None:
            values.update(mode=d.mode, slider=f"{d.slider:.3f}",
                          separation_m=f"{d.separation:.3f}")
        if not self._active:
            left = "" if self.held is None else f"; arm {self.held}"
            return [Status("robot connection", WARN, f"not active (lifecycle): not "
                           f"monitoring the robot at {host}{left}", values)]
        if not self.control_alive:
            return [Status("robot connection", ERROR, "control loop stopped", values)]
        if d is None or not d.connected:
            return [Status("robot connection", ERROR,
                           f"not connected to the robot controller at {host}", values)]
        return [Status("robot connection", OK, f"connected to {host} ({d.mode})", values)]

    def _live_logger(self) -> RcutilsLogger:
        """The node's logger; once its context is shut down (Ctrl-C, before the node is
        destroyed), one of another name that only prints: the rosout publisher is gone
        ("Failed to publish log message to rosout")."""
        if self.context.ok():
            return self.get_logger()
        return rclpy.logging.get_logger(f"{self.get_logger().name}.shutdown")

    def _report_refusal(self, message: str) -> None:
        """ur_rtde's bare "connect: Connection refused", as a throttled ROS warning."""
        self.get_logger().warning(f"{message}; retrying (is the robot, URSim or "
                                  f"`ltl-human-motion ur-sim` running?)",
                                  throttle_duration_sec=REFUSAL_LOG_PERIOD)

    def param(self, name: str) -> Any:
        return self.get_parameter(name).value

    # ------------------------------------------------------------------ occupancy input
    def _discover(self) -> None:
        for topic, types in self.get_topic_names_and_types():
            if OCCUPANCY_TYPE in types and topic not in self._subscribed:
                self._subscribe(topic)

    def _subscribe(self, topic: str) -> None:
        self._subscribed.add(topic)
        self._occupancy_subs.append(self.create_subscription(
            HumanOccupancy, topic, lambda data, t=topic: self._on_occupancy(t, data),
            STREAM_QOS, callback_group=self._occ_group, raw=True))
        self.get_logger().info(f"following human occupancy on {topic}")

    @property
    def humans(self) -> list[str]:
        """Keys of the humans whose occupancy the node holds."""
        with self._humans_lock:
            return sorted(self._humans)

    def _on_occupancy(self, topic: str, data: bytes) -> None:
        controller = self.controller
        if not self._active or controller is None:
            return
        self.messages_received += 1
        ctl_now = controller.clock()
        key = self._topic_keys.get(topic, topic)
        try:
            sample = decode_human_occupancy(data)
            key = sample.human_id or topic
            self._topic_keys[topic] = key
            age = self.get_clock().now().nanoseconds * 1e-9 - sample.stamp
            if not math.isfinite(age) or age < -self.future_tolerance:
                raise ValueError(f"stamp lies {-age:.3f} s in the future (tolerance "
                                 f"{self.future_tolerance:g} s)")
            fresh_at = ctl_now - max(age, 0.0)
            if ctl_now - fresh_at > self.config.stale_after:
                self.fault_receipts.append(ctl_now)
            controller.check_occupancy(sample.segments, sample.radii, fresh_at,
                                       sample.predicted or None)
        except ValueError as exc:
            self._fault(controller, topic, key, ctl_now, exc)
            return
        with self._humans_lock:
            self._humans[key] = _Human(ctl_now, fresh_at, sample)
            self._forget_silent(ctl_now)
            entries = list(self._humans.items())
        faulty = [k for k, h in entries if h.sample is None or not math.isfinite(h.fresh_at)]
        if faulty:
            controller.invalidate_occupancy(f"human {faulty[0]!r} has no valid occupancy")
            return
        fused = fuse_occupancies([(h.fresh_at, h.sample) for _, h in entries],  # type: ignore
                                 self.use_prediction)
        if not controller.update_occupancy(fused.segments, fused.radii, fused.stamp,
                                           fused.predicted, check_order=False):
            self.messages_rejected += 1

    def _fault(self, controller: CoexistenceController, topic: str, key: str, ctl_now: float,
               exc: Exception) -> None:
        """A faulty sample of human ``key``: hold them as faulty, drop the occupancy."""
        self.messages_rejected += 1
        self.fault_receipts.append(ctl_now)
        with self._humans_lock:
            human = self._humans.get(key)
            if human is None:
                self._humans[key] = _Human(ctl_now, -math.inf, None)
            else:
                human.received, human.fresh_at = ctl_now, -math.inf
            self._forget_silent(ctl_now)
        controller.invalidate_occupancy(f"human {key!r} on {topic}: {exc}")
        self.get_logger().warning(f"{topic}: occupancy of human {key!r} rejected ({exc}); "
                                  "slider minimum", throttle_duration_sec=2.0)

    def _forget_silent(self, ctl_now: float) -> None:
        """Drop humans silent for ``forget_after`` s (caller holds the lock)."""
        if self.forget_after <= 0:
            return
        for k in [k for k, h in self._humans.items() if ctl_now - h.received > self.forget_after]:
            del self._humans[k]
            self.get_logger().warning(f"human {k!r} silent for over {self.forget_after:g} s: "
                                      "forgotten")

    # ------------------------------------------------------------------ control
    def _on_decision(self, decision: ControlDecision) -> None:
        if decision.slider > self.params.min_slider:
            self.minimum_since = None
        elif self.minimum_since is None:
            self.minimum_since = decision.time
        self._latest = decision
        self.steps += 1
        if self.recorder is not None:
            self.recorder(decision)
        if self._extra_on_decision is not None:
            self._extra_on_decision(decision)

    def _control_loop(self, controller: CoexistenceController, stop: threading.Event) -> None:
        try:
            controller.run(self.rate, should_stop=stop.is_set)
        except Exception as exc:  # never die silently: the slider stays where it was
            self._live_logger().fatal(f"control loop failed: {type(exc).__name__}: {exc}")
            raise

    @property
    def latest(self) -> ControlDecision | None:
        """The latest control decision."""
        return self._latest

    @property
    def control_alive(self) -> bool:
        """True while the control thread runs."""
        return self._thread is not None and self._thread.is_alive()

    # ------------------------------------------------------------------ outputs
    def _publish_static(self) -> None:
        stamp = self.get_clock().now().to_msg()
        base_link = self.base @ np.linalg.inv(ur_frames.BASE_IN_BASE_LINK)
        tip = np.eye(4)
        tip[2, 3] = self.model.tool_length
        self._tf_static_pub.publish(TFMessage(transforms=[
            _transform(self.world_frame, f"{self.prefix}base_link", base_link, stamp),
            *[_transform(f"{self.prefix}{f.parent}", f"{self.prefix}{f.child}", f.transform,
                         stamp) for f in ur_frames.STATIC_FRAMES],
            _transform(f"{self.prefix}tool0", f"{self.prefix}tool_tip", tip, stamp)]))

    def _publish_state(self) -> None:
        d = self._latest
        if d is None:
            return
        stamp = self.get_clock().now().to_msg()
        status = SafetyStatus(separation=d.separation,
                              effective_separation=d.effective_separation,
                              protective_distance=d.protective_distance, slider=d.slider,
                              mode=d.mode, connected=d.connected, humans=len(self.humans))
        status.header.stamp = stamp
        status.header.frame_id = self.world_frame
        self._status_pub.publish(status)
        if d.q is None:
            return
        joints = JointState(name=self.joint_names, position=list(d.q))
        joints.header.stamp = stamp
        self._joint_pub.publish(joints)
        names = [f"{self.prefix}{n}" for n in ("base_link_inertia", *ur_frames.UR_LINKS)]
        links = ur_frames.link_transforms(np.asarray(d.q), self.model)
        self._tf_pub.publish(TFMessage(transforms=[
            _transform(names[i], names[i + 1], links[i], stamp) for i in range(6)]))

    def _publish_markers(self) -> None:
        d = self._latest
        if d is None or d.q is None:
            return
        segments, radii = robot_capsules(np.asarray(d.q), self.model, self.base)
        f = cv.MarkerFactory(self.world_frame, self.get_clock().now().to_msg(),
                             2.0 / max(self.param("marker_rate"), 1e-3))
        rgba = cv.color(*_MODE_COLORS.get(d.mode, (0.5, 0.5, 0.5)), 0.6)
        markers = f.capsules("robot/capsules", segments, radii, rgba)
        sep = "?" if math.isnan(d.separation) else f"{d.separation:.2f} m"
        label = f"{d.mode} {100 * d.slider:.0f}% sep {sep}"
        markers.append(f.text("robot/status", 0, self.base[:3, 3] + [0.0, 0.0, 1.2], label,
                              0.08, cv.color(1.0, 1.0, 1.0)))
        self._marker_pub.publish(MarkerArray(markers=markers))

    # ------------------------------------------------------------------ shutdown
    def stop_control(self, timeout: float = 5.0) -> None:
        """Stop the control loop, leave the arm at the minimum slider and disconnect
        (idempotent). The slider is confirmed by the controller's ``target_speed_fraction``
        (:meth:`~ltl_human_motion.robot.coexistence.CoexistenceController.hold_minimum`);
        when it cannot be, :attr:`held` and a warning say why."""
        thread, controller = self._thread, self.controller
        if thread is None or controller is None or self._stop.is_set():
            return
        self._stop.set()
        thread.join(timeout)
        why_not = controller.hold_minimum()
        slider = f"the minimum slider {self.params.min_slider:g}"
        self.held = f"left at {slider} (confirmed by the controller)" if why_not is None \
            else f"not confirmed at {slider}: {why_not}"
        log = self._live_logger()
        (log.info if why_not is None else log.warning)(f"control stopped; arm {self.held}")
        controller.close()

    def write_report(self, out_dir: str | Path, name: str = "coexistence",
                     cycle_times: tuple[float, ...] | list[float] = (),
                     baseline_cycle_time: float | None = None,
                     extra: dict[str, Any] | None = None) -> tuple[Path, Path] | None:
        """Write the commissioning report of the recorded decisions (None without any)."""
        if self.recorder is None or not self.recorder.decisions:
            return None
        info = {"use_prediction": self.use_prediction, "rate_target_hz": self.rate,
                "ssm_terms": self.params.terms(), **(extra or {})}
        return write_commissioning_report(
            list(self.recorder.decisions), out_dir, name, cycle_times, baseline_cycle_time,
            self.params.max_slider, self.params.min_slider, info)

    def destroy_node(self) -> None:
        self.stop_control()
        if self.metrics_out is not None:
            try:
                paths = self.write_report(self.metrics_out)
                if paths is not None:
                    self._live_logger().info(f"commissioning report: {paths[0]}, {paths[1]}")
            except (OSError, ValueError) as exc:
                self._live_logger().error(f"cannot write the commissioning report: {exc}")
        super().destroy_node()

