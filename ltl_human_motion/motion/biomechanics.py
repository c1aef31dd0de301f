"""Biomechanical plausibility of a whole motion: speeds, range of motion, self-penetration,
static balance and foot skate.

Every function takes world joint positions of the canonical skeleton, shape (T, J, 3)
(z up, metres) and the frame rate; :func:`check_biomechanics` runs all five checks and
returns report entries in the format of :func:`~ltl_human_motion.planning.verify.
verify_motion`, each failure naming the joint (or body part), the frame and the value.

Limits and where they come from (:class:`BiomechanicsLimits`):

* **Joint speeds** (m/s at the reference stature 1.75 m; scaled by ``H / 1.75`` because
  retargeted motions scale geometrically at the same cadence; measured as displacements
  over :data:`SPEED_WINDOW` = 1/30 s, the clips' frame interval). Calibrated on the real
  clips installed here (``bench/realism.py`` prints them): in the DeepMimic walking clips
  of pybullet (``walker/*.txt``, ``humanoid3d_walk.txt``) hands peak at 2.4-3.3 m/s,
  knees at 1.9-2.1 m/s, ankles at 3.1-3.4 m/s and toes at 3.6-3.9 m/s; in the CMU BVH
  takes 01_01/01_03 (assimp-testmodels) the 99th percentiles are hands 3.3-4.5, knees
  2.1-2.5 m/s. Hands: 2.5 m/s within hand goal tasks (ISO/TR 23049 and Bosch-era
  reaching data put deliberate reaching peaks at 1-2 m/s), 3.5 m/s elsewhere; knees
  2.5 m/s, 2.0 m/s while the pelvis sits, stands up or kneels (sit-to-stand knee
  velocities stay below 1.5 m/s, Schenkman et al. 1990); the swing foot (ankle, toe)
  at most 10 % over the peak of the default gait clips as the library prepares them
  (120 Hz, toes raised off the floor in swing by ``fix_feet``: ankle 3.76, toe
  4.47 m/s); every other joint 3.5 m/s.
* **Range of motion** (degrees; American Academy of Orthopaedic Surgeons, *Joint
  Motion: Method of Measuring and Recording*, 1965, as tabulated by Greene & Heckman,
  *The Clinical Measurement of Joint Motion*, AAOS 1994): knee flexion 0-150 (the
  issue's bound; AAOS 135-150) with 5 of hyperextension tolerated (the mean knee
  extension of healthy adults is 1-2 degrees of hyperextension, Soucie et al. 2011,
  *Haemophilia* 17:500); elbow flexion 0-150; hip flexion 125 (AAOS 120 + 5 measurement
  tolerance), extension 30, abduction 45, adduction 30; shoulder extension 60;
  thoracolumbar flexion 80, extension 25, lateral bending 35, rotation 45; cervical
  flexion 45, extension 45, lateral bending 45.
* **Self-penetration**: the bone axis of one body capsule
  (:data:`~ltl_human_motion.motion.capsules.BODY_CAPSULES`) must not enter another,
  non-neighbouring capsule (axis distance below the thicker capsule's radius): an arm
  segment through the trunk, head or a thigh, an arm through the other arm, a thigh
  through the other thigh, a shank or foot through the other.
* **Static balance**: in frames where both feet are planted (every foot joint within
  ``contact_height`` of the floor, moving under ``planted_speed``) and the pelvis moves
  slower than ``static_pelvis_speed``, the centre of mass (Winter's segment masses,
  :func:`~ltl_human_motion.motion.ik.center_of_mass`) projects inside the support
  polygon of the feet (heel 0.035 H behind the ankle, 0.01 H past the toe joint, half a
  foot breadth 0.0275 H either side; Drillis & Contini foot proportions) grown by
  ``balance_margin`` (2 cm, the foot outline's uncertainty). Seated frames (from the
  start of a ``sit`` to the end of the following ``standUp``) are skipped: the seat
  carries the body.
* **Foot skate** (Zhang et al., MOJO, 2021; the measure of :mod:`~ltl_human_motion.motion
  .quality`): the mean weighted horizontal speed of each foot's contact point over its
  contact frames is at most 0.03 m/s, and no frame with the contact point on the floor
  (below half the contact height) slides faster than 0.15 m/s (the issue's bounds; the
  real gait clips measure 0.01-0.03 m/s mean).
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.kernel.segments import compiled_module, joint_segment_distances
from ltl_human_motion.kernel.vectors import cross3, dot3, norm3
from ltl_human_motion.motion.capsules import BODY_CAPSULES, capsule_radii
from ltl_human_motion.motion.ik import center_of_mass
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, JOINT_NAMES
from ltl_human_motion.vocabulary import HAND_TASKS

__all__ = [
    "BiomechanicsLimits",
    "balance_margins",
    "check_biomechanics",
    "foot_skate",
    "joint_angles",
    "joint_speeds",
    "max_self_penetration",
    "self_penetration",
]

_J = JOINT_INDEX
_FOOT_JOINTS = ("l_ankle", "l_toe", "r_ankle", "r_toe")
#: Rest heights of the ankle and toe joints above the floor, fractions of stature (the
#: canonical skeleton's rest pose).
CONTACT_REST_HEIGHTS = (0.039, 0.010)
#: Tasks whose motion is the pelvis going down or coming up with the legs loaded.
POSTURE_TRANSITION_TASKS = ("sit", "standUp", "kneel", "stoop")


@dataclass(frozen=True)
class BiomechanicsLimits:
    """Limits of the biomechanical checks (module docstring gives the sources).

    Speeds are m/s at ``reference_stature`` (scaled by ``stature / reference_stature``);
    angles are degrees; lengths metres.
    """

    reference_stature: float = DEFAULT_STATURE
    hand_speed_goal: float = 2.5
    hand_speed: float = 3.5
    knee_speed: float = 2.5
    knee_speed_posture: float = 2.0
    ankle_speed: float = 4.1          # prepared gait clips' peak 3.76 m/s + 10 %
    toe_speed: float = 4.9            # prepared gait clips' peak 4.47 m/s + 10 %
    other_speed: float = 3.5
    rom: dict = field(default_factory=lambda: {
        "knee_flexion": (-5.0, 150.0),
        "elbow_flexion": (0.0, 150.0),
        "hip_flexion": (-30.0, 125.0),
        "hip_abduction": (-30.0, 45.0),
        "shoulder_extension": (-180.0, 60.0),
        "trunk_flexion": (-25.0, 80.0),
        "trunk_lateral": (-35.0, 35.0),
        "trunk_rotation": (-45.0, 45.0),
        "neck_flexion": (-45.0, 45.0),
        "neck_lateral": (-45.0, 45.0),
    })
    contact_height: float = 0.02
    planted_speed: float = 0.05
    static_pelvis_speed: float = 0.05
    balance_margin: float = 0.02
    skate_mean: float = 0.03
    skate_peak: float = 0.15


# ----------------------------------------------------------------------- speeds
#: Time base of the speed limits, s: speeds are displacements over this interval, the
#: frame interval of the 30 Hz clips the limits are calibrated on (at 120 Hz a per-frame
#: difference would see the same motion's peaks 10-15 % higher than the clips can).
SPEED_WINDOW = 1.0 / 30.0


def joint_speeds(positions: np.ndarray, fps: float, window: float = SPEED_WINDOW
                 ) -> np.ndarray:
    """Speed of every joint over ``window`` seconds, m/s, shape (T-w, J).

    Row ``t`` is the displacement from frame ``t`` to frame ``t + w``, ``w = round(window
    * fps)`` (at least 1), divided by ``w / fps``.
    """
    p = np.asarray(positions, dtype=np.float64)
    w = max(1, round(window * float(fps)))
    if len(p) <= w:
        return np.zeros((0, p.shape[1]))
    return norm3(p[w:] - p[:-w]) * (float(fps) / w)


def _kind(label: str) -> str:
    """The task of an activity label: ``"sit(stool)"`` -> ``"sit"``."""
    return str(label).split("(", 1)[0]


def _label_flags(labels: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """Whether each frame's activity (labels (n,)) is a hand goal task, and whether a
    posture transition: bool (n,) each."""
    distinct = {x: k for k, x in enumerate(set(labels))}    # a few labels, long runs
    kinds = [_kind(x) for x in distinct]
    code = np.fromiter(map(distinct.__getitem__, labels), dtype=np.intp, count=len(labels))
    return (np.isin(kinds, HAND_TASKS)[code] if kinds else np.zeros(0, dtype=bool),
            np.isin(kinds, POSTURE_TRANSITION_TASKS)[code] if kinds
            else np.zeros(0, dtype=bool))


def _flag_limits(n: int, hand_goal: np.ndarray, posture: np.ndarray,
                 lim: BiomechanicsLimits, scale: float) -> np.ndarray:
    """Per-interval, per-joint speed limit (n, J) from each frame's flags
    (:func:`_label_flags`)."""
    out = np.full((n, len(JOINT_NAMES)), lim.other_speed)
    for s in "lr":
        out[:, _J[f"{s}_hand"]] = np.where(hand_goal, lim.hand_speed_goal, lim.hand_speed)
        out[:, _J[f"{s}_wrist"]] = np.where(hand_goal, lim.hand_speed_goal, lim.hand_speed)
        out[:, _J[f"{s}_knee"]] = np.where(posture, lim.knee_speed_posture, lim.knee_speed)
        out[:, _J[f"{s}_ankle"]] = lim.ankle_speed
        out[:, _J[f"{s}_toe"]] = lim.toe_speed
    return out * scale


def _speed_limits(n: int, labels: Sequence[str], lim: BiomechanicsLimits,
                  scale: float) -> np.ndarray:
    """Per-interval, per-joint speed limit (n, J) from the activity label of each frame."""
    return _flag_limits(n, *_label_flags(labels[:n]), lim, scale)


# ---------------------------------------------------------------------- angles
def _unit(v: np.ndarray) -> np.ndarray:
    n = norm3(v)[..., None] if v.shape[-1] == 3 else np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, 1e-12)


def _frame(lateral: np.ndarray, up: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orthonormal (forward, left, up) axes (T, 3) each from a lateral and an up vector."""
    left = _unit(lateral)
    u = _unit(up - dot3(up, left)[..., None] * left)
    return cross3(left, u), left, u


