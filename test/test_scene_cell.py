"""Cell loading: the paper cell, frames, validation errors, footprints."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from ltl_human_motion.errors import CellError
from ltl_human_motion.scene import (
    Box,
    Cylinder,
    MeshShape,
    cell_by_name,
    cell_from_yaml,
    cell_search_paths,
    load_cell,
)

CONFIG = Path(__file__).resolve().parents[1] / "config"
PAPER_TEXT = (CONFIG / "paper_cell.yaml").read_text()


@pytest.fixture(scope="module")
def paper():
    return cell_by_name("paper_cell")


def _yup(p):
    """Independent z-up -> y-up conversion: (x, y, z) -> (x, z, -y)."""
    x, y, z = p
    return [x, z, -y]


def _to_paper_frame(data: dict) -> dict:
    """Rewrite a z-up cell mapping in the paper's y-up frame."""
    out = dict(data, frame="paper_yup")

    def bounds(spec):
        lo, hi = np.array(_yup(spec["lo"])), np.array(_yup(spec["hi"]))
        return {**spec, "lo": np.minimum(lo, hi).tolist(), "hi": np.maximum(lo, hi).tolist()}

    def shape(spec):
        s = dict(spec)
        s["position"] = _yup(s["position"])
        if s.get("shape") == "box":
            sx, sy, sz = s["size"]
            s["size"] = [sx, sz, sy]
        if "grasp_points" in s:
            s["grasp_points"] = [_yup(g) for g in s["grasp_points"]]
        return s

    out["workspace"] = bounds(data["workspace"])
    out["objects"] = {k: shape(v) for k, v in data["objects"].items()}
    out["regions"] = {k: bounds(v) for k, v in data["regions"].items()}
    out["obstacles"] = {k: {**v, "parts": [shape(p) for p in v["parts"]]}
                        for k, v in data["obstacles"].items()}
    return out


def test_paper_cell_matches_the_paper_numbers(paper):
    # Sec. IV, y up: O1 [-1, 0.2, 1.0], O2 [-1.5, 0.3, -1.2], R1 = [0.9, 1.1]^3.
    np.testing.assert_allclose(paper.object("O1").position, [-1.0, -1.0, 0.2])
    np.testing.assert_allclose(paper.object("O2").position, [-1.5, 1.2, 0.3])
    r1 = paper.region("R1")
    np.testing.assert_allclose(r1.lo, [0.9, -1.1, 0.9])
    np.testing.assert_allclose(r1.hi, [1.1, -0.9, 1.1])
    np.testing.assert_allclose(r1.center, [1.0, -1.0, 1.0])
    assert paper.start_region.name == "R0" and paper.final_region is r1
    assert paper.start_region.contains(np.array([0.0, 0.0, 0.05]))
    assert paper.shorthands == {"assemble": (("R",), "leftHand(R) & rightHand(R)")}
    assert paper.floor_z == 0.0 and paper.frame == "zup"


def test_paper_cell_layout_is_workable(paper):
    bench = paper.obstacle("workbench")
    lo, hi = bench.aabb()
    r1 = paper.region("R1")
    # R1 is just above the bench top and over the bench.
    assert 0.0 < r1.lo[2] - hi[2] <= 0.1
    assert np.all(r1.lo[:2] >= lo[:2]) and np.all(r1.hi[:2] <= hi[:2])
    # The parts lie low, free of every obstacle, and R0 is clear of the footprints.
    for name in ("O1", "O2"):
        assert paper.object(name).position[2] <= 0.3
        assert paper.floor_clearance(paper.object(name).position[None, :2])[0] > 0.5
    assert paper.floor_clearance(paper.start_region.center[None, :2])[0] > 0.5
    # The straight walks R0 -> O1, R0 -> O2 and O1 -> O2 are free for a 0.3 m disc.
    pts = {"R0": paper.start_region.center[:2], "O1": paper.object("O1").position[:2],
           "O2": paper.object("O2").position[:2]}
    a = np.array([pts["R0"], pts["R0"], pts["O1"]])
    b = np.array([pts["O1"], pts["O2"], pts["O2"]])
    assert not np.any(paper.segment_blocked(a, b, 0.3))
    assert {o.name for o in paper.obstacles} == {"workbench", "drill_press"}


