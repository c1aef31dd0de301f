"""BVH motion files (CMU BVH conversions, LAFAN-style takes, other Y-up BVH).

:func:`load` parses the file, runs forward kinematics on its own skeleton
(:func:`load_raw`), converts Y-up to our Z-up frame (``(x, y, z)_bvh -> (z, x, y)``:
BVH characters face +z with +x to their left, ours face +x with +y to the left), finds
the joints that correspond to the canonical ones by name (CMU, LAFAN/Mixamo-like and
Motion-Builder style names are known; see :data:`NAME_CANDIDATES`) and retargets onto the
canonical skeleton (:func:`~ltl_human_motion.motion.retarget.retarget_points`).

:func:`save` writes a canonical-skeleton motion. The hierarchy is the canonical skeleton
(:mod:`ltl_human_motion.motion.skeleton`) with its rest pose as offsets: 23 ``JOINT``
entries (the root ``pelvis`` has six channels ``Xposition Yposition Zposition Zrotation
Yrotation Xrotation``, every other joint three ``Zrotation Yrotation Xrotation``; R = Rz ·
Ry · Rx, angles in degrees) and an ``End Site`` after each leaf (head, hands, toes). Units
are metres (``scale`` changes them). By default the file follows the motion-capture
convention, **y up with the character facing +z** and its left at +x: ``(x, y, z)_ours ->
(y, z, x)_bvh``, the inverse of what :func:`load` applies, so written files load back.
Blender's importer (default axes: forward -Z, up Y) shows the worker standing on its
floor, facing -Y (towards the front view), i.e. our frame turned by -90 degrees about the
vertical. ``up="z"`` writes our frame unchanged (z up, facing +x; import into Blender
with forward Y, up Z).

Joint rotations come from the positions (:func:`~ltl_human_motion.motion.bone_rotations.
joint_rotations`). With rigid bone lengths the file reproduces the joint positions
exactly; :func:`save` returns the largest reconstruction error. Motions that are not
rigid (stretching bones, a deforming pelvis) are written exactly with
``translations=True``, which adds per-joint position channels (displacements from the
rest offsets, which Blender imports as bone locations).
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ltl_human_motion.atomic import atomic_write_text
from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.kernel.rotations import MOCAP_FROM_ZUP, ZUP_FROM_MOCAP
from ltl_human_motion.motion.bone_rotations import CHILDREN, joint_rotations, unit_vectors
from ltl_human_motion.motion.retarget import retarget_points
from ltl_human_motion.motion.rotations import matrix_from_euler
from ltl_human_motion.motion.skeleton import JOINT_NAMES, PARENTS, Skeleton
from ltl_human_motion.motion.types import Motion

__all__ = ["NAME_CANDIDATES", "BvhSkeleton", "canonical_points", "load", "load_raw", "save"]

# Candidate source joint names per canonical joint, first match wins (case-insensitive,
# namespace prefixes such as "mixamorig:" ignored). "<name>_End" is the End Site of <name>.
NAME_CANDIDATES: dict[str, tuple[str, ...]] = {
    "pelvis": ("Hips", "Hip", "Pelvis", "Root", "pelvis"),
    "spine": ("Spine", "LowerBack", "Ab", "Abdomen", "spine"),
    "chest": ("Chest", "Spine2", "Spine1", "UpperChest", "Spine3", "chest"),
    "neck": ("Neck", "Neck1", "neck"),
    "head": ("Head", "head"),
    "l_shoulder": ("LeftArm", "LeftUpArm", "LeftUpperArm", "LeftShoulder", "l_shoulder"),
    "l_elbow": ("LeftForeArm", "LeftElbow", "LeftLowArm", "LeftLowerArm", "l_elbow"),
    "l_wrist": ("LeftHand", "LeftWrist", "l_wrist"),
    "l_hand": ("LeftFingerBase", "LFingers", "LeftHandIndex1", "LeftHandMiddle1",
               "LeftHand_End", "LeftWrist_End", "l_hand"),
    "r_shoulder": ("RightArm", "RightUpArm", "RightUpperArm", "RightShoulder", "r_shoulder"),
    "r_elbow": ("RightForeArm", "RightElbow", "RightLowArm", "RightLowerArm", "r_elbow"),
    "r_wrist": ("RightHand", "RightWrist", "r_wrist"),
    "r_hand": ("RightFingerBase", "RFingers", "RightHandIndex1", "RightHandMiddle1",
               "RightHand_End", "RightWrist_End", "r_hand"),
    "l_hip": ("LeftUpLeg", "LeftHip", "LeftThigh", "LeftUpperLeg", "l_hip"),
    "l_knee": ("LeftLeg", "LeftKnee", "LeftShin", "LeftLowerLeg", "l_knee"),
    "l_ankle": ("LeftFoot", "LeftAnkle", "l_ankle"),
    "l_toe": ("LeftToeBase", "LeftToe", "LeftToes", "LeftFoot_End", "LeftAnkle_End", "l_toe"),
    "r_hip": ("RightUpLeg", "RightHip", "RightThigh", "RightUpperLeg", "r_hip"),
    "r_knee": ("RightLeg", "RightKnee", "RightShin", "RightLowerLeg", "r_knee"),
    "r_ankle": ("RightFoot", "RightAnkle", "r_ankle"),
    "r_toe": ("RightToeBase", "RightToe", "RightToes", "RightFoot_End", "RightAnkle_End",
              "r_toe"),
}


@dataclass(frozen=True)
class BvhSkeleton:
    """The hierarchy of a BVH file.

    Attributes
    ----------
    names : tuple of str
        Joint names; End Sites are named ``<parent>_End``.
    parents : tuple of int
    offsets : ndarray, shape (N, 3)
    channels : tuple of tuple of str
        Channel names per joint (empty for End Sites).
    """

    names: tuple[str, ...]
    parents: tuple[int, ...]
    offsets: np.ndarray
    channels: tuple[tuple[str, ...], ...]

    @property
    def n_channels(self) -> int:
        return sum(len(c) for c in self.channels)


_VALID_CHANNELS = {"Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation",
                   "Zrotation"}


def _err(path: Path, line: int | None, msg: str) -> MotionFormatError:
    where = f"line {line}: " if line is not None else ""
    return MotionFormatError(f"{path}: {where}{msg}")


def _parse(path: Path, text: str) -> tuple[BvhSkeleton, np.ndarray, float]:
    lines = text.splitlines()
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[tuple[str, ...]] = []
    stack: list[int] = []
    pending: int | None = None     # joint declared, waiting for its "{"
    i = 0
    n = len(lines)
    while i < n and not lines[i].strip():
        i += 1
    if i >= n or lines[i].strip().upper() != "HIERARCHY":
        raise _err(path, i + 1 if i < n else None, "expected 'HIERARCHY' at the start of a BVH "
                   "file")
    i += 1
    motion_line = None
    while i < n:
        raw = lines[i].strip()
        lineno = i + 1
        i += 1
        if not raw:
            continue
        tok = raw.split()
        key = tok[0].upper()
        if key in ("ROOT", "JOINT"):
            if len(tok) < 2:
                raise _err(path, lineno, f"{tok[0]} without a name")
            if key == "ROOT" and names:
                raise _err(path, lineno, "only one ROOT is supported")
            if key == "JOINT" and not stack:
                raise _err(path, lineno, "JOINT outside of a ROOT block")
            names.append(" ".join(tok[1:]))
            parents.append(stack[-1] if stack else -1)
            offsets.append([0.0, 0.0, 0.0])
            channels.append(())
            pending = len(names) - 1
        elif key == "END":
            if not stack:
                raise _err(path, lineno, "End Site outside of a joint")
            names.append(f"{names[stack[-1]]}_End")
            parents.append(stack[-1])
            offsets.append([0.0, 0.0, 0.0])
            channels.append(())
            pending = len(names) - 1
        elif key == "{":
            if pending is None:
                raise _err(path, lineno, "'{' without a joint")
            stack.append(pending)
            pending = None
        elif key == "}":
            if not stack:
                raise _err(path, lineno, "unbalanced '}'")
            stack.pop()
        elif key == "OFFSET":
            if not stack:
                raise _err(path, lineno, "OFFSET outside of a joint")
            try:
                vals = [float(v) for v in tok[1:4]]
            except ValueError:
                raise _err(path, lineno, f"OFFSET needs 3 numbers, got {' '.join(tok[1:])!r}") \
                    from None
            if len(vals) != 3 or len(tok) != 4:
                raise _err(path, lineno, "OFFSET needs 3 numbers")
            if not all(math.isfinite(v) and abs(v) <= MAX_OFFSET for v in vals):
                raise _err(path, lineno, f"OFFSET values must be finite and within "
                           f"+-{MAX_OFFSET:g} (MAX_OFFSET), got {' '.join(tok[1:])[:60]!r}")
            offsets[stack[-1]] = vals
        elif key == "CHANNELS":
            if not stack:
                raise _err(path, lineno, "CHANNELS outside of a joint")
            try:
                count = int(tok[1])
            except (IndexError, ValueError):
                raise _err(path, lineno, "CHANNELS needs a count") from None
            chans = tuple(tok[2:])
            if len(chans) != count or any(c not in _VALID_CHANNELS for c in chans):
                raise _err(path, lineno, f"CHANNELS {count} expects {count} of "
                           f"{sorted(_VALID_CHANNELS)}, got {' '.join(chans)!r}")
            channels[stack[-1]] = chans
        elif key == "MOTION":
            motion_line = lineno
            break
        else:
            raise _err(path, lineno, f"unexpected {tok[0]!r} in HIERARCHY")
    if motion_line is None:
        raise _err(path, None, "no MOTION section (file truncated?)")
    if stack or pending is not None:
        raise _err(path, motion_line, "HIERARCHY has unclosed '{' before MOTION")
    if not names:
        raise _err(path, motion_line, "HIERARCHY declares no joints")
    skel = BvhSkeleton(tuple(names), tuple(parents), np.asarray(offsets, dtype=np.float64),
                       tuple(channels))

    def header(prefix: str) -> tuple[str, int]:
        nonlocal i
        while i < n and not lines[i].strip():
            i += 1
        if i >= n:
            raise _err(path, None, f"missing '{prefix}' line after MOTION (file truncated?)")
        raw = lines[i].strip()
        i += 1
        if not raw.lower().startswith(prefix.lower()):
            raise _err(path, i, f"expected '{prefix} ...', got {raw[:40]!r}")
        return raw[len(prefix):].strip(), i

    val, ln = header("Frames:")
    try:
        n_frames = int(val)
    except ValueError:
        raise _err(path, ln, f"frame count must be an integer, got {val!r}") from None
    val, ln = header("Frame Time:")
    try:
        frame_time = float(val)
    except ValueError:
        raise _err(path, ln, f"frame time must be a number, got {val!r}") from None
    if n_frames < 1 or not frame_time > 0:
        raise _err(path, ln, f"need at least one frame and a positive frame time, got "
                   f"{n_frames} frames, {frame_time} s")
    if not MIN_FRAME_TIME <= frame_time <= MAX_FRAME_TIME:
        raise _err(path, ln, f"frame time {frame_time:g} s is outside [{MIN_FRAME_TIME:g}, "
                   f"{MAX_FRAME_TIME:g}] s (MIN_FRAME_TIME, MAX_FRAME_TIME)")
    if n_frames > n - i:          # each frame takes a line: never allocate for absent ones
        raise _err(path, n, f"frame {n - i}: the header announces {n_frames} frames but "
                   f"only {n - i} lines follow "
                   "(truncated, or a wrong frame count)")
    nch = skel.n_channels
    data = np.empty((n_frames, nch))
    f = 0
    while f < n_frames:
        if i >= n:
            raise _err(path, None, f"frame {f}: file ends after {f} of {n_frames} frames "
                       f"(truncated)")
        raw = lines[i].strip()
        i += 1
        if not raw:
            continue
        parts = raw.split()
        if len(parts) != nch:
            raise _err(path, i, f"frame {f}: expected {nch} channel values, found {len(parts)}")
        try:
            row = np.array([float(v) for v in parts])
        except ValueError:
            raise _err(path, i, f"frame {f}: not a number in {raw[:60]!r}") from None
        if not np.all(np.isfinite(row)):
            raise _err(path, i, f"frame {f}: NaN or infinite value")
        data[f] = row
        f += 1
    return skel, data, 1.0 / frame_time


def _fk(skel: BvhSkeleton, data: np.ndarray) -> np.ndarray:
    """World positions (T, N, 3) in the file's own axes and units."""
    T = data.shape[0]
    N = len(skel.names)
    pos = np.zeros((T, N, 3))
    rot = np.zeros((T, N, 3, 3))
    col = 0
    for j in range(N):
        chans = skel.channels[j]
        vals = data[:, col:col + len(chans)]
        col += len(chans)
        local_t = np.broadcast_to(skel.offsets[j], (T, 3)).copy()
        pos_ch = [(k, c) for k, c in enumerate(chans) if c.endswith("position")]
        if pos_ch:
            # BVH position channels replace the offset (root) / add to it (other joints)
            if skel.parents[j] >= 0:
                local_t = local_t.copy()
            else:
                local_t = np.zeros((T, 3))
            for k, c in pos_ch:
                local_t[:, "XYZ".index(c[0])] += vals[:, k]
        rot_ch = [(k, c) for k, c in enumerate(chans) if c.endswith("rotation")]
        if rot_ch:
            order = "".join(c[0] for _, c in rot_ch)
            local_r = matrix_from_euler(vals[:, [k for k, _ in rot_ch]], order)
        else:
            local_r = np.broadcast_to(np.eye(3), (T, 3, 3))
        p = skel.parents[j]
        if p < 0:
            pos[:, j] = local_t
            rot[:, j] = local_r
        else:
            pos[:, j] = pos[:, p] + np.einsum("tij,tj->ti", rot[:, p], local_t)
            rot[:, j] = rot[:, p] @ local_r
    return pos


