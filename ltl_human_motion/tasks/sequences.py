"""Task sequences under the cell model: the cost-optimal lasso first, then variations.

:func:`plan_sequences` is what the pipeline and ``ltl-human-motion tasks`` call when a
cell with geometry is given; without one it falls back to
:func:`ltl_human_motion.ltl.sequences.synthesize_sequences`.

Modes (the first sequence is always the cheapest lasso found):

``"all"``
    The ``n`` cheapest distinct lassos (k shortest walks in the product).
``"coverage"``
    Lassos forced through product transitions not yet covered, cheapest first.
``"random"``
    Seeded random lassos: the optimum under step costs scaled by seeded factors in
    ``[1, RANDOM_COST_FACTOR]``, so each costs at most that factor times the optimum.

Every sequence is physically possible in the cell model (no third part in two hands,
no release of a part not held, no grasp of a part in hand), and every sequence is
checked against the full specification by the independent evaluator.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from ltl_human_motion.errors import SpecError, VerificationError
from ltl_human_motion.ltl.evaluator import evaluate_lasso
from ltl_human_motion.ltl.formula import Atom
from ltl_human_motion.ltl.sequences import TaskSequence, synthesize_sequences
from ltl_human_motion.ltl.spec import Specification, build_specification
from ltl_human_motion.tasks.explain import explain_infeasible
from ltl_human_motion.tasks.model import CellModel, Limits
from ltl_human_motion.tasks.product import (
    Lasso,
    ProductSearch,
    SearchBudgetError,
    product_search,
    seeded_noise,
    task_steps,
)
from ltl_human_motion.tasks.recurrence import refuse_many_recurrences

__all__ = ["MODES", "RANDOM_COST_FACTOR", "PlanStats", "has_geometry", "plan_sequences"]

MODES = ("random", "coverage", "all")

#: Random lassos cost at most this factor times the optimum (a dataset's variety vs. a
#: foreman's patience: 25 % longer is still a plausible way of doing the job).
RANDOM_COST_FACTOR = 1.25

#: A* weights and work budgets tried in turn when a search exceeds its budget: the
#: optimal A* first, then weighted A* (at most ``weight`` times the optimum), the last
#: greedy. Work = nodes expanded times candidate steps (~20-50 us each on this machine),
#: so a budget bounds the time whatever the number of steps. The first budget lets the
#: optimal search answer 20-part kitting ("grasp", "move each part", the response
#: family: 205-247 nodes, bench/task_planning.py); the precedence family goes on to 1.2.
WEIGHT_LADDER = ((1.0, 16_000), (1.2, 12_000), (1.5, 100_000), (3.0, 200_000),
                 (1e6, 1_000_000))

#: Longest cycle made of a prefix's own last steps that is tried (each try is one
#: evaluator call).
SHRINK_STEPS = 6

@dataclass
class PlanStats:
    """How the sequences were found.

    Attributes
    ----------
    automaton_seconds, search_seconds : float
        Time spent on the specification's automaton (its set-up and the edges the
        searches made on the fly), and the rest of the product searches.
    expanded : int
        Product nodes expanded.
    weight : float
        A* weight of the first sequence (1.0: cost-optimal).
    costs : list of float
        The search's cost of each sequence (prefix and cycle repetitions; seconds of the
        cost model, which orders sequences: :func:`~ltl_human_motion.tasks.model.
        estimated_duration` estimates the motion's length).
    """

    automaton_seconds: float = 0.0
    search_seconds: float = 0.0
    expanded: int = 0
    weight: float = 1.0
    costs: list[float] = field(default_factory=list)
    _views: list = field(default_factory=list, repr=False)

    def _automaton_time(self) -> float:
        return sum(t + getattr(v, "build_seconds", 0.0) for t, v in self._views)

    @property
    def optimal(self) -> bool:
        """Whether the first sequence is proven cost-optimal under the model."""
        return self.weight == 1.0


def has_geometry(cell: object) -> bool:
    """Whether ``cell`` is a scene cell the model can be made of (object positions)."""
    objects = getattr(cell, "objects", None)
    return bool(hasattr(cell, "start_region") and hasattr(objects, "values")
                and all(hasattr(o, "position") for o in objects.values()))


def _ladder(spec: Specification, model: CellModel, backend: str, reps: int, k: int,
            stats: PlanStats, noise=None, reuse: ProductSearch | None = None,
            releases: str = "needed"
            ) -> tuple[ProductSearch, list[Atom], list[frozenset[str]], list[Lasso]]:
    """The cheapest ``k`` lassos by the first search of :data:`WEIGHT_LADDER` that ends
    within its budget (weight 1: cost-optimal; ``stats.weight`` records it). The rungs
    share one search (automaton and memos); ``reuse`` shares an earlier one's (same
    ``spec``, ``model`` and ``reps``). When the product over the needed releases has no
    lasso, the one over every release is searched (:func:`task_steps`)."""
    if reuse is not None and reuse.repetitions == reps:
        search, tasks, letters = reuse, list(reuse.tasks), list(reuse.aut.letters)
    else:
        t0 = time.perf_counter()
        search, tasks, letters = product_search(spec, model, backend, reps,
                                                releases=releases)
        stats._views.append((time.perf_counter() - t0, search.aut))
    for weight, budget in WEIGHT_LADDER:
        search.configure(weight, max(50, budget // len(tasks)), noise)
        try:
            found = search.lassos(k)
        except SearchBudgetError:
            stats.expanded += search.expanded
            continue
        stats.expanded += search.expanded
        if not found and releases == "needed" \
                and len(task_steps(spec, model, "all")[0]) > len(tasks):
            return _ladder(spec, model, backend, reps, k, stats, noise, releases="all")
        if noise is None:
            stats.weight = weight
        return search, tasks, letters, found
    raise SpecError(f"specification '{spec.text}': the product search with the cell model "
                    f"exceeded its budget ({WEIGHT_LADDER[-1][1]} successor evaluations) "
                    "even greedily",
                    text=spec.text)


class _Emitter:
    """Turns lassos into checked, distinct :class:`TaskSequence` objects."""

    def __init__(self, spec: Specification, search: ProductSearch, tasks: list[Atom],
                 letters: list[frozenset[str]], reps: int, stats: PlanStats) -> None:
        self.spec, self.search, self.tasks, self.letters = spec, search, tasks, letters
        self.reps, self.stats = reps, stats
        self.out: list[TaskSequence] = []
        self.seen: set[tuple[tuple[int, ...], ...]] = set()

    def _holds(self, prefix, cycle) -> bool:
        return evaluate_lasso(self.spec.formula, [self.letters[i] for i in prefix],
                              [self.letters[i] for i in cycle])

    def _shrink(self, lasso: Lasso) -> tuple[tuple[int, ...], tuple[int, ...]]:
        """The same prefix with a cycle made of its own last steps, when the word still
        satisfies the specification and the motion performed (prefix and the passes of
        the cycle) still passes the acceptance condition (then the extra cycle is not
        performed)."""
        u = lasso.prefix
        if not lasso.searched_cycle:
            return lasso.prefix, lasso.cycle
        for c in range(1, min(len(u), SHRINK_STEPS) + 1):
            pre, cyc = u[:-c], u[-c:]
            executed = pre + cyc * self.reps
            if self.search.cost_of(executed) is not None and self._holds(pre, cyc) \
                    and self.search.witnessed(pre, cyc):
                return pre, cyc
        return lasso.prefix, lasso.cycle

    def add(self, lasso: Lasso) -> bool:
        pre, cyc = self._shrink(lasso)
        executed = pre + cyc * self.reps
        key = (pre, cyc)
        if key in self.seen or tuple(executed) in self.seen:
            return False
        cost = self.search.cost_of(executed)
        if cost is None:
            raise VerificationError(f"internal error: lasso {key} of '{self.spec.text}' is "
                                    "not possible in the cell model", check="cell model")
        if not self._holds(pre, cyc):
            raise VerificationError(f"internal error: lasso {key} of '{self.spec.text}' is "
                                    "accepted by the product but violates the "
                                    "specification", check="ltl")
        if not self.search.witnessed(pre, cyc):
            raise VerificationError(f"internal error: the motion of lasso {key} of "
                                    f"'{self.spec.text}' (prefix and one pass of the cycle) "
                                    "does not pass the acceptance condition",
                                    check="ltl")
        self.seen.update({key, tuple(executed)})
        used = sorted(set(pre) | set(cyc))
        self.out.append(TaskSequence(tuple(self.tasks[i] for i in pre),
                                     tuple(self.tasks[i] for i in cyc), self.reps,
                                     tuple((self.tasks[i], self.letters[i]) for i in used)))
        self.stats.costs.append(cost)
        return True


def plan_sequences(spec: str | Specification, cell: object, n: int | None = 5, seed: int = 0,
                   mode: str = "random", cycles: int = 1, *, min_steps: int = 0,
                   backend: str = "auto", limits: Limits | None = None,
                   ) -> tuple[list[TaskSequence], PlanStats]:
    """Task sequences of ``spec`` that a worker in ``cell`` would do, cheapest first.

    Parameters
    ----------
    spec : str or Specification
    cell : Cell or vocabulary
        With geometry (:func:`has_geometry`) the cell model is used; otherwise
        :func:`~ltl_human_motion.ltl.sequences.synthesize_sequences` answers.
    n : int or None
        Number of sequences (None: 5 for "random", 20 for the other modes).
    seed : int
        Seed of the random variations (the first sequence does not depend on it).
    mode : {"random", "coverage", "all"}
    cycles : int
        Passes through the cycle (>= 1).
    min_steps : int
        Repeat the cycle until a sequence has at least this many steps.
    backend : {"auto", "builtin", "spot"}
        "spot" searches the product with Spot's automaton; otherwise the on-the-fly
        tableau (Spot, when installed, only through "spot").
    limits : Limits, optional
        Physical limits of the worker (default: two hands, posture enforced).

    Returns
    -------
    sequences, stats

    Raises
    ------
    SpecError
        Unsatisfiable, or impossible in the cell: the message names the conflicting
        conjuncts and the physical limit.
    """
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if n is not None and n < 1:
        raise ValueError(f"n must be >= 1 (or None), got {n}")
    if cycles < 1:
        raise ValueError(f"cycles must be >= 1, got {cycles}")
    if not isinstance(spec, Specification):
        spec = build_specification(spec, cell)
    stats = PlanStats()
    if not has_geometry(cell):
        t0 = time.perf_counter()
        seqs = synthesize_sequences(spec, cell, n=n if n is not None or mode != "random"
                                    else 5, seed=seed, mode=mode, cycles=cycles,
                                    min_steps=min_steps, backend=backend)
        stats.search_seconds = time.perf_counter() - t0
        return seqs, stats
    want = n if n is not None else (5 if mode == "random" else 20)
    model = CellModel.from_cell(cell, limits)
    refuse_many_recurrences(spec, task_steps(spec, model)[1])
    reps = cycles
    t0 = time.perf_counter()
    k = 3 * want if mode == "all" else 1     # equal words from other lassos are dropped
    search, tasks, letters, found = _ladder(spec, model, backend, reps, k, stats)
    stats.search_seconds = time.perf_counter() - t0
    if not found:
        raise SpecError(explain_infeasible(spec, model, backend), text=spec.text)
    if min_steps and found:
        first = found[0]
        reps = max(reps, math.ceil((min_steps - len(first.prefix)) / len(first.cycle)))
        if reps != cycles:
            search, tasks, letters, found = _ladder(spec, model, backend, reps, k, stats)
    emit = _Emitter(spec, search, tasks, letters, reps, stats)
    for lasso in found:
        emit.add(lasso)
    t0 = time.perf_counter()
    if mode == "random":
        for r in range(4 * want):
            if len(emit.out) >= want:
                break
            noise = seeded_noise(seed * 1_000_003 + r, RANDOM_COST_FACTOR)
            _s, _t, _l, more = _ladder(spec, model, backend, reps, 1, stats, noise,
                                       reuse=search)
            for lasso in more:
                emit.add(lasso)
        if len(emit.out) < want:     # few distinct optima under noise: the next cheapest
            limit = RANDOM_COST_FACTOR * emit.stats.costs[0]
            _s, _t, _l, more = _ladder(spec, model, backend, reps, 3 * want, stats,
                                       reuse=search)
            for lasso in more:
                if len(emit.out) < want and lasso.cost <= limit:
                    emit.add(lasso)
    elif mode == "coverage":
        _coverage(search, emit, want)
    stats.search_seconds += time.perf_counter() - t0
    stats.automaton_seconds = stats._automaton_time()
    stats._views.clear()                    # the searches' automata are not kept alive
    stats.search_seconds = max(stats.search_seconds - stats.automaton_seconds, 0.0)
    return emit.out[:want], stats


def _coverage(search: ProductSearch, emit: _Emitter, want: int) -> None:
    """Lassos forced through first steps not yet used, in order of the steps' cost."""
    model = search.model
    covered: set[tuple] = set()
    for seq in list(emit.out):
        covered.update(_transitions(search, seq))
    frontier = [((), search.aut.initial, model.initial_state(), 0.0)]
    while frontier and len(emit.out) < want:
        base, q, s, g = frontier.pop(0)
        for i in range(len(search.tasks)):
            nxt = search.step(s, i)
            if nxt is None:
                continue
            s2, c = nxt
            for q2, _m in search.aut.successors(q, i):
                if ((q, s, i) in covered) or len(emit.out) >= want:
                    continue
                try:
                    found = search.lassos(1, start=((*base, i), q2, s2, g + c))
                except SearchBudgetError:
                    continue
                if found and emit.add(found[0]):
                    covered.update(_transitions(search, emit.out[-1]))
                frontier.append(((*base, i), q2, s2, g + c))


def _transitions(search: ProductSearch, seq: TaskSequence) -> set[tuple]:
    """(automaton state, cell state, task) of the deterministic-prefix steps of ``seq``."""
    index = {t: i for i, t in enumerate(search.tasks)}
    q, s = search.aut.initial, search.model.initial_state()
    out = set()
    for t in seq.tasks:
        i = index[t]
        nxt = search.step(s, i)
        succ = search.aut.successors(q, i)
        if nxt is None or not succ:
            break
        out.add((q, s, i))
        q, s = succ[0][0], nxt[0]
    return out
