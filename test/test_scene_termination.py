"""Table I termination conditions on constructed poses and on a synthetic motion."""

from __future__ import annotations

import numpy as np
import pytest
from demo_motion import demo_synthesized_motion, reach_pose

from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.scene import (
    TASK_NAMES,
    cell_by_name,
    cell_from_yaml,
    chest_height,
    expand_task,
    knee_height,
    parse_task,
    termination_holds,
    termination_series,
)

REST = Skeleton().rest_positions()
J = JOINT_INDEX


@pytest.fixture(scope="module")
def paper():
    return cell_by_name("paper_cell")


@pytest.fixture(scope="module")
def demo():
    return cell_by_name("demo_cell")


def _at(offset) -> np.ndarray:
    return REST + np.asarray(offset, dtype=float)


def _bent(angle_deg: float, drop: float = 0.0) -> np.ndarray:
    """Upper body turned forward about the pelvis by ``angle_deg``, then lowered."""
    pose = REST.copy()
    a = np.radians(angle_deg)
    rot = np.array([[np.cos(a), 0.0, np.sin(a)], [0.0, 1.0, 0.0], [-np.sin(a), 0.0, np.cos(a)]])
    upper = [j for n, j in J.items() if not any(k in n for k in ("hip", "knee", "ankle", "toe",
                                                                "pelvis"))]
    pivot = REST[J["pelvis"]]
    pose[upper] = (REST[upper] - pivot) @ rot.T + pivot
    pose[:, 2] -= drop
    return pose


def test_heights_follow_the_stature():
    assert chest_height() == pytest.approx(0.72 * 1.75)
    assert knee_height() == pytest.approx(0.285 * 1.75)
    assert chest_height(2.0) > chest_height(1.5)


def test_posture_tasks(paper):
    standing, bent, stooped = REST, _bent(80.0), _bent(80.0, drop=0.45)
    assert termination_holds("standUp", (), standing, paper)
    assert not termination_holds("bend", (), standing, paper)
    assert not termination_holds("stoop", (), standing, paper)
    assert termination_holds("bend", (), bent, paper)
    assert not termination_holds("stoop", (), bent, paper)
    assert not termination_holds("standUp", (), bent, paper)
    assert termination_holds("stoop", (), stooped, paper)
    assert not termination_holds("bend", (), stooped, paper)
    # Kneeling: a knee within eps (5 cm) of the floor.
    knee_bottom = REST[J["l_knee"], 2] - 0.055
    assert termination_holds("kneel", (), _at([0, 0, -(knee_bottom - 0.04)]), paper)
    assert not termination_holds("kneel", (), _at([0, 0, -(knee_bottom - 0.07)]), paper)
    assert termination_holds("kneel", (), _at([0, 0, -(knee_bottom - 0.07)]), paper, eps=0.08)


def test_grasp_and_release(paper):
    grasp_point = paper.object("O1").grasp_points[0]
    near = _at(grasp_point + np.array([0, 0, 0.03]) - REST[J["r_hand"]])
    far = _at(grasp_point + np.array([0, 0, 0.20]) - REST[J["r_hand"]])
    assert termination_holds("grasp", ["O1"], near, paper)
    assert not termination_holds("release", ["O1"], near, paper)
    assert not termination_holds("grasp", ["O1"], far, paper)
    assert termination_holds("release(O1)", None, far, paper)
    assert termination_holds("grasp", ["O1"], far, paper, eps=0.2)
    # The object moves: grasp is evaluated where objects_state puts it.
    moved = {"O1": grasp_point + np.array([0, 0, 0.15])}
    assert termination_holds("grasp", ["O1"], far, paper, moved)


def test_hand_region_tasks(paper):
    r1 = paper.region("R1").center
    # Right-hand capsule (wrist-palm, vertical) centred in R1.
    mid = 0.5 * (REST[J["r_wrist"]] + REST[J["r_hand"]])
    pose = _at(r1 - mid)
    assert termination_holds("rightHand", ["R1"], pose, paper)
    assert not termination_holds("leftHand", ["R1"], pose, paper)
    assert not termination_holds("assemble", ["R1"], pose, paper)
    assert termination_holds("walk", ["R1"], pose, paper)
    assert not termination_holds("walk", ["R1"], REST, paper)
    assert termination_holds("walk", ["R0"], REST, paper)
    # Both hands: two-bone IK of each arm towards the region centre.
    both = _at([0.6, -1.0, 0.0])
    for side in ("l", "r"):
        for _ in range(4):
            m = 0.5 * (both[J[f"{side}_wrist"]] + both[J[f"{side}_hand"]])
            both = reach_pose(both, side, both[J[f"{side}_hand"]] + r1 - m)
    assert termination_holds("assemble", ["R1"], both, paper)
    assert expand_task("assemble", ["R1"], paper) == [("leftHand", ("R1",)),
                                                      ("rightHand", ("R1",))]


