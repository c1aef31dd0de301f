"""Turning on the spot: model-made standing-to-standing gait primitives.

The real walking clips only turn while walking forward, so a worker facing a bench
could not leave it. A turn primitive rotates the body about the pelvis with a
minimum-jerk heading profile while the feet step one after the other (the foot on the
turning side first), each lifted on a sine arc; knees follow by two-bone IK.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.biomechanics import max_self_penetration, self_penetration
from ltl_human_motion.motion.ik import min_jerk, two_bone_ik
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import MotionPrimitive

TURN_ANGLES_DEG = (-180.0, -135.0, -90.0, -45.0, -20.0, 20.0, 45.0, 90.0, 135.0)
#: Steps on the spot: (forward, left, turn in degrees). The short ones let a walk end
#: exactly where a goal primitive can reach its target.
STEPS = ((-0.3, 0.0, 0.0), (-0.3, 0.0, 90.0), (-0.3, 0.0, -90.0), (0.0, 0.25, 0.0),
         (0.0, -0.25, 0.0), (0.15, 0.0, 0.0), (-0.15, 0.0, 0.0), (0.0, 0.12, 0.0),
         (0.0, -0.12, 0.0))
_FOOT = {"l": ("l_ankle", "l_toe"), "r": ("r_ankle", "r_toe")}
#: Fraction of a foot's step window at either end where it only rises or sets down.
_LIFT_LEAD = 0.2


def _turned(yaw: np.ndarray, points: np.ndarray, inverse: bool = False) -> np.ndarray:
    """Points turned about +z per frame: ``yaw_matrix(yaw) @ p`` (``inverse``: its
    transpose), written out instead of a matrix product.

    Parameters
    ----------
    yaw : ndarray, shape (T,)
    points : ndarray, shape (T, J, 3) or (1, J, 3)
    inverse : bool

    Returns
    -------
    ndarray, shape (T, J, 3)
    """
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]                   # (T, 1)
    if inverse:
        s = -s
    x, y = points[..., 0], points[..., 1]
    out = np.empty((len(yaw), points.shape[1], 3))
    out[..., 0] = c * x - s * y
    out[..., 1] = s * x + c * y
    out[..., 2] = points[..., 2]
    return out


def _progress(t: np.ndarray, a: float, b: float) -> np.ndarray:
    return min_jerk(np.clip((t - a) / (b - a), 0.0, 1.0))


#: Clearance (m) the hanging arms keep from the thighs of the stepping legs, over the
#: self-penetration check of motion.biomechanics. 2 cm: foot locking (planning.footlock)
#: turns a thigh of a step by up to 1 cm towards its hand (1 cm left the hand 2 mm inside
#: the thigh in the steps back of a 1.55 m worker).
ARM_CLEARANCE = 0.02
#: Time (s) over which the arms swing out of the legs' way and back (half-width).
ARM_RAMP = 0.15


def _arms_clear_of_thighs(poses: np.ndarray, skeleton: Skeleton, fps: float) -> np.ndarray:
    """Poses (T, J, 3) (root-relative, facing +x) with each arm abducted about its shoulder
    just enough that no arm segment enters the thigh of its side (a thigh stepping back or
    turning swings through the hanging hand), the angle smoothed over ``ARM_RAMP``."""
    from scipy.ndimage import maximum_filter1d, uniform_filter1d

    out = np.array(poses, dtype=np.float64, copy=True)
    width = 2 * max(1, round(ARM_RAMP * fps)) + 1
    # the first and last frames stay the standing pose the primitive starts and ends in
    k = np.arange(len(out))
    half = max(1, round(ARM_RAMP * fps))
    ends_fixed = min_jerk(np.clip(k / half, 0.0, 1.0)) * min_jerk(
        np.clip((len(out) - 1 - k) / half, 0.0, 1.0))
    for _ in range(2):
        depth, pairs = self_penetration(out, skeleton.stature)
        done = True
        for side, sign in (("l", 1.0), ("r", -1.0)):
            cols = [i for i, (a, b) in enumerate(pairs) if b == f"{side}_thigh"
                    and a in (f"{side}_upper_arm", f"{side}_lower_arm", f"{side}_hand")]
            # never more clearance than the standing pose at either end has (it starts and
            # ends the primitive unchanged)
            ends = max(float(depth[0, cols].max()), float(depth[-1, cols].max()))
            clearance = float(np.clip(-ends, 0.0, ARM_CLEARANCE))
            need = np.maximum(depth[:, cols].max(axis=1) + clearance, 0.0)
            if not np.any(depth[:, cols] > -clearance):
                continue
            done = False
            sh = JOINT_INDEX[f"{side}_shoulder"]
            arm = [JOINT_INDEX[f"{side}_{x}"] for x in ("elbow", "wrist", "hand")]
            reach = np.linalg.norm(out[:, arm[-1]] - out[:, sh], axis=-1)
            ang = need / np.maximum(reach, 1e-6)
            ang = uniform_filter1d(maximum_filter1d(ang, width), width) * ends_fixed
            c, s = np.cos(sign * ang)[:, None], np.sin(sign * ang)[:, None]
            rel = out[:, arm] - out[:, sh][:, None]
            y, z = rel[..., 1].copy(), rel[..., 2].copy()
            rel[..., 1] = c * y - s * z
            rel[..., 2] = s * y + c * z
            out[:, arm] = out[:, sh][:, None] + rel
        if done:
            break
    return out


def make_step_primitive(stand: np.ndarray, height: float, dx: float, dy: float, angle: float,
                        skeleton: Skeleton, fps: float, task: str = "walk",
                        lift: float = 0.06) -> MotionPrimitive:
    """A standing-to-standing primitive: step by (dx, dy) and turn by ``angle``.

    The pelvis follows a minimum-jerk path; the feet step one after the other (the
    foot on the side of the turn or of the step first), each lifted on a sin^2 arc and
    moved only once lifted (the first and last fifth of its window are rise and set
    down), and the knees follow by two-bone IK.

    Parameters
    ----------
    stand : array-like, shape (J, 3)
        Root-relative standing pose facing +x (walk or carry arms).
    height : float
        Pelvis height above the floor.
    dx, dy : float
        Displacement of the root in its start frame, metres (dx < 0 steps back).
    angle : float
        Turn, radians (positive: to the left).
    skeleton : Skeleton
    fps : float
    task : {"walk", "carry"}
    lift : float
        Foot clearance of each step, metres.

    Returns
    -------
    MotionPrimitive
        Starts and ends in ``stand``; ``root[-1] == (dx, dy, height, angle)``.
    """
    stand = np.asarray(stand, dtype=np.float64)
    # Turns over 90 deg take two steps per foot (one step turning a foot further crosses
    # the legs), and correspondingly longer. The foot on the side of the turn (or of the
    # step) leads, unless the other lead, or a further step per foot, keeps the legs from
    # passing through each other (a step against the direction of the turn).
    n_min = 4 if abs(angle) > np.radians(95.0) else 2
    lead = "l" if (angle > 0 or (angle == 0 and dy > 0)) else "r"
    other = "r" if lead == "l" else "l"
    best = None
    for n_steps in (n_min, n_min + 2):
        for side in (lead, other):
            mp = _step_primitive(stand, height, dx, dy, angle, skeleton, fps, task, lift,
                                 side, n_steps)
            depth = max_self_penetration(mp.poses, skeleton.stature)
            if depth <= 0.0:
                return mp
            if best is None or depth < best[0]:
                best = (depth, mp)
    return best[1]


def _step_primitive(stand: np.ndarray, height: float, dx: float, dy: float, angle: float,
                    skeleton: Skeleton, fps: float, task: str, lift: float, lead: str,
                    n_steps: int) -> MotionPrimitive:
    """:func:`make_step_primitive` with ``lead`` ("l"/"r") stepping first and ``n_steps``
    steps (even)."""
    # (each foot moves only in the middle 60 % of its window, so the windows are longer
    # than a plain sine step's: knees stay under 2.5 m/s)
    duration = (0.6 + 0.45 * abs(angle) / (np.pi / 2) + 1.5 * np.hypot(dx, dy)) * (
        1.0 + 0.2 * (n_steps - 2))
    n = round(duration * fps) + 1
    t = np.linspace(0.0, 1.0, n)
    s_root = _progress(t, 0.05, 0.95)
    heading = angle * s_root
    root_xy = np.stack([dx * s_root, dy * s_root], axis=-1)
    # The pelvis dips a little mid-step so the straight standing legs can reach.
    dip = (0.02 + 0.08 * np.hypot(dx, dy)) * np.sin(np.pi * s_root)
    body = _turned(heading, stand[None])                                 # (T, J, 3)
    body[:, :, :2] += root_xy[:, None, :]
    body[:, :, 2] -= dip[:, None]
    first, second = (lead, "r" if lead == "l" else "l")
    # One foot after the other, never both in the air; each lifts before it moves and
    # lands before the other lifts, so no foot slides over the floor.
    edges = np.linspace(0.05, 0.95, n_steps + 1)
    progress = {first: np.zeros(n), second: np.zeros(n)}
    up = {first: np.zeros(n), second: np.zeros(n)}
    for i in range(n_steps):
        side = first if i % 2 == 0 else second
        a, b = edges[i], edges[i + 1]
        k0 = (i // 2) / (n_steps // 2)
        k1 = (i // 2 + 1) / (n_steps // 2)
        s = _progress(t, a + _LIFT_LEAD * (b - a), b - _LIFT_LEAD * (b - a))
        progress[side] = np.where(t >= a, k0 + (k1 - k0) * s, progress[side])
        up[side] += np.sin(np.pi * np.clip((t - a) / (b - a), 0.0, 1.0)) ** 2
    for side in (first, second):
        s = progress[side]
        foot_yaw = angle * s
        for name in _FOOT[side]:
            j = JOINT_INDEX[name]
            body[:, j] = _turned(foot_yaw, stand[None, None, j])[:, 0]
            body[:, j, 0] += dx * s
            body[:, j, 1] += dy * s
            body[:, j, 2] += lift * up[side]
        hip, knee, ankle = (JOINT_INDEX[f"{side}_{x}"] for x in ("hip", "knee", "ankle"))
        l1 = float(np.linalg.norm(stand[knee] - stand[hip]))
        l2 = float(np.linalg.norm(stand[ankle] - stand[knee]))
        pole = np.stack([np.cos(foot_yaw), np.sin(foot_yaw), np.zeros(n)], axis=-1)
        body[:, knee], body[:, ankle] = two_bone_ik(body[:, hip], body[:, ankle], l1, l2,
                                                     pole, max_stretch=1.0)
    body[:, :, :2] -= root_xy[:, None, :]
    body[:, :, 2] += dip[:, None]
    poses = _arms_clear_of_thighs(_turned(heading, body, inverse=True), skeleton, fps)
    root = np.zeros((n, 4))
    root[:, :2] = root_xy
    root[:, 2] = height - dip
    root[:, 3] = heading
    deg = round(np.degrees(angle))
    name = (f"{task}_turn_{deg:+d}" if dx == 0 and dy == 0 else
            f"{task}_step_{dx:+.2f}_{dy:+.2f}_{deg:+d}")
    return MotionPrimitive(name=name, task=task, poses=poses, root=root, fps=fps,
                           source=f"planner: step ({dx:+.2f}, {dy:+.2f}) m, turn {deg} deg",
                           meta={"turn": float(angle), "step": [float(dx), float(dy)]})


def make_turn_primitive(stand: np.ndarray, height: float, angle: float, skeleton: Skeleton,
                        fps: float, task: str = "walk", lift: float = 0.06) -> MotionPrimitive:
    """Turn on the spot by ``angle`` radians (see :func:`make_step_primitive`)."""
    return make_step_primitive(stand, height, 0.0, 0.0, angle, skeleton, fps, task, lift)


def turn_primitives(library) -> list[MotionPrimitive]:
    """Turns and steps on the spot for walking and carrying on the library's body."""
    out = []
    for task, stand in (("walk", library.standing_pose), ("carry", library.carry_standing_pose)):
        for deg in TURN_ANGLES_DEG:
            out.append(make_turn_primitive(stand, library.standing_height, np.radians(deg),
                                           library.skeleton, library.fps, task))
        for dx, dy, deg in STEPS:
            out.append(make_step_primitive(stand, library.standing_height, dx, dy,
                                           np.radians(deg), library.skeleton, library.fps, task))
    return out
