"""A worker who is already at (or beside) the region a part goes to: the part is put down
in front of them, or they turn on the spot and step there, instead of a search for a
gait that arrives facing the region's centre (in the aisle, 0.8 m wide, such searches
took 8,000 nodes and 4-6 s with the part in hand). And the stature a synthesis uses is
its library's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.planning.pipeline import get_library, synthesize
from ltl_human_motion.scene.cell_yaml import load_cell

AISLE = Path(__file__).resolve().parents[1] / "scenarios" / "cells" / "aisle.yaml"


def test_a_part_carried_into_the_region_the_worker_stands_in_goes_down_in_front() -> None:
    """carry(O2, R2): the grasp from the knee board leaves the 1.75 m worker standing in
    R2 facing the rack; the part goes into R2 in front of them (not at its centre,
    behind their shoulder), with no search for a place facing the centre."""
    cell = load_cell(AISLE)
    synth = synthesize("F carry(O2, R2)", cell, stature=1.75, seed=0)[0]
    assert synth.verification["passed"]
    assert synth.stats.nodes_expanded < 200
    region = cell.region("R2")
    carry = next(s for s in synth.timeline if s.task.startswith("carry"))
    end = synth.objects["O2"][carry.end_frame - 1]
    assert np.all(end >= region.lo) and np.all(end <= region.hi)
    assert np.hypot(*(end[:2] - np.asarray(region.center)[:2])) > 0.1


def test_a_worker_facing_away_turns_on_the_spot_before_stepping_to_the_region() -> None:
    """move(O1, R2) at 1.95 m: after the grasp from the left rack the worker faces it,
    0.6 m from where the move reaches R2's centre; no gait turns round in the aisle with
    the part in hand (the search took 5,800 nodes), so the worker turns on the spot and
    steps there: between the grasp and the move only standing steps and turns, one of
    them turning by more than 90 degrees."""
    synth = synthesize("F move(O1, R2)", AISLE, stature=1.95, seed=1)[0]
    assert synth.verification["passed"]
    names = [name for name, _, _ in synth.stats.segments]
    grasp = next(i for i, n in enumerate(names) if n.startswith("grasp_"))
    move = next(i for i, n in enumerate(names) if n.startswith("move_"))
    between = names[grasp + 1:move]
    assert between and all(n.startswith(("carry_step", "carry_turn")) for n in between)
    assert max(abs(float(n.rsplit("_", 1)[1])) for n in between) > 90.0
    assert synth.stats.nodes_expanded < 1000


def test_the_stature_is_the_library_s() -> None:
    """A library given without a stature sets it; a stature that contradicts the
    library is refused before any work, naming both."""
    lib = get_library(1.55)
    with pytest.raises(ValueError, match=r"stature 1\.750 m does not match the library's "
                                         r"1\.550 m"):
        synthesize("F grasp(O1)", "paper_cell", library=lib, stature=1.75)
    a = synthesize("F grasp(O1)", "paper_cell", library=lib, seed=2)[0]
    b = synthesize("F grasp(O1)", "paper_cell", stature=1.55, seed=2)[0]
    np.testing.assert_array_equal(a.motion.positions, b.motion.positions)
    assert a.verification == b.verification
