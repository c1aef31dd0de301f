"""Built-in LTL to Büchi translator (pure Python): a tableau with transition marks.

The construction follows Couvreur's on-the-fly tableau (FM'99), the one behind Spot's
``ltl2tgba_fm``, with explicit sets instead of BDDs:

* A state is a set of formulas in negation normal form, read as their conjunction.
* Each formula *expands* into terms ``(cube, next, promises)``: a letter condition, the
  obligations for the next position, and the eventualities (``U``, ``F``, ``M``) it
  postpones, e.g. ``a U b = b | (a & X(a U b) & promise(a U b))``.
* An edge is in the acceptance set of eventuality ``e`` iff it does not promise ``e``,
  so an accepting run cannot postpone ``e`` forever.
* Terms implied by a weaker term are dropped, and bisimilar states are merged afterwards.
* For obligation properties, the minimal weak deterministic Büchi automaton
  (:func:`~ltl_human_motion.ltl.wdba.minimize_obligation`, checked against the
  automaton of the negated formula) replaces the tableau automaton when it is smaller.

The formula is simplified first (:func:`~ltl_human_motion.ltl.simplify.simplify`).
"""

from __future__ import annotations

from functools import lru_cache

from ltl_human_motion.deadline import checkpoint
from ltl_human_motion.ltl.automaton import (
    TRUE_CUBE,
    Automaton,
    Cube,
    Edge,
    reduce,
    simulation_reduce,
    strip_marks,
    trim,
)
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
    atoms,
)
from ltl_human_motion.ltl.simplify import simplify
from ltl_human_motion.ltl.wdba import minimize_obligation

__all__ = ["translate_builtin"]

_Term = tuple[Cube, frozenset[Formula], frozenset[Formula]]
_EMPTY: frozenset = frozenset()
_TRUE_TERM: _Term = (TRUE_CUBE, _EMPTY, _EMPTY)


@lru_cache(maxsize=8192)
def _names(formulas: frozenset[Formula]) -> tuple[str, ...]:
    """The sorted texts of ``formulas`` (a hash-seed independent sort key)."""
    return tuple(sorted(map(str, formulas)))


def _prune(terms: list[_Term]) -> list[_Term]:
    """Remove duplicate terms and terms implied by a weaker one."""
    unique = sorted(set(terms), key=lambda t: (len(t[0].pos) + len(t[0].neg) + len(t[1])
                                               + len(t[2]), t[0].sort_key(),
                                               _names(t[1]), _names(t[2])))
    kept: list[_Term] = []
    for t in unique:
        checkpoint("translation")                 # quadratic: 4,096 terms of 12 G F
        c, nx, pr = t
        if not any(k[0].pos <= c.pos and k[0].neg <= c.neg and k[1] <= nx and k[2] <= pr
                   for k in kept):
            kept.append(t)
    return kept


def _product(left: list[_Term], right: list[_Term]) -> list[_Term]:
    out = []
    for c1, n1, p1 in left:
        for c2, n2, p2 in right:
            c = c1.conjoin(c2)
            if c is not None:
                out.append((c, n1 | n2, p1 | p2))
    return _prune(out)


def _state_key(formulas: frozenset[Formula]) -> frozenset[Formula]:
    """Flatten conjunctions, drop ``true`` and formulas implied by ``G`` of themselves."""
    flat: set[Formula] = set()
    stack = list(formulas)
    while stack:
        f = stack.pop()
        if isinstance(f, And):
            stack.extend(f.args)
        elif f != Const(True):
            flat.add(f)
    always = {f.arg for f in flat if isinstance(f, Globally)}
    return frozenset(f for f in flat if f not in always)


