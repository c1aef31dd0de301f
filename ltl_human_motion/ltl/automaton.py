"""The internal automaton type shared by both translators and the HOA reader.

A transition-based generalized Büchi automaton (TGBA): explicit states ``0..n-1``, one
initial state, edges labelled with a cube (a conjunction of literals over the atomic
propositions) and a set of acceptance marks. A run is accepting iff it takes edges of
every acceptance set infinitely often (``Inf(0) & ... & Inf(k-1)``; ``k = 0`` accepts
every infinite run). A state-based automaton is the special case in which all edges
leaving a state carry the same marks (``state_based=True`` records that, for HOA output).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from ltl_human_motion.deadline import checkpoint

__all__ = [
    "Automaton",
    "Cube",
    "Edge",
    "accepting_components",
    "degeneralize",
    "direct_simulation",
    "lasso_accepted",
    "reduce",
    "simulation_reduce",
    "strip_marks",
    "strongly_connected_components",
    "trim",
]


@dataclass(frozen=True)
class Cube:
    """A conjunction of literals: every atom of ``pos`` holds and none of ``neg``."""

    pos: frozenset[str] = frozenset()
    neg: frozenset[str] = frozenset()

    def satisfied_by(self, letter: Iterable[str]) -> bool:
        """True if the letter (a set of atom keys that hold) satisfies the cube."""
        letter = letter if isinstance(letter, (set, frozenset)) else set(letter)
        return self.pos <= letter and not (self.neg & letter)

    def conjoin(self, other: Cube) -> Cube | None:
        """The conjunction of two cubes, or None if it is contradictory."""
        pos, neg = self.pos | other.pos, self.neg | other.neg
        return None if pos & neg else Cube(pos, neg)

    def sort_key(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """A total order independent of hash seeds."""
        return (tuple(sorted(self.pos)), tuple(sorted(self.neg)))

    def __str__(self) -> str:
        lits = sorted([(a, "") for a in self.pos] + [(a, "!") for a in self.neg])
        return " & ".join(f"{s}{a}" for a, s in lits) or "true"


TRUE_CUBE = Cube()


@dataclass(frozen=True)
class Edge:
    """One transition ``src --guard / acc--> dst``."""

    src: int
    dst: int
    guard: Cube
    acc: frozenset[int] = frozenset()

    def sort_key(self) -> tuple:
        """A total order independent of hash seeds."""
        return (self.src, self.dst, self.guard.sort_key(), tuple(sorted(self.acc)))


def _sorted_edges(edges: Iterable[Edge]) -> tuple[Edge, ...]:
    return tuple(sorted(set(edges), key=Edge.sort_key))


def merge_cubes(cubes: Iterable[Cube]) -> list[Cube]:
    """An equivalent, usually shorter disjunction: drops cubes implied by another and
    joins pairs that differ in one literal's sign (``a & b | a & !b = a``)."""
    todo = set(cubes)
    changed = True
    while changed:
        changed = False
        for c in sorted(todo, key=Cube.sort_key):
            for d in sorted(todo, key=Cube.sort_key):
                if c == d:
                    continue
                if d.pos <= c.pos and d.neg <= c.neg:  # c implies d
                    todo.discard(c)
                    changed = True
                    break
                flip = (c.pos ^ d.pos) | (c.neg ^ d.neg)
                if len(flip) == 1 and c.pos | c.neg == d.pos | d.neg:
                    todo -= {c, d}
                    todo.add(Cube(c.pos - flip, c.neg - flip))
                    changed = True
                    break
            if changed:
                break
    return sorted(todo, key=Cube.sort_key)


def _merged_edges(edges: Iterable[Edge]) -> tuple[Edge, ...]:
    groups: dict[tuple[int, int, frozenset[int]], list[Cube]] = {}
    for e in edges:
        groups.setdefault((e.src, e.dst, e.acc), []).append(e.guard)
    return _sorted_edges(Edge(s, d, c, acc) for (s, d, acc), cubes in groups.items()
                         for c in merge_cubes(cubes))


