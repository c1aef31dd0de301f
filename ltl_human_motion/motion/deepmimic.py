"""DeepMimic motion clips (JSON text, as shipped in ``pybullet_data/data/motions``).

File layout: ``{"Loop": "wrap"|"none", "Frames": [[...], ...]}``; each frame holds 44
numbers: the frame duration (s), the root position (3), the root orientation as a
quaternion in (w, x, y, z) order (checked against pybullet's own
``humanoid_pose_interpolator``, which reorders ``frame[5:8] + frame[4]`` to pybullet's
x, y, z, w), then the joint rotations of the humanoid ``humanoid/humanoid.urdf`` in this
order: chest, neck, right hip (4 each, quaternions w, x, y, z), right knee (1 angle),
right ankle, right shoulder (4 each), right elbow (1), left hip (4), left knee (1),
left ankle, left shoulder (4 each), left elbow (1). Knees and elbows turn about the
joint's local z axis. The clips are y up with x forward and z to the right; they are
converted to our z up frame by ``(x, y, z) -> (x, -z, y)``.

The joint offsets come from the URDF (its geometry is 4x the clip scale; DeepMimic loads
it with ``globalScaling=0.25``). :func:`load` returns the motion retargeted onto the
canonical skeleton.
"""

from __future__ import annotations

import json
import os
import re
from functools import lru_cache
from pathlib import Path

import numpy as np

from ltl_human_motion.errors import MissingDependencyError, MotionFormatError
from ltl_human_motion.kernel.rotations import (
    ZUP_FROM_YUP,
    matrix_from_axis_angle,
    matrix_from_quaternion,
)
from ltl_human_motion.motion.retarget import retarget_points
from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.motion.types import Motion

__all__ = ["DEFAULT_GAIT_CLIPS", "FRAME_SIZE", "load", "load_raw", "motions_dir", "urdf_path"]

FRAME_SIZE = 44
URDF_SCALE = 0.25
# (name, parent, kind, slice into the frame)
_LAYOUT = (
    ("chest", "root", "sphere", 8),
    ("neck", "chest", "sphere", 12),
    ("right_hip", "root", "sphere", 16),
    ("right_knee", "right_hip", "revolute", 20),
    ("right_ankle", "right_knee", "sphere", 21),
    ("right_shoulder", "chest", "sphere", 25),
    ("right_elbow", "right_shoulder", "revolute", 29),
    ("left_hip", "root", "sphere", 30),
    ("left_knee", "left_hip", "revolute", 34),
    ("left_ankle", "left_knee", "sphere", 35),
    ("left_shoulder", "chest", "sphere", 39),
    ("left_elbow", "left_shoulder", "revolute", 43),
)
# Extra points in a link's local frame (URDF units): the wrist and the derived head, hand
# and toe.
_EXTRA = {
    "head": ("neck", (0.08, 0.70, 0.0)),
    "right_wrist": ("right_elbow", (0.0, -1.035788, 0.0)),
    "left_wrist": ("left_elbow", (0.0, -1.035788, 0.0)),
    "right_hand": ("right_elbow", (0.0, -1.035788 - 0.40, 0.0)),
    "left_hand": ("left_elbow", (0.0, -1.035788 - 0.40, 0.0)),
    "right_toe": ("right_ankle", (0.44, -0.12, 0.0)),
    "left_toe": ("left_ankle", (0.44, -0.12, 0.0)),
}
_CANONICAL = {
    "pelvis": "root", "chest": "chest", "neck": "neck", "head": "head",
    "l_shoulder": "left_shoulder", "l_elbow": "left_elbow", "l_wrist": "left_wrist",
    "l_hand": "left_hand", "r_shoulder": "right_shoulder", "r_elbow": "right_elbow",
    "r_wrist": "right_wrist", "r_hand": "right_hand", "l_hip": "left_hip", "l_knee": "left_knee",
    "l_ankle": "left_ankle", "l_toe": "left_toe", "r_hip": "right_hip", "r_knee": "right_knee",
    "r_ankle": "right_ankle", "r_toe": "right_toe",
}
# Looping gait clips used by the default library (paths relative to motions_dir()).
DEFAULT_GAIT_CLIPS: tuple[str, ...] = (
    "walker/0walk_forward.txt", "walker/turn_left0.txt", "walker/turn_left1.txt",
    "walker/turn_right0.txt", "walker/turn_right1.txt", "humanoid3d_walk.txt",
)


def _data_path() -> Path:
    try:
        import pybullet_data
    except ImportError as exc:  # pragma: no cover - pybullet is a dependency here
        raise MissingDependencyError(
            "the DeepMimic clips come with pybullet: pip install pybullet") from exc
    return Path(pybullet_data.getDataPath())


def motions_dir() -> Path:
    """Folder of the DeepMimic clips shipped with pybullet (``pybullet_data/data/motions``)."""
    return _data_path() / "data" / "motions"


def urdf_path() -> Path:
    """The DeepMimic humanoid body model (``pybullet_data/humanoid/humanoid.urdf``)."""
    return _data_path() / "humanoid" / "humanoid.urdf"


