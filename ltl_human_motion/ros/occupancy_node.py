"""The occupancy node: streams the space one human occupies, as capsules, and predicts it.

Publishes ``occupancy`` (ltl_human_motion/msg/HumanOccupancy) at ``rate`` Hz (default
100), stamped with the node clock at the instant of the pose; capsules come from
``scene.occupancy.capsules_from_positions`` and part names from ``BODY_CAPSULES``. With
``prediction_horizon`` > 0 each message also carries the capsules the planned motion will
occupy ``prediction_step``, 2 ``prediction_step``, ... up to ``prediction_horizon``
seconds later (following playback rate, looping and pauses) -- only a planned human can
offer this, and a robot controller can use it to slow down early. With ``marker_rate``
> 0 it also publishes ``markers_topic`` (``/occupancy_markers``): the current capsules
(``human_<id>/occupancy``) and those at the end of the horizon (``human_<id>/predicted``).

Playback clock, so the occupancy never drifts from the skeleton shown on TF:

* In one process (``ltl-human-motion bringup``) the node shares the skeleton publisher's
  :class:`~ltl_human_motion.planning.playback.Playback` object.
* Standing alone, it follows the skeleton publisher's ``task_state`` topic (same
  namespace): each message gives motion id, motion time at its stamp, rate, loop and
  state; the node re-anchors its own playback on it and extrapolates in between. The
  motion itself is loaded by id from the folder named on ``catalog_topic``.

Timing: the stream runs on a :class:`~ltl_human_motion.ros.wall_schedule.WallSchedule`
thread (an absolute schedule on the monotonic clock, outside the executor, so other
callbacks of the process cannot delay it and a late tick does not shift the ones after
it). Capsule rows of every frame are computed once when a motion is loaded, so a message
costs one interpolation and the CDR encoding. ``deadlines_missed`` counts the deadlines
a subscriber sees missed (a skipped slot, or a message half a period or more late: see
:mod:`~ltl_human_motion.ros.wall_schedule`) and a warning (throttled to one per
:data:`MISS_WARNING_PERIOD`) gives the count and the worst delay;
:meth:`OccupancyNode.stream_record` is the stream's own timing record. On a loaded
machine the thread's wake-up can wait longer than a period for a CPU, so it asks for a
real-time priority (``stream_priority``; refused without CAP_SYS_NICE or an ``rtprio``
limit, and then logged). With
``use_sim_time`` the stream follows the ROS clock on an rclpy timer instead.

Parameters: ``human_id`` ("1"), ``world_frame`` ("world"), ``rate`` (100.0 Hz),
``prediction_horizon`` (0.0 s = off), ``prediction_step`` (0.1 s), ``marker_rate``
(10.0 Hz; 0 = off), ``store_dir`` (""), ``catalog_topic`` ("/motion_catalog"),
``task_state_topic`` ("task_state"), ``markers_topic`` ("/occupancy_markers"),
``stream_priority`` (0 by default = normal scheduling; e.g. 10: ``SCHED_FIFO`` priority of
the stream thread where the process may have it).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.node import Node
from rclpy.parameter import Parameter
from visualization_msgs.msg import MarkerArray

from ltl_human_motion.msg import HumanOccupancy
from ltl_human_motion.planning.motion_store import MotionStore
from ltl_human_motion.planning.playback import Playback
from ltl_human_motion.ros import conversions as cv
from ltl_human_motion.ros.common import STREAM_QOS
from ltl_human_motion.ros.diagnostics import OK, WARN, Status, attach_diagnostics
from ltl_human_motion.ros.occupancy_cdr import capsule_rows, encode_occupancy_rows
from ltl_human_motion.ros.params import (
    ParamSpec,
    bounded,
    declare_parameters,
    frame_id,
    identifier,
    non_negative,
    positive,
    topic_name,
)
from ltl_human_motion.ros.playback_follower import PlaybackFollower, follower_parameters
from ltl_human_motion.ros.wall_schedule import WallSchedule

#: Seconds between two missed-deadline warnings of one node.
MISS_WARNING_PERIOD = 5.0
#: GIL switch interval (s) of a process that runs an occupancy node by itself: the stream
#: thread waits at most this long for the GIL after its sleep (CPython's default is 5 ms,
#: half a 100 Hz period). Same value as the coexistence node's control loop
#: (``coexistence_node.CONTROL_SWITCH_INTERVAL``, measured there: bench/coexistence_loop.py).
STREAM_SWITCH_INTERVAL = 0.0002
_ROWS_KEY = "occupancy_capsule_rows"
#: SCHED_FIFO priority asked for the stream thread (0: none, the default). 10 holds the
#: stream steadier on a loaded machine (above normal threads, below the kernel's own and
#: typical ros2_control loops at 50 and up), but with it a player's service was seen to
#: stop answering in the coexistence tests and a benchmark to hang: opt-in until found.
DEFAULT_STREAM_PRIORITY = 0


@bounded(0, 99, "an integer 0..99")
def _priority(value: Any) -> str | None:
    ok = isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 99
    return None if ok else f"expected an integer 0..99, got {value!r}"


def occupancy_parameters() -> list[ParamSpec]:
    """The occupancy node's parameters."""
    return [
        ParamSpec("human_id", "1", "Id of the human", identifier, read_only=True,
                  dynamic_typing=True),
        ParamSpec("world_frame", "world", "Frame of the capsules", frame_id, read_only=True),
        ParamSpec("rate", 100.0, "Occupancy messages per second", positive),
        ParamSpec("prediction_horizon", 0.0, "Seconds of predicted occupancy (0 = none)",
                  non_negative),
        ParamSpec("prediction_step", 0.1, "Seconds between predicted samples", positive),
        ParamSpec("marker_rate", 10.0, "Occupancy marker messages per second (0 = none)",
                  non_negative),
        ParamSpec("stream_priority", DEFAULT_STREAM_PRIORITY,
                  "SCHED_FIFO priority of the stream thread (0 = normal scheduling; "
                  "refused without CAP_SYS_NICE/rtprio, then normal)", _priority,
                  read_only=True),
        *follower_parameters(),
        ParamSpec("markers_topic", "/occupancy_markers", "MarkerArray topic", topic_name,
                  read_only=True),
    ]