def test_object_tasks(paper):
    r1 = paper.region("R1")
    body_at_bench = _at([0.6, -1.0, 0.0])
    reach = body_at_bench.copy()
    reach[J["r_hand"]] = r1.center            # (only enter(x, R1) matters for carry)
    state_in = {"O1": r1.center}
    state_out = {"O1": paper.object("O1").position}
    assert termination_holds("move", ["O1", "R1"], REST, paper, state_in)
    assert not termination_holds("move", ["O1", "R1"], REST, paper, state_out)
    assert not termination_holds("move", ["O1", "R1"], REST, paper)     # initial positions
    assert termination_holds("carry", ["O1", "R1"], reach, paper, state_in)
    assert not termination_holds("carry", ["O1", "R1"], REST, paper, state_in)
    assert not termination_holds("carry", ["O1", "R1"], reach, paper, state_out)


def test_insert_and_extract():
    cell = cell_from_yaml("""
start_region: R0
regions:
  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}
objects:
  peg: {position: [1.0, 0.0, 1.0], shape: cylinder, size: [0.02, 0.1]}
  bin: {position: [1.0, 1.0, 1.0], shape: box, size: [0.2, 0.2, 0.2], movable: false}
""")
    inside = {"peg": [1.0, 1.0, 1.0]}
    poking = {"peg": [1.0, 1.0, 1.06]}
    away = {"peg": [1.0, 0.0, 1.0]}
    assert termination_holds("insert", ["peg", "bin"], REST, cell, inside)
    assert not termination_holds("insert", ["peg", "bin"], REST, cell, poking)
    assert not termination_holds("extract", ["peg", "bin"], REST, cell, poking)
    assert termination_holds("extract", ["peg", "bin"], REST, cell, away)
    assert not termination_holds("insert", ["peg", "bin"], REST, cell)


def test_sit(demo):
    seat = demo.object("stool").sitting_surface_at()
    seat_top = seat.aabb()[1][2]
    lowest = REST[[J["l_hip"], J["r_hip"]], 2].min() - 0.105        # buttocks capsule bottom
    x, y = demo.object("stool").position[:2]
    sitting = _at([x, y, seat_top + 0.02 - lowest])
    hovering = _at([x, y, seat_top + 0.12 - lowest])
    assert termination_holds("sit", ["stool"], sitting, demo)
    assert not termination_holds("sit", ["stool"], hovering, demo)
    # Objects without a sitting surface use the top of their bounds.
    top = demo.object("O1").sitting_surface_at()
    np.testing.assert_allclose(top.aabb()[1], demo.object("O1").shape.aabb()[1])


def test_wait_needs_stillness_for_the_duration(paper):
    still = np.repeat(REST[None], 31, axis=0)                        # 1 s at 30 fps
    assert termination_holds("wait", [1.0], still, paper, fps=30.0)
    assert not termination_holds("wait", [2.0], still, paper, fps=30.0)
    assert termination_holds("wait", ["0.5s"], still, paper, fps=30.0)
    moving = still.copy()
    moving[10:, J["r_hand"], 0] += 0.08                              # hand moves 8 cm
    assert not termination_holds("wait", [1.0], moving, paper, fps=30.0)
    assert termination_holds("wait", [1.0], moving, paper, fps=30.0, eps=0.1)
    series = termination_series("wait", [0.5], moving, paper, fps=30.0)
    assert not series.any()                                          # broken at 0.33 s
    with pytest.raises(ValueError, match="needs fps"):
        termination_holds("wait", [1.0], still, paper)


def test_series_on_a_synthetic_motion(paper):
    synth = demo_synthesized_motion(paper)
    series = termination_series("assemble", ["R1"], synth.positions, paper,
                                synth.objects, fps=synth.fps)
    assert series.shape == (synth.n_frames,)
    first = int(np.argmax(series))
    start = synth.timeline[0].start_frame
    assert series[-1] and first > start and not series[:start].any()
    walk = termination_series("walk", ["R0"], synth.positions, paper)
    assert walk[0] and not walk[-1]


def test_every_table_i_task_is_evaluable(paper, demo):
    args = {"wait": ["0"], "move": ["O1", "R1"], "leftHand": ["R1"], "rightHand": ["R1"],
            "insert": ["O1", "O2"], "extract": ["O1", "O2"], "grasp": ["O1"],
            "release": ["O1"], "sit": ["O1"], "standUp": [], "bend": [], "stoop": [],
            "kneel": [], "walk": ["R1"], "carry": ["O1", "R1"]}
    assert set(args) == set(TASK_NAMES)
    for task in TASK_NAMES:
        value = termination_holds(task, args[task], REST, paper, fps=30.0)
        assert isinstance(value, bool)


def test_bad_tasks_raise(paper):
    with pytest.raises(ValueError, match="unknown task 'jump'"):
        termination_holds("jump", [], REST, paper)
    with pytest.raises(ValueError, match="takes 1 argument"):
        termination_holds("grasp", [], REST, paper)
    with pytest.raises(ValueError, match="no object 'O9'"):
        termination_holds("grasp", ["O9"], REST, paper)
    with pytest.raises(ValueError, match="shape"):
        termination_series("standUp", [], REST, paper)
    with pytest.raises(ValueError, match="expected a task"):
        parse_task("grasp(O1")
    assert parse_task(" carry( O1 , R1 ) ") == ("carry", ("O1", "R1"))
    assert parse_task("standUp") == ("standUp", ())
