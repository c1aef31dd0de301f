"""Parser: grammar and precedence of Sec. II-A, Spot's ASCII syntax, typed task atoms and
errors with line and column."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl import (
    FALSE,
    TRUE,
    And,
    Atom,
    Finally,
    Globally,
    Implies,
    Next,
    Not,
    Or,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
    Xor,
    parse,
    parse_spec,
    to_spot,
)

CELL = {"objects": ["O1", "O2", "chair"], "regions": ["R0", "R1", "R2", "R3"],
        "shorthands": {"assemble": (("R",), "leftHand(R) & rightHand(R)")},
        "final_region": "R1"}
a, b, c = Atom("a"), Atom("b"), Atom("c")


def p(text: str):
    return parse(text, free_atoms=True)


def test_unary_binds_strongest_and_until_tighter_than_boolean():
    assert p("!a U b") == Until(Not(a), b)
    assert p("X a U b") == Until(Next(a), b)
    assert p("a & b U c") == And((a, Until(b, c)))
    assert p("a | b U c") == Or((a, Until(b, c)))
    assert p("a -> b U c") == Implies(a, Until(b, c))
    assert p("F a U G b") == Until(Finally(a), Globally(b))


def test_boolean_precedence_and_associativity_follow_spot():
    assert p("a -> b -> c") == Implies(a, Implies(b, c))
    assert p("a & b -> c") == Implies(And((a, b)), c)
    assert p("a | b & c") == Or((a, And((b, c))))
    assert p("a U b U c") == Until(a, Until(b, c))
    assert p("a xor b & c") == Xor(a, And((b, c)))


def test_paper_and_spot_spellings_are_equivalent():
    assert p("¬a ∧ b ∨ c → a ↔ b") == p("!a & b | c -> (a <-> b)")
    assert p("[]<> a && b || c") == p("G F a & b | c")
    assert p("GFa") == Globally(Finally(a))
    assert p("XFp1") == Next(Finally(Atom("p1")))
    assert p("a R b") == Release(a, b) and p("a W b") == WeakUntil(a, b)
    assert p("a M b") == StrongRelease(a, b) and p("a ^ b") == Xor(a, b)
    assert p("1 & true") == And((TRUE, TRUE)) and p("0 | false") == Or((FALSE, FALSE))
    assert p('"grasp(O1)" U "Foo"') == Until(Atom("grasp", ("O1",)), Atom("Foo"))


def test_task_atoms_with_arguments_and_shorthands():
    f = parse("carry(O1, R2) & wait(2) & sit(chair) & standUp & enter(R3)", CELL)
    assert f == And((Atom("carry", ("O1", "R2")), Atom("wait", ("2.0",)),
                     Atom("sit", ("chair",)), Atom("standUp"), Atom("enter", ("R3",))))
    spec = parse_spec("F assemble(R1) & G !grasp(O2)", CELL)
    assert spec.formula == And((Finally(And((Atom("leftHand", ("R1",)),
                                             Atom("rightHand", ("R1",))))),
                                Globally(Not(Atom("grasp", ("O2",))))))
    assert [t.key for t in spec.tasks] == ["assemble(R1)", "grasp(O2)"]


def test_str_parses_back_and_to_spot_quotes_task_atoms():
    f = parse("grasp(O1) & G(assemble(R1) -> X(move(O1, R2) | wait(1.5)))", CELL)
    assert parse(str(f), CELL) == f
    assert '"move(O1, R2)"' in to_spot(f)
    assert parse(to_spot(f), CELL) == f


@pytest.mark.parametrize(("text", "column", "fragment"), [
    ("grab(O1)", 1, "unknown task 'grab'"),
    ("carry(O1)", 1, "takes 2 arguments (object, region), got 1"),
    ("grasp(O3)", 7, "unknown object 'O3'"),
    ("walk(O1)", 6, "unknown region 'O1'"),
    ("wait(soon)", 6, "expects a number"),
    ("G(grasp(O1)", 12, "expected ')'"),
    ("grasp(O1) &", 12, "expected an atom"),
    ("grasp(O1) grasp(O2)", 11, "expected a binary operator"),
    ("assemble(R1, R2)", 1, "shorthand 'assemble' takes 1 argument"),
    ("F grasp(O1) $", 13, "unexpected character"),
    ("", 1, "empty specification"),
])
def test_errors_give_line_column_and_expectation(text, column, fragment):
    with pytest.raises(SpecError, match=r"expect|unknown|takes|empty") as info:
        parse(text, CELL)
    err = info.value
    assert fragment in err.message
    assert (err.line, err.column) == (1, column)


def test_error_on_second_line_points_there():
    with pytest.raises(SpecError) as info:
        parse("grasp(O1) &\n  G walk(R9)", CELL)
    assert (info.value.line, info.value.column) == (2, 10)
    assert "^" in str(info.value)


def test_bad_shorthand_body_is_reported_at_the_use_site():
    cell = dict(CELL, shorthands={"bad": (("R",), "leftHand(R) &")})
    with pytest.raises(SpecError, match="in shorthand bad\\(R\\)"):
        parse("F bad(R1)", cell)


_alphabet = st.sampled_from([*'aXFGURWM!&|()-><=~[]^" ,.01pO', "grasp", "carry", "wait(",
                             "xor", "true", "¬", "→", "\n"])


@settings(max_examples=1500, derandomize=True, database=None, deadline=None)
@given(st.one_of(st.text(max_size=40), st.lists(_alphabet, max_size=25).map("".join)),
       st.booleans())
def test_fuzzed_input_raises_nothing_but_spec_error(text, free):
    try:
        f = parse(text, CELL, free_atoms=free)
    except SpecError as err:
        assert err.message
        assert err.line is None or err.line >= 1
    else:
        assert parse(str(f), CELL, free_atoms=free) == f