#: Frame times accepted (s): 10 kHz to one frame per 10 s. Capture runs at 30-480 Hz;
#: 1e-300 s overflowed the frame rate.
MIN_FRAME_TIME = 1e-4
MAX_FRAME_TIME = 10.0
#: Bone offsets (file units: cm, inches or m): a human bone is well under 1e4 of any.
MAX_OFFSET = 1e4


def load_raw(path: str | os.PathLike[str]) -> tuple[BvhSkeleton, np.ndarray, float]:
    """Parse a BVH file and run forward kinematics on its own skeleton.

    Returns
    -------
    skeleton : BvhSkeleton
    positions : ndarray, shape (T, N, 3)
        World joint (and End Site) positions, Z up (converted), in the file's units.
    fps : float

    Raises
    ------
    MotionFormatError
        Malformed or truncated file; the message names the file and the line or frame.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="strict")
    except UnicodeDecodeError as exc:
        raise _err(path, None, f"not a text BVH file ({exc.reason} at byte {exc.start})") \
            from None
    except OSError as exc:
        raise _err(path, None, f"cannot read: {exc.strerror or exc}") from None
    skel, data, fps = _parse(path, text)
    pos = _fk(skel, data) @ ZUP_FROM_MOCAP.T
    return skel, pos, fps


def _norm(name: str) -> str:
    return name.split(":")[-1].replace(" ", "").lower()


def canonical_points(skel: BvhSkeleton, positions: np.ndarray,
                     path: str | os.PathLike[str] = "<bvh>") -> dict[str, np.ndarray]:
    """Source trajectories for every canonical joint found by name (see module docstring).

    Raises
    ------
    MotionFormatError
        A joint needed for retargeting has no recognisable counterpart.
    """
    index = {_norm(n): i for i, n in enumerate(skel.names)}
    points: dict[str, np.ndarray] = {}
    head = positions[: min(len(positions), 50)]
    scale = float(np.median(np.linalg.norm(head - head[:, :1, :], axis=-1)
                            .max(axis=1))) or 1.0
    # canonical joints in hierarchy order; a candidate that coincides with the parent's
    # point (zero-length bone, e.g. CMU's Neck on Spine1) is skipped for the next one
    for canon in JOINT_NAMES:
        cands = NAME_CANDIDATES.get(canon)
        if cands is None:
            continue
        parent = PARENTS[JOINT_NAMES.index(canon)]
        while parent >= 0 and JOINT_NAMES[parent] not in points:
            parent = PARENTS[parent]
        ref = points.get(JOINT_NAMES[parent]) if parent >= 0 else None
        for c in cands:
            j = index.get(_norm(c))
            if j is None:
                continue
            if ref is not None and float(np.median(
                    np.linalg.norm(positions[:, j] - ref, axis=-1))) < 1e-3 * scale:
                continue
            points[canon] = positions[:, j]
            break
    for side in ("l", "r"):
        if f"{side}_hand" not in points and f"{side}_wrist" in points and \
                f"{side}_elbow" in points:
            w, e = points[f"{side}_wrist"], points[f"{side}_elbow"]
            points[f"{side}_hand"] = w + 0.35 * (w - e)
    missing = [c for c in NAME_CANDIDATES if c not in points and c != "spine"]
    if missing:
        raise MotionFormatError(
            f"{path}: cannot find joints for {', '.join(missing)} among "
            f"{', '.join(n for n in skel.names if not n.endswith('_End'))}")
    return points


def load(path: str | os.PathLike[str], skeleton: Skeleton | None = None) -> Motion:
    """Load a BVH file retargeted onto the canonical skeleton.

    Parameters
    ----------
    path : path-like
    skeleton : Skeleton, optional
        Target body (default stature 1.75 m).

    Returns
    -------
    Motion
        World positions, Z up, at the file's frame rate; ``name`` is the file stem.

    Raises
    ------
    MotionFormatError
        Malformed, truncated or unrecognised file (the message names file and line/frame).
    """
    skel, pos, fps = load_raw(path)
    points = canonical_points(skel, pos, path)
    try:
        return retarget_points(points, fps, skeleton, name=Path(path).stem)
    except ValueError as exc:
        raise MotionFormatError(f"{path}: {exc}") from None


# File axes from ours: bvh = C @ ours.
_UP_FROM_Z = {"z": np.eye(3), "y": MOCAP_FROM_ZUP}


def _fmt(v: float) -> str:
    s = f"{v:.6f}"
    return "0.000000" if s == "-0.000000" else s


def _hierarchy(rest: np.ndarray, C: np.ndarray, scale: float, translations: bool,
                   stature: float) -> tuple[list[str], list[int]]:
    """The HIERARCHY lines of :func:`save` and the joints in their file order.

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
        if CHILDREN[j]:
            for c in CHILDREN[j]:
                emit(c, depth + 1)
        else:
            tip, _ = unit_vectors(rest[j] - rest[p])
            end = tip @ C.T * 0.05 * stature * scale
            lines.append(f"{ind}  End Site")
            lines.append(f"{ind}  {{")
            lines.append(f"{ind}    OFFSET {' '.join(_fmt(v) for v in end)}")
            lines.append(f"{ind}  }}")
        lines.append(f"{ind}}}")

    emit(0, 0)
    return lines, order


