"""On-the-fly translation over a task alphabet: the letters are "which task step".

The specification's always-on exclusivity makes at most one task hold per step, so a
run reads one of a fixed list of letters (the letter of each candidate task step,
:func:`~ltl_human_motion.ltl.spec.letter_of`) instead of any subset of atoms. The
tableau of :mod:`~ltl_human_motion.ltl.translate_builtin` (Couvreur's, FM'99) is
expanded here for one letter at a time and only for the states a search visits:

* a state is a set of NNF formulas (their conjunction), interned to an int;
* ``expand(f, letter)`` gives the terms ``(next, promises)`` of ``f`` whose letter
  condition the letter satisfies; it is memoized per (formula, letter), so the many
  ``F`` conjuncts of a kitting specification share their work across states, and
  letters that agree on the formula's atoms share one expansion (a symbolic set of
  letters: every step of a task the formula does not name is one class);
* an edge carries acceptance mark ``e`` (a bit) iff it does not promise eventuality
  ``e``; a run is accepting iff it takes every mark infinitely often.

Nothing is built in full: 20 ``F`` conjuncts have 2**20 states, and a product search
touches a few hundred of them.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from ltl_human_motion.ltl.automaton import lasso_accepted
from ltl_human_motion.ltl.formula import (
    And,
    Atom,
    Const,
    Finally,
    Formula,
    Globally,
    Next,
    Not,
    Or,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)
from ltl_human_motion.ltl.simplify import simplify
from ltl_human_motion.ltl.translate_builtin import _state_key

__all__ = ["LetterTableau"]

_Term = tuple[frozenset[Formula], frozenset[Formula]]

#: States with at least this many formulas expand only those a letter touches (below, a
#: plain product is cheaper: the paper's S1/S2 states hold 2-6 formulas, kitting's 20-60).
SPLIT_MIN_FORMULAS = 12
_EMPTY: frozenset = frozenset()
_EVENTUALITIES = (Finally, Until, StrongRelease)
_PERSISTENT = (Globally, Release, WeakUntil)


def _prune(terms: list[_Term]) -> list[_Term]:
    """Drop duplicates and terms implied by a weaker one (subsets of next and promises)."""
    unique = sorted(set(terms), key=lambda t: (len(t[0]) + len(t[1]),
                                               sorted(map(str, t[0])), sorted(map(str, t[1]))))
    kept: list[_Term] = []
    for nx, pr in unique:
        if not any(k[0] <= nx and k[1] <= pr for k in kept):
            kept.append((nx, pr))
    return kept


def _product(left: list[_Term], right: list[_Term]) -> list[_Term]:
    if len(left) == 1 and len(right) == 1:
        (n1, p1), (n2, p2) = left[0], right[0]
        return [(n1 | n2, p1 | p2)]
    return _prune([(n1 | n2, p1 | p2) for n1, p1 in left for n2, p2 in right])


def _subformulas(f: Formula, out: set[Formula]) -> set[Formula]:
    if f not in out:
        out.add(f)
        for g in f.children():
            _subformulas(g, out)
    return out


class LetterTableau:
    """The tableau automaton of ``formula`` over the given letters, explored on demand.

    Parameters
    ----------
    formula : Formula
        Without the exclusivity conjunct (the letters make it true at every step).
    letters : sequence of frozenset of str
        Letter ``i`` is the set of atom keys that hold at a step of task ``i``.

    Attributes
    ----------
    initial : int
        The initial state.
    num_sets : int
        Number of acceptance marks (eventualities); ``full`` has all their bits set.
    """

    def __init__(self, formula: Formula, letters: Sequence[frozenset[str]]) -> None:
        self.formula = simplify(formula)
        self.letters = tuple(frozenset(x) for x in letters)
        subs = _subformulas(self.formula, set())
        events = sorted((f for f in subs if isinstance(f, _EVENTUALITIES)), key=str)
        self.mark_of = {f: 1 << i for i, f in enumerate(events)}
        self.num_sets = len(events)
        self.full = (1 << self.num_sets) - 1
        # letters that agree on the formula's atoms behave alike: one expansion per class
        keys = {a.key for a in subs if isinstance(a, Atom)}
        classes: dict[frozenset[str], int] = {}
        self._class = [classes.setdefault(letter & keys, i)
                       for i, letter in enumerate(self.letters)]
        # a letter holding none of the formula's atoms (index len(letters)): what every
        # formula of a state does on a letter none of its atoms holds in
        self._letter_sets = (*self.letters, _EMPTY)
        self._class.append(classes.setdefault(_EMPTY, len(self.letters)))
        self._split: dict[int, tuple] = {}
        self._atoms: dict[Formula, frozenset[str]] = {}
        self.states: list[frozenset[Formula]] = []
        self._ids: dict[frozenset[Formula], int] = {}
        self._memo: dict[tuple[Formula, int], list[_Term]] = {}
        self._succ: dict[tuple[int, int], tuple[tuple[int, int], ...]] = {}
        self._loopable: dict[int, bool] = {}
        self._proper: dict[Formula, frozenset[Formula]] = {}
        self._mentioned: dict[int, frozenset[str]] = {}
        self._next_ids: dict[frozenset[Formula], int] = {}
        self._formula_names: dict[Formula, frozenset[str]] = {}
        self.initial = self._intern(_state_key(frozenset({self.formula})))
        #: Seconds spent making edges (the automaton's share of a product search).
        self.build_seconds = 0.0

    def _intern(self, state: frozenset[Formula]) -> int:
        q = self._ids.get(state)
        if q is None:
            q = self._ids[state] = len(self.states)
            self.states.append(state)
        return q

    def expand(self, f: Formula, i: int) -> list[_Term]:
        """Terms ``(next, promises)`` of ``f`` allowed by letter ``i`` (memoized)."""
        i = self._class[i]
        key = (f, i)
        hit = self._memo.get(key)
        if hit is not None:
            return hit
        letter = self._letter_sets[i]
        if isinstance(f, Const):
            r = [(_EMPTY, _EMPTY)] if f.value else []
        elif isinstance(f, Atom):
            r = [(_EMPTY, _EMPTY)] if f.key in letter else []
        elif isinstance(f, Not):
            r = [] if f.arg.key in letter else [(_EMPTY, _EMPTY)]
        elif isinstance(f, And):
            r = [(_EMPTY, _EMPTY)]
            for g in f.args:
                r = _product(r, self.expand(g, i))
                if not r:
                    break
        elif isinstance(f, Or):
            r = _prune([t for g in f.args for t in self.expand(g, i)])
        elif isinstance(f, Next):
            r = [(frozenset({f.arg}), _EMPTY)]
        elif isinstance(f, Finally):
            r = _prune([*self.expand(f.arg, i), (frozenset({f}), frozenset({f}))])
        elif isinstance(f, Globally):
            r = _product(self.expand(f.arg, i), [(frozenset({f}), _EMPTY)])
        elif isinstance(f, Until):
            r = _prune(self.expand(f.right, i) + _product(
                self.expand(f.left, i), [(frozenset({f}), frozenset({f}))]))
        elif isinstance(f, WeakUntil):
            r = _prune(self.expand(f.right, i) + _product(
                self.expand(f.left, i), [(frozenset({f}), _EMPTY)]))
        elif isinstance(f, Release):
            r = _prune(_product(self.expand(f.left, i), self.expand(f.right, i)) + _product(
                self.expand(f.right, i), [(frozenset({f}), _EMPTY)]))
        elif isinstance(f, StrongRelease):
            r = _prune(_product(self.expand(f.left, i), self.expand(f.right, i)) + _product(
                self.expand(f.right, i), [(frozenset({f}), frozenset({f}))]))
        else:
            raise TypeError(f"not an NNF formula node: {f!r}")
        self._memo[key] = r
        return r

    def successors(self, q: int, i: int) -> tuple[tuple[int, int], ...]:
        """``(state, marks)`` of every edge leaving ``q`` on letter ``i`` (marks: bits)."""
        i = self._class[i]
        key = (q, i)
        hit = self._succ.get(key)
        if hit is not None:
            return hit
        t0 = time.perf_counter()
        if len(self.states[q]) < SPLIT_MIN_FORMULAS:
            terms = self._plain_terms(q, i)
        else:
            terms = self._split_terms(q, i)
        out = []
        for nx, pr in terms:
            promised = 0
            for e in pr:
                promised |= self.mark_of[e]
            q2 = self._next_ids.get(nx)
            if q2 is None:
                q2 = self._next_ids[nx] = self._intern(_state_key(nx))
            out.append((q2, self.full & ~promised))
        result = tuple(sorted(set(out)))
        self._succ[key] = result
        self.build_seconds += time.perf_counter() - t0
        return result

    def _plain_terms(self, q: int, i: int) -> list[_Term]:
        """The terms of state ``q`` on letter class ``i``: the product of the expansions
        of all its formulas."""
        terms: list[_Term] = [(_EMPTY, _EMPTY)]
        for f in sorted(self.states[q], key=str):
            terms = _product(terms, self.expand(f, i))
            if not terms:
                break
        return terms

    def _split_terms(self, q: int, i: int) -> list[_Term]:
        """The terms of :meth:`_plain_terms`, expanding only the formulas whose atoms the
        letter holds (:meth:`_split_state`)."""
        general, by_atom, nexts, promises, count_n, count_p, single = self._split_state(q)
        letter = self.letters[i]
        touched = set(general)
        for a in letter:
            touched.update(by_atom.get(a, ()))
        # the formulas none of whose atoms the letter holds: one term each, their union
        gone_n: dict[Formula, int] = {}
        gone_p: dict[Formula, int] = {}
        for f in touched:
            term = single.get(f)
            if term is not None:
                for x in term[0]:
                    gone_n[x] = gone_n.get(x, 0) + 1
                for x in term[1]:
                    gone_p[x] = gone_p.get(x, 0) + 1
        rest = (nexts - {x for x, k in gone_n.items() if k == count_n[x]},
                promises - {x for x, k in gone_p.items() if k == count_p[x]})
        terms: list[_Term] = [rest]
        for f in sorted(touched, key=str):
            terms = _product(terms, self.expand(f, i))
            if not terms:
                break
        return terms

    def _split_state(self, q: int) -> tuple:
        """Per state (memoized): the formulas whose expansion on a letter none of their
        atoms holds is not one term (always expanded), the others by atom, the union of
        those single terms (next, promises) with how many formulas give each part, and
        the single term of each. The product of single terms is their union, so a letter
        only expands the formulas whose atoms it holds."""
        hit = self._split.get(q)
        if hit is not None:
            return hit
        null = len(self.letters)
        general: list[Formula] = []
        by_atom: dict[str, list[Formula]] = {}
        count_n: dict[Formula, int] = {}
        count_p: dict[Formula, int] = {}
        single: dict[Formula, _Term] = {}
        for f in self.states[q]:
            terms = self.expand(f, null)
            if len(terms) != 1:
                general.append(f)
                continue
            single[f] = terms[0]
            for x in terms[0][0]:
                count_n[x] = count_n.get(x, 0) + 1
            for x in terms[0][1]:
                count_p[x] = count_p.get(x, 0) + 1
            for a in self._atom_keys(f):
                by_atom.setdefault(a, []).append(f)
        hit = self._split[q] = (tuple(general), by_atom, frozenset(count_n),
                                frozenset(count_p), count_n, count_p, single)
        return hit

    def _atom_keys(self, f: Formula) -> frozenset[str]:
        hit = self._atoms.get(f)
        if hit is None:
            hit = self._atoms[f] = frozenset(g.key for g in _subformulas(f, set())
                                             if isinstance(g, Atom))
        return hit

    def loopable(self, q: int) -> bool:
        """False if no accepting cycle can pass through ``q`` (a syntactic test).

        On a cycle back to ``q`` every formula of ``q`` must be there again; a formula is
        kept by itself only if it is a ``G``, ``R`` or ``W`` (an eventuality kept by
        itself is postponed, which blocks its mark), else it must be regenerated from a
        larger formula of ``q``.
        """
        hit = self._loopable.get(q)
        if hit is None:
            state = self.states[q]
            inner: set[Formula] = set()
            for g in state:
                inner |= self._proper_subformulas(g)
            hit = all(isinstance(f, _PERSISTENT) or f in inner for f in state)
            self._loopable[q] = hit
        return hit

    def _proper_subformulas(self, g: Formula) -> frozenset[Formula]:
        hit = self._proper.get(g)
        if hit is None:
            hit = frozenset(_subformulas(g, set()) - {g})
            self._proper[g] = hit
        return hit

    def accepts_lasso(self, prefix: Sequence[int], cycle: Sequence[int]) -> bool:
        """True iff the automaton accepts ``prefix cycle^omega`` (letter indices)."""
        word = [*prefix, *cycle]
        return lasso_accepted(self.initial,
                              lambda q, i: [(d, self.mark_set(m))
                                            for d, m in self.successors(q, word[i])],
                              len(prefix), len(cycle), self.num_sets)

    def mark_set(self, marks: int) -> frozenset[int]:
        """The acceptance sets of a mark bit field."""
        return frozenset(b for b in range(self.num_sets) if marks >> b & 1)

    def settled(self, q: int) -> bool:
        """Whether state ``q`` owes nothing now: it holds only ``G``, ``R`` and ``W``
        formulas (no eventuality, atom or next-step obligation is pending)."""
        return all(isinstance(f, _PERSISTENT) for f in self.states[q])

    def mentioned(self, q: int) -> frozenset[str]:
        """Arguments of the atoms of state ``q`` (the objects and regions it names)."""
        hit = self._mentioned.get(q)
        if hit is None:
            names: set[str] = set()
            for f in self.states[q]:
                names |= self._names(f)
            hit = self._mentioned[q] = frozenset(names)
        return hit

    def _names(self, f: Formula) -> frozenset[str]:
        hit = self._formula_names.get(f)
        if hit is None:
            hit = self._formula_names[f] = frozenset(
                n for g in _subformulas(f, set()) if isinstance(g, Atom) for n in g.args)
        return hit

    def pending(self, q: int) -> list[Formula]:
        """The ``F phi`` formulas of state ``q``: each needs a later step satisfying phi."""
        return [f for f in self.states[q] if isinstance(f, Finally)]
