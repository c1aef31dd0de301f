"""Exports of a :class:`SynthesizedMotion`: NPZ (lossless, round trip), JSON, CSV, BVH.

Every file is written atomically (temporary file beside the target, then rename) and
deterministically: identical motions give identical bytes (the NPZ archive is written
with fixed entry order and fixed zip timestamps; JSON keys are sorted).

BVH
---
The hierarchy is the canonical skeleton (:mod:`ltl_human_motion.motion.skeleton`) with
its rest pose as offsets: 23 ``JOINT`` entries (the root ``pelvis`` has six channels
``Xposition Yposition Zposition Zrotation Yrotation Xrotation``, every other joint three
``Zrotation Yrotation Xrotation``; R = Rz · Ry · Rx, angles in degrees) and an
``End Site`` after each leaf (head, hands, toes). Units are metres (``scale`` changes
them). By default the file follows the motion-capture convention, **y up with the
character facing +z** and its left at +x: ``(x, y, z)_ours -> (y, z, x)_bvh``, the
inverse of what :mod:`ltl_human_motion.motion.bvh` applies when loading, so exported
files load back with it. Blender's importer (default axes: forward -Z, up Y) shows the
worker standing on its floor, facing -Y (towards the front view), i.e. our frame turned
by -90 degrees about the vertical. ``up="z"`` writes our frame unchanged (z up, facing
+x; import into Blender with forward Y, up Z).

Joint rotations are derived from positions: a joint with several children (pelvis,
chest) gets the rotation that best maps its rest child offsets onto the current ones
(Kabsch); a joint with one child gets the swing that turns its parent-rotated rest bone
onto the current bone, plus a twist about the bone that aligns a reference direction
(legs: the foot, spine: the shoulder line); leaves keep their parent's rotation. With
rigid bone lengths the BVH reproduces the joint positions exactly;
:func:`save_bvh` returns the largest reconstruction error. Motions that are not rigid
(stretching bones, a deforming pelvis) can be written exactly with
``translations=True``, which adds per-joint position channels (displacements from the
rest offsets, which Blender imports as bone locations).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import warnings
import zipfile
from typing import Any

import numpy as np

from ltl_human_motion.atomic import atomic_write_bytes, atomic_write_text
from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.kernel.rotations import MOCAP_FROM_ZUP, matrix_from_unit_axis_angle
from ltl_human_motion.motion.skeleton import JOINT_INDEX, JOINT_NAMES, PARENTS, Skeleton
from ltl_human_motion.motion.types import Motion
from ltl_human_motion.planning.result import SynthesizedMotion, TaskSegment

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
        "stats": {k: v for k, v in synth.stats.items() if not _is_timing(k)},
        "verification": synth.verification,
        "timeline": [seg.to_dict() for seg in synth.timeline],
        "objects": sorted(synth.objects),
    }


def to_dict(synth: SynthesizedMotion, finite_only: bool = True) -> dict[str, Any]:
    """Everything in plain Python (lists of floats), e.g. for JSON.

    Non-finite floats in ``stats``/``verification`` become None when ``finite_only``.
    """
    d = _meta(synth)
    d["stats"] = dict(synth.stats)
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
            seed=int(data.get("seed", 0)), stats=dict(data.get("stats", {})),
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

_CHILDREN: tuple[tuple[int, ...], ...] = tuple(
    tuple(c for c, p in enumerate(PARENTS) if p == j) for j in range(len(PARENTS)))
# Twist references: (from joint, to joint) whose direction fixes the twist about a bone.
_TWIST_REF: dict[str, tuple[str, str]] = {
    "l_hip": ("l_ankle", "l_toe"), "l_knee": ("l_ankle", "l_toe"),
    "r_hip": ("r_ankle", "r_toe"), "r_knee": ("r_ankle", "r_toe"),
    "l_ankle": ("l_knee", "l_ankle"), "r_ankle": ("r_knee", "r_ankle"),
    "spine": ("r_clavicle", "l_clavicle"),
}
# File axes from ours: bvh = C @ ours.
_UP_FROM_Z = {"z": np.eye(3), "y": MOCAP_FROM_ZUP}


def _normalize(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, 1e-12), n[..., 0]


def _swing(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Smallest rotations taking unit vectors ``u`` (..., 3) onto ``v`` (..., 3)."""
    cross = np.cross(u, v)
    s = np.linalg.norm(cross, axis=-1)
    c = np.clip(np.sum(u * v, axis=-1), -1.0, 1.0)
    axis = cross / np.maximum(s, 1e-12)[..., None]
    # Anti-parallel: any axis perpendicular to u.
    helper = np.where(np.abs(u[..., :1]) < 0.9, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
    perp, _ = _normalize(np.cross(u, helper))
    axis = np.where((s < 1e-9)[..., None], perp, axis)
    angle = np.arctan2(s, c)
    return matrix_from_unit_axis_angle(axis, angle)


def _twist(rot: np.ndarray, bone: np.ndarray, ref_rest: np.ndarray, ref_cur: np.ndarray
           ) -> np.ndarray:
    """Turn ``rot`` about unit ``bone`` so ``rot @ ref_rest`` best matches ``ref_cur``."""
    u = np.einsum("...ij,...j->...i", rot, ref_rest)
    up = u - np.sum(u * bone, axis=-1, keepdims=True) * bone
    wp = ref_cur - np.sum(ref_cur * bone, axis=-1, keepdims=True) * bone
    nu, nw = np.linalg.norm(up, axis=-1), np.linalg.norm(wp, axis=-1)
    angle = np.arctan2(np.sum(bone * np.cross(up, wp), axis=-1), np.sum(up * wp, axis=-1))
    # Fade the twist out as the reference becomes parallel to the bone (ill-defined).
    weight = np.clip((np.minimum(nu, nw) / np.maximum(np.linalg.norm(ref_cur, axis=-1), 1e-12)
                      - 0.15) / 0.2, 0.0, 1.0)
    return matrix_from_unit_axis_angle(bone, angle * weight) @ rot


def _kabsch(rest: np.ndarray, cur: np.ndarray) -> np.ndarray:
    """Rotations (T, 3, 3) best mapping rest vectors (K, 3) onto current ones (T, K, 3)."""
    H = np.einsum("ki,tkj->tij", rest, cur)
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.swapaxes(Vt, -1, -2) @ np.swapaxes(U, -1, -2)))
    D = np.zeros_like(H)
    D[:, 0, 0] = 1.0
    D[:, 1, 1] = 1.0
    D[:, 2, 2] = d
    return np.swapaxes(Vt, -1, -2) @ D @ np.swapaxes(U, -1, -2)


