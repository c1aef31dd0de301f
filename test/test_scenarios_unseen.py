"""The unseen-style scenario family (issue 33 item 4): deterministic cells that the real
loader reads, physically laid out, labelled from geometry; the benchmark's failure causes.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from test_scenarios import _supported

from ltl_human_motion.scenarios.labels import Labeller, Opening, Worker, label_task
from ltl_human_motion.scenarios.run import failure_cause, judge, run_pair
from ltl_human_motion.scenarios.unseen import FAMILIES, build_cell, generate_unseen
from ltl_human_motion.scene.cell_yaml import cell_from_yaml

SCENARIOS = generate_unseen(2, seed=0)
CELLS = {(f, i): build_cell(f, 0, i) for f in FAMILIES for i in range(2)}


def test_the_family_is_deterministic_per_seed() -> None:
    again = generate_unseen(2, seed=0)
    assert [(s.name, s.stature, s.yaml, s.pairs) for s in again] == \
        [(s.name, s.stature, s.yaml, s.pairs) for s in SCENARIOS]
    other = build_cell("chamber", 1, 0)
    assert other.yaml != CELLS["chamber", 0].yaml
    assert {s.family for s in SCENARIOS} == set(FAMILIES)
    assert {s.stature for s in SCENARIOS} == {1.55, 1.75, 1.95}


def test_the_default_set_has_a_modest_share_of_clear_refusals() -> None:
    pairs = [p for s in SCENARIOS for p in s.pairs]
    infeasible = [p for p in pairs if p.expect == "infeasible"]
    assert 200 <= len(pairs) <= 320
    assert 0.08 <= len(infeasible) / len(pairs) <= 0.16
    reasons = Counter((s.family, p.reason) for s in SCENARIOS for p in s.pairs
                      if p.expect == "infeasible")
    assert {f for f, _ in reasons} >= set(FAMILIES) - {"conveyor"}
    assert {r for _, r in reasons} <= {"reach", "size", "no_floor"}
    for s in SCENARIOS:
        for p in s.pairs:
            assert p.expect in ("feasible", "infeasible")
            if p.expect == "infeasible":
                assert p.kind == f"infeasible:{p.reason}" and p.why, (s.name, p)


def _interior(lo: np.ndarray, hi: np.ndarray, shrink: float = 0.004) -> np.ndarray:
    axes = [np.linspace(lo[i] + shrink, hi[i] - shrink, 5) for i in range(3)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


@pytest.mark.parametrize("key", sorted(CELLS), ids=lambda k: f"{k[0]}_{k[1]}")
def test_every_cell_loads_and_is_physical(key) -> None:
    built = CELLS[key]
    cell = cell_from_yaml(built.yaml, source=built.name)
    assert cell.frame == "zup" and cell.start_region.name == "R0"
    for obj in cell.objects.values():
        lo, hi = obj.shape.aabb()
        assert np.all(lo >= cell.workspace_lo - 1e-9) and np.all(hi <= cell.workspace_hi + 1e-9)
        inside = np.zeros(125, dtype=bool)
        for ob in cell.obstacles:
            inside |= ob.contains(_interior(lo, hi))
        assert not inside.any(), f"{built.name}: {obj.name} overlaps an obstacle"
        if obj.movable:
            assert _supported(cell, obj.name), f"{built.name}: {obj.name} floats"
    for region in cell.regions.values():
        pts = _interior(region.lo, region.hi)
        assert not all(any(ob.contains(p[None])[0] for ob in cell.obstacles) for p in pts)
    for _kind, spec, tasks in built.candidates:
        assert spec.startswith("F")
        for t in tasks:
            for arg in t[t.find("(") + 1:-1].split(","):
                if arg.strip():
                    cell.lookup(arg.strip())


@pytest.mark.parametrize("index", [0, 1])
def test_a_chamber_opening_is_the_hole_in_the_machine_front(index: int) -> None:
    built = CELLS["chamber", index]
    cell = cell_from_yaml(built.yaml)
    (op,) = built.openings
    cnc = cell.obstacle("cnc")
    assert 0.5 <= op.width <= 0.9 and 0.6 <= op.height <= 0.8
    assert 0.8 <= op.lo[2] <= 1.1
    assert not cnc.contains(_interior(op.lo, op.hi, 0.01)).any()
    mid = (op.lo + op.hi) / 2
    toward = -np.sign(mid[op.axis])                  # the room is towards the cell's middle
    inner = op.lo[op.axis] if toward < 0 else op.hi[op.axis]
    side = 1 - op.axis
    for offset, blocked in ((0.0, False), (op.width / 2 + 0.04, True)):
        p = mid.copy()
        p[op.axis] = inner + toward * 0.025          # in the front panel
        p[2] = op.lo[2] + op.height / 2
        p[side] += offset
        assert bool(cnc.contains(p[None])[0]) == blocked
    for vise in ("vise_a", "vise_b"):
        lo, hi = cell.object(vise).shape.aabb()
        depth = min(abs(lo[op.axis] - inner), abs(hi[op.axis] - inner))
        assert 0.1 - 1e-3 <= depth <= 0.3 + 1e-3
    assert op.holds(cell.object("done").position)


# --------------------------------------------------------------- hand-checked labels
_CELL = """
name: hand_checked
workspace: {lo: [-3, -3, 0], hi: [3, 3, 3]}
start_region: R0
objects:
  P_table: {position: [1.1, 0.0, 0.95], shape: box, size: [0.08, 0.08, 0.08]}
  P_high:  {position: [1.1, 1.0, 2.24], shape: box, size: [0.08, 0.08, 0.08]}
  P_deep:  {position: [2.85, -2.85, 0.95], shape: box, size: [0.08, 0.08, 0.08]}
  big:     {position: [-1.5, 1.5, 0.3], shape: box, size: [0.6, 0.6, 0.6]}
  small:   {position: [-1.5, -1.5, 0.05], shape: box, size: [0.1, 0.1, 0.1]}
