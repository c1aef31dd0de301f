"""The ROS 2 part of the README demo, as one reusable function.

:func:`run_ros_demo` brings the node set up in this process (the bringup of
``config/bringup.yaml``), then -- from a separate client node in its own rclpy context,
so every call crosses DDS -- calls ``/synthesize_motion`` with the spec, plays the first
motion on ``/human_1/play_motion``, watches TF, markers, task state and occupancy while
it plays, records everything to ``<out_dir>/run.mcap`` and returns a summary (also
written to ``<out_dir>/ros_summary.json``).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from ltl_human_motion.atomic import atomic_write_text
from ltl_human_motion.msg import HumanOccupancy, TaskState
from ltl_human_motion.planning.playback import FINISHED
from ltl_human_motion.ros.bringup import Bringup
from ltl_human_motion.ros.client import ClientSession
from ltl_human_motion.srv import PlayMotion, SynthesizeMotion


def _stats_dict(stats: Any) -> dict[str, float]:
    names = ("automaton_time", "sequence_time", "planning_time", "blending_time",
             "verification_time", "total_time", "nodes_expanded", "real_time_factor")
    return {n: float(getattr(stats, n)) for n in names}   # PlanningStats message fields


def run_ros_demo(spec: str, cell: str, out_dir: str | Path, duration: float | None = None,
                 record: bool = True, *, config: str | Path | None = None,
                 human_id: str = "1", seed: int = 0, playback_rate: float = 1.0,
                 synthesis_timeout: float = 900.0,
                 synthesize_fn: Callable[..., list] | None = None) -> dict[str, Any]:
    """Bring up the nodes, synthesize ``spec`` over the service, play it, record it.

    Parameters
    ----------
    spec : str
        LTL specification (e.g. the paper's S2).
    cell : str
        Cell name (``config/<name>.yaml``) or inline cell YAML.
    out_dir : path
        Receives ``run.mcap``, ``motions/<id>.npz`` and ``ros_summary.json``.
    duration : float, optional
        Seconds to play; default the motion's duration (at ``playback_rate``) + 0.5 s.
    record : bool
        Write ``run.mcap``.

    Returns
    -------
    dict
        ``success``, ``error``, ``motion_ids``, ``task_sequence``, ``motion_duration``,
        ``synthesis_wall_time``, ``stats``, ``played_seconds``, ``received`` (per topic:
        count and rate as seen by the client), ``occupancy_rate_hz``, ``tf_frames``,
        ``markers_namespaces``, ``recorded`` (per topic: count and rate) and ``mcap``;
        ``occupancy_messages``, ``occupancy_deadlines_missed`` (deadlines a subscriber
        saw missed: gaps of 1.5 periods or more) and ``occupancy_worst_late_ms``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    mcap = out / "run.mcap" if record else None
    ns = f"/human_{human_id}"
    summary: dict[str, Any] = {"spec": spec, "cell": cell if "\n" not in cell else "<inline>",
                               "success": False, "error": ""}
    node_set = Bringup(config, record=mcap, synthesize_fn=synthesize_fn,
                       overrides={"store_dir": str(out / "motions"), "cell": cell})
    session: ClientSession | None = None
    try:
        node_set.start()
        session = ClientSession("demo_client")
        tf_log = session.watch(TFMessage, "/tf", keep=1)
        marker_log = session.watch(MarkerArray, "/markers", keep=300)
        state_log = session.watch(TaskState, f"{ns}/task_state", keep=1)
        occ_log = session.watch(HumanOccupancy, f"{ns}/occupancy", keep=0)

        started = time.monotonic()
        response = session.call(SynthesizeMotion, "/synthesize_motion", SynthesizeMotion.Request(
            spec=spec, cell=cell, seed=seed), timeout=synthesis_timeout,
            resend_after=min(30.0, synthesis_timeout))
        summary["synthesis_wall_time"] = round(time.monotonic() - started, 3)
        if not response.success:
            summary["error"] = response.error_message
            summary["error_line"], summary["error_column"] = (response.error_line,
                                                              response.error_column)
            return summary
        summary.update(motion_ids=list(response.motion_ids),
                       task_sequence=response.task_sequences[0],
                       motion_duration=float(response.durations[0]),
                       stats=_stats_dict(response.stats[0]))
        played = session.call(PlayMotion, f"{ns}/play_motion", PlayMotion.Request(
            command="play", motion_id=response.motion_ids[0], loop=False, rate=playback_rate))
        if not played.success:
            summary["error"] = f"play_motion: {played.message}"
            return summary
        play_for = duration if duration is not None \
            else response.durations[0] / playback_rate + 0.5
        t0 = time.monotonic()
        while time.monotonic() - t0 < play_for:
            last = state_log.last
            if duration is None and last is not None and last.playback_state == FINISHED:
                break
            time.sleep(0.05)
        summary["played_seconds"] = round(time.monotonic() - t0, 3)
        summary["received"] = session.watcher.summary()
        summary["occupancy_rate_hz"] = round(occ_log.rate(skip=5), 2)
        streams = [n for n in node_set.nodes if hasattr(n, "deadlines_missed")]
        summary["occupancy_messages"] = occ_log.count
        summary["occupancy_deadlines_missed"] = sum(n.deadlines_missed for n in streams)
        summary["occupancy_worst_late_ms"] = round(
            1e3 * max((n.worst_late for n in streams), default=0.0), 1)
        summary["tf_frames"] = sorted({t.child_frame_id for t in tf_log.last.transforms}) \
            if tf_log.last is not None else []
        summary["markers_namespaces"] = sorted({m.ns for a in marker_log.messages
                                                for m in a.markers})
        summary["success"] = occ_log.count > 0 and tf_log.count > 0
        if not summary["success"]:
            summary["error"] = "the played motion produced no TF or occupancy messages"
        return summary
    finally:
        if session is not None:
            session.close()
        path = node_set.shutdown()
        if node_set.recorder is not None:
            summary["recorded"] = node_set.recorder.summary()
        summary["mcap"] = str(path) if path is not None else None
        atomic_write_text(out / "ros_summary.json", json.dumps(summary, indent=2) + "\n")
