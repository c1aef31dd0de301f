"""Automaton reductions: minimal weak deterministic automata for obligation properties,
the cube covers they use, state counts against Spot's ``ltl2tgba -B``, and the faster
enumeration of ``mode="all"`` against a plain depth-first search."""

from __future__ import annotations

import csv
import itertools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ltl_human_motion.ltl.sequences as sequences
from ltl_human_motion.ltl import (
    Atom,
    Automaton,
    Const,
    Cube,
    Edge,
    Finally,
    Globally,
    Next,
    Not,
    Or,
    Release,
    Until,
    WeakUntil,
    automaton_from_hoa,
    build_specification,
    degeneralize,
    evaluate_lasso,
    parse,
    translate,
)
from ltl_human_motion.ltl.automaton import _reduce_state_based
from ltl_human_motion.ltl.translate_builtin import _tableau_automaton
from ltl_human_motion.ltl.wdba import cube_cover, minimize_obligation

REF = Path(__file__).resolve().parents[2] / "shared" / "data" / "spot-reference"
if not REF.is_dir():
    REF = Path("/work/shared/data/spot-reference")
ROWS = list(csv.DictReader((REF / "spot-ba-reference.tsv").open(), delimiter="\t")) \
    if REF.is_dir() else []

APS = ("p0", "p1", "p2")
PROFILE = dict(derandomize=True, database=None, deadline=None,
               suppress_health_check=[HealthCheck.too_slow])

_leaves = st.one_of(st.sampled_from([Atom(a) for a in APS]),
                    st.sampled_from([Const(True), Const(False)]))


def _extend(children: st.SearchStrategy) -> st.SearchStrategy:
    unary = st.sampled_from([Not, Next, Finally, Globally])
    binary = st.sampled_from([Until, Release, WeakUntil])
    return st.one_of(st.builds(lambda op, a: op(a), unary, children),
                     st.builds(lambda op, a, b: op(a, b), binary, children, children),
                     st.builds(lambda a, b: Or((a, b)), children, children))


formulas = st.recursive(_leaves, _extend, max_leaves=6)
letters = st.frozensets(st.sampled_from(APS))
lassos = st.tuples(st.lists(letters, max_size=4), st.lists(letters, min_size=1, max_size=4))


def _is_deterministic(aut) -> bool:
    """No letter leads from one state to two states (cubes to one state may overlap)."""
    for q in aut.states:
        for e, f in itertools.combinations(aut.successors(q), 2):
            if e.dst != f.dst and e.guard.conjoin(f.guard) is not None:
                return False
    return True


@settings(max_examples=600, **PROFILE)
@given(formulas, st.lists(lassos, min_size=6, max_size=6))
def test_minimal_wdba_has_the_language_of_the_tableau_automaton(formula, words):
    tableau = _tableau_automaton(formula, None)
    wdba = minimize_obligation(tableau, lambda: _tableau_automaton(Not(formula), None))
    if wdba is None:  # no obligation (or too large): the translator keeps the tableau one
        assert translate(formula, backend="builtin").num_states <= tableau.num_states
        return
    assert wdba.state_based and wdba.num_sets == 1 and _is_deterministic(wdba)
    for prefix, cycle in words:
        expected = evaluate_lasso(formula, prefix, cycle)
        assert tableau.accepts_lasso(prefix, cycle) == expected
        assert wdba.accepts_lasso(prefix, cycle) == expected, (str(formula), prefix, cycle)


def test_obligations_get_minimal_deterministic_automata_and_recurrences_do_not():
    def wdba(text):
        f = parse(text, free_atoms=True)
        return minimize_obligation(_tableau_automaton(f, None),
                                   lambda: _tableau_automaton(Not(f), None))

    # G(a U (b | G a)) is the safety property G(a W b): 1 state
    safety = wdba("G(a U (b | G a))")
    assert safety is not None and safety.num_states == 1
    guarantee = wdba("F a & F b")
    assert guarantee is not None and guarantee.num_states == 4
    assert _is_deterministic(guarantee)
    for text in ("G F a", "F G a", "G(a -> F b)"):
        assert wdba(text) is None, text


