"""REBA, RULA and NIOSH scoring from body angles and task data (the methods' inputs).

Properties of the tables and the step-by-step procedure on constructed postures. The
checks against the methods' publications (worksheet tables cell by cell, the NIOSH
manual's Example 4 and table values) are in test_assess_published.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.assess import niosh, reba, rula


# ---------------------------------------------------------------------- REBA
def test_reba_tables_shape_and_monotone():
    assert reba.TABLE_A.shape == (5, 3, 4)
    assert reba.TABLE_B.shape == (6, 2, 3)
    assert reba.TABLE_C.shape == (12, 12)
    # Worse posture never scores lower, along every axis of every table.
    for t in (reba.TABLE_A, reba.TABLE_B, reba.TABLE_C):
        for ax in range(t.ndim):
            assert np.all(np.diff(t, axis=ax) >= 0), (t.shape, ax)
    # Published anchor cells: best and worst combinations.
    assert reba.TABLE_A[0, 0, 0] == 1 and reba.TABLE_A[4, 2, 3] == 9
    assert reba.TABLE_B[0, 0, 0] == 1 and reba.TABLE_B[5, 1, 2] == 9
    assert reba.TABLE_C[0, 0] == 1 and reba.TABLE_C[11, 11] == 12
    # Table A, neck 3, trunk 1: 3 3 5 6 (the row open implementations most often get wrong).
    assert reba.TABLE_A[0, 2].tolist() == [3, 3, 5, 6]
    # Table C row 6: 6 6 6 7 8 8 9 9 10 10 10 10.
    assert reba.TABLE_C[5].tolist() == [6, 6, 6, 7, 8, 8, 9, 9, 10, 10, 10, 10]


def test_reba_body_part_rules():
    assert reba.trunk_score([0, 10, -10, 30, -30, 70]).tolist() == [1, 2, 2, 3, 3, 4]
    assert reba.trunk_score(30, True) == 4
    assert reba.neck_score([10, 25, -15]).tolist() == [1, 2, 2]
    assert reba.legs_score([False, True, False, False], [10, 10, 45, 70]).tolist() == \
        [1, 2, 2, 3]
    assert reba.legs_score(False, 90, sitting=True) == 1
    assert reba.load_score([2, 5, 10, 12]).tolist() == [0, 1, 1, 2]
    assert reba.upper_arm_score([0, -30, 30, 60, 100]).tolist() == [1, 2, 2, 3, 4]
    assert reba.upper_arm_score(100, True, True) == 6
    assert reba.upper_arm_score(0, supported=True) == 1         # never below 1
    assert reba.lower_arm_score([30, 80, 120]).tolist() == [2, 1, 2]
    assert reba.wrist_score([10, 20]).tolist() == [1, 2]
    assert reba.action_level([1, 2, 3, 4, 7, 8, 10, 11, 15]).tolist() == \
        [0, 1, 1, 2, 2, 3, 3, 4, 4]


def test_reba_procedure_stooped_lift():
    """A constructed stooped two-handed lift, scored step by step with the procedure.

    Inputs: trunk 30 deg flexion (3), neck 25 deg flexion (2), both feet down with knees
    40 deg (1 + 1 = 2), load 6 kg (1); upper arm 50 deg (3), lower arm 110 deg (2), wrist
    20 deg (2), fair coupling (1); one activity point (repeated). Table A (3, 2, 2) = 5,
    score A 6; Table B (3, 2, 2) = 5, score B 6; Table C (6, 6) = 8; REBA 9, "high".
    """
    parts = dict(trunk=reba.trunk_score(30), neck=reba.neck_score(25),
                 legs=reba.legs_score(False, 40), upper_arm=reba.upper_arm_score(50),
                 lower_arm=reba.lower_arm_score(110), wrist=reba.wrist_score(20))
    assert {k: int(v) for k, v in parts.items()} == dict(trunk=3, neck=2, legs=2,
                                                         upper_arm=3, lower_arm=2, wrist=2)
    r = reba.reba_score(**parts, load=reba.load_score(6), coupling=reba.COUPLING["fair"],
                        activity=1)
    assert (int(r["table_a"]), int(r["score_a"]), int(r["table_b"]), int(r["score_b"]),
            int(r["score_c"]), int(r["reba"])) == (5, 6, 5, 6, 8, 9)
    assert int(reba.action_level(r["reba"])) == 3


def test_reba_procedure_neutral_standing():
    """Standing upright, arms down, no load: every part scores 1 except the lower arm
    (elbow straight, < 60 deg: 2); Table A 1, Table B (1, 2, 1) = 1, Table C 1; REBA 1."""
    r = reba.reba_score(reba.trunk_score(0), reba.neck_score(5), reba.legs_score(False, 5),
                        reba.upper_arm_score(0), reba.lower_arm_score(0), reba.wrist_score(0))
    assert int(r["reba"]) == 1 and int(reba.action_level(r["reba"])) == 0


def test_reba_vectorized_and_rejects_bad_scores():
    r = reba.reba_score([1, 5], [1, 3], [1, 4], [1, 6], [1, 2], [1, 3], load=[0, 3],
                        coupling=[0, 3], activity=[0, 3])
    assert r["reba"].tolist() == [1, 15]
    with pytest.raises(ValueError, match=r"1\.\.5"):
        reba.reba_score(6, 1, 1, 1, 1, 1)


# ---------------------------------------------------------------------- RULA
def test_rula_tables():
    assert rula.TABLE_A.shape == (6, 3, 8)
    assert rula.TABLE_B.shape == (6, 12)
    assert rula.TABLE_C.shape == (8, 7)
    for t in (rula.TABLE_A, rula.TABLE_C):
        for ax in range(t.ndim):
            assert np.all(np.diff(t, axis=ax) >= 0)
    assert rula.TABLE_A[0, 0, 0] == 1 and rula.TABLE_A[5, 2, 7] == 9
    # Table B, neck 1: 1 3 2 3 3 4 5 5 6 6 7 7 (legs 2 above legs 1 for trunk 1).
    assert rula.TABLE_B[0].tolist() == [1, 3, 2, 3, 3, 4, 5, 5, 6, 6, 7, 7]
    assert rula.TABLE_C[0].tolist() == [1, 2, 3, 3, 4, 5, 5]
    assert rula.TABLE_C[7].tolist() == [5, 5, 6, 7, 7, 7, 7]


def test_rula_body_part_rules():
    assert rula.upper_arm_score([0, -30, 30, 60, 100]).tolist() == [1, 2, 2, 3, 4]
    assert rula.lower_arm_score([30, 80, 120]).tolist() == [2, 1, 2]
    assert rula.lower_arm_score(80, True) == 2
    assert rula.wrist_score([0, 10, 20]).tolist() == [1, 2, 3]
    assert rula.neck_score([5, 15, 25, -10]).tolist() == [1, 2, 3, 4]
    assert rula.trunk_score([0, 10, 30, 70]).tolist() == [1, 2, 3, 4]
    assert rula.force_score([1, 5, 5, 12, 12], [False, False, True, False, True]).tolist() \
        == [0, 1, 2, 2, 3]
    assert rula.action_level([1, 2, 3, 4, 5, 6, 7]).tolist() == [1, 1, 2, 2, 3, 3, 4]


def test_rula_procedure_reaching_assembly():
    """A constructed reach to a bench, scored step by step with the procedure.

    Group A: upper arm 50 deg (3), lower arm 70 deg (1), wrist 10 deg (2), wrist twist in
    mid-range (1): Table A = 4; muscle use +1 (repeated), load 3 kg intermittent +1:
    score C = 6. Group B: neck 15 deg (2), trunk 25 deg (3), legs supported (1): Table B =
    4; +1 muscle, +1 load: score D = 6. Grand score Table C (6, 6) = 7: action level 4.
    """
    r = rula.rula_score(rula.upper_arm_score(50), rula.lower_arm_score(70),
                        rula.wrist_score(10), 1, rula.neck_score(15), rula.trunk_score(25),
                        1, muscle_a=1, force_a=rula.force_score(3), muscle_b=1,
                        force_b=rula.force_score(3))
    assert (int(r["table_a"]), int(r["score_c"]), int(r["table_b"]), int(r["score_d"]),
            int(r["rula"])) == (4, 6, 4, 6, 7)
    assert int(rula.action_level(r["rula"])) == 4


def test_rula_caps_scores_over_table_range():
    r = rula.rula_score(6, 3, 4, 2, 6, 6, 2, 1, 3, 1, 3)
    assert int(r["score_c"]) == 13 and int(r["score_d"]) == 13 and int(r["rula"]) == 7


# ---------------------------------------------------------------------- NIOSH
def test_niosh_ideal_lift_gives_load_constant():
    res = niosh.lift(10.0, 25, 75, 25, 0, 0.2, "1h", "good")
    assert res.RWL == pytest.approx(23.0)
    assert res.LI == pytest.approx(10 / 23)


def test_niosh_multipliers_from_the_equation():
    res = niosh.lift(10.0, 50, 0, 100, 90, 0.2, "1h", "good")
    assert res.HM == pytest.approx(0.5)
    assert res.VM == pytest.approx(0.775)
    assert res.DM == pytest.approx(0.82 + 0.045)
    assert res.AM == pytest.approx(1 - 0.288)
    assert res.RWL == pytest.approx(23 * 0.5 * 0.775 * 0.865 * 0.712)
    # Beyond the ranges.
    far = niosh.lift(5.0, 70, 180, 200, 140, 0.2)
    assert (far.HM, far.VM, far.DM, far.AM, far.RWL) == (0.0, 0.0, 0.0, 0.0, 0.0)
    assert far.LI == float("inf")
    close = niosh.lift(5.0, 20, 75, 10, 0)
    assert (close.HM, close.DM) == (1.0, 1.0)


def test_niosh_frequency_and_coupling_tables():
    fm = niosh.frequency_multiplier
    assert fm(0.1, "1h", 30) == 1.00 and fm(1, "8h", 30) == 0.75
    assert fm(4, "2h", 80) == 0.72 and fm(9, "8h", 30) == 0.00 and fm(9, "8h", 80) == 0.15
    assert fm(12, "2h", 30) == 0.00 and fm(12, "2h", 80) == 0.21
    assert fm(15, "1h", 80) == 0.28 and fm(16, "1h", 80) == 0.0
    assert fm(2.5, "1h", 30) == pytest.approx(0.895)     # between rows: interpolated
    cm = niosh.coupling_multiplier
    assert (cm("good", 30), cm("fair", 30), cm("fair", 80), cm("poor", 80)) == \
        (1.0, 0.95, 1.0, 0.9)
    with pytest.raises(ValueError, match="duration"):
        fm(1, "4h", 30)
    with pytest.raises(ValueError, match="h_cm"):
        niosh.lift(1.0, -1, 75, 25)


def test_niosh_procedure_floor_to_bench():
    """A constructed lift: a box of 10 kg lifted from 20 cm to a 90 cm bench, 40 cm in
    front of the ankles at the origin and 30 cm at the destination, 30 deg asymmetry at the
    destination, 1 lift a minute for up to 8 hours, fair coupling. The Applications Manual's
    procedure:
    origin HM 0.625, VM 0.835, DM 0.82 + 4.5/70 = 0.8843, AM 1, FM 0.75, CM 0.95 ->
    RWL 23 x ... = 7.56 kg, LI 1.32; destination HM 0.833, VM 0.955, AM 0.904, CM 1.0 ->
    RWL 10.97 kg, LI 0.91. The lift is governed by its origin (LI 1.32 > 1)."""
    o = niosh.lift(10.0, 40, 20, 70, 0, 1, "8h", "fair")
    d = niosh.lift(10.0, 30, 90, 70, 30, 1, "8h", "fair")
    assert o.RWL == pytest.approx(23 * 0.625 * 0.835 * (0.82 + 4.5 / 70) * 0.75 * 0.95)
    assert o.RWL == pytest.approx(7.56, abs=0.01) and o.LI == pytest.approx(1.32, abs=0.01)
    assert d.RWL == pytest.approx(10.97, abs=0.01) and d.LI == pytest.approx(0.91, abs=0.01)


# ---------------------------------------------------------------------- OWAS
def test_owas_codes_and_categories():
    from ltl_human_motion.assess import owas
    assert owas.ACTION_CATEGORY.shape == (4, 3, 7, 3)
    assert set(np.unique(owas.ACTION_CATEGORY)) == {1, 2, 3, 4}
    assert owas.back_code([0, 30, 0, 30], [0, 0, 30, 30]).tolist() == [1, 2, 3, 4]
    assert owas.arms_code([0, 100, 100], [0, 0, 120]).tolist() == [1, 2, 3]
    assert owas.legs_code([0, 40, 40, 40, 0], [0, 40, 0, 0, 0],
                          one_leg=[False, False, False, True, True]).tolist() == [2, 4, 5, 5, 3]
    assert owas.legs_code(0, 0, walking=True) == 7 and owas.legs_code(90, 90, kneeling=True) == 6
    assert owas.load_code([5, 15, 25]).tolist() == [1, 2, 3]
    # Standing straight, arms down, light load: no action. Bent and twisted, both arms
    # up, squatting with more than 20 kg: act immediately.
    assert owas.action_category(1, 1, 2, 1) == 1
    assert owas.action_category(4, 3, 4, 3) == 4
    # Bent back, both arms down, standing on both straight legs, < 10 kg: category 2.
    assert owas.action_category(2, 1, 2, 1) == 2
