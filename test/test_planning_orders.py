"""Another order of the tasks where the motion planner cannot do a step
(:func:`ltl_human_motion.planning.pipeline._in_another_order`), on the product search's
real sequences of the kitting cell."""

from __future__ import annotations

from pathlib import Path

import pytest

from ltl_human_motion.errors import PlanningError, VerificationError
from ltl_human_motion.ltl.spec import build_specification
from ltl_human_motion.planning.pipeline import (
    OTHER_ORDERS,
    SynthesisOptions,
    _in_another_order,
    _other_sequences,
    _same_situation,
    _task_text,
    _verified_in_another_order,
    resolve_cell,
)
from ltl_human_motion.planning.result import SynthesisStats

KITTING = Path(__file__).resolve().parents[1] / "scenarios" / "cells" / "kitting.yaml"
SPEC = "F(grasp(bolt) & X insert(bolt, kit_a)) & F(grasp(gear) & X insert(gear, kit_c))"


@pytest.fixture(scope="module")
def kitting():
    cell = resolve_cell(KITTING)
    spec = build_specification(SPEC, cell)
    return cell, _other_sequences(spec, cell, 9, 0, SynthesisOptions(), 1)


def _texts(seq) -> list[str]:
    return [_task_text(t) for t in seq.tasks]


class _Made:
    """What a stand-in for the synthesis of one order returns: its tasks and stats."""

    def __init__(self, texts: list[str]) -> None:
        self.texts, self.stats = texts, SynthesisStats()


def _works(seq, failed=None) -> _Made:
    return _Made(_texts(seq))


def test_the_same_situation_is_the_same_set_of_tasks_before(kitting) -> None:
    _, seqs = kitting
    first = seqs[0]
    assert _texts(first)[:2] == ["grasp(bolt)", "grasp(gear)"]
    failed = {"grasp(gear)"}
    assert _same_situation(first, first, 1, failed)
    gear_first = [s for s in seqs if _texts(s)[0] == "grasp(gear)"]
    assert gear_first and not any(_same_situation(s, first, 1, failed) for s in gear_first)
    # the gear grasped after the bolt was put in its kit: another situation
    bolt_in_kit = [s for s in seqs if _texts(s)[:3] == ["grasp(bolt)", "insert(bolt, kit_a)",
                                                         "grasp(gear)"]]
    assert bolt_in_kit and not _same_situation(bolt_in_kit[0], first, 1, failed)


def test_other_orders_are_planned_in_turn_and_the_first_failure_is_kept(kitting) -> None:
    cell, seqs = kitting
    first = seqs[0]
    failure = PlanningError("task grasp(gear): blocked", task="grasp(gear)", reason="blocked")
    failure.step_index = 1
    tried = []

    def one(seq, failed=None):
        tried.append(_texts(seq))
        raise PlanningError("still blocked", task="x", reason="blocked")

    with pytest.raises(PlanningError) as err:
        _in_another_order(one, first, failure, lambda: seqs, cell, 1.75)
    assert len(tried) == OTHER_ORDERS
    assert all(t[:2] != ["grasp(bolt)", "grasp(gear)"] for t in tried)
    assert err.value.reason == "blocked" and err.value.task == "grasp(gear)"
    assert str(err.value).startswith("task grasp(gear): blocked; 2 other order(s)")

    made = _in_another_order(_works, first, failure, lambda: seqs, cell, 1.75)
    assert made.texts == tried[0]
    assert made.stats == SynthesisStats(orders_failed=1,
                                        first_failure="task grasp(gear): blocked")


def test_a_limit_of_the_cell_is_not_tried_in_another_order(kitting) -> None:
    cell, seqs = kitting
    failure = PlanningError("out of reach", task="grasp(gear)", reason="reach")
    failure.step_index = 0

    def one(seq, failed=None):
        raise AssertionError("no other order may be planned")

    with pytest.raises(PlanningError) as err:
        _in_another_order(one, seqs[0], failure, lambda: seqs, cell, 1.75)
    assert err.value is failure


