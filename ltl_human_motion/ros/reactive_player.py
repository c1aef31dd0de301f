"""The reactive player: a worker who reacts to the robot, live (docs/reactive.md).

A thin rclpy layer over :class:`~ltl_human_motion.planning.strategy_executor.StrategyExecutor`.
Plays a strategy the synthesis service made from a reactive specification (its
``strategy_id``) and reads the specification's inputs:

* ``robot_in(R)`` and ``robot_moving`` from ``joint_states_topic`` (``/joint_states``,
  sensor_msgs/JointState: the coexistence node publishes the joint state it reads over
  RTDE there): the arm's capsules at those joint positions (the model, tool and base
  parameters, the coexistence node's defaults) against region R's box, and the fastest
  joint's speed (differenced between messages) against ``moving_threshold`` (rad/s);
* ``offered(O)`` from ``<offered_prefix>/<O>`` (std_msgs/Bool, default ``/cell/offered/O``);
* the cell's own inputs from the topics the cell names (``inputs: {door_open:
  /cell/door_open}``, std_msgs/Bool).

An input message counts from its stamp (JointState) or its receipt (Bool). Every input is
false until its first message and keeps its last value; the player warns when no joint
state came for :data:`JOINT_STATES_SILENCE` s. When it
changes an input during a wait, the wait ends at once and the frame of the next move goes
out on TF from the same callback, so a waiting worker reacts within a few tens of ms of
the message (bench/react_latency.py).

Publishes at ``publish_rate`` (node clock): ``/tf`` (``<world_frame>`` -> ``human_<id>/``
``pelvis`` -> the joints, as the skeleton publisher), ``markers_topic`` (bones and the
task over the head) and ``task_state`` (ltl_human_motion/msg/TaskState with the strategy
fields: ``strategy_id``, ``strategy_step``, ``strategy_state``, ``input_names``,
``input_values``, ``inputs_stamp``).

Service ``play_motion`` (ltl_human_motion/srv/PlayMotion): ``play`` with ``motion_id`` a
strategy id (``<store_dir>/<id>.strategy.npz``, or a program shared in this process),
``stop``. Parameters: ``human_id`` ("1"), ``world_frame`` ("world"), ``publish_rate``
(30 Hz), ``store_dir`` ("": ``$ROS_HOME/ltl_human_motion/motions``), ``strategy_id``
("": play at once when given), ``playback_rate`` (1.0), ``joint_states_topic``, ``joint_prefix``,
``moving_threshold``, ``offered_prefix``, ``markers_topic``, and the robot's ``model``,
``tool_length``, ``tool_radius``, ``base_x``, ``base_y``, ``base_z``, ``base_yaw``.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import Bool
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from ltl_human_motion.errors import LtlHumanMotionError
from ltl_human_motion.motion.skeleton import JOINT_INDEX, PARENTS
from ltl_human_motion.msg import TaskState
from ltl_human_motion.planning.motion_store import default_store_dir
from ltl_human_motion.planning.strategy_executor import (
    LiveFrame,
    StrategyExecutor,
    StrategyStatus,
)
from ltl_human_motion.planning.strategy_motion import StrategyProgram, load_program
from ltl_human_motion.robot.events import DEFAULT_MOVING_THRESHOLD, robot_inputs
from ltl_human_motion.robot.kinematics import pose_from_xyz_rpy, ur_model
from ltl_human_motion.ros import conversions as cv
from ltl_human_motion.ros.coexistence_node import UR_JOINT_NAMES, coexistence_parameters
from ltl_human_motion.ros.common import STREAM_QOS, TF_QOS, now_seconds, resolve_cell
from ltl_human_motion.ros.params import (
    ParamSpec,
    declare_parameters,
    non_negative,
    positive,
    topic_name,
)
from ltl_human_motion.ros.skeleton_publisher import skeleton_parameters
from ltl_human_motion.srv import PlayMotion

__all__ = ["JOINT_STATES_SILENCE", "ROBOT_PARAMETERS", "ReactivePlayer",
           "reactive_player_parameters", "strategy_path"]

#: Seconds without a joint state after which the player warns (the robot's inputs then
#: keep their last values).
JOINT_STATES_SILENCE = 1.0
#: The coexistence node's parameters that place the robot's capsules.
ROBOT_PARAMETERS = ("model", "tool_length", "tool_radius", "base_x", "base_y", "base_z",
                    "base_yaw", "joint_prefix")
_BONE_PAIRS = np.array([(p, j) for j, p in enumerate(PARENTS) if p >= 0])


def strategy_path(directory: str | Path, strategy_id: str) -> Path:
    """The file of ``strategy_id`` in ``directory``."""
    return Path(directory) / f"{strategy_id}.strategy.npz"


def reactive_player_parameters() -> list[ParamSpec]:
    """The reactive player's parameters."""
    robot = [p for p in coexistence_parameters() if p.name in ROBOT_PARAMETERS]
    shown = {p.name: p for p in skeleton_parameters()}
    return [
        shown["human_id"], shown["world_frame"], shown["markers_topic"],
        replace(shown["publish_rate"], read_only=True),
        ParamSpec("store_dir", "", "Folder of <strategy_id>.strategy.npz ('' = $ROS_HOME/"
                  "ltl_human_motion/motions)", read_only=True),
        ParamSpec("strategy_id", "", "Strategy played at once ('' for none)",
                  read_only=True),
        ParamSpec("playback_rate", 1.0, "Playback rate (1.0 is real time; applies from the next "
                  "play)", positive),
        ParamSpec("joint_states_topic", "/joint_states", "JointState topic of the robot "
                  "(robot_in, robot_moving)", topic_name, read_only=True),
        ParamSpec("moving_threshold", DEFAULT_MOVING_THRESHOLD, "Joint speed (rad/s) above "
                  "which robot_moving holds", non_negative, read_only=True),
        ParamSpec("offered_prefix", "/cell/offered", "offered(O) is read from "
                  "<offered_prefix>/<O> (std_msgs/Bool)", topic_name, read_only=True),
        *robot,
    ]


