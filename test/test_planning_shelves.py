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
    from ltl_human_motion.planning.pipeline import get_library, resolve_cell
    from ltl_human_motion.planning.planner import PALM_SUPPORT_GAP, SequencePlanner
    from ltl_human_motion.scene.occupancy import BODY_PARTS, capsule_radii
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