#: The angles of :func:`joint_angles` measured in the chest's frame.
_CHEST_ANGLES = ("l_shoulder_extension", "r_shoulder_extension", "trunk_flexion",
                 "trunk_lateral", "trunk_rotation", "neck_flexion", "neck_lateral")


def joint_angles(positions: np.ndarray, names: Collection[str] | None = None
                 ) -> dict[str, np.ndarray]:
    """Anatomical joint angles of every frame, degrees.

    Keys (each an array of shape (T,)): ``{l,r}_knee_flexion`` (signed about the knee's
    hinge axis, which is normal to the shank and the foot; negative = hyperextension),
    ``{l,r}_elbow_flexion``, ``{l,r}_hip_flexion`` and ``{l,r}_hip_abduction`` (thigh in
    the pelvis frame), ``{l,r}_shoulder_extension`` (upper arm behind the chest's frontal
    plane), ``trunk_flexion``, ``trunk_lateral``, ``trunk_rotation`` (chest frame relative
    to the pelvis frame), ``neck_flexion``, ``neck_lateral`` (head relative to the chest).

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)
    names : collection of str, optional
        Only these keys (the same values); default all.
    """
    p = np.asarray(positions, dtype=np.float64)
    nb = compiled_module("ltl_human_motion.motion._angles_numba")
    if nb is not None and p.ndim == 3:
        return _joint_angles_compiled(nb, p, names)
    want = (lambda key: True) if names is None else frozenset(names).__contains__
    deg = np.degrees
    out: dict[str, np.ndarray] = {}
    fwd, left, up = _frame(p[:, _J["l_hip"]] - p[:, _J["r_hip"]],
                           p[:, _J["spine"]] - p[:, _J["pelvis"]])
    if any(want(k) for k in _CHEST_ANGLES):
        cf, cl, cu = _frame(p[:, _J["l_shoulder"]] - p[:, _J["r_shoulder"]],
                            p[:, _J["neck"]] - p[:, _J["chest"]])
    for s, side in (("l", 1.0), ("r", -1.0)):
        hip, knee, ank, toe = (p[:, _J[f"{s}_{n}"]] for n in ("hip", "knee", "ankle", "toe"))
        thigh, shank, foot = knee - hip, ank - knee, toe - ank
        if want(f"{s}_knee_flexion"):
            axis = _unit(-cross3(shank, foot))
            cr = dot3(cross3(thigh, shank), axis)
            out[f"{s}_knee_flexion"] = deg(np.arctan2(cr, dot3(thigh, shank)))
        t = _unit(thigh)
        if want(f"{s}_hip_flexion"):
            out[f"{s}_hip_flexion"] = deg(np.arctan2(dot3(t, fwd), -dot3(t, up)))
        if want(f"{s}_hip_abduction"):
            out[f"{s}_hip_abduction"] = deg(np.arcsin(np.clip(side * dot3(t, left), -1, 1)))
        if not (want(f"{s}_elbow_flexion") or want(f"{s}_shoulder_extension")):
            continue
        sh, el, wr = (p[:, _J[f"{s}_{n}"]] for n in ("shoulder", "elbow", "wrist"))
        ua, fa = _unit(el - sh), _unit(wr - el)
        if want(f"{s}_elbow_flexion"):
            out[f"{s}_elbow_flexion"] = deg(np.arccos(np.clip(dot3(ua, fa), -1, 1)))
        if want(f"{s}_shoulder_extension"):
            out[f"{s}_shoulder_extension"] = deg(np.arcsin(np.clip(-dot3(ua, cf), -1, 1)))
    if want("trunk_flexion"):
        out["trunk_flexion"] = deg(np.arctan2(dot3(cu, fwd), dot3(cu, up)))
    if want("trunk_lateral"):
        out["trunk_lateral"] = deg(np.arcsin(np.clip(dot3(cu, left), -1, 1)))
    if want("trunk_rotation"):
        out["trunk_rotation"] = deg(np.arctan2(dot3(cl, -fwd), dot3(cl, left)))
    if want("neck_flexion") or want("neck_lateral"):
        h = _unit(p[:, _J["head"]] - p[:, _J["neck"]])
        if want("neck_flexion"):
            out["neck_flexion"] = deg(np.arctan2(dot3(h, cf), dot3(h, cu)))
        if want("neck_lateral"):
            out["neck_lateral"] = deg(np.arcsin(np.clip(dot3(h, cl), -1, 1)))
    return out