@dataclass(frozen=True)
class Automaton:
    """A transition-based generalized Büchi automaton (see module docstring).

    Attributes
    ----------
    aps : tuple of str
        Atomic propositions (atom keys), in HOA order.
    num_states : int
    initial : int
    edges : tuple of Edge
    num_sets : int
        Number of acceptance sets ``k`` of ``Inf(0) & ... & Inf(k-1)``.
    state_based : bool
        All edges leaving a state carry the same marks.
    name : str
        Usually the formula the automaton was made from.
    """

    aps: tuple[str, ...]
    num_states: int
    initial: int
    edges: tuple[Edge, ...]
    num_sets: int = 1
    state_based: bool = False
    name: str = ""
    _out: tuple[tuple[Edge, ...], ...] = field(default=(), repr=False, compare=False)

    def __post_init__(self) -> None:
        if not 0 <= self.initial < max(self.num_states, 1):
            raise ValueError(f"initial state {self.initial} out of range "
                             f"0..{self.num_states - 1}")
        out: list[list[Edge]] = [[] for _ in range(self.num_states)]
        for e in self.edges:
            if not (0 <= e.src < self.num_states and 0 <= e.dst < self.num_states):
                raise ValueError(f"edge {e} leaves the states 0..{self.num_states - 1}")
            if any(not 0 <= m < self.num_sets for m in e.acc):
                raise ValueError(f"edge {e} has a mark outside 0..{self.num_sets - 1}")
            out[e.src].append(e)
        object.__setattr__(self, "_out", tuple(tuple(x) for x in out))

    @property
    def states(self) -> range:
        """All states."""
        return range(self.num_states)

    def successors(self, state: int) -> tuple[Edge, ...]:
        """The edges leaving ``state``."""
        return self._out[state]

    def accepting_states(self) -> frozenset[int]:
        """For a state-based automaton: states whose edges carry every mark."""
        full = frozenset(range(self.num_sets))
        return frozenset(q for q in self.states
                         if self._out[q] and all(e.acc >= full for e in self._out[q]))

    def accepts_lasso(self, prefix: Sequence[Iterable[str]],
                      cycle: Sequence[Iterable[str]]) -> bool:
        """True iff the automaton accepts ``prefix . cycle^omega``.

        Builds the product of the automaton with the lasso's positions and looks for a
        reachable strongly connected component that carries every acceptance mark.
        """
        word = [frozenset(x) for x in prefix] + [frozenset(x) for x in cycle]

        def succ(q: int, i: int):
            return [(e.dst, e.acc) for e in self._out[q] if e.guard.satisfied_by(word[i])]

        return lasso_accepted(self.initial, succ, len(prefix), len(cycle), self.num_sets)

    def is_empty(self) -> bool:
        """True iff the automaton accepts no word (ignoring label satisfiability)."""
        reach = self._reachable()
        adj = [[(e.dst, e.acc) for e in self._out[q]] if q in reach else []
               for q in self.states]
        return not accepting_components(adj, self.num_sets)

    def _reachable(self) -> set[int]:
        seen = {self.initial}
        stack = [self.initial]
        while stack:
            q = stack.pop()
            for e in self._out[q]:
                if e.dst not in seen:
                    seen.add(e.dst)
                    stack.append(e.dst)
        return seen


def lasso_accepted(initial: int, succ, n_prefix: int, n_cycle: int, num_sets: int) -> bool:
    """Whether an automaton accepts a lasso word: the product of the automaton with the
    word's positions (prefix ``0..n_prefix-1``, then the cycle) has a reachable strongly
    connected component carrying all ``num_sets`` marks.

    ``succ(q, i)`` gives the edges ``(state, marks)`` leaving ``q`` on the letter at
    position ``i``.

    Raises
    ------
    ValueError
        If the cycle is empty.
    """
    if n_cycle < 1:
        raise ValueError("a lasso needs at least one cycle letter, got an empty cycle")
    total = n_prefix + n_cycle
    index: dict[tuple[int, int], int] = {(initial, 0): 0}
    adj: list[list[tuple[int, frozenset[int]]]] = [[]]
    stack = [(initial, 0)]
    while stack:
        q, i = stack.pop()
        src = index[(q, i)]
        j = i + 1 if i + 1 < total else n_prefix
        for dst, acc in succ(q, i):
            key = (dst, j)
            if key not in index:
                index[key] = len(adj)
                adj.append([])
                stack.append(key)
            adj[src].append((index[key], acc))
    return bool(accepting_components(adj, num_sets))


