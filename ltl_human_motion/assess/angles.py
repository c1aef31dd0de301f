"""Body angles for observational ergonomics (REBA, RULA, OWAS) from joint positions.

Every angle is in degrees and measured from the neutral posture of the canonical skeleton
(:mod:`ltl_human_motion.motion.skeleton`: standing, facing +x, arms hanging down), the
reference posture of REBA and RULA. The body frame of each frame is built from the pelvis:

* ``lateral``: the hip line (right hip to left hip) projected on the floor, +y at rest;
* ``forward``: ``lateral x up`` (+x at rest), ``up``: world +z.

The trunk line runs from the pelvis to the neck; the trunk frame (``u`` along the trunk,
``f`` forward, ``l`` left) carries the neck and arm angles, so an arm raised 100 deg in front
of a flexed trunk still reads 100 deg, as the methods measure it (relative to the trunk).

What 23 joint positions cannot show: head yaw (the head is one point), forearm and wrist
rotation, and the wrist's flexion apart from its deviation (the hand is one point). Those
read as neutral; the wrist's total bend counts as flexion.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, fields

import numpy as np

from ltl_human_motion.kernel.vectors import cross3, norm3
from ltl_human_motion.motion.skeleton import JOINT_INDEX, N_JOINTS, Skeleton

__all__ = ["BodyAngles", "body_angles"]

_J = JOINT_INDEX
_SIDES = (("l_shoulder", "l_elbow", "l_wrist", "l_hand", "l_clavicle", "l_hip", "l_knee",
           "l_ankle"),
          ("r_shoulder", "r_elbow", "r_wrist", "r_hand", "r_clavicle", "r_hip", "r_knee",
           "r_ankle"))


@dataclass(frozen=True)
class BodyAngles:
    """Per-frame body angles (degrees) and support features.

    Attributes
    ----------
    trunk_flexion : ndarray, shape (T,)
        Forward bend of the trunk from vertical (negative: extension).
    trunk_side_bend, trunk_twist : ndarray, shape (T,)
        Lateral bend of the trunk, and rotation of the shoulder line against the hip line
        about the vertical (absolute values).
    neck_flexion : ndarray, shape (T,)
        Flexion of the neck-head line against the trunk (negative: extension).
    neck_side_bend : ndarray, shape (T,)
    upper_arm_flexion : ndarray, shape (T, 2)
        Elevation of the upper arm from hanging along the trunk, signed negative when the
        elbow lies behind the trunk (extension); columns left, right.
    upper_arm_abduction : ndarray, shape (T, 2)
        Angle of the upper arm out of the trunk's sagittal plane, outward positive (90 for
        an arm held straight out to the side, 0 for one raised straight forward).
    shoulder_raise : ndarray, shape (T, 2)
        Elevation of the clavicle-shoulder line above its rest angle.
    elbow_flexion : ndarray, shape (T, 2)
        0 for a straight arm.
    wrist_flexion : ndarray, shape (T, 2)
        Bend of the hand against the forearm.
    wrist_across : ndarray, shape (T, 2)
        Lateral distance (m) of the wrist past the body's mid-line (positive: the wrist
        crosses it) or, if negative, how far it stays on its own side.
    wrist_out : ndarray, shape (T, 2)
        Lateral distance (m) of the wrist outside its shoulder (positive: out to the side).
    knee_flexion : ndarray, shape (T, 2)
    ankle_height_difference : ndarray, shape (T,)
        |z_left_ankle - z_right_ankle| (m): one-legged support when large.
    hands_height : ndarray, shape (T, 2)
        Height of each hand above the floor (m).
    """

    trunk_flexion: np.ndarray
    trunk_side_bend: np.ndarray
    trunk_twist: np.ndarray
    neck_flexion: np.ndarray
    neck_side_bend: np.ndarray
    upper_arm_flexion: np.ndarray
    upper_arm_abduction: np.ndarray
    shoulder_raise: np.ndarray
    elbow_flexion: np.ndarray
    wrist_flexion: np.ndarray
    wrist_across: np.ndarray
    wrist_out: np.ndarray
    knee_flexion: np.ndarray
    ankle_height_difference: np.ndarray
    hands_height: np.ndarray

    @property
    def n_frames(self) -> int:
        return len(self.trunk_flexion)

    def frame(self, t: int) -> dict[str, object]:
        """The angles of frame ``t`` as plain Python values (for reports)."""
        out: dict[str, object] = {}
        for f in fields(self):
            v = getattr(self, f.name)[t]
            out[f.name] = v.tolist() if np.ndim(v) else float(v)
        return out


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(norm3(v)[..., None], 1e-12)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle (deg) between vectors a and b (..., 3)."""
    c = np.clip(_dot(_unit(a), _unit(b)), -1.0, 1.0)
    return np.degrees(np.arccos(c))


