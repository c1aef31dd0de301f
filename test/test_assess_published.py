"""REBA, RULA and NIOSH against what the methods' own publications print.

Each test names its source. The sources were read through stored public copies:

- REBA: "REBA Employee Assessment Worksheet" (based on Hignett & McAtamney, Applied
  Ergonomics 31 (2000) 201-205), text of https://scribd.com/document/731952909 and
  https://pdfcoffee.com/reba-7-pdf-free.html; the group A definitions of Hignett &
  McAtamney's chapter in "Fundamentals and Assessment Tools for Occupational Ergonomics"
  (Table 42.2), http://what-when-how.com/Tutorial/topic-53604/
  Fundamentals-and-Assessment-Tools-for-Occupational-Ergonomics-823.html.
- RULA: McAtamney & Corlett, Applied Ergonomics 24 (1993) 91-99 (text of the paper's
  stage 2 and 3 sections, th4.ilovetranslation.com/vCKe8TzaeWW=d and /hZeRv4cNDav=d) and
  the "RULA Employee Assessment Worksheet", https://www.scribd.com/document/36693774.
- NIOSH: Applications Manual for the Revised NIOSH Lifting Equation, DHHS (NIOSH)
  Publication 94-110 (revised 9/2021), Tables 5 and 7 and the Example 4 worksheet
  (Figure 14, p. 46) as transcribed, with page locators, in the nbarr1/ErgonomicTool
  repository (docs/methods/rnle.md and methods/rnle/transcription/*.csv).

No published worked example of REBA or RULA with its body-part inputs and final score was
found in those copies (the papers' example figures are images); their tables and rules are
checked cell by cell here instead, and the grand-score property the RULA paper states in
words is checked over the whole of Table C.
"""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.assess import niosh, reba, rula

# ---------------------------------------------------------------------- REBA
#: REBA worksheet Table A: rows trunk 1-5; columns neck 1 (legs 1-4), neck 2, neck 3.
_REBA_A = [
    [1, 2, 3, 4, 1, 2, 3, 4, 3, 3, 5, 6],
    [2, 3, 4, 5, 3, 4, 5, 6, 4, 5, 6, 7],
    [2, 4, 5, 6, 4, 5, 6, 7, 5, 6, 7, 8],
    [3, 5, 6, 7, 5, 6, 7, 8, 6, 7, 8, 9],
    [4, 6, 7, 8, 6, 7, 8, 9, 7, 8, 9, 9],
]
#: REBA worksheet Table B: rows upper arm 1-6; columns lower arm 1 (wrist 1-3), lower arm 2.
_REBA_B = [
    [1, 2, 2, 1, 2, 3],
    [1, 2, 3, 2, 3, 4],
    [3, 4, 5, 4, 5, 5],
    [4, 5, 5, 5, 6, 7],
    [6, 7, 8, 7, 8, 8],
    [7, 8, 8, 8, 9, 9],
]
#: REBA worksheet Table C, rows score A 1-10 (columns score B 1-12), as printed.
_REBA_C = [
    [1, 1, 1, 2, 3, 3, 4, 5, 6, 7, 7, 7],
    [1, 2, 2, 3, 4, 4, 5, 6, 6, 7, 7, 8],
    [2, 3, 3, 3, 4, 5, 6, 7, 7, 8, 8, 8],
    [3, 4, 4, 4, 5, 6, 7, 8, 8, 9, 9, 9],
    [4, 4, 4, 5, 6, 7, 8, 8, 9, 9, 9, 9],
    [6, 6, 6, 7, 8, 8, 9, 9, 10, 10, 10, 10],
    [7, 7, 7, 8, 9, 9, 9, 10, 10, 11, 11, 11],
    [8, 8, 8, 9, 10, 10, 10, 10, 10, 11, 11, 11],
    [9, 9, 9, 10, 10, 10, 11, 11, 11, 12, 12, 12],
    [10, 10, 10, 11, 11, 11, 11, 12, 12, 12, 12, 12],
]


