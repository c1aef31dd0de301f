"""GR(1) specifications: robot events as inputs, the worker's tasks as outputs
(docs/reactive.md).

A reactive specification is ``(A1 & A2 ...) -> (G1 & G2 ...)`` (or only guarantees).
Each conjunct is one of

* **init**: a formula of the first step, no temporal operator;
* **safety**: ``G phi`` where ``phi`` uses ``X`` only directly over formulas of one step
  (``G(robot_in(R1) -> X !assemble(R1))``);
* **liveness**: ``G F psi`` with ``psi`` of one step;
* **eventually** (guarantees only): ``F psi`` with ``psi`` of one step, kept by a monitor
  bit, false at first and ``m' <-> (m | psi)``, whose ``G F m`` is a liveness goal.

Assumptions may mention inputs only, so the worker can never win by blocking them.

The game is solved with omega's GR(1) (generalized Streett) fixpoint on BDDs from ``dd``
(CUDD where installed). Moore reading: the worker picks a step's task at the boundary
before it, from the inputs observed so far; the step's inputs are those observed at its
end, so ``G(robot_in(R1) -> X !assemble(R1))`` reads "when the robot is in R1 as a task
ends, the next task is not assembly". The worker's physical model is a finite
:class:`Plant` whose moves are the tasks, so a strategy only asks for what the cell model
allows. Among the moves the strategy allows, :class:`Strategy` takes the one closest to
its goal, then the cheapest by the plant's costs.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl.formula import (
    And,
    Atom,
    Const,
    Equiv,
    Finally,
    Formula,
    Globally,
    Implies,
    Next,
    Not,
    Or,
    Xor,
    atoms,
    conj,
    to_spot,
    top_level_conjuncts,
)

__all__ = ["Gr1Conjunct", "Gr1Game", "Gr1Spec", "Plant", "Strategy", "plain_text",
           "split_gr1"]

@dataclass(frozen=True)
class Gr1Conjunct:
    """One assumption or guarantee.

    Attributes
    ----------
    kind : {"init", "safety", "liveness", "eventually"}
    body : Formula
        ``phi`` of ``G phi``, ``psi`` of ``G F psi`` / ``F psi``, or the init formula.
    text : str
        The conjunct as written (Spot syntax), for messages.
    """

    kind: str
    body: Formula
    text: str


@dataclass(frozen=True)
class Gr1Spec:
    """A specification split into assumptions and guarantees.

    Attributes
    ----------
    assumptions, guarantees : tuple of Gr1Conjunct
    inputs : tuple of str
        Keys of the input atoms (``"robot_in(R1)"``), in order of first appearance.
    """

    assumptions: tuple[Gr1Conjunct, ...]
    guarantees: tuple[Gr1Conjunct, ...]
    inputs: tuple[str, ...]

    def assumption_formula(self) -> Formula:
        """The conjunction of the assumptions as LTL (``true`` when there is none)."""
        return conj(*(_as_ltl(c) for c in self.assumptions))


def _as_ltl(c: Gr1Conjunct) -> Formula:
    if c.kind == "safety":
        return Globally(c.body)
    if c.kind == "liveness":
        return Globally(Finally(c.body))
    if c.kind == "eventually":
        return Finally(c.body)
    return c.body


def _temporal_depth(f: Formula) -> tuple[int, bool]:
    """(nesting depth of X, whether another temporal operator occurs)."""

    def depth(g: Formula, children: list[tuple[int, bool]]) -> tuple[int, bool]:
        if isinstance(g, (Atom, Const)):
            return 0, False
        if isinstance(g, Next):
            return children[0][0] + 1, children[0][1]
        if isinstance(g, (Not, And, Or, Implies, Equiv, Xor)):
            return max(d for d, _ in children), any(o for _, o in children)
        return 0, True

    return f.fold(depth)


def plain_text(f: Formula) -> str:
    """``f`` in Spot's syntax without the quotes around atoms (``G F grasp(O1)``)."""
    return re.sub(r'"([^"]*)"', r"\1", to_spot(f))


def _classify(f: Formula, role: str) -> Gr1Conjunct:
    text = plain_text(f)
    depth, other = _temporal_depth(f)
    if not other and depth == 0:
        return Gr1Conjunct("init", f, text)
    if isinstance(f, Globally):
        inner = f.arg
        if isinstance(inner, Finally):
            d, o = _temporal_depth(inner.arg)
            if d == 0 and not o:
                return Gr1Conjunct("liveness", inner.arg, text)
        else:
            d, o = _temporal_depth(inner)
            if d <= 1 and not o:
                return Gr1Conjunct("safety", inner, text)
    if isinstance(f, Finally) and role == "guarantee":
        d, o = _temporal_depth(f.arg)
        if d == 0 and not o:
            return Gr1Conjunct("eventually", f.arg, text)
    raise SpecError(f"{role} '{text}' is not of GR(1) form; expected a formula of the "
                    "first step, G(...) with X only over formulas of one step, G F (...)"
                    + (", or F (...) of one step" if role == "guarantee" else "")
                    + " (docs/reactive.md)")


