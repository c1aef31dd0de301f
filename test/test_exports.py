"""SynthesizedMotion: validation, and its NPZ / JSON / CSV / BVH exports."""

from __future__ import annotations

import csv
import json
import math
import zipfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from demo_motion import demo_synthesized_motion

from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.motion.skeleton import JOINT_NAMES, Skeleton
from ltl_human_motion.motion.types import Motion
from ltl_human_motion.planning.exports import (
    bvh_rotations,
    load_json,
    load_npz,
    npz_bytes,
    save,
    save_bvh,
    save_csv,
    save_json,
    save_npz,
    to_dict,
)
from ltl_human_motion.planning.result import SynthesizedMotion, TaskSegment
from ltl_human_motion.scene import cell_by_name


@pytest.fixture(scope="module")
def synth() -> SynthesizedMotion:
    s = demo_synthesized_motion(cell_by_name("paper_cell"), fps=30.0)
    s.stats = replace(s.stats, nodes_expanded=np.int64(42), realism={"ratio": float("inf")})
    s.verification.update({"passed": np.bool_(True), "collision": {"frames": 0}})
    # Let O1 follow the right hand for the last frames (a carried object).
    s.objects["O1"][-10:] = s.positions[-10:, JOINT_NAMES.index("r_hand")]
    return s


def _assert_same(a: SynthesizedMotion, b: SynthesizedMotion) -> None:
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.root_yaw, b.root_yaw)
    np.testing.assert_array_equal(a.task_index, b.task_index)
    assert a.fps == b.fps and a.motion.skeleton.stature == b.motion.skeleton.stature
    assert a.motion.name == b.motion.name
    assert sorted(a.objects) == sorted(b.objects)
    for k in a.objects:
        np.testing.assert_array_equal(a.objects[k], b.objects[k])
    assert a.spec == b.spec and a.sequence == b.sequence and a.seed == b.seed
    assert [s.to_dict() for s in a.timeline] == [s.to_dict() for s in b.timeline]


def test_active_task_and_accessors(synth):
    seg = synth.timeline[0]
    assert synth.active_task(0) is None
    assert synth.active_task(seg.start_frame) == "assemble(R1)"
    assert synth.active_segment(seg.start_frame) is seg
    assert synth.active_segment(0) is None
    assert synth.frame_at(1.0) == 30 and synth.frame_at(1e9) == synth.n_frames - 1
    assert set(synth.objects_at(3)) == {"O1", "O2"}
    with pytest.raises(ValueError, match="frame must be an integer"):
        synth.active_task(synth.n_frames)


def test_validation_of_synthesized_motion():
    m = Motion(np.repeat(Skeleton().rest_positions()[None], 5, axis=0), 30.0)
    ok = dict(motion=m, root_yaw=np.zeros(5), task_index=np.array([-1, 0, 0, 1, 1]),
              timeline=[TaskSegment("grasp(O1)", 1, 3), TaskSegment("walk(R1)", 3, 5)],
              sequence=["grasp(O1)", "walk(R1)"])
    SynthesizedMotion(**ok)
    with pytest.raises(ValueError, match=r"root_yaw must have shape \(5,\)"):
        SynthesizedMotion(**{**ok, "root_yaw": np.zeros(4)})
    with pytest.raises(ValueError, match=r"task_index values must lie in \[-1, 1\]"):
        SynthesizedMotion(**{**ok, "task_index": np.array([0, 0, 2, 0, 0])})
    with pytest.raises(ValueError, match="int array"):
        SynthesizedMotion(**{**ok, "task_index": np.zeros(5)})
    with pytest.raises(ValueError, match=r"objects\['O1'\] must have shape \(5, 3\)"):
        SynthesizedMotion(**{**ok, "objects": {"O1": np.zeros((4, 3))}})
    with pytest.raises(ValueError, match="ends at frame 6 > 5"):
        SynthesizedMotion(**{**ok, "timeline": [TaskSegment("grasp(O1)", 1, 6)]})
    with pytest.raises(ValueError, match="start_frame <= end_frame"):
        TaskSegment("grasp(O1)", 3, 1)
    with pytest.raises(ValueError, match=r"target must have shape \(3,\)"):
        TaskSegment("grasp(O1)", 1, 3, target=[1.0, 2.0])