def test_reba_tables_match_the_worksheet_cell_by_cell():
    """Tables A, B and C of the REBA Employee Assessment Worksheet (scribd 731952909)."""
    for trunk in range(5):
        for neck in range(3):
            assert reba.TABLE_A[trunk, neck].tolist() == \
                _REBA_A[trunk][4 * neck:4 * neck + 4], (trunk + 1, neck + 1)
    for arm in range(6):
        for lower in range(2):
            assert reba.TABLE_B[arm, lower].tolist() == \
                _REBA_B[arm][3 * lower:3 * lower + 3], (arm + 1, lower + 1)
    assert reba.TABLE_C[:10].tolist() == _REBA_C
    # Row 11, as far as the stored copy's text runs: 11 11 11 11 12 12 12.
    assert reba.TABLE_C[10, :7].tolist() == [11, 11, 11, 11, 12, 12, 12]


def test_reba_body_part_bands_match_the_published_definitions():
    """Group A definitions (Table 42.2) and the worksheet's steps 5, 7-9 and 11."""
    # Trunk: upright 1; 0-20 flexion or extension 2; 20-60 flexion or > 20 extension 3;
    # > 60 flexion 4; +1 twisting or side flexed.
    assert reba.trunk_score([0, 15, -15, 40, -25, 75]).tolist() == [1, 2, 2, 3, 3, 4]
    assert int(reba.trunk_score(40, True)) == 4
    # Neck: 0-20 flexion 1; > 20 flexion or extension 2; +1 twisting or side flexed.
    assert reba.neck_score([10, 25, -10]).tolist() == [1, 2, 2]
    assert int(reba.neck_score(25, True)) == 3
    # Legs: bilateral, walking or sitting 1; unilateral or unstable 2; +1 knees 30-60,
    # +2 knees > 60 (not for sitting).
    assert reba.legs_score([False, True, False, True], [0, 0, 45, 70]).tolist() == [1, 2, 2, 4]
    assert int(reba.legs_score(False, 70, sitting=True)) == 1
    # Load/force: < 11 lb (5 kg) 0; 11-22 lb 1; > 22 lb (10 kg) 2; +1 shock.
    assert reba.load_score([4.9, 5.0, 10.0, 10.1]).tolist() == [0, 1, 1, 2]
    assert int(reba.load_score(3, shock=True)) == 1
    # Upper arm: 20 ext - 20 flex 1; > 20 ext or 20-45 flex 2; 45-90 3; 90+ 4;
    # +1 raised, +1 abducted, -1 supported or leaning.
    assert reba.upper_arm_score([0, -30, 30, 60, 100]).tolist() == [1, 2, 2, 3, 4]
    assert int(reba.upper_arm_score(60, True, True)) == 5
    assert int(reba.upper_arm_score(60, supported=True)) == 2
    # Lower arm: 60-100 flexion 1; < 60 or > 100 2.
    assert reba.lower_arm_score([80, 30, 120]).tolist() == [1, 2, 2]
    # Wrist: 15 ext - 15 flex 1; > 15 2; +1 bent from midline or twisted.
    assert reba.wrist_score([10, -10, 20]).tolist() == [1, 1, 2]
    assert int(reba.wrist_score(20, True)) == 3
    # Coupling: good 0, fair 1, poor 2, unacceptable 3.
    assert reba.COUPLING == {"good": 0, "fair": 1, "poor": 2, "unacceptable": 3}
    # Scoring: 1 negligible; 2-3 low; 4-7 medium; 8-10 high; 11+ very high.
    assert reba.action_level([1, 2, 3, 4, 7, 8, 10, 11, 15]).tolist() == \
        [0, 1, 1, 2, 2, 3, 3, 4, 4]


# ---------------------------------------------------------------------- RULA
#: RULA worksheet Table B, rows neck 1-4 (columns trunk 1-6 x legs 1-2), as printed.
_RULA_B = [
    [1, 3, 2, 3, 3, 4, 5, 5, 6, 6, 7, 7],
    [2, 3, 2, 3, 4, 5, 5, 5, 6, 7, 7, 7],
    [3, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 7],
    [5, 5, 5, 6, 6, 7, 7, 7, 7, 7, 8, 8],
]


