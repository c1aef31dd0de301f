"""Loaders: real CMU BVH files, DeepMimic clips, hand-written ASF/AMC, npz; corrupt files."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.motion import asfamc, bvh, deepmimic, npz
from ltl_human_motion.motion.rotations import yaw_from_positions
from ltl_human_motion.motion.skeleton import JOINT_INDEX, PARENTS, Skeleton

BVH_DIR = Path("/usr/share/assimp/models/BVH")
CMU_FILES = ["01_01.bvh", "01_03.bvh", "Boxing_Toes.bvh"]
needs_bvh = pytest.mark.skipif(not (BVH_DIR / "01_01.bvh").is_file(),
                               reason="Debian assimp-testmodels not installed")


def _bone_error(positions: np.ndarray, skeleton: Skeleton) -> float:
    par = np.array(PARENTS)
    child = np.arange(1, len(PARENTS))
    lengths = np.linalg.norm(positions[:, child] - positions[:, par[child]], axis=-1)
    return float(np.abs(lengths - skeleton.bone_lengths()[child]).max())


def _header_frames(path: Path) -> tuple[int, float]:
    text = path.read_text()
    n = int(re.search(r"Frames:\s*(\d+)", text).group(1))
    dt = float(re.search(r"Frame Time:\s*([0-9.eE+-]+)", text).group(1))
    return n, dt


# ------------------------------------------------------------------------------ BVH
@needs_bvh
@pytest.mark.parametrize("name", CMU_FILES)
def test_cmu_bvh_loads_retargeted(name: str) -> None:
    path = BVH_DIR / name
    m = bvh.load(path)
    n, dt = _header_frames(path)
    assert m.n_frames == n
    assert m.fps == pytest.approx(1.0 / dt)
    assert _bone_error(m.positions, m.skeleton) < 1e-9
    feet = [JOINT_INDEX[j] for j in ("l_ankle", "l_toe", "r_ankle", "r_toe")]
    rest = m.skeleton.rest_positions()
    # grounded: the lowest foot joint over the clip sits exactly at its rest height
    assert np.min(m.positions[:, feet, 2] - rest[feet, 2]) == pytest.approx(0.0, abs=1e-9)
    # upright at the start: head well above the pelvis, feet below
    p0 = m.positions[0]
    assert p0[JOINT_INDEX["head"], 2] - p0[0, 2] > 0.3 * m.skeleton.stature
    assert p0[JOINT_INDEX["l_ankle"], 2] < p0[JOINT_INDEX["l_knee"], 2] < p0[0, 2]
    # left is left: the left hip is on the body's left of its heading
    yaw = yaw_from_positions(p0)
    lat = p0[JOINT_INDEX["l_hip"], :2] - p0[JOINT_INDEX["r_hip"], :2]
    assert np.dot(lat, [-np.sin(yaw), np.cos(yaw)]) > 0


@needs_bvh
def test_bvh_stature_scales_body() -> None:
    small = bvh.load(BVH_DIR / "01_01.bvh", skeleton=Skeleton(1.55))
    big = bvh.load(BVH_DIR / "01_01.bvh", skeleton=Skeleton(1.95))
    h_small = small.positions[0, JOINT_INDEX["head"], 2]
    h_big = big.positions[0, JOINT_INDEX["head"], 2]
    assert h_big / h_small == pytest.approx(1.95 / 1.55, rel=0.02)


@needs_bvh
def test_bvh_save_load_round_trip(tmp_path: Path) -> None:
    m = bvh.load(BVH_DIR / "01_03.bvh")
    sub = type(m)(m.positions[:240], m.fps, m.skeleton, "clip")
    out = tmp_path / "clip.bvh"
    bvh.save(sub, out, translations=True)         # exact: the clip is not rigid
    back = bvh.load(out)
    assert back.n_frames == sub.n_frames
    assert back.fps == pytest.approx(sub.fps, rel=1e-6)
    diff = back.positions - sub.positions
    # loading grounds the clip again (its lowest foot on the floor): a constant lift only
    assert np.abs(diff[..., :2]).max() < 2e-3
    assert np.abs(diff[..., 2] - diff[..., 2].mean()).max() < 2e-3


# A LAFAN1-style hierarchy (names as in the LAFAN1 takes), offsets in centimetres, Y up.
LAFAN_JOINTS = [  # name, parent, offset
    ("Hips", None, (0, 90, 0)),
    ("LeftUpLeg", "Hips", (10, -5, 0)), ("LeftLeg", "LeftUpLeg", (0, -40, 0)),
    ("LeftFoot", "LeftLeg", (0, -40, 0)), ("LeftToe", "LeftFoot", (0, -5, 12)),
    ("RightUpLeg", "Hips", (-10, -5, 0)), ("RightLeg", "RightUpLeg", (0, -40, 0)),
    ("RightFoot", "RightLeg", (0, -40, 0)), ("RightToe", "RightFoot", (0, -5, 12)),
    ("Spine", "Hips", (0, 10, 0)), ("Spine1", "Spine", (0, 10, 0)),
    ("Spine2", "Spine1", (0, 10, 0)), ("Neck", "Spine2", (0, 15, 0)),
    ("Head", "Neck", (0, 10, 0)),
    ("LeftShoulder", "Spine2", (5, 12, 0)), ("LeftArm", "LeftShoulder", (12, 0, 0)),
    ("LeftForeArm", "LeftArm", (0, -28, 0)), ("LeftHand", "LeftForeArm", (0, -25, 0)),
    ("RightShoulder", "Spine2", (-5, 12, 0)), ("RightArm", "RightShoulder", (-12, 0, 0)),
    ("RightForeArm", "RightArm", (0, -28, 0)), ("RightHand", "RightForeArm", (0, -25, 0)),
]


def _lafan_text(frames: np.ndarray) -> str:
    out = ["HIERARCHY"]

    def emit(name: str, depth: int) -> None:
        pad = "  " * depth
        parent = next(p for n, p, _ in LAFAN_JOINTS if n == name)
        off = next(o for n, _, o in LAFAN_JOINTS if n == name)
        out.append(f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}")
        out.append(pad + "{")
        out.append(f"{pad}  OFFSET {off[0]} {off[1]} {off[2]}")
        if parent is None:
            out.append(f"{pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation "
                       "Xrotation")
        else:
            out.append(f"{pad}  CHANNELS 3 Zrotation Yrotation Xrotation")
        kids = [n for n, p, _ in LAFAN_JOINTS if p == name]
        for k in kids:
            emit(k, depth + 1)
        if not kids:
            out.extend([f"{pad}  End Site", pad + "  {", f"{pad}    OFFSET 0 -5 0", pad + "  }"])
        out.append(pad + "}")

    emit("Hips", 0)
    out += ["MOTION", f"Frames: {len(frames)}", "Frame Time: 0.0333333"]
    out += [" ".join(f"{v:.4f}" for v in row) for row in frames]
    return "\n".join(out) + "\n"


def test_lafan_style_names_and_rotation(tmp_path: Path) -> None:
    n_ch = 6 + 3 * (len(LAFAN_JOINTS) - 1)
    frames = np.zeros((3, n_ch))
    frames[:, 0:3] = [[0, 90, 0], [0, 90, 10], [0, 90, 20]]   # walk forward along BVH +z
    path = tmp_path / "lafan_like.bvh"
    path.write_text(_lafan_text(frames))
    m = bvh.load(path)
    assert m.n_frames == 3 and m.fps == pytest.approx(30.0, rel=1e-4)
    assert _bone_error(m.positions, m.skeleton) < 1e-9
    # BVH +z (forward) becomes our +x: the pelvis moves along +x and faces +x
    assert np.all(np.diff(m.positions[:, 0, 0]) > 0)
    assert yaw_from_positions(m.positions[0]) == pytest.approx(0.0, abs=1e-6)
    # a 90 degree yaw of the root (Y rotation in BVH) turns the body to face +y
    frames[:, 4] = 90.0
    path.write_text(_lafan_text(frames))
    turned = bvh.load(path)
    assert yaw_from_positions(turned.positions[0]) == pytest.approx(np.pi / 2, abs=1e-6)


@needs_bvh
def test_truncated_bvh_names_file_and_frame(tmp_path: Path) -> None:
    lines = (BVH_DIR / "01_01.bvh").read_text().splitlines()
    bad = tmp_path / "truncated.bvh"
    bad.write_text("\n".join(lines[:400]) + "\n")
    with pytest.raises(MotionFormatError, match=r"truncated\.bvh.*frame \d+.*truncated"):
        bvh.load(bad)
    # a cut in the middle of a frame line: wrong number of channel values on that line
    bad.write_text("\n".join(lines[:399]) + "\n" + lines[399][: len(lines[399]) // 2] + "\n")
    with pytest.raises(MotionFormatError, match=r"truncated\.bvh: line 400: frame \d+"):
        bvh.load(bad)


@pytest.mark.parametrize("mutate, message", [
    (lambda t: t.replace("Frame Time: 0.0333333", "Frame Time: fast"), r"line \d+: frame time"),
    (lambda t: t.replace("CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 4 Zrotation",
                         1), r"line \d+: CHANNELS 4"),
    (lambda t: t.replace("MOTION", ""), r"line \d+: unexpected .Frames:. in HIERARCHY"),
    (lambda t: t[: t.index("MOTION")], r"no MOTION section"),
    (lambda t: t.replace("HIERARCHY", "HIERARCH"), r"line 1: expected 'HIERARCHY'"),
    (lambda t: t.replace("\n0.0000 90.0000", "\n0.0000 nan", 1), r"line \d+: frame 0"),
    (lambda t: t.replace("0.0000 90.0000 10.0000", "0.0000 abc 10.0000"), r"frame 1: not a number"),
])
def test_corrupt_bvh_errors(tmp_path: Path, mutate, message: str) -> None:
    n_ch = 6 + 3 * (len(LAFAN_JOINTS) - 1)
    frames = np.zeros((3, n_ch))
    frames[:, 0:3] = [[0, 90, 0], [0, 90, 10], [0, 90, 20]]
    path = tmp_path / "broken.bvh"
    path.write_text(mutate(_lafan_text(frames)))
    with pytest.raises(MotionFormatError, match=r"broken\.bvh.*" + message):
        bvh.load(path)


def test_binary_garbage_is_a_format_error(tmp_path: Path) -> None:
    path = tmp_path / "junk.bvh"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(MotionFormatError, match=r"junk\.bvh"):
        bvh.load(path)


# ------------------------------------------------------------------------- DeepMimic
def test_deepmimic_walk_clips_load() -> None:
    for rel in deepmimic.DEFAULT_GAIT_CLIPS:
        path = deepmimic.motions_dir() / rel
        frames = json.loads(path.read_text())["Frames"]
        m = deepmimic.load(path)
        assert m.n_frames == len(frames)
        assert m.fps == pytest.approx(1.0 / frames[0][0])
        assert _bone_error(m.positions, m.skeleton) < 1e-9
        _, _, loop = deepmimic.load_raw(path)
        assert loop


def test_deepmimic_quaternion_order_and_axes() -> None:
    """Root quaternions are (w, x, y, z) and the clip is y up: the body must face the way it
    walks, stand upright, and the left-turn clip must turn left (positive yaw)."""
    walk = deepmimic.load(deepmimic.motions_dir() / "walker/0walk_forward.txt")
    p = walk.positions
    travel = p[-1, 0, :2] - p[0, 0, :2]
    heading = np.mean(np.unwrap(yaw_from_positions(p)))
    assert np.arctan2(travel[1], travel[0]) == pytest.approx(heading, abs=np.deg2rad(15))
    assert np.all(p[:, JOINT_INDEX["head"], 2] > p[:, 0, 2] + 0.3)
    for rel, sign in (("walker/turn_left1.txt", 1.0), ("walker/turn_right1.txt", -1.0)):
        m = deepmimic.load(deepmimic.motions_dir() / rel)
        yaw = np.unwrap(yaw_from_positions(m.positions))
        assert sign * (yaw[-1] - yaw[0]) > np.deg2rad(20)


@pytest.mark.parametrize("mutate, message", [
    (lambda d: d["Frames"][3].pop(), r"frame 3: expected 44 numbers, found 43"),
    (lambda d: d["Frames"][2].__setitem__(5, "x"), r"frame 2: contains a value"),
    (lambda d: d["Frames"][1][4:8].__init__([0, 0, 0, 0]) or d["Frames"][1].__setitem__(
        slice(4, 8), [0, 0, 0, 0]), r"frame 1: quaternion of zero length"),
    (lambda d: d.pop("Frames"), r"expected a JSON object with a 'Frames' list"),
])
def test_corrupt_deepmimic_errors(tmp_path: Path, mutate, message: str) -> None:
    data = json.loads((deepmimic.motions_dir() / "walker/0walk_forward.txt").read_text())
    mutate(data)
    path = tmp_path / "clip.txt"
    path.write_text(json.dumps(data))
    with pytest.raises(MotionFormatError, match=r"clip\.txt: " + message):
        deepmimic.load(path)


def test_truncated_deepmimic_names_line(tmp_path: Path) -> None:
    text = (deepmimic.motions_dir() / "walker/0walk_forward.txt").read_text()
    path = tmp_path / "cut.txt"
    path.write_text(text[: len(text) // 2])
    with pytest.raises(MotionFormatError, match=r"cut\.txt: line \d+: not valid DeepMimic JSON"):
        deepmimic.load(path)


# ------------------------------------------------------------------------------- npz
def test_npz_round_trip_and_errors(tmp_path: Path) -> None:
    m = deepmimic.load(deepmimic.motions_dir() / "humanoid3d_walk.txt")
    path = tmp_path / "walk.npz"
    npz.save(m, path)
    back = npz.load(path)
    np.testing.assert_array_equal(back.positions, m.positions)
    assert back.fps == m.fps and back.name == m.name
    other = npz.load(path, skeleton=Skeleton(1.6))
    assert _bone_error(other.positions, other.skeleton) < 1e-9
    bad = tmp_path / "bad.npz"
    pos = m.positions.copy()
    pos[7, 3, 1] = np.nan
    np.savez(bad, positions=pos, fps=30.0)
    with pytest.raises(MotionFormatError, match=r"bad\.npz: frame 7"):
        npz.load(bad)
    np.savez(bad, positions=pos[:, :, :2], fps=30.0)
    with pytest.raises(MotionFormatError, match=r"bad\.npz: 'positions' must have shape"):
        npz.load(bad)
    bad.write_bytes(b"PK\x03\x04 not really a zip")
    with pytest.raises(MotionFormatError, match=r"bad\.npz: not a readable"):
        npz.load(bad)


# --------------------------------------------------------------------------- ASF/AMC
_BONES = [  # name, parent, direction (y up, character faces +z, +x is its left), length
    ("lhipjoint", "root", (1, -0.5, 0), 2.0), ("lfemur", "lhipjoint", (0, -1, 0), 7.0),
    ("ltibia", "lfemur", (0, -1, 0), 7.0), ("lfoot", "ltibia", (0, -0.3, 1), 2.5),
    ("rhipjoint", "root", (-1, -0.5, 0), 2.0), ("rfemur", "rhipjoint", (0, -1, 0), 7.0),
    ("rtibia", "rfemur", (0, -1, 0), 7.0), ("rfoot", "rtibia", (0, -0.3, 1), 2.5),
    ("lowerback", "root", (0, 1, 0), 2.0), ("upperback", "lowerback", (0, 1, 0), 2.0),
    ("thorax", "upperback", (0, 1, 0), 2.0), ("lowerneck", "thorax", (0, 1, 0), 1.5),
    ("upperneck", "lowerneck", (0, 1, 0), 1.5), ("head", "upperneck", (0, 1, 0), 1.5),
    ("lclavicle", "thorax", (1, 0.3, 0), 3.0), ("lhumerus", "lclavicle", (0, -1, 0), 5.0),
    ("lradius", "lhumerus", (0, -1, 0), 4.0), ("lwrist", "lradius", (0, -1, 0), 1.0),
    ("rclavicle", "thorax", (-1, 0.3, 0), 3.0), ("rhumerus", "rclavicle", (0, -1, 0), 5.0),
    ("rradius", "rhumerus", (0, -1, 0), 4.0), ("rwrist", "rradius", (0, -1, 0), 1.0),
]


def _write_asf(path: Path) -> None:
    out = [":version 1.10", ":name test", ":units", "  mass 1.0", "  length 0.45",
           "  angle deg", ":root", "   order TX TY TZ RX RY RZ", "   axis XYZ",
           "   position 0 0 0", "   orientation 0 0 0", ":bonedata"]
    for i, (name, _, d, length) in enumerate(_BONES, 1):
        out += ["  begin", f"     id {i}", f"     name {name}",
                f"     direction {d[0]} {d[1]} {d[2]}", f"     length {length}",
                "     axis 0 0 0 XYZ", "     dof rx ry rz",
                "     limits (-180 180)", "            (-180 180)", "            (-180 180)",
                "  end"]
    out += [":hierarchy", "  begin"]
    children: dict[str, list[str]] = {}
    for name, parent, _, _ in _BONES:
        children.setdefault(parent, []).append(name)
    out += [f"    {p} {' '.join(c)}" for p, c in children.items()]
    out += ["  end"]
    path.write_text("\n".join(out) + "\n")


def _write_amc(path: Path, frames: list[dict[str, list[float]]]) -> None:
    out = ["# hand-written test motion", ":FULLY-SPECIFIED", ":DEGREES"]
    for i, fr in enumerate(frames, 1):
        out.append(str(i))
        out.append("root " + " ".join(str(v) for v in fr.get("root", [0, 20, 0, 0, 0, 0])))
        for name, *_ in _BONES:
            out.append(f"{name} " + " ".join(str(v) for v in fr.get(name, [0, 0, 0])))
    path.write_text("\n".join(out) + "\n")


def test_asfamc_hand_written_forward_kinematics(tmp_path: Path) -> None:
    asf, amc = tmp_path / "t.asf", tmp_path / "t.amc"
    _write_asf(asf)
    _write_amc(amc, [{}, {"lfemur": [90, 0, 0]}, {"root": [0, 20, 5, 0, 90, 0]}])
    _, pts = asfamc.load_raw(asf, amc)
    assert pts["lfemur"].shape == (3, 3)
    # frame 1: the thigh rotated +90 degrees about the ASF x axis: (0, -1, 0) -> (0, 0, -1),
    # i.e. backwards along the character's -z; in our frame (z, x, y) that is -x
    thigh = pts["lfemur"][1] - pts["lhipjoint"][1]
    np.testing.assert_allclose(thigh, [-7.0, 0.0, 0.0], atol=1e-9)
    # frame 0: a straight leg hangs down in our z-up frame
    np.testing.assert_allclose(pts["lfemur"][0] - pts["lhipjoint"][0], [0, 0, -7.0], atol=1e-9)
    # frame 2: the root moved 5 units along its forward axis (+z ASF -> +x ours) and yawed 90
    np.testing.assert_allclose(pts["root"][2], [5.0, 0.0, 20.0], atol=1e-9)
    hips = pts["lhipjoint"][2] - pts["root"][2]
    # a +90 degree yaw about the up axis turns the body left: its left hip points backwards
    assert hips[0] < -0.9 * np.linalg.norm(hips[:2])

    m = asfamc.load(asf, amc, fps=120.0)
    assert m.n_frames == 3 and m.fps == 120.0
    assert _bone_error(m.positions, m.skeleton) < 1e-9
    assert "dm_control" not in sys.modules


def test_asfamc_corrupt_files(tmp_path: Path) -> None:
    asf, amc = tmp_path / "t.asf", tmp_path / "t.amc"
    _write_asf(asf)
    _write_amc(amc, [{}, {}, {}])
    lines = amc.read_text().splitlines()
    amc.write_text("\n".join(lines[:-5]) + "\n")          # last frame lacks bones
    with pytest.raises(MotionFormatError, match=r"t\.amc: line \d+: frame 3 lacks bone"):
        asfamc.load(asf, amc)
    lines[10] = lines[10].split()[0] + " 1 2 x"
    amc.write_text("\n".join(lines) + "\n")
    with pytest.raises(MotionFormatError, match=r"t\.amc: line 11: frame 1: not a number"):
        asfamc.load(asf, amc)
    text = asf.read_text()
    asf.write_text(text.replace("length 7.0", "length seven", 1))
    with pytest.raises(MotionFormatError, match=r"t\.asf: line \d+: malformed"):
        asfamc.load(asf, amc)
    asf.write_text(text[: text.index(":hierarchy") - 10])
    with pytest.raises(MotionFormatError, match=r"t\.asf: line \d+: bone not closed"):
        asfamc.load(asf, amc)