def bvh_rotations(positions: np.ndarray, skeleton: Skeleton | None = None) -> np.ndarray:
    """World rotation of every joint per frame, derived from joint positions (z up).

    Parameters
    ----------
    positions : array-like, shape (T, J, 3)
    skeleton : Skeleton, optional
        Gives the rest pose (default: stature 1.75 m).

    Returns
    -------
    rotations : ndarray, shape (T, J, 3, 3)
        ``G[t, j]`` maps rest-pose offsets of ``j``'s children onto their current ones.
    """
    pos = np.asarray(positions, dtype=np.float64)
    skeleton = skeleton or Skeleton()
    if pos.ndim != 3 or pos.shape[1:] != (skeleton.n_joints, 3):
        raise ValueError(f"positions must have shape (T, {skeleton.n_joints}, 3), got {pos.shape}")
    rest = skeleton.rest_positions()
    T, J = pos.shape[:2]
    G = np.zeros((T, J, 3, 3))
    for j in range(J):
        parent = PARENTS[j]
        base = G[:, parent] if parent >= 0 else np.broadcast_to(np.eye(3), (T, 3, 3))
        kids = _CHILDREN[j]
        if len(kids) >= 2:
            G[:, j] = _kabsch(rest[list(kids)] - rest[j], pos[:, list(kids)] - pos[:, j:j + 1])
        elif len(kids) == 1:
            c = kids[0]
            rest_dir, _ = _normalize(rest[c] - rest[j])
            cur_dir, _ = _normalize(pos[:, c] - pos[:, j])
            moved = np.einsum("tij,j->ti", base, rest_dir)
            rot = _swing(moved, cur_dir) @ base
            ref = _TWIST_REF.get(JOINT_NAMES[j])
            if ref is not None:
                a, b = JOINT_INDEX[ref[0]], JOINT_INDEX[ref[1]]
                rot = _twist(rot, cur_dir, rest[b] - rest[a], pos[:, b] - pos[:, a])
            G[:, j] = rot
        else:
            G[:, j] = base
    return G


def _fmt(v: float) -> str:
    s = f"{v:.6f}"
    return "0.000000" if s == "-0.000000" else s


def _bvh_hierarchy(rest: np.ndarray, C: np.ndarray, scale: float, translations: bool,
                   stature: float) -> tuple[list[str], list[int]]:
    """The HIERARCHY lines of :func:`save_bvh` and the joints in their file order.

    ``rest`` is the (J, 3) rest pose, ``C`` the (3, 3) rotation from our frame to the file's.
    """
    lines = ["HIERARCHY"]
    order: list[int] = []

    def emit(j: int, depth: int) -> None:
        order.append(j)
        ind = "  " * depth
        p = PARENTS[j]
        offset = (np.zeros(3) if p < 0 else (rest[j] - rest[p]) @ C.T * scale)
        lines.append(f"{ind}{'ROOT' if p < 0 else 'JOINT'} {JOINT_NAMES[j]}")
        lines.append(f"{ind}{{")
        lines.append(f"{ind}  OFFSET {' '.join(_fmt(v) for v in offset)}")
        if p < 0 or translations:
            lines.append(f"{ind}  CHANNELS 6 Xposition Yposition Zposition "
                         "Zrotation Yrotation Xrotation")
        else:
            lines.append(f"{ind}  CHANNELS 3 Zrotation Yrotation Xrotation")
        if _CHILDREN[j]:
            for c in _CHILDREN[j]:
                emit(c, depth + 1)
        else:
            tip, _ = _normalize(rest[j] - rest[p])
            end = tip @ C.T * 0.05 * stature * scale
            lines.append(f"{ind}  End Site")
            lines.append(f"{ind}  {{")
            lines.append(f"{ind}    OFFSET {' '.join(_fmt(v) for v in end)}")
            lines.append(f"{ind}  }}")
        lines.append(f"{ind}}}")

    emit(0, 0)
    return lines, order


