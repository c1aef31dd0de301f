"""The worker's URDF (motion/urdf.py): it loads with urdf_parser_py, and forward
kinematics of the parsed model from our joint angles reproduces the joint positions of a
whole synthesized motion (the paper's S1)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

urdf_parser = pytest.importorskip("urdf_parser_py.urdf")

from ltl_human_motion.motion import urdf  # noqa: E402
from ltl_human_motion.motion.capsules import BODY_CAPSULES, capsule_radii  # noqa: E402
from ltl_human_motion.motion.skeleton import JOINT_NAMES, N_JOINTS, Skeleton  # noqa: E402

#: Issue 14: FK from the joint states reproduces our joint positions within 1 mm.
FK_TOLERANCE = 1e-3
#: Degrees a bent elbow or knee may turn about the link's x and z axes (see the test).
HINGE_OFF_AXIS_DEG = 5.0


def _transform(xyz: list[float] | None, rpy: list[float] | None) -> np.ndarray:
    T = np.eye(4)
    if rpy is not None:
        T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()   # URDF: fixed-axis r, p, y
    if xyz is not None:
        T[:3, 3] = xyz
    return T


def forward_kinematics(robot: object, root: np.ndarray, angles: dict[str, np.ndarray]
                       ) -> dict[str, np.ndarray]:
    """World poses (T, 4, 4) of every link of a parsed URDF, from the root link's poses
    (T, 4, 4) and revolute joint angles (name -> (T,))."""
    poses = {robot.get_root(): root}
    pending = list(robot.joints)
    while pending:
        joint = next(j for j in pending if j.parent in poses)
        pending.remove(joint)
        origin = _transform(joint.origin.xyz, joint.origin.rpy) if joint.origin is not None \
            else np.eye(4)
        local = np.broadcast_to(origin, root.shape).copy()
        if joint.type == "revolute":
            rot = Rotation.from_rotvec(np.outer(angles[joint.name], joint.axis)).as_matrix()
            local[:, :3, :3] = origin[:3, :3] @ rot
        else:
            assert joint.type == "fixed", joint.type
        poses[joint.child] = poses[joint.parent] @ local
    return poses


@pytest.fixture(scope="module")
def s1() -> object:
    from ltl_human_motion.planning import synthesize
    from ltl_human_motion.scene import cell_by_name

    return synthesize("S1", cell_by_name("paper_cell"), seed=3)[0]


@pytest.mark.parametrize("stature", [1.55, 1.75, 1.95])
def test_the_urdf_loads_and_matches_the_skeleton(stature: float) -> None:
    robot = urdf_parser.URDF.from_xml_string(urdf.worker_urdf(stature, "7"))
    assert robot.get_root() == "body_7"
    links = {link.name: link for link in robot.links}
    assert {urdf.link_name(j, "7") for j in JOINT_NAMES} <= set(links)
    revolute = [j for j in robot.joints if j.type == "revolute"]
    assert [j.name for j in revolute] == urdf.joint_names("7")
    assert len(revolute) == 3 * (N_JOINTS - 1)
    for joint in revolute:
        assert joint.limit.lower < 0 < joint.limit.upper or joint.limit.lower < joint.limit.upper
        assert joint.limit.effort > 0 and joint.limit.velocity > 0
    # Rest pose: all angles 0, root at the rest pelvis -> the skeleton's rest positions.
    rest = Skeleton(stature).rest_positions()
    root = np.eye(4)[None].copy()
    root[0, :3, 3] = rest[0]
    poses = forward_kinematics(robot, root, {j.name: np.zeros(1) for j in revolute})
    for j, name in enumerate(JOINT_NAMES):
        np.testing.assert_allclose(poses[urdf.link_name(name, "7")][0, :3, 3], rest[j],
                                   atol=1e-9)
    # Geometry: every body capsule's radius (scaled to the stature) is on some link.
    radii = sorted(round(float(g.geometry.radius), 5) for link in robot.links
                   for g in link.collisions if hasattr(g.geometry, "length"))
    expected = sorted(round(float(r), 5) for (_, a, b, _), r in
                      zip(BODY_CAPSULES, capsule_radii(stature), strict=True) if a != b)
    assert radii == expected
    assert all(link.inertial is not None and link.inertial.mass > 0 for link in robot.links)


def test_forward_kinematics_reproduces_a_whole_motion_within_1_mm(s1: object) -> None:
    positions = s1.positions
    skeleton = s1.motion.skeleton
    robot = urdf_parser.URDF.from_xml_string(urdf.worker_urdf(skeleton.stature, "1"))
    q = urdf.joint_angles(positions, skeleton)
    assert q.shape == (len(positions), 3 * (N_JOINTS - 1)) and np.isfinite(q).all()
    poses = forward_kinematics(robot, urdf.root_poses(positions, skeleton),
                               dict(zip(urdf.joint_names("1"), q.T, strict=True)))
    fk = np.stack([poses[urdf.link_name(n, "1")][:, :3, 3] for n in JOINT_NAMES], axis=1)
    error = np.linalg.norm(fk - positions, axis=-1)
    assert error.max() < FK_TOLERANCE, f"max FK error {error.max() * 1e3:.3f} mm"


def test_elbow_and_knee_bend_about_one_axis(s1: object) -> None:
    """Hinges: where bent (the twist that defines the plane fades out towards a straight
    limb), the forearm and the shank bend in the x-z plane of their parent link."""
    q = urdf.joint_angles(s1.positions, s1.motion.skeleton)
    names = urdf.joint_names("1")
    for joint in ("l_elbow", "r_elbow", "l_knee", "r_knee"):
        bend = np.abs(q[:, names.index(f"{joint}_y_1")])
        bent = bend > np.radians(30.0)
        assert bent.sum() > 10, joint
        off_axis = np.stack([q[bent, names.index(f"{joint}_{a}_1")] for a in "xz"])
        # The plane holds the bone, which is up to ~2 degrees off the link's z axis in the
        # rest pose (the upper arm slants outwards), so the off-axis angles are small,
        # not zero.
        assert np.abs(off_axis).max() < np.radians(HINGE_OFF_AXIS_DEG), joint


def test_bad_input_is_refused() -> None:
    with pytest.raises(ValueError, match="stature"):
        urdf.worker_urdf(3.0)
    with pytest.raises(ValueError, match="human_id"):
        urdf.worker_urdf(1.75, "")