def strongly_connected_components(adj: Sequence[Sequence[tuple[int, object]]]) -> list[int]:
    """Component index of every node (iterative Tarjan); ``adj[v]`` = [(w, label), ...]."""
    n = len(adj)
    index = [-1] * n
    low = [0] * n
    comp = [-1] * n
    on_stack = [False] * n
    stack: list[int] = []
    counter = 0
    ncomp = 0
    for root in range(n):
        if index[root] != -1:
            continue
        work = [(root, 0)]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack[root] = True
        while work:
            v, k = work[-1]
            if k < len(adj[v]):
                work[-1] = (v, k + 1)
                w = adj[v][k][0]
                if index[w] == -1:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack[w] = True
                    work.append((w, 0))
                elif on_stack[w]:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[v])
                if low[v] == index[v]:
                    while True:
                        w = stack.pop()
                        on_stack[w] = False
                        comp[w] = ncomp
                        if w == v:
                            break
                    ncomp += 1
    return comp


def accepting_components(adj: Sequence[Sequence[tuple[int, frozenset[int]]]],
                         num_sets: int) -> set[int]:
    """Components (by index of :func:`strongly_connected_components`) with a cycle that
    carries all ``num_sets`` marks."""
    comp = strongly_connected_components(adj)
    marks: dict[int, set[int]] = {}
    for v, edges in enumerate(adj):
        for w, acc in edges:
            if comp[v] == comp[w]:
                marks.setdefault(comp[v], set()).update(acc)
    return {c for c, m in marks.items() if len(m) >= num_sets}


def _renumber(aut: Automaton, keep: Iterable[int], state_based: bool | None = None) -> Automaton:
    order = sorted(set(keep) | {aut.initial}, key=lambda q: (q != aut.initial, q))
    new = {q: i for i, q in enumerate(order)}
    edges = _sorted_edges(Edge(new[e.src], new[e.dst], e.guard, e.acc)
                          for e in aut.edges if e.src in new and e.dst in new)
    return Automaton(aut.aps, len(order), 0, edges, aut.num_sets,
                     aut.state_based if state_based is None else state_based, aut.name)


def trim(aut: Automaton) -> Automaton:
    """Keep only states that are reachable and can reach an accepting cycle.

    An empty language gives a single initial state without edges.
    """
    reach = aut._reachable()
    adj = [[(e.dst, e.acc) for e in aut.successors(q)] if q in reach else []
           for q in aut.states]
    good = accepting_components(adj, aut.num_sets)
    comp = strongly_connected_components(adj)
    useful = {q for q in reach if comp[q] in good}
    rev: list[list[int]] = [[] for _ in aut.states]
    for e in aut.edges:
        if e.src in reach:
            rev[e.dst].append(e.src)
    stack = list(useful)
    while stack:
        q = stack.pop()
        for p in rev[q]:
            if p not in useful:
                useful.add(p)
                stack.append(p)
    return _renumber(aut, useful)


def reduce(aut: Automaton) -> Automaton:
    """Merge bisimilar states (same guards, marks and successor classes).

    For a state-based automaton the marks are a property of the source state, so the
    result stays state-based.
    """
    block = [0] * aut.num_states
    count = 1
    while True:
        sigs: dict[tuple, int] = {}
        new_block = []
        for q in aut.states:
            sig = (block[q], frozenset((e.guard, e.acc, block[e.dst])
                                       for e in aut.successors(q)))
            new_block.append(sigs.setdefault(sig, len(sigs)))
        if len(sigs) == count:
            break
        block, count = new_block, len(sigs)
    block = new_block
    rep: dict[int, int] = {}
    for q in sorted(aut.states, key=lambda q: (q != aut.initial, q)):
        rep.setdefault(block[q], q)
    order = sorted(rep.values(), key=lambda q: (q != aut.initial, q))
    new = {q: i for i, q in enumerate(order)}
    edges = _merged_edges(Edge(new[rep[block[e.src]]], new[rep[block[e.dst]]], e.guard, e.acc)
                          for e in aut.edges if rep[block[e.src]] == e.src)
    return Automaton(aut.aps, len(order), 0, edges, aut.num_sets, aut.state_based, aut.name)


