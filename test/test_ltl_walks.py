"""The generic walks of LTL formulas: ``Formula.map`` rebuilds a node through its kind's
``make`` (``&`` and ``|`` flattened), ``Formula.fold`` computes bottom-up once per distinct
subformula; the passes written with them (nnf, simplify, the evaluator) agree with the
definitions."""

from __future__ import annotations

import pytest

from ltl_human_motion.ltl import (
    FALSE,
    TRUE,
    And,
    Atom,
    Finally,
    Globally,
    Next,
    Or,
    Until,
    evaluate_lasso,
    nnf,
    parse,
)
from ltl_human_motion.ltl.evaluator import propositional_letters
from ltl_human_motion.ltl.formula import size

a, b, c = Atom("a"), Atom("b"), Atom("c")


def test_map_keeps_the_kind_and_leaves_and_flattens_junctions() -> None:
    f = parse("G(a & b) U X c", free_atoms=True)
    assert f.map(lambda g: g) == f and type(f.map(lambda g: g)) is Until
    assert a.map(lambda g: b) is a and TRUE.map(lambda g: FALSE) is TRUE
    assert And((a, b)).map(lambda g: And((g, c)) if g == a else g) == And((a, c, b))
    assert Or((a, b)).map(lambda g: TRUE if g == b else g) == TRUE
    assert And((a, b)).map(lambda g: a) == a
    assert Next(a).map(lambda g: Finally(g)) == Next(Finally(a))


def test_fold_calls_once_per_distinct_subformula_and_passes_child_values() -> None:
    f = And((Finally(a), Globally(Finally(a)), Until(a, Finally(a))))
    seen: list[str] = []

    def count(g, children):
        seen.append(str(g))
        return 1 + sum(children)

    assert f.fold(count) == size(f) == 10
    assert sorted(seen) == sorted({"a", "F a", "G F a", "a U F a", str(f)})
    memo: dict = {}
    f.fold(count, memo)
    assert memo[Finally(a)] == 2 and memo[f] == 10


@pytest.mark.parametrize("text, expected", [
    ("!(a U b)", "!a R !b"), ("!X F a", "X G !a"), ("!(a & (b W c))", "!a | !b M !c"),
    ("!(a -> b)", "a & !b"), ("a xor b", "a & !b | !a & b"),
])
def test_nnf_pushes_negations_through_the_dual_of_each_kind(text, expected) -> None:
    assert str(nnf(parse(text, free_atoms=True))) == expected


def test_the_evaluator_and_propositional_letters_read_the_definitions() -> None:
    f = parse("a W b", free_atoms=True)
    assert evaluate_lasso(f, [], [{"a"}]) and not evaluate_lasso(f, [{"a"}], [set()])
    assert evaluate_lasso(f, [{"a"}, {"a"}], [{"b"}])
    letters = [frozenset(), frozenset({"a"}), frozenset({"a", "b"})]
    assert propositional_letters(parse("a & !b", free_atoms=True), letters) == (1,)
    assert propositional_letters(parse("!a | b", free_atoms=True), letters) == (0, 2)
    assert propositional_letters(parse("a | F b", free_atoms=True), letters) is None
    assert propositional_letters(parse("F b", free_atoms=True), []) == ()
