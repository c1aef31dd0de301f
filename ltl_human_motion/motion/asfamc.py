"""Acclaim ASF/AMC motion files (the CMU Graphics Lab database's own format).

No third-party parser is needed (dm-control is not used). Forward kinematics follows the
Acclaim convention as implemented by common AMC parsers: for a bone with axis rotation
``C`` (from its ``axis`` line) and per-frame rotation ``M`` (from its ``dof`` values),

    R_bone = R_parent @ C @ M @ C^-1,    end = parent_end + length * R_bone @ direction

where Euler angles ``a0 a1 a2`` on axes ``o0 o1 o2`` (e.g. ``axis 0 0 -20 XYZ``, or the
``dof rx ry rz`` order) give ``R = R_o2(a2) @ R_o1(a1) @ R_o0(a0)`` (rotations applied in
the listed order about fixed axes). A bone's position is its *end* point. The root's
translation and rotation come from its ``order`` line. The skeleton is Y up; it is
converted to our Z up frame like BVH (``(x, y, z) -> (z, x, y)``) and retargeted onto the
canonical skeleton by bone names (:data:`NAME_CANDIDATES`, CMU names by default).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.kernel.rotations import ZUP_FROM_MOCAP
from ltl_human_motion.motion.retarget import retarget_points
from ltl_human_motion.motion.rotations import matrix_from_euler
from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.motion.types import Motion

__all__ = ["NAME_CANDIDATES", "AsfBone", "AsfSkeleton", "load", "load_raw", "parse_asf"]

NAME_CANDIDATES: dict[str, tuple[str, ...]] = {
    "pelvis": ("root",),
    "spine": ("lowerback",),
    "chest": ("thorax", "upperback"),
    "neck": ("lowerneck", "upperneck"),
    "head": ("head",),
    "l_shoulder": ("lclavicle",), "r_shoulder": ("rclavicle",),
    "l_elbow": ("lhumerus",), "r_elbow": ("rhumerus",),
    "l_wrist": ("lradius",), "r_wrist": ("rradius",),
    "l_hand": ("lwrist", "lhand"), "r_hand": ("rwrist", "rhand"),
    "l_hip": ("lhipjoint",), "r_hip": ("rhipjoint",),
    "l_knee": ("lfemur",), "r_knee": ("rfemur",),
    "l_ankle": ("ltibia",), "r_ankle": ("rtibia",),
    "l_toe": ("lfoot",), "r_toe": ("rfoot",),
}


@dataclass(frozen=True)
class AsfBone:
    """One ``:bonedata`` entry."""

    name: str
    direction: np.ndarray
    length: float
    axis: np.ndarray
    axis_order: str
    dof: tuple[str, ...]


@dataclass(frozen=True)
class AsfSkeleton:
    """A parsed ASF file: bones, hierarchy (parent name per bone), root order and axis."""

    bones: dict[str, AsfBone]
    parent: dict[str, str]
    root_order: tuple[str, ...]
    root_axis: str
    root_position: np.ndarray
    root_orientation: np.ndarray
    angle_unit: str = "deg"

    def topological(self) -> list[str]:
        """Bone names with every parent before its children."""
        order: list[str] = []
        children: dict[str, list[str]] = {}
        for b, p in self.parent.items():
            children.setdefault(p, []).append(b)
        stack = list(reversed(children.get("root", [])))
        while stack:
            b = stack.pop()
            order.append(b)
            stack.extend(reversed(children.get(b, [])))
        return order


def _axis_order(text: str, lineno: int, fail: Any) -> str:
    """An Euler order such as ``XYZ`` (each axis once), else the ``fail`` error."""
    order = text.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise fail(lineno, f"axis order must be a permutation of XYZ, got {text[:20]!r}")
    return order


def _euler(angles: np.ndarray, order: str, unit: str) -> np.ndarray:
    """Fixed-axis rotations applied in ``order``: R = R_o2 @ R_o1 @ R_o0."""
    a = np.asarray(angles, dtype=np.float64)
    if unit == "rad":
        a = np.rad2deg(a)
    return matrix_from_euler(a[..., ::-1], order[::-1])


def parse_asf(path: str | os.PathLike[str]) -> AsfSkeleton:
    """Parse an ASF skeleton file.

    Raises
    ------
    MotionFormatError
        The message names the file and line.
    """
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise MotionFormatError(f"{path}: cannot read ASF file: {exc}") from None
    section = None
    bones: dict[str, AsfBone] = {}
    parent: dict[str, str] = {}
    root_order: tuple[str, ...] = ("TX", "TY", "TZ", "RX", "RY", "RZ")
    root_axis = "XYZ"
    root_pos = np.zeros(3)
    root_ori = np.zeros(3)
    unit = "deg"
    cur: dict | None = None
    start_line = 0

    def fail(lineno: int, msg: str) -> MotionFormatError:
        return MotionFormatError(f"{path}: line {lineno}: {msg}")

    def close_bone(lineno: int) -> None:
        nonlocal cur
        if cur is None:
            raise fail(lineno, "'end' without 'begin'")
        for key in ("name", "direction", "length"):
            if key not in cur:
                raise fail(start_line, f"bone has no '{key}'")
        bones[cur["name"]] = AsfBone(
            name=cur["name"], direction=cur["direction"], length=cur["length"],
            axis=cur.get("axis", np.zeros(3)), axis_order=cur.get("axis_order", "XYZ"),
            dof=cur.get("dof", ()))
        cur = None

    for lineno, raw in enumerate(lines, 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        if line.startswith(":"):
            tok = line.split()
            section = tok[0][1:].lower()
            continue
        tok = line.split()
        try:
            if section == "units":
                if tok[0] == "angle" and len(tok) > 1:
                    unit = "rad" if tok[1].lower().startswith("rad") else "deg"
            elif section == "root":
                if tok[0] == "order":
                    root_order = tuple(t.upper() for t in tok[1:])
                elif tok[0] == "axis":
                    root_axis = _axis_order(tok[1], lineno, fail)
                elif tok[0] == "position":
                    root_pos = np.array([float(v) for v in tok[1:4]])
                elif tok[0] == "orientation":
                    root_ori = np.array([float(v) for v in tok[1:4]])
            elif section == "bonedata":
                if tok[0] == "begin":
                    cur, start_line = {}, lineno
                elif tok[0] == "end":
                    close_bone(lineno)
                elif cur is None:
                    raise fail(lineno, f"{tok[0]!r} outside begin/end")
                elif tok[0] == "name":
                    cur["name"] = tok[1]
                elif tok[0] == "direction":
                    cur["direction"] = np.array([float(v) for v in tok[1:4]])
                    if cur["direction"].shape != (3,):
                        raise fail(lineno, "direction needs 3 numbers")
                elif tok[0] == "length":
                    cur["length"] = float(tok[1])
                elif tok[0] == "axis":
                    cur["axis"] = np.array([float(v) for v in tok[1:4]])
                    if cur["axis"].shape != (3,):
                        raise fail(lineno, "axis needs 3 angles and an order such as XYZ")
                    cur["axis_order"] = _axis_order(tok[4], lineno, fail) if len(tok) > 4 \
                        else "XYZ"
                elif tok[0] == "dof":
                    dof = tuple(t.lower() for t in tok[1:])
                    bad = [d for d in dof if d not in ("rx", "ry", "rz", "tx", "ty", "tz", "l")]
                    if bad:
                        raise fail(lineno, f"unknown dof {bad[0]!r}")
                    cur["dof"] = dof
            elif section == "hierarchy":
                if tok[0] in ("begin", "end"):
                    continue
                for child in tok[1:]:
                    parent[child] = tok[0]
        except MotionFormatError:
            raise
        except (ValueError, IndexError):
            raise fail(lineno, f"malformed line {line[:60]!r}") from None
    if cur is not None:
        raise MotionFormatError(f"{path}: line {start_line}: bone not closed (file truncated?)")
    if not bones:
        raise MotionFormatError(f"{path}: no :bonedata found")
    unknown = [c for c in parent if c not in bones]
    if unknown:
        raise MotionFormatError(f"{path}: hierarchy names unknown bone {unknown[0]!r}")
    for b in bones:
        if b not in parent:
            raise MotionFormatError(f"{path}: bone {b!r} is missing from :hierarchy")
    return AsfSkeleton(bones, parent, root_order, root_axis, root_pos, root_ori, unit)


def _read_amc(path: Path, skel: AsfSkeleton) -> tuple[list[dict[str, np.ndarray]], list[int]]:
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise MotionFormatError(f"{path}: cannot read AMC file: {exc}") from None
    frames: list[dict[str, np.ndarray]] = []
    numbers: list[int] = []
    cur: dict[str, np.ndarray] | None = None
    expected = {b: sum(1 for d in bone.dof if d != "l") for b, bone in skel.bones.items()}
    expected["root"] = len(skel.root_order)
    frame_line = 0
    for lineno, raw in enumerate(lines, 1):
        line = raw.strip()
        if not line or line.startswith("#") or line.startswith(":"):
            continue
        if re.fullmatch(r"\d+", line):
            if cur is not None:
                _check_frame(path, cur, expected, numbers[-1], frame_line)
            cur = {}
            frames.append(cur)
            numbers.append(int(line))
            frame_line = lineno
            continue
        if cur is None:
            raise MotionFormatError(f"{path}: line {lineno}: data before the first frame number")
        tok = line.split()
        name = tok[0]
        if name not in expected:
            raise MotionFormatError(f"{path}: line {lineno}: frame {numbers[-1]}: unknown bone "
                                    f"{name!r}")
        try:
            vals = np.array([float(v) for v in tok[1:]])
        except ValueError:
            raise MotionFormatError(f"{path}: line {lineno}: frame {numbers[-1]}: not a number "
                                    f"in {line[:60]!r}") from None
        if vals.size != expected[name] or not np.all(np.isfinite(vals)):
            raise MotionFormatError(f"{path}: line {lineno}: frame {numbers[-1]}: bone {name!r} "
                                    f"needs {expected[name]} finite values, got {vals.size}")
        cur[name] = vals
    if cur is None:
        raise MotionFormatError(f"{path}: no frames")
    _check_frame(path, cur, expected, numbers[-1], frame_line)
    return frames, numbers


def _check_frame(path: Path, frame: dict, expected: dict, number: int, line: int) -> None:
    missing = [b for b, n in expected.items() if n > 0 and b not in frame]
    if missing:
        raise MotionFormatError(f"{path}: line {line}: frame {number} lacks bone(s) "
                                f"{', '.join(missing[:4])} (file truncated?)")


def load_raw(asf_path: str | os.PathLike[str], amc_path: str | os.PathLike[str]
             ) -> tuple[AsfSkeleton, dict[str, np.ndarray]]:
    """Forward kinematics of an AMC motion on its ASF skeleton.

    Returns
    -------
    skeleton : AsfSkeleton
    points : dict of str to ndarray, shape (T, 3)
        End point of every bone plus ``"root"``, Z up, in the file's length units.
    """
    skel = parse_asf(asf_path)
    amc = Path(amc_path)
    frames, _ = _read_amc(amc, skel)
    T = len(frames)
    unit = skel.angle_unit
    root = np.stack([f["root"] for f in frames])
    trans = np.zeros((T, 3)) + skel.root_position
    rot_vals = np.zeros((T, 3))
    rot_order = ""
    for k, ch in enumerate(skel.root_order):
        if ch.startswith("T"):
            trans[:, "XYZ".index(ch[1])] = root[:, k] + skel.root_position["XYZ".index(ch[1])]
        elif ch.startswith("R"):
            rot_vals[:, len(rot_order)] = root[:, k]
            rot_order += ch[1]
    rot_vals = rot_vals[:, :len(rot_order)]
    c_root = _euler(skel.root_orientation, skel.root_axis, unit)
    m_root = _euler(rot_vals, rot_order, unit) if rot_order else np.broadcast_to(np.eye(3),
                                                                                  (T, 3, 3))
    rot = {"root": c_root @ m_root @ c_root.T}
    pos = {"root": trans}
    for name in skel.topological():
        bone = skel.bones[name]
        par = skel.parent[name]
        c = _euler(bone.axis, bone.axis_order, unit)
        axes = "".join(d[1].upper() for d in bone.dof if d.startswith("r"))
        if axes:
            vals = np.stack([f[name][[i for i, d in enumerate(
                [d for d in bone.dof if d != "l"]) if d.startswith("r")]] for f in frames])
            m = _euler(vals, axes, unit)
        else:
            m = np.broadcast_to(np.eye(3), (T, 3, 3))
        r = rot[par] @ c @ m @ c.T
        rot[name] = r
        pos[name] = pos[par] + bone.length * np.einsum("tij,j->ti", r, bone.direction)
    return skel, {k: v @ ZUP_FROM_MOCAP.T for k, v in pos.items()}


def load(asf_path: str | os.PathLike[str], amc_path: str | os.PathLike[str],
         skeleton: Skeleton | None = None, fps: float = 120.0) -> Motion:
    """Load an AMC motion (with its ASF skeleton) retargeted onto the canonical skeleton.

    Parameters
    ----------
    asf_path, amc_path : path-like
    skeleton : Skeleton, optional
    fps : float
        AMC files do not store their rate; the CMU database is 120 Hz.

    Returns
    -------
    Motion

    Raises
    ------
    MotionFormatError
        Malformed or truncated files, or bones that cannot be matched.
    """
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps!r}")
    _, pts = load_raw(asf_path, amc_path)
    points: dict[str, np.ndarray] = {}
    for canon, cands in NAME_CANDIDATES.items():
        for c in cands:
            if c in pts:
                points[canon] = pts[c]
                break
    missing = [c for c in NAME_CANDIDATES if c not in points and c != "spine"]
    if missing:
        raise MotionFormatError(f"{asf_path}: no bones for {', '.join(missing)} "
                                f"(expected CMU bone names such as lfemur, ltibia, lhumerus)")
    try:
        return retarget_points(points, fps, skeleton, name=Path(amc_path).stem)
    except ValueError as exc:
        raise MotionFormatError(f"{amc_path}: {exc}") from None
