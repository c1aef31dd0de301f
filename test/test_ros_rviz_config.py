"""config/ltl_human_motion.rviz shows what the shipped bringups publish, and only that
(issue 38 item 4).

Both shipped bringups (config/bringup.yaml and config/bringup_coexistence.yaml) are
started for real, in turn; a client in its own rclpy context (its own DDS participant)
lists the topics they publish. Every topic of a type RViz's default displays show must
be in the config, and every topic the config names must be published by one of them.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

rclpy = pytest.importorskip("rclpy")

from ltl_human_motion.ros.bringup import Bringup  # noqa: E402
from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
RVIZ = ROOT / "config" / "ltl_human_motion.rviz"
BRINGUPS = (ROOT / "config" / "bringup.yaml", ROOT / "config" / "bringup_coexistence.yaml")

#: Types that rviz_default_plugins displays, by the display class that shows them.
DISPLAYS = {
    "visualization_msgs/msg/MarkerArray": "rviz_default_plugins/MarkerArray",
    "geometry_msgs/msg/PointStamped": "rviz_default_plugins/PointStamped",
    "tf2_msgs/msg/TFMessage": "rviz_default_plugins/TF",
}
#: Published types left out, and why.
NOT_SHOWN = {
    "sensor_msgs/msg/JointState": "shown through TF (the RobotModel's links)",
    "geometry_msgs/msg/TwistStamped": "no display in rviz_default_plugins",
    "hri_msgs/msg/IdsList": "a list of ids",
    "diagnostic_msgs/msg/DiagnosticArray": "rqt_robot_monitor's, not RViz's",
    "lifecycle_msgs/msg/TransitionEvent": "the synthesis node's lifecycle transitions",
}


def rviz_topics() -> dict[str, str]:
    """Topic -> display class of every enabled display of the config that reads one
    (TF reads /tf and /tf_static; a RobotModel its description topic)."""
    displays = yaml.safe_load(RVIZ.read_text())["Visualization Manager"]["Displays"]
    out: dict[str, str] = {}
    for d in displays:
        assert d.get("Enabled", True), d["Name"]
        if d["Class"] == "rviz_default_plugins/TF":
            out["/tf"] = out["/tf_static"] = d["Class"]
        elif d["Class"] == "rviz_default_plugins/RobotModel":
            assert d["Description Source"] == "Topic"
            assert d["Description Topic"]["Durability Policy"] == "Transient Local"
            out[d["Description Topic"]["Value"]] = d["Class"]
        elif "Topic" in d:
            out[d["Topic"]["Value"]] = d["Class"]
    return out


def shown(topic: str, type_name: str) -> str | None:
    """The display class that shows ``topic`` of ``type_name``, or None."""
    if type_name == "std_msgs/msg/String" and topic.endswith("/urdf"):
        return "rviz_default_plugins/RobotModel"
    return DISPLAYS.get(type_name)


@pytest.fixture(scope="module")
def published(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """Topic -> type of everything the shipped bringups publish (seen over DDS)."""
    out: dict[str, str] = {}
    with ClientSession("test_rviz_client") as client:
        for config in BRINGUPS:
            # 127.0.0.2: nothing serves RTDE there; the coexistence node only publishes.
            bringup = Bringup(config, overrides={
                "store_dir": str(tmp_path_factory.mktemp("m")), "robot_host": "127.0.0.2"})
            try:
                topics = bringup.config.topics()

                def seen(topics: dict[str, str] = topics) -> bool:
                    graph = dict(client.node.get_topic_names_and_types())
                    return all(t in graph and client.node.count_publishers(t) > 0
                               for t in topics)
                wait_until(seen, 20.0, f"the topics of {config.name} over DDS")
                for name, types in client.node.get_topic_names_and_types():
                    if client.node.count_publishers(name) > 0 and not name.startswith(
                            ("/rosout", "/parameter_events")):
                        out[name] = types[0]
            finally:
                bringup.shutdown()
    return out


def test_every_displayable_topic_is_in_the_config(published: dict[str, str]) -> None:
    config = rviz_topics()
    missing = {t: k for t, k in published.items()
               if shown(t, k) is not None and config.get(t) != shown(t, k)}
    assert not missing, f"published but not shown (or by the wrong display): {missing}"
    others = {k for t, k in published.items() if shown(t, k) is None}
    assert all(k.startswith("ltl_human_motion/") or k in NOT_SHOWN
               or k == "std_msgs/msg/String" for k in others), others


def test_every_topic_of_the_config_is_published(published: dict[str, str]) -> None:
    config = rviz_topics()
    stray = {t: c for t, c in config.items() if t not in published}
    assert not stray, f"the config shows topics no bringup publishes: {stray}"
    assert {"/ergonomics_markers", "/robot_markers", "/humans/bodies/h1/urdf"} <= set(config)