#: The joints :mod:`._angles_numba` reads, in its order, and the keys of its outputs
#: (arctan2, arcsin, arccos rows) in :func:`joint_angles`' order.
_ANGLE_JOINTS = np.array([_J[n] for n in (
    "pelvis", "spine", "chest", "neck", "head", "l_shoulder", "r_shoulder", "l_hip", "r_hip",
    *(f"{s}_{n}" for s in "lr" for n in ("hip", "knee", "ankle", "toe", "elbow", "wrist")))],
    dtype=np.int64)
_ANGLE_ROWS = {
    **{f"{s}_{n}": (kind, 2 * k + i) for k, s in enumerate("lr")
       for kind, pair in ((0, ("knee_flexion", "hip_flexion")),
                          (1, ("hip_abduction", "shoulder_extension")))
       for i, n in enumerate(pair)},
    "l_elbow_flexion": (2, 0), "r_elbow_flexion": (2, 1), "trunk_flexion": (0, 4),
    "trunk_lateral": (1, 4), "trunk_rotation": (0, 5), "neck_flexion": (0, 6),
    "neck_lateral": (1, 5)}
_ANGLE_ORDER = tuple(f"{s}_{n}" for s in "lr" for n in (
    "knee_flexion", "hip_flexion", "hip_abduction", "elbow_flexion",
    "shoulder_extension")) + ("trunk_flexion", "trunk_lateral", "trunk_rotation",
                              "neck_flexion", "neck_lateral")