def test_rula_tables_match_the_worksheet_where_its_text_is_unambiguous():
    """Table B rows neck 1-4, and Table A rows (upper arm 1, lower arm 1-3), (upper arm 5,
    lower arm 1-3), (upper arm 6, lower arm 1-3) of the RULA worksheet (scribd
    36693774). The stored copy interleaves the other Table A rows with the figure labels,
    so they are not checked here. (Row (6, 2) read 8 8 8 8 8 9 9 9 here until the
    worksheet's 7 8 8 8 8 9 9 9 was checked.)"""
    assert rula.TABLE_B[:4].tolist() == _RULA_B
    assert rula.TABLE_A[0].tolist() == [[1, 2, 2, 2, 2, 3, 3, 3], [2, 2, 2, 2, 3, 3, 3, 3],
                                        [2, 3, 3, 3, 3, 3, 4, 4]]
    assert rula.TABLE_A[4].tolist() == [[5, 5, 5, 5, 5, 6, 6, 7], [5, 6, 6, 6, 6, 7, 7, 7],
                                        [6, 6, 6, 7, 7, 7, 7, 8]]
    assert rula.TABLE_A[5, 0].tolist() == [7, 7, 7, 7, 7, 8, 8, 9]
    assert rula.TABLE_A[5, 1].tolist() == [7, 8, 8, 8, 8, 9, 9, 9]
    assert rula.TABLE_A[5, 2].tolist() == [9] * 8


def test_rula_grand_score_one_or_two_only_for_low_scores_c_and_d():
    """McAtamney & Corlett (1993), stage 3: "For a grand score of 1 or 2, the working
    posture would have scored 2 or less for both body segment groups A and B, and the
    scores for muscle use and force would be 0"; a grand score of 3 or more otherwise."""
    c, d = np.meshgrid(np.arange(1, 9), np.arange(1, 8), indexing="ij")
    low = (c <= 2) & (d <= 2)
    assert np.all(rula.TABLE_C[low] <= 2)
    assert np.all(rula.TABLE_C[~low] >= 3)
    # Through the scorer: both groups at their best posture, no muscle use, no force.
    r = rula.rula_score(1, 1, 1, 1, 1, 1, 1)
    assert int(r["rula"]) in (1, 2) and int(rula.action_level(r["rula"])) == 1
    # The same posture with muscle use on one group is no longer acceptable.
    r = rula.rula_score(1, 1, 2, 1, 1, 1, 1, muscle_a=1)
    assert int(r["score_c"]) == 3 and int(r["rula"]) >= 3


def test_rula_body_part_and_force_bands_match_the_paper():
    """McAtamney & Corlett (1993) Figures 1-2 and stage 2, and the worksheet."""
    # Neck: 0-10 flexion 1; 10-20 2; 20+ 3; in extension 4; +1 twisted, +1 side bent.
    assert rula.neck_score([5, 15, 30, -10]).tolist() == [1, 2, 3, 4]
    assert int(rula.neck_score(5, True, True)) == 3
    # Trunk: sitting well supported 1; 0-20 flexion 2; 20-60 3; 60+ 4.
    assert rula.trunk_score([10, 30, 70]).tolist() == [2, 3, 4]
    assert int(rula.trunk_score(10, sitting_supported=True)) == 1
    # Force/load: < 2 kg intermittent 0; 2-10 kg intermittent 1; 2-10 kg static or
    # repeated 2; > 10 kg intermittent 2; > 10 kg static or repeated 3; shock 3.
    assert rula.force_score([1, 5, 5, 12, 12], [False, False, True, False, True]).tolist() \
        == [0, 1, 2, 2, 3]
    assert int(rula.force_score(1, shock=True)) == 3
    # Upper arm 20 ext - 20 flex 1; > 20 ext or 20-45 flex 2; 45-90 3; 90+ 4.
    assert rula.upper_arm_score([0, -30, 30, 60, 100]).tolist() == [1, 2, 2, 3, 4]
    # Lower arm 60-100 1; 0-60 or 100+ 2; +1 across the midline or out to the side.
    assert rula.lower_arm_score([80, 30, 120]).tolist() == [1, 2, 2]
    assert int(rula.lower_arm_score(30, True)) == 3
    # Scoring: 1-2 acceptable; 3-4 investigate; 5-6 change soon; 7 change immediately.
    assert rula.action_level([1, 2, 3, 4, 5, 6, 7]).tolist() == [1, 1, 2, 2, 3, 3, 4]


