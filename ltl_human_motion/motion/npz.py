"""Plain ``.npz`` files of canonical-skeleton joint positions.

Layout: ``positions`` (T, J, 3) float, metres, Z up; ``fps`` (scalar); optional
``stature`` (scalar, metres), ``joint_names`` (J,) str and ``name`` (scalar str). Files
written by :func:`save` load back exactly. A file whose joints are named differently (or
whose stature differs from the requested skeleton) is retargeted by name.
"""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import numpy as np

from ltl_human_motion.atomic import atomic_write_with
from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.motion.retarget import retarget_points
from ltl_human_motion.motion.skeleton import JOINT_NAMES, Skeleton
from ltl_human_motion.motion.types import Motion

__all__ = ["load", "save"]


def save(motion: Motion, path: str | os.PathLike[str]) -> None:
    """Write ``motion`` as ``.npz`` (atomically)."""
    if not isinstance(motion, Motion):
        raise ValueError(f"motion must be a Motion, got {type(motion).__name__}")

    def writer(fh) -> None:
        np.savez(fh, positions=motion.positions, fps=np.float64(motion.fps),
                 stature=np.float64(motion.skeleton.stature),
                 joint_names=np.array(JOINT_NAMES), name=np.array(motion.name))

    atomic_write_with(path, writer)


def load(path: str | os.PathLike[str], skeleton: Skeleton | None = None) -> Motion:
    """Load an ``.npz`` of joint positions.

    Parameters
    ----------
    path : path-like
    skeleton : Skeleton, optional
        Target body; default: the file's stature (or 1.75 m).

    Raises
    ------
    MotionFormatError
        Not an npz, missing arrays, wrong shapes or non-finite values.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise MotionFormatError(f"{path}: not a readable .npz file ({exc})") from None
    for key in ("positions", "fps"):
        if key not in arrays:
            raise MotionFormatError(f"{path}: missing array {key!r}")
    pos = np.asarray(arrays["positions"], dtype=np.float64)
    if pos.ndim != 3 or pos.shape[2] != 3 or pos.shape[0] < 1:
        raise MotionFormatError(f"{path}: 'positions' must have shape (T, J, 3), got {pos.shape}")
    bad = np.nonzero(~np.all(np.isfinite(pos), axis=(1, 2)))[0]
    if bad.size:
        raise MotionFormatError(f"{path}: frame {int(bad[0])}: NaN or infinite value")
    fps = float(arrays["fps"])
    if not fps > 0:
        raise MotionFormatError(f"{path}: fps must be positive, got {fps}")
    names = tuple(str(n) for n in arrays["joint_names"]) if "joint_names" in arrays \
        else JOINT_NAMES[:pos.shape[1]]
    if len(names) != pos.shape[1]:
        raise MotionFormatError(f"{path}: {len(names)} joint names for {pos.shape[1]} joints")
    stature = float(arrays["stature"]) if "stature" in arrays else 1.75
    name = str(arrays["name"]) if "name" in arrays else path.stem
    if skeleton is None:
        try:
            skeleton = Skeleton(stature)
        except ValueError as exc:
            raise MotionFormatError(f"{path}: {exc}") from None
    if names == JOINT_NAMES and abs(stature - skeleton.stature) < 1e-9:
        return Motion(pos, fps, skeleton, name)
    points = {n: pos[:, i] for i, n in enumerate(names)}
    try:
        return retarget_points(points, fps, skeleton, name=name)
    except ValueError as exc:
        raise MotionFormatError(f"{path}: {exc}") from None
