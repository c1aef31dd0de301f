"""Another order of the tasks where the motion planner cannot do a step
(:func:`ltl_human_motion.planning.pipeline._in_another_order`), on the product search's
real sequences of the kitting cell."""

from __future__ import annotations

from pathlib import Path

import pytest

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.ltl.spec import build_specification
from ltl_human_motion.planning.pipeline import (
    OTHER_ORDERS,
    SynthesisOptions,
    _in_another_order,
    _other_sequences,
    _same_situation,
    _task_text,
    resolve_cell,
)

KITTING = Path(__file__).resolve().parents[1] / "scenarios" / "cells" / "kitting.yaml"
SPEC = "F(grasp(bolt) & X insert(bolt, kit_a)) & F(grasp(gear) & X insert(gear, kit_c))"


@pytest.fixture(scope="module")
def kitting():
    cell = resolve_cell(KITTING)
    spec = build_specification(SPEC, cell)
    return cell, _other_sequences(spec, cell, 9, 0, SynthesisOptions(), 1)


def _texts(seq) -> list[str]:
    return [_task_text(t) for t in seq.tasks]


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

    def one(seq):
        tried.append(_texts(seq))
        raise PlanningError("still blocked", task="x", reason="blocked")

    with pytest.raises(PlanningError) as err:
        _in_another_order(one, first, failure, lambda: seqs, cell, 1.75)
    assert len(tried) == OTHER_ORDERS
    assert all(t[:2] != ["grasp(bolt)", "grasp(gear)"] for t in tried)
    assert err.value.reason == "blocked" and err.value.task == "grasp(gear)"
    assert str(err.value).startswith("task grasp(gear): blocked; 2 other order(s)")

    def works(seq):
        return _texts(seq)

    assert _in_another_order(works, first, failure, lambda: seqs, cell, 1.75) == tried[0]


def test_a_limit_of_the_cell_is_not_tried_in_another_order(kitting) -> None:
    cell, seqs = kitting
    failure = PlanningError("out of reach", task="grasp(gear)", reason="reach")
    failure.step_index = 0

    def one(seq):
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

    def one(seq):
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
