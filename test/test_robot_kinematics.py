"""UR kinematics, trajectories and the simulated controller's state (no sockets)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.robot import (
    UR_MODELS,
    JointTrajectory,
    SimulatedUR,
    Waypoint,
    compact_axis_angle_from_matrix,
    default_pick_and_place,
    forward_kinematics,
    load_robot_config,
    matrix_from_compact_axis_angle,
    pose_from_xyz_rpy,
    robot_capsules,
    tcp_pose,
    ur_model,
)

CONFIG = Path(__file__).resolve().parents[1] / "config" / "ur_pick_place.yaml"


class FakeClock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def test_ur5e_zero_configuration_matches_dh_closed_form() -> None:
    m = ur_model("UR5e")
    pose = tcp_pose(np.zeros(6), m)
    # At q = 0: x = a2 + a3, y = -(d4 + d6), z = d1 - d5.
    assert pose[:3] == pytest.approx([-0.425 - 0.3922, -(0.1333 + 0.0996), 0.1625 - 0.0997])
    # Flange orientation: rotation of pi/2 about x (from the DH twists).
    R = matrix_from_compact_axis_angle(pose[3:])
    assert R @ np.array([0, 0, 1.0]) == pytest.approx([0, -1.0, 0], abs=1e-12)


def test_forward_kinematics_is_vectorized_and_rigid() -> None:
    rng = np.random.default_rng(1)
    q = rng.uniform(-np.pi, np.pi, size=(5, 4, 6))
    frames = forward_kinematics(q, "ur10e")
    assert frames.shape == (5, 4, 7, 4, 4)
    R = frames[..., :3, :3]
    eye = np.broadcast_to(np.eye(3), R.shape)
    assert np.allclose(R @ np.swapaxes(R, -1, -2), eye, atol=1e-12)
    single = forward_kinematics(q[2, 3], "ur10e")
    assert np.allclose(single, frames[2, 3])
    # Joint 1 rotates everything about the base z axis: z of the flange is unchanged.
    q2 = q[0, 0].copy()
    q2[0] += 0.7
    assert tcp_pose(q2, "ur10e")[2] == pytest.approx(tcp_pose(q[0, 0], "ur10e")[2])


def test_axis_angle_round_trip_including_near_pi() -> None:
    rng = np.random.default_rng(2)
    axes = rng.normal(size=(200, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = np.concatenate([rng.uniform(0, np.pi, 190), np.full(5, np.pi), np.full(5, 1e-9)])
    v = axes * angles[:, None]
    R = matrix_from_compact_axis_angle(v)
    back = compact_axis_angle_from_matrix(R)
    assert np.allclose(matrix_from_compact_axis_angle(back), R, atol=1e-9)
    regular = angles < np.pi - 1e-6
    assert np.allclose(back[regular], v[regular], atol=1e-7)
    from ltl_human_motion.robot import axis_angle_from_matrix  # the package's old name
    np.testing.assert_array_equal(axis_angle_from_matrix(R), back)


def test_models_and_capsules() -> None:
    assert set(UR_MODELS) == {"ur3e", "ur5e", "ur10e", "ur16e"}
    base = pose_from_xyz_rpy([1.0, -1.0, 0.85], [0, 0, math.pi / 2])
    seg, radii = robot_capsules(np.zeros(6), "ur5e", base)
    assert seg.shape == (7, 2, 3) and radii.shape == (7,)
    assert seg[0, 0] == pytest.approx([1.0, -1.0, 0.85])        # base at the configured pose
    assert np.allclose(seg[1:, 0], seg[:-1, 1])                  # a connected chain
    flange = base @ forward_kinematics(np.zeros(6), "ur5e")[6]
    assert seg[6, 0] == pytest.approx(flange[:3, 3])
    assert np.linalg.norm(seg[6, 1] - seg[6, 0]) == pytest.approx(0.15)  # tool capsule
    # Reach grows with the model.
    reach = {n: np.linalg.norm(tcp_pose(np.zeros(6), n)[:3]) for n in UR_MODELS}
    assert reach["ur3e"] < reach["ur5e"] < reach["ur10e"]
    batch, _ = robot_capsules(np.zeros((3, 6)), "ur3e")
    assert batch.shape == (3, 7, 2, 3)


@pytest.mark.parametrize("bad", [np.zeros(5), np.full(6, np.nan), np.zeros((2, 7))])
def test_kinematics_rejects_bad_joints(bad: np.ndarray) -> None:
    with pytest.raises(ValueError, match="joint positions"):
        tcp_pose(bad)


def test_unknown_model_and_bad_base() -> None:
    with pytest.raises(ValueError, match="unknown UR model"):
        ur_model("ur7")
    with pytest.raises(ValueError, match="base"):
        robot_capsules(np.zeros(6), "ur5e", np.eye(3))


def test_trajectory_is_smooth_and_loops() -> None:
    traj = default_pick_and_place()
    T = traj.cycle_time
    assert T == pytest.approx(6.2)
    t = np.linspace(0, 2 * T, 4001)
    q = traj.positions(t)
    # Continuous (no jumps), periodic, and at rest at the waypoints.
    assert np.max(np.abs(np.diff(q, axis=0))) < 0.01
    assert traj.position(0.3) == pytest.approx(traj.position(0.3 + T))
    for w, start in zip(traj.waypoints[1:], np.cumsum([w.move_time + w.dwell
                                                       for w in traj.waypoints])[:-1]):
        qq, qd, _ = traj.sample(start + w.move_time)
        assert qq == pytest.approx(np.array(w.q), abs=1e-9)
        assert np.allclose(qd, 0.0, atol=1e-9)
    with pytest.raises(ValueError, match="at least 2"):
        JointTrajectory([Waypoint("a", (0.0,) * 6, 1.0)])
    with pytest.raises(ValueError, match="move_time"):
        JointTrajectory([Waypoint("a", (0.0,) * 6, 0.0), Waypoint("b", (0.0,) * 6, 1.0)])


def test_robot_config_file() -> None:
    cfg = load_robot_config(CONFIG)
    assert cfg["model"] == "ur5e"
    assert cfg["trajectory"].cycle_time == pytest.approx(6.2)
    base = pose_from_xyz_rpy(cfg["base_xyz"], cfg["base_rpy"])
    seg, _ = robot_capsules(cfg["trajectory"].positions(np.linspace(0, 6.2, 200)), "ur5e", base)
    assert seg[..., 2].min() >= 0.85 - 1e-9   # never below the bench top it stands on


def test_simulated_ur_speed_slider_scales_trajectory_time() -> None:
    clock = FakeClock()
    sim = SimulatedUR("ur5e", clock=clock)
    clock.t += 1.0
    sim.step()
    assert sim.trajectory_time == pytest.approx(1.0)
    assert sim.set_speed_slider(0.25)
    clock.t += 2.0
    sim.step()
    assert sim.trajectory_time == pytest.approx(1.5)
    assert sim.speed_scaling == pytest.approx(0.25)
    assert not sim.set_speed_slider(float("nan"))
    assert sim.speed_slider == pytest.approx(0.25)


def test_simulated_ur_protective_stop_and_cycle_times() -> None:
    clock = FakeClock()
    sim = SimulatedUR("ur5e", clock=clock)
    for _ in range(700):   # 7 s at full speed: one full cycle of 6.2 s
        clock.t += 0.01
        sim.step()
    assert sim.cycle_times == [pytest.approx(6.2, abs=0.011)]
    sim.protective_stop("test")
    q = sim.joint_positions()
    clock.t += 1.0
    sim.step()
    assert sim.safety_mode == 3 and sim.speed_scaling == 0.0
    assert np.array_equal(sim.joint_positions(), q)
    assert sim.unlock_protective_stop()
    clock.t += 0.5
    sim.step()
    assert not np.array_equal(sim.joint_positions(), q)
    assert [e.kind for e in sim.events] == ["protective_stop", "unlock_protective_stop"]


def test_simulated_ur_zero_slider_then_change_is_a_protective_stop() -> None:
    sim = SimulatedUR("ur5e", clock=FakeClock())
    sim.set_speed_slider(0.0)
    assert sim.safety_mode == 1
    sim.set_speed_slider(0.5)
    assert sim.safety_mode == 3


@pytest.mark.parametrize(("text", "match"), [
    ("trajectory: {units: grad, waypoints: [{q: [0, 0, 0, 0, 0, 0]}]}", "units"),
    ("trajectory: {waypoints: [{name: a}]}", "needs a mapping with 'q'"),
    ("trajectory: {waypoints: [{q: [0, 0, 0]}, {q: [0, 0, 0]}]}", "6"),
    ("base: [1, 2, 3]", "base"),
    ("- just a list", "mapping"),
])
def test_robot_config_errors_name_the_problem(tmp_path: Path, text: str, match: str) -> None:
    path = tmp_path / "robot.yaml"
    path.write_text(text)
    with pytest.raises(ValueError, match=match):
        load_robot_config(path)
