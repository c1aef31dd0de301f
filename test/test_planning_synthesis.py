"""End-to-end synthesis on the paper's cell (S1, S2) and on cells with obstacles.

These use the real motion library (DeepMimic clips from pybullet, cached on disk) and
the real scene, LTL and verification code: nothing is mocked.
"""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.errors import PlanningError, SpecError, VerificationError
from ltl_human_motion.ltl.evaluator import evaluate_lasso
from ltl_human_motion.ltl.spec import build_specification
from ltl_human_motion.planning.exports import npz_bytes
from ltl_human_motion.planning.pipeline import (
    SynthesisOptions,
    get_library,
    resolve_cell,
    synthesize,
)
from ltl_human_motion.planning.result import SynthesizedMotion
from ltl_human_motion.planning.verify import verify_motion
from ltl_human_motion.scene.predicates import collision

# The checks verify_motion runs by default, the biomechanical ones (tested one by one in
# test_biomechanics.py) included.
CHECKS = ("start", "collision", "termination", "ltl", "smoothness", "feet",
          "joint_speed", "range_of_motion", "self_penetration", "balance", "foot_skate")


@pytest.fixture(scope="module")
def paper_cell():
    return resolve_cell("paper_cell")


@pytest.fixture(scope="module")
def library():
    return get_library()


@pytest.fixture(scope="module")
def s1(paper_cell, library) -> SynthesizedMotion:
    return synthesize("S1", paper_cell, library=library, seed=3, cycles=2)[0]


@pytest.fixture(scope="module")
def s2_variants(paper_cell, library) -> list[SynthesizedMotion]:
    return synthesize("S2", paper_cell, library=library, variants=2, seed=5)


def _passed(synth: SynthesizedMotion) -> dict[str, bool]:
    return {k: v["passed"] for k, v in synth.verification.items() if isinstance(v, dict)}


def test_s1_repeats_grasp_then_assemble_and_passes_every_check(s1, paper_cell) -> None:
    assert s1.sequence == ["grasp(O1)", "assemble(R1)"] * 2
    assert _passed(s1) == dict.fromkeys(CHECKS, True)
    assert s1.verification["passed"]
    # The timeline marks each task step once, in order, inside the motion.
    assert [seg.task for seg in s1.timeline] == s1.sequence
    starts = [seg.start_frame for seg in s1.timeline]
    assert starts == sorted(starts) and s1.timeline[-1].end_frame <= s1.motion.n_frames
    # The right or left palm really is at O1 while grasping, and both palms in R1 later.
    r1 = paper_cell.region("R1")
    assemble = s1.timeline[1]
    window = s1.motion.positions[assemble.start_frame:assemble.end_frame]
    palms = window[:, [s1.motion.skeleton.index("l_hand"), s1.motion.skeleton.index("r_hand")]]
    inside = np.all(r1.contains(palms.reshape(-1, 3)).reshape(palms.shape[:2]), axis=1)
    assert inside.any()


def test_s1_carries_the_part_to_the_bench(s1, paper_cell) -> None:
    o1 = s1.objects["O1"]
    assert o1.shape == (s1.motion.n_frames, 3)
    start = paper_cell.object("O1").position
    np.testing.assert_allclose(o1[0], start)
    # While assembling, the part is in the assembly region's neighbourhood.
    seg = s1.timeline[1]
    mid = (seg.start_frame + seg.end_frame) // 2
    assert np.linalg.norm(o1[mid] - paper_cell.region("R1").center) < 0.3


def test_s2_variants_grasp_both_parts_in_both_orders(s2_variants) -> None:
    orders = {tuple(s.sequence[:2]) for s in s2_variants}
    assert orders == {("grasp(O1)", "grasp(O2)"), ("grasp(O2)", "grasp(O1)")}
    for synth in s2_variants:
        assert synth.sequence[2] == "assemble(R1)"
        assert synth.verification["passed"], synth.verification


def test_every_returned_trace_satisfies_the_spec_with_the_independent_evaluator(
        s2_variants, paper_cell) -> None:
    spec = build_specification("S2", paper_cell)
    for synth in s2_variants:
        trace = [frozenset(x) for x in synth.verification["ltl"]["trace"]]
        assert evaluate_lasso(spec.formula, [], trace)


def test_same_seed_gives_identical_bytes_and_other_seeds_differ(paper_cell, library) -> None:
    a = synthesize("S1", paper_cell, library=library, seed=11)[0]
    b = synthesize("S1", paper_cell, library=library, seed=11)[0]
    c = synthesize("S1", paper_cell, library=library, seed=12)[0]
    assert npz_bytes(a) == npz_bytes(b)
    assert npz_bytes(a) != npz_bytes(c)


