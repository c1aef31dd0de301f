"""The on-the-fly tableau over a task alphabet (at most one atom per step) against Spot's
reference automata (57 formulas), the built-in translator and the evaluator.

Language equivalence under exclusivity is checked two ways:

* exactly, in one direction: the product of Spot's automaton for phi with our automaton
  for !phi, over the exclusive alphabet, has no accepting cycle (so ours for !phi
  accepts no word of phi), and the same for ours(phi) x ours(!phi);
* on every lasso with a prefix of at most 1 and a cycle of at most 2 letters, and on
  seeded random longer lassos: ours accepts exactly when Spot's automaton does and
  exactly when the evaluator says the formula holds.
"""

from __future__ import annotations

import csv
import itertools
import random
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ltl_human_motion.ltl import Not, automaton_from_hoa, evaluate_lasso, parse, translate
from ltl_human_motion.ltl.automaton import accepting_components
from ltl_human_motion.ltl.formula import atoms
from ltl_human_motion.ltl.onthefly import LetterTableau

REF = Path(__file__).resolve().parents[2] / "shared" / "data" / "spot-reference"
if not REF.is_dir():
    REF = Path("/work/shared/data/spot-reference")
ROWS = list(csv.DictReader((REF / "spot-ba-reference.tsv").open(), delimiter="\t")) \
    if REF.is_dir() else []


def _exclusive_letters(aps: list[str]) -> list[frozenset[str]]:
    """The empty letter and one letter per atom: at most one task per step."""
    return [frozenset(), *(frozenset({a}) for a in aps)]


def _product_empty(succ_a, init_a, sets_a, succ_b, init_b, sets_b, n_letters) -> bool:
    """No accepting cycle in the product of two automata given by successor functions
    ``succ(q, i) -> [(q', frozenset marks)]`` (marks of b shifted by ``sets_a``)."""
    index = {(init_a, init_b): 0}
    adj: list[list] = [[]]
    stack = [(init_a, init_b)]
    while stack:
        qa, qb = stack.pop()
        src = index[(qa, qb)]
        for i in range(n_letters):
            for da, ma in succ_a(qa, i):
                for db, mb in succ_b(qb, i):
                    key = (da, db)
                    if key not in index:
                        index[key] = len(adj)
                        adj.append([])
                        stack.append(key)
                    adj[src].append((index[key], ma | {sets_a + m for m in mb}))
    return not accepting_components(adj, sets_a + sets_b)


def _tableau_succ(tab: LetterTableau):
    return lambda q, i: [(d, tab.mark_set(m)) for d, m in tab.successors(q, i)]


def _explicit_succ(aut, letters):
    def succ(q, i):
        return [(e.dst, e.acc) for e in aut.successors(q) if e.guard.satisfied_by(letters[i])]
    return succ


def _small_lassos(n_letters: int):
    for lp in range(2):
        for lc in range(1, 3):
            for word in itertools.product(range(n_letters), repeat=lp + lc):
                yield word[:lp], word[lp:]


@pytest.mark.skipif(not ROWS, reason="shared/data/spot-reference not present")
@pytest.mark.parametrize("row", ROWS, ids=[r["name"] for r in ROWS])
def test_tableau_matches_spot_reference_under_exclusivity(row):
    formula = parse(row["formula"], free_atoms=True)
    spot = automaton_from_hoa((REF / f"{row['name']}.hoa").read_text())
    aps = sorted(set(spot.aps) | {a.key for a in atoms(formula)})
    letters = _exclusive_letters(aps)
    ours = LetterTableau(formula, letters)
    neg = LetterTableau(Not(formula), letters)
    assert _product_empty(_explicit_succ(spot, letters), spot.initial, spot.num_sets,
                          _tableau_succ(neg), neg.initial, neg.num_sets, len(letters))
    assert _product_empty(_tableau_succ(ours), ours.initial, ours.num_sets,
                          _tableau_succ(neg), neg.initial, neg.num_sets, len(letters))
    rng = random.Random(row["name"])
    words = list(_small_lassos(len(letters)))
    words += [(tuple(rng.randrange(len(letters)) for _ in range(rng.randint(0, 4))),
               tuple(rng.randrange(len(letters)) for _ in range(rng.randint(1, 4))))
              for _ in range(150)]
    for prefix, cycle in words:
        pl, cl = [letters[i] for i in prefix], [letters[i] for i in cycle]
        expected = spot.accepts_lasso(pl, cl)
        assert ours.accepts_lasso(prefix, cycle) == expected, (row["formula"], pl, cl)
        assert evaluate_lasso(formula, pl, cl) == expected, (row["formula"], pl, cl)


APS = ("p0", "p1", "p2")


def _formulas() -> st.SearchStrategy:
    from test_ltl_equivalence import formulas
    return formulas


@settings(max_examples=400, derandomize=True, database=None, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(_formulas(), st.lists(st.tuples(
    st.lists(st.integers(0, len(APS)), max_size=4),
    st.lists(st.integers(0, len(APS)), min_size=1, max_size=4)), min_size=6, max_size=6))
def test_tableau_agrees_with_evaluator_and_builtin_on_random_formulas(formula, words):
    letters = _exclusive_letters(list(APS))
    ours = LetterTableau(formula, letters)
    builtin = translate(formula, backend="builtin")
    for prefix, cycle in words:
        pl, cl = [letters[i] for i in prefix], [letters[i] for i in cycle]
        expected = evaluate_lasso(formula, pl, cl)
        assert ours.accepts_lasso(prefix, cycle) == expected, (str(formula), pl, cl)
        assert builtin.accepts_lasso(pl, cl) == expected


def test_many_f_conjuncts_share_work_and_stay_small():
    text = " & ".join(f"F p{i}" for i in range(20))
    letters = _exclusive_letters([f"p{i}" for i in range(20)])
    tab = LetterTableau(parse(text, free_atoms=True), letters)
    q = tab.initial
    for i in range(1, 21):
        (q, marks), = tab.successors(q, i)     # deterministic over the task alphabet
    assert tab.states[q] == frozenset() and marks == tab.full
    assert len(tab.states) == 21 and tab.loopable(q) and not tab.loopable(tab.initial)
    assert len(tab._memo) <= 21 * 21 + 21     # one expansion per (conjunct, letter)
