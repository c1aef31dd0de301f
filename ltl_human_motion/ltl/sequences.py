"""Task sequences: finite paths through the automaton (Sec. II-C).

A sequence is a lasso ``prefix . cycle^omega`` accepted by the automaton of the full
specification, cut after ``repetitions`` passes through the accepting cycle, so the
acceptance condition is passed at least once. Edges are given concrete letters: the
letter of a candidate task step (:func:`~ltl_human_motion.ltl.spec.letter_of`) that
satisfies the edge guard. Only if no lasso exists over task letters is the empty letter
(a step with no task) allowed; such steps are dropped and the shortened word is checked
again. Every emitted sequence is checked by the independent evaluator.

Variation modes:

``"all"``
    All distinct lassos in order of length (shortest first), up to ``max_length`` letters.
``"coverage"``
    A set of lassos in which every reachable transition that lies on an accepting run
    (and has a task letter) appears at least once, in the spirit of transition coverage
    in state-machine testing (ref. [48]).
``"random"``
    Seeded random walks: a random prefix, then a random accepting cycle.

Lassos are put in a canonical form (shortest prefix, primitive cycle), so two sequences
are distinct only if they describe different infinite words. The same seed gives the
same output.
"""

from __future__ import annotations

import math
import random
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

from ltl_human_motion.errors import SpecError, VerificationError
from ltl_human_motion.ltl.automaton import Automaton, accepting_components
from ltl_human_motion.ltl.automaton import strongly_connected_components as _sccs
from ltl_human_motion.ltl.evaluator import evaluate_lasso
from ltl_human_motion.ltl.formula import Atom, Formula, conj
from ltl_human_motion.ltl.limits import translation_budget
from ltl_human_motion.ltl.spec import Specification, build_specification, letter_of
from ltl_human_motion.ltl.translate import translate

__all__ = ["MODES", "TaskSequence", "synthesize_sequences", "task_automaton",
           "unsat_core"]

MODES = ("random", "coverage", "all")
_WORK_LIMIT = 200_000


@dataclass(frozen=True)
class TaskSequence:
    """``prefix + cycle * repetitions``: a finite task sequence from an accepting lasso.

    Attributes
    ----------
    prefix : tuple of Task
    cycle : tuple of Task
        Non-empty; passing it once passes the acceptance condition.
    repetitions : int
        How often the cycle is performed (>= 1).
    letters : tuple of frozenset, optional
        The letter of each distinct task step (filled by the synthesizer).
    """

    prefix: tuple[Atom, ...]
    cycle: tuple[Atom, ...]
    repetitions: int = 1
    letter_map: tuple[tuple[Atom, frozenset[str]], ...] = ()

    def __post_init__(self) -> None:
        if not self.cycle:
            raise ValueError("a task sequence needs a non-empty cycle")
        if self.repetitions < 1:
            raise ValueError(f"repetitions must be >= 1, got {self.repetitions}")

    @property
    def tasks(self) -> tuple[Atom, ...]:
        """The finite sequence of task steps."""
        return self.prefix + self.cycle * self.repetitions

    def lasso(self, cell: object = None) -> tuple[list[frozenset[str]], list[frozenset[str]]]:
        """(letters of the prefix, letters of the cycle)."""
        known = dict(self.letter_map)

        def letter(t: Atom) -> frozenset[str]:
            return known[t] if t in known else letter_of(t, cell)

        return [letter(t) for t in self.prefix], [letter(t) for t in self.cycle]

    def __str__(self) -> str:
        pre = ", ".join(map(str, self.prefix))
        cyc = ", ".join(map(str, self.cycle))
        head = f"{pre}, " if pre else ""
        return f"{head}({cyc}) x{self.repetitions}"


# --------------------------------------------------------------------------- graph

@dataclass(frozen=True)
class _Arc:
    src: int
    dst: int
    edge: int          # index into automaton edges
    letter: int        # index into the letters, -1 = empty letter
    acc: frozenset[int]


