"""The playback a stream node (occupancy, ergonomics) reads.

In one process with the skeleton publisher (``ltl-human-motion bringup``) the node shares
the publisher's :class:`~ltl_human_motion.planning.playback.Playback`. Standing alone it keeps
its own in step with the publisher's ``task_state`` topic, loading each motion by id from
its store or from the folder the latched motion catalog names. The parameters that say
where (:func:`follower_parameters`) are declared by each such node.
"""

from __future__ import annotations

import gc

from rclpy.node import Node

from ltl_human_motion.msg import MotionCatalog, TaskState
from ltl_human_motion.planning.motion_store import MotionSource, MotionStore
from ltl_human_motion.planning.playback import STATES, STOPPED, Playback
from ltl_human_motion.ros.common import LATCHED_QOS, STREAM_QOS, now_seconds, stamp_seconds
from ltl_human_motion.ros.params import ParamSpec, topic_name

__all__ = ["PlaybackFollower", "follower_parameters"]


def follower_parameters() -> list[ParamSpec]:
    """A following node's ``store_dir``, ``catalog_topic`` and ``task_state_topic``."""
    return [
        ParamSpec("store_dir", "", "Folder of <motion_id>.npz ('' = use the catalog's)",
                  read_only=True),
        ParamSpec("catalog_topic", "/motion_catalog", "Latched MotionCatalog topic",
                  topic_name, read_only=True),
        ParamSpec("task_state_topic", "task_state", "TaskState topic to follow when alone",
                  topic_name, read_only=True),
    ]


class PlaybackFollower:
    """A node's playback: shared, or following a player's ``TaskState``.

    Parameters
    ----------
    node : Node
        Owns the subscriptions and the logger.
    playback : Playback or None
        The skeleton publisher's playback (same process); None: the follower keeps its own
        and subscribes to ``task_state_topic`` and ``catalog_topic``.
    store : MotionStore or None
        Where to find motions by id.
    store_dir : str
        Folder of a store to open when ``store`` is None ("" for none).
    task_state_topic, catalog_topic : str
    """

    def __init__(self, node: Node, playback: Playback | None, store: MotionStore | None,
                 store_dir: str, task_state_topic: str, catalog_topic: str) -> None:
        self.node = node
        self.following = playback is None
        self.playback = Playback() if playback is None else playback
        self.source = MotionSource(store if store is not None
                                   else MotionStore(store_dir) if store_dir else None)
        self._missing_warned: set[str] = set()
        if self.following:
            node.create_subscription(TaskState, task_state_topic, self.on_task_state,
                                     STREAM_QOS)
            node.create_subscription(MotionCatalog, catalog_topic, self.source.on_catalog,
                                     LATCHED_QOS)

    @classmethod
    def from_parameters(cls, node: Node, playback: Playback | None,
                        store: MotionStore | None) -> PlaybackFollower:
        """The follower that ``node``'s declared :func:`follower_parameters` describe."""
        def value(name: str) -> str:
            return node.get_parameter(name).value
        return cls(node, playback, store, value("store_dir"), value("task_state_topic"),
                   value("catalog_topic"))

    def on_task_state(self, msg: TaskState) -> None:
        """Re-anchor the playback on a player's ``TaskState``, loading the motion when it
        changes (a motion not found yet is warned about once)."""
        if msg.playback_state not in STATES or msg.playback_state == STOPPED \
                or not msg.motion_id:
            if self.playback.state(now_seconds(self.node)) != STOPPED:
                self.playback.stop()
            return
        motion = None
        if msg.motion_id != self.playback.motion_id:
            try:
                motion = self.source.get(msg.motion_id)
            except (KeyError, ValueError, OSError) as exc:
                if msg.motion_id not in self._missing_warned:
                    self._missing_warned.add(msg.motion_id)
                    self.node.get_logger().warning(
                        f"cannot follow {msg.motion_id!r} yet: {exc}")
                return
            # Loading imported the planning modules and made the motion's objects: keep
            # them out of the collector's full passes, which would stall a stream
            # (measured: 120 ms gaps in bench/occupancy_stream.py --layout launch).
            gc.freeze()
        self.playback.sync(msg.motion_id, motion, msg.motion_time,
                           stamp_seconds(msg.header.stamp), msg.rate, msg.loop,
                           msg.playback_state)