@lru_cache(maxsize=4)
def _joint_offsets(urdf: str) -> dict[str, np.ndarray]:
    """Joint origins (URDF units, parent frame) keyed by joint name."""
    try:
        text = Path(urdf).read_bytes().decode("latin-1")
    except OSError as exc:
        raise MotionFormatError(f"{urdf}: cannot read the DeepMimic body model: {exc}") from exc
    offsets: dict[str, np.ndarray] = {}
    for m in re.finditer(r'<joint\s+name\s*=\s*"(\w+)"[^>]*>(.*?)</joint>', text, re.S):
        o = re.search(r'<origin[^>]*xyz\s*=\s*"([^"]+)"', m.group(2))
        if o:
            offsets[m.group(1)] = np.array([float(v) for v in o.group(1).split()])
    needed = [n for n, *_ in _LAYOUT]
    missing = [n for n in needed if n not in offsets]
    if missing:
        raise MotionFormatError(f"{urdf}: body model lacks joints {', '.join(missing)}")
    return offsets


def _read_frames(path: Path) -> tuple[np.ndarray, bool]:
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise MotionFormatError(f"{path}: cannot read DeepMimic clip: {exc}") from exc
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise MotionFormatError(
            f"{path}: line {exc.lineno}: not valid DeepMimic JSON ({exc.msg})") from exc
    if not isinstance(data, dict) or not isinstance(data.get("Frames"), list):
        raise MotionFormatError(f"{path}: expected a JSON object with a 'Frames' list")
    frames = data["Frames"]
    if len(frames) < 2:
        raise MotionFormatError(f"{path}: needs at least 2 frames, found {len(frames)}")
    for i, f in enumerate(frames):
        if not isinstance(f, list) or len(f) != FRAME_SIZE:
            n = len(f) if isinstance(f, list) else type(f).__name__
            raise MotionFormatError(
                f"{path}: frame {i}: expected {FRAME_SIZE} numbers, found {n}")
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in f):
            raise MotionFormatError(f"{path}: frame {i}: contains a value that is not a number")
    arr = np.asarray(frames, dtype=np.float64)
    bad = np.nonzero(~np.all(np.isfinite(arr), axis=1))[0]
    if bad.size:
        raise MotionFormatError(f"{path}: frame {int(bad[0])}: NaN or infinite value")
    for off in (4, 8, 12, 16, 21, 25, 30, 35, 39):
        norms = np.linalg.norm(arr[:, off:off + 4], axis=1)
        if np.any(norms < 1e-6):
            raise MotionFormatError(
                f"{path}: frame {int(np.argmax(norms < 1e-6))}: quaternion of zero length")
    # the last frame of a clip may carry duration 0 (it only closes the loop)
    if np.any(arr[:-1, 0] <= 0) or arr[-1, 0] < 0:
        bad_t = np.nonzero(np.concatenate([arr[:-1, 0] <= 0, [arr[-1, 0] < 0]]))[0]
        raise MotionFormatError(
            f"{path}: frame {int(bad_t[0])}: frame duration must be positive")
    loop = str(data.get("Loop", "none")).lower() == "wrap"
    return arr, loop


def load_raw(path: str | os.PathLike[str]) -> tuple[dict[str, np.ndarray], float, bool]:
    """Forward kinematics of a DeepMimic clip in the source body (z up, metres).

    Parameters
    ----------
    path : path-like

    Returns
    -------
    points : dict of str to ndarray, shape (T, 3)
        World positions of the DeepMimic joints plus derived ``head``, ``*_wrist``,
        ``*_hand`` and ``*_toe`` points, keyed by DeepMimic link name.
    fps : float
        From the first frame's duration.
    loop : bool
        True when the clip is marked ``"Loop": "wrap"``.
    """
    path = Path(path)
    arr, loop = _read_frames(path)
    offsets = _joint_offsets(str(urdf_path()))
    rot: dict[str, np.ndarray] = {"root": matrix_from_quaternion(arr[:, 4:8])}
    pos: dict[str, np.ndarray] = {"root": arr[:, 1:4].copy()}
    z_axis = np.array([0.0, 0.0, 1.0])
    for name, parent, kind, k in _LAYOUT:
        local = (matrix_from_quaternion(arr[:, k:k + 4]) if kind == "sphere"
                 else matrix_from_axis_angle(z_axis, arr[:, k]))
        pos[name] = pos[parent] + rot[parent] @ (offsets[name] * URDF_SCALE)
        rot[name] = rot[parent] @ local
    for name, (link, local_xyz) in _EXTRA.items():
        pos[name] = pos[link] + rot[link] @ (np.asarray(local_xyz) * URDF_SCALE)
    points = {k: v @ ZUP_FROM_YUP.T for k, v in pos.items()}
    fps = 1.0 / float(arr[0, 0])
    return points, fps, loop


def load(path: str | os.PathLike[str], skeleton: Skeleton | None = None) -> Motion:
    """Load a DeepMimic clip retargeted onto the canonical skeleton.

    Parameters
    ----------
    path : path-like
        A DeepMimic motion file (e.g. ``motions_dir() / "walker/0walk_forward.txt"``).
    skeleton : Skeleton, optional
        Target body size (default 1.75 m).

    Returns
    -------
    Motion
        World positions (z up), at the clip's frame rate; ``Motion.name`` is the file stem.
        Whether the clip loops is available from :func:`load_raw`.

    Raises
    ------
    MotionFormatError
        The file is not a valid DeepMimic clip (the message names the file and frame).
    """
    points, fps, _ = load_raw(path)
    canon = {c: points[s] for c, s in _CANONICAL.items()}
    return retarget_points(canon, fps, skeleton, name=Path(path).stem)
