"""A bringup with a reactive player in place of the skeleton publisher, over real DDS.

The node set runs as ``ltl-human-motion bringup`` runs it (one process, the params file);
a client node in its own context calls the synthesis service with a reactive
specification, plays the strategy on the worker's play_motion and watches its task state
and occupancy stream (the occupancy node follows the reactive player).
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("rclpy")

from ltl_human_motion.msg import HumanOccupancy, TaskState
from ltl_human_motion.srv import PlayMotion, SynthesizeMotion

from ltl_human_motion.ros.bringup import Bringup
from ltl_human_motion.ros.client import ClientSession, wait_until
from ltl_human_motion.ros.launch_support.bringup_config import load_bringup_config

pytestmark = pytest.mark.ros

SPEC = "(G F !robot_in(R1)) -> (G(robot_in(R1) -> X !assemble(R1)) & G F assemble(R1))"
CONFIG = """
/**:
  ros__parameters:
    world_frame: world
    cell: paper_cell
bringup:
  ros__parameters:
    nodes: [{nodes}]
    humans: ["1"]
    executor_threads: 4
"""


def write_config(tmp: Path, nodes: str) -> Path:
    path = tmp / "bringup.yaml"
    path.write_text(CONFIG.format(nodes=nodes))
    return path


def test_a_reactive_player_and_skeleton_publisher_together_are_refused(tmp_path: Path):
    path = write_config(tmp_path, "synthesis_node, skeleton_publisher, reactive_player")
    with pytest.raises(ValueError, match="reactive_player plays the worker instead of "
                                         "skeleton_publisher"):
        load_bringup_config(path)


def test_bringup_plays_a_strategy_and_streams_the_worker_s_occupancy(tmp_path: Path):
    config = load_bringup_config(write_config(
        tmp_path, "synthesis_node, reactive_player, occupancy_node"))
    assert "/human_1/task_state" in config.topics()
    bringup = Bringup(config, overrides={"store_dir": str(tmp_path / "store")}).start()
    try:
        with ClientSession("reactive_bringup_client") as session:
            states = session.watch(TaskState, "/human_1/task_state", keep=1)
            occupancy = session.watch(HumanOccupancy, "/human_1/occupancy", keep=1)
            response = session.call(SynthesizeMotion, "/synthesize_motion",
                                    SynthesizeMotion.Request(spec=SPEC, cell="paper_cell"),
                                    timeout=300.0, resend_after=60.0)
            assert response.success, response.error_message
            played = session.call(PlayMotion, "/human_1/play_motion", PlayMotion.Request(
                command="play", motion_id=response.strategy_id), timeout=30.0,
                resend_after=5.0)
            assert played.success, played.message
            wait_until(lambda: states.last is not None
                       and states.last.strategy_id == response.strategy_id, 20.0,
                       "the strategy on /human_1/task_state")
            count = occupancy.count
            wait_until(lambda: occupancy.count > count + 20, 10.0,
                       "the worker's occupancy while the strategy plays")
            assert occupancy.last.human_id == "1"
            assert bringup.node("reactive_player", "1").executor_ is not None
    finally:
        bringup.shutdown()
