"""Gait primitives (walk and carry) from looping real walking clips.

Pipeline for every looping clip (default: the DeepMimic walk and walking-turn loops that
ship with pybullet, see :data:`~ltl_human_motion.motion.deepmimic.DEFAULT_GAIT_CLIPS`):

1. load and retarget onto the canonical skeleton; optionally mirror left/right;
2. make the loop seamless: the pose mismatch between the last frame and the first (the
   clips repeat their first pose at the end) is spread linearly over the cycle;
3. tile three cycles (each one moved by the cycle's own root displacement), resample
   with a cubic spline to ``LIBRARY_FPS`` and re-impose canonical bone lengths;
4. cut primitives of ``PRIMITIVE_FRAMES + 1`` frames (20 intervals = 166.6 ms at 120 Hz,
   the last frame of a primitive is the first of its natural successor) starting every
   ``phase_step`` frames of the middle cycle, so successive cycles are covered seamlessly;
5. ``carry`` primitives are the same with the arms posed (by two-bone IK) to hold an
   object in front of the chest;
6. start and stop primitives: the clip is time-warped from standing still to full speed
   (or back) with a minimum-jerk speed ramp while the pose blends from the standing pose
   into the walk (or back), so synthesis can begin and end standing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ltl_human_motion.kernel.rotations import matrix_from_yaw
from ltl_human_motion.motion.ik import min_jerk, two_bone_ik
from ltl_human_motion.motion.ops import (
    compose,
    decompose,
    poses_from_world,
    relative_root,
    resample_positions,
)
from ltl_human_motion.motion.retarget import enforce_bone_lengths, fix_feet, mirror_positions
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import Motion, MotionPrimitive

__all__ = [
    "CARRY_HAND_OFFSET",
    "LIBRARY_FPS",
    "OVERLAP",
    "PRIMITIVE_FRAMES",
    "GaitClip",
    "carry_poses",
    "clip_motion",
    "gait_primitives",
    "prepare_clip",
    "prepare_loop",
    "standing_pose",
    "start_stop_primitives",
]

LIBRARY_FPS = 120.0
PRIMITIVE_FRAMES = 20
OVERLAP = 5          # frames blended between consecutive primitives (= k_comp)
_J = JOINT_INDEX
# Palm centres when carrying, in the pelvis heading frame relative to the chest joint,
# as fractions of stature (forward, left, up).
CARRY_HAND_OFFSET = np.array([0.17, 0.075, -0.09])
#: Length of the speed ramp of start and stop primitives, s: gait initiation and
#: termination take one to two steps, 0.8-1.2 s at a self-selected pace (Jian et al.
#: 1993, *Gait & Posture* 1:9); a shorter ramp makes the pose blend from the standing
#: pose sweep the swing foot faster than any real step.
START_STOP_DURATION = 1.0


@dataclass(frozen=True)
class GaitClip:
    """A seamless gait loop resampled to the library rate and tiled over three cycles.

    Attributes
    ----------
    name : str
    root : ndarray, shape (F, 4)
        Pelvis x, y, z and unwrapped heading over three cycles.
    poses : ndarray, shape (F, J, 3)
        Root-relative heading-frame poses.
    period : int
        Frames per cycle at ``LIBRARY_FPS``; the middle cycle starts at frame ``period``.
        0 for a clip that does not loop (then primitives are cut along the whole clip).
    source : str
    """

    name: str
    root: np.ndarray
    poses: np.ndarray
    period: int
    source: str

    @property
    def loops(self) -> bool:
        return self.period > 0


def _clean(root: np.ndarray, poses: np.ndarray, fps: float,
           skeleton: Skeleton) -> tuple[np.ndarray, np.ndarray]:
    """Apply :func:`fix_feet` in the world frame, keeping the given heading track."""
    world = fix_feet(compose(root, poses), fps, skeleton)
    root = root.copy()
    root[:, :3] = world[:, 0]
    return root, poses_from_world(world, root[:, 3])


def prepare_loop(motion: Motion, name: str, source: str, mirror: bool = False,
                 fps: float = LIBRARY_FPS) -> GaitClip:
    """Seamless, resampled, three-cycle version of a looping clip (see module docstring).

    Parameters
    ----------
    motion : Motion
        A looping clip whose last frame repeats the first pose.
    name, source : str
    mirror : bool
        Mirror left/right first.
    fps : float
        Output rate.
    """
    if motion.n_frames < 4:
        raise ValueError(f"a gait loop needs at least 4 frames, {name!r} has {motion.n_frames}")
    pos = mirror_positions(motion.positions) if mirror else motion.positions
    root, poses = decompose(pos)
    root = relative_root(root)
    n = root.shape[0]
    ramp = np.arange(n) / (n - 1)
    poses = poses - ramp[:, None, None] * (poses[-1] - poses[0])[None]
    root[:, 2] -= ramp * (root[-1, 2] - root[0, 2])
    delta = root[-1].copy()                                    # one cycle's displacement
    cycles_root, cycles_poses = [], []
    offset = np.zeros(4)
    for k in range(3):
        c, s = np.cos(offset[3]), np.sin(offset[3])
        r = root[:-1].copy() if k < 2 else root.copy()
        x = offset[0] + c * r[:, 0] - s * r[:, 1]
        y = offset[1] + s * r[:, 0] + c * r[:, 1]
        cycles_root.append(np.stack([x, y, r[:, 2], r[:, 3] + offset[3]], axis=1))
        cycles_poses.append(poses[:-1] if k < 2 else poses)
        # compose the cycle displacement
        offset = np.array([offset[0] + c * delta[0] - s * delta[1],
                           offset[1] + s * delta[0] + c * delta[1], 0.0, offset[3] + delta[3]])
    root3 = np.concatenate(cycles_root)
    poses3 = np.concatenate(cycles_poses)
    # Root heading = the pelvis/shoulder heading averaged over one gait cycle, so it
    # follows the walking direction instead of swinging with the pelvis at every step.
    from scipy.ndimage import uniform_filter1d

    smooth = uniform_filter1d(root3[:, 3], size=n - 1, mode="nearest")
    twist = matrix_from_yaw(root3[:, 3] - smooth)
    poses3 = np.einsum("tij,tkj->tki", twist, poses3)
    root3[:, 3] = smooth
    root_r = resample_positions(root3, motion.fps, fps)
    poses_r = resample_positions(poses3, motion.fps, fps)
    poses_r = enforce_bone_lengths(poses_r - poses_r[:, :1], motion.skeleton)
    root_r, poses_r = _clean(root_r, poses_r, fps, motion.skeleton)
    period = round((n - 1) / motion.fps * fps)
    return GaitClip(name=name + ("_m" if mirror else ""), root=root_r, poses=poses_r,
                    period=period, source=source + (" (mirrored)" if mirror else ""))


def prepare_clip(motion: Motion, name: str, source: str, mirror: bool = False,
                 fps: float = LIBRARY_FPS) -> GaitClip:
    """A non-looping clip resampled to ``fps`` (for user-supplied walking clips)."""
    if motion.n_frames < 4:
        raise ValueError(f"a gait clip needs at least 4 frames, {name!r} has {motion.n_frames}")
    pos = mirror_positions(motion.positions) if mirror else motion.positions
    pos = fix_feet(pos, motion.fps, motion.skeleton)
    root, poses = decompose(pos)
    root = relative_root(root)
    if abs(motion.fps - fps) > 1e-9:
        root = resample_positions(root, motion.fps, fps)
        poses = resample_positions(poses, motion.fps, fps)
        poses = enforce_bone_lengths(poses - poses[:, :1], motion.skeleton)
    root, poses = _clean(root, poses, fps, motion.skeleton)
    return GaitClip(name=name + ("_m" if mirror else ""), root=root, poses=poses, period=0,
                    source=source + (" (mirrored)" if mirror else ""))


def carry_poses(poses: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """Replace the arms so both hands hold an object in front of the chest.

    Parameters
    ----------
    poses : ndarray, shape (T, J, 3)
        Root-relative heading-frame poses.

    Returns
    -------
    ndarray, shape (T, J, 3)
    """
    out = np.array(poses, dtype=np.float64, copy=True)
    b = skeleton.bone_lengths()
    H = skeleton.stature
    chest = out[:, _J["chest"]]
    for side, sign in (("l", 1.0), ("r", -1.0)):
        sh, el, wr, ha = (_J[f"{side}_{n}"] for n in ("shoulder", "elbow", "wrist", "hand"))
        hand = chest + H * CARRY_HAND_OFFSET * np.array([1.0, sign, 1.0])
        hand_dir = np.array([0.6, -0.55 * sign, 0.58])
        hand_dir /= np.linalg.norm(hand_dir)
        wrist = hand - b[ha] * hand_dir
        pole = np.broadcast_to(np.array([-0.3, 0.6 * sign, -1.0]), wrist.shape)
        elbow, wrist = two_bone_ik(out[:, sh], wrist, b[el], b[wr], pole)
        out[:, el], out[:, wr], out[:, ha] = elbow, wrist, wrist + b[ha] * hand_dir
    return out


def standing_pose(skeleton: Skeleton, carry: bool = False) -> tuple[np.ndarray, float]:
    """The standing pose that start primitives begin with and stop primitives end in.

    Returns
    -------
    pose : ndarray, shape (J, 3)
        Root-relative pose facing +x (the rest pose, arms hanging; or holding an object).
    root_height : float
        Pelvis height above the floor.
    """
    rest = skeleton.rest_positions()
    pose = rest - rest[0]
    if carry:
        pose = carry_poses(pose[None], skeleton)[0]
    return pose, float(rest[0, 2])


def _cut(clip: GaitClip, task: str, poses: np.ndarray, phase_step: int, overlap: int,
         fps: float, prefix: str) -> list[MotionPrimitive]:
    out = []
    n = PRIMITIVE_FRAMES + overlap
    if clip.loops:
        starts = [(ph, clip.period + ph - (overlap - 1)) for ph in range(0, clip.period,
                                                                          phase_step)]
    else:
        starts = [(s + overlap - 1, s) for s in range(0, clip.root.shape[0] - n + 1, phase_step)]
    for ph, s in starts:
        out.append(MotionPrimitive(
            name=f"{prefix}_{clip.name}_p{ph:03d}", task=task, poses=poses[s:s + n],
            root=relative_root(clip.root[s:s + n]), fps=fps,
            source=f"{clip.source} frames {ph - overlap + 1}-{ph + PRIMITIVE_FRAMES} "
                   f"@ {fps:g} Hz",
            meta={"clip": clip.name, "phase": ph, "period": clip.period, "kind": "loop"}))
    return out


def gait_primitives(clip: GaitClip, skeleton: Skeleton, phase_step: int = 4,
                    overlap: int = OVERLAP, carry: bool = True,
                    fps: float = LIBRARY_FPS) -> list[MotionPrimitive]:
    """Walk (and carry) primitives cut from the middle cycle of ``clip``.

    Each primitive has ``PRIMITIVE_FRAMES + overlap`` frames: its successor's first
    ``overlap`` frames are blended with its last ``overlap`` frames (paper Eq. 2 with
    ``nf = overlap``), so it advances time by exactly ``PRIMITIVE_FRAMES`` frames, and a
    natural successor (the next piece of the same clip) has distance 0.

    Parameters
    ----------
    clip : GaitClip
    skeleton : Skeleton
    phase_step : int
        Frames between the starts of consecutive primitives; must divide 20.
    overlap : int
        Frames shared with the successor (the transition window ``k_comp``).
    carry : bool
        Also make carry primitives.
    """
    if PRIMITIVE_FRAMES % phase_step or overlap < 1:
        raise ValueError(f"phase_step must divide {PRIMITIVE_FRAMES} and overlap be >= 1, "
                         f"got {phase_step}, {overlap}")
    prims = _cut(clip, "walk", clip.poses, phase_step, overlap, fps, "walk")
    if carry:
        prims += _cut(clip, "carry", carry_poses(clip.poses, skeleton), phase_step, overlap,
                      fps, "carry")
    return prims


def _sample(track: np.ndarray, phase: np.ndarray) -> np.ndarray:
    """Linear interpolation of ``track`` (F, ...) at fractional frames ``phase`` (T,)."""
    i0 = np.clip(np.floor(phase).astype(int), 0, track.shape[0] - 2)
    a = (phase - i0).reshape((-1,) + (1,) * (track.ndim - 1))
    return (1 - a) * track[i0] + a * track[i0 + 1]


def _transition(clip: GaitClip, skeleton: Skeleton, poses: np.ndarray, stand: np.ndarray,
                stand_z: float, phase0: float, n: int, overlap: int,
                starting: bool) -> tuple[np.ndarray, np.ndarray]:
    tau = np.arange(n + 1) / n
    ramp = min_jerk(tau)
    if starting:   # ramp up, then overlap - 1 frames of plain walking
        speed, weight = ramp, ramp
    else:          # overlap - 1 frames of plain walking, then ramp down
        speed, weight = 1.0 - ramp, 1.0 - ramp
    ramp_phase = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]))])
    extra = np.arange(1, overlap, dtype=np.float64)
    if starting:
        phase = np.concatenate([ramp_phase, ramp_phase[-1] + extra])
        weight = np.concatenate([weight, np.ones(overlap - 1)])
    else:
        phase = np.concatenate([extra - overlap, ramp_phase])
        weight = np.concatenate([np.ones(overlap - 1), weight])
    phase = phase + phase0
    root = relative_root(_sample(clip.root, phase))
    walk = _sample(poses, phase)
    w = weight[:, None, None]
    blended = w * walk + (1 - w) * stand[None]
    blended = enforce_bone_lengths(blended - blended[:, :1], skeleton)
    root[:, 2] = weight * root[:, 2] + (1 - weight) * stand_z
    root, blended = _clean(root, blended, LIBRARY_FPS, skeleton)
    return relative_root(root), blended


def start_stop_primitives(clip: GaitClip, skeleton: Skeleton, n_phases: int = 4,
                          duration: float = START_STOP_DURATION, overlap: int = OVERLAP,
                          carry: bool = True,
                          fps: float = LIBRARY_FPS) -> list[MotionPrimitive]:
    """Start (standing to walking) and stop (walking to standing) primitives.

    A start primitive begins in :func:`standing_pose` and ends with ``overlap`` frames of
    plain walking, so that its natural successor (the loop primitive whose first frames are
    those) has distance 0; a stop primitive begins with ``overlap`` frames of plain walking
    and ends standing still in :func:`standing_pose`.

    Parameters
    ----------
    clip : GaitClip
    skeleton : Skeleton
    n_phases : int
        Number of evenly spaced gait phases to start from / stop at.
    duration : float
        Length of the speed ramp in seconds (rounded to a multiple of 8 frames so that a
        start ends on the primitive grid).
    overlap : int

    Returns
    -------
    list of MotionPrimitive
        ``meta["kind"]`` is ``"start"`` or ``"stop"``.
    """
    n = max(8, round(duration * fps / 8.0) * 8)
    out: list[MotionPrimitive] = []
    if not clip.loops:
        return out
    variants = [("walk", clip.poses, False)]
    if carry:
        variants.append(("carry", carry_poses(clip.poses, skeleton), True))
    for task, poses, is_carry in variants:
        stand, stand_z = standing_pose(skeleton, carry=is_carry)
        for k in range(n_phases):
            ph = (k * clip.period // n_phases) // PRIMITIVE_FRAMES * PRIMITIVE_FRAMES
            for starting, kind in ((True, "start"), (False, "stop")):
                root, p = _transition(clip, skeleton, poses, stand, stand_z,
                                      clip.period + ph, n, overlap, starting)
                what = "standing -> walk" if starting else "walk -> standing"
                out.append(MotionPrimitive(
                    name=f"{task}_{kind}_{clip.name}_p{ph:03d}", task=task, poses=p,
                    root=root, fps=fps, source=f"{clip.source}: {what} at phase {ph}",
                    meta={"clip": clip.name, "phase": ph, "period": clip.period,
                          "kind": kind}))
    return out


def clip_motion(clip: GaitClip, skeleton: Skeleton, fps: float = LIBRARY_FPS) -> Motion:
    """World motion of the three tiled cycles of ``clip`` (the realism report compares
    these prepared clips with synthesized motion)."""
    return Motion(compose(clip.root, clip.poses), fps, skeleton, clip.name)
