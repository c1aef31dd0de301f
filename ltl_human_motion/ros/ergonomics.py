"""Ergonomics in ROS: the synthesis response's figures and the ``ergonomics`` topic.

:func:`response_figures` gives what the synthesis service returns per motion (cycle time,
worst REBA and RULA). :class:`ErgonomicsNode` publishes, for one human, the current
posture scores at ``rate`` Hz (default 10) during playback on ``ergonomics``
(ltl_human_motion/msg/ErgonomicsState, ``/human_<id>/ergonomics`` in the human's
namespace) and a marker above the head coloured by the REBA action level (green
negligible, yellow low, orange medium, red high, dark red very high) with the scores as
text on ``markers_topic`` (``/ergonomics_markers``), so an operator sees a red posture
in RViz as it happens.

Playback clock as for the occupancy node: in one process (``ltl-human-motion bringup``)
it shares the skeleton publisher's :class:`~ltl_human_motion.planning.playback.Playback`;
alone, it follows ``task_state`` and loads the motion by id from the catalog's folder.
Scores are computed once per motion (:func:`ltl_human_motion.assess.assess_motion`,
part masses from the ``cell`` parameter) and looked up per frame.

Parameters: ``human_id`` ("1"), ``world_frame`` ("world"), ``rate`` (10.0 Hz), ``cell``
("paper_cell"), ``store_dir`` (""), ``catalog_topic`` ("/motion_catalog"),
``task_state_topic`` ("task_state"), ``markers_topic`` ("/ergonomics_markers").
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.node import Node
from visualization_msgs.msg import Marker, MarkerArray

from ltl_human_motion.assess import assess_motion
from ltl_human_motion.assess import reba as reba_mod
from ltl_human_motion.assess import rula as rula_mod
from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.msg import ErgonomicsState
from ltl_human_motion.planning.motion_store import MotionStore
from ltl_human_motion.planning.playback import Playback
from ltl_human_motion.ros import conversions as cv
from ltl_human_motion.ros.common import STREAM_QOS
from ltl_human_motion.ros.params import (
    ParamSpec,
    declare_parameters,
    frame_id,
    identifier,
    positive,
    topic_name,
)
from ltl_human_motion.ros.playback_follower import PlaybackFollower, follower_parameters
from ltl_human_motion.scene.cell import Cell

__all__ = ["LEVEL_COLORS", "ErgonomicsNode", "cell_masses", "response_figures"]

#: RGBA per REBA action level 0-4 (negligible, low, medium, high, very high).
LEVEL_COLORS = ((0.1, 0.75, 0.2, 0.9), (0.85, 0.85, 0.1, 0.9), (1.0, 0.55, 0.0, 0.9),
                (0.95, 0.1, 0.1, 0.95), (0.55, 0.0, 0.0, 0.95))
#: m above the head joint where the marker floats.
MARKER_HEIGHT = 0.35


def cell_masses(cell: Cell | str | Path) -> dict[str, float]:
    """Part masses (kg) of a cell (a Cell, a name or a YAML path); {} if unresolvable."""
    from ltl_human_motion.planning.pipeline import resolve_cell
    try:
        c = cell if isinstance(cell, Cell) else resolve_cell(cell)
    except (ValueError, OSError, KeyError):
        return {}
    return {name: float(obj.mass) for name, obj in c.objects.items()}


def response_figures(motion: Any, masses: dict[str, float] | None = None, cycles: int = 1
                     ) -> tuple[float, int, int]:
    """Cycle time (s), worst REBA and worst RULA of a synthesized motion."""
    rep = assess_motion(motion, masses, cycles=max(int(cycles), 1))
    return (float(motion.duration) / max(int(cycles), 1), int(rep.reba.max()),
            int(rep.rula.max()))


def ergonomics_parameters() -> list[ParamSpec]:
    """The ergonomics node's parameters."""
    return [
        ParamSpec("human_id", "1", "Id of the human", identifier, read_only=True,
                  dynamic_typing=True),
        ParamSpec("world_frame", "world", "Frame of the marker", frame_id, read_only=True),
        ParamSpec("rate", 10.0, "Ergonomics messages per second", positive, read_only=True),
        ParamSpec("cell", "paper_cell", "Cell whose part masses load the hands",
                  lambda v: None if str(v).strip() else "expected a cell name"),
        *follower_parameters(),
        ParamSpec("markers_topic", "/ergonomics_markers", "MarkerArray topic", topic_name,
                  read_only=True),
    ]