def test_npz_round_trip_and_determinism(synth, tmp_path):
    a, b = tmp_path / "a.npz", tmp_path / "sub" / "b.npz"
    save_npz(synth, a)
    save_npz(synth, b)
    assert a.read_bytes() == b.read_bytes() == npz_bytes(synth)
    with zipfile.ZipFile(a) as zf:
        assert [i.filename for i in zf.infolist()] == [
            "meta.npy", "positions.npy", "root_yaw.npy", "task_index.npy", "objects.npy"]
        assert {i.date_time for i in zf.infolist()} == {(1980, 1, 1, 0, 0, 0)}
    back = load_npz(a)
    _assert_same(synth, back)
    assert back.stats.nodes_expanded == 42 and math.isinf(back.stats.realism["ratio"])
    assert back.verification["passed"] is True
    np.testing.assert_array_equal(back.timeline[0].target, synth.timeline[0].target)
    # Loads without pickles; no temporary files are left behind.
    with np.load(a, allow_pickle=False) as z:
        assert z["positions"].shape == synth.positions.shape
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.npz", "sub"]


def test_npz_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a zip")
    with pytest.raises(MotionFormatError, match=r"bad\.npz"):
        load_npz(bad)
    with pytest.raises(MotionFormatError, match=r"missing\.npz"):
        load_npz(tmp_path / "missing.npz")


def test_json_round_trip_is_standard_json(synth, tmp_path):
    path = tmp_path / "m.json"
    save_json(synth, path)
    text = path.read_text()

    def reject(token):
        raise AssertionError(f"non-standard JSON constant {token}")
    data = json.loads(text, parse_constant=reject)
    assert data["stats"]["realism"]["ratio"] is None        # inf -> null
    assert data["joint_names"] == list(JOINT_NAMES)
    back = load_json(path)
    _assert_same(synth, back)
    save_json(synth, tmp_path / "m2.json")
    assert (tmp_path / "m2.json").read_text() == text


def test_a_stats_field_the_format_does_not_know_names_the_file(synth, tmp_path):
    data = json.loads(json.dumps(to_dict(synth)))
    data["stats"]["planning_s"] = 1.25
    path = tmp_path / "odd.json"
    path.write_text(json.dumps(data))
    with pytest.raises(MotionFormatError, match=r"odd\.json.*unknown stats field.*planning_s"):
        load_json(path)


def test_csv_columns_and_values(synth, tmp_path):
    path = tmp_path / "m.csv"
    save_csv(synth, path)
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], rows[1:]
    assert header[:5] == ["frame", "time", "task_index", "task", "root_yaw"]
    assert header[5:8] == ["pelvis_x", "pelvis_y", "pelvis_z"]
    assert header[-3:] == ["O2_x", "O2_y", "O2_z"]
    assert len(body) == synth.n_frames
    values = np.array([[float(v) for v in r[5:5 + 3 * len(JOINT_NAMES)]] for r in body])
    np.testing.assert_allclose(values.reshape(synth.positions.shape), synth.positions,
                               atol=1e-6)
    start = synth.timeline[0].start_frame
    assert body[start][3] == "assemble(R1)" and body[0][3] == ""


def _parse_bvh(path: Path):
    """A minimal, independent BVH reader: hierarchy, offsets, channels, frames."""
    tokens = path.read_text().split()
    i = 0
    joints = []          # (name, parent, offset, channels)
    stack: list[int] = []
    last = -1
    while tokens[i] != "MOTION":
        tok = tokens[i]
        if tok in ("ROOT", "JOINT"):
            joints.append([tokens[i + 1], stack[-1] if stack else -1, None, []])
            last = len(joints) - 1
            i += 2
        elif tok == "End":
            last = None
            i += 2
        elif tok == "{":
            stack.append(last)
            i += 1
        elif tok == "}":
            stack.pop()
            i += 1
        elif tok == "OFFSET":
            if last is not None:
                joints[last][2] = np.array([float(t) for t in tokens[i + 1:i + 4]])
            i += 4
        elif tok == "CHANNELS":
            n = int(tokens[i + 1])
            joints[last][3] = tokens[i + 2:i + 2 + n]
            i += 2 + n
        else:
            i += 1
    n_frames = int(tokens[i + 2])
    frame_time = float(tokens[i + 5])
    values = np.array([float(t) for t in tokens[i + 6:]]).reshape(n_frames, -1)
    return joints, values, frame_time


