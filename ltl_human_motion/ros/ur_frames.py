"""A UR arm's TF frames as ur_description names and places them.

Universal Robots' ``ur_description`` (``urdf/ur_macro.xacro`` with a model's
``default_kinematics.yaml``) gives every link a frame at the joint that moves it, not at
the DH frames: ``base_link`` (root) -> ``base_link_inertia`` (turned by pi about z) ->
``shoulder_link`` -> ``upper_arm_link`` -> ``forearm_link`` -> ``wrist_1_link`` ->
``wrist_2_link`` -> ``wrist_3_link`` -> ``flange`` -> ``tool0``, and ``base_link -> base``
(the controller's base frame, in which the DH kinematics are written). The joint origins
are the DH parameters of :class:`~ltl_human_motion.robot.kinematics.URModel` placed as
the default kinematics of ur_description places them (d1, a2, a3, d4, d5, d6), so
``tool0`` is the DH flange frame (``test/test_ros_ur_frames.py`` checks it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ltl_human_motion.robot.kinematics import URModel

#: The links the six joints move, in order (ur_description's names).
UR_LINKS = ("shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link",
            "wrist_2_link", "wrist_3_link")


def _pose(xyz: tuple[float, float, float] = (0.0, 0.0, 0.0),
          rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """A URDF origin as a homogeneous transform (4, 4): translation, then fixed-axis r p y."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    T[:3, 3] = xyz
    return T


_PI = np.pi


@dataclass(frozen=True)
class StaticFrame:
    """A fixed transform (4, 4) from ``parent`` to ``child`` (names without prefix)."""

    parent: str
    child: str
    transform: np.ndarray


#: ur_description's fixed joints around the arm chain.
STATIC_FRAMES = (
    StaticFrame("base_link", "base_link_inertia", _pose(rpy=(0.0, 0.0, _PI))),
    StaticFrame("base_link", "base", _pose(rpy=(0.0, 0.0, _PI))),
    StaticFrame("wrist_3_link", "flange", _pose(rpy=(0.0, -_PI / 2, -_PI / 2))),
    StaticFrame("flange", "tool0", _pose(rpy=(_PI / 2, 0.0, _PI / 2))),
)
#: The controller's base frame in ``base_link`` (4, 4).
BASE_IN_BASE_LINK = STATIC_FRAMES[1].transform


def joint_origins(model: URModel) -> np.ndarray:
    """Origins (6, 4, 4) of the six revolute joints in their parent links (the default
    kinematics of ur_description, from the DH offsets and lengths of ``model``)."""
    d, a = model.d, model.a
    return np.array([
        _pose((0.0, 0.0, d[0])),
        _pose(rpy=(_PI / 2, 0.0, 0.0)),
        _pose((a[1], 0.0, 0.0)),
        _pose((a[2], 0.0, d[3])),
        _pose((0.0, -d[4], 0.0), (_PI / 2, 0.0, 0.0)),
        _pose((0.0, d[5], 0.0), (_PI / 2, _PI, _PI)),
    ])


def link_transforms(q: np.ndarray, model: URModel) -> np.ndarray:
    """Transforms (6, 4, 4) of each arm link in its parent (``base_link_inertia`` for the
    shoulder) at joint positions ``q`` (6,), rad: joint origin, then the turn about z."""
    out = joint_origins(model).copy()
    turn = np.zeros((6, 4, 4))
    c, s = np.cos(np.asarray(q, dtype=np.float64)), np.sin(np.asarray(q, dtype=np.float64))
    turn[:, 0, 0], turn[:, 0, 1], turn[:, 1, 0], turn[:, 1, 1] = c, -s, s, c
    turn[:, 2, 2] = turn[:, 3, 3] = 1.0
    return out @ turn