def _joint_angles_compiled(nb, p: np.ndarray, names: Collection[str] | None
                           ) -> dict[str, np.ndarray]:
    """:func:`joint_angles` of poses ``p`` (T, J, 3) by the compiled loop (the same
    numbers): its arguments of arctan2 (7, T), arcsin (6, T) and arccos (2, T), then
    numpy's functions on them."""
    T = p.shape[0]
    y, z, s, c = np.empty((7, T)), np.empty((7, T)), np.empty((6, T)), np.empty((2, T))
    nb.angle_arguments(np.ascontiguousarray(p), _ANGLE_JOINTS, y, z, s, c)
    rows = (np.degrees(np.arctan2(y, z)), np.degrees(np.arcsin(s)),
            np.degrees(np.arccos(c)))
    wanted = None if names is None else frozenset(names)
    keys = _ANGLE_ORDER if wanted is None else [k for k in _ANGLE_ORDER if k in wanted]
    return {k: rows[_ANGLE_ROWS[k][0]][_ANGLE_ROWS[k][1]] for k in keys}


def _rom_key(name: str) -> str:
    return name[2:] if name[:2] in ("l_", "r_") else name


# ---------------------------------------------------------------- self-penetration
_ARM_PARTS = ("upper_arm", "lower_arm", "hand")


def _penetration_pairs() -> list[tuple[int, int]]:
    """Capsule index pairs checked for self-penetration (no shared joint)."""
    names = [c[0] for c in BODY_CAPSULES]
    idx = {n: i for i, n in enumerate(names)}
    pairs: set[tuple[int, int]] = set()
    trunk = ("head", "abdomen", "torso", "pelvis", "l_thigh", "r_thigh")
    for s, o in (("l", "r"), ("r", "l")):
        for a in _ARM_PARTS:
            for b in trunk:
                pairs.add((idx[f"{s}_{a}"], idx[b]))
            for b in ("upper_arm", "lower_arm"):
                pairs.add(tuple(sorted((idx[f"{s}_{a}"], idx[f"{o}_{b}"]))))
    for a, b in (("l_thigh", "r_thigh"), ("l_shank", "r_shank"), ("l_foot", "r_foot"),
                 ("l_shank", "r_foot"), ("r_shank", "l_foot")):
        pairs.add((idx[a], idx[b]))
    ends = {i: {c[1], c[2]} for i, c in enumerate(BODY_CAPSULES)}
    return sorted(p for p in pairs if not ends[p[0]] & ends[p[1]])


_PAIRS = _penetration_pairs()
#: Capsule indices (2, P) of the pairs, and the joints (2, P, 2) ending their capsules.
_PAIR_CAPSULES = np.array(_PAIRS, dtype=np.intp).T
_PAIR_ENDS = np.array([[_J[c[1]], _J[c[2]]] for c in BODY_CAPSULES],
                      dtype=np.intp)[_PAIR_CAPSULES]


#: The segments (S, 2) (joint pairs) of the pairs, and the segment of each side of each
#: pair (P,) each (:func:`_deepest_penetration`'s compiled call).
_PAIR_SEGMENTS, _PAIR_SEGMENT_INDEX = np.unique(_PAIR_ENDS.reshape(-1, 2), axis=0,
                                                return_inverse=True)