class ReactivePlayer(Node):
    """Plays one worker's strategy live, reading the robot's events.

    Parameters
    ----------
    programs : mapping of str to StrategyProgram, optional
        Programs made in this process (the synthesis node's), found before the folder.
    """

    def __init__(self, *, programs: Mapping[str, StrategyProgram] | None = None,
                 node_name: str = "reactive_player", **node_kwargs: Any) -> None:
        super().__init__(node_name, **node_kwargs)
        declare_parameters(self, reactive_player_parameters())
        p = self.param
        self.human_id = str(p("human_id"))
        self.world_frame: str = p("world_frame")
        self.store_dir = Path(p("store_dir") or default_store_dir())
        self.programs = programs if programs is not None else {}
        self.model = ur_model(p("model")).with_tool(float(p("tool_length")),
                                                    float(p("tool_radius")))
        self.base = pose_from_xyz_rpy((p("base_x"), p("base_y"), p("base_z")),
                                      (0.0, 0.0, p("base_yaw")))
        self.joint_names = [p("joint_prefix") + n for n in UR_JOINT_NAMES]
        self.executor_: StrategyExecutor | None = None
        self.view = ExecutorView(self)
        self._regions: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._robot_keys: tuple[str, ...] = ()
        self._last_joints: tuple[float, np.ndarray] | None = None
        self._joints_at = 0.0                   # node clock: the latest joint state (or play)
        self._input_subs: list[Any] = []
        self.frames_published = 0
        self._error_logged = False
        self._junctions_warned = 0
        #: (input stamp, stamp of the reaction's first frame), s, of the latest 1000 waits
        #: ended by an input.
        self.reactions: deque[tuple[float, float]] = deque(maxlen=1000)

        self._group = MutuallyExclusiveCallbackGroup()
        self._tf_pub = self.create_publisher(TFMessage, "/tf", TF_QOS)
        self._marker_pub = self.create_publisher(MarkerArray, p("markers_topic"), STREAM_QOS)
        self._state_pub = self.create_publisher(TaskState, "task_state", STREAM_QOS)
        self.create_service(PlayMotion, "play_motion", self._on_play,
                            callback_group=MutuallyExclusiveCallbackGroup())
        self.create_subscription(JointState, p("joint_states_topic"), self._on_joints,
                                 STREAM_QOS, callback_group=self._group)
        self.create_timer(1.0 / p("publish_rate"), self._tick, callback_group=self._group)
        if p("strategy_id"):
            try:
                self.play(p("strategy_id"))
            except (KeyError, ValueError, OSError, LtlHumanMotionError) as exc:
                self.get_logger().error(f"cannot play {p('strategy_id')!r}: {exc}")

    def param(self, name: str) -> Any:
        return self.get_parameter(name).value

    # -- playing ---------------------------------------------------------------------
    def program(self, strategy_id: str) -> StrategyProgram:
        """The program of ``strategy_id`` (this process's, else its file)."""
        if strategy_id in self.programs:
            return self.programs[strategy_id]
        path = strategy_path(self.store_dir, strategy_id)
        if not path.is_file():
            raise KeyError(f"unknown strategy id {strategy_id!r} (not in this process or "
                           f"in {self.store_dir})")
        return load_program(path)

    def play(self, strategy_id: str) -> StrategyProgram:
        """Start ``strategy_id`` now (its inputs' subscriptions replace the last ones)."""
        if "/" in strategy_id or not strategy_id.strip():
            raise ValueError(f"expected a strategy id, got {strategy_id!r}")
        program = self.program(strategy_id)
        cell = resolve_cell(program.cell)
        for sub in self._input_subs:
            self.destroy_subscription(sub)
        self._input_subs = []
        self._regions = {n: (np.asarray(r.lo, dtype=np.float64), np.asarray(r.hi,
                                                                           dtype=np.float64))
                         for n, r in cell.regions.items()}
        self._robot_keys = tuple(k for k in program.inputs
                                 if k == "robot_moving" or k.startswith("robot_in("))
        for key in program.inputs:
            topic = self._bool_topic(key, cell)
            if topic is not None:
                self._input_subs.append(self.create_subscription(
                    Bool, topic, lambda msg, k=key: self._on_bool(k, msg), STREAM_QOS,
                    callback_group=self._group))
        self._last_joints = None
        self._error_logged = False
        self._joints_at = now_seconds(self)
        self._junctions_warned = 0
        self.executor_ = StrategyExecutor(program, now_seconds(self),
                                          rate=float(self.param("playback_rate")), cell=cell)
        self.get_logger().info(f"playing strategy {strategy_id} ({len(program.clips)} moves; "
                               f"inputs {', '.join(program.inputs)})")
        return program

    def _bool_topic(self, key: str, cell: Any) -> str | None:
        if key.startswith("offered("):
            return f"{self.param('offered_prefix').rstrip('/')}/{key[8:-1]}"
        return getattr(cell, "inputs", {}).get(key)

    def _on_play(self, request: PlayMotion.Request,
                 response: PlayMotion.Response) -> PlayMotion.Response:
        try:
            response.message = self._command(request.command.strip().lower(),
                                             request.motion_id)
            response.success = True
        except (KeyError, ValueError, OSError, LtlHumanMotionError) as exc:
            response.message = str(exc.args[0]) if isinstance(exc, KeyError) else str(exc)
            self.get_logger().warning(f"play_motion {request.command}: {response.message}")
        return response

    def _command(self, command: str, strategy_id: str) -> str:
        """Run a play_motion command; the answer's message."""
        if command == "play":
            program = self.play(strategy_id)
            return f"playing strategy {program.strategy_id} ({len(program.clips)} moves)"
        if command == "stop":
            if self.executor_ is not None:
                self.executor_.stop()
            return "stopped"
        raise ValueError(f"unknown command {command!r}; the reactive player knows play and "
                         "stop")

    # -- inputs ----------------------------------------------------------------------
    def _on_joints(self, msg: JointState) -> None:
        executor = self.executor_
        if executor is None or not self._robot_keys:
            return
        index = {n: i for i, n in enumerate(msg.name)}
        try:
            q = np.array([msg.position[index[n]] for n in self.joint_names], dtype=np.float64)
        except (KeyError, IndexError):
            self.get_logger().warning(f"joint_states without the joints {self.joint_names}",
                                      throttle_duration_sec=5.0)
            return
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        self._joints_at = now_seconds(self)
        qd = None
        if len(msg.velocity) == len(msg.position) and len(msg.velocity) > 0:
            qd = np.array([msg.velocity[index[n]] for n in self.joint_names])
        elif self._last_joints is not None and stamp > self._last_joints[0]:
            qd = (q - self._last_joints[1]) / (stamp - self._last_joints[0])
        self._last_joints = (stamp, q)
        if not np.all(np.isfinite(q)):
            return
        values = robot_inputs(q, qd, self.model, self.base, self._regions, self._robot_keys,
                              float(self.param("moving_threshold")))
        self._take(executor, values, stamp)

    def _on_bool(self, key: str, msg: Bool) -> None:
        executor = self.executor_
        if executor is not None:
            self._take(executor, {key: bool(msg.data)}, now_seconds(self))

    def _take(self, executor: StrategyExecutor, values: dict[str, bool], stamp: float) -> None:
        if executor.set_inputs(values, stamp, now_seconds(self)):
            published = self._tick()
            if published is not None:
                self.reactions.append((stamp, published))

    # -- outputs ---------------------------------------------------------------------
    def _tick(self) -> float | None:
        """Publish the current frame; its stamp (s), or None when nothing plays."""
        executor = self.executor_
        stamp_time = self.get_clock().now()
        stamp = stamp_time.to_msg()
        frame = executor.frame_at(stamp_time.nanoseconds * 1e-9) \
            if executor is not None else None
        if executor is not None and self._robot_keys \
                and stamp_time.nanoseconds * 1e-9 - self._joints_at > JOINT_STATES_SILENCE:
            self.get_logger().warning(
                f"no joint state on {self.param('joint_states_topic')} for over "
                f"{JOINT_STATES_SILENCE:g} s: {', '.join(self._robot_keys)} keep their last "
                "values (false before the first message); is the coexistence node running?",
                throttle_duration_sec=10.0)
        if executor is not None and executor.junctions_failed > self._junctions_warned:
            self._junctions_warned = executor.junctions_failed
            bad = next(j for j in reversed(executor.junctions) if not j.passed)
            self.get_logger().warning(
                f"junction into {bad.task} (step {bad.step}) fails {', '.join(bad.failed)} "
                f"even blended over {bad.blend:.2f} s; played so ({bad.detail})")
        if executor is not None and executor.error is not None and not self._error_logged:
            self._error_logged = True
            self.get_logger().error(f"strategy {executor.motion_id} stopped: {executor.error}")
        if frame is not None:
            self._tf_pub.publish(TFMessage(transforms=cv.skeleton_transforms(
                frame.positions, frame.yaw, self.human_id, self.world_frame, stamp)))
            self._publish_markers(frame, stamp)
            self.frames_published += 1
        self._state_pub.publish(self._task_state(frame, stamp))
        return None if frame is None else stamp_time.nanoseconds * 1e-9

    def _task_state(self, frame: LiveFrame | None, stamp: Any) -> TaskState:
        msg = TaskState()
        msg.header.stamp = stamp
        msg.header.frame_id = self.world_frame
        msg.human_id = self.human_id
        msg.rate = float(self.param("playback_rate"))
        if frame is None:
            msg.playback_state = "stopped"
            msg.task_index = -1
            return msg
        status: StrategyStatus = frame.status
        msg.motion_id = status.strategy_id
        msg.current_task = status.task
        msg.task_index = status.step
        msg.motion_time = frame.step_time
        msg.motion_duration = frame.step_duration
        msg.progress = float(min(frame.step_time / frame.step_duration, 1.0)) \
            if frame.step_duration > 0 else 1.0
        msg.playback_state = "playing"
        msg.strategy_id = status.strategy_id
        msg.strategy_step = status.step
        msg.strategy_state = status.state_text()
        msg.input_names = list(status.inputs)
        msg.input_values = [bool(v) for v in status.inputs.values()]
        msg.inputs_stamp.sec, msg.inputs_stamp.nanosec = divmod(
            round(status.inputs_stamp * 1e9), 1_000_000_000)
        return msg

    def _publish_markers(self, frame: LiveFrame, stamp: Any) -> None:
        ns = cv.human_prefix(self.human_id)
        f = cv.MarkerFactory(self.world_frame, stamp, 1.0)
        pos = frame.positions
        status = frame.status
        inputs = " ".join(("" if v else "!") + k for k, v in status.inputs.items())
        markers = [
            f.line_list(f"{ns}/bones", 0, pos[_BONE_PAIRS], cv.color(0.9, 0.9, 0.9), 0.02),
            f.sphere_list(f"{ns}/joints", 0, pos, cv.color(0.2, 0.4, 1.0), 0.05),
            f.text(f"{ns}/task", 0, pos[JOINT_INDEX["head"]] + np.array([0.0, 0.0, 0.35]),
                   f"human {self.human_id}: {status.task} [{inputs}]", 0.15,
                   cv.color(1.0, 1.0, 1.0)),
        ]
        self._marker_pub.publish(MarkerArray(markers=markers))


class ExecutorView:
    """The player's current strategy as a Playback for an occupancy node in the same
    process (``OccupancyNode(playback=player.view)``)."""

    def __init__(self, player: ReactivePlayer) -> None:
        self._player = player

    @property
    def motion_id(self) -> str:
        ex = self._player.executor_
        return ex.motion_id if ex is not None else ""

    @property
    def stature(self) -> float:
        ex = self._player.executor_
        return ex.stature if ex is not None else 1.75

    def state(self, now: float) -> str:
        ex = self._player.executor_
        return ex.state(now) if ex is not None else "stopped"

    def positions_ahead(self, now: float, offsets: np.ndarray) -> np.ndarray | None:
        ex = self._player.executor_
        return ex.positions_ahead(now, offsets) if ex is not None else None

    def sample_ahead(self, now: float, offsets: np.ndarray, key: str,
                     per_frame: Any) -> np.ndarray | None:
        ex = self._player.executor_
        return ex.sample_ahead(now, offsets, key, per_frame) if ex is not None else None