def test_real_time_factor_and_stage_times_are_reported(s1) -> None:
    stats = s1.stats
    for key in ("automaton_time", "sequence_time", "planning_time", "blending_time",
                "verification_time", "total_time"):
        assert getattr(stats, key) >= 0.0, key
    assert stats.planning_time > 0.0 and stats.nodes_expanded > 0
    assert stats.real_time_factor == pytest.approx(s1.motion.duration / stats.total_time)


def test_walks_around_a_wall_between_the_worker_and_the_part(library) -> None:
    cell = resolve_cell("obstacle_cell")
    synth = synthesize("grasp(O1) & F assemble(R1)", cell, library=library, seed=0)[0]
    assert synth.verification["passed"]
    wall = cell.obstacle("wall")
    lo, hi = wall.aabb()
    root = synth.motion.positions[:, 0]
    crossing = np.abs(root[:, 0] - (lo[0] + hi[0]) / 2) < 0.1
    assert crossing.any()
    # Where the worker passes the wall's plane, it is beyond the wall's end.
    assert np.all((root[crossing, 1] < lo[1]) | (root[crossing, 1] > hi[1]))
    assert not collision(synth.motion.positions, cell).any()


def test_unreachable_object_gives_a_specific_error(library) -> None:
    cell = resolve_cell("""
name: high_shelf
start_region: R0
objects:
  O1: {position: [1.5, 0.0, 2.6], shape: box, size: [0.1, 0.1, 0.1]}
regions:
  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}
""")
    # Refused by the early analysis (planning/feasibility.py), before any search.
    with pytest.raises(PlanningError, match=r"grasp\(O1\).*above the reach of a 1.75 m "
                                            r"worker") as info:
        synthesize("F grasp(O1)", cell, library=library)
    assert info.value.reason == "reach"
    assert info.value.task == "grasp(O1)"


def test_object_walled_in_gives_a_blocked_error(library) -> None:
    cell = resolve_cell("""
name: cage
start_region: R0
objects:
  O1: {position: [2.0, 0.0, 0.8], shape: box, size: [0.1, 0.1, 0.1]}
regions:
  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}
obstacles:
  cage:
    parts:
      - {shape: box, position: [1.2, 0.0, 1.0], size: [0.1, 3.0, 2.0]}
      - {shape: box, position: [2.8, 0.0, 1.0], size: [0.1, 3.0, 2.0]}
      - {shape: box, position: [2.0, 1.45, 1.0], size: [1.7, 0.1, 2.0]}
      - {shape: box, position: [2.0, -1.45, 1.0], size: [1.7, 0.1, 2.0]}
""")
    with pytest.raises(PlanningError, match="block") as info:
        synthesize("F grasp(O1)", cell, library=library)
    assert info.value.reason == "blocked"


def test_bad_spec_and_bad_names_raise_spec_errors(paper_cell, library) -> None:
    with pytest.raises(SpecError, match="line 1, column"):
        synthesize("grasp(O1) & (", paper_cell, library=library)
    with pytest.raises(SpecError, match="O9"):
        synthesize("F grasp(O9)", paper_cell, library=library)
    with pytest.raises(SpecError):
        synthesize("grasp(O1) & G !grasp(O1)", paper_cell, library=library)


def test_verification_rejects_a_motion_with_a_jump(s1, paper_cell) -> None:
    from ltl_human_motion.ltl.sequences import synthesize_sequences
    from ltl_human_motion.motion.types import Motion

    pos = s1.motion.positions.copy()
    pos[500:, :, 0] += 0.3                                   # teleport by 30 cm
    broken = SynthesizedMotion(Motion(pos, s1.motion.fps, s1.motion.skeleton), s1.root_yaw,
                               s1.task_index, s1.timeline, s1.objects, s1.spec, s1.sequence)
    spec = build_specification("S1", paper_cell)
    seq = synthesize_sequences(spec, paper_cell, n=1, mode="all", cycles=2)[0]
    with pytest.raises(VerificationError, match="smoothness") as info:
        verify_motion(broken, paper_cell, spec, seq, stature=1.75)
    assert info.value.check in ("collision", "smoothness")
    assert "fastest joint" in str(info.value)


def test_options_from_service_json_are_checked() -> None:
    opts = SynthesisOptions.from_dict({"sequence_mode": "coverage", "max_nodes": 500})
    assert opts.sequence_mode == "coverage" and opts.planner.budget.max_nodes == 500
    with pytest.raises(ValueError, match="unknown synthesis options"):
        SynthesisOptions.from_dict({"speed": 3})
    # the biomechanical checks are on unless the request turns them off, with a boolean
    assert SynthesisOptions.from_dict({}).verification.biomechanics is True
    assert SynthesisOptions.from_dict({"biomechanics": False}).verification.biomechanics \
        is False
    with pytest.raises(ValueError, match="'biomechanics' must be true or false"):
        SynthesisOptions.from_dict({"biomechanics": "no"})