def test_paper_yup_version_loads_to_the_identical_cell(paper):
    data = yaml.safe_load(PAPER_TEXT)
    yup = _to_paper_frame(data)
    # The y-up file holds the paper's own numbers.
    assert yup["objects"]["O1"]["position"] == [-1.0, 0.2, 1.0]
    assert yup["objects"]["O2"]["position"] == [-1.5, 0.3, -1.2]
    assert yup["regions"]["R1"] == {"lo": [0.9, 0.9, 0.9], "hi": [1.1, 1.1, 1.1]}
    other = cell_from_yaml(yaml.safe_dump(yup), source="paper_yup.yaml")
    assert other.frame == "paper_yup"
    for name, obj in paper.objects.items():
        o2 = other.object(name)
        np.testing.assert_allclose(o2.position, obj.position, atol=1e-12)
        np.testing.assert_allclose(o2.shape.aabb(), obj.shape.aabb(), atol=1e-12)
        np.testing.assert_allclose(o2.grasp_points, obj.grasp_points, atol=1e-12)
    for name, reg in paper.regions.items():
        np.testing.assert_allclose(other.region(name).lo, reg.lo, atol=1e-12)
        np.testing.assert_allclose(other.region(name).hi, reg.hi, atol=1e-12)
    for ob in paper.obstacles:
        ob2 = other.obstacle(ob.name)
        assert [p.kind for p in ob2.parts] == [p.kind for p in ob.parts]
        for p, q in zip(ob.parts, ob2.parts):
            np.testing.assert_allclose(q.aabb(), p.aabb(), atol=1e-12)
    np.testing.assert_allclose(other.workspace_lo, paper.workspace_lo)
    np.testing.assert_allclose(other.workspace_hi, paper.workspace_hi)


@pytest.mark.parametrize("name", ["paper_cell", "obstacle_cell", "demo_cell"])
def test_shipped_cells_load(name):
    cell = cell_by_name(name)
    assert cell.name == name
    assert cell.start_region.name in cell.regions
    assert cell.obstacles and cell.objects
    # Nothing starts inside an obstacle.
    for obj in cell.objects.values():
        for ob in cell.obstacles:
            assert not np.any(ob.contains(obj.shape.vertices()))


def test_obstacle_cell_wall_blocks_the_straight_walk():
    cell = cell_by_name("obstacle_cell")
    start = cell.start_region.center[:2]
    goal = cell.object("O1").position[:2]
    assert cell.segment_blocked(start, goal, 0.3)
    wall_lo, wall_hi = cell.obstacle("wall").aabb()
    assert wall_lo[0] > start[0] and wall_hi[0] < goal[0]
    # Around the +y end of the wall is free: three legs passing 0.4 m beyond its end.
    y = wall_hi[1] + 0.4
    via = np.array([start, [wall_lo[0] - 0.45, y], [wall_hi[0] + 0.45, y], goal])
    legs = cell.segment_blocked(via[:-1], via[1:], 0.3)
    assert legs.shape == (3,) and not legs.any()


def test_floor_clearance_is_signed_and_vectorized(paper):
    xy = np.array([[0.5, -1.0], [1.0, -1.0], [0.0, 0.0], [1.2, -0.2]])
    d = paper.floor_clearance(xy)
    assert d.shape == (4,)
    np.testing.assert_allclose(d[0], 0.3, atol=1e-9)        # bench front edge at x = 0.8
    np.testing.assert_allclose(d[1], -0.2, atol=1e-9)       # 0.2 inside the bench footprint
    np.testing.assert_allclose(d[3], 0.2, atol=1e-9)        # bench back edge at y = -0.4
    assert paper.floor_clearance(np.zeros((2, 3, 2))).shape == (2, 3)
    with pytest.raises(ValueError, match="shape"):
        paper.floor_clearance(np.zeros((3, 3)))


def test_segment_blocked_by_workspace_and_radius(paper):
    assert paper.segment_blocked([0.0, 0.0], [2.9, 0.0], 0.3)            # leaves workspace
    assert not paper.segment_blocked([0.0, 0.0], [2.9, 0.0], 0.3, check_workspace=False)
    # Passing 0.25 m beside the bench front: blocked for 0.3, free for 0.2.
    a, b = np.array([0.55, 0.5]), np.array([0.55, -2.0])
    assert paper.segment_blocked(a, b, 0.3) and not paper.segment_blocked(a, b, 0.2)
    with pytest.raises(ValueError, match="radius"):
        paper.segment_blocked(a, b, -1.0)