def _rot(axis: str, deg: np.ndarray) -> np.ndarray:
    a = np.radians(deg)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    if axis == "X":
        m = [[o, z, z], [z, c, -s], [z, s, c]]
    elif axis == "Y":
        m = [[c, z, s], [z, o, z], [-s, z, c]]
    else:
        m = [[c, -s, z], [s, c, z], [z, z, o]]
    return np.moveaxis(np.array(m), (0, 1), (-2, -1))


def _bvh_positions(path: Path) -> tuple[list[str], np.ndarray, float]:
    joints, values, frame_time = _parse_bvh(path)
    T = len(values)
    glob_rot = [None] * len(joints)
    glob_pos = np.zeros((T, len(joints), 3))
    col = 0
    for j, (_, parent, offset, channels) in enumerate(joints):
        local_pos = np.broadcast_to(offset, (T, 3)).copy()
        local_rot = np.broadcast_to(np.eye(3), (T, 3, 3)).copy()
        for ch in channels:
            v = values[:, col]
            col += 1
            if ch.endswith("position"):
                local_pos[:, "XYZ".index(ch[0])] = v + offset["XYZ".index(ch[0])]
            else:
                local_rot = local_rot @ _rot(ch[0], v)
        if parent < 0:
            glob_rot[j] = local_rot
            glob_pos[:, j] = local_pos
        else:
            glob_rot[j] = glob_rot[parent] @ local_rot
            glob_pos[:, j] = glob_pos[:, parent] + np.einsum("tij,tj->ti", glob_rot[parent],
                                                             local_pos)
    return [j[0] for j in joints], glob_pos, frame_time


