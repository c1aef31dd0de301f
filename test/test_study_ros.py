"""Ergonomics in ROS over real DDS: the synthesis response's cycle time and worst
REBA/RULA, and ``/human_1/ergonomics`` with its coloured marker during playback.

One in-process bringup (synthesis node, skeleton publisher, ergonomics node) serves the
module with the real planner; a client in its own rclpy context synthesizes S1, plays it
and watches the topics.
"""

from __future__ import annotations

import numpy as np
import pytest

rclpy = pytest.importorskip("rclpy")

from ltl_human_motion.msg import ErgonomicsState  # noqa: E402
from ltl_human_motion.srv import PlayMotion, SynthesizeMotion  # noqa: E402
from visualization_msgs.msg import MarkerArray  # noqa: E402

from ltl_human_motion.assess import assess_motion  # noqa: E402
from ltl_human_motion.ros.bringup import Bringup  # noqa: E402
from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402
from ltl_human_motion.ros.ergonomics import LEVEL_COLORS, cell_masses  # noqa: E402

pytestmark = pytest.mark.ros

BRINGUP = """\
bringup:
  ros__parameters:
    nodes: [synthesis_node, skeleton_publisher, ergonomics_node]
    humans: ["1"]
synthesis_node:
  ros__parameters:
    default_cell: paper_cell
/**/skeleton_publisher:
  ros__parameters:
    publish_rate: 30.0
    autoplay: false
/**/ergonomics_node:
  ros__parameters:
    rate: 10.0
    markers_topic: /ergonomics_markers
"""


@pytest.fixture(scope="module")
def node_set(tmp_path_factory):
    path = tmp_path_factory.mktemp("config") / "bringup.yaml"
    path.write_text(BRINGUP)
    bringup = Bringup(path, overrides={"store_dir": ""}).start()
    yield bringup
    bringup.shutdown()


@pytest.fixture(scope="module")
def session(node_set):
    with ClientSession("test_study_ros_client") as s:
        yield s


def test_synthesis_response_has_cycle_time_and_worst_scores(node_set, session):
    resp = session.call(SynthesizeMotion, "/synthesize_motion", SynthesizeMotion.Request(
        spec="S1", cell="paper_cell", variants=2, seed=1, cycles=1), timeout=60.0)
    assert resp.success, resp.error_message
    assert len(resp.cycle_times) == len(resp.reba_max) == len(resp.rula_max) == 2
    store = node_set.node("synthesis_node").store
    for i, motion_id in enumerate(resp.motion_ids):
        motion = store.get(motion_id)
        rep = assess_motion(motion, cell_masses("paper_cell"))
        assert resp.cycle_times[i] == pytest.approx(resp.durations[i])
        assert resp.reba_max[i] == rep.reba.max() and resp.rula_max[i] == rep.rula.max()
        assert 4 <= resp.reba_max[i] <= 15       # S1 picks O1 from 0.2 m: a deep bend
    bad = session.call(SynthesizeMotion, "/synthesize_motion", SynthesizeMotion.Request(
        spec="grasp(O1) & (F assemble(R1)", cell="paper_cell"), timeout=30.0)
    assert not bad.success and len(bad.reba_max) == 0


def test_ergonomics_topic_during_playback(node_set, session):
    resp = session.call(SynthesizeMotion, "/synthesize_motion", SynthesizeMotion.Request(
        spec="S1", cell="paper_cell", seed=3), timeout=60.0)
    assert resp.success, resp.error_message
    state = session.watch(ErgonomicsState, "/human_1/ergonomics", keep=200)
    markers = session.watch(MarkerArray, "/ergonomics_markers", keep=200)
    played = session.call(PlayMotion, "/human_1/play_motion", PlayMotion.Request(
        command="play", motion_id=resp.motion_ids[0], loop=True, rate=2.0))
    assert played.success, played.message
    wait_until(lambda: state.count >= 40, 15.0, "40 ergonomics messages")
    assert 7.0 <= state.rate(skip=2) <= 13.0                 # 10 Hz
    motion = node_set.node("synthesis_node").store.get(resp.motion_ids[0])
    rep = assess_motion(motion, cell_masses("paper_cell"))
    msgs = state.messages
    for m in msgs:
        assert m.human_id == "1" and m.motion_id == resp.motion_ids[0]
        i = int(np.clip(np.floor(m.motion_time * motion.fps), 0, motion.n_frames - 1))
        near = rep.reba[max(i - 1, 0):i + 2]
        assert near.min() <= m.reba <= near.max()
        assert 1 <= m.rula <= 7
    assert len({m.reba for m in msgs}) > 1                   # the posture changes
    # The marker's colour follows the REBA action level of the same instant.
    by_level = {}
    for arr in markers.messages:
        ball = arr.markers[0]
        text = arr.markers[1].text
        reba = int(text.split()[1])
        level = int(np.searchsorted([1, 3, 7, 10], reba, side="left"))
        by_level[level] = (ball.color.r, ball.color.g, ball.color.b)
    assert by_level
    for level, rgb in by_level.items():
        assert rgb == pytest.approx(LEVEL_COLORS[level][:3], abs=1e-6)
    session.call(PlayMotion, "/human_1/play_motion", PlayMotion.Request(command="stop"))
