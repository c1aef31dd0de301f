"""What a batch worker reuses across items (issue 37): structures that depend only on the
specification's text, the cell's names or its obstacle layout are built once and found
again for the cells of later items, whose parts and start region were moved; a renamed or
rearranged cell gets its own."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.batch.items import ItemParams, cell_for_item
from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl.spec import build_specification
from ltl_human_motion.motion.library import library_cached
from ltl_human_motion.planning.feasibility import floor_components
from ltl_human_motion.planning.navigation import stand_clearance_map
from ltl_human_motion.planning.pipeline import get_library
from ltl_human_motion.scene.cell_yaml import resolve_cell

SPEC = "F insert(P2, kit) & F insert(P7, kit)"


@pytest.fixture(scope="module")
def cell():
    return resolve_cell("kitting_cell")


def _moved(cell, index: int):
    """The cell of a batch item: two parts and the start region moved."""
    return cell_for_item(cell, ItemParams(
        index=index, spec_name="s", spec=SPEC, seed=index,
        object_offsets={"P2": (0.01 * index, 0.02, 0.0), "P7": (-0.02, 0.01 * index, 0.0)},
        region_offsets={"R0": (0.03, -0.01 * index, 0.0)}))


def test_a_specification_is_parsed_once_for_cells_with_moved_parts(cell) -> None:
    first = build_specification(SPEC, _moved(cell, 1))
    assert build_specification(SPEC, _moved(cell, 2)) is first
    assert build_specification(SPEC, cell) is first
    assert first.text == SPEC and first.letters        # a complete specification
    other = build_specification("F insert(P3, kit)", _moved(cell, 1))
    assert other is not first and "insert(P3, kit)" in {t.key for t in other.tasks}


def test_a_renamed_part_is_not_answered_from_the_cache(cell) -> None:
    build_specification(SPEC, cell)
    objects = dict(cell.objects)
    objects["Q2"] = objects.pop("P2")
    renamed = dataclasses.replace(cell, objects=objects)
    with pytest.raises(SpecError, match="P2"):
        build_specification(SPEC, renamed)


def test_obstacle_maps_are_shared_by_moved_cells_not_by_moved_obstacles(cell) -> None:
    assert stand_clearance_map(_moved(cell, 1)) is stand_clearance_map(_moved(cell, 2))
    table = cell.obstacles[0]
    shifted = dataclasses.replace(table, parts=tuple(
        p.translated(np.array([0.3, 0.0, 0.0])) for p in table.parts))
    rearranged = dataclasses.replace(cell, obstacles=(shifted, *cell.obstacles[1:]))
    assert stand_clearance_map(rearranged) is not stand_clearance_map(cell)


@pytest.mark.parametrize("stature", [1.60, 1.90])
def test_floor_components_equal_the_per_part_test(cell, stature: float) -> None:
    radius, block = 0.07 * stature, 0.285 * stature
    grid, labels = floor_components(cell, radius, 0.05, block)
    lo, hi = np.asarray(cell.workspace_lo[:2]), np.asarray(cell.workspace_hi[:2])
    xy = grid.centres
    free = np.all((xy >= lo + radius) & (xy <= hi - radius), axis=-1)
    for ob in cell.obstacles:
        for part in ob.parts:
            if part.aabb()[0][2] - cell.floor_z < block:
                free &= part.footprint().signed_distance(xy) > radius
    np.testing.assert_array_equal(grid.free.ravel(), free)
    assert labels.shape == (len(xy),)
    # the table legs block the floor only for a worker whose knees are above them
    assert not free.all() and free.any()


def test_library_cached_says_whether_load_library_would_build(tmp_path: Path) -> None:
    get_library(1.75)
    assert library_cached(1.75)
    assert not library_cached(1.75, cache_dir=tmp_path)


def test_lasso_truths_are_remembered_per_formula_and_word(cell) -> None:
    from ltl_human_motion.ltl.evaluator import evaluate_lasso, evaluate_positions
    spec = build_specification(SPEC, cell)
    p2, p7 = ({t.key} for t in spec.tasks)
    words = [([p2], [p7]), ([], [p2, p7]), ([p2], [p2]), ([], [set()])]
    first = [evaluate_lasso(spec.formula, pre, cyc) for pre, cyc in words]
    assert first == [evaluate_positions(spec.formula, pre, cyc)[0] for pre, cyc in words]
    assert first[:2] == [True, True] and first[2:] == [False, False]
    again = [evaluate_lasso(spec.formula, [list(x) for x in pre], (frozenset(x) for x in cyc))
             for pre, cyc in words]
    assert again == first
    with pytest.raises(ValueError, match="cycle"):
        evaluate_lasso(spec.formula, [p2], [])