class ErgonomicsNode(Node):
    """Publishes one human's REBA/RULA scores during playback.

    Parameters
    ----------
    playback : Playback, optional
        The skeleton publisher's playback (same process); without it the node follows
        ``task_state``.
    store : MotionStore, optional
        Where to find motions when following ``task_state``.
    """

    def __init__(self, *, playback: Playback | None = None, store: MotionStore | None = None,
                 node_name: str = "ergonomics_node", **node_kwargs: Any) -> None:
        super().__init__(node_name, **node_kwargs)
        declare_parameters(self, ergonomics_parameters())
        self.human_id = str(self.param("human_id"))
        self.follower = PlaybackFollower.from_parameters(self, playback, store)
        self.following, self.playback = self.follower.following, self.follower.playback
        self._scores: BoundedCache[tuple[np.ndarray, ...]] = BoundedCache(16)
        self.messages_published = 0
        self._pub = self.create_publisher(ErgonomicsState, "ergonomics", STREAM_QOS)
        self._marker_pub = self.create_publisher(MarkerArray, self.param("markers_topic"),
                                                 STREAM_QOS)
        self._timer = self.create_timer(1.0 / self.param("rate"), self._tick,
                                        callback_group=MutuallyExclusiveCallbackGroup())
        self.get_logger().info(f"ergonomics of human {self.human_id} at "
                               f"{self.param('rate'):g} Hz")

    def param(self, name: str) -> Any:
        return self.get_parameter(name).value

    def scores(self, motion_id: str, motion: Any
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per-frame REBA, RULA, load (kg) and trunk flexion (deg) of a motion (cached)."""
        def build() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
            rep = assess_motion(motion, cell_masses(self.param("cell")))
            return rep.reba, rep.rula, rep.load, rep.angles.trunk_flexion

        return self._scores.get_or_build(motion_id, build)

    def _tick(self) -> None:
        now = self.get_clock().now()
        frame = self.playback.frame_at(now.nanoseconds * 1e-9)
        motion = self.playback.motion
        if frame is None or motion is None:
            return
        reba, rula, load, trunk = self.scores(frame.motion_id, motion)
        i = int(np.clip(frame.index, 0, len(reba) - 1))
        msg = ErgonomicsState()
        msg.header.stamp = now.to_msg()
        msg.header.frame_id = self.param("world_frame")
        msg.human_id, msg.motion_id = self.human_id, frame.motion_id
        msg.motion_time = float(frame.time)
        msg.current_task = frame.task.current_task
        msg.reba, msg.rula = int(reba[i]), int(rula[i])
        msg.reba_action_level = int(reba_mod.action_level(reba[i]))
        msg.rula_action_level = int(rula_mod.action_level(rula[i]))
        msg.load, msg.trunk_flexion = float(load[i]), float(trunk[i])
        self._pub.publish(msg)
        self._marker_pub.publish(self.markers(msg, frame.positions, now.to_msg()))
        self.messages_published += 1

    def markers(self, state: ErgonomicsState, positions: np.ndarray, stamp: Any
                ) -> MarkerArray:
        """A sphere coloured by the REBA action level and the scores as text, above the
        head (``positions``: the frame's joints (J, 3))."""
        f = cv.MarkerFactory(self.param("world_frame"), stamp, 3.0 / self.param("rate"))
        ns = f"{cv.human_prefix(self.human_id)}/ergonomics"
        top = np.asarray(positions)[JOINT_INDEX["head"]] + np.array([0.0, 0.0, MARKER_HEIGHT])
        rgba = cv.color(*LEVEL_COLORS[min(max(state.reba_action_level, 0), 4)])
        ball = f.sphere_list(ns, 0, top[None], rgba, 0.12)
        text = f.make(ns, 1, Marker.TEXT_VIEW_FACING, rgba, (0.0, 0.0, 0.1))
        text.pose.position.x, text.pose.position.y = float(top[0]), float(top[1])
        text.pose.position.z = float(top[2] + 0.14)
        text.text = f"REBA {state.reba}  RULA {state.rula}"
        return MarkerArray(markers=[ball, text])
