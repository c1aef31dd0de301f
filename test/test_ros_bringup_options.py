"""The in-process bringup under a namespace and on simulated time (issue 38 item 5), as a
plain rclpy client in another context sees it over DDS: the node set's service and own
topics under the namespace, TF and REP 155 topics global, every node's clock on
``/clock``, and the recording following the moved topics; and the CLI's options of the
same names in a real process.

``test_ros_launch.py`` checks that these options give each node the parameters the
launch arguments of the same names give the launched node."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

rclpy = pytest.importorskip("rclpy")

from ltl_human_motion.srv import SynthesizeMotion  # noqa: E402
from ros_fakes import scripted_synthesize  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402

from ltl_human_motion.ros.bringup import Bringup  # noqa: E402
from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402

pytestmark = pytest.mark.ros

CONFIG = Path(__file__).resolve().parents[1] / "config" / "bringup.yaml"
SIM_NS = 1_234_500_000_000          # 1234.5 s: a /clock time no wall clock shows


def test_bringup_under_a_namespace_on_sim_time(tmp_path: Path) -> None:
    bringup = Bringup(CONFIG, namespace="cell_c", use_sim_time=True,
                      record=tmp_path / "cell_c.mcap", synthesize_fn=scripted_synthesize,
                      overrides={"store_dir": str(tmp_path / "motions")}).start()
    try:
        assert sorted(n.get_fully_qualified_name() for n in bringup.nodes) == [
            "/cell_c/human_1/ergonomics_node", "/cell_c/human_1/occupancy_node",
            "/cell_c/human_1/skeleton_publisher", "/cell_c/synthesis_node"]
        with ClientSession("bringup_options_client") as session:
            node = session.node
            assert session.service_ready(SynthesizeMotion, "/cell_c/synthesize_motion", 30.0)

            def wired() -> bool:
                return (node.count_publishers("/cell_c/motion_catalog") == 1
                        and node.count_publishers("/cell_c/markers") == 1
                        and node.count_publishers("/humans/bodies/h1/urdf") == 1)
            wait_until(wired, 30.0, "the node set's wiring under /cell_c")
            for topic in ("/cell_c/occupancy_markers", "/cell_c/ergonomics_markers",
                          "/cell_c/human_1/occupancy", "/cell_c/human_1/task_state"):
                assert node.count_publishers(topic) == 1, topic
            for topic in ("/motion_catalog", "/markers", "/occupancy_markers",
                          "/human_1/occupancy"):
                assert node.count_publishers(topic) == 0, topic
            players = [n for n in bringup.nodes if n.get_namespace() == "/cell_c/human_1"]
            assert len(players) == 3 and all(
                n.get_parameter("catalog_topic").value == "/cell_c/motion_catalog"
                for n in players)

            clock = node.create_publisher(Clock, "/clock", 10)
            sec, nanosec = divmod(SIM_NS, 1_000_000_000)

            def on_sim_time() -> bool:
                clock.publish(Clock(clock=rclpy.time.Time(
                    seconds=sec, nanoseconds=nanosec).to_msg()))
                return all(n.get_clock().now().nanoseconds == SIM_NS for n in bringup.nodes)
            wait_until(on_sim_time, 30.0, "every node's clock at the /clock time")
            assert all(n.get_parameter("use_sim_time").value for n in bringup.nodes)
        wait_until(lambda: "/cell_c/motion_catalog" in bringup.recorder.summary(), 10.0,
                   "the namespaced catalog in the recording")
    finally:
        bringup.shutdown()
    recorded = bringup.recorder.summary()
    assert recorded["/cell_c/motion_catalog"]["count"] >= 1
    assert "/motion_catalog" not in recorded


def test_cli_bringup_takes_the_launch_arguments(tmp_path: Path) -> None:
    """``ltl-human-motion bringup --namespace --use-sim-time``: a real process; bad values
    stop it at once, naming the option."""
    base = [sys.executable, "-m", "ltl_human_motion", "bringup", str(CONFIG),
            "--store-dir", str(tmp_path / "m")]
    run = subprocess.run([*base, "--namespace", "/cell_d/", "--use-sim-time", "true",
                          "--duration", "2"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    banner = next(line for line in run.stderr.splitlines() if line.startswith("bringup: "))
    assert banner == ("bringup: /cell_d/synthesis_node, /cell_d/human_1/skeleton_publisher, "
                      "/cell_d/human_1/occupancy_node, /cell_d/human_1/ergonomics_node")
    for option, value, message in [
            ("--namespace", "9 lives", "argument --namespace: expected a ROS namespace such "
                                       "as 'cell_a', got '9 lives'"),
            ("--use-sim-time", "maybe", "argument --use-sim-time: expected true or false, "
                                        "got 'maybe'")]:
        bad = subprocess.run([*base, option, value], capture_output=True, text=True,
                             timeout=60)
        assert bad.returncode == 2 and message in bad.stderr, bad.stderr[-1000:]