@settings(max_examples=300, **PROFILE)
@given(st.integers(1, 4).flatmap(
    lambda n: st.tuples(st.just(n), st.sets(st.integers(0, (1 << n) - 1)))))
def test_cube_cover_is_exact_and_irredundant(case):
    n, minterms = case

    def covered(cubes):
        return {m for m in range(1 << n) for pos, neg in cubes
                if all(m >> j & 1 for j in pos) and not any(m >> j & 1 for j in neg)}

    cover = cube_cover(minterms, n)
    assert covered(cover) == minterms
    for k in range(len(cover)):
        assert covered(cover[:k] + cover[k + 1:]) != minterms
    assert len(cover) <= len(minterms)


@pytest.mark.skipif(not ROWS, reason="shared/data/spot-reference not present")
@pytest.mark.parametrize("row", ROWS, ids=[r["name"] for r in ROWS])
def test_state_based_automaton_within_twice_spot_and_same_words(row):
    spot = automaton_from_hoa((REF / f"{row['name']}.hoa").read_text())
    formula = parse(row["formula"], free_atoms=True)
    ours = degeneralize(translate(formula, backend="builtin"))
    assert ours.num_states <= 2 * int(row["states"]), (row["name"], ours.num_states)
    rng = np.random.default_rng(11)
    aps = spot.aps
    for _ in range(40):
        prefix = [frozenset(a for a in aps if rng.random() < 0.5)
                  for _ in range(rng.integers(0, 4))]
        cycle = [frozenset(a for a in aps if rng.random() < 0.5)
                 for _ in range(rng.integers(1, 4))]
        assert ours.accepts_lasso(prefix, cycle) == spot.accepts_lasso(prefix, cycle)


@pytest.mark.parametrize(("text", "states"), [
    # dac40 and dac45: Spot's ltl2tgba -B gives 3 and 9 states
    ("G(p0 -> ((!(!p1 & p2 & X(!p1 U (!p1 & p3))) U (p1 | p4)) | G!(p2 & XFp3)))", 3),
    ("G(p0 -> (((p1 & X(!p2 U p3)) -> X(!p2 U (p3 & Fp4))) U (p2 | G((p1 & X(!p2 U p3)) "
     "-> X(!p2 U (p3 & Fp4))))))", 9),
    ("G((p0 & XFp1) -> XF(p1 & Fp2))", 7),  # dac41, Spot: 4
])
def test_state_counts_of_dac40_dac45_dac41(text, states):
    assert degeneralize(translate(parse(text, free_atoms=True), backend="builtin")) \
        .num_states == states


# ------------------------------------------------------------------------ mode "all"

CELL = {"objects": ["O1", "O2"], "regions": ["R0", "R1"],
        "shorthands": {"assemble": (("R",), "leftHand(R) & rightHand(R)")},
        "final_region": "R1"}


def _reference_all(synth, n, max_length, limit):
    """The plain enumeration: every path of each length, depth first."""
    g = synth.graph
    work = 0
    for length in range(1, max_length + 1):
        found = []
        stack = [([], [g.aut.initial])]
        while stack and work < limit:
            path, states = stack.pop()
            work += 1
            if len(path) == length:
                for j in range(length):
                    if states[j] == states[-1]:
                        marks = set().union(*(a.acc for a in path[j:]))
                        if len(marks) >= g.aut.num_sets:
                            found.append((path[:j], path[j:]))
                continue
            for a in reversed(g.out[states[-1]]):
                stack.append(([*path, a], [*states, a.dst]))
        found.sort(key=lambda pc: (len(pc[0]) + len(pc[1]),
                                   [a.letter for a in pc[0] + pc[1]], len(pc[0])))
        for prefix, cycle in found:
            synth.add(prefix, cycle)
        if n is not None and len(synth.out) >= n:
            break
    synth.out.sort(key=lambda s: (len(s.prefix) + len(s.cycle), list(map(str, s.tasks))))
    if n is not None:
        del synth.out[n:]
    return synth.out


