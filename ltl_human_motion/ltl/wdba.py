"""Minimal weak deterministic Büchi automata for obligation properties.

Many specification patterns (safety, guarantee and their Boolean combinations: the
*obligation* properties) are recognized by a weak deterministic Büchi automaton (WDBA),
which has a unique minimal form and is often much smaller than a tableau automaton.
:func:`minimize_obligation` follows Dax, Eisinger and Klaedtke (ATVA'07), as Spot's
``minimize_obligation`` does:

1. The powerset construction over explicit letters gives a deterministic automaton ``D``.
2. A strongly connected component of ``D`` is accepting iff the original automaton
   accepts a word whose run in ``D`` ends in it. For an obligation property every cycle
   of a component gives the same answer; a shortest cycle through some state of an
   accepting component that is rejected proves the property is no obligation and stops
   early (before an automaton of the negation is built).
3. ``D`` is checked against the formula: ``L(f) & !L(D)`` and ``L(D) & L(!f)`` must be
   empty (the first uses the original automaton and the complement of the weak ``D``,
   which swaps accepting and rejecting components; only the second needs an automaton
   of ``!f``). For a safety automaton (no
   acceptance sets, every infinite run accepting) ``D`` is exact by König's lemma and
   the check is skipped.
4. Components are colored as in Löding's minimization of weak automata (colors never
   increase along a run, even = accepting, transient states take the smallest color of
   their successors) and the states are merged by Moore's partition refinement on the
   color parity.

The result is a state-based Büchi automaton (edge guards are irredundant sums of cubes).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

from ltl_human_motion.ltl.automaton import (
    Automaton,
    Cube,
    Edge,
    accepting_components,
    strongly_connected_components,
    trim,
)

__all__ = ["cube_cover", "minimize_obligation"]

MAX_APS = 8
MAX_STATES = 64
MAX_WORK = 8192  # bound on letters x states of the input and of the powerset automaton

_Cover = list[tuple[frozenset[int], frozenset[int]]]


def cube_cover(minterms: set[int], num_vars: int) -> _Cover:
    """An irredundant sum of cubes for the set of ``minterms`` (Minato–Morreale ISOP).

    Parameters
    ----------
    minterms : set of int
        Bit ``j`` of a minterm is the value of variable ``j``.
    num_vars : int

    Returns
    -------
    list of (frozenset of int, frozenset of int)
        ``(positive variables, negative variables)`` of each cube.
    """
    return _isop(frozenset(minterms), frozenset(minterms), 0, num_vars)


def _isop(lower: frozenset[int], upper: frozenset[int], var: int, n: int) -> _Cover:
    # functions over the variables var..n-1; bits below var are 0 in every minterm
    if not lower:
        return []
    if len(upper) == 1 << (n - var):
        return [(frozenset(), frozenset())]
    bit = 1 << var
    l0 = frozenset(m for m in lower if not m & bit)
    l1 = frozenset(m & ~bit for m in lower if m & bit)
    u0 = frozenset(m for m in upper if not m & bit)
    u1 = frozenset(m & ~bit for m in upper if m & bit)
    c0 = _isop(l0 - u1, u0, var + 1, n)
    c1 = _isop(l1 - u0, u1, var + 1, n)
    r0, r1 = _covered(c0, var + 1, n), _covered(c1, var + 1, n)
    rest = _isop((l0 - r0) | (l1 - r1), u0 & u1, var + 1, n)
    return ([(p, q | {var}) for p, q in c0] + [(p | {var}, q) for p, q in c1] + rest)


def _covered(cover: _Cover, var: int, n: int) -> frozenset[int]:
    """The minterms over the variables ``var..n-1`` that satisfy some cube of ``cover``."""
    out: set[int] = set()
    for pos, neg in cover:
        free = [j for j in range(var, n) if j not in pos and j not in neg]
        base = sum(1 << j for j in pos)
        for k in range(1 << len(free)):
            out.add(base + sum(1 << j for i, j in enumerate(free) if k >> i & 1))
    return frozenset(out)


def _letters_of(cube: Cube, aps: tuple[str, ...]) -> list[int]:
    """The letters (as minterms over ``aps``) that satisfy ``cube``."""
    pos = sum(1 << aps.index(a) for a in cube.pos)
    fixed = pos | sum(1 << aps.index(a) for a in cube.neg)
    return [m for m in range(1 << len(aps)) if m & fixed == pos]


class _Powerset:
    """The complete deterministic automaton of reachable state sets (0 = empty sink)."""

    def __init__(self, aut: Automaton, edge_letters: list[list[int]], limit: int) -> None:
        n = 1 << len(aut.aps)
        self.num_letters = n
        self.letter_sets = [frozenset(a for j, a in enumerate(aut.aps) if m >> j & 1)
                            for m in range(n)]
        succ = [[0] * n for _ in aut.states]
        for e, ms in zip(aut.edges, edge_letters):
            for m in ms:
                succ[e.src][m] |= 1 << e.dst
        start = 1 << aut.initial
        self.sets = [start]
        index = {start: 0}
        self.delta: list[list[int]] = []
        self.complete = True
        k = 0
        while k < len(self.sets):
            members = [q for q in aut.states if self.sets[k] >> q & 1]
            row = []
            for m in range(n):
                target = 0
                for q in members:
                    target |= succ[q][m]
                if target not in index:
                    if len(self.sets) >= limit:
                        self.complete = False
                        return
                    index[target] = len(self.sets)
                    self.sets.append(target)
                row.append(index[target])
            self.delta.append(row)
            k += 1
        adj = [[(d, None) for d in set(row)] for row in self.delta]
        self.comp = strongly_connected_components(adj)
        self.cyclic = {self.comp[s] for s, row in enumerate(self.delta)
                       if any(self.comp[d] == self.comp[s] for d in row)}

    def prefixes(self) -> list[list[int]]:
        """A shortest word (letter indices) from the initial state to each state."""
        words: list[list[int] | None] = [None] * len(self.sets)
        words[0] = []
        queue = deque([0])
        while queue:
            s = queue.popleft()
            for m, d in enumerate(self.delta[s]):
                if words[d] is None:
                    words[d] = [*words[s], m]
                    queue.append(d)
        return words  # type: ignore[return-value]

    def cycle(self, s: int) -> list[int]:
        """A shortest nonempty word from ``s`` back to ``s`` inside its component."""
        comp = self.comp[s]
        parent: dict[int, tuple[int, int]] = {}
        queue = deque([s])
        while queue:
            p = queue.popleft()
            for m, d in enumerate(self.delta[p]):
                if self.comp[d] != comp:
                    continue
                if d == s:
                    word = [m]
                    while p != s:
                        p, letter = parent[p]
                        word.append(letter)
                    return word[::-1]
                if d not in parent:
                    parent[d] = (p, m)
                    queue.append(d)
        raise ValueError(f"state {s} is on no cycle")


def _accepting_components(aut: Automaton, dba: _Powerset,
                          masks: list[int]) -> dict[int, bool] | None:
    """Acceptance of each cyclic component, or None if two of its cycles disagree.

    A component is accepting iff ``aut`` accepts some word whose deterministic run ends
    in it: iff the product of ``aut`` with the component has an accepting cycle. Every
    cycle of a rejecting component is then rejected; in an accepting component, the
    shortest cycle through each state is tried (for an obligation property all are
    accepted).
    """
    index: dict[tuple[int, int], int] = {}
    nodes: list[tuple[int, int]] = []
    for s, members in enumerate(dba.sets):
        if dba.comp[s] in dba.cyclic:
            for q in aut.states:
                if members >> q & 1:
                    index[(q, s)] = len(nodes)
                    nodes.append((q, s))
    leaving: list[list[tuple[Edge, int]]] = [[] for _ in aut.states]
    for e, mask in zip(aut.edges, masks):
        leaving[e.src].append((e, mask))
    adj: list[list[tuple[int, frozenset[int]]]] = []
    for q, s in nodes:
        out = set()
        row = dba.delta[s]
        for e, mask in leaving[q]:
            for m, d in enumerate(row):
                if mask >> m & 1 and dba.comp[d] == dba.comp[s]:
                    out.add((index[(e.dst, d)], e.acc))
        adj.append(list(out))
    product_comp = strongly_connected_components(adj)
    good = accepting_components(adj, aut.num_sets)
    accepting = {c: False for c in dba.cyclic}
    for (_, s), pc in zip(nodes, product_comp):
        if pc in good:
            accepting[dba.comp[s]] = True
    words = dba.prefixes()
    letters = dba.letter_sets
    checked = [s for s in range(len(dba.sets)) if accepting.get(dba.comp[s], False)]
    for s in checked:
        prefix = [letters[m] for m in words[s]]
        if not aut.accepts_lasso(prefix, [letters[m] for m in dba.cycle(s)]):
            return None
    return accepting


def _colors(dba: _Powerset, accepting: dict[int, bool]) -> list[int]:
    """Löding's coloring per state: even = accepting, never increasing along edges."""
    members: dict[int, list[int]] = {}
    for s, c in enumerate(dba.comp):
        members.setdefault(c, []).append(s)
    top = 2 * len(dba.sets) + 2
    color: dict[int, int] = {}
    for c in sorted(members):  # Tarjan numbers successors first
        below = [color[dba.comp[d]] for s in members[c] for d in dba.delta[s]
                 if dba.comp[d] != c]
        m = min(below, default=top)
        if c in dba.cyclic and (m % 2 == 0) != accepting[c]:
            m -= 1
        color[c] = m
    return [color[c] for c in dba.comp]


