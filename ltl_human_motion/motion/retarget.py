"""Retargeting joint positions onto the canonical skeleton.

Every loader returns world joint positions already retargeted onto the canonical
skeleton (:mod:`~ltl_human_motion.motion.skeleton`). They all go through
:func:`retarget_points`: the loader supplies, for each canonical joint, the trajectory of
the corresponding point of its own skeleton; this module keeps the *direction* of every
limb bone and sets the canonical length, while the rigid parts (pelvis to hips, chest to
clavicles and shoulders) follow the orientation of the source pelvis and chest. The root
(pelvis) path is scaled by the ratio of canonical to source leg length, so that steps
keep their length relative to the body, and the motion is lifted so that the feet touch
but never go below the floor.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.skeleton import JOINT_INDEX, JOINT_NAMES, PARENTS, Skeleton
from ltl_human_motion.motion.types import Motion

__all__ = [
    "REQUIRED_POINTS",
    "enforce_bone_lengths",
    "fix_feet",
    "frame_from_axes",
    "mirror_positions",
    "retarget_points",
]

# Source points a loader must provide (the spine is taken halfway between pelvis and chest
# when missing; head, hands and toes may be derived by the loader).
REQUIRED_POINTS: tuple[str, ...] = tuple(n for n in JOINT_NAMES if n not in ("spine",
                                                                             "l_clavicle",
                                                                             "r_clavicle"))
# Joints placed by a rigid frame rather than by a source bone direction.
_PELVIS_RIGID = ("l_hip", "r_hip")
_CHEST_RIGID = ("l_clavicle", "r_clavicle", "l_shoulder", "r_shoulder")


def frame_from_axes(lateral: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Orthonormal frames whose y axis is ``lateral`` and whose z axis is ``up`` made orthogonal.

    Parameters
    ----------
    lateral, up : ndarray, shape (..., 3)

    Returns
    -------
    R : ndarray, shape (..., 3, 3)
        Columns are the x (forward), y (left) and z (up) axes.
    """
    y = lateral / np.maximum(np.linalg.norm(lateral, axis=-1, keepdims=True), 1e-12)
    z = up - np.sum(up * y, axis=-1, keepdims=True) * y
    z = z / np.maximum(np.linalg.norm(z, axis=-1, keepdims=True), 1e-12)
    x = np.cross(y, z)
    return np.stack([x, y, z], axis=-1)


_RIGID = {JOINT_INDEX[n]: "pelvis" for n in _PELVIS_RIGID} | {
    JOINT_INDEX[n]: "chest" for n in _CHEST_RIGID}
#: Joints placed along their source bone, and their parents.
_FREE_J = np.array([j for j in range(1, len(JOINT_NAMES)) if j not in _RIGID])
_FREE_P = np.array([PARENTS[j] for j in _FREE_J])
_FREE_HIPS_J = np.array([j for j in range(1, len(JOINT_NAMES))
                         if j not in _RIGID or _RIGID[j] == "pelvis"])
_FREE_HIPS_P = np.array([PARENTS[j] for j in _FREE_HIPS_J])