def split_gr1(formula: Formula, inputs: Iterable[Atom]) -> Gr1Spec:
    """Split ``formula`` into GR(1) assumptions and guarantees.

    Parameters
    ----------
    formula : Formula
        ``A -> G`` (``A`` mentions an input) or ``G`` alone; conjunctions are split at
        the top.
    inputs : iterable of Atom
        The input propositions (the rest are the worker's).

    Raises
    ------
    SpecError
        A conjunct outside GR(1), or an assumption that mentions a task of the worker.
    """
    keys = tuple(dict.fromkeys(a.key for a in inputs))
    if isinstance(formula, Implies) and {a.key for a in atoms(formula.left)} & set(keys):
        left, right = top_level_conjuncts(formula.left), top_level_conjuncts(formula.right)
    else:                                   # no input on the left: one guarantee
        left, right = [], top_level_conjuncts(formula)
    assumptions = []
    for f in left:
        c = _classify(f, "assumption")
        outputs = sorted({a.key for a in atoms(f)} - set(keys))
        if outputs:
            raise SpecError(f"assumption '{c.text}' mentions {', '.join(outputs)}, which the "
                            "worker does; assumptions may speak of inputs (robot events) only")
        assumptions.append(c)
    guarantees = [_classify(f, "guarantee") for f in right if f != Const(True)]
    return Gr1Spec(tuple(assumptions), tuple(guarantees), keys)


@dataclass(frozen=True)
class Plant:
    """The worker's physical model as a finite system whose moves are tasks.

    Attributes
    ----------
    labels : tuple of frozenset of str
        Per task index k, the atom keys true at a step doing task k.
    initial : tuple of (int, int, float)
        Moves from the start: (task k, state after it, cost in s).
    moves : tuple of tuple of (int, int, float)
        Per state s, its moves (task k, next state, cost in s).
    """

    labels: tuple[frozenset[str], ...]
    initial: tuple[tuple[int, int, float], ...]
    moves: tuple[tuple[tuple[int, int, float], ...], ...]


def _env_name(i: int) -> str:
    return f"in{i}"