class _LetterGraph:
    """The automaton with each edge expanded into the task letters satisfying its guard."""

    def __init__(self, aut: Automaton, letters: Sequence[frozenset[str]],
                 allow_empty: bool) -> None:
        self.aut = aut
        self.out: list[list[_Arc]] = [[] for _ in aut.states]
        for k, e in enumerate(aut.edges):
            options = [i for i, letter in enumerate(letters) if e.guard.satisfied_by(letter)]
            if allow_empty and e.guard.satisfied_by(frozenset()):
                options.append(-1)
            for i in options:
                self.out[e.src].append(_Arc(e.src, e.dst, k, i, e.acc))
        adj = [[(a.dst, a.acc) for a in arcs] for arcs in self.out]
        self.comp = _sccs(adj)
        self.good = accepting_components(adj, aut.num_sets)
        reach = self._reach([aut.initial], self.out)
        rev: list[list[_Arc]] = [[] for _ in aut.states]
        for arcs in self.out:
            for a in arcs:
                rev[a.dst].append(_Arc(a.dst, a.src, a.edge, a.letter, a.acc))
        seeds = [q for q in aut.states if self.comp[q] in self.good]
        self.useful = reach & self._reach(seeds, rev)
        for q in aut.states:
            self.out[q] = [a for a in self.out[q] if a.dst in self.useful]

    @staticmethod
    def _reach(seeds: list[int], out: list[list[_Arc]]) -> set[int]:
        seen = set(seeds)
        stack = list(seeds)
        while stack:
            q = stack.pop()
            for a in out[q]:
                if a.dst not in seen:
                    seen.add(a.dst)
                    stack.append(a.dst)
        return seen

    def nonempty(self) -> bool:
        return self.aut.initial in self.useful

    def in_good_scc(self, q: int) -> bool:
        return self.comp[q] in self.good

    def path(self, src: int, goal, inside: int | None = None) -> list[_Arc] | None:
        """Shortest path (>= 0 arcs) from src to an arc ``a`` with ``goal(a)`` (included),
        or to a state if goal is an int (then the path may be empty)."""
        if isinstance(goal, int) and goal == src:
            return []
        parent: dict[int, _Arc | None] = {src: None}
        queue = deque([src])
        while queue:
            q = queue.popleft()
            for a in self.out[q]:
                if inside is not None and self.comp[a.dst] != inside:
                    continue
                hit = a.dst == goal if isinstance(goal, int) else goal(a)
                if hit:
                    return [*self._unwind(parent, q), a]
                if a.dst not in parent:
                    parent[a.dst] = a
                    queue.append(a.dst)
        return None

    @staticmethod
    def _unwind(parent: dict[int, _Arc | None], q: int) -> list[_Arc]:
        out = []
        while parent[q] is not None:
            a = parent[q]
            out.append(a)
            q = a.src
        return out[::-1]

    def accepting_cycle(self, start: int, rng: random.Random | None = None) -> list[_Arc]:
        """A cycle from ``start`` (in an accepting SCC) back to it with every mark."""
        comp = self.comp[start]
        cycle: list[_Arc] = []
        here = start
        if rng is not None:
            for _ in range(rng.randint(0, 4)):
                arcs = [a for a in self.out[here] if self.comp[a.dst] == comp]
                a = rng.choice(arcs)
                cycle.append(a)
                here = a.dst
        seen = set().union(*(a.acc for a in cycle)) if cycle else set()
        for m in range(self.aut.num_sets):
            if m in seen:
                continue
            seg = self.path(here, lambda a, m=m: m in a.acc, inside=comp)
            cycle += seg
            seen |= set().union(*(a.acc for a in seg))
            here = cycle[-1].dst
        if here != start or not cycle:
            if here == start:  # need at least one arc: leave and come back
                seg = self.path(start, lambda a: True, inside=comp)
                cycle += seg
                here = seg[-1].dst
            if here != start:
                cycle += self.path(here, start, inside=comp)
        return cycle


# --------------------------------------------------------------------------- lassos

