"""Specs files, item derivation and jittered cells of the batch module (no synthesis)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.batch import (
    BatchConfigError,
    cell_for_item,
    derive_item,
    load_specs,
    specs_from_yaml,
    validate_against_cell,
)
from ltl_human_motion.scene.cell_yaml import cell_by_name

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "config" / "specs_example.yaml"

BASE = """
specs:
  - {name: a, spec: S1, weight: 1}
  - {name: b, spec: S2, weight: 3, cycles: [1, 2]}
stature: {min: 1.6, max: 1.8, step: 0.1}
objects: {O1: [0.1, 0.2, 0.0], O2: {lo: [0.0, -0.1, 0.0], hi: [0.1, 0.0, 0.05]}}
regions: {R0: [0.1, 0.1, 0.0]}
"""


@pytest.fixture(scope="module")
def cell():
    return cell_by_name("paper_cell")


def test_example_file_parses_and_fits_the_paper_cell(cell) -> None:
    specs = load_specs(EXAMPLE)
    assert [s.name for s in specs.specs] == ["S1", "S2"]
    assert specs.statures == (1.6, 1.65, 1.7, 1.75, 1.8)
    assert specs.objects["O1"].lo == (-0.1, -0.1, 0.0)
    validate_against_cell(specs, cell)


def test_items_are_a_function_of_seed_and_index() -> None:
    specs = specs_from_yaml(BASE, "base.yaml")
    a = [derive_item(specs, 7, i) for i in range(50)]
    b = [derive_item(specs, 7, i) for i in reversed(range(50))][::-1]
    assert a == b
    assert derive_item(specs, 8, 3) != a[3]
    for item in a:
        assert item.stature in (1.6, 1.7, 1.8)
        assert item.cycles in ((1,) if item.spec_name == "a" else (1, 2))
        dx, dy, dz = item.object_offsets["O1"]
        assert abs(dx) <= 0.1 and abs(dy) <= 0.2 and dz == 0.0
        ox, oy, oz = item.object_offsets["O2"]
        assert 0.0 <= ox <= 0.1 and -0.1 <= oy <= 0.0 and 0.0 <= oz <= 0.05
        assert 0 <= item.seed < 2**31


def test_weights_shape_the_mix() -> None:
    specs = specs_from_yaml(BASE, "base.yaml")
    names = [derive_item(specs, 0, i).spec_name for i in range(2000)]
    share_b = names.count("b") / len(names)
    assert 0.70 < share_b < 0.80          # weight 3 of 4


def test_cell_for_item_moves_objects_regions_and_start(cell) -> None:
    specs = specs_from_yaml(BASE, "base.yaml")
    item = derive_item(specs, 0, 5)
    moved = cell_for_item(cell, item)
    off = np.asarray(item.object_offsets["O1"])
    np.testing.assert_allclose(moved.objects["O1"].position, cell.objects["O1"].position + off)
    np.testing.assert_allclose(moved.objects["O1"].occupancy.center,
                               cell.objects["O1"].occupancy.center + off)
    r0 = np.asarray(item.region_offsets["R0"])
    np.testing.assert_allclose(moved.start_region.lo, cell.start_region.lo + r0)
    assert moved.start_region is moved.regions["R0"]
    assert moved.final_region is moved.regions["R1"]
    np.testing.assert_allclose(moved.regions["R1"].lo, cell.regions["R1"].lo)
    assert cell.objects["O1"].position.tolist() == [-1.0, -1.0, 0.2]      # untouched


@pytest.mark.parametrize(("text", "match"), [
    ("specs: []", r"bad\.yaml: specs: expected a non-empty list"),
    ("specs: [{spec: S1, weight: -1}]", r"bad\.yaml: specs\[0\]\.weight: expected a positive"),
    ("specs: [{spec: S1, wieght: 1}]", r"bad\.yaml: specs\[0\]\.wieght: unknown key"),
    ("specs: [S1]\nstature: 2.5", r"bad\.yaml: stature: stature 2\.5 m is outside"),
    ("specs: [S1]\nstature: {min: 1.6, max: 1.9, step: 0.001}", r"stature\.step: 301 statures"),
    ("specs: [S1]\nobjects: {O1: [0.1, 0.1]}", r"bad\.yaml: objects\.O1: expected 3 numbers"),
    ("specs: [S1]\nregions: {R1: {lo: [0, 0, 0], hi: [-1, 0, 0]}}", r"regions\.R1: lo"),
    ("specs: [S1]\ncycles: [1, 0]", r"bad\.yaml: cycles\[1\]: expected an integer >= 1"),
    ("specs: [S1]\nsequence_mode: best", r"sequence_mode: expected one of"),
    ("specs: [S1]\noptions: {verify: false}", r"options\.verify: not allowed"),
    ("specs: [S1]\noptions: {speed: 2}", r"bad\.yaml: options: unknown synthesis options"),
    ("specs: [S1]\ncolour: red", r"bad\.yaml: colour: unknown key"),
    ("specs: [{name: x, spec: S1}, {name: x, spec: S2}]", r"specs\[1\]\.name: duplicate"),
    ("specs: [S1\n", r"bad\.yaml: not valid YAML"),
])
def test_malformed_specs_name_the_file_and_key(text: str, match: str) -> None:
    with pytest.raises(BatchConfigError, match=match):
        specs_from_yaml(text, "bad.yaml")


def test_specs_are_checked_against_the_cell(cell) -> None:
    with pytest.raises(BatchConfigError, match=r"x\.yaml: objects\.O9: cell 'paper_cell' has "
                                               r"no such object"):
        validate_against_cell(specs_from_yaml("specs: [S1]\nobjects: {O9: [0, 0, 0]}",
                                              "x.yaml"), cell)
    with pytest.raises(BatchConfigError, match=r"x\.yaml: specs\[0\]\.spec: "):
        validate_against_cell(specs_from_yaml("specs: ['grasp(O7)']", "x.yaml"), cell)


def test_missing_specs_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(BatchConfigError, match=r"nope\.yaml: cannot read specs file"):
        load_specs(tmp_path / "nope.yaml")
    with pytest.raises(ValueError, match="index must be an integer >= 0"):
        derive_item(specs_from_yaml("specs: [S1]"), 0, -1)
