"""The product of a specification automaton with the cell model, searched on the fly.

A product node is ``(automaton state, cell state)``; an edge does one task step: the
automaton reads the task's letter and the cell model (:class:`~.model.CellModel`) does
the task, at its cost (the cost model's seconds). Nothing is built in full: nodes are
made when the search reaches them.

A task sequence is a lasso ``prefix . cycle`` whose infinite word ``prefix cycle^w``
the automaton accepts. As in the paper, the worker performs ``prefix`` and the cycle
``repetitions`` times, and that finite motion must pass the acceptance condition at
least once: prefix plus the first pass of the cycle (:meth:`ProductSearch.witnessed`),
not only a later pass of the infinite word. The cycle must be physically possible from
where the prefix ends (and again for each repetition); the cell need not return to its
state. The search (A*, or Dijkstra without a heuristic) pops prefixes in order of cost;
a prefix ends in a goal when

* its last steps (up to :data:`TAIL_STEPS`) ran as an accepting cycle of the
  automaton (back to the same state with every mark), or its automaton state owes
  nothing and repeating those steps forever is accepted (``F a`` ends right after the
  ``a``), or those steps passed every mark into a state that can lie on an accepting
  cycle, from which repeating them is accepted (S1 ends after ``grasp, assemble``:
  the tableau's initial state still holds the first ``grasp``, so the pass ends in the
  accepting component rather than where it began; a pass ending in ``sit`` with
  ``X wait`` still owed ends outside it and is no goal),
  or, only when no such lasso exists, from its
  node a longer cycle of the automaton back to the same state with every mark is
  possible in the cell (a second Dijkstra over ``(state, cell, marks)``, only from
  states that can lie on an accepting cycle, :meth:`LetterTableau.loopable`).

Goals enter the same queue at the cost of prefix plus cycle, so the first goal popped is
the cost-optimal lasso (with an admissible heuristic and weight 1). Nodes may be popped
up to ``k`` times, which gives the ``k`` cheapest lassos (k shortest walks).

:func:`product_search` sets a search up for a specification over the candidate steps of
:func:`task_steps`; the sequences (:mod:`~.sequences`) and the explanations
(:mod:`~.explain`) both start from it.
"""

from __future__ import annotations

import heapq
import itertools
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ltl_human_motion.ltl.automaton import Automaton, accepting_components, lasso_accepted
from ltl_human_motion.ltl.automaton import strongly_connected_components as _sccs
from ltl_human_motion.ltl.evaluator import propositional_letters
from ltl_human_motion.ltl.formula import Atom, Finally, Formula, Globally, Or, conj
from ltl_human_motion.ltl.onthefly import LetterTableau
from ltl_human_motion.ltl.spec import Specification, letter_of
from ltl_human_motion.ltl.translate import resolve_backend, translate
from ltl_human_motion.tasks.model import DONE, HELD, CellModel, CellState
from ltl_human_motion.tasks.recurrence import cycle_steps

__all__ = ["ExplicitView", "Lasso", "ProductSearch", "SearchBudgetError", "product_search",
           "seeded_noise", "task_steps"]


#: Longest cycle made of a path's own last steps that the search tries as a goal.
TAIL_STEPS = 6

#: Children are pushed with a bound derived from their parent's heuristic and get
#: their own only when popped (most never are); False evaluates every child at once.
LAZY_HEURISTIC = True

#: Decimals (of seconds) of the search's priorities (:func:`_key`).
KEY_DIGITS = 9

#: Tasks that leave a hand free (the part is put down, placed or used up).
_FREEING = frozenset({"release", "move", "insert", "assemble"})

#: Tasks that take a part somewhere in hand (fetching it first if needed).
_CARRYING = frozenset({"move", "insert", "carry"})

#: Of those, the tasks that set the part down there (the hand is free after them).
_SETTING_DOWN = frozenset({"move", "insert"})


class SearchBudgetError(RuntimeError):
    """The product search expanded more nodes than its budget allowed."""


class ExplicitView:
    """An explicit :class:`Automaton` (e.g. Spot's) read over the task letters.

    Offers the interface of :class:`~ltl_human_motion.ltl.onthefly.LetterTableau` that
    the search uses: ``initial``, ``full``, ``successors(q, i)``, ``loopable(q)``.
    """

    def __init__(self, aut: Automaton, letters: Sequence[frozenset[str]]) -> None:
        self.aut = aut
        self.letters = tuple(letters)
        self.initial = aut.initial
        self.full = (1 << aut.num_sets) - 1
        self._succ: dict[tuple[int, int], tuple[tuple[int, int], ...]] = {}
        adj = [[(d, frozenset(m)) for i in range(len(self.letters))
                for d, m in self._edges(q, i)] for q in aut.states]
        comp = _sccs(adj)
        good = accepting_components(adj, aut.num_sets)
        self._loop = [comp[q] in good for q in aut.states]
        self._sink: dict[int, bool] = {}

    def _edges(self, q: int, i: int) -> list[tuple[int, list[int]]]:
        return [(e.dst, sorted(e.acc)) for e in self.aut.successors(q)
                if e.guard.satisfied_by(self.letters[i])]

    def successors(self, q: int, i: int) -> tuple[tuple[int, int], ...]:
        """``(state, marks as bits)`` of the edges leaving ``q`` on letter ``i``."""
        key = (q, i)
        hit = self._succ.get(key)
        if hit is None:
            hit = tuple(sorted({(d, sum(1 << m for m in acc)) for d, acc in self._edges(q, i)}))
            self._succ[key] = hit
        return hit

    def loopable(self, q: int) -> bool:
        """Whether ``q`` lies in an accepting strongly connected component."""
        return self._loop[q]

    def pending(self, q: int) -> list[Formula]:
        """No formula view of an explicit automaton: no heuristic."""
        return []

    def sink(self, q: int) -> bool:
        """Whether ``q`` loops to itself on every letter with every mark (it accepts
        every continuation: reaching it passes the acceptance condition)."""
        hit = self._sink.get(q)
        if hit is None:
            hit = self._sink[q] = all((q, self.full) in self.successors(q, i)
                                      for i in range(len(self.letters)))
        return hit