def _canonical(prefix: list[int], cycle: list[int]) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Same infinite word with the shortest prefix and a primitive cycle."""
    prefix, cycle = list(prefix), list(cycle)
    m = len(cycle)
    for p in range(1, m + 1):
        if m % p == 0 and cycle[:p] * (m // p) == cycle:
            cycle = cycle[:p]
            break
    while prefix and prefix[-1] == cycle[-1]:
        cycle = [prefix.pop(), *cycle[:-1]]
    return tuple(prefix), tuple(cycle)


def task_automaton(spec: Specification, backend: str = "auto") -> Automaton:
    """The automaton of the full specification (user formula and always-on conjuncts),
    built within :data:`~ltl_human_motion.ltl.limits.MAX_TRANSLATION_SECONDS` (a
    SpecError beyond)."""
    with translation_budget():
        return translate(spec.formula, backend=backend)


def _graph_for(formula: Formula, spec: Specification, backend: str,
               allow_empty: bool) -> _LetterGraph:
    return _LetterGraph(translate(formula, backend=backend), spec.letters, allow_empty)


def unsat_core(spec: Specification, backend: str = "auto",
               allow_empty: bool = True, limit: int = 16) -> list[str]:
    """A minimal set of labelled conjuncts that admits no task sequence (deletion-based).

    Returns all conjunct labels if there are more than ``limit`` of them. Within
    :data:`~ltl_human_motion.ltl.limits.MAX_TRANSLATION_SECONDS` (a SpecError beyond).
    """
    with translation_budget():
        return _unsat_core(spec, backend, allow_empty, limit)


def _unsat_core(spec: Specification, backend: str, allow_empty: bool, limit: int
                ) -> list[str]:
    parts = spec.labelled_conjuncts()
    if len(parts) > limit:
        return [label for label, _ in parts]
    keep = list(parts)
    for item in list(parts):
        trial = [p for p in keep if p is not item]
        graph = _graph_for(conj(*(f for _, f in trial)), spec, backend, allow_empty)
        if not graph.nonempty():
            keep = trial
    return [label for label, _ in keep]


def _raise_unsat(spec: Specification, backend: str) -> None:
    aut = translate(spec.formula, backend=backend)
    core = unsat_core(spec, backend)
    reason = ("is unsatisfiable" if aut.is_empty() else
              "admits no sequence of task steps " +
              "(candidate steps: " + ", ".join(map(str, spec.tasks)) + ")")
    listed = "\n  ".join(core)
    raise SpecError(f"specification '{spec.text}' {reason}; these conjuncts conflict:\n"
                    f"  {listed}", text=spec.text)


class _Synth:
    def __init__(self, spec: Specification, graph: _LetterGraph, cycles: int,
                 min_steps: int, strict: bool = True) -> None:
        self.spec = spec
        self.strict = strict
        self.graph = graph
        self.cycles = cycles
        self.min_steps = min_steps
        self.out: list[TaskSequence] = []
        self.seen: set[tuple[tuple[int, ...], tuple[int, ...]]] = set()

    def add(self, prefix: list[_Arc], cycle: list[_Arc]) -> bool:
        """Turn a lasso of arcs into a checked TaskSequence; False if a duplicate."""
        return self.add_letters([a.letter for a in prefix], [a.letter for a in cycle])

    def add_letters(self, prefix: Sequence[int], cycle: Sequence[int],
                    pending: list[int] | None = None) -> bool:
        """:meth:`add` for letter indices (-1 = empty letter).

        With ``pending``, a lasso whose check can only confirm it (no empty step dropped,
        automaton made from the specification) is added unchecked and its position in
        ``out`` is recorded in ``pending``; the caller checks the ones it emits
        (:meth:`check`).
        """
        pre = [x for x in prefix if x >= 0]
        cyc = [x for x in cycle if x >= 0]
        dropped = len(pre) + len(cyc) != len(prefix) + len(cycle)
        if not cyc:
            return False
        key = _canonical(pre, cyc)
        if key in self.seen:
            return False
        if pending is not None and not dropped and self.strict:
            pending.append(len(self.out))
        elif not self._satisfies(key):
            if dropped or not self.strict:
                # the word without its empty steps (or a run of an automaton given by the
                # caller) does not satisfy the full specification: not emitted
                return False
            self._fail(key)
        self.seen.add(key)
        tasks, letters = self.spec.tasks, self.spec.letters
        reps = self.cycles
        if self.min_steps:
            reps = max(reps, math.ceil((self.min_steps - len(key[0])) / len(key[1])))
        used = sorted(set(key[0]) | set(key[1]))
        self.out.append(TaskSequence(tuple(tasks[i] for i in key[0]),
                                     tuple(tasks[i] for i in key[1]), reps,
                                     tuple((tasks[i], letters[i]) for i in used)))
        return True

    def _satisfies(self, key: tuple[tuple[int, ...], tuple[int, ...]]) -> bool:
        letters = self.spec.letters
        return evaluate_lasso(self.spec.formula, [letters[i] for i in key[0]],
                              [letters[i] for i in key[1]])

    def _fail(self, key: tuple[tuple[int, ...], tuple[int, ...]]) -> None:
        raise VerificationError(
            f"internal error: lasso {key} of '{self.spec.text}' is accepted by the "
            "automaton but violates the specification", check="ltl")

    def check(self, seq: TaskSequence) -> None:
        """Check an unchecked sequence of :meth:`add_letters` with the evaluator."""
        index = {t: i for i, t in enumerate(self.spec.tasks)}
        key = (tuple(index[t] for t in seq.prefix), tuple(index[t] for t in seq.cycle))
        if not self._satisfies(key):
            self._fail(key)

    # ----------------------------------------------------------------- modes
    def lasso_through(self, arc: _Arc) -> tuple[list[_Arc], list[_Arc]]:
        g = self.graph
        head = [*g.path(g.aut.initial, arc.src), arc]
        here = arc.dst
        tail = g.path(here, lambda a: g.in_good_scc(a.dst)) if not g.in_good_scc(here) else []
        if tail:
            here = tail[-1].dst
        return head + tail, g.accepting_cycle(here)

    def coverage(self, n: int | None) -> None:
        g = self.graph
        reach = g._reach([g.aut.initial], g.out)
        targets: dict[int, _Arc] = {}
        for q in sorted(reach):
            for a in g.out[q]:
                targets.setdefault(a.edge, a)
        covered: set[int] = set()
        for edge in sorted(targets):
            if edge in covered:
                continue
            prefix, cycle = self.lasso_through(targets[edge])
            covered.update(a.edge for a in prefix + cycle)
            self.add(prefix, cycle)
            if n is not None and len(self.out) >= n:
                return

    def random(self, n: int, seed: int, max_length: int) -> None:
        g = self.graph
        rng = random.Random(seed)
        for _ in range(max(50 * n, 200)):
            if len(self.out) >= n:
                return
            here, prefix = g.aut.initial, []
            for _ in range(rng.randint(0, max_length)):
                prefix.append(rng.choice(g.out[here]))
                here = prefix[-1].dst
            if not g.in_good_scc(here):
                tail = g.path(here, lambda a: g.in_good_scc(a.dst))
                prefix += tail
                here = tail[-1].dst
            self.add(prefix, g.accepting_cycle(here, rng))

    def all(self, n: int | None, max_length: int) -> None:
        """All lassos of ``1..max_length`` arcs, by length, then letters, then prefix length.

        Same result as a depth-first enumeration of every path from the initial state
        (stopped after ``_WORK_LIMIT`` path nodes), but computed from the distinct letter
        words of prefixes and of accepting cycles (:class:`_LassoWords`); only the
        sequences that are returned are checked with the evaluator.
        """
        g = self.graph
        words = _LassoWords(g)
        pending: list[int] = []
        work = 0
        for length in range(1, max_length + 1):
            nodes = words.path_count(length)
            if work + nodes > _WORK_LIMIT:  # the work limit cuts this length short
                found = _dfs_lassos(g, length, _WORK_LIMIT - work)
                work = _WORK_LIMIT
            else:
                found = words.lassos(length)
                work += nodes
            for prefix, cycle in found:
                self.add_letters(prefix, cycle, pending)
            if work >= _WORK_LIMIT or (n is not None and len(self.out) >= n):
                break
        unchecked = {id(self.out[i]) for i in pending}
        self.out.sort(key=lambda s: (len(s.prefix) + len(s.cycle), list(map(str, s.tasks))))
        if n is not None:
            del self.out[n:]
        for seq in self.out:
            if id(seq) in unchecked:
                self.check(seq)


_Lasso = tuple[tuple[int, ...], tuple[int, ...]]


def _dfs_lassos(g: _LetterGraph, length: int, budget: int) -> list[_Lasso]:
    """Lassos of ``length`` arcs found by a depth-first search of at most ``budget`` path
    nodes, sorted by letters and prefix length."""
    found: list[tuple[list[_Arc], list[_Arc]]] = []
    stack: list[tuple[list[_Arc], list[int]]] = [([], [g.aut.initial])]
    work = 0
    while stack and work < budget:
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
    out = sorted({(tuple(a.letter for a in p + c), len(p)) for p, c in found})
    return [(w[:j], w[j:]) for w, j in out]


class _LassoWords:
    """Letter words of the lassos of a letter graph, by length.

    A lasso of ``L`` arcs with a prefix of ``j`` arcs is a path of ``j`` arcs from the
    initial state to a state ``s`` and a cycle of ``L - j`` arcs from ``s`` back to ``s``
    whose arcs carry every mark. Prefix words are kept per state and length; cycle words
    are found by a search that only enters states that can still return to ``s`` in the
    remaining number of arcs.
    """

    def __init__(self, g: _LetterGraph) -> None:
        self.g = g
        n = g.aut.num_states
        self.full = (1 << g.aut.num_sets) - 1
        moves: list[set[tuple[int, int, int]]] = [set() for _ in range(n)]
        for q in range(n):
            for a in g.out[q]:
                moves[q].add((a.letter, a.dst, sum(1 << m for m in a.acc)))
        self.moves = [sorted(m) for m in moves]
        self.prefix_words: list[dict[int, set[tuple[int, ...]]]] = [{g.aut.initial: {()}}]
        self.back: dict[int, list[set[int]]] = {}
        self.cycle_words: dict[tuple[int, int], set[tuple[int, ...]]] = {}
        self.paths: list[int] = [1]        # paths with t arcs from the initial state
        self.ends: dict[int, int] = {g.aut.initial: 1}

    def path_count(self, length: int) -> int:
        """Nodes of a depth-first enumeration of all paths of at most ``length`` arcs."""
        while len(self.paths) <= length:
            ends: dict[int, int] = {}
            for q, c in self.ends.items():
                for a in self.g.out[q]:
                    ends[a.dst] = ends.get(a.dst, 0) + c
            self.ends = ends
            self.paths.append(sum(ends.values()))
        return sum(self.paths[:length + 1])

    def _prefixes(self, j: int) -> dict[int, set[tuple[int, ...]]]:
        while len(self.prefix_words) <= j:
            last = self.prefix_words[-1]
            layer: dict[int, set[tuple[int, ...]]] = {}
            for q, ws in last.items():
                for letter, dst, _ in self.moves[q]:
                    target = layer.setdefault(dst, set())
                    for w in ws:
                        target.add((*w, letter))
            self.prefix_words.append(layer)
        return self.prefix_words[j]

    def _returning(self, s: int, k: int) -> set[int]:
        """States with a path of exactly ``k`` arcs to ``s``."""
        levels = self.back.setdefault(s, [{s}])
        while len(levels) <= k:
            prev = levels[-1]
            levels.append({q for q in range(len(self.moves))
                           if any(dst in prev for _, dst, _ in self.moves[q])})
        return levels[k]

    def _cycles(self, s: int, k: int) -> set[tuple[int, ...]]:
        """Words of the cycles of ``k`` arcs from ``s`` to ``s`` that carry every mark."""
        key = (s, k)
        if not self.g.in_good_scc(s):  # no cycle through s carries every mark
            return set()
        if key not in self.cycle_words:
            layer: set[tuple[int, int, tuple[int, ...]]] = {(s, 0, ())}
            for left in range(k - 1, -1, -1):
                ok = self._returning(s, left)
                layer = {(dst, marks | acc, (*w, letter)) for q, marks, w in layer
                         for letter, dst, acc in self.moves[q] if dst in ok}
            self.cycle_words[key] = {w for q, marks, w in layer if marks == self.full}
        return self.cycle_words[key]

    def lassos(self, length: int) -> list[_Lasso]:
        """Distinct (prefix word, cycle word) of ``length`` letters, sorted by the whole
        word and then by the prefix length."""
        out: set[tuple[tuple[int, ...], int]] = set()
        for j in range(length):
            for s, prefixes in self._prefixes(j).items():
                cycles = self._cycles(s, length - j)
                for c in cycles:
                    for p in prefixes:
                        out.add(((*p, *c), j))
        return [(w[:j], w[j:]) for w, j in sorted(out)]


def synthesize_sequences(spec: str | Specification, cell: object = None, n: int | None = 5,
                         seed: int = 0, mode: str = "random", cycles: int = 1, *,
                         min_steps: int = 0, backend: str = "auto",
                         max_length: int | None = None, free_atoms: bool = False,
                         automaton: Automaton | None = None) -> list[TaskSequence]:
    """Task sequences satisfying ``spec`` (with the always-on conjuncts).

    Parameters
    ----------
    spec : str or Specification
        Specification text (or a name of ``PAPER_SPECS``, e.g. "S1").
    cell : CellVocabulary, dict, path or None
    n : int or None
        Maximum number of sequences; None with ``mode="coverage"`` or ``"all"`` returns
        the full coverage set / all sequences up to ``max_length``.
    seed : int
        Seed of ``mode="random"``; the same seed gives the same output.
    mode : {"random", "coverage", "all"}
    cycles : int
        Passes through the accepting cycle (>= 1).
    min_steps : int
        Repeat the cycle until the sequence has at least this many steps.
    backend : {"auto", "builtin", "spot"}
    max_length : int, optional
        Bound on prefix + cycle letters for "all" and on random prefixes
        (default: twice the number of automaton states, at least 6).
    free_atoms : bool
        Accept plain propositions (see :func:`~ltl_human_motion.ltl.parser.parse`).
    automaton : Automaton, optional
        Use this automaton (e.g. read from Spot's ``ltl2tgba`` output with
        :func:`~ltl_human_motion.ltl.hoa.automaton_from_hoa`; its propositions are atom
        keys such as ``grasp(O1)``) instead of translating ``spec``. Its lassos that
        violate the full specification are not emitted.

    Returns
    -------
    list of TaskSequence
        Each one checked with :func:`~ltl_human_motion.ltl.evaluator.evaluate_lasso`.

    Raises
    ------
    SpecError
        Malformed, ill-typed or unsatisfiable specification (naming conflicting conjuncts),
        or one whose automaton takes longer than
        :data:`~ltl_human_motion.ltl.limits.MAX_TRANSLATION_SECONDS` to build.
    ValueError
        Bad ``mode``, ``n``, ``cycles``.
    """
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if n is not None and n < 1:
        raise ValueError(f"n must be >= 1 (or None), got {n}")
    if cycles < 1:
        raise ValueError(f"cycles must be >= 1, got {cycles}")
    if mode == "random" and n is None:
        raise ValueError("mode='random' needs a number of sequences n")
    if not isinstance(spec, Specification):
        spec = build_specification(spec, cell, free_atoms=free_atoms)
    with translation_budget():
        return _synthesize(spec, n, seed, mode, cycles, min_steps, backend, max_length,
                           automaton)


def _synthesize(spec: Specification, n: int | None, seed: int, mode: str, cycles: int,
                min_steps: int, backend: str, max_length: int | None,
                automaton: Automaton | None) -> list[TaskSequence]:
    aut = automaton if automaton is not None else task_automaton(spec, backend)
    graph = _LetterGraph(aut, spec.letters, allow_empty=False)
    if not graph.nonempty():
        graph = _LetterGraph(aut, spec.letters, allow_empty=True)
        if not graph.nonempty():
            _raise_unsat(spec, backend)
    bound = max_length if max_length is not None else max(6, 2 * aut.num_states)
    synth = _Synth(spec, graph, cycles, min_steps, strict=automaton is None)
    if mode == "coverage":
        synth.coverage(n)
    elif mode == "all":
        synth.all(n, bound)
    else:
        synth.random(n, seed, bound)
    if not synth.out and automaton is not None:
        raise SpecError(f"no lasso of the given automaton ({aut.name or 'unnamed'}) "
                        f"satisfies the specification '{spec.text}' with its always-on "
                        "conjuncts", text=spec.text)
    if not synth.out:
        raise SpecError(f"specification '{spec.text}' has accepting runs only through steps "
                        "without a task, and dropping them violates it; add a task such as "
                        "wait(1.0) to the specification", text=spec.text)
    return synth.out
