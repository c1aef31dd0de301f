"""Realism metrics of a motion, and their comparison with real motion capture.

For a motion on the canonical skeleton (world positions (T, J, 3), z up) the samples of
six distributions are measured:

* ``hand_speed``, ``knee_speed``, ``foot_speed`` (m/s): joint speeds over 1/30 s
  (:func:`~ltl_human_motion.motion.biomechanics.joint_speeds`);
* ``knee_angle``, ``hip_angle``, ``elbow_angle``, ``trunk_angle`` (deg): knee, hip and
  elbow flexion and trunk flexion (:func:`~ltl_human_motion.motion.biomechanics.
  joint_angles`);
* ``hand_jerk`` (m/s^3): magnitude of the third derivative of the palm positions
  (central differences on a 30 Hz resampling, so mocap noise at 120 Hz does not dominate);
* ``step_length`` (m) and ``cadence`` (steps/min): from foot strikes (a foot joint coming
  down within the contact height of its rest height after a swing), the distance between
  the feet at each strike and the interval between consecutive strikes of opposite feet;
* ``foot_skate`` (m/s): horizontal speed of each foot's contact point over its contact
  frames (the MOJO samples, :func:`~ltl_human_motion.motion.biomechanics.foot_skate`).

:func:`compare` gives, per metric, summary statistics of ours and of the real data and
the 1-Wasserstein distance between the two distributions (``scipy.stats.
wasserstein_distance``, in the metric's unit): 0 when they are the same distribution.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable

import numpy as np

from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX

__all__ = ["CMU_BVH_DIR", "METRICS", "compare", "motion_samples", "real_clip_samples",
           "real_sources", "realism_summary", "summary"]

#: Genuine CMU BVH takes installed by Debian's assimp-testmodels.
CMU_BVH_DIR = "/usr/share/assimp/models/BVH"

_J = JOINT_INDEX
METRICS: tuple[str, ...] = ("hand_speed", "knee_speed", "foot_speed", "knee_angle",
                            "hip_angle", "elbow_angle", "trunk_angle", "hand_jerk",
                            "step_length", "cadence", "foot_skate")
_UNITS = {"hand_speed": "m/s", "knee_speed": "m/s", "foot_speed": "m/s", "knee_angle": "deg",
          "hip_angle": "deg", "elbow_angle": "deg", "trunk_angle": "deg",
          "hand_jerk": "m/s^3", "step_length": "m", "cadence": "steps/min",
          "foot_skate": "m/s"}
#: The joint angles the metrics sample (:func:`motion_samples`).
_ANGLES = ("l_knee_flexion", "r_knee_flexion", "l_hip_flexion", "r_hip_flexion",
           "l_elbow_flexion", "r_elbow_flexion", "trunk_flexion")
#: Shortest time between two strikes of opposite feet counted as steps, s (cadences over
#: 200 steps/min are running).
_MIN_STEP = 0.3
#: Longest such time, s (slower than 40 steps/min is standing, not walking).
_MAX_STEP = 1.5


def _strikes(p: np.ndarray, fps: float, stature: float, floor_z: float) -> list[tuple[int, int]]:
    """(frame, foot) of every foot strike, foot 0 = left, 1 = right, in time order."""
    from ltl_human_motion.motion.biomechanics import CONTACT_REST_HEIGHTS
    out = []
    for k, s in enumerate("lr"):
        idx = [_J[f"{s}_ankle"], _J[f"{s}_toe"]]
        h = (p[:, idx, 2] - floor_z - np.asarray(CONTACT_REST_HEIGHTS) * stature).min(axis=1)
        lifted = h >= 0.04
        # A strike is a foot-down frame whose last lifted-or-down frame before it was
        # lifted (the foot re-arms when lifted and strikes once when it comes down).
        events = np.flatnonzero(lifted | (h <= 0.02))
        up = lifted[events]
        out += [(int(t), k) for t in events[1:][up[:-1] & ~up[1:]]]
    return sorted(out)


def motion_samples(positions: np.ndarray, fps: float, stature: float = DEFAULT_STATURE,
                   floor_z: float = 0.0, frames: np.ndarray | None = None
                   ) -> dict[str, np.ndarray]:
    """Samples of every metric of :data:`METRICS` for one motion.

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)
    fps, stature, floor_z : float
    frames : ndarray of bool, shape (T,), optional
        Frames to measure speeds, angles, jerk and skate on (default all); gait metrics
        always use the whole motion.

    Returns
    -------
    dict of str to ndarray (1-D)
    """
    from ltl_human_motion.motion.biomechanics import foot_skate, joint_angles, joint_speeds
    p = np.asarray(positions, dtype=np.float64)
    T = len(p)
    sel = np.ones(T, dtype=bool) if frames is None else np.asarray(frames, dtype=bool)
    out: dict[str, np.ndarray] = {}
    v = joint_speeds(p, fps)
    vs = v[sel[:len(v)]] if len(v) else v
    out["hand_speed"] = vs[:, [_J["l_hand"], _J["r_hand"]]].ravel()
    out["knee_speed"] = vs[:, [_J["l_knee"], _J["r_knee"]]].ravel()
    out["foot_speed"] = vs[:, [_J["l_ankle"], _J["r_ankle"]]].ravel()
    ang = joint_angles(p, _ANGLES)
    out["knee_angle"] = np.concatenate([ang["l_knee_flexion"][sel], ang["r_knee_flexion"][sel]])
    out["hip_angle"] = np.concatenate([ang["l_hip_flexion"][sel], ang["r_hip_flexion"][sel]])
    out["elbow_angle"] = np.concatenate([ang["l_elbow_flexion"][sel],
                                         ang["r_elbow_flexion"][sel]])
    out["trunk_angle"] = ang["trunk_flexion"][sel]
    step = max(1, round(fps / 30.0))
    hands = p[::step][:, [_J["l_hand"], _J["r_hand"]]]
    keep = sel[::step]
    if len(hands) >= 4:
        dt = step / fps
        jerk = np.diff(hands, n=3, axis=0) / dt ** 3
        mag = np.linalg.norm(jerk, axis=-1)
        out["hand_jerk"] = mag[keep[3:]].ravel()
    else:
        out["hand_jerk"] = np.zeros(0)
    strikes = _strikes(p, fps, stature, floor_z)
    lengths, cadences = [], []
    for (t0, f0), (t1, f1) in itertools.pairwise(strikes):
        dt = (t1 - t0) / fps
        if f0 != f1 and _MIN_STEP <= dt <= _MAX_STEP:
            a, b = p[t1, _J["l_ankle"], :2], p[t1, _J["r_ankle"], :2]
            lengths.append(float(np.linalg.norm(a - b)))
            cadences.append(60.0 / dt)
    out["step_length"] = np.array(lengths)
    out["cadence"] = np.array(cadences)
    _, speed, grounded = foot_skate(p, fps, stature, floor_z)
    g = grounded & sel[1:, None] if len(speed) else grounded
    out["foot_skate"] = speed[g] if len(speed) else np.zeros(0)
    return out


def summary(samples: np.ndarray) -> dict:
    """n, mean, median, 5th and 95th percentile, max of 1-D samples (None when empty)."""
    x = np.asarray(samples, dtype=np.float64)
    if x.size == 0:
        return {"n": 0, "mean": None, "p5": None, "median": None, "p95": None, "max": None}
    p5, p95 = np.percentile(x, [5, 95])
    return {"n": int(x.size), "mean": float(x.mean()), "p5": float(p5),
            "median": float(np.median(x)), "p95": float(p95), "max": float(x.max())}


def compare(ours: Iterable[dict[str, np.ndarray]], real: Iterable[dict[str, np.ndarray]]
            ) -> dict[str, dict]:
    """Per metric: summaries of ours and of the real samples and the 1-Wasserstein
    distance between them (None when either side has no sample)."""
    from scipy.stats import wasserstein_distance
    ours, real = list(ours), list(real)
    out = {}
    for m in METRICS:
        a = np.concatenate([s[m] for s in ours if m in s] or [np.zeros(0)])
        b = np.concatenate([s[m] for s in real if m in s] or [np.zeros(0)])
        a, b = a[np.isfinite(a)], b[np.isfinite(b)]
        dist = float(wasserstein_distance(a, b)) if a.size and b.size else None
        out[m] = {"unit": _UNITS[m], "ours": summary(a), "real": summary(b),
                  "wasserstein": dist}
    return out


def real_sources(extra: Iterable[str] = ()) -> list[tuple[str, str]]:
    """(kind, path) of the real clips installed here: the DeepMimic gait clips of
    pybullet (``"deepmimic"``), the CMU BVH takes (``"cmu_bvh"``), and every BVH, AMC or
    DeepMimic file under the ``extra`` folders or files (``"user"``)."""
    from pathlib import Path

    from ltl_human_motion.motion import deepmimic
    out = [("deepmimic", str(deepmimic.motions_dir() / c)) for c in deepmimic.DEFAULT_GAIT_CLIPS]
    out += [("cmu_bvh", str(p)) for p in sorted(Path(CMU_BVH_DIR).glob("*.bvh"))]
    for src in extra:
        root = Path(src)
        files = sorted(root.rglob("*")) if root.is_dir() else [root]
        out += [("user", str(f)) for f in files if f.suffix.lower() in (".bvh", ".amc", ".txt")]
    return out


def real_clip_samples(kind: str, path: str, stature: float = DEFAULT_STATURE
                      ) -> dict[str, np.ndarray]:
    """:func:`motion_samples` of one real clip retargeted onto the canonical skeleton.

    DeepMimic gait loops are measured as the gait library prepares them (seamless, 120
    Hz); every clip is stood on the floor at its lowest foot joint, and the first 0.1 s
    of a BVH / AMC take (often a T-pose snapping into the take) is skipped.
    """
    from ltl_human_motion.motion.gait import clip_motion, prepare_loop
    from ltl_human_motion.motion.library import load_motion
    from ltl_human_motion.motion.skeleton import Skeleton
    sk = Skeleton(stature)
    m = load_motion(path, sk)
    if kind == "deepmimic":
        m = clip_motion(prepare_loop(m, str(path), str(path)), sk)
    p = m.positions.copy()
    feet = [_J[n] for n in ("l_ankle", "l_toe", "r_ankle", "r_toe")]
    rest = sk.rest_positions()[feet, 2]
    p[..., 2] -= float((p[:, feet, 2] - rest).min())
    trim = round(0.1 * m.fps) if kind != "deepmimic" else 0
    return motion_samples(p[trim:], m.fps, stature)


def realism_summary(positions: np.ndarray, fps: float, stature: float = DEFAULT_STATURE,
                    floor_z: float = 0.0) -> dict[str, dict]:
    """:func:`summary` of every metric of one motion (what a synthesized motion's
    ``stats["realism"]`` and a dataset item's ``realism`` record hold)."""
    samples = motion_samples(positions, fps, stature, floor_z)
    return {m: summary(samples[m]) for m in METRICS}
