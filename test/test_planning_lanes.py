"""Walking lanes: overhead parts are no tall parts, the navigation field prefers
roomy floor to a gap the body barely fits (scenario families timeout:grasp and
planning:*:budget in the cells with clutter and the 0.8 m aisle), and squeezes through
a gap only the footprints leave (the aisle's planning:*:blocked)."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.planning.astar import placement_key
from ltl_human_motion.planning.navigation import (
    NARROW_COST,
    ClearanceMap,
    NavigationField,
    floor_grid,
)
from ltl_human_motion.scene.cell_yaml import cell_from_yaml

CELL = """
name: lanes
frame: zup
workspace: {lo: [-2.0, -2.0, 0.0], hi: [2.0, 2.0, 2.5]}
start_region: R0
regions:
  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}
obstacles:
  board:                               # an overhead board, 1.8 m up
    shape: box
    position: [-1.5, 1.5, 1.8]
    size: [0.5, 0.5, 0.02]
  column:                              # a column from the floor to 2 m
    shape: box
    position: [-1.5, -1.5, 1.0]
    size: [0.5, 0.5, 2.0]
"""


def test_overhead_parts_are_no_tall_parts() -> None:
    cell = cell_from_yaml(CELL)
    walk = ClearanceMap(cell)
    plain = ClearanceMap(cell, tall_extra=0.0)
    beside_board = np.array([[-1.5, 1.0]])          # 0.25 m from the board's footprint
    beside_column = np.array([[-1.5, -1.0]])        # 0.25 m from the column's
    assert walk(beside_board)[0] == plain(beside_board)[0]
    assert walk(beside_column)[0] < plain(beside_column)[0] - 0.2


def test_narrow_floor_counts_longer() -> None:
    """A wall with two 0.6 m gaps between the worker and the goal: with lanes, the
    field's distance counts the floor the body barely fits up to ``1 + NARROW_COST``
    times its length (longer than plain, never more than that bound)."""
    cell = cell_from_yaml(CELL.replace("obstacles:", """obstacles:
  wall_a:
    shape: box
    position: [0.0, 1.2, 1.0]
    size: [0.1, 1.6, 2.0]
  wall_b:
    shape: box
    position: [0.0, -0.8, 1.0]
    size: [0.1, 1.2, 2.0]"""))
    clearance = ClearanceMap(cell, tall_extra=0.0)
    lo, hi = np.asarray(cell.workspace_lo[:2]), np.asarray(cell.workspace_hi[:2])

    def goal(xy: np.ndarray) -> np.ndarray:
        return np.hypot(xy[:, 0] - 1.5, xy[:, 1] - 0.2) < 0.1

    plain = NavigationField.on_grid(floor_grid(clearance, lo, hi, 0.15, 0.05), goal)
    lanes = NavigationField.on_grid(floor_grid(clearance, lo, hi, 0.15, 0.05,
                                               passage=0.25), goal)
    start = (np.array([-1.0]), np.array([0.2]))      # in front of the 0.4 m gap
    assert np.isfinite(plain.distance(*start)[0]) and np.isfinite(lanes.distance(*start)[0])
    assert lanes.distance(*start)[0] > plain.distance(*start)[0]
    assert lanes.distance(*start)[0] <= (1.0 + NARROW_COST) * plain.distance(*start)[0] + 1e-9


CORRIDOR = """
name: corridor
frame: zup
workspace: {lo: [-1.0, -2.0, 0.0], hi: [5.0, 2.0, 2.5]}
start_region: R0
regions:
  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}
  R_in: {lo: [2.2, -0.3, 0.0], hi: [2.8, 0.3, 2.0]}     # in the corridor
obstacles:
  wall_left:                           # tall walls 0.8 m apart, x from 1.0 to 4.0
    shape: box
    position: [2.5, 0.65, 1.0]
    size: [3.0, 0.5, 2.0]
  wall_right:
    shape: box
    position: [2.5, -0.65, 1.0]
    size: [3.0, 0.5, 2.0]