def _bvh_reconstruction_error(pos: np.ndarray, rest: np.ndarray, euler: np.ndarray,
                              root: np.ndarray, delta_file: np.ndarray, order: list[int],
                              C: np.ndarray, scale: float) -> float:
    """Largest distance (m) between ``pos`` (T, J, 3) and the joints the BVH values give.

    ``euler`` (T, J, 3) degrees ZYX, ``root`` (T, 3) and ``delta_file`` (T, J, 3) as
    written by :func:`save_bvh`, in the file's frame and unit.
    """
    from scipy.spatial.transform import Rotation

    T, J = euler.shape[:2]
    R = Rotation.from_euler("ZYX", euler.reshape(-1, 3), degrees=True).as_matrix()
    R = C.T @ R.reshape(T, J, 3, 3) @ C
    world = np.empty_like(R)
    recon = np.empty((T, J, 3))
    for j in order:
        p = PARENTS[j]
        if p < 0:
            world[:, j] = R[:, j]
            recon[:, j] = root @ C / scale
        else:
            world[:, j] = world[:, p] @ R[:, j]
            off = rest[j] - rest[p] + delta_file[:, j] @ C / scale
            recon[:, j] = recon[:, p] + np.einsum("tij,tj->ti", world[:, p], off)
    return float(np.max(np.linalg.norm(recon - pos, axis=-1))) if T else 0.0


def save_bvh(motion: SynthesizedMotion | Motion, path: PathLike, up: str = "y",
             scale: float = 1.0, translations: bool = False) -> float:
    """Write a BVH file (Blender-compatible) of a motion.

    Parameters
    ----------
    motion : SynthesizedMotion or Motion
    path : path-like
    up : {"y", "z"}
        ``"y"``: y up, facing +z (the mocap convention, default); ``"z"``: our frame.
    scale : float
        Unit scale (1.0 = metres, 100.0 = centimetres).
    translations : bool
        Also give every joint ``Xposition Yposition Zposition`` channels holding its
        per-frame displacement from the rest offset (in the parent's frame), so that
        motions whose bones stretch or whose pelvis/chest deform are reproduced exactly.
        Off by default: rotation-only files are what most tools expect.

    Returns
    -------
    max_error : float
        Largest distance (metres) between the input joint positions and the positions
        the written file reproduces (0 up to rounding with ``translations``; otherwise it
        measures how far the motion is from rigid).
    """
    m = motion.motion if isinstance(motion, SynthesizedMotion) else motion
    if not isinstance(m, Motion):
        raise ValueError(f"expected a SynthesizedMotion or Motion, got {type(motion).__name__}")
    if up not in _UP_FROM_Z:
        raise ValueError(f"up must be 'y' or 'z', got {up!r}")
    if not scale > 0:
        raise ValueError(f"scale must be positive, got {scale!r}")
    from scipy.spatial.transform import Rotation

    C = _UP_FROM_Z[up]
    skel = m.skeleton
    rest = skel.rest_positions()
    pos = m.positions
    G = bvh_rotations(pos, skel)                                    # (T, J, 3, 3)
    T, J = G.shape[:2]
    local = np.empty_like(G)
    delta = np.zeros((T, J, 3))                  # displacement from the rest offset
    for j in range(J):
        p = PARENTS[j]
        if p < 0:
            local[:, j] = G[:, j]
            continue
        local[:, j] = np.swapaxes(G[:, p], -1, -2) @ G[:, j]
        if translations:
            in_parent = np.einsum("tji,tj->ti", G[:, p], pos[:, j] - pos[:, p])
            delta[:, j] = in_parent - (rest[j] - rest[p])
    local_file = C @ local @ C.T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)         # gimbal lock is still exact
        euler = Rotation.from_matrix(local_file.reshape(-1, 3, 3)).as_euler(
            "ZYX", degrees=True).reshape(T, J, 3)
    euler = np.round(euler, 6)
    root = np.round((pos[:, 0] @ C.T) * scale, 6)
    delta_file = np.round((delta @ C.T) * scale, 6)

    lines, order = _bvh_hierarchy(rest, C, scale, translations, skel.stature)
    lines.append("MOTION")
    lines.append(f"Frames: {T}")
    lines.append(f"Frame Time: {1.0 / m.fps:.8f}")
    for t in range(T):
        vals: list[float] = []
        for j in order:
            if PARENTS[j] < 0:
                vals.extend(root[t])
            elif translations:
                vals.extend(delta_file[t, j])
            vals.extend(euler[t, j])
        lines.append(" ".join(_fmt(v) for v in vals))
    atomic_write_text(path, "\n".join(lines) + "\n")

    # Reconstruction error of what was written (rounded values included).
    return _bvh_reconstruction_error(pos, rest, euler, root, delta_file, order, C, scale)


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