def _intersection_empty(aut: Automaton, dba: _Powerset, marked: list[bool]) -> bool:
    """True iff no word is accepted by ``aut`` and visits ``marked`` states of ``dba``
    infinitely often."""
    letters_of = [_letters_of(e.guard, aut.aps) for e in aut.edges]
    edge_ids: list[list[int]] = [[] for _ in aut.states]
    for i, e in enumerate(aut.edges):
        edge_ids[e.src].append(i)
    k = aut.num_sets
    extra = frozenset({k})
    index = {(aut.initial, 0): 0}
    adj: list[list[tuple[int, frozenset[int]]]] = [[]]
    stack = [(aut.initial, 0)]
    while stack:
        q, s = stack.pop()
        src = index[(q, s)]
        out: set[tuple[int, frozenset[int]]] = set()
        for i in edge_ids[q]:
            e = aut.edges[i]
            acc = e.acc | extra if marked[s] else e.acc
            for m in letters_of[i]:
                key = (e.dst, dba.delta[s][m])
                if key not in index:
                    index[key] = len(adj)
                    adj.append([])
                    stack.append(key)
                out.add((index[key], acc))
        adj[src] = list(out)
    return not accepting_components(adj, k + 1)


def _aligned(aut: Automaton, aps: tuple[str, ...]) -> Automaton | None:
    """``aut`` over the propositions ``aps`` (None if it uses others)."""
    if not set(aut.aps) <= set(aps):
        return None
    return Automaton(aps, aut.num_states, aut.initial, aut.edges, aut.num_sets,
                     aut.state_based, aut.name)


