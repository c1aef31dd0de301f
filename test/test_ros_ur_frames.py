"""The robot's TF frames follow ur_description (issue 38 item 6): its link names, and its
joint origins placed so that ``tool0`` is the DH flange of our kinematics, for every UR
model, at random joint positions."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.robot.kinematics import forward_kinematics, ur_model
from ltl_human_motion.ros import ur_frames


def _static(parent: str, child: str) -> np.ndarray:
    return next(f.transform for f in ur_frames.STATIC_FRAMES
                if (f.parent, f.child) == (parent, child))


@pytest.mark.parametrize("name", ["ur3e", "ur5e", "ur10e", "ur16e"])
def test_tool0_is_the_dh_flange_and_every_link_sits_on_its_joint(name: str) -> None:
    model = ur_model(name)
    rng = np.random.default_rng(7)
    base_link_in_base = np.linalg.inv(ur_frames.BASE_IN_BASE_LINK)
    for q in rng.uniform(-np.pi, np.pi, (25, 6)):
        dh = forward_kinematics(q, model)
        pose = base_link_in_base @ _static("base_link", "base_link_inertia")
        for k, link in enumerate(ur_frames.link_transforms(q, model)):
            pose = pose @ link
            # ur_description puts each link's frame on the axis of the joint moving it
            # (z along the axis): the DH frame before that joint has the same z axis.
            axis_point = dh[k][:3, 3]
            offset = pose[:3, 3] - axis_point
            np.testing.assert_allclose(np.cross(offset, dh[k][:3, 2]), 0.0, atol=1e-9)
            np.testing.assert_allclose(abs(pose[:3, 2] @ dh[k][:3, 2]), 1.0, atol=1e-9)
        tool0 = pose @ _static("wrist_3_link", "flange") @ _static("flange", "tool0")
        np.testing.assert_allclose(tool0, dh[6], atol=1e-9)


def test_names_are_ur_descriptions() -> None:
    assert ur_frames.UR_LINKS == ("shoulder_link", "upper_arm_link", "forearm_link",
                                  "wrist_1_link", "wrist_2_link", "wrist_3_link")
    assert {(f.parent, f.child) for f in ur_frames.STATIC_FRAMES} == {
        ("base_link", "base_link_inertia"), ("base_link", "base"),
        ("wrist_3_link", "flange"), ("flange", "tool0")}