TASK_CELL = """
name: tasks
start_region: R0
objects:
  O1: {position: [1.2, 0.8, 0.8], shape: box, size: [0.08, 0.08, 0.08],
       grasp_points: [[0, 0, 0.04]]}
  stool: {position: [-1.2, 0.0, 0.225], shape: cylinder, size: [0.18, 0.45], movable: false,
          sitting_surface: {lo: [-0.18, -0.18, 0.2], hi: [0.18, 0.18, 0.225]}}
regions:
  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}
  R1: {lo: [1.1, -1.1, 0.9], hi: [1.3, -0.9, 1.1]}
  R2: {lo: [-1.5, 1.2, 0.0], hi: [-0.9, 1.8, 2.0]}
obstacles:
  table: {shape: box, position: [1.4, 0.8, 0.375], size: [0.6, 0.6, 0.75]}
"""


@pytest.mark.parametrize("spec", [
    "grasp(O1) & X move(O1, R1) & X X release(O1)",
    "grasp(O1) & X carry(O1, R2) & X X release(O1)",
    "wait(1.0) & X bend & X X stoop & X X X kneel",
    "sit(stool) & X standUp & X X walk(R2)",
    "grasp(O1) & X rightHand(R1) & X X leftHand(R1)",
])
def test_every_table_i_task_plans_and_verifies(spec: str, library) -> None:
    synth = synthesize(spec, TASK_CELL, library=library, seed=0)[0]
    assert synth.verification["passed"], synth.verification
    assert len(synth.timeline) == len(synth.sequence) >= 3


@pytest.mark.parametrize("stature", [1.55, 1.95])
def test_s1_verifies_for_the_smallest_and_the_tallest_worker(stature: float,
                                                              paper_cell) -> None:
    """The part carried by a 1.55 m worker hangs lower: the planner checks it against
    the bench while stepping in, as verification does."""
    synth = synthesize("S1", paper_cell, stature=stature, seed=0)[0]
    assert synth.verification["passed"], synth.verification
    head = synth.motion.positions[0, synth.motion.skeleton.index("head"), 2]
    assert abs(head - 0.9 * stature) < 0.1 * stature


@pytest.mark.parametrize("spec, last_primitive", [
    ("F move(O1, R1)", "rightHand"),          # R1 (final region) is entered by a hand
    ("F carry(O1, R1)", "move"),              # the part is put into R1
    ("F (grasp(O1) & F (release(O1) & F grasp(O2)))", "rightHand"),
])
def test_a_region_above_the_bench_is_entered_with_the_hands(spec: str, last_primitive: str,
                                                             paper_cell, library) -> None:
    """Nobody can stand in R1 (a box above the bench), yet walk(R1) and carry(O, R1) need
    enter(x, R1): the planner reaches into it, and verification agrees."""
    synth = synthesize(spec, paper_cell, library=library, seed=0)[0]
    assert synth.verification["passed"], synth.verification
    # the step that enters R1 (the cell model may place it before the last step)
    entry = next(s for s in synth.timeline if s.task in ("walk(R1)", "carry(O1, R1)"))
    assert entry.primitive.startswith(last_primitive)
    r1 = paper_cell.region("R1")
    hands = synth.motion.positions[:, [synth.motion.skeleton.index(j)
                                       for j in ("l_hand", "r_hand")]]
    inside = np.all((hands >= r1.lo) & (hands <= r1.hi), axis=-1).any(axis=-1)
    assert inside.any()


def test_carry_and_move_fetch_the_part_first(library) -> None:
    """carry(O1, R2) and move(O1, R1) without an earlier grasp: the part is grasped on
    the way, and its track passes through the region during the task."""
    for spec, region in (("carry(O1, R2)", "R2"), ("move(O1, R1)", "R1")):
        synth = synthesize(spec, TASK_CELL, library=library, seed=0)[0]
        assert synth.verification["passed"], (spec, synth.verification)
        cell = resolve_cell(TASK_CELL)
        start = np.asarray(cell.object("O1").position)
        seg = synth.timeline[0]
        track = synth.objects["O1"]
        assert np.allclose(track[0], start)
        reg = cell.region(region)
        window = track[seg.start_frame:seg.end_frame]
        assert np.all((window >= reg.lo) & (window <= reg.hi), axis=-1).any()
