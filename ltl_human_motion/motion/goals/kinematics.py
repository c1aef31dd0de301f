"""The worker's kinematic model in pinocchio: the URDF of :mod:`..urdf` on a free-flyer
root (72 degrees of freedom), joint positions <-> configurations, the body's capsules and
a part in hand as the goal-motion program keeps them clear.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ltl_human_motion.motion.capsules import BODY_CAPSULES, capsule_radii
from ltl_human_motion.motion.skeleton import JOINT_INDEX, JOINT_NAMES
from ltl_human_motion.motion.urdf import joint_angles, joint_names, link_name, root_poses

__all__ = ["BODY_ID", "BodyKinematics", "HeldPart", "body_capsules", "body_kinematics",
           "frames_capsules", "point_jacobians"]

#: The body id of the model's link names.
BODY_ID = "wbik"
#: The joints ending each body capsule (K,), (K,).
CAPSULE_A = np.array([JOINT_INDEX[c[1]] for c in BODY_CAPSULES])
CAPSULE_B = np.array([JOINT_INDEX[c[2]] for c in BODY_CAPSULES])


class BodyKinematics:
    """The worker's URDF in pinocchio: joint positions <-> configurations.

    ``q`` is (7 + 66,): the root's position and quaternion (x y z w), then the revolute
    joints in pinocchio's order.
    """

    def __init__(self, stature: float) -> None:
        import pinocchio as pin

        from ltl_human_motion.motion.urdf import worker_urdf
        self.stature = float(stature)
        self.model = pin.buildModelFromXML(worker_urdf(stature, BODY_ID),
                                           pin.JointModelFreeFlyer())
        self.data = self.model.createData()
        names = joint_names(BODY_ID)
        self._q_index = np.array([self.model.idx_qs[self.model.getJointId(n)]
                                  for n in names])
        self.frames = np.array([self.model.getFrameId(link_name(j, BODY_ID))
                                for j in JOINT_NAMES])
        self._frame_ids = [int(f) for f in self.frames]
        self._jacobians: np.ndarray | None = None
        self.radii = capsule_radii(stature)

    def configurations(self, positions: np.ndarray, roots: np.ndarray | None = None
                       ) -> np.ndarray:
        """Configurations (T, nq) whose forward kinematics are ``positions`` (T, J, 3);
        ``roots`` (T, 4, 4): their :func:`.urdf.root_poses` where the caller has them."""
        from scipy.spatial.transform import Rotation
        pos = np.asarray(positions, dtype=np.float64)
        roots = root_poses(pos) if roots is None else roots
        q = np.zeros((len(pos), self.model.nq))
        q[:, :3] = roots[:, :3, 3]
        q[:, 3:7] = Rotation.from_matrix(roots[:, :3, :3]).as_quat()
        q[:, self._q_index] = joint_angles(pos)
        return q

    def positions(self, q: np.ndarray) -> np.ndarray:
        """Joint positions (J, 3) of configuration ``q`` (nq,); the joint Jacobians of
        ``q`` are computed on the way (:func:`point_jacobians` reads them)."""
        import pinocchio as pin
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        self._jacobians = None
        placements = self.data.oMf
        return np.array([placements[f].translation for f in self._frame_ids])

    def jacobians(self) -> np.ndarray:
        """Translational Jacobians (J, 3, nv) of every joint link at the configuration
        :meth:`positions` last computed (world frame), computed once per configuration."""
        import pinocchio as pin
        if self._jacobians is None:
            out = np.empty((len(self._frame_ids), 3, self.model.nv))
            for k, f in enumerate(self._frame_ids):
                out[k] = pin.getFrameJacobian(self.model, self.data, f,
                                              pin.LOCAL_WORLD_ALIGNED)[:3]
            self._jacobians = out
        return self._jacobians


@lru_cache(maxsize=8)
def body_kinematics(stature: float) -> BodyKinematics:
    """The cached :class:`BodyKinematics` of a stature."""
    return BodyKinematics(round(float(stature), 4))


def point_jacobians(kin: BodyKinematics, joints: np.ndarray) -> np.ndarray:
    """Translational Jacobians (K, 3, nv) of the joint links ``joints`` (K,) at the
    current kinematics (world frame; :meth:`BodyKinematics.jacobians`)."""
    return kin.jacobians()[np.asarray(joints, dtype=np.intp)]


@dataclass(frozen=True)
class HeldPart:
    """A part carried by a hand: its edges as zero-radius capsules relative to the
    holding joint, ``edges`` (E, 2, 3), and that joint's index."""

    joint: int
    edges: np.ndarray

    @staticmethod
    def box(joint: int, offset: np.ndarray, half: np.ndarray,
            rotation: np.ndarray | None = None) -> HeldPart:
        """A box of half extents ``half`` (3,) along the axes ``rotation`` (3, 3) (columns;
        default the motion frame's), centred ``offset`` (3,) from the holding joint (the
        part keeps its orientation, as carried parts do)."""
        s = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
        rot = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
        corners = np.asarray(offset) + (s * np.asarray(half)) @ rot.T
        edges = [(p, q) for p in range(8) for q in range(p + 1, 8)
                 if np.count_nonzero(s[p] != s[q]) == 1]
        return HeldPart(int(joint), np.array([[corners[p], corners[q]] for p, q in edges]))


def body_capsules(kin: BodyKinematics, pos: np.ndarray, held: HeldPart | None
              ) -> tuple[np.ndarray, ...]:
    """Capsule end points a, b (K, 3), radii (K,) and the joints that carry each end
    (K,), (K,): the body's, then the held part's edges (radius 0, carried by its joint)."""
    a, b, rad = pos[CAPSULE_A], pos[CAPSULE_B], kin.radii
    ja, jb = CAPSULE_A, CAPSULE_B
    if held is not None:
        e = held.edges + pos[held.joint]
        a = np.concatenate([a, e[:, 0]])
        b = np.concatenate([b, e[:, 1]])
        rad = np.concatenate([rad, np.zeros(len(e))])
        ja = np.concatenate([ja, np.full(len(e), held.joint)])
        jb = np.concatenate([jb, np.full(len(e), held.joint)])
    return a, b, rad, ja, jb


def frames_capsules(kin: BodyKinematics, pos: np.ndarray, held: HeldPart | None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`body_capsules` of every frame of ``pos`` (T, J, 3) at once: end points a, b
    (T, K, 3) and radii (K,) (the same numbers)."""
    a, b, rad = pos[:, CAPSULE_A], pos[:, CAPSULE_B], kin.radii
    if held is not None:
        e = held.edges[None] + pos[:, held.joint][:, None, None]
        a = np.concatenate([a, e[:, :, 0]], axis=1)
        b = np.concatenate([b, e[:, :, 1]], axis=1)
        rad = np.concatenate([rad, np.zeros(len(held.edges))])
    return a, b, rad
