"""Exports of a :class:`SynthesizedMotion`: NPZ (lossless, round trip), JSON, CSV, BVH.

Every file is written atomically (temporary file beside the target, then rename) and
deterministically: identical motions give identical bytes (the NPZ archive is written
with fixed entry order and fixed zip timestamps; JSON keys are sorted).

BVH files come from :func:`ltl_human_motion.motion.bvh.save` (:func:`save_bvh` unwraps a
:class:`SynthesizedMotion`); that module describes the file. :func:`bvh_rotations`, the
joints' world rotations, is :func:`ltl_human_motion.motion.bone_rotations.joint_rotations`
(kept here under its old name).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import zipfile
from typing import Any

import numpy as np

from ltl_human_motion.atomic import atomic_write_bytes, atomic_write_text
from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.motion import bvh
from ltl_human_motion.motion.bone_rotations import joint_rotations as bvh_rotations
from ltl_human_motion.motion.skeleton import JOINT_NAMES, Skeleton
from ltl_human_motion.motion.types import Motion
from ltl_human_motion.planning.result import SynthesisStats, SynthesizedMotion, TaskSegment

__all__ = [
    "FORMAT_NAME", "FORMAT_VERSION", "bvh_rotations", "from_dict", "load_json", "load_npz",
    "npz_bytes", "save", "save_bvh", "save_csv", "save_json", "save_npz", "to_dict",
]

FORMAT_NAME = "ltl_human_motion.synthesized_motion"
FORMAT_VERSION = 1
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)

PathLike = str | os.PathLike[str]


# --------------------------------------------------------------------------- dicts

def _plain(value: Any, finite_only: bool = False) -> Any:
    """Turn numpy values and containers into plain, JSON-ready Python."""
    if isinstance(value, dict):
        return {str(k): _plain(v, finite_only) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v, finite_only) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist(), finite_only)
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        v = float(value)
        return None if finite_only and not math.isfinite(v) else v
    if value is None or isinstance(value, str):
        return value
    return str(value)


def _is_timing(key: str) -> bool:
    return key.endswith("_time") or key in ("real_time_factor", "seconds")


def _meta(synth: SynthesizedMotion) -> dict[str, Any]:
    """Metadata stored with the motion; wall-clock timings are left out so that the same
    inputs give the same bytes (they stay in :func:`to_dict` / JSON)."""
    return {
        "format": FORMAT_NAME, "version": FORMAT_VERSION,
        "name": synth.motion.name, "fps": float(synth.fps),
        "stature": float(synth.motion.skeleton.stature),
        "joint_names": list(synth.motion.skeleton.names),
        "spec": synth.spec, "sequence": list(synth.sequence), "seed": synth.seed,
        "stats": {k: v for k, v in synth.stats.to_dict().items() if not _is_timing(k)},
        "verification": synth.verification,
        "timeline": [seg.to_dict() for seg in synth.timeline],
        "objects": sorted(synth.objects),
    }


def to_dict(synth: SynthesizedMotion, finite_only: bool = True) -> dict[str, Any]:
    """Everything in plain Python (lists of floats), e.g. for JSON.

    Non-finite floats in ``stats``/``verification`` become None when ``finite_only``.
    """
    d = _meta(synth)
    d["stats"] = synth.stats.to_dict()
    d["positions"] = synth.positions.tolist()
    d["root_yaw"] = synth.root_yaw.tolist()
    d["task_index"] = synth.task_index.tolist()
    d["objects"] = {name: synth.objects[name].tolist() for name in sorted(synth.objects)}
    return _plain(d, finite_only)


def from_dict(data: dict[str, Any], source: str = "<dict>") -> SynthesizedMotion:
    """Inverse of :func:`to_dict`; MotionFormatError names ``source`` on bad input."""
    try:
        if data.get("format") != FORMAT_NAME:
            raise MotionFormatError(f"{source}: not a synthesized motion (format "
                                    f"{data.get('format')!r})")
        if int(data.get("version", 0)) > FORMAT_VERSION:
            raise MotionFormatError(f"{source}: format version {data['version']} is newer than "
                                    f"{FORMAT_VERSION}")
        names = tuple(data["joint_names"])
        if names != JOINT_NAMES:
            raise MotionFormatError(f"{source}: joints {names[:3]}... are not the canonical "
                                    "skeleton")
        skeleton = Skeleton(stature=float(data["stature"]))
        motion = Motion(np.asarray(data["positions"], dtype=np.float64), float(data["fps"]),
                        skeleton, data.get("name", ""))
        objects = data.get("objects", {})
        return SynthesizedMotion(
            motion=motion,
            root_yaw=np.asarray(data["root_yaw"], dtype=np.float64),
            task_index=np.asarray(data["task_index"], dtype=np.int64),
            timeline=[TaskSegment.from_dict(s) for s in data.get("timeline", [])],
            objects={k: np.asarray(v, dtype=np.float64) for k, v in objects.items()},
            spec=data.get("spec", ""), sequence=list(data.get("sequence", [])),
            seed=int(data.get("seed", 0)),
            stats=SynthesisStats.from_dict(dict(data.get("stats", {}))),
            verification=dict(data.get("verification", {})))
    except MotionFormatError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise MotionFormatError(f"{source}: malformed synthesized motion: {exc}") from exc


# --------------------------------------------------------------------------- NPZ

def _npy_bytes(arr: np.ndarray) -> bytes:
    buf = io.BytesIO()
    arr = np.asarray(arr)
    if arr.ndim and not arr.flags.c_contiguous:
        arr = np.ascontiguousarray(arr)          # (keeps 0-d arrays 0-d)
    np.lib.format.write_array(buf, arr, allow_pickle=False)
    return buf.getvalue()


def npz_bytes(synth: SynthesizedMotion) -> bytes:
    """The bytes of the deterministic archive :func:`save_npz` writes."""
    names = sorted(synth.objects)
    objects = (np.stack([synth.objects[n] for n in names]) if names
               else np.zeros((0, synth.n_frames, 3)))
    meta = json.dumps(_plain(_meta(synth)), sort_keys=True, allow_nan=True)
    entries = [("meta", np.array(meta)), ("positions", synth.positions),
               ("root_yaw", synth.root_yaw), ("task_index", synth.task_index),
               ("objects", objects)]
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name, arr in entries:
            info = zipfile.ZipInfo(f"{name}.npy", date_time=_ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, _npy_bytes(np.asarray(arr)))
    return buf.getvalue()


def save_npz(synth: SynthesizedMotion, path: PathLike) -> None:
    """Write a lossless, deterministic ``.npz`` (read back with :func:`load_npz`).

    Entries: ``meta`` (a JSON string with everything but the arrays), ``positions``
    (T, J, 3), ``root_yaw`` (T,), ``task_index`` (T,) and ``objects`` (N, T, 3) in the
    order of ``meta["objects"]`` (sorted names). No pickles; fixed zip timestamps.
    """
    atomic_write_bytes(path, npz_bytes(synth))


def load_npz(path: PathLike) -> SynthesizedMotion:
    """Read a file written by :func:`save_npz`.

    Raises
    ------
    MotionFormatError
        Unreadable or malformed file (the message names it).
    """
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"].reshape(-1)[0]))
            objects = z["objects"]
            data = dict(meta)
            data["positions"] = z["positions"]
            data["root_yaw"] = z["root_yaw"]
            data["task_index"] = z["task_index"]
    except (OSError, KeyError, ValueError, zipfile.BadZipFile) as exc:
        raise MotionFormatError(f"{path}: cannot read synthesized motion: {exc}") from exc
    names = meta.get("objects", [])
    if objects.shape[0] != len(names):
        raise MotionFormatError(f"{path}: {objects.shape[0]} object trajectories for "
                                f"{len(names)} names")
    data["objects"] = {n: objects[i] for i, n in enumerate(names)}
    return from_dict(data, source=str(path))


# --------------------------------------------------------------------------- JSON / CSV

def save_json(synth: SynthesizedMotion, path: PathLike, indent: int | None = None) -> None:
    """Write everything as standard JSON (non-finite stats become null), sorted keys."""
    atomic_write_text(path, json.dumps(to_dict(synth), sort_keys=True, indent=indent,
                                       allow_nan=False) + "\n")


def load_json(path: PathLike) -> SynthesizedMotion:
    """Read a file written by :func:`save_json`."""
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError) as exc:
        raise MotionFormatError(f"{path}: cannot read JSON motion: {exc}") from exc
    if not isinstance(data, dict):
        raise MotionFormatError(f"{path}: expected a JSON object")
    return from_dict(data, source=str(path))


def save_csv(synth: SynthesizedMotion, path: PathLike, precision: int = 6) -> None:
    """One row per frame: frame, time, task_index, task, root_yaw, joints, objects.

    Joint columns are ``<joint>_x``, ``<joint>_y``, ``<joint>_z`` (metres, z up); object
    columns ``<object>_x`` etc. ``task`` is empty between tasks.
    """
    names = sorted(synth.objects)
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    header = ["frame", "time", "task_index", "task", "root_yaw"]
    header += [f"{j}_{a}" for j in synth.motion.skeleton.names for a in "xyz"]
    header += [f"{o}_{a}" for o in names for a in "xyz"]
    writer.writerow(header)
    fmt = f"{{:.{int(precision)}f}}"
    pos = synth.positions.reshape(synth.n_frames, -1)
    obj = (np.concatenate([synth.objects[n] for n in names], axis=1) if names
           else np.zeros((synth.n_frames, 0)))
    for t in range(synth.n_frames):
        task = synth.active_task(t) or ""
        row = [str(t), fmt.format(t / synth.fps), str(int(synth.task_index[t])), task,
               fmt.format(synth.root_yaw[t])]
        row += [fmt.format(v) for v in pos[t]]
        row += [fmt.format(v) for v in obj[t]]
        writer.writerow(row)
    atomic_write_text(path, buf.getvalue())


# --------------------------------------------------------------------------- BVH

def save_bvh(motion: SynthesizedMotion | Motion, path: PathLike, up: str = "y",
             scale: float = 1.0, translations: bool = False) -> float:
    """Write a BVH file of a motion with :func:`ltl_human_motion.motion.bvh.save` (same
    arguments; returns the largest reconstruction error, metres)."""
    m = motion.motion if isinstance(motion, SynthesizedMotion) else motion
    if not isinstance(m, Motion):
        raise ValueError(f"expected a SynthesizedMotion or Motion, got {type(motion).__name__}")
    return bvh.save(m, path, up=up, scale=scale, translations=translations)


# --------------------------------------------------------------------------- dispatch

_WRITERS = {".npz": save_npz, ".json": save_json, ".csv": save_csv, ".bvh": save_bvh}


def save(synth: SynthesizedMotion, path: PathLike) -> None:
    """Write ``synth`` in the format named by the file suffix (npz, json, csv, bvh)."""
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    try:
        writer = _WRITERS[suffix]
    except KeyError:
        raise ValueError(f"unknown export format {suffix!r}; expected one of "
                         f"{', '.join(sorted(_WRITERS))}") from None
    writer(synth, path)
