"""Walks to a goal nearer or smaller than the gait's start and stop strides: model-made
steps into it (machine_tending at 1.95 m: the search from 0.45 m away flooded 8000
nodes, 3 s, before another order of the tasks was tried); and the collision answers of
the clearance bounds the planner relies on."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.scene.cell_yaml import load_cell
from ltl_human_motion.scene.predicates import object_clearance, object_collides

CELLS = Path(__file__).resolve().parents[1] / "scenarios" / "cells"


@pytest.mark.parametrize("steps", [True, False])
def test_a_worker_beside_a_small_reach_spot_steps_into_it(steps: bool,
                                                          monkeypatch) -> None:
    """A 1.95 m worker 0.45 m from where the extract reaches the fixture, which stands
    0.3 m from the machine's front (no room to turn there): two model-made steps and
    the standing adjustment, no search; without the steps the search runs out."""
    from ltl_human_motion.errors import PlanningError
    from ltl_human_motion.planning import steps as steps_module
    from ltl_human_motion.planning.astar import SearchBudget
    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    from ltl_human_motion.planning.steps import body_clear_every_frame
    cell = load_cell(CELLS / "machine_tending.yaml")
    lib = get_library(1.95)
    planner = SequencePlanner(cell, lib, np.random.default_rng(0))
    planner.state.start_at((1.07, -0.22, -0.45))
    target = planner.target_of("extract", ("done", "fixture"))
    placement, _ = planner._placement("extract", target, "extract(done, fixture)",
                                      ("done", "fixture"))
    if not steps:
        monkeypatch.setattr(steps_module, "STEP_INTO_TRIES", 0)
        with pytest.raises(PlanningError, match="budget ran out"):
            planner.goal_steps.approach(target, placement, "extract(done, fixture)",
                                        budget=SearchBudget(2000))
        return
    planner.goal_steps.approach(target, placement, "extract(done, fixture)")
    assert planner.state.expanded == 0
    world = np.concatenate([s.positions for s in planner.state.segments])
    assert body_clear_every_frame(world, cell, 1.95)
    x, y, yaw = planner.state.pose
    c, s = np.cos(yaw), np.sin(yaw)
    local = (c * (target[0] - x) + s * (target[1] - y), -s * (target[0] - x) + c * (target[1] - y))
    # Where the goal model reaches from: the placement, or a little further back.
    assert local[0] == pytest.approx(placement[0], abs=0.2)
    assert local[1] == pytest.approx(placement[1], abs=0.05)


def test_object_clearance_exact_below_keeps_the_collision_answer() -> None:
    """Exact distances only up to ``exact_below``: the same answer to "does the part
    touch an obstacle", and the same distances up to that bound."""
    cell = load_cell(CELLS / "machine_tending.yaml")
    rng = np.random.default_rng(1)
    lo, hi = np.array([1.3, -0.7, 0.6]), np.array([2.5, 0.7, 2.0])
    traj = lo + rng.random((400, 3)) * (hi - lo)
    full = object_clearance(cell, "done", traj)
    quick = object_clearance(cell, "done", traj, exact_below=0.0)
    assert (full <= 0.0).any() and (full > 0.0).any()
    np.testing.assert_array_equal(full <= 0.0, quick <= 0.0)
    np.testing.assert_array_equal(full <= 0.0, object_collides(cell, "done", traj))
    np.testing.assert_array_equal(full <= 0.05, object_collides(cell, "done", traj, 0.05))
    assert np.all(quick <= full + 1e-12)
    some = object_clearance(cell, "done", traj, exact_below=0.1)
    close = full <= 0.1
    np.testing.assert_allclose(some[close], full[close])
