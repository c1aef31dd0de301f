"""Configuration of the ROS layer: launch file vs bringup, params files, RViz, and the
plain-Python pieces (playback clock, motion store, CDR encoder, message definitions)."""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

rclpy = pytest.importorskip("rclpy")

from launch_stand_ins import launch_description, launched_nodes  # noqa: E402
from ltl_human_motion.msg import HumanOccupancy, PredictedOccupancy  # noqa: E402
from rclpy.serialization import deserialize_message  # noqa: E402
from ros_fakes import make_test_motion  # noqa: E402

from ltl_human_motion.planning.motion_store import MotionStore, check_motion_id  # noqa: E402
from ltl_human_motion.planning.playback import Playback  # noqa: E402
from ltl_human_motion.ros import conversions as cv  # noqa: E402
from ltl_human_motion.ros.bringup import Bringup  # noqa: E402
from ltl_human_motion.ros.launch_support.bringup_config import load_bringup_config  # noqa: E402
from ltl_human_motion.ros.occupancy_cdr import encode_human_occupancy  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
LAUNCH_FILE = ROOT / "launch" / "bringup.launch.py"
CONFIGS = [ROOT / "config" / "bringup.yaml", ROOT / "config" / "bringup_two_humans.yaml"]
KIND = {"SynthesisNode": "synthesis_node", "SkeletonPublisher": "skeleton_publisher",
        "OccupancyNode": "occupancy_node", "ErgonomicsNode": "ergonomics_node"}


# ------------------------------------------------------------------ launch vs bringup
def _launch_nodes(monkeypatch: pytest.MonkeyPatch, config: Path) -> list[dict[str, Any]]:
    """Run the launch file against recording stand-ins of launch/launch_ros (absent
    here) and return the keyword arguments of every launch_ros Node it creates."""
    description = launch_description(monkeypatch, LAUNCH_FILE)
    declared = [a for a in description if isinstance(a, tuple)]
    assert declared[0][1] == "config" and declared[0][2]["default_value"].endswith(
        "bringup.yaml")
    return launched_nodes(description, {"config": str(config)})


def _yaml_parameters(data: dict, namespace: str, name: str) -> dict[str, Any]:
    fqn = f"/{namespace}/{name}" if namespace else f"/{name}"
    out: dict[str, Any] = {}
    for key in ("/**", f"/**/{name}", name, fqn):
        out.update((data.get(key) or {}).get("ros__parameters", {}))
    return out


@pytest.mark.parametrize("config", CONFIGS, ids=lambda p: p.stem)
def test_launch_file_and_bringup_start_the_same_nodes_with_the_same_parameters(
        monkeypatch: pytest.MonkeyPatch, config: Path) -> None:
    launched = _launch_nodes(monkeypatch, config)
    data = yaml.safe_load(config.read_text())
    bringup = Bringup(config, overrides={"store_dir": ""})
    try:
        started = {(n.get_namespace(), n.get_name()): n for n in bringup.nodes}
        launched_keys = {("/" + (kw["namespace"] or "").strip("/"), kw["name"])
                         for kw in launched}
        assert launched_keys == set(started)
        for kw in launched:
            node = started[("/" + (kw["namespace"] or "").strip("/"), kw["name"])]
            assert kw["package"] == "ltl_human_motion"
            assert kw["executable"] == KIND[type(node).__name__]
            assert kw["parameters"][0] == str(config.resolve())
            extra = yaml.safe_load(Path(kw["parameters"][1]).read_text())["/**"][
                "ros__parameters"] if len(kw["parameters"]) > 1 else {}
            expected = {**_yaml_parameters(data, (kw["namespace"] or ""), kw["name"]), **extra}
            expected.pop("store_dir", None)            # overridden for this test
            declared = {k: v for k, v in expected.items() if node.has_parameter(k)}
            if extra:                       # per-human nodes get human_id and the file's
                assert len(declared) > len(extra), f"{kw['name']}: the file did not apply"
            for key, value in declared.items():
                assert node.get_parameter(key).value == value, (kw["name"], key)
    finally:
        bringup.shutdown()


def test_launch_file_imports_launch_only_inside_generate_launch_description() -> None:
    tree = ast.parse(LAUNCH_FILE.read_text())
    for node in tree.body:
        if isinstance(node, ast.Import | ast.ImportFrom):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) \
                else [node.module or ""]
            assert not any(n.split(".")[0] in ("launch", "launch_ros") for n in names)
    assert any(isinstance(n, ast.FunctionDef) and n.name == "generate_launch_description"
               for n in tree.body)