def _raw(p: np.ndarray) -> dict[str, np.ndarray]:
    up = np.array([0.0, 0.0, 1.0])
    hip = p[:, _J["l_hip"]] - p[:, _J["r_hip"]]
    hip[:, 2] = 0.0
    lat = _unit(hip)
    fwd = cross3(lat, up)
    trunk = p[:, _J["neck"]] - p[:, _J["pelvis"]]
    u = _unit(trunk)
    f = _unit(fwd - _dot(fwd, u)[:, None] * u)
    lt = cross3(u, f)
    out: dict[str, np.ndarray] = {
        "trunk_flexion": np.degrees(np.arctan2(_dot(trunk, fwd), _dot(trunk, up))),
        "trunk_side_bend": np.abs(np.degrees(np.arctan2(_dot(trunk, lat), _dot(trunk, up)))),
    }
    sh = p[:, _J["l_shoulder"]] - p[:, _J["r_shoulder"]]
    sh[:, 2] = 0.0
    cross = hip[:, 0] * sh[:, 1] - hip[:, 1] * sh[:, 0]
    out["trunk_twist"] = np.abs(np.degrees(np.arctan2(cross, _dot(hip, sh))))
    h = p[:, _J["head"]] - p[:, _J["neck"]]
    out["neck_flexion"] = np.degrees(np.arctan2(_dot(h, f), _dot(h, u)))
    out["neck_side_bend"] = np.degrees(np.arctan2(_dot(h, lt), _dot(h, u)))
    mid = p[:, _J["pelvis"]]
    cols: dict[str, list[np.ndarray]] = {k: [] for k in (
        "upper_arm_flexion", "upper_arm_abduction", "shoulder_raise", "elbow_flexion",
        "wrist_flexion", "wrist_across", "wrist_out", "knee_flexion", "hands_height")}
    for side, names in enumerate(_SIDES):
        shoulder, elbow, wrist, hand, clav, hip_j, knee, ankle = (p[:, _J[n]] for n in names)
        out_sign = 1.0 if side == 0 else -1.0
        a = elbow - shoulder
        elevation = _angle(a, -u)
        ahead = _dot(a, f)
        sideways = out_sign * _dot(a, lt)
        behind = (ahead < 0) & (-ahead > np.abs(sideways))
        cols["upper_arm_flexion"].append(np.where(behind, -elevation, elevation))
        cols["upper_arm_abduction"].append(np.degrees(np.arcsin(np.clip(
            sideways / np.maximum(norm3(a), 1e-12), -1.0, 1.0))))
        c = shoulder - clav
        cols["shoulder_raise"].append(np.degrees(np.arctan2(_dot(c, u),
                                                            np.abs(_dot(c, lt)) + 1e-12)))
        cols["elbow_flexion"].append(_angle(a, wrist - elbow))
        cols["wrist_flexion"].append(_angle(wrist - elbow, hand - wrist))
        lateral = _dot(wrist - mid, lt) * out_sign
        cols["wrist_across"].append(-lateral)
        cols["wrist_out"].append(lateral - _dot(shoulder - mid, lt) * out_sign)
        cols["knee_flexion"].append(_angle(knee - hip_j, ankle - knee))
        cols["hands_height"].append(hand[:, 2])
    for k, v in cols.items():
        out[k] = np.stack(v, axis=1)
    out["ankle_height_difference"] = np.abs(p[:, _J["l_ankle"], 2] - p[:, _J["r_ankle"], 2])
    return out


#: Angles that are measured from the skeleton's rest pose (its neutral posture), so that
#: the rest pose reads 0 for each.
_NEUTRAL_ZEROED = ("trunk_flexion", "neck_flexion", "neck_side_bend", "shoulder_raise")


@functools.lru_cache(maxsize=16)
def _neutral(stature: float) -> dict[str, np.ndarray]:
    raw = _raw(Skeleton(stature).rest_positions()[None])
    return {name: raw[name][0].copy() for name in _NEUTRAL_ZEROED}


def body_angles(positions: np.ndarray, stature: float | None = None) -> BodyAngles:
    """Body angles of every frame.

    Parameters
    ----------
    positions : ndarray, shape (T, 23, 3) or (23, 3)
        Joint positions of the canonical skeleton (metres, z up).
    stature : float, optional
        Only used to place the neutral rest pose (angles are scale-free); default 1.75 m.

    Returns
    -------
    BodyAngles
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim == 2:
        p = p[None]
    if p.ndim != 3 or p.shape[1:] != (N_JOINTS, 3):
        raise ValueError(f"positions must have shape (T, {N_JOINTS}, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("positions contain NaN or inf")
    raw = _raw(p)
    rest = _neutral(float(stature or 1.75))
    for name in _NEUTRAL_ZEROED:
        raw[name] = raw[name] - rest[name]
    raw["neck_side_bend"] = np.abs(raw["neck_side_bend"])
    return BodyAngles(**raw)
