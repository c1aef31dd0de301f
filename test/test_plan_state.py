"""The worker's pose moves only with the segments placed: WorkerState.place (a segment
with its hand-over pose, or one in place), StepExecutor.advance, and mark/restore taking
both back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.planning.blend import PlacedSegment
from ltl_human_motion.planning.plan_state import WorkerState

CELLS = Path(__file__).resolve().parents[1] / "scenarios" / "cells"


def _segment(n: int = 5) -> PlacedSegment:
    return PlacedSegment(np.zeros((n, 23, 3)), np.zeros(n), -1, 0, "test")


def test_place_moves_the_worker_only_with_an_end_pose_and_restore_takes_it_back() -> None:
    state = WorkerState()
    state.start_at((1.0, 2.0, 0.5))
    assert state.place(_segment()) == 0
    assert state.pose == (1.0, 2.0, 0.5)                 # in place: where it stood
    mark = state.mark()
    assert state.place(_segment(), (1.3, 2.0, 0.6)) == 1
    assert state.place(_segment(), (1.6, 2.1, 0.7)) == 2
    assert state.pose == (1.6, 2.1, 0.7)
    state.restore(mark)
    assert len(state.segments) == 1
    assert state.pose == (1.0, 2.0, 0.5)


def test_advance_places_a_step_where_the_worker_stands_and_moves_it_to_the_hand_over() -> None:
    """A model-made 0.2 m step ahead from (0.5, 0, pi/2): the segment starts at the pose,
    the worker ends 0.2 m along +y; an arm motion in place (``add`` without an end)
    leaves the pose where the step put it."""
    from ltl_human_motion.motion.types import world_positions
    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    from ltl_human_motion.planning.turns import make_step_primitive
    from ltl_human_motion.scene.cell_yaml import load_cell
    lib = get_library(1.75)
    planner = SequencePlanner(load_cell(CELLS / "machine_tending.yaml"), lib,
                              np.random.default_rng(0))
    ex, state = planner.executor, planner.state
    start = (0.5, 0.0, float(np.pi / 2))
    state.start_at(start)
    step = make_step_primitive(np.asarray(lib.standing_pose), lib.standing_height, 0.2, 0.0,
                               0.0, lib.skeleton, lib.fps, "walk")
    assert ex.advance(step) == 0
    np.testing.assert_array_equal(state.segments[0].positions, world_positions(step, *start))
    assert state.pose == ex.hand_over_pose(step, start)
    assert state.pose[0] == pytest.approx(0.5, abs=1e-6)
    assert state.pose[1] == pytest.approx(0.2, abs=0.01)
    after_step = state.pose
    ex.stand_still(-1, 0.5)
    assert len(state.segments) == 2 and state.pose == after_step
    assert state.segments[1].blend_in == planner.ctx.overlap