_PAIR_SEGMENT_INDEX = _PAIR_SEGMENT_INDEX.reshape(2, -1).astype(np.intp)
_PAIR_SEGMENTS = np.ascontiguousarray(_PAIR_SEGMENTS, dtype=np.intp)
_PAIR_NAMES = [(BODY_CAPSULES[i][0], BODY_CAPSULES[j][0]) for i, j in _PAIRS]


def _deepest_penetration(p: np.ndarray, stature: float) -> tuple[int, int, float] | None:
    """The frame, pair and depth of ``self_penetration(p, stature)``'s first maximum
    (the same numbers), by the compiled kernel that measures only pairs that may reach
    it; None where the kernel is not in use or ``p`` (T, J, 3) is empty or not finite."""
    nb = compiled_module("ltl_human_motion.kernel._segments_numba")
    x = np.ascontiguousarray(p, dtype=np.float64)
    if nb is None or not x.size or not np.isfinite(x).all():
        return None
    r = capsule_radii(stature)
    a, b = _PAIR_CAPSULES
    where = np.zeros(2, dtype=np.intp)
    depth = nb.indexed_max_excess(x, _PAIR_SEGMENTS, _PAIR_SEGMENT_INDEX[0],
                                  _PAIR_SEGMENT_INDEX[1],
                                  np.ascontiguousarray(np.maximum(r[a], r[b]),
                                                       dtype=np.float64), where)
    return int(where[0]), int(where[1]), float(depth)


def max_self_penetration(positions: np.ndarray, stature: float = DEFAULT_STATURE) -> float:
    """The largest depth of :func:`self_penetration` over every frame and pair of
    ``positions`` (T, J, 3), T >= 1 (the same number), by the compiled search for the
    deepest pair where it is in use; positive = some capsule enters another."""
    deepest = _deepest_penetration(positions, stature)
    if deepest is not None:
        return deepest[2]
    return float(np.max(self_penetration(positions, stature)[0]))


def self_penetration(positions: np.ndarray, stature: float = DEFAULT_STATURE
                     ) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """Depth by which a capsule's bone axis is inside another (non-neighbour) capsule.

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)
    stature : float

    Returns
    -------
    depth : ndarray, shape (T, P)
        ``max(r_a, r_b) - axis distance``; positive = penetration.
    pairs : list of (part_a, part_b), length P
    """
    p = np.asarray(positions, dtype=np.float64)
    r = capsule_radii(stature)
    a, b = _PAIR_CAPSULES
    d = joint_segment_distances(p, _PAIR_ENDS[0], _PAIR_ENDS[1])
    depth = np.maximum(r[a], r[b])[None] - d
    names = [(BODY_CAPSULES[i][0], BODY_CAPSULES[j][0]) for i, j in _PAIRS]
    return depth, names


# ------------------------------------------------------------------------ balance
def _foot_outline(ankle: np.ndarray, toe: np.ndarray, stature: float) -> np.ndarray:
    """Corners (T, 4, 2) of a foot's sole on the floor plane."""
    a, t = ankle[:, :2], toe[:, :2]
    d = _unit(t - a)
    n = np.stack([-d[:, 1], d[:, 0]], -1)
    heel = a - 0.035 * stature * d
    front = t + 0.01 * stature * d
    w = 0.0275 * stature
    return np.stack([heel - w * n, front - w * n, front + w * n, heel + w * n], 1)