# ---------------------------------------------------------------------- NIOSH
#: Applications Manual Table 5 (p. 15): F rows, then <=1 h (V<30 in, V>=30), <=2 h, <=8 h.
_TABLE_5 = [
    (0.2, 1.00, 1.00, .95, .95, .85, .85), (0.5, .97, .97, .92, .92, .81, .81),
    (1, .94, .94, .88, .88, .75, .75), (2, .91, .91, .84, .84, .65, .65),
    (3, .88, .88, .79, .79, .55, .55), (4, .84, .84, .72, .72, .45, .45),
    (5, .80, .80, .60, .60, .35, .35), (6, .75, .75, .50, .50, .27, .27),
    (7, .70, .70, .42, .42, .22, .22), (8, .60, .60, .35, .35, .18, .18),
    (9, .52, .52, .30, .30, .00, .15), (10, .45, .45, .26, .26, .00, .13),
    (11, .41, .41, .00, .23, .00, .00), (12, .37, .37, .00, .21, .00, .00),
    (13, .00, .34, .00, .00, .00, .00), (14, .00, .31, .00, .00, .00, .00),
    (15, .00, .28, .00, .00, .00, .00),
]


def test_niosh_frequency_table_matches_table_5_cell_by_cell():
    for f, *row in _TABLE_5:
        got = [niosh.frequency_multiplier(f, dur, v, units="us")
               for dur in ("1h", "2h", "8h") for v in (29.0, 30.0)]
        assert got == pytest.approx(row, abs=1e-12), f
        metric = [niosh.frequency_multiplier(f, dur, v)
                  for dur in ("1h", "2h", "8h") for v in (74.0, 75.0)]
        assert metric == pytest.approx(row, abs=1e-12), f
    # "> 15" lifts/min: 0 everywhere; "<= 0.2" (and below): the 0.2 row.
    assert niosh.frequency_multiplier(15.5, "1h", 80) == 0.0
    assert niosh.frequency_multiplier(0.05, "8h", 30) == 0.85


def test_niosh_frequency_is_interpolated_between_rows():
    """Manual p. 7: "when the measured frequency is not a whole number, the appropriate
    multiplier must be interpolated between the frequency values in the table for the two
    values that are closest"; Example 7 interpolates F = 2.4 between 2 and 3 lifts/min."""
    assert niosh.frequency_multiplier(2.4, "1h", 30) == pytest.approx(.91 + .4 * (.88 - .91))
    assert niosh.frequency_multiplier(2.4, "8h", 80) == pytest.approx(.65 + .4 * (.55 - .65))


def test_niosh_coupling_table_matches_table_7():
    """Table 7 (p. 18): good 1.00/1.00, fair 0.95/1.00, poor 0.90/0.90 for V < / >= 30 in
    (75 cm)."""
    for c, (lo, hi) in {"good": (1.0, 1.0), "fair": (.95, 1.0), "poor": (.90, .90)}.items():
        assert (niosh.coupling_multiplier(c, 29.9, "us"), niosh.coupling_multiplier(c, 30, "us"),
                niosh.coupling_multiplier(c, 74.9), niosh.coupling_multiplier(c, 75)) == \
            (lo, hi, lo, hi)


