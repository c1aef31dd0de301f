"""Fuzzing the specification parser and translator: any text gives a Formula or a
SpecError (never another exception), by depth, width and unicode."""

from __future__ import annotations

import pytest
from fuzzing import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

from ltl_human_motion.deadline import BudgetExhaustedError, Deadline, active
from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl import parse
from ltl_human_motion.ltl.translate_builtin import translate_builtin
from ltl_human_motion.scene.cell_yaml import cell_by_name

CELL = cell_by_name("paper_cell")
ATOMS = ["grasp(O1)", "grasp(O2)", "assemble(R1)", "wait(1.0)", "leftHand(R1)", "p", "X1"]
UNARY = ["!", "X ", "F ", "G ", "~", "()"]
BINARY = [" & ", " | ", " -> ", " <-> ", " U ", " R ", " W ", " M ", " ^ ", "&&", "||"]


@st.composite
def formula_text(draw: st.DrawFn, max_depth: int = 1000) -> str:
    """Operator soup: deep unary chains, wide conjunctions, stray parentheses."""
    depth = draw(st.integers(0, max_depth))
    parts = [draw(st.sampled_from(ATOMS))]
    for _ in range(draw(st.integers(0, 60))):
        parts.append(draw(st.sampled_from(BINARY)) + draw(st.sampled_from(ATOMS)))
    body = "".join(parts)
    prefix = "".join(draw(st.lists(st.sampled_from([*UNARY, "("]), max_size=depth)))
    return prefix + body + ")" * draw(st.integers(0, depth))


def _parse_or_spec_error(text: str, cell: object) -> None:
    try:
        parse(text, cell)
    except SpecError as exc:
        assert str(exc)                           # a message, never empty
        assert "unexpected the end" not in str(exc)


@fuzz_settings()
@given(formula_text())
def test_operator_soup_parses_or_gives_a_spec_error(text: str) -> None:
    _parse_or_spec_error(text, CELL)


@fuzz_settings()
@given(st.text(alphabet=st.characters(codec="utf-8"), max_size=300))
def test_unicode_text_parses_or_gives_a_spec_error(text: str) -> None:
    _parse_or_spec_error(text, CELL)


@fuzz_settings()
@given(st.integers(1, 900), st.sampled_from(["p -> ", "!", "X ", "!(", "p U (", "G (F "]))
def test_any_depth_parses_or_gives_a_spec_error(depth: int, op: str) -> None:
    closing = ")" * (depth * op.count("("))
    try:
        f = parse(op * depth + "p" + closing, free_atoms=True)
    except SpecError as exc:
        assert "MAX_NESTING" in str(exc) or "MAX_TEMPORAL_OPERATORS" in str(exc)
    else:
        assert f == f and hash(f) == hash(f)       # equality and hashing stay in bounds


@fuzz_settings(divisor=2)
@given(formula_text(max_depth=12))
def test_translation_of_what_parses_ends_within_the_budget(text: str) -> None:
    try:
        f = parse(text, free_atoms=True)
    except SpecError:
        return
    try:
        with active(Deadline(2.0)):
            aut = translate_builtin(f)
    except BudgetExhaustedError as exc:
        assert "exhausted in translation" in str(exc)
    else:
        assert aut.num_states >= 1


@pytest.mark.parametrize("text", ["", " ", "\x00", "\ufeffgrasp(O1)", "grasp(O1)\u202e"])
def test_edge_texts(text: str) -> None:
    _parse_or_spec_error(text, CELL)