def _component_kinds(aut: Automaton) -> tuple[list[int], set[int], set[int]]:
    """SCC index per state, accepting SCCs, and "full" SCCs (every internal edge carries
    every mark, so every cycle in them is accepting)."""
    adj = [[(e.dst, e.acc) for e in aut.successors(q)] for q in aut.states]
    comp = strongly_connected_components(adj)
    full_marks = frozenset(range(aut.num_sets))
    inside: dict[int, list[Edge]] = {}
    for e in aut.edges:
        if comp[e.src] == comp[e.dst]:
            inside.setdefault(comp[e.src], []).append(e)
    accepting = {c for c, es in inside.items()
                 if len(frozenset().union(*(e.acc for e in es))) >= aut.num_sets}
    full = {c for c in accepting if all(e.acc >= full_marks for e in inside[c])}
    return comp, accepting, full


def strip_marks(aut: Automaton) -> Automaton:
    """Remove acceptance marks that no accepting cycle can use.

    Marks on edges between two SCCs, and inside SCCs without an accepting cycle, never
    decide acceptance; removing them keeps the language and lets more states merge.
    """
    if aut.state_based or aut.num_sets == 0:
        return aut
    comp, accepting, _ = _component_kinds(aut)
    edges = tuple(e if comp[e.src] == comp[e.dst] and comp[e.src] in accepting
                  else Edge(e.src, e.dst, e.guard, frozenset()) for e in aut.edges)
    return Automaton(aut.aps, aut.num_states, aut.initial, edges, aut.num_sets, False,
                     aut.name)


def degeneralize(aut: Automaton) -> Automaton:
    """An equivalent state-based Büchi automaton (one acceptance set on states).

    States are ``(q, level)``: level ``l < k`` waits for the l-th mark, level ``k`` means
    a full round of marks was just completed (accepting). Levels are only tracked inside
    accepting SCCs: entering an SCC resets the level, SCCs whose every edge carries every
    mark are accepting throughout, and SCCs without accepting cycles stay at level 0.
    The result is trimmed and reduced (states on no cycle may be made accepting when that
    lets them merge, see :func:`_reduce_state_based`); for up to three marks every order
    of the marks is tried and the smallest result kept.
    """
    if aut.num_sets > 3 or (aut.state_based and aut.num_sets <= 1):
        return _degeneralize(aut, tuple(range(aut.num_sets)))
    candidates = [_degeneralize(aut, order)
                  for order in itertools.permutations(range(aut.num_sets))]
    return min(candidates, key=lambda a: (a.num_states, len(a.edges)))


def _degeneralize(aut: Automaton, order: tuple[int, ...]) -> Automaton:
    k = aut.num_sets
    if aut.state_based and k <= 1:
        return aut
    if k == 0:
        edges = tuple(Edge(e.src, e.dst, e.guard, frozenset({0})) for e in aut.edges)
        return reduce(trim(Automaton(aut.aps, aut.num_states, aut.initial, edges, 1, True,
                                     aut.name)))
    comp, accepting, full = _component_kinds(aut)

    def entry_level(q: int) -> int:
        return k if comp[q] in full else 0

    start = (aut.initial, entry_level(aut.initial))
    index: dict[tuple[int, int], int] = {start: 0}
    todo = [start]
    raw: list[tuple[int, int, Cube]] = []
    while todo:
        q, level = todo.pop()
        src = index[(q, level)]
        for e in aut.successors(q):
            c = comp[e.dst]
            if c != comp[q] or c in full or c not in accepting:
                nxt = entry_level(e.dst)
            else:
                nxt = 0 if level == k else level
                while nxt < k and order[nxt] in e.acc:
                    nxt += 1
            key = (e.dst, nxt)
            if key not in index:
                index[key] = len(index)
                todo.append(key)
            raw.append((src, index[key], e.guard))
    accepting_states = {i for (q, level), i in index.items() if level == k}
    edges = tuple(Edge(s, d, g, frozenset({0}) if s in accepting_states else frozenset())
                  for s, d, g in raw)
    return _reduce_state_based(Automaton(aut.aps, len(index), 0, edges, 1, True, aut.name))