def _tumbling(synth: SynthesizedMotion) -> Motion:
    """The synthetic motion turned about a tilting axis (poses far from upright)."""
    T = synth.n_frames
    ang = np.linspace(0.0, 2.5, T)
    axis = np.stack([np.cos(ang), np.sin(ang), 0.3 * np.ones(T)], -1)
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    K = np.zeros((T, 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    K -= np.swapaxes(K, 1, 2)
    R = np.eye(3) + np.sin(3 * ang)[:, None, None] * K + \
        (1 - np.cos(3 * ang))[:, None, None] * (K @ K)
    c = synth.positions[:, :1]
    return Motion(np.einsum("tij,tkj->tki", R, synth.positions - c) + c + [0, 0, 1.0],
                  synth.fps, synth.motion.skeleton, "tumbling")


@pytest.mark.parametrize("up, scale", [("y", 1.0), ("z", 100.0)])
def test_bvh_round_trip_with_independent_fk(synth, tmp_path, up, scale):
    for motion in (synth, _tumbling(synth)):
        path = tmp_path / f"m_{up}.bvh"
        err = save_bvh(motion, path, up=up, scale=scale)
        assert err < 1e-4
        names, pos, frame_time = _bvh_positions(path)
        assert names == list(JOINT_NAMES)
        assert frame_time == pytest.approx(1.0 / synth.fps)
        pos = pos / scale
        if up == "y":                                    # file (x, y, z) = ours (y, z, x)
            pos = np.stack([pos[..., 2], pos[..., 0], pos[..., 1]], axis=-1)
        ref = motion.positions if isinstance(motion, Motion) else motion.motion.positions
        assert np.max(np.linalg.norm(pos - ref, axis=-1)) < 0.003


def test_bvh_rest_frame_is_upright(synth, tmp_path):
    rest = Motion(Skeleton().rest_positions()[None], 30.0)
    path = tmp_path / "rest.bvh"
    save_bvh(rest, path)
    joints, values, _ = _parse_bvh(path)
    np.testing.assert_allclose(values[0, 3:], 0.0, atol=1e-6)         # no rotation at rest
    neck = next(j for j in joints if j[0] == "neck")
    toe = next(j for j in joints if j[0] == "l_toe")
    assert neck[2][1] > 0                                   # y up: neck above the chest
    assert toe[2][2] > 0 and abs(toe[2][0]) < 1e-9          # the feet point along +z


def test_bvh_loads_back_with_the_project_bvh_reader(synth, tmp_path):
    bvh = pytest.importorskip("ltl_human_motion.motion.bvh")
    path = tmp_path / "m.bvh"
    save_bvh(synth, path)
    skel, pos, fps = bvh.load_raw(path)
    assert fps == pytest.approx(synth.fps)
    idx = [list(skel.names).index(n) for n in JOINT_NAMES]
    assert np.max(np.linalg.norm(pos[:, idx] - synth.positions, axis=-1)) < 0.003


def test_bvh_rotations_are_rotations_that_carry_the_rest_offsets(synth):
    """The old public name of the joints' world rotations (motion.bone_rotations)."""
    G = bvh_rotations(synth.positions, synth.motion.skeleton)
    assert G.shape == (*synth.positions.shape[:2], 3, 3)
    np.testing.assert_allclose(G @ np.swapaxes(G, -1, -2), np.broadcast_to(np.eye(3), G.shape),
                               atol=1e-9)
    rest = synth.motion.skeleton.rest_positions()
    j, k = JOINT_NAMES.index("l_hip"), JOINT_NAMES.index("l_knee")
    offset = synth.positions[:, k] - synth.positions[:, j]
    np.testing.assert_allclose(G[:, j] @ (rest[k] - rest[j]), offset, atol=1e-6)


def test_bvh_rejects_bad_arguments(synth, tmp_path):
    with pytest.raises(ValueError, match="up must be"):
        save_bvh(synth, tmp_path / "x.bvh", up="x")
    with pytest.raises(ValueError, match="scale must be positive"):
        save_bvh(synth, tmp_path / "x.bvh", scale=0.0)
    assert not (tmp_path / "x.bvh").exists()


def test_save_dispatches_on_suffix_and_keeps_old_file_on_failure(synth, tmp_path,
                                                                  monkeypatch):
    for suffix in ("npz", "json", "csv", "bvh"):
        save(synth, tmp_path / f"m.{suffix}")
        assert (tmp_path / f"m.{suffix}").stat().st_size > 0
    with pytest.raises(ValueError, match=r"unknown export format '\.txt'"):
        save(synth, tmp_path / "m.txt")
    target = tmp_path / "m.npz"
    before = target.read_bytes()

    def boom(arr):
        raise RuntimeError("disk on fire")
    import ltl_human_motion.planning.exports as exports
    monkeypatch.setattr(exports, "_npy_bytes", boom)
    with pytest.raises(RuntimeError, match="disk on fire"):
        save_npz(synth, target)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.bvh", "m.csv", "m.json",
                                                          "m.npz"]


def test_bvh_translations_reproduce_non_rigid_motion(synth, tmp_path):
    pos = synth.positions.copy()
    e, w, h = (JOINT_NAMES.index(n) for n in ("r_elbow", "r_wrist", "r_hand"))
    stretch = 0.04 * np.sin(np.linspace(0, np.pi, len(pos)))[:, None]    # up to 4 cm
    fore = pos[:, w] - pos[:, e]
    shift = stretch * fore / np.linalg.norm(fore, axis=-1, keepdims=True)
    pos[:, w] += shift
    pos[:, h] += shift
    pos[:, JOINT_NAMES.index("l_hip")] += [0.0, 0.0, 0.02]           # a deforming pelvis
    motion = Motion(pos, synth.fps, synth.motion.skeleton)
    rigid_err = save_bvh(motion, tmp_path / "r.bvh")
    assert rigid_err > 0.01
    err = save_bvh(motion, tmp_path / "t.bvh", translations=True)
    assert err < 1e-4
    names, got, _ = _bvh_positions(tmp_path / "t.bvh")
    got = np.stack([got[..., 2], got[..., 0], got[..., 1]], axis=-1)
    assert names == list(JOINT_NAMES)
    assert np.max(np.linalg.norm(got - pos, axis=-1)) < 1e-4
