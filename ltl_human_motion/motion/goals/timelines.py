"""Minimum-jerk timelines of the goal models, and the finished primitive.

Piecewise minimum-jerk interpolation (Flash & Hogan 1985) of scalars, arrays and
shoulder-to-palm vectors (an arc about the shoulder), the frame count of a duration, and
:func:`_finish`, which blends the model's residual against the start pose in at the ends
and builds the :class:`~ltl_human_motion.motion.types.MotionPrimitive`.
"""

from __future__ import annotations

import itertools

import numpy as np

from ltl_human_motion.motion.goals.body import _Start
from ltl_human_motion.motion.ik import min_jerk
from ltl_human_motion.motion.ops import relative_root
from ltl_human_motion.motion.types import MotionPrimitive


def _profile(t: np.ndarray, keys: list[tuple[float, float]]) -> np.ndarray:
    """Piecewise minimum-jerk interpolation of scalar key values ``[(time, value), ...]``."""
    out = np.full_like(t, keys[0][1], dtype=np.float64)
    for (t0, v0), (t1, v1) in itertools.pairwise(keys):
        if t1 <= t0:
            continue
        m = (t >= t0) & (t <= t1)
        out[m] = v0 + (v1 - v0) * min_jerk((t[m] - t0) / (t1 - t0))
    out[t > keys[-1][0]] = keys[-1][1]
    return out


def _interp_keys(t: np.ndarray, keys: list[tuple[float, np.ndarray]]) -> np.ndarray:
    """Piecewise minimum-jerk interpolation of array key values (same shapes)."""
    first = np.asarray(keys[0][1], dtype=np.float64)
    out = np.broadcast_to(first, (t.size, *first.shape)).copy()
    for (t0, v0), (t1, v1) in itertools.pairwise(keys):
        if t1 <= t0:
            continue
        m = (t >= t0) & (t <= t1)
        s = min_jerk((t[m] - t0) / (t1 - t0)).reshape((-1,) + (1,) * first.ndim)
        out[m] = np.asarray(v0) + s * (np.asarray(v1) - np.asarray(v0))
    out[t > keys[-1][0]] = np.asarray(keys[-1][1])
    return out


def _arc_keys(t: np.ndarray, keys: list[tuple[float, np.ndarray]]) -> np.ndarray:
    """Like :func:`_interp_keys` for shoulder-to-palm vectors (..., 3): the direction is
    slerped and the length interpolated, so the palm swings in an arc about the shoulder
    (never through it), with the minimum-jerk timing."""
    first = np.asarray(keys[0][1], dtype=np.float64)
    out = np.broadcast_to(first, (t.size, *first.shape)).copy()
    for (t0, v0), (t1, v1) in itertools.pairwise(keys):
        if t1 <= t0:
            continue
        m = (t >= t0) & (t <= t1)
        s = min_jerk((t[m] - t0) / (t1 - t0)).reshape((-1,) + (1,) * (first.ndim - 1))[..., None]
        v0, v1 = np.asarray(v0, dtype=np.float64), np.asarray(v1, dtype=np.float64)
        n0 = np.linalg.norm(v0, axis=-1, keepdims=True)
        n1 = np.linalg.norm(v1, axis=-1, keepdims=True)
        u0, u1 = v0 / np.maximum(n0, 1e-9), v1 / np.maximum(n1, 1e-9)
        omega = np.arccos(np.clip(np.sum(u0 * u1, axis=-1, keepdims=True), -1.0, 1.0))
        so = np.sin(omega)
        small = so < 1e-6
        a = np.where(small, 1.0 - s, np.sin((1.0 - s) * omega) / np.where(small, 1.0, so))
        b = np.where(small, s, np.sin(s * omega) / np.where(small, 1.0, so))
        u = a * u0 + b * u1
        u /= np.maximum(np.linalg.norm(u, axis=-1, keepdims=True), 1e-12)
        out[m] = u * ((1.0 - s) * n0 + s * n1)
    out[t > keys[-1][0]] = np.asarray(keys[-1][1])
    return out


def _n_frames(total: float, fps: float) -> int:
    return round(total * fps) + 1


def _finish(name: str, task: str, world: np.ndarray, st: _Start, fps: float, source: str,
            meta: dict, start_exact: bool = True, end_exact: bool = True) -> MotionPrimitive:
    """Blend the model residual against ``start_pose`` in at the ends, build the primitive."""
    T = world.shape[0]
    t = np.arange(T) / fps
    ramp = 0.3
    corrected = world.copy()
    for exact, ref, w in ((start_exact, world[0], 1.0 - min_jerk(t / ramp)),
                          (end_exact, world[-1], 1.0 - min_jerk((t[-1] - t) / ramp))):
        if not exact:
            continue
        pose = st.pose.copy()
        pose[:, :2] += ref[0, :2] - pose[0, :2]
        residual = pose - ref
        if np.max(np.abs(residual)) > 0.0:
            corrected += w[:, None, None] * residual[None]
    world = corrected
    yaw = np.zeros(T)
    root = np.concatenate([world[:, 0, :], yaw[:, None]], axis=1)
    root = relative_root(root)
    root[:, :2] = world[:, 0, :2] - world[0, 0, :2]
    poses = world - world[:, :1, :]
    meta = dict(meta)
    meta.setdefault("kind", "goal")
    return MotionPrimitive(name=name, task=task, poses=poses, root=root, fps=fps,
                           source=source, meta=meta)