class Gr1Game:
    """The GR(1) game of a :class:`Gr1Spec` over a :class:`Plant`, solved with omega.

    Parameters
    ----------
    spec : Gr1Spec
    plant : Plant
    fixed_inputs : mapping of str to bool, optional
        Inputs the robot holds at these values forever (used to find counter-strategies).
    cooperative : bool
        The worker also picks the inputs, keeping the assumptions (init, safety and
        liveness become its own): solvable iff some robot behaviour lets the worker win.
    respond : (int, mapping, mapping), optional
        ``(k, on, off)``: the robot sets the inputs to ``on`` as a step doing task ``k``
        ends and to ``off`` as any other step ends (a reacting counter-strategy).
    """

    def __init__(self, spec: Gr1Spec, plant: Plant,
                 fixed_inputs: Mapping[str, bool] | None = None,
                 cooperative: bool = False,
                 respond: tuple[int, Mapping[str, bool], Mapping[str, bool]] | None = None
                 ) -> None:
        from omega.symbolic import temporal as trl

        self.spec = spec
        self.plant = plant
        self.inputs = spec.inputs
        self._env = {k: _env_name(i) for i, k in enumerate(self.inputs)}
        n_tasks, n_states = len(plant.labels), max(len(plant.moves), 1)
        monitors = [c for c in spec.guarantees if c.kind == "eventually"]
        self._monitors = [f"m{i}" for i in range(len(monitors))]
        aut = trl.Automaton()
        decl: dict[str, object] = {v: "bool" for v in self._env.values()}
        decl.update({m: "bool" for m in self._monitors})
        decl["task"] = (0, max(n_tasks - 1, 1))
        decl["cs"] = (0, max(n_states - 1, 1))
        decl["_free"] = "bool"
        aut.declare_variables(**decl)
        inputs = list(self._env.values())
        aut.varlist.update(env=["_free"] if cooperative else inputs,
                           sys=["task", "cs", *self._monitors, *(inputs if cooperative else ())])
        aut.prime_varlists()
        self.aut = aut
        self._eqs: dict[str, object] = {}

        env_init, env_action = aut.true, aut.true
        for c in spec.assumptions:
            if c.kind == "init":
                env_init &= self._bdd(c.body)
            elif c.kind == "safety":
                env_action &= self._bdd(c.body)
        for key, value in (fixed_inputs or {}).items():
            lit = aut.add_expr(self._env[key])
            env_init &= lit if value else ~lit
            lit_next = aut.add_expr(self._env[key] + "'")
            env_action &= lit_next if value else ~lit_next
        if respond is not None:
            k, on, off = respond
            trigger = self._eq(f"task' = {k}")
            for key in self.inputs:
                lit = self._eq(self._env[key] + "'")
                env_action &= (trigger & (lit if on[key] else ~lit)) | \
                    (~trigger & (lit if off[key] else ~lit))
        sys_init = self._plant_init()
        sys_action = self._plant_action()
        goals = []
        for c in spec.guarantees:
            if c.kind == "init":
                sys_init &= self._bdd(c.body)
            elif c.kind == "safety":
                sys_action &= self._bdd(c.body)
            elif c.kind == "liveness":
                goals.append(self._bdd(c.body))
        for m, c in zip(self._monitors, monitors):
            mv, mn = aut.add_expr(m), aut.add_expr(m + "'")
            sys_init &= ~mv
            sys_action &= mn.equiv(mv | self._bdd(c.body))
            goals.append(mv)
        holds = [~self._bdd(c.body) for c in spec.assumptions if c.kind == "liveness"]
        if cooperative:
            sys_init, sys_action = sys_init & env_init, sys_action & env_action
            env_init = env_action = aut.true
            goals += [~h for h in holds]
            holds = []
        aut.init["env"], aut.init["sys"] = env_init, sys_init
        aut.action["env"], aut.action["sys"] = env_action, sys_action
        aut.win["<>[]"] = holds or [aut.false]
        aut.win["[]<>"] = goals or [aut.true]
        aut.qinit = r"\E \A"
        aut.moore = True
        aut.plus_one = False
        self._solved: tuple | None = None

    # ---------------------------------------------------------------- encoding
    def _eq(self, expr: str) -> object:
        """The BDD of ``expr`` (parsed once)."""
        u = self._eqs.get(expr)
        if u is None:
            u = self._eqs[expr] = self.aut.add_expr(expr)
        return u

    def _atom(self, key: str, primed: bool) -> object:
        aut, tick = self.aut, "'" if primed else ""
        if key in self._env:
            return self._eq(self._env[key] + tick)
        u = aut.false
        for k, letter in enumerate(self.plant.labels):
            if key in letter:
                u |= self._eq(f"task{tick} = {k}")
        return u

    def _bdd(self, f: Formula, primed: bool = False) -> object:
        aut = self.aut
        if isinstance(f, Const):
            return aut.true if f.value else aut.false
        if isinstance(f, Atom):
            return self._atom(f.key, primed)
        if isinstance(f, Next):
            if primed:
                raise SpecError(f"X X in '{plain_text(f)}' looks two steps ahead; GR(1) "
                                "allows one")
            return self._bdd(f.arg, True)
        if isinstance(f, Not):
            return ~self._bdd(f.arg, primed)
        if isinstance(f, And):
            u = aut.true
            for g in f.args:
                u &= self._bdd(g, primed)
            return u
        if isinstance(f, Or):
            u = aut.false
            for g in f.args:
                u |= self._bdd(g, primed)
            return u
        a, b = self._bdd(f.left, primed), self._bdd(f.right, primed)
        if isinstance(f, Implies):
            return ~a | b
        if isinstance(f, Equiv):
            return a.equiv(b)
        if isinstance(f, Xor):
            return ~a.equiv(b)
        raise SpecError(f"'{plain_text(f)}' is not of GR(1) form")

    def _move(self, k: int, s: int, primed: bool) -> object:
        tick = "'" if primed else ""
        return self._eq(f"task{tick} = {k}") & self._eq(f"cs{tick} = {s}")

    def _plant_init(self) -> object:
        u = self.aut.false
        for k, s, _ in self.plant.initial:
            u |= self._move(k, s, False)
        return u

    def _plant_action(self) -> object:
        aut = self.aut
        u = aut.false
        for s, moves in enumerate(self.plant.moves):
            here = self._eq(f"cs = {s}")
            nxt = aut.false
            for k, s2, _ in moves:
                nxt |= self._move(k, s2, True)
            u |= here & nxt
        return u

    # ---------------------------------------------------------------- solving
    def solve(self) -> bool:
        """Whether the worker wins from every initial input (realizability)."""
        from omega.games import gr1

        if self._solved is None:
            z, yij, xijk = gr1.solve_streett_game(self.aut)
            aut = self.aut
            init = (aut.init["sys"] & z) | ~aut.init["env"]
            u = aut.exist(aut.varlist["sys"], aut.forall(aut.varlist["env"], init))
            self._solved = (u == aut.true, z, yij, xijk)
        return bool(self._solved[0])

    def strategy(self) -> Strategy:
        """The winning strategy (a BDD transducer); SpecError when unrealizable."""
        from omega.games import gr1

        if not self.solve():
            raise SpecError("the specification is unrealizable; no strategy exists")
        _, z, yij, xijk = self._solved
        impl = gr1.make_streett_transducer(z, yij, xijk, self.aut)
        return Strategy(self, impl, self.aut.init["impl"], yij)