def _hull_distance(points: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Signed distance (T,) of ``p`` (T, 2) to the convex hull of ``points`` (T, V, 2).

    The largest signed distance of ``p`` to the lines of the hull's edges (negative
    inside), as ``max(n . p + c)`` over the facet equations of a per-frame Qhull
    ``ConvexHull``, for all frames at once: an edge of two points belongs to the hull
    when no other point lies beyond it (to within ``1e-12`` of the points' extent).
    """
    P = np.ascontiguousarray(points, dtype=np.float64)
    q = np.ascontiguousarray(p, dtype=np.float64)
    nb = compiled_module("ltl_human_motion.motion._biomechanics_numba")
    if nb is not None:
        return nb.hull_distance(P, q)
    i, j = np.nonzero(~np.eye(P.shape[1], dtype=bool))        # every ordered pair
    x, y = P[..., 0], P[..., 1]
    xi, yi = x[:, i], y[:, i]                                  # (T, E)
    ex, ey = x[:, j] - xi, y[:, j] - yi
    length = np.hypot(ex, ey)
    # |e| times the distance of every point beyond the edge's line (outward normal
    # (ey, -ex) / |e|), shape (T, E, V)
    beyond = ey[..., None] * (x[:, None, :] - xi[..., None]) \
        - ex[..., None] * (y[:, None, :] - yi[..., None])
    tol = 1e-12 * np.max(np.abs(P), axis=(1, 2))[:, None]
    edge = (length > tol) & np.all(beyond <= (length * tol)[..., None], axis=2)
    dist = (ey * (q[:, :1] - xi) - ex * (q[:, 1:] - yi)) / np.maximum(length, 1e-300)
    return np.max(np.where(edge, dist, -np.inf), axis=1)


def balance_margins(positions: np.ndarray, fps: float, stature: float = DEFAULT_STATURE,
                    floor_z: float = 0.0, skip: np.ndarray | None = None,
                    limits: BiomechanicsLimits = BiomechanicsLimits()
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Static frames and the centre of mass's distance outside their support polygon.

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)
    fps, stature, floor_z : float
    skip : ndarray of bool, shape (T,), optional
        Frames not to check (seated).

    Returns
    -------
    frames : ndarray of int, shape (S,)
        The static, double-support frames.
    outside : ndarray, shape (S,)
        Signed horizontal distance of the centre of mass outside the support polygon, m
        (negative = inside).
    """
    p = np.asarray(positions, dtype=np.float64)
    T = len(p)
    if T < 2:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    feet = [_J[n] for n in _FOOT_JOINTS]
    v = np.linalg.norm(np.diff(p[:, feet, :2], axis=0), axis=-1) * fps
    v = np.vstack([v[:1], v])                                        # (T, 4)
    rest_h = np.tile(CONTACT_REST_HEIGHTS, 2) * stature
    low = np.all(p[:, feet, 2] - floor_z - rest_h <= limits.contact_height, axis=1)
    slow = np.all(v <= limits.planted_speed * stature / limits.reference_stature, axis=1)
    pv = norm3(np.diff(p[:, 0], axis=0)) * fps
    pv = np.concatenate([pv[:1], pv])
    static = low & slow & (pv <= limits.static_pelvis_speed)
    if skip is not None:
        static &= ~np.asarray(skip, dtype=bool)
    frames = np.flatnonzero(static)
    if frames.size == 0:
        return frames, np.zeros(0)
    q = p[frames]
    poly = np.concatenate([_foot_outline(q[:, _J["l_ankle"]], q[:, _J["l_toe"]], stature),
                           _foot_outline(q[:, _J["r_ankle"]], q[:, _J["r_toe"]], stature)], 1)
    com = center_of_mass(q)[:, :2]
    return frames, _hull_distance(poly, com)


# -------------------------------------------------------------------------- skate
def foot_skate(positions: np.ndarray, fps: float, stature: float = DEFAULT_STATURE,
               floor_z: float = 0.0, contact_height: float = 0.02
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MOJO foot skate of each foot over a whole motion.

    Per foot the contact point is the joint (ankle = heel, toe = ball) nearer its rest
    height above the floor; a frame counts with weight ``2 - 2**(h / c)`` while the
    contact point is within ``c = contact_height`` of its rest height.

    Returns
    -------
    mean : ndarray, shape (2,)
        Mean weighted horizontal speed of the left and right foot's contact point over its
        contact frames, m/s.
    speed : ndarray, shape (T-1, 2)
        Horizontal speed of each foot's contact point, m/s.
    grounded : ndarray of bool, shape (T-1, 2)
        Frames where the contact point is within half the contact height (on the floor).
    """
    p = np.asarray(positions, dtype=np.float64)
    feet = [_J[n] for n in _FOOT_JOINTS]
    if len(p) < 2:
        return np.zeros(2), np.zeros((0, 2)), np.zeros((0, 2), dtype=bool)
    rest_h = np.tile(CONTACT_REST_HEIGHTS, 2) * stature
    vel = np.linalg.norm(np.diff(p[:, feet, :2], axis=0), axis=-1) * fps       # (T-1, 4)
    h = np.maximum(p[:, feet, 2] - floor_z - rest_h, 0.0)
    h = 0.5 * (h[1:] + h[:-1]) / contact_height
    h2 = h.reshape(-1, 2, 2)
    pick = np.argmin(h2, axis=2)
    h_c = np.take_along_axis(h2, pick[..., None], 2)[..., 0]
    v_c = np.take_along_axis(vel.reshape(-1, 2, 2), pick[..., None], 2)[..., 0]
    weight = np.where(h_c < 1.0, 2.0 - np.exp2(h_c), 0.0)
    counts = (h_c < 1.0).sum(0)
    mean = np.where(counts > 0, (v_c * weight).sum(0) / np.maximum(counts, 1), 0.0)
    return mean, v_c, h_c < 0.5


# --------------------------------------------------------------------- the checks
def _entry(passed: bool, detail: str, **values: object) -> dict:
    return {"passed": bool(passed), "detail": detail, **values}


def frame_labels(n_frames: int, timeline: Sequence, default: str = "walk") -> list[str]:
    """Activity of every frame: the task of the timeline segment holding it, else walk.

    ``timeline`` holds objects with ``task``, ``start_frame`` and ``end_frame``.
    """
    lab = [default] * n_frames
    for seg in timeline:
        for f in range(max(0, seg.start_frame), min(n_frames, seg.end_frame)):
            lab[f] = seg.task
    return lab


def seated_frames(n_frames: int, timeline: Sequence) -> np.ndarray:
    """Frames from the start of each ``sit`` to the end of the next ``standUp``, (T,)."""
    out = np.zeros(n_frames, dtype=bool)
    start = None
    for seg in timeline:
        if _kind(seg.task) == "sit" and start is None:
            start = seg.start_frame
        elif _kind(seg.task) == "standUp":
            out[seg.start_frame if start is None else start:seg.end_frame] = True
            start = None
    if start is not None:
        out[start:] = True
    return out


def check_biomechanics(positions: np.ndarray, fps: float, *, stature: float = DEFAULT_STATURE,
                       labels: Sequence[str] | None = None, floor_z: float = 0.0,
                       seated: np.ndarray | None = None,
                       limits: BiomechanicsLimits = BiomechanicsLimits()) -> dict:
    """The five biomechanical checks of a whole motion.

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)
    fps, stature, floor_z : float
    labels : sequence of str, length T, optional
        The activity of every frame (a Table I task name, or ``"walk"``); default walk.
    seated : ndarray of bool, shape (T,), optional
        Frames where a seat carries the body (skipped by the balance check).
    limits : BiomechanicsLimits

    Returns
    -------
    dict
        ``{"joint_speed", "range_of_motion", "self_penetration", "balance",
        "foot_skate"}``, each ``{"passed", "detail", ...}``; a failure's detail names the
        joint or part, the frame and the value.
    """
    p = np.asarray(positions, dtype=np.float64)
    T = len(p)
    labels = list(labels) if labels is not None else ["walk"] * T
    if len(labels) != T:
        raise ValueError(f"labels must have one entry per frame ({T}), got {len(labels)}")
    scale = float(stature) / limits.reference_stature
    out: dict = {}

    out["joint_speed"] = _speed_entry(p, fps, labels, limits, scale)
    out["range_of_motion"] = _rom_entry(p, fps, labels, limits)
    out["self_penetration"] = _penetration_entry(p, fps, labels, stature)
    out["balance"] = _balance_entry(p, fps, labels, stature, floor_z, seated, limits)
    out["foot_skate"] = _skate_entry(p, fps, labels, stature, floor_z, limits)
    return out


def _speeds_and_limits(p: np.ndarray, fps: float, labels: Sequence[str],
                       limits: BiomechanicsLimits, scale: float
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Joint speeds (T-w, J) (:func:`joint_speeds`) and their limits (T-w, J): an
    interval is limited by the stricter of its two end frames' activities."""
    T = len(p)
    speed = joint_speeds(p, fps)
    w = T - len(speed)
    hand_goal, posture = _label_flags(labels[:T])
    lim_a = _flag_limits(T - w, hand_goal[:T - w], posture[:T - w], limits, scale)
    lim_b = _flag_limits(T - w, hand_goal[w:], posture[w:], limits, scale)
    return speed, np.minimum(lim_a, lim_b)


def speed_excess(positions: np.ndarray, fps: float, labels: Sequence[str], *,
                 stature: float = DEFAULT_STATURE,
                 limits: BiomechanicsLimits = BiomechanicsLimits()) -> np.ndarray:
    """Whether a joint moves faster than its limit (the ``joint_speed`` check) at each
    frame (the middle of each speed interval), shape (T,) of bool."""
    p = np.asarray(positions, dtype=np.float64)
    out = np.zeros(len(p), dtype=bool)
    speed, lim = _speeds_and_limits(p, fps, list(labels), limits,
                                    float(stature) / limits.reference_stature)
    if speed.size:
        w = len(p) - len(speed)
        out[w // 2:w // 2 + len(speed)] = np.any(speed > lim, axis=1)
    return out


def _speed_entry(p: np.ndarray, fps: float, labels: list[str], limits: BiomechanicsLimits,
                 scale: float) -> dict:
    """The ``joint_speed`` entry of :func:`check_biomechanics`; ``p`` is (T, J, 3)."""
    T = len(p)
    speed, limit = _speeds_and_limits(p, fps, labels, limits, scale)
    if speed.size:
        w = T - len(speed)
        ratio = speed / limit
        f0, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        lim = float(limit[f0, j])
        ok = bool(ratio[f0, j] <= 1.0)
        jf = int(np.argmax(speed.max(axis=0)))
        f = int(f0) + w // 2
        return _entry(
            ok, (f"{JOINT_NAMES[j]} at frame {f} ({f / fps:.2f} s, {labels[f]}) moves "
                 f"at {speed[f0, j]:.2f} m/s, over its limit {lim:.2f} m/s") if not ok else
            f"fastest joint {JOINT_NAMES[jf]} at {speed[:, jf].max():.2f} m/s; every joint "
            f"within its limit (closest: {JOINT_NAMES[j]} at {100 * ratio[f0, j]:.0f} %)",
            max_speed=float(speed.max()), joint=JOINT_NAMES[j], frame=f,
            value=float(speed[f0, j]), limit=float(lim))
    return _entry(True, "a single frame has no speed", max_speed=0.0)


def _rom_entry(p: np.ndarray, fps: float, labels: list[str],
               limits: BiomechanicsLimits) -> dict:
    """The ``range_of_motion`` entry of :func:`check_biomechanics`; ``p`` is (T, J, 3)."""
    angles = joint_angles(p)
    worst = (0.0, "", 0, 0.0, (0.0, 0.0))
    for name, a in angles.items():
        lo, hi = limits.rom[_rom_key(name)]
        excess = np.maximum(lo - a, a - hi)
        f = int(np.argmax(excess))
        if excess[f] > worst[0]:
            worst = (float(excess[f]), name, f, float(a[f]), (lo, hi))
    ok = worst[0] <= 0.0
    return _entry(
        ok, "every joint angle within its range of motion" if ok else
        f"{worst[1]} at frame {worst[2]} ({worst[2] / fps:.2f} s, {labels[worst[2]]}) is "
        f"{worst[3]:.1f} deg, outside [{worst[4][0]:.0f}, {worst[4][1]:.0f}] deg",
        joint=worst[1], frame=worst[2], value=worst[3],
        extremes={k: [float(v.min()), float(v.max())] for k, v in angles.items()})


def _penetration_entry(p: np.ndarray, fps: float, labels: list[str], stature: float) -> dict:
    """The ``self_penetration`` entry of :func:`check_biomechanics`; ``p`` is (T, J, 3)."""
    deepest = _deepest_penetration(p, stature) if _PAIRS else None
    if deepest is not None:
        f, k, dmax = deepest
        names = _PAIR_NAMES
    else:
        depth, names = self_penetration(p, stature)
        f, k = np.unravel_index(int(np.argmax(depth)), depth.shape) if depth.size else (0, 0)
        dmax = float(depth[f, k]) if depth.size else -1.0
    ok = dmax <= 0.0
    a, b = names[k] if names else ("", "")
    return _entry(
        ok, f"no body part passes through another (closest: {a} and {b}, "
            f"{-dmax * 100:.1f} cm apart)" if ok else
        f"{a} passes through {b} at frame {f} ({f / fps:.2f} s, {labels[f]}) by "
        f"{dmax * 100:.1f} cm", joint=a, other=b, frame=int(f), value=dmax)


def _balance_entry(p: np.ndarray, fps: float, labels: list[str], stature: float,
                   floor_z: float, seated: np.ndarray | None,
                   limits: BiomechanicsLimits) -> dict:
    """The ``balance`` entry of :func:`check_biomechanics`; ``p`` is (T, J, 3)."""
    frames, outside = balance_margins(p, fps, stature, floor_z, seated, limits)
    i = int(np.argmax(outside)) if outside.size else 0
    worst_out = float(outside[i]) if outside.size else -np.inf
    ok = worst_out <= limits.balance_margin
    fr = int(frames[i]) if frames.size else 0
    return _entry(
        ok, (f"{frames.size} static frames, the centre of mass at most "
             f"{100 * worst_out:+.1f} cm outside the support polygon (limit "
             f"{100 * limits.balance_margin:.0f} cm)") if frames.size and ok else
        "no static double-support frame" if ok else
        f"centre of mass at frame {fr} ({fr / fps:.2f} s, {labels[fr]}) is "
        f"{100 * worst_out:.1f} cm outside the support polygon of the feet (limit "
        f"{100 * limits.balance_margin:.0f} cm)", joint="center_of_mass", frame=fr,
        value=worst_out if frames.size else None, static_frames=int(frames.size))


def _skate_entry(p: np.ndarray, fps: float, labels: list[str], stature: float,
                 floor_z: float, limits: BiomechanicsLimits) -> dict:
    """The ``foot_skate`` entry of :func:`check_biomechanics`; ``p`` is (T, J, 3)."""
    mean, v, grounded = foot_skate(p, fps, stature, floor_z, limits.contact_height)
    vg = np.where(grounded, v, 0.0)
    f, k = np.unravel_index(int(np.argmax(vg)), vg.shape) if vg.size else (0, 0)
    peak = float(vg[f, k]) if vg.size else 0.0
    foot = ("left foot", "right foot")
    worst_mean = int(np.argmax(mean))
    ok_mean = bool(mean.max() <= limits.skate_mean)
    ok_peak = peak <= limits.skate_peak
    if not ok_mean:
        detail = (f"{foot[worst_mean]} skates at {mean[worst_mean]:.3f} m/s on average over "
                  f"its contact frames (limit {limits.skate_mean} m/s)")
    elif not ok_peak:
        detail = (f"{foot[k]} slides at {peak:.2f} m/s on the floor at frame {f} "
                  f"({f / fps:.2f} s, {labels[f]}) (limit {limits.skate_peak} m/s)")
    else:
        detail = (f"mean foot skate {mean.max():.3f} m/s, fastest planted slide "
                  f"{peak:.2f} m/s")
    return _entry(ok_mean and ok_peak, detail, joint=foot[k], frame=int(f),
                  value=peak, mean=float(mean.max()))