def _write(tmp_path: Path, text: str, name: str = "paper_cell.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_error_names_file_and_key(tmp_path):
    text = PAPER_TEXT.replace("position: [-1.0, -1.0, 0.2]", "position: [-1.0, -1.0]")
    with pytest.raises(CellError, match=r"paper_cell\.yaml: objects\.O1\.position: "
                                        r"expected 3 numbers, got 2"):
        load_cell(_write(tmp_path, text))


@pytest.mark.parametrize("old, new, pattern", [
    ("frame: zup", "frame: zup\ncolour: red", r"colour: unknown key"),
    ("    grasp_points: [[0.0, 0.0, 0.05]]\n    color: tab:orange",
     "    grasp_points: [[0.0, 0.0, 0.05]]\n    colour: tab:orange",
     r"objects\.O1\.colour: unknown"),
    ("start_region: R0", "start_region: R7", r"start_region: unknown region 'R7'"),
    ("final_region: R1", "final_region: 5", r"final_region: unknown region"),
    ("R1: {lo: [0.9, -1.1, 0.9], hi: [1.1, -0.9, 1.1]}",
     "R1: {lo: [1.1, -1.1, 0.9], hi: [0.9, -0.9, 1.1]}", r"regions\.R1: needs lo < hi"),
    ("frame: zup", "frame: yup", r"frame: expected zup or paper_yup"),
    ("    shape: box\n    size: [0.1, 0.1, 0.1]\n    grasp_points: [[0.0, 0.0, 0.05]]\n"
     "    color: tab:orange", "    shape: cone\n    size: [0.1, 0.1, 0.1]\n"
     "    grasp_points: [[0.0, 0.0, 0.05]]\n    color: tab:orange",
     r"objects\.O1\.shape: expected box, cylinder, sphere or mesh"),
    ("size: [0.05, 1.6]", "size: [0.05]", r"drill_press\.parts\[1\]\.size: expected 2 numbers"),
    ("size: [0.05, 1.6]", "size: [0.05, -1.6]", r"parts\[1\]\.size: expected positive"),
    ("assemble(R): leftHand(R) & rightHand(R)", "assemble(R): leftHand(R) & jump(R)",
     r"shorthands\.assemble\(R\): unknown task 'jump'"),
    ("assemble(R): leftHand(R) & rightHand(R)", "assemble(R): leftHand(Q)",
     r"'Q' in body 'leftHand\(Q\)' is neither a parameter"),
    ("assemble(R): leftHand(R) & rightHand(R)", "grasp(R): leftHand(R)",
     r"'grasp' is already a task"),
    ("assemble(R): leftHand(R) & rightHand(R)", "assemble(R): leftHand(R) | rightHand(R)",
     r"shorthands\.assemble\(R\): shorthand body .*only a conjunction of tasks is allowed, "
     r"not '\| rightHand\(R\)' at character 13"),
    ("assemble(R): leftHand(R) & rightHand(R)", "assemble(R): leftHand(R) & X rightHand(R)",
     r"shorthands\.assemble\(R\): .*not 'X' at character 15"),
    ("  O2:\n", "  R1:\n", r"names used for both an object and a region"),
    ("floor_z: 0.0", "floor_z: low", r"floor_z: expected a number"),
    ("workspace: {lo: [-3.0, -3.0, 0.0], hi: [3.0, 3.0, 2.5]}",
     "workspace: {lo: [1.0, 1.0, 0.0], hi: [3.0, 3.0, 2.5]}",
     r"start_region: region 'R0' lies outside the workspace"),
])
def test_malformed_cells_raise_cell_error(tmp_path, old, new, pattern):
    assert old in PAPER_TEXT
    with pytest.raises(CellError, match=pattern):
        load_cell(_write(tmp_path, PAPER_TEXT.replace(old, new, 1)))


def test_invalid_yaml_and_missing_file(tmp_path):
    with pytest.raises(CellError, match=r"bad\.yaml: invalid YAML"):
        cell_from_yaml("objects: [unclosed", source="bad.yaml")
    with pytest.raises(CellError, match="missing required key 'regions'"):
        cell_from_yaml("start_region: R0\n")
    with pytest.raises(CellError, match="cannot read cell file"):
        load_cell(tmp_path / "nope.yaml")
    with pytest.raises(CellError, match="expected a mapping"):
        cell_from_yaml("- 1\n- 2\n")


def test_cell_by_name_lists_known_cells():
    assert cell_search_paths()[0] == CONFIG
    with pytest.raises(CellError, match=r"no cell named 'kitchen'.*paper_cell"):
        cell_by_name("kitchen")
    with pytest.raises(CellError, match="plain name"):
        cell_by_name("../etc/passwd")
    assert cell_by_name("paper_cell.yaml").name == "paper_cell"


def test_lookups_name_the_known_entries(paper):
    with pytest.raises(ValueError, match="no region 'R9'; regions: R0, R1"):
        paper.region("R9")
    with pytest.raises(ValueError, match="no object 'O3'; objects: O1, O2"):
        paper.object("O3")
    with pytest.raises(ValueError, match="no obstacle 'lathe'"):
        paper.obstacle("lathe")
    assert paper.lookup("O1") is paper.object("O1")
    assert paper.lookup("R1") is paper.region("R1")


def test_mesh_obstacle_and_region_from_files(tmp_path):
    import trimesh
    trimesh.creation.box(extents=[0.4, 0.6, 1.0]).export(tmp_path / "crate.stl")
    trimesh.creation.icosphere(subdivisions=2, radius=0.2).export(tmp_path / "zone.stl")
    text = """
name: meshes
start_region: R0
regions:
  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}
  Z: {mesh: zone.stl, position: [1.0, 1.0, 1.0]}
obstacles:
  crate: {shape: mesh, mesh: crate.stl, position: [2.0, 0.0, 0.5], color: gray}
  drum: {shape: cylinder, position: [-2.0, 0.0, 0.5], size: [0.3, 1.0]}
"""
    cell = load_cell(_write(tmp_path, text, "meshes.yaml"))
    crate = cell.obstacle("crate").parts[0]
    assert isinstance(crate, MeshShape)
    ref = Box([2.0, 0.0, 0.5], [0.4, 0.6, 1.0])
    rng = np.random.default_rng(3)
    pts = rng.uniform([1.5, -0.6, -0.2], [2.5, 0.6, 1.2], size=(200, 3))
    np.testing.assert_array_equal(crate.contains(pts), ref.contains(pts))
    np.testing.assert_allclose(crate.signed_distance(pts), ref.signed_distance(pts), atol=1e-6)
    np.testing.assert_allclose(cell.floor_clearance(np.array([[2.0, 1.0]])), [0.7], atol=1e-6)
    assert isinstance(cell.obstacle("drum").parts[0], Cylinder)
    zone = cell.region("Z")
    assert not zone.is_box
    assert zone.contains(np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 1.25]])).tolist() == [True, False]
    with pytest.raises(CellError, match=r"regions\.Z\.mesh: mesh file not found"):
        cell_from_yaml(text, source="m.yaml", base_dir=tmp_path / "elsewhere")


