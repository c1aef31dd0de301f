"""A URDF of the worker, generated for a stature, and its joint angles per frame.

The URDF reproduces the canonical 23-joint skeleton (:mod:`~ltl_human_motion.motion.skeleton`):

* Every skeleton joint ``j`` has a link ``<j>_<id>`` (the head ``head_<id>``, the pelvis
  ``body_<id>`` or, with ``rep155``, ``pelvis_<id>``) whose origin is the joint's
  position. Its axes are the rest pose's (x forward, y left, z up; REP 103) turned by the
  rotation of the bone that ends at ``j``, so a bone's rest offset is also its offset in
  the parent's link frame.
* Every bone ``p -> c`` is three revolute joints at ``p`` (a ball joint as three
  rotations about the axes of :data:`BONE_JOINTS`, outer to inner) with links
  ``<c>_bone_<axis>_<id>`` between them, a link ``<c>_bone_<id>`` that carries the bone's
  capsule, and a fixed joint ``<c>_end_<id>`` to ``<c>_<id>`` translated by the rest
  offset ``rest[c] - rest[p]``. Every link and joint name ends in ``_<id>``.
* The root link is ``body_<id>``; its pose in the world frame is the transform
  ``world -> body_<id>`` (:func:`root_poses`), which the skeleton publisher puts on TF
  (robot_state_publisher leaves floating roots to others). By default it sits at the
  pelvis joint (the whole-body program's model). With ``rep155`` it is REP 155's body
  frame: its origin at the midpoint of the hips (the pelvis link's hip sockets, rest
  offsets carried by the pelvis' rotation), its axes the pelvis link's, and the pelvis a
  fixed child link ``pelvis_<id>``; the revolute joints then take REP 155's recommended
  names (:func:`joint_names`).

Joint angles per frame (:func:`joint_angles`) come from the motion's positions with the
BVH exporter's rotations (:func:`~ltl_human_motion.motion.bone_rotations.joint_rotations`: swing
of each bone onto its current direction plus the twist references), corrected by one
swing per bone so that a parent with several children (pelvis, chest) places each of
them exactly. The skeleton's bone lengths are fixed, so forward kinematics from these
angles reproduces the joint positions (to rounding) whenever the motion keeps the
skeleton's bone lengths, as retargeted motions do.

Limits come from the human range of motion: the normative values of the American Academy
of Orthopaedic Surgeons, *Joint Motion: Method of Measuring and Recording* (AAOS, 1965;
tabulated in Greene & Heckman, *The Clinical Measurement of Joint Motion*, AAOS 1994),
for shoulder, elbow, forearm, wrist, hip, knee, ankle, cervical and thoracolumbar spine;
sternoclavicular motion from Ludewig et al., "Motion of the shoulder complex during
multiplanar humeral elevation", J Bone Joint Surg Am 91(2):378-389 (2009). Each is
mapped onto the axis it turns about in the rest pose (:data:`BONE_JOINTS`), with a margin
of :data:`LIMIT_MARGIN` because the three rotations of a ball joint are Euler angles, not
clinical planes. Pelvis-to-hip and chest-to-clavicle bones, rigid in a real body, get
:data:`RIGID_LIMIT` so that retargeting noise stays representable.

Geometry: the body capsules of :mod:`~ltl_human_motion.scene.occupancy`
(``BODY_CAPSULES`` radii scaled to the stature), each as a cylinder and two end spheres,
for both ``<visual>`` and ``<collision>``; masses and inertias follow the segment mass
fractions of Winter (2009, Table 4.1) at :data:`BODY_MASS`.

No ROS: plain numpy, scipy and the standard library's XML writer.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ltl_human_motion.motion.bone_rotations import (
    CHILDREN,
    kabsch_matrices,
    swing_matrices,
    twist_matrices,
    unit_vectors,
)
from ltl_human_motion.motion.capsules import BODY_CAPSULES, capsule_radii
from ltl_human_motion.motion.skeleton import JOINT_INDEX, JOINT_NAMES, PARENTS, Skeleton

#: Degrees of slack on every ROM limit (Euler angles of a ball joint vs clinical planes).
LIMIT_MARGIN = 15.0
#: Limits (degrees) of bones that are rigid in a real body (pelvis -> hip, chest -> clavicle).
RIGID_LIMIT = 30.0
#: Body mass (kg) for link inertias: 50th-percentile adult (ISO 7250-1 / Winter 2009 use
#: 70-75 kg; robot safety standards' body models use 75 kg).
BODY_MASS = 75.0
#: Effort (N m) and velocity (rad/s) on every joint: URDF requires them for revolute
#: joints; these are generous upper bounds of human joints (peak knee torque ~250 N m).
JOINT_EFFORT = 300.0
JOINT_VELOCITY = 20.0


@dataclass(frozen=True)
class BoneJoint:
    """The ball joint that turns the bone ending at ``child``.

    ``name`` is the anatomical joint (``l_shoulder`` turns the upper arm, which ends at
    ``l_elbow``); ``axes`` the rotation axes in the parent link frame, outer to inner;
    ``limits`` (lower, upper) in degrees per axis, before :data:`LIMIT_MARGIN`.
    """

    child: str
    name: str
    axes: str
    limits: tuple[tuple[float, float], tuple[float, float], tuple[float, float]]


def _side(name: str, axes: str, limits: tuple) -> tuple[BoneJoint, BoneJoint]:
    """Left and right versions of ``"<child>:<joint>"``: mirrored in the sagittal plane
    (y -> -y), rotations about x and z change sign, those about y do not."""
    left = BoneJoint("l_" + name.split(":")[0], "l_" + name.split(":")[1], axes, limits)
    flipped = tuple((-hi, -lo) if a in "xz" else (lo, hi)
                    for a, (lo, hi) in zip(axes, limits, strict=True))
    right = BoneJoint("r_" + name.split(":")[0], "r_" + name.split(":")[1], axes, flipped)
    return left, right


_R = (-RIGID_LIMIT, RIGID_LIMIT)
#: Rest directions: limbs hang along -z, so +y turns them backwards (extension), +x to
#: the left (abduction on the left side) and z is their twist. Spine bones point up (+z):
#: y is flexion (+)/extension (-), x lateral bending, z axial rotation. Clavicles point
#: sideways; feet forward (+x: y dorsi (-)/plantar (+) flexion, x inversion/eversion).
BONE_JOINTS: tuple[BoneJoint, ...] = (
    # Thoracolumbar (AAOS): flexion 80, extension 25, lateral bending 35, rotation 45,
    # shared between the lumbar and thoracic bones.
    BoneJoint("spine", "lumbar", "yxz", ((-15, 40), (-20, 20), (-20, 20))),
    BoneJoint("chest", "thoracic", "yxz", ((-10, 40), (-15, 15), (-25, 25))),
    # Cervical (AAOS): flexion 45, extension 45, lateral bending 45, rotation 60.
    BoneJoint("neck", "cervicothoracic", "yxz", ((-20, 20), (-15, 15), (-20, 20))),
    BoneJoint("head", "neck", "yxz", ((-45, 45), (-45, 45), (-60, 60))),
    *_side("clavicle:sternal", "zxy", (_R, _R, _R)),
    # Sternoclavicular (Ludewig 2009): protraction/retraction ~ +-30, elevation ~ 0..45,
    # axial rotation ~ 0..50; about x, +angle lifts the left clavicle.
    *_side("shoulder:sternoclavicular", "zxy", ((-30, 30), (-10, 45), (-50, 50))),
    # Shoulder (AAOS): flexion 180, extension 60, abduction 180, adduction 45 (across),
    # internal/external rotation 70/90.
    *_side("elbow:shoulder", "yxz", ((-180, 60), (-45, 180), (-90, 70))),
    # Elbow (AAOS): flexion 150, hyperextension ~10 (carrying angle in x); forearm
    # pronation/supination 80/80 as the twist.
    *_side("wrist:elbow", "yxz", ((-150, 10), (-20, 20), (-80, 80))),
    # Wrist (AAOS): flexion 80, extension 70, radial/ulnar deviation 20/30.
    *_side("hand:wrist", "yxz", ((-70, 80), (-30, 20), (-20, 20))),
    *_side("hip:pelvis", "yxz", (_R, _R, _R)),
    # Hip (AAOS): flexion 120, extension 30, abduction 45, adduction 30, rotation 45/45.
    *_side("knee:hip", "yxz", ((-120, 30), (-30, 45), (-45, 45))),
    # Knee (AAOS): flexion 135, hyperextension 10; tibial rotation ~ +-30 when flexed.
    *_side("ankle:knee", "yxz", ((-10, 135), (-10, 10), (-30, 30))),
    # Ankle (AAOS): dorsiflexion 20, plantarflexion 50; inversion 35, eversion 15;
    # forefoot abduction/adduction ~ +-20.
    *_side("toe:ankle", "yzx", ((-20, 50), (-20, 20), (-35, 15))),
)
_BY_CHILD = {b.child: b for b in BONE_JOINTS}

#: Segment mass fractions (Winter 2009, Table 4.1), by the link that carries the segment.
_MASS_FRACTION = {
    "spine": 0.139, "chest": 0.216, "neck": 0.0, "head": 0.081,
    "l_clavicle": 0.0, "r_clavicle": 0.0, "l_shoulder": 0.0, "r_shoulder": 0.0,
    "l_elbow": 0.028, "r_elbow": 0.028, "l_wrist": 0.016, "r_wrist": 0.016,
    "l_hand": 0.006, "r_hand": 0.006, "l_hip": 0.0, "r_hip": 0.0,
    "l_knee": 0.100, "r_knee": 0.100, "l_ankle": 0.0465, "r_ankle": 0.0465,
    "l_toe": 0.0145, "r_toe": 0.0145, "pelvis": 0.142,
}
#: Mass (kg) of links without a segment of their own (URDF tools want positive masses).
_MIN_MASS = 0.01


def link_name(joint: str, human_id: str, rep155: bool = False) -> str:
    """The URDF link (and TF frame) of skeleton joint ``joint`` for human ``human_id``
    (the pelvis' is the root ``body_<id>``, with ``rep155`` the root's child
    ``pelvis_<id>``)."""
    if joint == "pelvis" and not rep155:
        return f"body_{human_id}"
    return f"{joint}_{human_id}"


#: REP 155's rotation names of the axes (REP 103: roll about x, pitch y, yaw z).
_REP155_AXIS = {"x": "r", "y": "p", "z": "y"}
#: Our anatomical joints that REP 155's model names otherwise: the joint that turns the
#: head is its ``head`` joint, the lumbar spine its ``waist``.
_REP155_JOINT = {"neck": "head", "lumbar": "waist"}
#: REP 155's one-axis joints: their pitch axis takes the bare name (``l_elbow``).
_REP155_HINGES = ("elbow", "knee", "waist")


def rep155_joint_name(bone: BoneJoint, axis: str) -> str:
    """REP 155's recommended name (without the id) of ``bone``'s rotation about ``axis``:
    ``l_y_shoulder``, ``p_head``, ``l_elbow`` (a hinge's pitch), ``l_r_elbow``, ..."""
    side, base = (bone.name[:2], bone.name[2:]) if bone.name[:2] in ("l_", "r_") \
        else ("", bone.name)
    base = _REP155_JOINT.get(base, base)
    if base in _REP155_HINGES and axis == "y":
        return f"{side}{base}"
    return f"{side}{_REP155_AXIS[axis]}_{base}"


def joint_names(human_id: str, rep155: bool = False) -> list[str]:
    """Names of the URDF's revolute joints (3 per bone, 66), in :func:`joint_angles` order:
    ``<anatomical>_<axis>_<id>`` (``l_shoulder_y_7``), with ``rep155`` REP 155's names
    (:func:`rep155_joint_name`: ``l_p_shoulder_7``)."""
    if rep155:
        return [f"{rep155_joint_name(b, axis)}_{human_id}" for b in _bones()
                for axis in b.axes]
    return [f"{b.name}_{axis}_{human_id}" for b in _bones() for axis in b.axes]


def bone_joint(child: str) -> BoneJoint:
    """The ball joint that turns the bone ending at skeleton joint ``child``."""
    return _BY_CHILD[child]


def bone_chain(child: str, human_id: str) -> list[str]:
    """The links that the three revolute joints of the bone ending at skeleton joint
    ``child`` turn, outer to inner: ``<child>_bone_<axis>_<id>`` twice, then the bone's
    own link ``<child>_bone_<id>`` (which carries its capsule)."""
    axes = _BY_CHILD[child].axes
    return [f"{child}_bone_{axis}_{human_id}" for axis in axes[:2]] + [f"{child}_bone_{human_id}"]


def _bones() -> list[BoneJoint]:
    return [_BY_CHILD[JOINT_NAMES[j]] for j in range(len(JOINT_NAMES)) if PARENTS[j] >= 0]


#: Links turned about their bone so that the next bone bends in their x-z plane (elbow and
#: knee are hinges): link -> (child joint, rest direction the child bends towards).
_HINGE_TWIST: dict[str, tuple[str, tuple[float, float, float]]] = {
    "l_elbow": ("l_wrist", (1.0, 0.0, 0.0)), "r_elbow": ("r_wrist", (1.0, 0.0, 0.0)),
    "l_knee": ("l_ankle", (-1.0, 0.0, 0.0)), "r_knee": ("r_ankle", (-1.0, 0.0, 0.0)),
}
#: The chest link's twist follows the clavicles (as the BVH exporter's spine twist).
_LINE_TWIST: dict[str, tuple[str, str]] = {"chest": ("r_clavicle", "l_clavicle")}


def link_rotations(positions: np.ndarray, skeleton: Skeleton | None = None) -> np.ndarray:
    """World rotation of every joint's link per frame: (T, J, 3, 3) from positions (T, J, 3).

    The root's is the BVH exporter's pelvis rotation (a best fit of its three bones,
    ``bone_rotations.kabsch_matrices``).
    Every other link ``c`` (parent ``p``) is ``p``'s turned by the smallest rotation that
    puts the rest bone ``rest[c] - rest[p]`` onto the current one (the exporter's swing),
    then, for the chest, upper arms and thighs, turned about the bone by the exporter's
    twist so that the clavicle line, the forearm and the shank follow (elbow and knee
    then bend about their link's y axis only). Positions carry no twist of the other
    bones, so they have none relative to their parent.
    """
    skeleton = skeleton or Skeleton()
    pos = np.asarray(positions, dtype=np.float64)
    rest = skeleton.rest_positions()
    R = np.empty((len(pos), len(JOINT_NAMES), 3, 3))
    kids = list(CHILDREN[0])              # the BVH exporter's pelvis rotation
    R[:, 0] = kabsch_matrices(rest[kids] - rest[0], pos[:, kids] - pos[:, :1])
    for c in range(1, len(JOINT_NAMES)):
        p, name = PARENTS[c], JOINT_NAMES[c]
        rest_dir, _ = unit_vectors(rest[c] - rest[p])
        cur_dir, _ = unit_vectors(pos[:, c] - pos[:, p])
        moved = np.einsum("tij,j->ti", R[:, p], rest_dir)
        rot = swing_matrices(moved, cur_dir) @ R[:, p]
        if name in _HINGE_TWIST:
            child, towards = _HINGE_TWIST[name]
            k = JOINT_INDEX[child]
            rot = twist_matrices(rot, cur_dir, np.array(towards), pos[:, k] - pos[:, c])
        elif name in _LINE_TWIST:
            a, b = (JOINT_INDEX[j] for j in _LINE_TWIST[name])
            rot = twist_matrices(rot, cur_dir, rest[b] - rest[a], pos[:, b] - pos[:, a])
        R[:, c] = rot
    return R


def joint_angles(positions: np.ndarray, skeleton: Skeleton | None = None) -> np.ndarray:
    """Angles (T, 66) of :func:`joint_names` per frame, radians, from positions (T, J, 3).

    Not clipped to the limits: forward kinematics reproduces the motion as it is.
    """
    return angles_from_rotations(link_rotations(positions, skeleton))


def angles_from_rotations(rotations: np.ndarray) -> np.ndarray:
    """Joint angles (..., 66) from world link rotations (..., J, 3, 3)."""
    R = np.asarray(rotations, dtype=np.float64)
    lead = R.shape[:-3]
    R = R.reshape(-1, *R.shape[-3:])
    local = np.swapaxes(R[:, _PARENT_INDEX], -1, -2) @ R[:, 1:]          # (N, J-1, 3, 3)
    quats = Rotation.from_matrix(local.reshape(-1, 3, 3)).as_quat()
    return angles_from_local_quaternions(quats.reshape(len(R), -1, 4)).reshape(*lead, -1)


def angles_from_local_quaternions(quats: np.ndarray) -> np.ndarray:
    """Joint angles (N, 66) from each bone's rotation relative to its parent link, as
    quaternions x y z w (N, J-1, 4) (bone ``c - 1`` ends at joint ``c``)."""
    q = np.asarray(quats, dtype=np.float64)
    out = np.empty((len(q), len(JOINT_NAMES) - 1, 3))
    for axes, bones in _BONES_BY_AXES.items():      # one scipy call per rotation order
        out[:, bones] = Rotation.from_quat(q[:, bones].reshape(-1, 4)).as_euler(
            axes.upper()).reshape(len(q), len(bones), 3)
    return out.reshape(len(q), -1)


_PARENT_INDEX = np.array(PARENTS[1:])
#: Bone indices (0 = the bone ending at joint 1) by rotation order.
_BONES_BY_AXES: dict[str, list[int]] = {}
for _c in range(1, len(JOINT_NAMES)):
    _BONES_BY_AXES.setdefault(_BY_CHILD[JOINT_NAMES[_c]].axes, []).append(_c - 1)


def body_id(human_id: str) -> str:
    """The REP 155 body id of human ``human_id`` (the suffix of its link names): the id
    itself, or ``h<id>`` when it starts with a digit, since a ROS name token cannot
    (``/humans/bodies/1/...`` is no valid topic)."""
    human_id = str(human_id)
    return f"h{human_id}" if human_id[:1].isdigit() else human_id


def hip_offset(skeleton: Skeleton | None = None) -> np.ndarray:
    """The midpoint of the hips in the pelvis link's frame (3,), metres: the origin of
    REP 155's ``body_<id>`` relative to ``pelvis_<id>``."""
    rest = (skeleton or Skeleton()).rest_positions()
    return (rest[JOINT_INDEX["l_hip"]] + rest[JOINT_INDEX["r_hip"]]) / 2 - rest[0]


def root_poses(positions: np.ndarray, skeleton: Skeleton | None = None,
               rep155: bool = False) -> np.ndarray:
    """Homogeneous poses (T, 4, 4) of ``body_<id>`` in the world frame from positions
    (T, J, 3): at the pelvis joint, with ``rep155`` at the midpoint of the hips
    (:func:`hip_offset` turned by the pelvis link)."""
    pos = np.asarray(positions, dtype=np.float64)
    T = np.tile(np.eye(4), (len(pos), 1, 1))
    T[:, :3, :3] = link_rotations(pos, skeleton)[:, 0]
    T[:, :3, 3] = pos[:, 0]
    if rep155:
        T[:, :3, 3] += T[:, :3, :3] @ hip_offset(skeleton)
    return T


def _fmt(values: np.ndarray | tuple[float, ...]) -> str:
    return " ".join(f"{float(v):.6g}" for v in values)


def _origin(parent: ET.Element, xyz: np.ndarray, rpy: np.ndarray | None = None) -> None:
    ET.SubElement(parent, "origin", xyz=_fmt(xyz), rpy=_fmt(rpy if rpy is not None
                                                          else np.zeros(3)))


def _capsule_geometry(link: ET.Element, a: np.ndarray, b: np.ndarray, radius: float,
                      name: str) -> None:
    """A cylinder from ``a`` to ``b`` (link frame) and two spheres, visual and collision."""
    axis = b - a
    length = float(np.linalg.norm(axis))
    shapes: list[tuple[np.ndarray, np.ndarray, str, dict[str, str]]] = []
    if length > 1e-9:
        z = axis / length
        rot = swing_matrices(np.array([0.0, 0.0, 1.0]), z)
        rpy = Rotation.from_matrix(rot).as_euler("xyz")
        shapes.append(((a + b) / 2, rpy, "cylinder",
                       {"radius": f"{radius:.6g}", "length": f"{length:.6g}"}))
    shapes.append((a, np.zeros(3), "sphere", {"radius": f"{radius:.6g}"}))
    if length > 1e-9:
        shapes.append((b, np.zeros(3), "sphere", {"radius": f"{radius:.6g}"}))
    for kind in ("visual", "collision"):
        for i, (xyz, rpy, shape, attrs) in enumerate(shapes):
            element = ET.SubElement(link, kind, name=f"{name}_{i}")
            _origin(element, xyz, rpy)
            geometry = ET.SubElement(element, "geometry")
            ET.SubElement(geometry, shape, **attrs)
            if kind == "visual":
                material = ET.SubElement(element, "material", name="worker")
                ET.SubElement(material, "color", rgba="0.2 0.5 0.9 1")


def _inertial(link: ET.Element, mass: float, centre: np.ndarray, radius: float,
              length: float) -> None:
    """Inertia of a solid cylinder of ``radius`` and ``length`` along the local z."""
    inertial = ET.SubElement(link, "inertial")
    _origin(inertial, centre)
    ET.SubElement(inertial, "mass", value=f"{mass:.6g}")
    ixx = mass * (3 * radius ** 2 + length ** 2) / 12
    izz = mass * radius ** 2 / 2
    ET.SubElement(inertial, "inertia", ixx=f"{ixx:.6g}", ixy="0", ixz="0", iyy=f"{ixx:.6g}",
                  iyz="0", izz=f"{izz:.6g}")


def worker_urdf(stature: float = 1.75, human_id: str = "1", *,
                body_mass: float = BODY_MASS, rep155: bool = False) -> str:
    """The URDF (XML text) of a worker of ``stature`` metres, links named for ``human_id``;
    with ``rep155`` REP 155's body frame and joint names (see the module docstring).

    Raises
    ------
    ValueError
        If the stature is outside the skeleton's range or ``human_id`` is empty.
    """
    if not str(human_id):
        raise ValueError("human_id must not be empty")
    skeleton = Skeleton(stature=stature)
    rest = skeleton.rest_positions()
    radii = capsule_radii(stature)
    robot = ET.Element("robot", name=f"human_{human_id}")
    links: dict[str, ET.Element] = {}

    def add_link(name: str) -> ET.Element:
        links[name] = ET.SubElement(robot, "link", name=name)
        return links[name]

    def link(joint: str) -> str:
        return link_name(joint, human_id, rep155)

    names = iter(joint_names(human_id, rep155))
    if rep155:
        add_link(f"body_{human_id}")
        _inertial(links[f"body_{human_id}"], _MIN_MASS, np.zeros(3), 0.01, 0.0)
        add_link(link("pelvis"))
        fixed = ET.SubElement(robot, "joint", name=f"pelvis_end_{human_id}", type="fixed")
        ET.SubElement(fixed, "parent", link=f"body_{human_id}")
        ET.SubElement(fixed, "child", link=link("pelvis"))
        _origin(fixed, -hip_offset(skeleton))
    else:
        add_link(link("pelvis"))
    for c in range(1, len(JOINT_NAMES)):
        p, child = PARENTS[c], JOINT_NAMES[c]
        bone = _BY_CHILD[child]
        parent_link = link(JOINT_NAMES[p])
        chain = bone_chain(child, human_id)
        for k, axis in enumerate(bone.axes):
            add_link(chain[k])
            joint = ET.SubElement(robot, "joint", name=next(names), type="revolute")
            ET.SubElement(joint, "parent", link=parent_link if k == 0 else chain[k - 1])
            ET.SubElement(joint, "child", link=chain[k])
            _origin(joint, np.zeros(3))
            ET.SubElement(joint, "axis", xyz=_fmt(np.eye(3)["xyz".index(axis)]))
            lo, hi = bone.limits[k]
            ET.SubElement(joint, "limit", lower=f"{np.radians(lo - LIMIT_MARGIN):.6g}",
                          upper=f"{np.radians(hi + LIMIT_MARGIN):.6g}",
                          effort=f"{JOINT_EFFORT:g}", velocity=f"{JOINT_VELOCITY:g}")
        add_link(link(child))
        fixed = ET.SubElement(robot, "joint", name=f"{child}_end_{human_id}", type="fixed")
        ET.SubElement(fixed, "parent", link=chain[-1])
        ET.SubElement(fixed, "child", link=link(child))
        _origin(fixed, rest[c] - rest[p])
        offset = rest[c] - rest[p]
        mass = max(body_mass * _MASS_FRACTION[child], _MIN_MASS)
        _inertial(links[chain[-1]], mass, offset / 2, 0.05 * stature / 1.75,
                  float(np.linalg.norm(offset)))
        for k in range(2):
            _inertial(links[chain[k]], _MIN_MASS, np.zeros(3), 0.01, 0.0)
        _inertial(links[link(child)], _MIN_MASS, np.zeros(3), 0.01, 0.0)
    _inertial(links[link("pelvis")],
              body_mass * _MASS_FRACTION["pelvis"], np.zeros(3), 0.1 * stature / 1.75, 0.1)

    for k, (part, ja, jb, _) in enumerate(BODY_CAPSULES):
        a, b = JOINT_INDEX[ja], JOINT_INDEX[jb]
        if a == b:                                   # a sphere at the joint
            _capsule_geometry(links[link(ja)], np.zeros(3), np.zeros(3),
                              float(radii[k]), part)
        elif PARENTS[b] == a:                        # the bone a -> b: its bone link
            _capsule_geometry(links[f"{jb}_bone_{human_id}"], np.zeros(3), rest[b] - rest[a],
                              float(radii[k]), part)
        else:                                        # two children of one joint
            base = PARENTS[a]
            if PARENTS[b] != base:
                raise ValueError(f"capsule {part}: {ja} and {jb} share no parent")
            _capsule_geometry(links[link(JOINT_NAMES[base])],
                              rest[a] - rest[base], rest[b] - rest[base], float(radii[k]), part)
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"