"""


def test_walk_squeezes_through_a_narrow_corridor() -> None:
    """Tall walls 0.8 m apart: the walking map (arms at shoulder width) leaves no way in,
    so the field squeezes on the footprint map; the walk the search finds keeps every
    frame clear of the walls, as the verifier checks (the aisle cell's family
    planning:*:blocked / walk:unreachable)."""
    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    from ltl_human_motion.planning.steps import body_clear_every_frame
    cell = cell_from_yaml(CORRIDOR)
    lib = get_library(1.75)
    planner = SequencePlanner(cell, lib, np.random.default_rng(0))
    planner.state.start_at((0.0, 0.0, 0.0))
    assert planner.ctx.clearance(np.array([[2.5, 0.0]]))[0] <= planner.ctx.options.body_radius
    goal = planner.goals.region(cell.region("R_in"), "walk into R_in", "walk(R_in)")
    assert goal.clearance is planner.ctx.stand_map
    walked = planner.executor.walk(goal, "walk(R_in)", 0, carry=False)
    assert walked > 0
    world = np.concatenate([s.positions for s in planner.state.segments])
    assert body_clear_every_frame(world, cell, lib.skeleton.stature)
    x, y, _ = planner.state.pose
    assert 1.0 < x < 4.0 and abs(y) < 0.4                    # in the corridor


def test_roomy_floor_needs_no_squeeze() -> None:
    """Where the walking map has a way, the field keeps to it (no squeeze)."""
    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    cell = cell_from_yaml(CORRIDOR.replace("0.65", "0.95"))      # 1.4 m apart
    planner = SequencePlanner(cell, get_library(1.75), np.random.default_rng(0))
    planner.state.start_at((0.0, 0.0, 0.0))
    goal = planner.goals.region(cell.region("R_in"), "walk into R_in", "walk(R_in)")
    assert goal.clearance is planner.ctx.clearance


def test_field_without_a_spot_leads_around_it() -> None:
    """Blocking a disc on the straight way keeps the goal cells and lengthens the way."""
    cell = cell_from_yaml(CELL)
    clearance = ClearanceMap(cell)
    lo, hi = np.asarray(cell.workspace_lo[:2]), np.asarray(cell.workspace_hi[:2])

    def goal(xy: np.ndarray) -> np.ndarray:
        return np.hypot(xy[:, 0] - 1.5, xy[:, 1]) < 0.1

    field = NavigationField.on_grid(floor_grid(clearance, lo, hi, 0.15, 0.05), goal)
    around = field.without((0.5, 0.0), 0.3)
    start = (np.array([-0.5]), np.array([0.0]))
    np.testing.assert_array_equal(around.goal_cells, field.goal_cells)
    assert around.reachable_from(-0.5, 0.0)
    assert around.distance(*start)[0] > field.distance(*start)[0] + 0.05
    assert not np.isfinite(around.distance(np.array([0.5]), np.array([0.0]))[0])
    assert field.grid.free[field.grid.free].size > around.grid.free[around.grid.free].size


def test_search_walks_around_a_gap_the_body_does_not_pass() -> None:
    """The cell with crates: from the far corner a field that counted the 0.45 m gap
    between two crates (one as high as the swinging hands) only twice its length led
    the search into it, which flooded the floor before the gap (planning:grasp:budget,
    later 5,600 nodes until it stalled and rerouted). The field counts such floor
    ``1 + LANE_NARROW_COST`` times: the search walks around without stalling, and the
    walk is clear on every frame."""
    from pathlib import Path

    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    from ltl_human_motion.planning.standing import standing_offset
    from ltl_human_motion.planning.steps import STALL_NODES, body_clear_every_frame
    from ltl_human_motion.scene.cell_yaml import resolve_cell
    root = Path(__file__).resolve().parents[1]
    cell = resolve_cell(root / "scenarios" / "cells" / "cluttered.yaml")
    lib = get_library(1.75)
    planner = SequencePlanner(cell, lib, np.random.default_rng(0))
    planner.state.start_at((-1.39, 1.26, 2.39))
    target = planner.target_of("grasp", ("O1",))
    goal, _ = planner.goals.reach(target, standing_offset(planner.ctx, "grasp", target,
                                                          "grasp(O1)"),
                                  "reach grasp(O1)", "grasp(O1)")
    assert goal.reroute is not None
    walked = planner.executor.walk(goal, "grasp(O1)", -1, carry=False)
    assert walked > 0 and planner.state.expanded < STALL_NODES
    world = np.concatenate([s.positions for s in planner.state.segments])
    assert body_clear_every_frame(world, cell, lib.skeleton.stature)
    assert np.hypot(planner.state.pose[0] - target[0], planner.state.pose[1] - target[1]) < 0.8


def test_a_colliding_stop_forbids_the_stops_around_it() -> None:
    """A walk's last stop that hit the table on a frame the search did not sample: the
    repair forbids every gait stop from that spot and the closed-set cells around it
    (one at a time, the next search stopped a grid cell over and hit it again, five
    times: wall_gap's planning:grasp:blocked); a first move is forbidden alone, a turn
    on the spot with every other turn on the spot there (they sweep the legs through
    nearly the same space: a worker facing a conveyor tried them one by one)."""
    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    planner = SequencePlanner(cell_from_yaml(CELL), get_library(1.75),
                              np.random.default_rng(0))
    index = planner.ctx.index
    stop = int(np.flatnonzero(index.stops & ~index.standing)[0])
    walk = int(np.flatnonzero(~index.stops & ~index.carry)[0])
    turn = int(np.flatnonzero(index.standing)[0])
    poses = [(0.0, 0.0, 0.0), (0.5, 0.1, 0.2)]
    wide = planner.executor.forbid([walk, stop], poses, 1)
    n_stops = int(np.sum(index.stops & ~index.standing))
    assert len(wide) == 9 * n_stops and (stop, *placement_key(*poses[1])) in wide
    assert planner.executor.forbid([stop], poses[:1], 0) == {(stop, *placement_key(*poses[0]))}
    turns = {p for p in np.flatnonzero(index.standing).tolist()
             if index.primitives[p].meta.get("turn")}
    assert turn in turns
    assert planner.executor.forbid([walk, turn], poses, 1) == {
        (p, *placement_key(*poses[1])) for p in turns}


def test_arms_come_up_after_a_step_aside_from_a_board_at_elbow_height() -> None:
    """In the 0.8 m aisle, a board 1.2 m up on the right: raising the arms there swings
    the right elbow into it, and no step back helps; a step aside does (the aisle's
    planning:?:blocked of assemble, leftHand and rightHand in R2)."""
    from pathlib import Path

    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    from ltl_human_motion.planning.steps import body_clear_every_frame
    from ltl_human_motion.scene.cell_yaml import resolve_cell
    cell = resolve_cell(Path(__file__).resolve().parents[1] / "scenarios" / "cells"
                        / "aisle.yaml")
    lib = get_library(1.75)
    planner = SequencePlanner(cell, lib, np.random.default_rng(0))
    planner.state.start_at((1.2, -0.1, 0.0))
    planner.executor.stand_still(-1, 0.3)
    planner.executor.arm_transition(False, -1)
    assert abs(planner.state.pose[1] + 0.1) > 0.05                 # stepped aside
    world = np.concatenate([s.positions for s in planner.state.segments])
    assert body_clear_every_frame(world, cell, lib.skeleton.stature)


TABLE = CELL.replace("hi: [0.3, 0.3, 0.1]}", """hi: [0.3, 0.3, 0.1]}
  R_far: {lo: [-1.8, -0.3, 0.0], hi: [-1.2, 0.3, 2.0]}""").replace("obstacles:", """obstacles:
  table:
    shape: box
    position: [1.0, 0.0, 0.375]
    size: [1.0, 1.6, 0.75]""")


def test_field_leads_from_the_floor_beside_the_lanes() -> None:
    """A worker at a table's edge stands where the floor keeps less than
    ``PASSAGE_RADIUS``: the walk's field is finite there and wherever the search may
    step (clearance over ``body_radius``; the search drops poses where it is infinite),
    and it still counts that floor longer than the roomy floor behind the worker."""
    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    from ltl_human_motion.planning.walk_goals import LANE_NARROW_COST, PASSAGE_RADIUS
    cell = cell_from_yaml(TABLE)
    planner = SequencePlanner(cell, get_library(1.95), np.random.default_rng(0))
    planner.state.start_at((0.3, 0.0, 0.0))
    radius = planner.ctx.options.body_radius
    here = planner.ctx.clearance(np.array([[0.3, 0.0]]))[0]
    assert radius < here < PASSAGE_RADIUS
    goal = planner.goals.region(cell.region("R_far"), "walk into R_far", "walk(R_far)")
    x, y = np.meshgrid(np.linspace(-1.9, 0.45, 48), np.linspace(-1.9, 1.9, 76))
    x, y = x.ravel(), y.ravel()
    walkable = planner.ctx.clearance(np.stack([x, y], axis=-1)) > radius + 0.02
    assert np.all(np.isfinite(goal.distance(x[walkable], y[walkable])))
    # 0.2 m along the edge costs more than 0.2 m on the roomy floor, within the bound.
    along = goal.distance(np.array([0.3]), np.array([0.0]))[0] \
        - goal.distance(np.array([0.3]), np.array([0.2]))[0]
    away = goal.distance(np.array([-0.3]), np.array([0.0]))[0] \
        - goal.distance(np.array([-0.5]), np.array([0.0]))[0]
    assert abs(along) < 0.2 * (1.0 + LANE_NARROW_COST)
    assert 0.1 < away <= 0.2 + 0.05


def test_the_reach_goals_band_holds_every_spot_ideal_placement_can_pick() -> None:
    # the goal test of a reach skips poses outside this band: every spot of
    # standing.ideal_placement (target - R(yaw) (d + b, lat), b in [0, back]) within
    # ``adjust`` of a pose puts that pose inside it
    from ltl_human_motion.planning.walk_goals import _spot_band
    rng = np.random.default_rng(3)
    for _ in range(200):
        d, lat = rng.uniform(-0.2, 0.7), rng.uniform(-0.4, 0.4)
        back, adjust = rng.uniform(0.0, 0.4), rng.uniform(0.05, 0.4)
        lo, hi = _spot_band((d, lat), back, adjust)
        b = rng.uniform(0.0, back, 50)
        spots = np.hypot(d + b, lat)                      # distance of each spot
        r = spots + rng.uniform(-adjust, adjust, 50)      # poses within adjust of it
        assert np.all((r >= lo) & (r <= hi))


def test_compiled_successor_poses_and_clearances_equal_the_numpy_ones() -> None:
    # astar's one compiled call per expansion (ClearanceMap.placed_paths) gives the
    # numbers of _place and _path_clearance, bit for bit
    from ltl_human_motion.planning.astar import _path_clearance, _place
    from ltl_human_motion.planning.gait_index import gait_index
    from ltl_human_motion.planning.pipeline import get_library
    index = gait_index(get_library())
    cmap = ClearanceMap(cell_from_yaml(CELL), resolution=0.04)
    rng = np.random.default_rng(5)
    for _ in range(50):
        ids = rng.choice(len(index.disp), 40)
        pose = (rng.uniform(-2.2, 2.2), rng.uniform(-2.2, 2.2), rng.uniform(-7, 7))
        placed = cmap.placed_paths(index.disp, index.path, ids, pose)
        if placed is None:
            pytest.skip("the compiled kernels are not in use")
        ends, gap = placed
        np.testing.assert_array_equal(ends, _place(index, ids, *pose))
        np.testing.assert_array_equal(gap, _path_clearance(index, ids, *pose, cmap))
