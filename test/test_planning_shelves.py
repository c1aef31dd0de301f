"""Parts on shelf boards: the level hand path of goal primitives and the palm target
raised off a part's support (scenario families planning:grasp:blocked on shelves)."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.gait import standing_pose
from ltl_human_motion.motion.goals import make_goal_primitive, reach_placement
from ltl_human_motion.motion.quality import primitive_metrics
from ltl_human_motion.motion.skeleton import JOINT_INDEX as J
from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.motion.types import world_positions

SK = Skeleton(1.75)


@pytest.mark.parametrize("height", [0.75, 1.0, 1.45, 1.68])
def test_level_path_comes_in_at_the_approach_height(height: float) -> None:
    """From the carry stance the planner reaches from, the palm never dips below the
    target while it is further out than 5 cm before it (it comes in over a board's
    front edge), and the motion passes the quality checks."""
    from ltl_human_motion.planning.pipeline import get_library
    carry = get_library(1.75).carry_standing_pose
    x, y = reach_placement("grasp", height, SK)
    target = np.array([x, y, height])
    mp = make_goal_primitive("grasp", target, SK, rng=np.random.default_rng(0),
                             path="level", start_pose=carry)
    w = world_positions(mp, 0.0, 0.0, 0.0)
    assert primitive_metrics(w, mp.fps, SK)["passed"]
    palm = w[:, J["r_hand"]]
    shoulder = w[:, J["r_shoulder"]]
    contact = mp.meta["contact_frame"]
    assert np.linalg.norm(palm[contact] - target) < 0.01
    ahead = np.hypot(*(palm[:, :2] - shoulder[:, :2]).T)
    out = ahead > ahead[contact] - 0.05          # the last 5 cm in towards the target
    assert out.any() and np.all(palm[out, 2] >= height - 1e-6)
    arc = make_goal_primitive("grasp", target, SK, rng=np.random.default_rng(0),
                              start_pose=carry)
    assert mp.n_frames > arc.n_frames                 # a longer path, slower


def test_level_path_rejects_unknown_paths() -> None:
    with pytest.raises(ValueError, match="path must be one of"):
        make_goal_primitive("grasp", np.array([0.5, 0.0, 1.0]), SK, path="spiral",
                            start_pose=standing_pose(SK))


def test_grasp_palm_target_clears_a_flat_parts_support() -> None:
    """A 4 cm disc on a board: the palm target rises until the palm clears the board,
    and the palm there still enters the part (grasp holds)."""
    from ltl_human_motion.motion.capsules import BODY_PARTS, capsule_radii
    from ltl_human_motion.planning.pipeline import get_library, resolve_cell
    from ltl_human_motion.planning.planner import SequencePlanner
    from ltl_human_motion.planning.standing import PALM_SUPPORT_GAP
    cell = resolve_cell("scenarios/cells/kitting.yaml")
    planner = SequencePlanner(cell, get_library(1.75), np.random.default_rng(0))
    point = np.asarray(cell.object("gear").grasp_points_at(cell.object("gear").position)[0])
    palm = planner.target_of("grasp", ("gear",))
    radius = float(capsule_radii(1.75)[BODY_PARTS.index("r_palm")])
    assert palm[2] > point[2] and np.allclose(palm[:2], point[:2])
    clear = float(cell.part_set.capsule_clearance(np.stack([palm, palm])[None], radius)[0])
    assert clear > PALM_SUPPORT_GAP
    part = cell.object("gear").occupancy_at(cell.object("gear").position)
    assert float(part.signed_distance(palm[None])[0]) < radius


def _board_clearance(world: np.ndarray, board: tuple[float, float, float]) -> float:
    """Smallest distance (m) of the body's capsules (frames (T, J, 3)) from a board beyond
    x = edge between heights bottom and top (``board``), the capsules sampled densely."""
    from ltl_human_motion.motion.capsules import capsule_ends, capsule_radii
    edge, bottom, top = board
    ia, ib = capsule_ends()
    s = np.linspace(0.0, 1.0, 11)[:, None, None, None]
    pts = world[:, ia] + s * (world[:, ib] - world[:, ia])
    x, z = pts[..., 0], pts[..., 2]
    dz = np.maximum(bottom - z, z - top)
    inside = (x >= edge) & (dz <= 0.0)
    dist = np.where(inside, -np.minimum(x - edge, -dz),
                    np.hypot(np.maximum(edge - x, 0.0), np.maximum(dz, 0.0)))
    return float(np.min(dist - capsule_radii(SK.stature)))


@pytest.mark.parametrize(("height", "depth", "bottom"),
                         [(0.08, 0.12, 0.40), (0.06, 0.10, 0.45), (0.21, 0.12, 0.54)])
def test_reach_under_a_low_board_keeps_the_body_clear_of_it(height: float, depth: float,
                                                            bottom: float) -> None:
    """A part under a low board (on the floor, on a cupboard's bottom board): the worker
    stands where a crouch reaches it, the hand goes down in front of the edge and in under
    the board, no body part touches the board, and the motion passes the quality checks."""
    from ltl_human_motion.planning.pipeline import get_library
    carry = get_library(1.75).carry_standing_pose
    top = bottom + 0.02
    x, y = reach_placement("grasp", height, SK, board=(depth, bottom, top))
    target = np.array([x, y, height])
    board = (x - depth, bottom, top)
    mp = make_goal_primitive("grasp", target, SK, rng=np.random.default_rng(1),
                             start_pose=carry, board=board)
    w = world_positions(mp, 0.0, 0.0, 0.0)
    assert primitive_metrics(w, mp.fps, SK)["passed"]
    assert np.linalg.norm(w[mp.meta["contact_frame"], J["r_hand"]] - target) < 0.01
    assert _board_clearance(w, board) > 0.0
    # without the board the reach either runs into it or, where only a crouch past the
    # hips' range of motion would reach (the board reach's own postures), is refused
    try:
        arc = make_goal_primitive("grasp", target, SK, rng=np.random.default_rng(1),
                                  start_pose=carry)
    except ValueError as exc:
        assert "out of reach" in str(exc)
    else:
        assert _board_clearance(world_positions(arc, 0.0, 0.0, 0.0), board) < 0.0


@pytest.mark.parametrize("spec", ["F grasp(O1)", "F grasp(O2)"])
def test_grasp_under_a_low_board_verifies(spec: str) -> None:
    """The planner finds the board over the part, stands square to its edge, and the
    plan verifies (planning:grasp:blocked in under_shelf before)."""
    from ltl_human_motion.scenarios.run import run_pair
    outcome = run_pair(spec, "scenarios/cells/under_shelf.yaml", 1.75, 0, timeout=30.0)
    assert outcome.status == "verified", outcome.message[:300]