regions:
  R0: {lo: [-0.3, -0.3, 0], hi: [0.3, 0.3, 0.1]}
  R_in: {lo: [-2.75, -0.5, 1.0], hi: [-1.95, 0.5, 1.8]}
obstacles:
  table: {shape: box, position: [1.4, 0.0, 0.45], size: [0.8, 1.0, 0.9]}
  board: {shape: box, position: [1.25, 1.0, 2.19], size: [0.4, 0.8, 0.02]}
  line: {shape: box, position: [2.05, -2.0, 0.45], size: [1.9, 2.0, 0.9]}
  machine:
    parts:
      - {shape: box, position: [-2.35, 0, 0.5], size: [0.9, 1.2, 1.0]}
      - {shape: box, position: [-2.35, 0, 1.85], size: [0.9, 1.2, 0.1]}
      - {shape: box, position: [-2.35, 0.55, 1.4], size: [0.9, 0.1, 0.8]}
      - {shape: box, position: [-2.35, -0.55, 1.4], size: [0.9, 0.1, 0.8]}
      - {shape: box, position: [-2.85, 0, 1.4], size: [0.1, 1.2, 0.8]}
      - {shape: box, position: [-1.925, 0.375, 1.4], size: [0.05, 0.25, 0.8]}
      - {shape: box, position: [-1.925, -0.375, 1.4], size: [0.05, 0.25, 0.8]}
      - {shape: box, position: [-1.925, 0, 1.75], size: [0.05, 0.5, 0.1]}