@pytest.mark.parametrize("text", ["S1", "S2", "F enter(R0) & G F grasp(O1)",
                                  "G F grasp(O1) & G F grasp(O2) & F assemble(R1)",
                                  "grasp(O2) U (grasp(O1) & X G !grasp(O2))"])
@pytest.mark.parametrize("limit", [sequences._WORK_LIMIT, 5000])
def test_all_mode_equals_plain_depth_first_enumeration(text, limit, monkeypatch):
    monkeypatch.setattr(sequences, "_WORK_LIMIT", limit)
    spec = build_specification(text, CELL)
    aut = translate(spec.formula, backend="builtin")
    emitted = 0
    for allow_empty in (False, True):
        graph = sequences._LetterGraph(aut, spec.letters, allow_empty)
        for n, max_length, cycles in ((5, 14, 1), (None, 7, 2), (1, 9, 1), (12, 10, 1)):
            fast = sequences._Synth(spec, graph, cycles, 5)
            fast.all(n, max_length)
            plain = _reference_all(sequences._Synth(spec, graph, cycles, 5), n, max_length,
                                   limit)
            assert fast.out == plain, (text, allow_empty, n, max_length)
            emitted += len(fast.out)
    assert emitted > 0


def test_all_mode_lists_the_paper_loops_first():
    s1 = sequences.synthesize_sequences("S1", CELL, n=1, mode="all")
    assert s1[0].tasks == (Atom("grasp", ("O1",)), Atom("assemble", ("R1",)))
    g1, g2, a = Atom("grasp", ("O1",)), Atom("grasp", ("O2",)), Atom("assemble", ("R1",))
    s2 = sequences.synthesize_sequences("S2", CELL, n=5, mode="all")
    assert [s.tasks for s in s2[:2]] == [(g1, g2, a), (g2, g1, a)]
    assert [len(s.prefix) + len(s.cycle) for s in s2] == sorted(
        len(s.prefix) + len(s.cycle) for s in s2)


def test_states_on_no_cycle_may_become_accepting_to_merge():
    # 0 -a-> 1, 1 -true-> 1 accepting; 0 also loops nowhere: 0 is transient and its
    # edges equal those of 2, an accepting copy, so marking 0 accepting merges them
    full, none = frozenset({0}), frozenset()
    edges = (Edge(0, 1, Cube(frozenset({"a"})), none), Edge(0, 2, Cube(), none),
             Edge(1, 1, Cube(), full), Edge(2, 1, Cube(frozenset({"a"})), full),
             Edge(2, 2, Cube(), full))
    sba = Automaton(("a",), 3, 0, edges, 1, True)
    reduced = _reduce_state_based(sba)
    assert reduced.num_states < sba.num_states
    for prefix, cycle in _small_lassos(("a",)):
        assert reduced.accepts_lasso(prefix, cycle) == sba.accepts_lasso(prefix, cycle)


def _small_lassos(aps):
    alphabet = [frozenset(c) for k in range(len(aps) + 1)
                for c in itertools.combinations(aps, k)]
    for n in range(3):
        for m in range(1, 3):
            for word in itertools.product(alphabet, repeat=n + m):
                yield list(word[:n]), list(word[n:])


@settings(max_examples=300, **PROFILE)
@given(formulas, st.lists(lassos, min_size=6, max_size=6))
def test_degeneralized_automaton_agrees_with_the_evaluator(formula, words):
    sba = degeneralize(translate(formula, backend="builtin"))
    assert sba.state_based and sba.num_sets == 1
    for prefix, cycle in words:
        assert sba.accepts_lasso(prefix, cycle) == evaluate_lasso(formula, prefix, cycle)
