"""HOA import of Spot's reference automata, HOA/DOT export, and the Spot adapter."""

from __future__ import annotations

import csv
import re
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.errors import MissingDependencyError
from ltl_human_motion.ltl import (
    HoaError,
    atoms,
    automaton_from_hoa,
    dot_from_automaton,
    evaluate_lasso,
    hoa_from_automaton,
    parse,
    spot_available,
    translate,
)

REF = Path(__file__).resolve().parents[2] / "shared" / "data" / "spot-reference"
if not REF.is_dir():  # the work tree may sit elsewhere; the data lives beside the repo
    REF = Path("/work/shared/data/spot-reference")
ROWS = list(csv.DictReader((REF / "spot-ba-reference.tsv").open(), delimiter="\t")) \
    if REF.is_dir() else []


def _random_lassos(aps, rng, count):
    def letter():
        return frozenset(a for a in aps if rng.random() < 0.5)
    return [([letter() for _ in range(rng.integers(0, 4))],
             [letter() for _ in range(rng.integers(1, 4))]) for _ in range(count)]


@pytest.mark.skipif(not ROWS, reason="shared/data/spot-reference not present")
@pytest.mark.parametrize("row", ROWS, ids=[r["name"] for r in ROWS])
def test_reference_hoa_imports_and_agrees_with_evaluator_and_builtin(row):
    aut = automaton_from_hoa((REF / f"{row['name']}.hoa").read_text())
    assert aut.num_states == int(row["states"])
    assert aut.state_based and aut.num_sets == 1
    formula = parse(row["formula"], free_atoms=True)
    ours = translate(formula, backend="builtin")
    rng = np.random.default_rng(int(row["name"][-2:]) if row["name"][-2:].isdigit() else 7)
    verdicts = []
    for prefix, cycle in _random_lassos(aut.aps, rng, 60):
        expected = evaluate_lasso(formula, prefix, cycle)
        verdicts.append(expected)
        assert aut.accepts_lasso(prefix, cycle) == expected
        assert ours.accepts_lasso(prefix, cycle) == expected
    assert len(verdicts) == 60


@pytest.mark.skipif(not ROWS, reason="shared/data/spot-reference not present")
def test_reference_words_include_accepted_and_rejected_ones():
    rng = np.random.default_rng(3)
    counts = {True: 0, False: 0}
    for row in ROWS:
        formula = parse(row["formula"], free_atoms=True)
        aps = sorted(a.key for a in atoms(formula))
        for prefix, cycle in _random_lassos(aps, rng, 20):
            counts[evaluate_lasso(formula, prefix, cycle)] += 1
    assert min(counts.values()) > 200, counts


def test_hoa_export_reads_back_and_dot_lists_every_edge():
    aut = translate(parse("G(a -> F b) & F c", free_atoms=True), backend="builtin")
    text = dot_from_automaton(aut)
    edge_lines = re.findall(r"^  \d+ -> \d+ \[label=", text, flags=re.M)
    assert text.startswith("digraph") and len(edge_lines) == len(aut.edges)
    back = automaton_from_hoa(hoa_from_automaton(aut))
    assert back.aps == aut.aps and set(back.edges) == set(aut.edges)


@pytest.mark.parametrize(("text", "fragment"), [
    ("HOA: v1\nStates: 1\nStart: 0\nAP: 0\nAcceptance: 1 Fin(0)\n--BODY--\n--END--",
     "generalized Büchi"),
    ("HOA: v1\nStates: 1\nStart: 0\nAP: 1 \"a\"\nAcceptance: 1 Inf(0)\n--BODY--\n"
     "State: 0\n[3] 0\n--END--", "not declared"),
    ("HOA: v1\nStates: 1\nAP: 0\nAcceptance: 0 t\n--BODY--\n--END--", "Start"),
    ("HOA: v1\nStates: 1\nStart: 0\nAcceptance: 0 t\n--BODY--\nState: 0\n[t] 5\n--END--",
     "states"),
    ("garbage", "expected HOA:"),
])
def test_malformed_hoa_raises_hoa_error(text, fragment):
    with pytest.raises(HoaError, match=fragment):
        automaton_from_hoa(text)


def test_spot_backend_without_spot_is_a_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "spot", None)
    assert not spot_available()
    with pytest.raises(MissingDependencyError, match="backend='builtin'"):
        translate(parse("F a", free_atoms=True), backend="spot")
    assert translate(parse("F a", free_atoms=True), backend="auto").num_states == 2


def test_spot_adapter_reads_spot_output_through_hoa(monkeypatch):
    """A stand-in 'spot' module returning the reference HOA exercises the adapter."""
    calls = []

    class FakeAut:
        def to_str(self, fmt):
            assert fmt == "hoa"
            return (REF / "S1_formula3.hoa").read_text()

    fake = types.SimpleNamespace(formula=lambda text: calls.append(text) or text,
                                 translate=lambda f, *opts: calls.append(opts) or FakeAut())
    monkeypatch.setitem(sys.modules, "spot", fake)
    f = parse("g & G((a -> F g) & (g -> F a))", free_atoms=True)
    aut = translate(f, backend="spot", state_based=True)
    assert calls[0] == "g & G((a -> F g) & (g -> F a))"
    assert calls[1] == ("BA", "SBAcc", "small", "high")
    assert aut.num_states == 5 and aut.name == str(f)
    assert aut.accepts_lasso([], [{"g"}, {"a"}]) and not aut.accepts_lasso([{"a"}], [{"g"}])
