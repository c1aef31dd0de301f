"""The REP 155 variant of the worker's URDF (``worker_urdf(..., rep155=True)``) against
the REP's text (REP 155, "Kinematic Model and Coordinate Frames"):

* "The body frame is named ``body_<bodyID>`` ... The origin of the frame is located at
  the mid point of the line connecting the hips. ... The ``x`` axis is expected to point
  forward ..., the ``z`` axis ... toward the head."
* "The other skeleton points published as TF frames must be parented to the root
  ``body_<bodyID>`` frame, and all be suffixed with the same ``_<bodyID>``."
* "each of these links and joints must be suffixed with the corresponding ``<bodyID>``";
  the recommended model's links and joints are :data:`REP_LINKS` and :data:`REP_JOINTS`.
"""

from __future__ import annotations

import numpy as np
import pytest

urdf_parser = pytest.importorskip("urdf_parser_py.urdf")

from test_motion_urdf import forward_kinematics  # noqa: E402

from ltl_human_motion.motion import urdf  # noqa: E402
from ltl_human_motion.motion.skeleton import JOINT_INDEX, JOINT_NAMES, Skeleton  # noqa: E402

#: Metres the body origin may be from the hip joints' midpoint in a synthesized motion:
#: S1 (seed 3) turns its pelvis -> hip bones by up to 16 mm at the hips (median 0.04 mm).
HIP_SLACK = 0.02
#: Links of REP 155's recommended kinematic model (its diagram) that our skeleton has: the
#: REP's ``waist``, ``torso`` and the head's intermediate links have no equivalent.
REP_LINKS = ("body", "head", "l_shoulder", "l_elbow", "l_wrist", "r_shoulder", "r_elbow",
             "r_wrist", "l_hip", "l_knee", "l_ankle", "r_hip", "r_knee", "r_ankle")
#: REP 155's recommended revolute joints -> the skeleton joint they turn about (where our
#: joint of that name must sit) and the axis their name says (r: x, p: y, y: z; the
#: hinges elbow, knee and waist bend forward, about y).
REP_JOINTS: dict[str, tuple[str, str]] = {
    "waist": ("pelvis", "y"), "r_head": ("neck", "x"), "y_head": ("neck", "z"),
    "p_head": ("neck", "y"),
    **{f"{s}_{a}_shoulder": (f"{s}_shoulder", axis) for s in "lr"
       for a, axis in (("y", "z"), ("p", "y"), ("r", "x"))},
    **{f"{s}_elbow": (f"{s}_elbow", "y") for s in "lr"},
    **{f"{s}_{a}_hip": (f"{s}_hip", axis) for s in "lr"
       for a, axis in (("y", "z"), ("p", "y"), ("r", "x"))},
    **{f"{s}_knee": (f"{s}_knee", "y") for s in "lr"},
}


def _robot(stature: float, body: str) -> object:
    return urdf_parser.URDF.from_xml_string(urdf.worker_urdf(stature, body, rep155=True))


@pytest.mark.parametrize("body", ["h1", "67dd1"])
def test_every_link_and_joint_ends_in_the_body_id(body: str) -> None:
    robot = _robot(1.75, body)
    links = [link.name for link in robot.links]
    joints = [joint.name for joint in robot.joints]
    assert len(links) == len(set(links)) and len(joints) == len(set(joints))
    names = links + joints
    assert [n for n in names if not n.endswith(f"_{body}")] == []
    assert robot.get_root() == f"body_{body}"
    assert {f"{name}_{body}" for name in REP_LINKS} <= {link.name for link in robot.links}


@pytest.mark.parametrize("stature", [1.55, 1.95])
def test_recommended_joint_names_sit_where_the_rep_puts_them(stature: float) -> None:
    robot = _robot(stature, "b")
    rest = Skeleton(stature).rest_positions()
    root = np.eye(4)[None].copy()
    root[0, :3, 3] = urdf.root_poses(rest[None], Skeleton(stature), rep155=True)[0, :3, 3]
    revolute = [j for j in robot.joints if j.type == "revolute"]
    assert [j.name for j in revolute] == urdf.joint_names("b", rep155=True)
    poses = forward_kinematics(robot, root, {j.name: np.zeros(1) for j in revolute})
    by_name = {j.name: j for j in revolute}
    for name, (joint, axis) in REP_JOINTS.items():
        urdf_joint = by_name[f"{name}_b"]
        np.testing.assert_allclose(poses[urdf_joint.parent][0, :3, 3],
                                   rest[JOINT_INDEX[joint]], atol=1e-9, err_msg=name)
        assert list(urdf_joint.axis) == list(np.eye(3)["xyz".index(axis)]), name


def test_body_frame_is_at_the_hips_midpoint_x_forward_z_up() -> None:
    sk = Skeleton(1.75)
    rest = sk.rest_positions()
    body = urdf.root_poses(rest[None], sk, rep155=True)[0]
    hips = (rest[JOINT_INDEX["l_hip"]] + rest[JOINT_INDEX["r_hip"]]) / 2
    np.testing.assert_allclose(body[:3, 3], hips, atol=1e-12)
    np.testing.assert_allclose(body[:3, :3], np.eye(3), atol=1e-9)   # rest faces +x, z up
    assert np.linalg.norm(urdf.hip_offset(sk)) > 0.03    # not the pelvis joint


def test_forward_kinematics_of_a_motion_from_the_rep155_body_frame() -> None:
    """FK of the REP 155 URDF from ``root_poses(rep155=True)`` and the joint angles gives
    the motion's joint positions, and the body origin stays at the hips' midpoint."""
    from ltl_human_motion.planning import synthesize
    from ltl_human_motion.scene import cell_by_name

    motion = synthesize("S1", cell_by_name("paper_cell"), seed=3)[0].motion
    pos = np.asarray(motion.positions)[::10]
    robot = _robot(float(motion.skeleton.stature), "h1")
    roots = urdf.root_poses(pos, motion.skeleton, rep155=True)
    angles = urdf.joint_angles(pos, motion.skeleton)
    names = urdf.joint_names("h1", rep155=True)
    fk = forward_kinematics(robot, roots, {n: angles[:, k] for k, n in enumerate(names)})
    for j, name in enumerate(JOINT_NAMES):
        np.testing.assert_allclose(fk[urdf.link_name(name, "h1", rep155=True)][:, :3, 3],
                                   pos[:, j], atol=1e-3, err_msg=name)
    # The origin is the midpoint of the pelvis segment's hip sockets; the hip joints
    # leave them only by the pelvis -> hip bones' retargeting slack (RIGID_LIMIT).
    hips = (pos[:, JOINT_INDEX["l_hip"]] + pos[:, JOINT_INDEX["r_hip"]]) / 2
    off = np.linalg.norm(roots[:, :3, 3] - hips, axis=1)
    assert np.median(off) < 1e-3 and off.max() < HIP_SLACK, (np.median(off), off.max())


def test_the_default_model_keeps_its_pelvis_root() -> None:
    """The whole-body program's model (no ``rep155``) keeps ``body_<id>`` at the pelvis
    joint and its own joint names; only the intermediate links were renamed."""
    robot = urdf_parser.URDF.from_xml_string(urdf.worker_urdf(1.75, "wbik"))
    assert robot.get_root() == urdf.link_name("pelvis", "wbik") == "body_wbik"
    assert urdf.joint_names("wbik")[0] == "lumbar_y_wbik"
    assert all(link.name.endswith("_wbik") for link in robot.links)
