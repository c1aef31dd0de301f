"""BVH motion files (CMU BVH conversions, LAFAN-style takes, other Y-up BVH).

:func:`load` parses the file, runs forward kinematics on its own skeleton
(:func:`load_raw`), converts Y-up to our Z-up frame (``(x, y, z)_bvh -> (z, x, y)``:
BVH characters face +z with +x to their left, ours face +x with +y to the left), finds
the joints that correspond to the canonical ones by name (CMU, LAFAN/Mixamo-like and
Motion-Builder style names are known; see :data:`NAME_CANDIDATES`) and retargets onto the
canonical skeleton (:func:`~ltl_human_motion.motion.retarget.retarget_points`).

:func:`save` writes a canonical-skeleton motion as BVH in which every joint carries
position channels (its offset from the parent at every frame, no rotations), so that the
file reproduces the positions exactly; it loads back with :func:`load`.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ltl_human_motion.atomic import atomic_write_text
from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.kernel.rotations import ZUP_FROM_MOCAP
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


def save(motion: Motion, path: str | os.PathLike[str], precision: int = 6) -> None:
    """Write a canonical-skeleton motion as BVH (Y up, metres; written atomically).

    Every joint has three position channels holding its offset from its parent in world
    axes and no rotation channels, so the positions are reproduced exactly.
    """
    if not isinstance(motion, Motion):
        raise ValueError(f"motion must be a Motion, got {type(motion).__name__}")
    pos = motion.positions @ ZUP_FROM_MOCAP          # z-up -> y-up (inverse rotation)
    rest = motion.skeleton.rest_positions() @ ZUP_FROM_MOCAP
    children: dict[int, list[int]] = {j: [] for j in range(len(JOINT_NAMES))}
    for j, p in enumerate(PARENTS):
        if p >= 0:
            children[p].append(j)
    out = ["HIERARCHY"]

    def emit(j: int, depth: int) -> None:
        pad = "\t" * depth
        p = PARENTS[j]
        off = rest[j] - (rest[p] if p >= 0 else 0.0)
        out.append(f"{pad}{'ROOT' if p < 0 else 'JOINT'} {JOINT_NAMES[j]}")
        out.append(f"{pad}{{")
        out.append(f"{pad}\tOFFSET {off[0]:.{precision}f} {off[1]:.{precision}f} "
                   f"{off[2]:.{precision}f}")
        out.append(f"{pad}\tCHANNELS 3 Xposition Yposition Zposition")
        for c in children[j]:
            emit(c, depth + 1)
        if not children[j]:
            out.append(f"{pad}\tEnd Site")
            out.append(f"{pad}\t{{")
            out.append(f"{pad}\t\tOFFSET 0 0 0")
            out.append(f"{pad}\t}}")
        out.append(f"{pad}}}")

    emit(0, 0)
    order: list[int] = []

    def walk(j: int) -> None:
        order.append(j)
        for c in children[j]:
            walk(c)

    walk(0)
    parents = np.array(PARENTS)
    local = pos.copy()
    nonroot = parents >= 0
    local[:, nonroot] = pos[:, nonroot] - pos[:, parents[nonroot]]
    # non-root position channels are added to the OFFSET, so store the difference
    local[:, nonroot] -= (rest[nonroot] - rest[parents[nonroot]])[None]
    out.append("MOTION")
    out.append(f"Frames: {motion.n_frames}")
    out.append(f"Frame Time: {1.0 / motion.fps:.8f}")
    flat = local[:, order].reshape(motion.n_frames, -1)
    fmt = f"%.{precision}f"
    out.extend(" ".join(fmt % v for v in row) for row in flat)
    atomic_write_text(path, "\n".join(out) + "\n")
