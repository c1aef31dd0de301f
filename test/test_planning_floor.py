"""Cells on a platform or in a pit (``floor_z`` not 0): planned on a floor at z = 0 and
lifted back, so the motion is the zero-floor motion moved up by ``floor_z``.

The family came from the random generator (seed 7: 6 of 30 cells on a raised or sunk
floor failed 70 of 330 feasible pairs: parts "at height -0.30 m", feet 0.5 m under the
floor, the first frame outside R0).
"""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.planning.pipeline import resolve_cell, synthesize

CELL = """
name: platform
floor_z: {floor}
workspace: {{lo: [-3, -3, {floor}], hi: [3, 3, {top}]}}
start_region: R0
objects:
  O1: {{position: [1.2, -0.9, {o1}], shape: box, size: [0.06, 0.06, 0.06]}}
  stool:
    position: [-1.0, 1.0, {stool}]
    shape: cylinder
    size: [0.18, 0.45]
    movable: false
    sitting_surface: {{lo: [-0.18, -0.18, 0.2], hi: [0.18, 0.18, 0.225]}}
regions:
  R0: {{lo: [-0.4, -0.4, {floor}], hi: [0.4, 0.4, {r0}]}}
  R2: {{lo: [1.0, 0.6, {floor}], hi: [1.5, 1.1, {r0}]}}
obstacles:
  table: {{shape: box, position: [1.2, -1.1, {table}], size: [0.8, 0.6, 0.75]}}
"""


def _cell(floor: float):
    return resolve_cell(CELL.format(floor=floor, top=floor + 2.5, o1=floor + 0.78,
                                    stool=floor + 0.225, r0=floor + 0.1,
                                    table=floor + 0.375))


@pytest.mark.parametrize("spec", ["F grasp(O1)", "F move(O1, R2)",
                                  "F(sit(stool) & X standUp)", "F kneel"])
@pytest.mark.parametrize("floor", [0.5, -0.4])
def test_a_raised_or_sunk_floor_moves_the_motion_up_by_its_height(spec, floor):
    flat = synthesize(spec, _cell(0.0), seed=3)[0]
    raised = synthesize(spec, _cell(floor), seed=3)[0]
    assert raised.verification["passed"], raised.verification
    assert raised.sequence == flat.sequence
    lift = np.array([0.0, 0.0, floor])
    np.testing.assert_allclose(raised.motion.positions, flat.motion.positions + lift,
                               atol=1e-9)
    for name, track in flat.objects.items():
        np.testing.assert_allclose(raised.objects[name], track + lift, atol=1e-9)


def test_floor_at_zero_moves_every_solid_and_keeps_the_names():
    cell = _cell(1.2)
    low = cell.floor_at_zero()
    assert low.floor_z == 0.0 and cell.floor_z == 1.2
    assert low.region("R0").lo[2] == pytest.approx(0.0)
    assert low.object("O1").position[2] == pytest.approx(0.78)
    assert low.obstacle("table").aabb()[1][2] == pytest.approx(0.75)
    assert low.start_region is low.region("R0")
    flat = _cell(0.0)
    assert flat.floor_at_zero() is flat