def test_bad_bringup_files_are_rejected(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("bringup:\n  ros__parameters:\n    nodes: [synthesis_node, teleporter]\n")
    with pytest.raises(ValueError, match=r"bringup\.nodes"):
        load_bringup_config(path)
    path.write_text("bringup:\n  ros__parameters:\n    humans: ['1', '1']\n")
    with pytest.raises(ValueError, match=r"bringup\.humans"):
        load_bringup_config(path)
    with pytest.raises(FileNotFoundError):
        load_bringup_config(tmp_path / "missing.yaml")


def test_rviz_config_shows_tf_markers_and_occupancy() -> None:
    config = yaml.safe_load((ROOT / "config" / "ltl_human_motion.rviz").read_text())
    manager = config["Visualization Manager"]
    assert manager["Global Options"]["Fixed Frame"] == "world"
    displays = {d["Class"]: d for d in manager["Displays"]}
    assert {"rviz_default_plugins/Grid", "rviz_default_plugins/TF",
            "rviz_default_plugins/MarkerArray"} <= set(displays)
    topics = {d["Topic"]["Value"] for d in manager["Displays"]
              if d["Class"] == "rviz_default_plugins/MarkerArray"}
    assert topics == {"/markers", "/occupancy_markers", "/ergonomics_markers",
                      "/robot_markers"}   # test_ros_rviz_config: all the bringups publish


# ------------------------------------------------------------------ plain-Python pieces
def test_playback_clock() -> None:
    motion = make_test_motion(duration=2.0, fps=60.0)
    playback = Playback()
    assert playback.frame_at(0.0) is None
    playback.play("m", motion, now=10.0, rate=2.0, loop=False)
    assert playback.motion_time(10.4) == pytest.approx(0.8)
    frame = playback.frame_at(10.4)
    np.testing.assert_allclose(frame.positions, motion.motion.positions[48], atol=1e-9)
    assert frame.task.current_task == "" and frame.task.next_task == "grasp(O1)"
    assert frame.task.progress == pytest.approx(0.8)
    assert playback.state(11.5) == "finished" and playback.motion_time(20.0) == 2.0
    playback.play("m", motion, now=0.0, loop=True)
    assert playback.motion_time(2.5) == pytest.approx(0.5)
    ahead = playback.positions_ahead(1.9, np.array([0.0, 0.2]))
    np.testing.assert_allclose(ahead[1], motion.motion.positions[6], atol=1e-9)
    playback.pause(now=1.5)
    assert playback.motion_time(5.0) == pytest.approx(1.5)
    frame = playback.frame_at(5.0)
    assert frame.task.current_task == "grasp(O1)" and 0 < frame.task.progress < 1
    np.testing.assert_allclose(frame.objects["O1"],
                               frame.positions[cv.JOINT_NAMES.index("r_hand")], atol=0.01)
    with pytest.raises(ValueError, match="cannot pause"):
        playback.pause(now=5.0)
    playback.resume(now=5.0)
    assert playback.motion_time(5.25) == pytest.approx(1.75)
    follower = Playback()
    follower.sync("m", motion, motion_time=1.0, at=100.0, rate=1.0, loop=True,
                  state="playing")
    assert follower.motion_time(100.5) == pytest.approx(1.5)
    with pytest.raises(ValueError, match="rate"):
        playback.set_rate(6.0, 0.0)
    playback.stop()
    assert playback.motion_time(6.0) is None


def test_motion_store_memory_and_folder(tmp_path: Path) -> None:
    motion = make_test_motion(duration=0.5)
    memory = MotionStore()
    motion_id = memory.add(motion)
    assert memory.get(motion_id) is motion and motion_id in memory
    with pytest.raises(KeyError, match="unknown motion id"):
        memory.get("motion_missing")
    with pytest.raises(ValueError, match="motion id"):
        check_motion_id("../escape")
    folder = MotionStore(tmp_path)
    saved = folder.add(motion, "kept_on_disk")
    assert (tmp_path / "kept_on_disk.npz").is_file() and saved == "kept_on_disk"
    other = MotionStore(tmp_path)                # e.g. a player in another process
    assert other.ids() == ["kept_on_disk"]
    np.testing.assert_allclose(other.get("kept_on_disk").motion.positions,
                               motion.motion.positions)
    assert not list(tmp_path.glob(".*"))         # no temporary files left


def test_occupancy_cdr_matches_rclpy() -> None:
    rng = np.random.default_rng(7)
    for n, k in [(11, 23), (1, 23), (3, 2), (2, 0)]:
        segments = rng.normal(size=(n, k, 2, 3))
        radii = rng.uniform(0.01, 0.2, k)
        offsets = np.arange(n) * 0.1
        names = [f"part{i}" * (i % 3 + 1) for i in range(k)]
        msg = HumanOccupancy()
        msg.header.stamp.sec, msg.header.stamp.nanosec = 1_700_000_000, 123_456_789
        msg.header.frame_id, msg.human_id = "world", "h" * (n % 4)
        msg.part_names = names
        msg.capsules = cv.capsule_messages(segments[0], radii)
        msg.prediction_horizon = float(offsets[-1]) if n > 1 else 0.0
        msg.predicted = [PredictedOccupancy(time_from_now=float(offsets[i]),
                                            capsules=cv.capsule_messages(segments[i], radii))
                         for i in range(1, n)]
        data = encode_human_occupancy(1_700_000_000, 123_456_789, "world", msg.human_id,
                                      names, segments, radii, offsets)
        assert deserialize_message(data, HumanOccupancy) == msg


def test_cylinder_orientation_turns_z_onto_the_capsule_axis() -> None:
    from scipy.spatial.transform import Rotation
    rng = np.random.default_rng(11)
    for v in [*rng.normal(size=(20, 3)), np.array([0, 0, 2.0]), np.array([0, 0, -0.5])]:
        q = cv.quaternion_z_to(v)
        turned = Rotation.from_quat([q.x, q.y, q.z, q.w]).apply([0.0, 0.0, 1.0])
        np.testing.assert_allclose(turned, v / np.linalg.norm(v), atol=1e-12)
    assert cv.quaternion_z_to(np.zeros(3)).w == 1.0


def test_playback_follower_follows_task_state_and_warns_once_per_missing_motion() -> None:
    from ltl_human_motion.msg import TaskState

    from ltl_human_motion.ros.playback_follower import PlaybackFollower

    context = rclpy.context.Context()
    rclpy.init(context=context)
    try:
        node = rclpy.create_node("follower_test", context=context)
        store = MotionStore()
        motion_id = store.add(make_test_motion(duration=2.0, fps=60.0))
        follower = PlaybackFollower(node, None, store, "", "task_state", "/motion_catalog")
        assert follower.following and node.count_subscribers("/motion_catalog") == 1
        assert node.count_subscribers("/task_state") == 1
        msg = TaskState(motion_id="motion_unknown", playback_state="playing", rate=1.0)
        follower.on_task_state(msg)
        follower.on_task_state(msg)
        assert follower.playback.motion is None
        assert follower._missing_warned == {"motion_unknown"}
        msg = TaskState(motion_id=motion_id, playback_state="playing", rate=1.0,
                        motion_time=0.5)
        msg.header.stamp.sec = 100
        follower.on_task_state(msg)
        assert follower.playback.motion_id == motion_id
        assert follower.playback.motion_time(100.5) == pytest.approx(1.0)
        follower.on_task_state(TaskState(playback_state="stopped"))
        assert follower.playback.motion_time(101.0) is None
        shared = Playback()
        assert PlaybackFollower(node, shared, store, "", "t2", "/c2").playback is shared
        assert node.count_subscribers("/t2") == 0
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)


def test_playback_follower_from_the_nodes_declared_parameters() -> None:
    from rclpy.parameter import Parameter

    from ltl_human_motion.ros.params import declare_parameters
    from ltl_human_motion.ros.playback_follower import PlaybackFollower, follower_parameters

    context = rclpy.context.Context()
    rclpy.init(context=context)
    try:
        node = rclpy.create_node("follower_params_test", context=context, parameter_overrides=[
            Parameter("task_state_topic", value="/h2/task_state"),
            Parameter("catalog_topic", value="/catalog_b")])
        declare_parameters(node, follower_parameters())
        follower = PlaybackFollower.from_parameters(node, None, MotionStore())
        assert follower.following
        assert node.count_subscribers("/h2/task_state") == 1
        assert node.count_subscribers("/catalog_b") == 1
        assert node.count_subscribers("/motion_catalog") == 0
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