def test_niosh_formulas_govern_where_the_printed_multiplier_tables_round_off():
    """The manual's p. 7 table of formulas (metric and U.S.), and the three rows of Tables
    1 and 3 whose printed two-decimal value differs from the formula (H = 22 in: .46,
    H = 23 in: .44, D = 130 cm: .86); the manual says each multiplier "should be computed
    from the appropriate formula"."""
    us = dict(units="us")
    assert niosh.lift(10, 22, 30, 10, **us).HM == pytest.approx(10 / 22)      # .4545
    assert niosh.lift(10, 23, 30, 10, **us).HM == pytest.approx(10 / 23)      # .4348
    assert niosh.lift(10, 25, 75, 130).DM == pytest.approx(.82 + 4.5 / 130)   # .8546
    assert niosh.lift(10, 10, 20, 10, **us).VM == pytest.approx(1 - .0075 * 10)
    assert niosh.lift(10, 10, 30, 40, **us).DM == pytest.approx(.82 + 1.8 / 40)
    # Limits (p. 8-12): H > 25 in -> 0; V > 70 in -> 0; D < 10 in -> 1; A > 135 -> 0.
    assert niosh.lift(10, 26, 30, 10, **us).HM == 0.0
    assert niosh.lift(10, 10, 71, 10, **us).VM == 0.0
    assert niosh.lift(10, 10, 30, 5, **us).DM == 1.0
    assert niosh.lift(10, 10, 30, 10, 140, **us).AM == 0.0
    # LC: 51 lb (U.S.), 23 kg (metric).
    assert niosh.lift(10, 10, 30, 10, **us).RWL == pytest.approx(51.0)
    assert niosh.lift(10, 25, 75, 25).RWL == pytest.approx(23.0)


def test_niosh_example_4_package_inspection():
    """Applications Manual Example 4 (Package Inspection, Figure 14, p. 46), as quoted in
    nbarr1/ErgonomicTool docs/methods/rnle.md ("Rounding" and "Coupling Multiplier"):

    origin V = 22 in, D = 37 in, fair coupling; worksheet multipliers HM 1.0, VM .94,
    DM .87, AM 1.0, FM .88, CM .95 and RWL 51 x ... = 34.9 lb, "at full precision ... the
    RWL is 34.8 lb"; destination V = 59 in, CM 1.0, RWL 15.2 lb on the worksheet and 15.3
    lb at full precision.

    The quotation gives neither F nor the duration: Table 5 has FM = .88 for 3 lifts/min
    at <= 1 h and for 1 lift/min at <= 2 h, and both are checked. It gives no destination
    H or A either: the published destination RWLs (15.2 from the rounded multipliers, 15.3
    at full precision) fix HM x AM = .50, e.g. H = 20 in, A = 0, which is used.
    FM at the destination uses V at the origin (p. 15)."""
    for f, dur in ((3, "1h"), (1, "2h")):
        o = niosh.lift(30.0, 10, 22, 37, 0, f, dur, "fair", units="us")
        assert (round(o.HM, 2), round(o.VM, 2), round(o.DM, 2), round(o.AM, 2),
                round(o.FM, 2), round(o.CM, 2)) == (1.0, .94, .87, 1.0, .88, .95)
        assert round(o.RWL, 1) == 34.8                                  # full precision
        assert round(51 * 1.0 * .94 * .87 * 1.0 * .88 * .95, 1) == 34.9  # the worksheet
        d = niosh.lift(30.0, 20, 59, 37, 0, f, dur, "fair", v_origin_cm=22, units="us")
        assert (round(d.VM, 2), round(d.FM, 2), d.CM) == (.78, .88, 1.0)
        assert round(d.RWL, 1) == 15.3                                  # full precision
        assert round(51 * .50 * .78 * .87 * 1.0 * .88 * 1.0, 1) == 15.2  # the worksheet
        # The lift is governed by its destination (the lower RWL, p. 26).
        assert d.RWL < o.RWL and d.LI > o.LI


def test_niosh_fm_uses_the_origin_height_at_the_destination():
    """Manual p. 15: FM depends on "the vertical location (V) of the hands at the origin".
    At 9 lifts/min for 8 h the two V columns differ (.00 below 30 in, .15 above)."""
    low_origin = niosh.lift(5.0, 10, 40, 20, 0, 9, "8h", "good", v_origin_cm=20, units="us")
    assert low_origin.FM == 0.0
    own_height = niosh.lift(5.0, 10, 40, 20, 0, 9, "8h", "good", units="us")
    assert own_height.FM == 0.15
    with pytest.raises(ValueError, match="units"):
        niosh.lift(5.0, 10, 40, 20, units="imperial")