def _reconstruction_error(pos: np.ndarray, rest: np.ndarray, euler: np.ndarray,
                              root: np.ndarray, delta_file: np.ndarray, order: list[int],
                              C: np.ndarray, scale: float) -> float:
    """Largest distance (m) between ``pos`` (T, J, 3) and the joints the BVH values give.

    ``euler`` (T, J, 3) degrees ZYX, ``root`` (T, 3) and ``delta_file`` (T, J, 3) as
    written by :func:`save`, in the file's frame and unit.
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


def save(motion: Motion, path: str | os.PathLike[str], up: str = "y", scale: float = 1.0,
         translations: bool = False) -> float:
    """Write a BVH file (Blender-compatible) of a canonical-skeleton motion (atomically).

    Parameters
    ----------
    motion : Motion
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
    m = motion
    if not isinstance(m, Motion):
        raise ValueError(f"motion must be a Motion, got {type(motion).__name__}")
    if up not in _UP_FROM_Z:
        raise ValueError(f"up must be 'y' or 'z', got {up!r}")
    if not scale > 0:
        raise ValueError(f"scale must be positive, got {scale!r}")
    from scipy.spatial.transform import Rotation

    C = _UP_FROM_Z[up]
    skel = m.skeleton
    rest = skel.rest_positions()
    pos = m.positions
    G = joint_rotations(pos, skel)                                    # (T, J, 3, 3)
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

    lines, order = _hierarchy(rest, C, scale, translations, skel.stature)
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
    return _reconstruction_error(pos, rest, euler, root, delta_file, order, C, scale)