"""
#: The machine's door: 0.5 x 0.7 m at 1.0-1.7 m, the cavity behind it.
_OPENING = Opening("machine", np.array([-2.8, -0.5, 1.0]), np.array([-1.95, 0.5, 1.8]),
                   0.5, 0.7, 0)


def _labeller() -> Labeller:
    return Labeller(cell_from_yaml(_CELL), (_OPENING,))


def test_a_part_beyond_the_short_workers_reach_is_infeasible_for_them_only() -> None:
    lab = _labeller()
    short = lab.label(["grasp(P_high)"], 1.55)          # bottom 2.20 m > 1.94 + 0.10 m
    assert (short.expect, short.reason) == ("infeasible", "reach")
    assert "1.55 m worker" in short.why
    assert lab.label(["grasp(P_high)"], 1.95).expect == "ambiguous"   # reachable, not comfy
    for h in (1.55, 1.75, 1.95):
        assert lab.label(["grasp(P_table)"], h).expect == "feasible"
    assert Worker(1.55).vertical == pytest.approx(1.9375)


def test_a_part_wider_than_the_opening_cannot_go_in() -> None:
    lab = _labeller()
    wide = lab.label(["move(big, R_in)"], 1.75)         # a 0.6 m cube, a 0.5 m door
    assert (wide.expect, wide.reason) == ("infeasible", "size")
    assert "0.50 x 0.70 m opening of machine" in wide.why
    assert lab.label(["move(small, R_in)"], 1.75).expect == "feasible"
    # without the opening the same cavity is big enough for the cube
    assert label_task(cell_from_yaml(_CELL), "move(big, R_in)", 1.75).expect \
        == "feasible"


def test_a_part_with_no_floor_within_any_reach_is_infeasible() -> None:
    lab = _labeller()
    for h in (1.55, 1.75, 1.95):
        label = lab.label(["grasp(P_deep)"], h)          # 1.8 m into a line at the walls
        assert (label.expect, label.reason) == ("infeasible", "no_floor"), h
    seq = lab.label(["grasp(P_table)", "grasp(P_deep)"], 1.75)
    assert seq.reason == "no_floor"


def test_generated_refusals_are_the_geometric_ones() -> None:
    by = {(s.family, s.stature): s for s in SCENARIOS if s.index == 0}
    chamber = next(p for p in by["chamber", 1.75].pairs if p.expect == "infeasible")
    assert chamber.spec == "F move(casting, R_bay)" and chamber.reason == "size"
    assert "opening of cnc" in chamber.why
    for fam in ("boards", "aisle"):
        short = [p for p in by[fam, 1.55].pairs if p.expect == "infeasible"]
        assert [p.reason for p in short] == ["reach"]
        assert all(p.spec != "F grasp(P_top)" for p in by[fam, 1.95].pairs)
        assert any(spec == "F grasp(P_top)" for spec, _ in by[fam, 1.95].dropped)


def test_a_generated_refusal_is_refused_by_the_pipeline_for_its_reason() -> None:
    scen = next(s for s in SCENARIOS if s.family == "desk" and s.stature == 1.75)
    pair = next(p for p in scen.pairs if p.expect == "infeasible")
    outcome = run_pair(pair.spec, scen.yaml, scen.stature, 0, timeout=60.0)
    assert judge(pair.expect, pair.reason, outcome) == (True, "ok"), outcome.message


# --------------------------------------------------------------- failure causes
@pytest.mark.parametrize("message, cause", [
    ("task insert(blank, vise_b): every insert motion tried (6) runs into an obstacle; "
     "closest try: the right upper arm enters cnc by 5.6 cm at t = 0.70 s; so did 3 other "
     "placements tried", "insert: right upper arm enters cnc"),
    ("verification failed (collision): collision: 18 frames collide, first at t = 3.00 s; "
     "a carried part meets an obstacle", "verification collision: a carried part meets an "
     "obstacle"),
    ("verification failed (collision, feet): collision: 5 frames collide, first at t = "
     "1.00 s; deepest: the right hand enters desk by 1.0 cm at t = 2.00 s",
     "verification collision: right hand enters desk"),
    ("verification failed (joint_speed): joint_speed: r_toe at frame 2053 (17.11 s, walk) "
     "moves at 5.80 m/s, over its limit 5.46 m/s", "verification joint_speed: r_toe"),
    ("task grasp(O2): reach grasp(O2) at (2.00, -0.52, 0.50): no place to stop within 0.05 "
     "m of the reach spot keeps the body clear (400 nodes searched)",
     "grasp: no place to stop within # m of the reach spot keeps the body clear"),
    ("no answer within 10.0 s (planning grasp(P1))", "timeout grasp"),
    ("no answer within 10.0 s", "timeout"),
])
def test_failure_causes_group_runs_that_failed_alike(message: str, cause: str) -> None:
    assert failure_cause(message) == cause


def test_a_run_without_a_message_is_named_by_its_family() -> None:
    assert failure_cause("", "false_verified") == "false_verified"