def test_an_order_that_fails_like_one_tried_before_is_skipped(kitting) -> None:
    cell, seqs = kitting
    first = seqs[0]
    failure = PlanningError("task grasp(gear): blocked", task="grasp(gear)", reason="blocked")
    failure.step_index = 1
    gear_first = [s for s in seqs if _texts(s)[0] == "grasp(gear)"]
    assert len(gear_first) >= 2              # the same situation comes up more than once
    tried = []

    def one(seq, failed=None):
        texts = _texts(seq)
        at = texts.index("grasp(gear)")
        tried.append(frozenset(texts[:at]))
        exc = PlanningError("task grasp(gear): still blocked", task="grasp(gear)",
                            reason="blocked")
        exc.step_index = at
        raise exc

    with pytest.raises(PlanningError) as err:
        _in_another_order(one, first, failure, lambda: [first, *gear_first], cell, 1.75)
    # the second order that grasps the gear first would fail as the first one did
    assert tried == [frozenset()]
    assert "1 other order(s) of the tasks failed too" in str(err.value)


AISLE = Path(__file__).resolve().parents[1] / "scenarios" / "cells" / "aisle.yaml"


def _aisle_planner(failed: dict | None = None):
    import numpy as np

    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.plan_state import PlannerOptions
    from ltl_human_motion.planning.planner import SequencePlanner

    cell = resolve_cell(AISLE)
    planner = SequencePlanner(cell.floor_at_zero(), get_library(1.75),
                              np.random.default_rng([0, 0]),
                              PlannerOptions(refuse_self_penetration=True, whole_body=False),
                              failed_before=failed)
    return cell, planner


def _steps(cell, texts: list[tuple[str, tuple[str, ...]]]):
    from ltl_human_motion.vocabulary import task_step
    return [task_step(name, args, cell.shorthands) for name, args in texts]


def test_a_step_that_failed_in_the_same_situation_fails_without_a_search() -> None:
    """Holding O1 in the right hand, a 1.75 m worker who assembled at R2 first and comes
    from the aisle's end finds no grasp of O2 on the knee board without the whole-body
    program (the program, off here, finds one); another order that comes to it the same
    way fails the same way at once, its earlier steps planned as before. The hand that
    holds O1 is part of the situation."""
    tail = [("grasp", ("O1",)), ("walk", ("R1",)), ("grasp", ("O2",))]
    cell, first = _aisle_planner()
    with pytest.raises(PlanningError) as err:
        first.plan(_steps(cell, [("assemble", ("R2",)), *tail]), (0.0, 0.0, 0.0))
    failure = err.value
    assert failure.step_index == 3
    assert failure.situation[:3] == ("grasp(O2)", "walk(R1)", frozenset({("O1", "r_hand")}))

    again = [("wait", ("1.0",)), *tail]
    cell, before = _aisle_planner()
    before.plan(_steps(cell, again[:-1]), (0.0, 0.0, 0.0))      # the steps before it plan
    cell, second = _aisle_planner({failure.situation: failure})
    with pytest.raises(PlanningError) as err:
        second.plan(_steps(cell, again), (0.0, 0.0, 0.0))
    assert err.value.step_index == 3 and str(err.value) == str(failure)
    assert err.value.reason == failure.reason
    assert second.state.expanded == before.state.expanded    # no node searched for it

    # with O1 in the left hand (straight from the start) it is another situation
    cell, third = _aisle_planner({failure.situation: failure})
    with pytest.raises(PlanningError) as err:
        third.plan(_steps(cell, tail), (0.0, 0.0, 0.0))
    assert err.value.situation[2] == frozenset({("O1", "l_hand")})
    assert str(err.value) != str(failure)                    # planned, not replayed


def test_a_motion_that_fails_verification_is_made_in_another_order(kitting) -> None:
    cell, seqs = kitting
    first = seqs[0]
    failure = VerificationError("verification failed (joint_speed): l_toe", "joint_speed")
    tried = []

    def one(seq, failed=None):
        tried.append(_texts(seq))
        raise VerificationError("verification failed (foot_skate): left foot", "foot_skate")

    with pytest.raises(VerificationError) as err:
        _verified_in_another_order(one, first, failure, lambda: seqs, cell, 1.75)
    assert len(tried) == OTHER_ORDERS and _texts(first) not in tried
    assert err.value.check == "joint_speed"
    assert str(err.value) == ("verification failed (joint_speed): l_toe; 2 other order(s) "
                              "of the tasks failed too")

    made = _verified_in_another_order(_works, first, failure, lambda: seqs, cell, 1.75)
    assert made.texts == tried[0] and made.stats.orders_failed == 1
    assert made.stats.first_failure == str(failure)
    # no other order: the failure as it was
    with pytest.raises(VerificationError) as err:
        _verified_in_another_order(_works, first, failure, lambda: [first], cell, 1.75)
    assert err.value is failure