def test_cells_pickle_for_worker_processes(tmp_path):
    import pickle

    import trimesh
    trimesh.creation.box(extents=[0.4, 0.6, 1.0]).export(tmp_path / "crate.stl")
    cell = cell_from_yaml("""
start_region: R0
regions: {R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}}
obstacles: {crate: {mesh: crate.stl, position: [2.0, 0.0, 0.5]}}
""", base_dir=tmp_path)
    seg = np.array([[[1.0, 0.0, 0.5], [1.5, 0.0, 0.5]]])
    before = cell.obstacle_clearance(seg, np.array([0.1]))          # builds the fcl model
    again = pickle.loads(pickle.dumps(cell))
    np.testing.assert_allclose(again.obstacle_clearance(seg, np.array([0.1])), before)
    np.testing.assert_allclose(before, [0.2], atol=1e-6)
    paper = pickle.loads(pickle.dumps(cell_by_name("paper_cell")))
    np.testing.assert_allclose(paper.region("R1").center, [1.0, -1.0, 1.0])


def test_yaml_exponent_numbers_are_numbers():
    cell = cell_from_yaml("start_region: R0\nfloor_z: 1e-3\nregions:\n"
                          "  R0: {lo: [-3e-1, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}\n")
    assert cell.floor_z == pytest.approx(0.001)
    np.testing.assert_allclose(cell.region("R0").lo, [-0.3, -0.3, 0.0])
    with pytest.raises(CellError, match=r"floor_z: expected a number, got 'abc'"):
        cell_from_yaml("start_region: R0\nfloor_z: abc\nregions:\n"
                       "  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}\n")


def test_resolve_cell_takes_a_cell_a_name_a_path_or_yaml_text(tmp_path: Path) -> None:
    """One resolver for the library, the CLI and the ROS nodes: the same text resolves to
    the same cell whichever layer reads it."""
    from ltl_human_motion.ros.common import resolve_cell as ros_resolve
    from ltl_human_motion.scene.cell_yaml import looks_like_yaml, resolve_cell

    paper = resolve_cell("paper_cell")
    assert resolve_cell(paper) is paper
    path = Path(__file__).resolve().parents[1] / "config" / "paper_cell.yaml"
    text = path.read_text()
    for given in (str(path), path, text, "  paper_cell  "):
        assert sorted(resolve_cell(given).objects) == sorted(paper.objects)
    flow = ("{name: tiny, start_region: R0, "
            "regions: {R0: {lo: [-0.3, -0.3, 0], hi: [0.3, 0.3, 2]}}}")
    assert looks_like_yaml(flow) and looks_like_yaml("name: tiny") and looks_like_yaml(text)
    assert not looks_like_yaml("paper_cell") and not looks_like_yaml(str(path))
    assert resolve_cell(flow).name == ros_resolve(flow).name == "tiny"
    assert sorted(ros_resolve("paper_cell").objects) == sorted(paper.objects)
    for bad in ("", "   ", 3):
        with pytest.raises(CellError, match="cell must be"):
            resolve_cell(bad)  # type: ignore[arg-type]
    with pytest.raises(CellError, match="no_such_cell"):
        resolve_cell("no_such_cell")