@dataclass(frozen=True)
class Lasso:
    """A lasso of task indices with its cost (the cost model's seconds).

    Attributes
    ----------
    prefix, cycle : tuple of int
        Indices into the search's task list; ``cycle`` is non-empty.
    cost : float
        Estimated seconds of ``prefix`` and the repetitions of ``cycle``.
    searched_cycle : bool
        The cycle was found by a cycle search after the prefix (not its last step).
    """

    prefix: tuple[int, ...]
    cycle: tuple[int, ...]
    cost: float
    searched_cycle: bool = False


class ProductSearch:
    """Searches the product of ``automaton`` and ``model`` for cheap accepting lassos.

    Parameters
    ----------
    automaton : LetterTableau or ExplicitView
        Over the letters of ``tasks`` (same order).
    model : CellModel
    tasks : sequence of Atom
        The candidate task steps.
    repetitions : int
        How often the cycle is performed; above 1 the cycle must be possible again
        from where it ends.
    weight : float
        A* weight (1: optimal with the admissible heuristic; larger: faster, at most
        ``weight`` times the optimum).
    budget : int
        Most prefix nodes expanded before :class:`SearchBudgetError`.
    cost_noise : callable, optional
        ``(node, task index) -> factor >= 1`` on step costs (seeded random variations).
    """

    def __init__(self, automaton, model: CellModel, tasks: Sequence[Atom],
                 repetitions: int = 1, weight: float = 1.0, budget: int = 200_000,
                 cost_noise: Callable[[tuple, int], float] | None = None,
                 heuristic: bool = True) -> None:
        self.aut = automaton
        self.model = model
        self.tasks = tuple(tasks)
        self.repetitions = repetitions
        self.weight = weight
        self.budget = budget
        self.noise = cost_noise
        self.use_h = heuristic and weight > 0
        self.expanded = 0
        self._step: dict[tuple[CellState, int], tuple[CellState, float] | None] = {}
        self._cycles: dict[tuple[int, CellState], tuple[float, tuple[int, ...]] | None] = {}
        letters = getattr(automaton, "letters", None)
        self._letters = tuple(letters) if letters is not None else ()
        self._min_dur = [self._duration(t) for t in self.tasks]
        self._kind = [model.kind(t)[0] for t in self.tasks]
        free = [d for d, k in zip(self._min_dur, self._kind) if k in _FREEING]
        self._free_dur = min(free) if free else None
        self._grasp_dur = float(model.durations.get("grasp", 0.0))
        self._walk = model.walk_time.tolist()
        self._h: dict[tuple[int, CellState], float] = {}
        self._qneeds: dict[int, tuple[float, int, list[tuple]]] = {}
        self._fneeds: dict[Formula, tuple] = {}
        self._rules: dict[Formula, tuple | None] = {}
        self._need_sets: dict[Formula, frozenset[int]] = {}
        self._trees: dict[frozenset[int], float] = {}
        self._tgt = [self._static_target(t) for t in self.tasks]
        # the trip bound holds when every candidate step that frees a hand ends at a fixed
        # place (move, insert into a fixed container, assemble) and none is a release
        freeing = [self._tgt[i] for i, k in enumerate(self._kind) if k in _FREEING]
        self._dests = sorted({v for _k, v in freeing}) if freeing and all(
            k == 0 and v is not None for k, v in freeing) and "release" not in self._kind \
            else []
        self._near_place: list[float] = []      # per place, made on the first trip bound
        self._dest_dist: list[float] = []
        self._forget = hasattr(automaton, "mentioned")
        self._drop: dict[int, tuple[int, ...]] = {}
        self._tails: dict[tuple[int, tuple[int, ...]], bool] = {}
        #: Longest tail of a path tried as its cycle (a specification whose cycles must
        #: be longer sets more, :func:`~ltl_human_motion.tasks.recurrence.cycle_steps`).
        self.tail_steps = TAIL_STEPS

    def configure(self, weight: float, budget: int,
                  cost_noise: Callable[[tuple, int], float] | None = None) -> ProductSearch:
        """The same search (automaton, memoized steps, heuristic values and cycles, which
        depend on neither) with another weight, budget and cost noise; ``expanded``
        restarts at 0. A weight ladder reuses one search instead of translating again."""
        self.weight = weight
        self.budget = budget
        self.noise = cost_noise
        self.expanded = 0
        return self

    def _duration(self, task: Atom) -> float:
        kind, args = self.model.kind(task)
        if kind == "wait":
            return float(args[0]) if args else 0.0
        return float(self.model.durations.get(kind, 0.0))

    # ---------------------------------------------------------------- pieces
    def step(self, s: CellState, i: int) -> tuple[CellState, float] | None:
        """The cell model's step (memoized)."""
        key = (s, i)
        if key not in self._step:
            self._step[key] = self.model.step(s, self.tasks[i])
        return self._step[key]

    def forget(self, q: int, s: CellState) -> CellState:
        """``s`` without the places of parts that state ``q`` no longer mentions (as
        :meth:`CellModel.forget`, with the parts to drop memoized per state ``q``)."""
        if not self._forget:
            return s
        drop = self._drop.get(q)
        if drop is None:
            keep = self.aut.mentioned(q)
            drop = self._drop[q] = tuple(p for p, name in enumerate(self.model.part_names)
                                         if name not in keep)
        parts = s.parts
        if all(parts[p] in (HELD, DONE) for p in drop):
            return s
        new = list(parts)
        for p in drop:
            if new[p] != HELD:
                new[p] = DONE
        return CellState(s.location, s.held, tuple(new), s.posture)

    def _cost(self, node: tuple, i: int, c: float) -> float:
        return c * self.noise(node, i) if self.noise is not None else c

    def heuristic(self, q: int, s: CellState) -> float:
        """A lower bound on the time still needed (admissible):

        * the durations of the tasks the pending ``F`` formulas of ``q`` need, counted
          once per disjoint set of letters;
        * the walk through their places: to the nearest, then a minimum spanning tree
          over the places of the formulas with one place (a walk visiting them all is at
          least as long), or the walk to the farthest other one;
        * at least the distance each part still to be moved, inserted or carried travels
          in hand, over the number of hands (at most that many parts ride along at once);
        * the walk of the trips that fetch the parts still to be moved or inserted and set
          them down (:meth:`_trips`), when no step but those frees a hand;
        * the grasp that fetches such a part when it is not in hand;
        * the hand-freeing steps that two hands force: parts in hand plus parts still to
          be picked up (grasped, or fetched by a move that keeps them in hand), minus the
          hands, minus the pending formulas that free a hand;
        * pending formulas include the responses ``F psi`` of ``G(phi -> F psi)`` whose
          trigger a pending formula will fire (:meth:`_responses`).
        """
        if not self.use_h:
            return 0.0
        key = (q, s)
        hit = self._h.get(key)
        if hit is not None:
            return hit
        base, freeing, needs = self._needs(q)
        total, far = base, 0.0
        carried: list[float] = []
        walk = self._walk
        here = s.location
        places: set[int] = set()
        pickups: set[int] = set()
        parts = s.parts
        grasping = {item[3] for item in needs}
        delivered: list[int] = []
        for opts, carry_part, carry_dest, grasp_part, sets_down in needs:
            if carry_part is not None:
                where = parts[carry_part]
                if where >= 0:
                    if carry_part not in grasping:   # else its grasp is counted already
                        total += self._grasp_dur
                    places.add(where)
                    carried.append(walk[where][carry_dest])
                    if sets_down:
                        delivered.append(carry_part)
                elif where == HELD:
                    carried.append(walk[here][carry_dest])
            if len(opts) == 1:
                t = self._target(opts[0], s)
                if t is not None:
                    places.add(t)
            else:
                targets = {self._target(i, s) for i in opts}
                if None in targets:
                    pass
                elif len(targets) == 1:
                    places.update(targets)
                else:
                    far = max(far, min(walk[here][t] for t in targets))
            if grasp_part is not None and grasp_part not in s.held:
                pickups.add(grasp_part)
            if carry_part is not None and parts[carry_part] >= 0:
                pickups.add(carry_part)       # fetched into a hand first
        hands = self.model.limits.hands
        carry = sum(carried) / hands
        trips = self._trips(s, delivered) if self._dests and delivered else 0.0
        total += max(far, self._tree(here, places), carry, trips)
        to_grasp = sum(self.model._width[p] for p in pickups)
        if self._free_dur is not None:
            held = sum(self.model._width[p] for p in s.held)
            total += max(0, held + to_grasp - self.model.limits.hands - freeing) \
                * self._free_dur
        self._h[key] = total
        return total

    def _trips(self, s: CellState, delivered: list[int]) -> float:
        """A lower bound (s) on the walk that picks up the parts ``delivered`` (each at its
        place, not in hand) and sets them down by a ``move`` or ``insert``, with the
        candidate steps' only hand-freeing steps ending at :attr:`_dests` (no release).

        Between two hand-freeing steps at most ``hands`` parts are picked up, so the
        pickups fall into at least ``T = ceil(m / hands)`` groups. Each pickup is reached
        by its own stretch of walk: the first of a group from a freeing place (the first
        group: from the worker's place or a freeing place), any other from the nearest
        other place (0 when another part lies there); the last pickup of each group walks
        on to a freeing place. The stretches are disjoint, so their least sum, with the
        roles given to the parts that make it least, is a lower bound. With two hands a
        group is one part or two, so every part pays its way from or to a freeing place,
        the second of a pair the nearest-place stretch too (a pair costs less than two
        single trips); with more hands the roles may overlap in the bound."""
        if not self._near_place:
            walk = self._walk
            n_pts = len(walk)
            self._near_place = [min((walk[j][x] for j in range(n_pts) if j != x),
                                    default=0.0) for x in range(n_pts)]
            self._dest_dist = [min(walk[d][x] for d in self._dests) for x in range(n_pts)]
        parts = s.parts
        row = self._walk[s.location]
        near, to_dest = self._near_place, self._dest_dist
        hands = self.model.limits.hands
        nears: list[float] = []       # the nearest-place stretch of each part
        ends: list[float] = []        # its stretch from or to a freeing place
        starts: list[float] = []      # its stretch from the worker's place, at most that
        for p in delivered:
            x = parts[p]
            # at most its end stretch, so that a pair never costs more than two singles
            nears.append(0.0 if parts.count(x) > 1 else min(near[x], to_dest[x]))
            ends.append(to_dest[x])
            starts.append(min(row[x], to_dest[x]))
        m = len(delivered)
        if hands == 2:
            # every part: its end stretch; the second of each pair: its near stretch; a
            # single trip: a second end stretch; less what starting from here saves
            saved = max(t - w for t, w in zip(ends, starts))
            return max(0.0, sum(ends) + sum(sorted(nears)[:m // 2])
                       + (min(ends) if m % 2 else 0.0) - saved)
        groups = -(-m // hands)
        firsts = sorted(t - nb for t, nb in zip(ends, nears))
        start = min(w - nb for w, nb in zip(starts, nears))
        return max(0.0, sum(nears) + start + sum(firsts[:groups - 1])
                   + sum(sorted(ends)[:groups]))

    def _target(self, i: int, s: CellState) -> int | None:
        """Where task ``i`` ends in ``s`` (fast path of :meth:`CellModel.target`)."""
        kind, value = self._tgt[i]
        if kind == 0:
            return value
        if kind == 1:
            where = s.parts[value]
            if where >= 0:
                return where
            if where == HELD:
                return s.location
        return self.model.target(self.tasks[i], s)

    def _needs(self, q: int) -> tuple[float, int, list[tuple]]:
        """Per automaton state: the durations of its pending ``F`` formulas (once per
        disjoint letter set), how many of them free a hand, and per formula (letters,
        part carried, its destination, part to grasp)."""
        hit = self._qneeds.get(q)
        if hit is not None:
            return hit
        base, freeing, needs = 0.0, 0, []
        used: set[int] = set()
        pending = list(self.aut.pending(q))
        have = set(pending)                 # (list membership compares formulas deeply)
        for f in self._responses(q, pending):
            if f not in have:
                have.add(f)
                pending.append(f)
        for f in pending:
            need, dur, frees, item = self._formula_need(f)
            if not need:
                continue
            if used.isdisjoint(need):
                base += dur
                used.update(need)
            freeing += frees
            needs.append(item)
        hit = self._qneeds[q] = (base, freeing, needs)
        return hit

    def _responses(self, q: int, pending: list[Formula]) -> list[Formula]:
        """``F psi`` of every ``G(!phi | F psi)`` of ``q`` whose trigger ``phi`` a pending
        ``F chi`` will make true (every letter of ``chi`` satisfies ``phi``): psi is
        needed after that step, so it counts too."""
        out = []
        states = getattr(self.aut, "states", None)
        if states is None:
            return out
        needs = [n for f in pending if (n := self._need_set(f))]
        singles = {next(iter(n)) for n in needs if len(n) == 1}
        multi = [n for n in needs if len(n) > 1]
        for g in states[q]:
            rule = self._rules.get(g, ())
            if rule == ():
                rule = self._rules[g] = self._response_rule(g)
            if rule is not None and (not rule[0].isdisjoint(singles)
                                     or any(n <= rule[0] for n in multi)):
                out.append(rule[1])
        return out

    def _need_set(self, f: Formula) -> frozenset[int]:
        """The letters satisfying the pending ``F phi`` as a set (memoized)."""
        hit = self._need_sets.get(f)
        if hit is None:
            hit = self._need_sets[f] = frozenset(self._formula_need(f)[0])
        return hit

    def _response_rule(self, g: Formula) -> tuple[frozenset[int], Formula] | None:
        """(trigger letters, ``F psi``) of ``g = G(a | b | ... | F psi)`` with a, b, ...
        propositional (the trigger: the letters on which they are all false)."""
        if not isinstance(g, Globally) or not isinstance(g.arg, Or):
            return None
        eventual = [a for a in g.arg.args if isinstance(a, Finally)]
        rest = [a for a in g.arg.args if not isinstance(a, Finally)]
        if len(eventual) != 1 or not rest:
            return None
        holds = propositional_letters(Or(tuple(rest)) if len(rest) > 1 else rest[0],
                                       self._letters)
        if holds is None:
            return None
        trigger = frozenset(range(len(self._letters))) - frozenset(holds)
        return trigger, eventual[0]

    def _formula_need(self, f: Formula) -> tuple:
        """What the pending ``F phi`` needs: (letters satisfying phi, least duration,
        whether all of them free a hand, (letters, part carried, destination, part to
        grasp))."""
        hit = self._fneeds.get(f)
        if hit is not None:
            return hit
        need = propositional_letters(f.arg, self._letters)
        if not need:
            self._fneeds[f] = ((), 0.0, False, None)
            return self._fneeds[f]
        kinds = {self._kind[i] for i in need}
        carry_part = carry_dest = grasp_part = None
        if len(need) == 1 and self._kind[need[0]] in _CARRYING and self._tgt[need[0]][0] == 0:
            carry_part = self.model.part_index.get(self.tasks[need[0]].args[0])
            carry_dest = self._tgt[need[0]][1]
        heads = {self.tasks[i].args[0] for i in need} if kinds == {"grasp"} else ()
        if len(heads) == 1:
            grasp_part = self.model.part_index.get(next(iter(heads)))
        sets_down = carry_part is not None and self._kind[need[0]] in _SETTING_DOWN
        hit = self._fneeds[f] = (need, min(self._min_dur[i] for i in need),
                                 kinds <= _FREEING,
                                 (need, carry_part, carry_dest, grasp_part, sets_down))
        return hit

    def _static_target(self, task: Atom) -> tuple[int, int | None]:
        """(0, location) for a task ending at a fixed place, (1, part) for one ending where
        a part lies (grasp, sit), (2, None) otherwise."""
        kind, args = self.model.kind(task)
        if kind in ("walk", "carry", "leftHand", "rightHand", "assemble", "shorthand", "move"):
            region = args[-1] if args else None
            if region in self.model.region_index:
                return 0, self.model.region_location(region)
            return 0, None
        if kind in ("grasp", "sit") and args[0] in self.model.part_index:
            return 1, self.model.part_index[args[0]]
        if kind in ("wait", "release", "standUp", "kneel", "bend", "stoop"):
            return 0, None
        if kind in ("insert", "extract") and args[1] in self.model.part_index:
            c = self.model.part_index[args[1]]
            if not self.model.movable[c]:
                return 0, self.model.supply(c)
        return 2, None

    def _tree(self, here: int, places: set[int]) -> float:
        """A lower bound (s) on a walk from ``here`` through all ``places``: the walk to
        the nearest of them plus a minimum spanning tree over them (Prim, memoized per
        set of places: the rest of the walk connects them all). At least the spanning
        tree over ``here`` and ``places``."""
        places.discard(here)
        if not places:
            return 0.0
        row = self._walk[here]
        return min(row[t] for t in places) + self._places_tree(frozenset(places))

    def _places_tree(self, key: frozenset[int]) -> float:
        """Length (s) of a minimum spanning tree over the places ``key`` (Prim)."""
        hit = self._trees.get(key)
        if hit is not None:
            return hit
        walk = self._walk
        rest = list(key)
        first = rest.pop()
        best = [walk[first][t] for t in rest]
        total = 0.0
        while rest:
            j = min(range(len(rest)), key=best.__getitem__)
            total += best[j]
            u = rest.pop(j)
            best.pop(j)
            row = walk[u]
            best = [min(b, row[t]) for b, t in zip(best, rest)]
        self._trees[key] = total
        return total

    def _again(self, s: CellState, cycle: Sequence[int], times: int | None = None
               ) -> float | None:
        """Cost (s) of doing the cycle ``times`` (default ``repetitions - 1``) more times
        from ``s``, or None when the cell does not allow it."""
        total = 0.0
        for _ in range(self.repetitions - 1 if times is None else times):
            for i in cycle:
                nxt = self.step(s, i)
                if nxt is None:
                    return None
                s, c = nxt
                total += c
        return total

    def cycle_from(self, q0: int, s0: CellState, limit: int = 20_000
                   ) -> tuple[float, tuple[int, ...]] | None:
        """The cheapest cycle of the automaton from ``q0`` back to ``q0`` with every mark,
        possible in the cell from ``s0``: (cost, task indices), or None."""
        key = (q0, s0)
        if key in self._cycles:
            return self._cycles[key]
        full = self.aut.full
        tie = itertools.count()
        heap: list = [(0.0, next(tie), q0, s0, 0, ())]
        done: set[tuple[int, CellState, int]] = set()
        result = None
        while heap and len(done) < limit:
            g, _, q, s, marks, path = heapq.heappop(heap)
            if path and q == q0 and marks == full:
                again = self._again(s, path)
                if again is not None:
                    result = (g + again, path)
                    break
                continue
            if (q, s, marks) in done:
                continue
            done.add((q, s, marks))
            for i in range(len(self.tasks)):
                nxt = self.step(s, i)
                if nxt is None:
                    continue
                for q2, m in self.aut.successors(q, i):
                    if not self.aut.loopable(q2):
                        continue
                    s2, c = self.forget(q2, nxt[0]), nxt[1]
                    m2 = marks | m
                    if (q2 == q0 and m2 == full) or (q2, s2, m2) not in done:
                        heapq.heappush(heap, (g + c, next(tie), q2, s2, m2, (*path, i)))
        self._cycles[key] = result
        return result

    # ---------------------------------------------------------------- search
    def lassos(self, k: int = 1, start: tuple[tuple[int, ...], int, CellState, float] | None = None,
               bound: float = float("inf"), long_cycles: bool = False) -> list[Lasso]:
        """Up to ``k`` cheapest lassos in order of cost (fewer if the product has fewer).

        ``start`` = (task indices done, automaton state, cell state, cost) starts the
        search after a given prefix (coverage mode). Nodes whose cost plus heuristic
        exceeds ``bound`` are not expanded (a known lasso's cost proves them useless).
        Cycles of up to :data:`TAIL_STEPS` steps are found as the tails of paths; only
        if there is no such lasso is the search repeated with ``long_cycles`` (a cycle
        search from every node that may lie on an accepting cycle).

        Raises
        ------
        SearchBudgetError
            When more than ``budget`` prefix nodes were expanded.
        """
        tie = itertools.count()
        # labels: (node, parent label, task index, g)
        labels: list[tuple[tuple[int, CellState], int, int, float]] = []
        heap: list = []
        if start is None:
            root = (self.aut.initial,
                    self.forget(self.aut.initial, self.model.initial_state()))
            base: tuple[int, ...] = ()
            g0 = 0.0
        else:
            base, q, s, g0 = start
            root = (q, self.forget(q, s))
        labels.append((root, -1, -1, g0, 0))
        depth = [0]        # steps of each label's path: fewer steps win a tie in cost
        heapq.heappush(heap, (_key(g0 + self.weight * self.heuristic(*root)), -_key(g0),
                              (0, next(tie)), 0, 0, ()))
        lazy = self.use_h and LAZY_HEURISTIC
        pops: dict[tuple[int, CellState], int] = {}
        closed_g: dict[tuple[int, CellState], float] = {}
        out: list[Lasso] = []
        while heap and len(out) < k:
            f, _, _, kind, lab, cycle = heapq.heappop(heap)
            node, _parent, task, g, _marks = labels[lab]
            if kind == 1:
                prefix = base + self._path(labels, lab)
                if isinstance(cycle, int):
                    out.append(Lasso(prefix[:-cycle], prefix[-cycle:], f))
                else:
                    out.append(Lasso(prefix, cycle, f, searched_cycle=True))
                continue
            count = pops.get(node, 0)
            if count >= k and (k > 1 or g >= closed_g[node] - 1e-9):
                continue  # (k = 1: a cheaper path reopens it; the heuristic is admissible
                #           but not always consistent)
            if kind == 2:  # pushed with a lower bound of its heuristic: now the real one
                h = self.heuristic(*node)
                if g + h > bound:
                    continue
                if g + self.weight * h > f + 1e-9:
                    heapq.heappush(heap, (_key(g + self.weight * h), -_key(g),
                                          (depth[lab], next(tie)), 0, lab, ()))
                    continue
            pops[node] = count + 1
            closed_g[node] = min(g, closed_g.get(node, g))
            self.expanded += 1
            if self.expanded > self.budget:
                raise SearchBudgetError(f"product search expanded {self.budget} nodes")
            q, s = node
            h_here = self.heuristic(q, s) if self.use_h else 0.0
            if task >= 0:
                c, again = self._tail_goal(q, s, *self._tail(labels, lab))
                if c:
                    heapq.heappush(heap, (_key(g + again), -_key(g),
                                          (depth[lab], next(tie)), 1, lab, c))
            if long_cycles and self.aut.loopable(q):
                cyc = self.cycle_from(q, s)
                if cyc is not None:
                    heapq.heappush(heap, (_key(g + cyc[0]), -_key(g + cyc[0]),
                                          (depth[lab] + len(cyc[1]), next(tie)), 1, lab,
                                          cyc[1]))
            for i in range(len(self.tasks)):
                nxt = self.step(s, i)
                if nxt is None:
                    continue
                s2, c = nxt
                g2 = g + self._cost(node, i, c)
                for q2, m2 in self.aut.successors(q, i):
                    node2 = (q2, self.forget(q2, s2))
                    if pops.get(node2, 0) >= k and (k > 1 or g2 >= closed_g[node2] - 1e-9):
                        continue
                    if lazy:
                        # push with h(here) - step cost, the real value only if the child
                        # is popped (most never are). It stays a lower bound of the cost
                        # through the child (h(here) <= c + h*(child) as h is admissible),
                        # so the optimal search (weight 1) stays optimal.
                        h = max(0.0, h_here - c)
                    else:
                        h = self.heuristic(*node2) if self.use_h else 0.0
                    if g2 + h > bound:
                        continue
                    labels.append((node2, lab, i, g2, m2))
                    depth.append(depth[lab] + 1)
                    heapq.heappush(heap, (_key(g2 + self.weight * h), -_key(g2),
                                          (depth[lab] + 1, next(tie)),
                                          2 if lazy else 0, len(labels) - 1, ()))
        if not out and not long_cycles:
            return self.lassos(k, start, bound, long_cycles=True)
        return out

    def _tail(self, labels: list, lab: int) -> tuple[tuple[int, ...], tuple[int, ...],
                                                     tuple[int, ...]]:
        """The last (up to :attr:`tail_steps`) steps of a label's path: their tasks, the
        automaton state before each, and the marks of each."""
        tasks, states, marks = [], [], []
        while lab > 0 and len(tasks) < self.tail_steps:
            _node, parent, task, _g, m = labels[lab]
            tasks.append(task)
            marks.append(m)
            states.append(labels[parent][0][0])
            lab = parent
        return tuple(reversed(tasks)), tuple(reversed(states)), tuple(reversed(marks))

    def _tail_goal(self, q: int, s: CellState, tail: tuple[int, ...],
                   before: tuple[int, ...], marks: tuple[int, ...]) -> tuple[int, float]:
        """The shortest ``c`` such that the path's last ``c`` steps are its cycle, and the
        cost of the further repetitions; ``(0, 0)`` if there is none. The path is what the
        worker performs for one pass, so that pass must pass the acceptance condition
        itself (finite-trace semantics, :meth:`witnessed`). They are when

        * the path ran them as a cycle of the automaton: from ``q`` back to ``q`` with
          every mark (the acceptance condition was passed once), or
        * repeating them forever from ``q`` is accepted, and either ``q`` owes nothing
          (:meth:`done`: ``F a`` ends right after the ``a``, with no extra step) or they
          passed every mark into a state ``q`` that may lie on an accepting cycle and the
          cell allows going round them again (S1's ``grasp, assemble``: a loop the worker
          could repeat; a pass ending in ``sit`` with ``X wait`` still owed is not one).
        """
        done = self.done(q)
        full = self.aut.full
        # an explicit automaton's marks on edges off its cycles are arbitrary: there the
        # accepting component and the word's acceptance decide
        marked = hasattr(self.aut, "settled")
        acc = 0
        for c in range(1, len(tail) + 1):
            cyc = tail[-c:]
            acc |= marks[-c]
            if before[-c] == q and acc == full:
                ok = True
            elif done or ((acc == full or not marked) and self.aut.loopable(q)):
                key = (q, cyc)
                ok = self._tails.get(key)
                if ok is None:
                    ok = self._tails[key] = self._accepts_cycle(q, cyc)
                # a loop the worker could go round again, unless nothing is owed
                ok = ok and (done or self._again(s, cyc, max(1, self.repetitions - 1))
                             is not None)
            else:
                continue
            again = self._again(s, cyc) if ok else None
            if again is not None:
                return c, again
        return 0, 0.0

    def done(self, q: int) -> bool:
        """Whether reaching ``q`` passes the acceptance condition for good: the tableau's
        ``q`` owes nothing (:meth:`LetterTableau.settled`), or an explicit automaton's
        ``q`` accepts every continuation (:meth:`ExplicitView.sink`)."""
        settled = getattr(self.aut, "settled", None)
        return settled(q) if settled is not None else self.aut.sink(q)

    def witnessed(self, prefix: Sequence[int], cycle: Sequence[int]) -> bool:
        """Whether the motion ``prefix`` plus one pass of ``cycle`` (task indices, from
        the initial state) passes the acceptance condition itself, as the worker performs
        it (finite-trace semantics): some run of the automaton on it reaches a state that
        is :meth:`done`, or passes every mark during the pass of the cycle and ends in a
        state that may lie on an accepting cycle (:meth:`LetterTableau.loopable`) from
        which repeating the cycle forever is accepted. (A cycle rotated so that its
        acceptance comes only in a later pass fails: the run ends owing a step.)"""
        full = self.aut.full
        q0 = self.aut.initial
        if self.done(q0):
            return True
        # (state, marks passed during the cycle; see _tail_goal for explicit automata)
        runs = {(q0, 0 if hasattr(self.aut, "settled") else full)}
        n = len(prefix)
        for k, i in enumerate((*prefix, *cycle)):
            nxt: set[tuple[int, int]] = set()
            for q, acc in runs:
                for q2, m in self.aut.successors(q, i):
                    if self.done(q2):
                        return True
                    nxt.add((q2, acc | m if k >= n else acc))
            runs = nxt
            if not runs:
                return False
        cyc = tuple(cycle)
        return any(acc == full and self.aut.loopable(q) and self._accepts_cycle(q, cyc)
                   for q, acc in runs)

    def _accepts_cycle(self, q0: int, cyc: tuple[int, ...]) -> bool:
        """Whether the automaton accepts ``cyc^omega`` from state ``q0``."""
        bits = range(self.aut.full.bit_length())
        return lasso_accepted(
            q0, lambda q, i: [(d, frozenset(b for b in bits if m >> b & 1))
                              for d, m in self.aut.successors(q, cyc[i])],
            0, len(cyc), self.aut.full.bit_length())

    @staticmethod
    def _path(labels: list, lab: int) -> tuple[int, ...]:
        out = []
        while lab > 0:
            _node, parent, task, _g, _m = labels[lab]
            out.append(task)
            lab = parent
        return tuple(reversed(out))

    def cost_of(self, tasks: Sequence[int]) -> float | None:
        """Estimated seconds of doing ``tasks`` from the start (None if impossible)."""
        s = self.model.initial_state()
        total = 0.0
        for i in tasks:
            nxt = self.model.step(s, self.tasks[i])
            if nxt is None:
                return None
            s, c = nxt
            total += c
        return total


def _key(f: float) -> float:
    """A priority rounded to :data:`KEY_DIGITS` decimals: costs summed in another order
    differ in the last bits, and equal costs must tie so that the deeper node wins (many
    orders of the same trips cost the same), then the path with fewer steps."""
    return round(f, KEY_DIGITS)


def seeded_noise(seed: int, factor: float) -> Callable[[tuple, int], float]:
    """Cost factors in ``[1, factor]``, drawn once per (node, task) from ``seed``."""
    rng = random.Random(seed)
    drawn: dict[tuple[tuple, int], float] = {}

    def noise(node: tuple, i: int) -> float:
        key = (node, i)
        x = drawn.get(key)
        if x is None:
            x = drawn[key] = 1.0 + (factor - 1.0) * rng.random()
        return x

    return noise


#: Parts a task step handles, by task name (argument index of the part).
_PART_TASKS = {"grasp": 0, "release": 0, "move": 0, "insert": 0, "carry": 0, "extract": 0}


def task_steps(spec: Specification, model: CellModel, releases: str = "needed"
               ) -> tuple[list[Atom], list[frozenset[str]]]:
    """Candidate steps: the specification's, plus ``grasp`` of every part a step handles,
    and ``release`` of it when the hands cannot hold them all (a worker picks parts up
    and puts them down between the tasks the specification names), with their letters.

    ``releases="needed"`` adds a ``release`` only for a part that no step of the
    specification sets down or uses up (``move``, ``insert``, ``release``, a two-hand
    shorthand): putting down a part that the specification will have carried elsewhere
    is a detour a foreman would not accept. ``"all"`` adds one for every handled part
    (the fallback when the first product has no lasso, and the yardstick of the
    benchmark's exhaustive search)."""
    if releases not in ("needed", "all"):
        raise ValueError(f"releases must be 'needed' or 'all', got {releases!r}")
    tasks = list(spec.tasks)
    handled = [t.args[0] for t in spec.tasks if t.name in _PART_TASKS
               and len(t.args) > _PART_TASKS[t.name] and t.args[0] in model.part_index]
    handled = list(dict.fromkeys(handled))
    # A release the specification does not name is only a candidate when the hands cannot
    # hold every part it handles at once: otherwise a search may put a part down to have
    # it nearer next time (S2 over several cycles put O2 down beside O1, never assembling it).
    width = sum(2 if model.two_handed[model.part_index[p]] else 1 for p in handled)
    freed: set[str] = set()
    if releases == "needed":
        for t in spec.tasks:
            kind = model.kind(t)[0]
            if kind == "assemble":
                freed.update(handled)
            elif kind in ("move", "insert", "release") and t.args:
                freed.add(t.args[0])
    for part in handled:
        helpers = ("grasp", "release") if width > model.limits.hands \
            and part not in freed else ("grasp",)
        for helper in helpers:
            a = Atom(helper, (part,))
            if a not in tasks:
                tasks.append(a)
    letters = [*spec.letters, *(letter_of(t, spec.vocabulary) for t in tasks[len(spec.tasks):])]
    return tasks, letters


def _search_formula(spec: Specification):
    """The specification without its exclusivity conjunct (the letters make it true)."""
    return conj(spec.user_formula, *(f for label, f in spec.always_on
                                     if not label.startswith("exclusivity")))


def product_search(spec: Specification, model: CellModel, backend: str = "builtin",
                   repetitions: int = 1, releases: str = "needed", **kwargs
                   ) -> tuple[ProductSearch, list[Atom], list[frozenset[str]]]:
    """A :class:`ProductSearch` of ``spec`` in ``model`` (on-the-fly tableau, or the
    explicit automaton of Spot for ``backend="spot"``) over the candidate steps of
    :func:`task_steps` (``releases``)."""
    tasks, letters = task_steps(spec, model, releases)
    if resolve_backend(backend) == "spot":
        view = ExplicitView(translate(spec.formula, backend="spot"), letters)
    else:
        view = LetterTableau(_search_formula(spec), letters)
    search = ProductSearch(view, model, tasks, repetitions=repetitions, **kwargs)
    search.tail_steps = max(search.tail_steps, cycle_steps(spec, model, tasks, letters))
    return search, tasks, letters