@dataclass
class Strategy:
    """A winning strategy: picks the worker's next task from the inputs seen so far.

    Moore reading (docs/reactive.md): step i's task is chosen at the boundary before it,
    from the inputs observed at the end of the steps before; step i's inputs are those
    observed at its end. Deterministic: among the moves the transducer allows, the one
    closest to the next goal to reach (the lowest layer of that goal's attractor, then of
    the goals after it, for every input to come, so the worker does not idle where it
    can progress), then the cheapest by the plant's cost, then the lowest task index and
    goal counter.
    """

    game: Gr1Game
    action: object
    init: object
    layers: list = field(default_factory=list)
    state: dict[str, object] = field(default_factory=dict)
    _chosen: dict[str, object] = field(default_factory=dict)

    def reset(self) -> None:
        """Back to before the first step."""
        self.state = {}
        self._chosen = {}

    def _sys_vars(self) -> list[str]:
        return [*self.game.aut.varlist["sys"], "_goal"]

    def _next_goal(self) -> int:
        """The goal to reach next: the counter's, or the one after it where the current
        state already meets the counter's goal."""
        if not self.state:
            return 0
        aut = self.game.aut
        c = int(self.state["_goal"])
        here = {k: v for k, v in self.state.items() if k != "_goal"}
        goals = aut.win["[]<>"]
        return (c + 1) % len(goals) if aut.let(here, goals[c]) == aut.true else c

    def _ranks(self, values: dict[str, object], first: int) -> tuple[int, ...]:
        """Layers of a successor (its system part ``values``) in the attractors of goal
        ``first`` and of the goals after it, whatever the inputs."""
        aut = self.game.aut
        sys = {k: v for k, v in values.items() if k != "_goal"}
        env = aut.varlist["env"]
        n = len(self.layers)
        out = []
        for i in range(n):
            layers = self.layers[(first + i) % n]
            out.append(next((r for r, layer in enumerate(layers)
                             if aut.forall(env, aut.let(sys, layer)) == aut.true),
                            len(layers)))
        return tuple(out)

    def choose(self) -> int:
        """The task index of the next step (before its inputs are known).

        Raises
        ------
        SpecError
            When the inputs observed so far broke an assumption (no move is winning).
        """
        aut, plant = self.game.aut, self.game.plant
        sys_vars = self._sys_vars()
        if not self.state:
            picks = list(aut.pick_iter(aut.exist(aut.varlist["env"], self.init),
                                       care_vars=sys_vars))
            costs = {(k, s2): c for k, s2, c in plant.initial}
        else:
            u = aut.let(self.state, self.action)
            picks = [{k.rstrip("'"): v for k, v in p.items()}
                     for p in aut.pick_iter(u, care_vars=[v + "'" for v in sys_vars])]
            costs = {(k, s2): c for k, s2, c in plant.moves[int(self.state["cs"])]}
        if not picks:
            raise SpecError("the inputs broke an assumption; the strategy has no move")

        first = self._next_goal()

        def key(p: dict[str, object]) -> tuple:
            return (self._ranks(p, first),
                    costs.get((int(p["task"]), int(p["cs"])), float("inf")),
                    int(p["task"]), int(p["_goal"]))
        self._chosen = min(picks, key=key)
        return int(self._chosen["task"])

    def observe(self, inputs: Mapping[str, bool]) -> None:
        """Record the inputs observed at the end of the chosen step (keys of
        :attr:`Gr1Spec.inputs`; missing ones are false)."""
        if not self._chosen:
            raise ValueError("observe() before choose()")
        env = {self.game._env[k]: bool(inputs.get(k, False)) for k in self.game.inputs}
        self.state = {**env, **self._chosen}
        self._chosen = {}

    def step(self, inputs: Mapping[str, bool]) -> int:
        """:meth:`choose` the step's task, then :meth:`observe` ``inputs`` at its end."""
        task = self.choose()
        self.observe(inputs)
        return task

    def memory(self) -> tuple:
        """The strategy's state (hashable): it decides the next move."""
        return tuple(sorted((k, int(v)) for k, v in self.state.items()))


def input_valuations(inputs: Sequence[str], limit: int = 256
                     ) -> Iterable[dict[str, bool]]:
    """Every assignment of ``inputs`` (at most ``limit`` of them)."""
    for bits in itertools.islice(itertools.product((True, False), repeat=len(inputs)),
                                 limit):
        yield dict(zip(inputs, bits))