def _build(points: dict[str, np.ndarray], pelvis: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """Canonical positions (T, J, 3) from source points and a given pelvis path."""
    spine = points.get("spine")
    if spine is None:
        spine = 0.5 * (points["pelvis"] + points["chest"])
    src = np.zeros((pelvis.shape[0], len(JOINT_NAMES), 3))
    for j, n in enumerate(JOINT_NAMES):
        if n == "spine":
            src[:, j] = spine
        elif n in points:
            src[:, j] = points[n]             # clavicles are placed rigidly, not from points
    return _build_array(src, pelvis, skeleton)


def _build_array(src: np.ndarray, pelvis: np.ndarray, skeleton: Skeleton,
                 rigid_hips: bool = True) -> np.ndarray:
    """Canonical positions (T, J, 3) from source points ``src`` (T, J, 3) and a pelvis path.

    Limb bones keep their source direction (a degenerate source bone the rest direction)
    and get the canonical length; hips (unless not ``rigid_hips``: then they are free
    bones too), clavicles and shoulders follow the frames of the source pelvis and
    chest. Each joint is its parent plus its bone. The work is
    done on a joint-, then coordinate-major copy (J, 3, T), so every step runs over
    contiguous rows.
    """
    rest = skeleton.rest_positions()
    lengths = skeleton.bone_lengths()
    T, J = pelvis.shape[0], len(JOINT_NAMES)
    s = np.ascontiguousarray(np.asarray(src, dtype=np.float64).transpose(1, 2, 0))  # (J,3,T)

    def point(name: str) -> np.ndarray:                  # (T, 3) view
        return s[JOINT_INDEX[name]].T

    frames = {"pelvis": frame_from_axes(point("l_hip") - point("r_hip"),
                                        point("chest") - point("pelvis")),
              "chest": frame_from_axes(point("l_shoulder") - point("r_shoulder"),
                                       point("neck") - point("chest"))}
    free_j, free_p = (_FREE_J, _FREE_P) if rigid_hips else (_FREE_HIPS_J, _FREE_HIPS_P)
    rigid = {j: frames[which] @ (rest[j] - rest[PARENTS[j]]) for j, which in _RIGID.items()
             if rigid_hips or which != "pelvis"}                          # (T, 3) each
    # a degenerate (zero-length) source bone keeps the canonical rest direction
    rest_vec = rest[free_j] - rest[free_p]
    rest_dir = rest_vec / np.maximum(np.linalg.norm(rest_vec, axis=-1, keepdims=True), 1e-12)
    compiled = _compiled_chain(src, pelvis, free_j, free_p, lengths[free_j], rest_dir, rigid)
    if compiled is not None:
        return compiled
    bone = np.empty((J, 3, T))                          # each joint minus its parent
    for j, rigid_bone in rigid.items():
        bone[j] = rigid_bone.T
    vec = s[free_j] - s[free_p]                                         # (n, 3, T)
    norm = np.sqrt(vec[:, 0] * vec[:, 0] + vec[:, 1] * vec[:, 1]
                   + vec[:, 2] * vec[:, 2])[:, None]                     # (n, 1, T)
    direction = np.where(norm > 1e-9, vec / np.maximum(norm, 1e-12), rest_dir[:, :, None])
    bone[free_j] = lengths[free_j][:, None, None] * direction
    out = np.empty((J, 3, T))
    out[0] = np.asarray(pelvis, dtype=np.float64).T
    for j in range(1, J):                               # parents come before children
        out[j] = out[PARENTS[j]] + bone[j]
    return np.ascontiguousarray(out.transpose(2, 0, 1))


_PARENTS = np.asarray(PARENTS, dtype=np.int64)


def _compiled_chain(src: np.ndarray, pelvis: np.ndarray, free_j: np.ndarray,
                    free_p: np.ndarray, free_len: np.ndarray, rest_dir: np.ndarray,
                    rigid: dict[int, np.ndarray]) -> np.ndarray | None:
    """The positions (T, J, 3) of :func:`_build_array` by the compiled loop (the same
    numbers) from its free bones (joints, parents, lengths and rest directions) and its
    rigid bones (joint -> (T, 3)), or None where it is not in use (numba off)."""
    from ltl_human_motion.kernel.segments import compiled_module
    nb = compiled_module("ltl_human_motion.motion._retarget_numba")
    if nb is None:
        return None
    T = len(pelvis)
    rigid_j = np.array(sorted(rigid), dtype=np.int64)
    out = np.empty((T, len(JOINT_NAMES), 3))
    nb.chain_positions(np.ascontiguousarray(src, dtype=np.float64),
                       np.ascontiguousarray(pelvis, dtype=np.float64),
                       np.asarray(free_j, dtype=np.int64), np.asarray(free_p, dtype=np.int64),
                       np.ascontiguousarray(free_len, dtype=np.float64),
                       np.ascontiguousarray(rest_dir, dtype=np.float64), rigid_j,
                       np.ascontiguousarray(np.stack([rigid[j] for j in rigid_j])
                                            if len(rigid_j) else np.zeros((0, T, 3))),
                       _PARENTS, out)
    return out


def _check_points(points: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    missing = [n for n in REQUIRED_POINTS if n not in points]
    if missing:
        raise ValueError(f"retargeting needs source points for {', '.join(missing)}")
    arrays = {k: np.asarray(v, dtype=np.float64) for k, v in points.items()}
    shape = arrays["pelvis"].shape
    if len(shape) != 2 or shape[1] != 3:
        raise ValueError(f"source points must have shape (T, 3), got {shape} for pelvis")
    for k, v in arrays.items():
        if v.shape != shape:
            raise ValueError(f"source point {k!r} has shape {v.shape}, expected {shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError(f"source point {k!r} contains NaN or infinite values")
    return arrays


def retarget_points(points: dict[str, np.ndarray], fps: float, skeleton: Skeleton | None = None,
                    name: str = "", ground: bool = True) -> Motion:
    """Retarget source joint trajectories (z up, metres) onto the canonical skeleton.

    Parameters
    ----------
    points : dict of str to ndarray, shape (T, 3)
        Source trajectories keyed by canonical joint name; every name of
        :data:`REQUIRED_POINTS` is needed (``spine`` is optional). Must be z up and face
        the same way as the source body; units only matter for the root path, which is
        rescaled by leg length.
    fps : float
    skeleton : Skeleton, optional
        Target body (default stature 1.75 m).
    name : str
    ground : bool
        Lift or lower the whole motion so that its lowest foot point touches the floor.

    Returns
    -------
    Motion
    """
    skeleton = skeleton or Skeleton()
    pts = _check_points(points)
    rest = skeleton.rest_positions()
    src_leg = np.median(
        np.linalg.norm(pts["l_hip"] - pts["l_knee"], axis=-1)
        + np.linalg.norm(pts["l_knee"] - pts["l_ankle"], axis=-1))
    canon_leg = (np.linalg.norm(rest[JOINT_INDEX["l_hip"]] - rest[JOINT_INDEX["l_knee"]])
                 + np.linalg.norm(rest[JOINT_INDEX["l_knee"]] - rest[JOINT_INDEX["l_ankle"]]))
    if not src_leg > 1e-9:
        raise ValueError("source legs have zero length")
    pelvis = pts["pelvis"] * (canon_leg / src_leg)
    out = _build(pts, pelvis, skeleton)
    if ground:
        out = _ground(out, skeleton)
    return Motion(out, fps, skeleton, name)


def _ground(positions: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """Shift vertically so the lowest foot joint over the motion sits at its rest height."""
    feet = [JOINT_INDEX[n] for n in ("l_ankle", "l_toe", "r_ankle", "r_toe")]
    rest = skeleton.rest_positions()
    # Height of each foot joint above its own rest height; the minimum over joints & frames.
    lift = positions[:, feet, 2] - rest[feet, 2]
    shift = -float(lift.min())
    out = positions.copy()
    out[..., 2] += shift
    return out


def fix_feet(positions: np.ndarray, fps: float, skeleton: Skeleton, clearance: float = 0.02,
             swing_speed: tuple[float, float] = (0.3, 1.0)) -> np.ndarray:
    """Remove toe scuffing and floor penetration (keeps bone lengths).

    1. A toe that moves horizontally faster than ``swing_speed[0]`` m/s is a swinging foot:
       it is raised (by turning the foot about the ankle, keeping its length and heading)
       to at least ``clearance`` above its rest height, fully at ``swing_speed[1]`` m/s.
    2. Frames where a foot joint is still below its rest height lift the whole body by
       the deficit (smoothed over 50 ms so the lift does not jerk).

    Parameters
    ----------
    positions : ndarray, shape (T, J, 3)
        World positions on the canonical skeleton.
    fps : float
    skeleton : Skeleton

    Returns
    -------
    ndarray, shape (T, J, 3)
    """
    from scipy.ndimage import maximum_filter1d, uniform_filter1d

    out = np.array(positions, dtype=np.float64, copy=True)
    rest = skeleton.rest_positions()
    T = out.shape[0]
    for side in ("l", "r"):
        a, t = JOINT_INDEX[f"{side}_ankle"], JOINT_INDEX[f"{side}_toe"]
        if T > 1:
            v = np.linalg.norm(np.gradient(out[:, t, :2], axis=0), axis=-1) * fps
        else:
            v = np.zeros(T)
        ramp = np.clip((v - swing_speed[0]) / (swing_speed[1] - swing_speed[0]), 0.0, 1.0)
        ramp = ramp * ramp * (3 - 2 * ramp)
        width = max(1, round(0.03 * fps))
        ramp = uniform_filter1d(maximum_filter1d(ramp, 2 * width + 1), 4 * width + 1)
        floor_t = rest[t, 2] + clearance * ramp
        low = out[:, t, 2] < floor_t
        if np.any(low):
            foot = out[low, t] - out[low, a]
            length = np.linalg.norm(foot, axis=-1)
            vz = np.clip(floor_t[low] - out[low, a, 2], -length, length)
            horiz = foot[:, :2]
            hn = np.linalg.norm(horiz, axis=-1, keepdims=True)
            hdir = horiz / np.maximum(hn, 1e-9)
            hmag = np.sqrt(np.maximum(length ** 2 - vz ** 2, 0.0))[:, None]
            out[low, t, :2] = out[low, a, :2] + hdir * hmag
            out[low, t, 2] = out[low, a, 2] + vz
    feet = [JOINT_INDEX[n] for n in ("l_ankle", "l_toe", "r_ankle", "r_toe")]
    deficit = np.max(rest[feet, 2] - out[:, feet, 2], axis=1).clip(min=0.0)
    if np.any(deficit > 0):
        width = max(1, round(0.05 * fps))
        lift = maximum_filter1d(deficit, size=2 * width + 1)
        lift = np.maximum(uniform_filter1d(lift, size=2 * width + 1), deficit)
        out[..., 2] += lift[:, None]
    return out


def enforce_bone_lengths(positions: np.ndarray, skeleton: Skeleton,
                         rigid_hips: bool = True) -> np.ndarray:
    """Re-impose canonical bone lengths on canonical-skeleton positions (keeps directions).

    Parameters
    ----------
    positions : ndarray, shape (T, J, 3)
    rigid_hips : bool
        Place the hips rigidly in the pelvis frame (lateral from hip to hip, up towards
        the chest), as retargeting does. False keeps each hip's direction from the pelvis
        like any other bone's: a model-made pose whose pelvis tilts less than its chest
        (a crouch) keeps its legs and feet where the model put them (rebuilt rigidly,
        the hips of a 60 degree trunk flexion swing 3-4 cm back, and the feet with them).

    Returns
    -------
    ndarray, shape (T, J, 3)
        Same pelvis path; every bone has its canonical length.
    """
    pos = np.asarray(positions, dtype=np.float64)
    return _build_array(pos, pos[:, 0], skeleton, rigid_hips)


def mirror_positions(positions: np.ndarray) -> np.ndarray:
    """Mirror canonical-skeleton positions left/right (y -> -y and swap l_/r_ joints).

    Parameters
    ----------
    positions : ndarray, shape (..., J, 3)

    Returns
    -------
    ndarray, shape (..., J, 3)
    """
    from ltl_human_motion.motion.skeleton import MIRROR_PERMUTATION

    out = np.asarray(positions, dtype=np.float64)[..., list(MIRROR_PERMUTATION), :].copy()
    out[..., 1] *= -1.0
    return out