def _reduce_state_based(sba: Automaton) -> Automaton:
    """Trim and reduce a state-based Büchi automaton.

    A state on no cycle is visited at most once by a run, so whether it is accepting does
    not matter; the automaton is reduced both with such states rejecting and with them
    accepting (which lets them merge with accepting states), and the smaller result kept.
    """
    plain = simulation_reduce(reduce(trim(sba)))
    adj = [[(e.dst, e.acc) for e in sba.successors(q)] for q in sba.states]
    comp = strongly_connected_components(adj)
    size: dict[int, int] = {}
    for c in comp:
        size[c] = size.get(c, 0) + 1
    transient = {q for q in sba.states if size[comp[q]] == 1
                 and all(e.dst != q for e in sba.successors(q))}
    if not any(e.src in transient and not e.acc for e in sba.edges):
        return plain
    edges = tuple(Edge(e.src, e.dst, e.guard, frozenset({0})) if e.src in transient else e
                  for e in sba.edges)
    marked = simulation_reduce(reduce(trim(Automaton(sba.aps, sba.num_states, sba.initial,
                                                     edges, 1, True, sba.name))))
    return min((plain, marked), key=lambda a: (a.num_states, len(a.edges)))


def _implies(c1: Cube, c2: Cube) -> bool:
    """True if every letter satisfying ``c1`` satisfies ``c2``."""
    return c2.pos <= c1.pos and c2.neg <= c1.neg


#: Larger automata skip the simulation reduction (the language is the same, the automaton
#: larger): its relation holds n^2 state pairs, 17 million (over 1 GB) for the 4,097
#: states of 12 ``GF`` terms, while every formula of the corpus stays under 100 states.
MAX_SIMULATION_STATES = 1500


def direct_simulation(aut: Automaton) -> list[set[int]]:
    """``sim[q]``: the states that directly simulate ``q``.

    ``p`` simulates ``q`` if every edge ``q --g/A--> q'`` is matched by an edge
    ``p --g'/A'--> p'`` with ``g`` implying ``g'``, ``A`` a subset of ``A'`` and ``p'``
    simulating ``q'`` (greatest fixpoint).
    """
    sim = [set(aut.states) for _ in aut.states]
    changed = True
    while changed:
        changed = False
        for q in aut.states:
            checkpoint("translation")
            for p in list(sim[q]):
                if p == q:
                    continue
                for e in aut.successors(q):
                    if not any(_implies(e.guard, f.guard) and e.acc <= f.acc
                               and f.dst in sim[e.dst] for f in aut.successors(p)):
                        sim[q].discard(p)
                        changed = True
                        break
    return sim


def simulation_reduce(aut: Automaton) -> Automaton:
    """Merge states that simulate each other and drop dominated edges.

    Both steps use direct simulation (:func:`direct_simulation`) and keep the language:
    an edge is dropped when another edge of the same state reads at least its letters,
    carries at least its marks and leads to a state that simulates its target. Automata
    of more than :data:`MAX_SIMULATION_STATES` states are returned unchanged.
    """
    if aut.num_states > MAX_SIMULATION_STATES:
        return aut
    sim = direct_simulation(aut)
    rep = [min(p for p in sim[q] if q in sim[p]) for q in aut.states]
    merged = _sorted_edges(Edge(rep[e.src], rep[e.dst], e.guard, e.acc)
                           for e in aut.edges if rep[e.src] == e.src)
    by_src: dict[int, list[Edge]] = {}
    for e in merged:
        by_src.setdefault(e.src, []).append(e)
    kept: list[Edge] = []
    for edges in by_src.values():
        alive = list(edges)
        for e in edges:
            if any(f is not e and _implies(e.guard, f.guard) and e.acc <= f.acc
                   and f.dst in sim[e.dst] for f in alive):
                alive.remove(e)
        kept.extend(alive)
    init = rep[aut.initial]
    quotient = Automaton(aut.aps, aut.num_states, init, tuple(kept), aut.num_sets,
                         aut.state_based, aut.name)
    return reduce(trim(quotient))