def _quotient(aut: Automaton, dba: _Powerset, color: list[int]) -> Automaton:
    """Moore's partition refinement on color parity, as a state-based Büchi automaton."""
    block = [c % 2 for c in color]
    count = len(set(block))
    while True:
        sigs: dict[tuple, int] = {}
        new = [sigs.setdefault((block[s], tuple(block[d] for d in row)), len(sigs))
               for s, row in enumerate(dba.delta)]
        if len(sigs) == count:
            break
        block, count = new, len(sigs)
    block = new
    order: dict[int, int] = {}
    reps: list[int] = []
    for s in range(len(dba.sets)):
        if block[s] not in order:
            order[block[s]] = len(reps)
            reps.append(s)
    n = len(aut.aps)
    edges = []
    for i, s in enumerate(reps):
        acc = frozenset({0}) if color[s] % 2 == 0 else frozenset()
        groups: dict[int, set[int]] = {}
        for m, d in enumerate(dba.delta[s]):
            groups.setdefault(order[block[d]], set()).add(m)
        for dst, minterms in groups.items():
            for pos, neg in cube_cover(minterms, n):
                cube = Cube(frozenset(aut.aps[j] for j in pos),
                            frozenset(aut.aps[j] for j in neg))
                edges.append(Edge(i, dst, cube, acc))
    return trim(Automaton(aut.aps, len(reps), 0, tuple(edges), 1, True, aut.name))


def minimize_obligation(aut: Automaton, negation: Callable[[], Automaton],
                        max_states: int = MAX_STATES) -> Automaton | None:
    """The minimal weak deterministic Büchi automaton of ``L(aut)``, if there is one.

    Parameters
    ----------
    aut : Automaton
        A (generalized) Büchi automaton of a formula ``f``.
    negation : callable
        Returns an automaton of ``!f``; called only when the candidate must be checked.
    max_states : int
        Give up when the powerset construction exceeds this many state sets.

    Returns
    -------
    Automaton or None
        A state-based Büchi automaton with the language of ``aut``, or None if the
        property is no obligation, the automaton has more than ``MAX_APS``
        propositions, or the automaton or its powerset is too large (``MAX_WORK``).
    """
    if len(aut.aps) > MAX_APS:
        return None
    num_letters = 1 << len(aut.aps)
    if num_letters * aut.num_states > MAX_WORK:
        return None
    edge_letters = [_letters_of(e.guard, aut.aps) for e in aut.edges]
    dba = _Powerset(aut, edge_letters, min(max_states, MAX_WORK // num_letters))
    if not dba.complete:
        return None
    masks = [sum(1 << m for m in ms) for ms in edge_letters]
    accepting = _accepting_components(aut, dba, masks)
    if accepting is None:
        return None
    color = _colors(dba, accepting)
    if aut.num_sets > 0:
        # L(aut) within L(D) first: it needs no automaton of the negation
        if not _intersection_empty(aut, dba, [c % 2 == 1 for c in color]):
            return None
        neg = _aligned(negation(), aut.aps)
        if neg is None or not _intersection_empty(neg, dba, [c % 2 == 0 for c in color]):
            return None
    return _quotient(aut, dba, color)