class OccupancyNode(Node):
    """Streams ``HumanOccupancy`` for one human.

    Parameters
    ----------
    playback : Playback, optional
        The skeleton publisher's playback (same process). Without it the node follows
        ``task_state``.
    store : MotionStore, optional
        Where to find motions when following ``task_state``.
    """

    def __init__(self, *, playback: Playback | None = None, store: MotionStore | None = None,
                 node_name: str = "occupancy_node", **node_kwargs: Any) -> None:
        super().__init__(node_name, **node_kwargs)
        declare_parameters(self, occupancy_parameters())
        self.human_id = str(self.param("human_id"))
        self.world_frame: str = self.param("world_frame")
        self.follower = PlaybackFollower.from_parameters(self, playback, store)
        self.following, self.playback = self.follower.following, self.follower.playback
        self._part_names: list[str] | None = None
        self.messages_published = 0

        self._pub = self.create_publisher(HumanOccupancy, "occupancy", STREAM_QOS)
        self._marker_pub = self.create_publisher(MarkerArray, self.param("markers_topic"),
                                                 STREAM_QOS)
        self._group = MutuallyExclusiveCallbackGroup()
        self._names = cv.capsule_part_names()
        self.deadlines_missed = 0
        #: The latest a tick has started so far, s (0 when none was late).
        self.worst_late = 0.0
        self._timer = None
        self._schedule: WallSchedule | None = None
        if self.param("use_sim_time"):
            self._timer = self.create_timer(1.0 / self.param("rate"), self._tick,
                                            callback_group=self._group)
        else:
            self._schedule = WallSchedule(1.0 / self.param("rate"), self._tick,
                                          on_miss=self._on_miss, on_error=self._on_error,
                                          name=f"occupancy-{self.human_id}",
                                          priority=self._stream_thread_priority())
            if self._schedule.priority_error:
                self.get_logger().info(f"stream thread: {self._schedule.priority_error}")
        self._marker_timer = None
        self._set_marker_timer(self.param("marker_rate"))
        self.add_post_set_parameters_callback(self._on_parameters_set)
        self._missed_reported = 0
        attach_diagnostics(self, self.diagnostics)
        mode = "following task_state" if self.following else "sharing the playback clock"
        if self._schedule is not None and self._schedule.realtime:
            mode += f", stream thread SCHED_FIFO {self._schedule.priority}"
        self.get_logger().info(f"occupancy of human {self.human_id} at {self.param('rate'):g} Hz"
                               f" ({mode})")

    def param(self, name: str) -> Any:
        return self.get_parameter(name).value

    def _set_marker_timer(self, rate: float) -> None:
        if self._marker_timer is not None:
            self._marker_timer.cancel()
            self.destroy_timer(self._marker_timer)
            self._marker_timer = None
        if rate > 0:
            self._marker_timer = self.create_timer(1.0 / rate, self._publish_markers,
                                                   callback_group=MutuallyExclusiveCallbackGroup())

    def _stream_thread_priority(self) -> int:
        """``stream_priority`` + 1 for the stream thread: above the rest of its process,
        which the entry point puts at ``stream_priority`` (equal FIFO priorities do not
        preempt each other, so the executor thread could keep the stream waiting)."""
        priority = self.param("stream_priority")
        return min(priority + 1, 99) if priority > 0 else 0

    def _on_miss(self, missed: int, late: float) -> None:
        self.deadlines_missed += missed
        self.worst_late = max(self.worst_late, late)
        skipped = int(late * self.param("rate"))
        self.get_logger().warning(
            f"occupancy stream of human {self.human_id} missed {self.deadlines_missed} "
            f"deadline(s) so far (this tick {late * 1e3:.1f} ms late, "
            f"{skipped} message(s) skipped)", throttle_duration_sec=MISS_WARNING_PERIOD)

    def diagnostics(self) -> list[Status]:
        """The stream's deadlines for ``/diagnostics``: WARN when some were missed since
        the previous report."""
        missed = self.deadlines_missed
        new, self._missed_reported = missed - self._missed_reported, missed
        message = f"{new} deadline(s) missed since the last report" if new else "on time"
        return [Status("occupancy stream", WARN if new else OK, message, {
            "rate_hz": f"{self.param('rate'):g}", "deadlines_missed": str(missed),
            "worst_late_ms": f"{self.worst_late * 1e3:.1f}",
            "messages_published": str(self.messages_published)})]

    def stream_record(self) -> np.ndarray:
        """The stream's recent ticks: array (n, 2) of each tick's slot (due time) and
        start time, monotonic seconds (empty under ``use_sim_time``)."""
        if self._schedule is None:
            return np.zeros((0, 2))
        return self._schedule.record()

    def _on_error(self, exc: BaseException) -> None:
        self.get_logger().error(f"occupancy tick failed: {type(exc).__name__}: {exc}",
                                throttle_duration_sec=MISS_WARNING_PERIOD)

    def destroy_node(self) -> None:
        if self._schedule is not None:
            self._schedule.stop()
        super().destroy_node()

    def _on_parameters_set(self, params: list[Parameter]) -> None:
        for p in params:
            if p.name == "rate" and self._schedule is not None:
                self._schedule.set_period(1.0 / p.value)
            elif p.name == "rate":
                self._timer.cancel()
                self.destroy_timer(self._timer)
                self._timer = self.create_timer(1.0 / p.value, self._tick,
                                                callback_group=self._group)
            elif p.name == "marker_rate":
                self._set_marker_timer(p.value)

    def offsets(self) -> np.ndarray:
        """Clock offsets (s) of the published samples: 0, then the predicted ones."""
        horizon, step = self.param("prediction_horizon"), self.param("prediction_step")
        n = int(np.floor(horizon / step + 1e-9)) if horizon > 0 else 0
        return np.arange(n + 1) * step

    def _rows_per_frame(self, positions: np.ndarray) -> np.ndarray:
        """Capsule rows (T, K, 7) of every frame of positions (T, J, 3)."""
        segments, radii, _ = cv.body_capsules(positions, self.playback.stature)
        return capsule_rows(segments, radii)

    def _tick(self) -> None:
        now = self.get_clock().now()
        offsets = self.offsets()
        rows = self.playback.sample_ahead(now.nanoseconds * 1e-9, offsets, _ROWS_KEY,
                                          self._rows_per_frame)
        if rows is None:
            return
        sec, nanosec = divmod(now.nanoseconds, 1_000_000_000)
        if not self.context.ok():            # shutting down (Ctrl-C, SIGTERM)
            return
        self._pub.publish(encode_occupancy_rows(sec, nanosec, self.world_frame,
                                                self.human_id, self._names, rows, offsets))
        self.messages_published += 1

    def _publish_markers(self) -> None:
        now = self.get_clock().now()
        offsets = self.offsets()
        positions = self.playback.positions_ahead(now.nanoseconds * 1e-9, offsets[[0, -1]])
        if positions is None:
            return
        segments, radii, _ = cv.body_capsules(positions, self.playback.stature)
        f = cv.MarkerFactory(self.world_frame, now.to_msg(), 2.0 / max(self.param("marker_rate"),
                                                                        1e-3))
        ns = cv.human_prefix(self.human_id)
        markers = f.capsules(f"{ns}/occupancy", segments[0], radii, cv.color(0.9, 0.2, 0.2, 0.3))
        if len(offsets) > 1:
            markers += f.capsules(f"{ns}/predicted", segments[1], radii,
                                  cv.color(1.0, 0.6, 0.0, 0.15))
        self._marker_pub.publish(MarkerArray(markers=markers))