class _Tableau:
    def __init__(self) -> None:
        self.memo: dict[Formula, list[_Term]] = {}

    def expand(self, f: Formula) -> list[_Term]:
        if f in self.memo:
            return self.memo[f]
        if isinstance(f, Const):
            r = [_TRUE_TERM] if f.value else []
        elif isinstance(f, Atom):
            r = [(Cube(frozenset({f.key}), _EMPTY), _EMPTY, _EMPTY)]
        elif isinstance(f, Not):
            r = [(Cube(_EMPTY, frozenset({f.arg.key})), _EMPTY, _EMPTY)]
        elif isinstance(f, And):
            r = [_TRUE_TERM]
            for g in f.args:
                r = _product(r, self.expand(g))
                if not r:
                    break
        elif isinstance(f, Or):
            r = _prune([t for g in f.args for t in self.expand(g)])
        elif isinstance(f, Next):
            r = [(TRUE_CUBE, frozenset({f.arg}), _EMPTY)]
        elif isinstance(f, Finally):
            r = _prune([*self.expand(f.arg), (TRUE_CUBE, frozenset({f}), frozenset({f}))])
        elif isinstance(f, Globally):
            r = _product(self.expand(f.arg), [(TRUE_CUBE, frozenset({f}), _EMPTY)])
        elif isinstance(f, Until):
            r = _prune(self.expand(f.right) + _product(
                self.expand(f.left), [(TRUE_CUBE, frozenset({f}), frozenset({f}))]))
        elif isinstance(f, WeakUntil):
            r = _prune(self.expand(f.right) + _product(
                self.expand(f.left), [(TRUE_CUBE, frozenset({f}), _EMPTY)]))
        elif isinstance(f, Release):
            r = _prune(_product(self.expand(f.left), self.expand(f.right)) + _product(
                self.expand(f.right), [(TRUE_CUBE, frozenset({f}), _EMPTY)]))
        elif isinstance(f, StrongRelease):
            r = _prune(_product(self.expand(f.left), self.expand(f.right)) + _product(
                self.expand(f.right), [(TRUE_CUBE, frozenset({f}), frozenset({f}))]))
        else:
            raise TypeError(f"not an NNF formula node: {f!r}")
        self.memo[f] = r
        return r

    def expand_state(self, state: frozenset[Formula]) -> list[_Term]:
        r = [_TRUE_TERM]
        for f in sorted(state, key=str):
            r = _product(r, self.expand(f))
            if not r:
                break
        return r


def translate_builtin(formula: Formula, name: str | None = None) -> Automaton:
    """Translate ``formula`` into a transition-based generalized Büchi automaton.

    Parameters
    ----------
    formula : Formula
    name : str, optional
        Name stored in the automaton (default: the formula's text).

    Returns
    -------
    Automaton
        Trimmed (only states on some accepting run, or one state for an empty language)
        and reduced by bisimulation and direct simulation. If the property is an
        obligation and its minimal weak deterministic Büchi automaton
        (:func:`~ltl_human_motion.ltl.wdba.minimize_obligation`) has fewer states, or as
        many states and the tableau automaton has acceptance sets, that one is returned
        (state-based, one acceptance set).
    """
    aut = _tableau_automaton(formula, name)
    if aut.num_states == 1 and aut.num_sets == 0:
        return aut
    wdba = minimize_obligation(aut, lambda: _tableau_automaton(Not(formula), name))
    if wdba is not None and (wdba.num_states < aut.num_states or (
            wdba.num_states == aut.num_states and aut.num_sets > 0)):
        return wdba
    return aut


def _tableau_automaton(formula: Formula, name: str | None) -> Automaton:
    f = simplify(formula)
    tableau = _Tableau()
    init = _state_key(frozenset({f}))
    index: dict[frozenset[Formula], int] = {init: 0}
    todo = [init]
    raw: list[tuple[int, int, Cube, frozenset[Formula]]] = []
    while todo:
        checkpoint("translation")
        state = todo.pop()
        src = index[state]
        for cube, nxt, promises in tableau.expand_state(state):
            key = _state_key(nxt)
            if key not in index:
                index[key] = len(index)
                todo.append(key)
            raw.append((src, index[key], cube, promises))
    postponed = sorted({e for *_, p in raw for e in p}, key=str)
    mark = {e: i for i, e in enumerate(postponed)}
    edges = tuple(Edge(s, d, c, frozenset(mark[e] for e in postponed if e not in p))
                  for s, d, c, p in raw)
    aps = tuple(sorted(a.key for a in atoms(formula)))
    aut = Automaton(aps, len(index), 0, edges, len(postponed), False,
                    str(formula) if name is None else name)
    return simulation_reduce(reduce(strip_marks(trim(aut))))
