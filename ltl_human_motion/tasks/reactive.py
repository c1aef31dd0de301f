"""A worker who reacts to the robot: GR(1) strategies over the cell model
(docs/reactive.md).

:func:`reactive_worker` parses a reactive specification, builds the worker's physical
model (:class:`~ltl_human_motion.tasks.model.CellModel`: two hands, parts held, posture)
as a :class:`~ltl_human_motion.ltl.gr1.Plant` whose moves are the specification's tasks
plus the idle step ``wait(WAIT_STEP)``, and solves the game. An unrealizable
specification raises :class:`UnrealizableError` naming the guarantee the robot can
defeat and a counter-strategy in words, before any motion planning.

:func:`draw_run` draws a robot behaviour that keeps the assumptions (a lasso of steps,
:func:`random_input_lasso`; a schedule in seconds, :func:`random_schedule`; or the
robot's own trajectory) and runs the strategy on it (:func:`run_strategy`,
:func:`timed_run`): the joint run of a finite strategy on an eventually periodic input is
eventually periodic, so it is returned as an exact lasso that the independent evaluator
checks against the whole specification (:func:`joint_satisfies`).
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl.evaluator import evaluate_lasso
from ltl_human_motion.ltl.formula import Atom, Not
from ltl_human_motion.ltl.gr1 import (
    Gr1Conjunct,
    Gr1Game,
    Gr1Spec,
    Plant,
    Strategy,
    input_valuations,
    plain_text,
    split_gr1,
)
from ltl_human_motion.ltl.spec import Specification, build_specification, letter_of
from ltl_human_motion.tasks.model import CellModel, CellState

__all__ = ["DEMO_SPEC", "MAX_PLANT_STATES", "TRACE_KINDS", "WAIT_STEP", "JointLasso",
           "ReactiveWorker", "UnrealizableError", "draw_run", "joint_satisfies",
           "keeps_assumptions", "random_input_lasso", "random_schedule", "reactive_worker",
           "run_strategy", "timed_run"]

#: Length (s) of the idle step ``wait(WAIT_STEP)``: a waiting worker reads the inputs
#: again at its end. Its motion lasts WAIT_STEP plus the blend into the next primitive
#: (0.29 s in all on the paper cell), so from a wait the worker starts the next task
#: within 0.3 s of an event (a human reaction time is 0.2-0.3 s).
WAIT_STEP = 0.15

#: The reactive specification of the demo's stage on the paper cell: the worker fetches
#: O1, walks to the bench (R1), waits there while the robot is in R1 and assembles when
#: it has left; the robot leaves R1 again and again.
DEMO_SPEC = ("(G F !robot_in(R1)) -> (G(robot_in(R1) -> X !assemble(R1)) & G F grasp(O1) & "
             "G F assemble(R1) & G(grasp(O1) -> X walk(R1)))")

#: States of the worker's physical model beyond which the game is refused.
MAX_PLANT_STATES = 5000

#: Steps a strategy run may take before its joint lasso must have closed.
MAX_RUN_STEPS = 2000


class UnrealizableError(SpecError):
    """No strategy of the worker meets the guarantees against every robot behaviour
    that keeps the assumptions; the message names the defeated guarantee and how."""


@dataclass
class ReactiveWorker:
    """A solved reactive specification.

    Attributes
    ----------
    specification : Specification
        The whole specification (always-on conjuncts included), with its inputs.
    gr1 : Gr1Spec
        Assumptions and guarantees (the final region's ``F enter(R)`` among them).
    tasks : tuple of Atom
        Task of each plant move index (the idle ``wait`` last).
    plant : Plant
    game : Gr1Game
    strategy : Strategy
    model : CellModel
        The worker's physical model.
    states : tuple of CellState
        The model state of each plant state.
    """

    specification: Specification
    gr1: Gr1Spec
    tasks: tuple[Atom, ...]
    plant: Plant
    game: Gr1Game
    strategy: Strategy
    model: CellModel
    states: tuple[CellState, ...]

    def letter(self, inputs: dict[str, bool], task: int) -> frozenset[str]:
        """The joint letter of one step: true inputs and the task's atoms."""
        return frozenset(k for k, v in inputs.items() if v) | self.plant.labels[task]


@dataclass(frozen=True)
class JointLasso:
    """A joint run ``prefix . cycle^omega`` of inputs and the worker's tasks.

    Attributes
    ----------
    prefix_inputs, cycle_inputs : tuple of dict
        Input values per step.
    prefix_tasks, cycle_tasks : tuple of int
        Task index per step.
    """

    prefix_inputs: tuple[dict[str, bool], ...]
    prefix_tasks: tuple[int, ...]
    cycle_inputs: tuple[dict[str, bool], ...]
    cycle_tasks: tuple[int, ...]


def _plant(model: CellModel, tasks: tuple[Atom, ...], labels: tuple[frozenset[str], ...]
           ) -> tuple[Plant, tuple[CellState, ...]]:
    """The reachable states of ``model`` under ``tasks`` (breadth first) as a plant, and
    the model state of each plant state."""
    index: dict[CellState, int] = {}
    order: list[CellState] = []

    def moves_from(state: CellState) -> tuple[tuple[int, int, float], ...]:
        out = []
        for k, task in enumerate(tasks):
            nxt = model.step(state, task)
            if nxt is None:
                continue
            s2, cost = nxt
            if s2 not in index:
                if len(order) >= MAX_PLANT_STATES:
                    raise SpecError(f"the worker's model has more than {MAX_PLANT_STATES} "
                                    "states with these tasks (MAX_PLANT_STATES); use fewer "
                                    "parts or tasks")
                index[s2] = len(order)
                order.append(s2)
                queue.append(s2)
            out.append((k, index[s2], float(cost)))
        return tuple(out)

    queue: deque[CellState] = deque()
    initial = moves_from(model.initial_state())
    moves: dict[int, tuple[tuple[int, int, float], ...]] = {}
    while queue:
        state = queue.popleft()
        moves[index[state]] = moves_from(state)
    return Plant(labels, initial, tuple(moves[i] for i in range(len(order)))), tuple(order)


#: How a robot input reads in an explanation: held for ever (true, false), then as a
#: task ends (true, false).
_INPUT_WORDS = {
    "robot_in": ("stays in {}", "stays out of {}", "is in {}", "is out of {}"),
    "robot_moving": ("keeps moving", "stays still", "moves", "stands still"),
    "offered": ("keeps offering {}", "never offers {}", "offers {}", "does not offer {}"),
}


def _input_words(key: str, value: bool, forever: bool = True) -> str:
    name, _, rest = key.partition("(")
    forms = _INPUT_WORDS.get(name, (f"keeps {key} true", f"keeps {key} false",
                                    f"sets {key} true", f"sets {key} false"))
    return forms[(0 if forever else 2) + (0 if value else 1)].format(rest.rstrip(")"))


def _realizable(spec: Gr1Spec, plant: Plant, fixed: dict[str, bool] | None = None,
                cooperative: bool = False, respond=None) -> bool:
    return Gr1Game(spec, plant, fixed, cooperative, respond).solve()


def _reacting_counter(spec: Gr1Spec, plant: Plant, tasks: tuple[str, ...]) -> str | None:
    """A robot that answers one task of the worker with some inputs and every other task
    with others, and defeats the worker, in words (None: none found)."""
    if len(spec.inputs) > 3:
        return None
    values = list(input_valuations(spec.inputs))
    for k, task in enumerate(tasks):
        for on in values:
            for off in values:
                if on != off and not _realizable(spec, plant, respond=(k, on, off)):
                    changed = [key for key in spec.inputs if on[key] != off[key]]
                    when = " and ".join(_input_words(key, on[key], False) for key in changed)
                    other = " and ".join(_input_words(key, off[key], False)
                                         for key in changed)
                    return (f"the robot {when} as each {task} of the worker ends, and "
                            f"{other} otherwise")
    return None


def _with_guarantees(spec: Gr1Spec, guarantees: list[Gr1Conjunct]) -> Gr1Spec:
    return Gr1Spec(spec.assumptions, tuple(guarantees), spec.inputs)


def _minimal_safety(spec: Gr1Spec, plant: Plant, fixed: dict[str, bool] | None,
                    goal: list[Gr1Conjunct], safety: list[Gr1Conjunct],
                    cooperative: bool = False) -> list[Gr1Conjunct]:
    """A subset of ``safety`` that with ``goal`` is still unrealizable (deletion)."""
    kept = list(safety)
    for c in list(safety):
        trial = [s for s in kept if s is not c]
        if not _realizable(_with_guarantees(spec, trial + goal), plant, fixed, cooperative):
            kept = trial
    return kept


def _defeated(spec: Gr1Spec, plant: Plant, fixed: dict[str, bool] | None,
              pretty: Callable[[str], str], cooperative: bool = False) -> str:
    """The guarantees that cannot all be met (with the fewest safety guarantees that
    make them so), in words."""
    safety = [c for c in spec.guarantees if c.kind in ("init", "safety")]
    goals = [c for c in spec.guarantees if c.kind in ("liveness", "eventually")]
    if not _realizable(_with_guarantees(spec, safety), plant, fixed, cooperative):
        core = _minimal_safety(spec, plant, fixed, [], safety, cooperative)
        return f"the safety guarantee{'s' if len(core) > 1 else ''} " + \
            ", ".join(f"'{pretty(c.text)}'" for c in core)
    single = [g for g in goals if not _realizable(_with_guarantees(spec, [*safety, g]),
                                                   plant, fixed, cooperative)]
    if not single:
        return "the guarantees " + ", ".join(f"'{pretty(g.text)}'" for g in goals) + \
            " together"
    core = _minimal_safety(spec, plant, fixed, [single[0]], safety, cooperative)
    return ("the guarantee " if len(single) == 1 else "each of the guarantees ") \
        + ", ".join(f"'{pretty(g.text)}'" for g in single) \
        + (" given " + ", ".join(f"'{pretty(c.text)}'" for c in core) if core else "")


def explain_unrealizable(spec: Gr1Spec, plant: Plant,
                         pretty: Callable[[str], str] = str,
                         tasks: tuple[str, ...] = ()) -> str:
    """Why ``spec`` is unrealizable on ``plant``: the guarantee the robot can defeat,
    a counter-strategy in words, and an assumption that would help (``pretty`` rewrites
    a conjunct's text for the message; ``tasks`` names the plant's tasks)."""
    if not _realizable(spec, plant, cooperative=True):
        return (f"the worker cannot meet {_defeated(spec, plant, None, pretty, True)} "
                "whatever the robot does, with its two hands, the parts it holds and the "
                "specification's tasks; add the tasks that free its hands (e.g. an "
                "assembly or a release) or weaken the guarantees")
    assumption = spec.assumption_formula()
    counter: dict[str, bool] | None = None
    for values in input_valuations(spec.inputs):
        letter = frozenset(k for k, v in values.items() if v)
        if evaluate_lasso(assumption, [], [letter]) and not _realizable(spec, plant, values):
            counter = values
            break
    defeated = _defeated(spec, plant, counter, pretty)
    if counter is None:
        how = _reacting_counter(spec, plant, tasks) or (
            "no fixed robot behaviour suffices: the robot wins by reacting to the "
            "worker's moves")
        hint = ("the worker sees an input only when a task ends: guard a task with the "
                "inputs of the step before (G(... -> X !task)), or assume more about the "
                "robot")
    else:
        words = [_input_words(k, v) for k, v in counter.items()] or ["does anything"]
        how = f"the robot {' and '.join(words)} forever"
        fixes = []
        for k, v in counter.items():
            text = f"G F {'!' if v else ''}{k}"
            body = Atom(*_split_key(k))
            lit = body if not v else Not(body)
            extra = Gr1Spec((*spec.assumptions, Gr1Conjunct("liveness", lit, text)),
                            spec.guarantees, spec.inputs)
            if _realizable(extra, plant):
                fixes.append(text)
        hint = (f"add an assumption such as {' or '.join(fixes)}" if fixes else
                "no single recurrence assumption on one input makes it realizable; "
                "weaken the guarantees or assume more about the robot")
    return (f"the robot can defeat {defeated} (with the worker's two hands and the parts "
            f"it holds): {how}; {hint}")


def _split_key(key: str) -> tuple[str, tuple[str, ...]]:
    name, _, rest = key.partition("(")
    return name, tuple(a.strip() for a in rest.rstrip(")").split(",") if a.strip())


def _readable(text: str, specification: Specification) -> str:
    """A conjunct's text without Spot's quotes, shorthands folded back
    (``leftHand(R1) & rightHand(R1)`` -> ``assemble(R1)``)."""
    from ltl_human_motion.ltl.parser import parse_spec

    for task in specification.tasks:
        if task.name in specification.vocabulary.shorthands:
            body = plain_text(parse_spec(task.key, specification.vocabulary).formula)
            text = text.replace(f"({body})", f" {task.key}").replace(body, task.key)
    return re.sub(r"([(!])\s+", r"\1", re.sub(r"\s{2,}", " ", text))


def reactive_worker(text: str, cell, *, wait_step: float = WAIT_STEP) -> ReactiveWorker:
    """Parse, check and solve a reactive specification on ``cell``.

    Parameters
    ----------
    text : str
        ``assumptions -> guarantees`` over inputs (robot events) and tasks.
    cell : Cell
        The scene cell (its model gives the physics and the costs).
    wait_step : float
        Seconds of the idle step the worker may take to wait for the robot.

    Raises
    ------
    SpecError
        Malformed, or not of GR(1) form.
    UnrealizableError
        No strategy exists; the message explains why (no motion is planned).
    """
    specification = build_specification(text, cell, reactive=True)
    final = [c for label, c in specification.always_on if label.startswith("final region")]
    gr1 = split_gr1(specification.user_formula, specification.inputs)
    if final:
        gr1 = Gr1Spec(gr1.assumptions, (*gr1.guarantees, Gr1Conjunct(
            "eventually", final[0].arg, plain_text(final[0]))), gr1.inputs)
    idle = Atom("wait", (repr(float(wait_step)),))
    tasks = tuple(dict.fromkeys((*specification.tasks, idle)))
    labels = tuple(letter_of(t, specification.vocabulary) for t in tasks)
    model = CellModel.from_cell(cell)
    plant, states = _plant(model, tasks, labels)
    game = Gr1Game(gr1, plant)
    if not game.solve():
        raise UnrealizableError("unrealizable: " + explain_unrealizable(
            gr1, plant, lambda t: _readable(t, specification), tuple(t.key for t in tasks)),
            text=specification.text)
    return ReactiveWorker(specification, gr1, tasks, plant, game, game.strategy(), model,
                          states)


def random_input_lasso(worker: ReactiveWorker, rng: np.random.Generator, *,
                       max_prefix: int = 3, max_cycle: int = 4, tries: int = 500
                       ) -> tuple[list[dict[str, bool]], list[dict[str, bool]]]:
    """A seeded random robot behaviour ``prefix . cycle^omega`` that keeps the
    assumptions: random orders of the input values and random dwell (a value held for
    several steps), from a random walk on the assumptions' safety, closed into a loop
    and kept when the evaluator says it meets every assumption.

    Raises
    ------
    SpecError
        When ``tries`` draws found none (assumptions that few behaviours keep).
    """
    game = worker.game
    aut = game.aut
    names = game.inputs
    values = list(input_valuations(names))
    env_init, env_action = aut.init["env"], aut.action["env"]

    def env(v: dict[str, bool], primed: bool = False) -> dict[str, bool]:
        return {game._env[k] + ("'" if primed else ""): b for k, b in v.items()}

    def ok_init(v: dict[str, bool]) -> bool:
        return aut.let(env(v), env_init) == aut.true if names else True

    def ok_step(a: dict[str, bool], b: dict[str, bool]) -> bool:
        return aut.let({**env(a), **env(b, True)}, env_action) == aut.true if names else True

    assumption = worker.gr1.assumption_formula()
    for _ in range(tries):
        n_pre = int(rng.integers(0, max_prefix + 1))
        n_cyc = int(rng.integers(1, max_cycle + 1))
        starts = [v for v in values if ok_init(v)]
        if not starts:
            break
        word = [starts[int(rng.integers(len(starts)))]]
        while len(word) < n_pre + n_cyc:
            nxt = [v for v in values if ok_step(word[-1], v)]
            if not nxt:
                break
            if rng.random() < 0.4 and word[-1] in nxt:
                word.append(word[-1])           # the robot dwells
            else:
                word.append(nxt[int(rng.integers(len(nxt)))])
        if len(word) < n_pre + n_cyc or not ok_step(word[-1], word[n_pre]):
            continue
        pre, cyc = word[:n_pre], word[n_pre:]
        letters = [frozenset(k for k, b in v.items() if b) for v in word]
        if evaluate_lasso(assumption, letters[:n_pre], letters[n_pre:]):
            return pre, cyc
    raise SpecError(f"no random robot behaviour keeping the assumptions was found in "
                    f"{tries} draws")


def run_strategy(worker: ReactiveWorker, prefix: list[dict[str, bool]],
                 cycle: list[dict[str, bool]]) -> JointLasso:
    """Run the strategy from its start on inputs ``prefix . cycle^omega``; the joint run
    as an exact lasso (it closes when the strategy's state repeats at the same place of
    the input cycle), as short as the joint word allows.

    Raises
    ------
    SpecError
        When the run has not closed within :data:`MAX_RUN_STEPS` steps.
    """
    strategy = worker.strategy
    strategy.reset()
    word = list(prefix) + list(cycle)
    n = len(prefix)
    seen: dict[tuple, int] = {}
    inputs: list[dict[str, bool]] = []
    tasks: list[int] = []
    pos = 0
    for i in range(MAX_RUN_STEPS):
        inputs.append(word[pos])
        tasks.append(strategy.step(word[pos]))
        if pos >= n:
            key = (strategy.memory(), pos)
            if key in seen:
                j = seen[key]
                return _shortest(list(zip(inputs, tasks)), j + 1)
            seen[key] = i
        pos = pos + 1 if pos + 1 < len(word) else n
    raise SpecError(f"the strategy's run did not repeat within {MAX_RUN_STEPS} steps")


def _shortest(steps: list[tuple[dict[str, bool], int]], n_prefix: int) -> JointLasso:
    """The shortest lasso of the same infinite word as ``steps`` (looping back to
    ``n_prefix``): the cycle cut to its smallest period, the prefix rolled into it."""
    pre, cyc = steps[:n_prefix], steps[n_prefix:]
    m = len(cyc)
    period = next(p for p in range(1, m + 1) if m % p == 0 and cyc == cyc[:p] * (m // p))
    cyc = cyc[:period]
    while pre and pre[-1] == cyc[-1]:
        pre.pop()
        cyc = [cyc[-1], *cyc[:-1]]
    return JointLasso(tuple(x for x, _ in pre), tuple(k for _, k in pre),
                      tuple(x for x, _ in cyc), tuple(k for _, k in cyc))


def timed_run(worker: ReactiveWorker, events: Callable[[float], dict[str, bool]],
              until: float, *, grid: float = 0.05) -> tuple[JointLasso, list[float]]:
    """Run the strategy against a robot whose inputs are ``events(t)`` (``t`` in s) until
    ``until`` and ``events(until)`` ever after, observed at the end of each task.

    Each task lasts its estimated motion length
    (:data:`~ltl_human_motion.tasks.model.TIME_CALIBRATION`), ``wait`` its argument,
    rounded to ``grid`` s (at least one grid step).

    Returns
    -------
    run : JointLasso
    ends : list of float
        Time (s) at the end of each step of the run as returned (prefix, then cycle).
    """
    from ltl_human_motion.tasks.model import TIME_CALIBRATION

    timed = worker.model.with_timing(TIME_CALIBRATION)
    strategy = worker.strategy
    strategy.reset()
    last = int(np.ceil(until / grid))
    t = 0
    state = timed.initial_state()
    seen: dict[tuple, int] = {}
    steps: list[tuple[dict[str, bool], int]] = []
    ends: list[float] = []
    for i in range(MAX_RUN_STEPS):
        k = strategy.choose()
        moved = timed.step(state, worker.tasks[k])
        if moved is None:
            raise SpecError(f"the strategy chose {worker.tasks[k]}, which the worker's "
                            "model cannot do there")
        state, seconds = moved
        t += max(round(seconds / grid), 1)
        values = events(min(t, last) * grid)
        inputs = {key: bool(values.get(key, False)) for key in worker.gr1.inputs}
        strategy.observe(inputs)
        steps.append((inputs, k))
        ends.append(t * grid)
        key = (strategy.memory(), t if t < last else -1)
        if key in seen:
            run = _shortest(steps, seen[key] + 1)
            return run, ends[:len(run.prefix_tasks) + len(run.cycle_tasks)]
        seen[key] = i
    raise SpecError(f"the timed run did not repeat within {MAX_RUN_STEPS} steps")


def random_schedule(worker: ReactiveWorker, rng: np.random.Generator, *,
                    segments: tuple[int, int] = (1, 6), dwell: tuple[float, float] = (0.5, 8.0)
                    ) -> tuple[Callable[[float], dict[str, bool]], float]:
    """A seeded random robot behaviour in seconds: 1-6 segments, each holding random
    input values for a random dwell (0.5-8 s), then values that keep the assumptions
    when held forever. Returns ``(events(t), until)`` for :func:`timed_run`.

    Raises
    ------
    SpecError
        When no constant robot behaviour keeps the assumptions.
    """
    inputs = worker.gr1.inputs
    assumption = worker.gr1.assumption_formula()
    tails = [v for v in input_valuations(inputs)
             if evaluate_lasso(assumption, [], [frozenset(k for k, b in v.items() if b)])]
    if not tails:
        raise SpecError("no constant robot behaviour keeps the assumptions; timed robot "
                        "behaviours need one to end with")
    n = int(rng.integers(segments[0], segments[1] + 1))
    values = [{k: bool(rng.random() < 0.5) for k in inputs} for _ in range(n)]
    values.append(tails[int(rng.integers(len(tails)))])
    edges = np.concatenate([[0.0], np.cumsum(rng.uniform(dwell[0], dwell[1], n))])

    def events(t: float) -> dict[str, bool]:
        return values[min(int(np.searchsorted(edges, t, side="right")) - 1, n)]
    return events, float(edges[-1])


def keeps_assumptions(worker: ReactiveWorker, run: JointLasso) -> bool:
    """Whether the inputs of ``run`` keep every assumption (independent evaluator)."""
    def letters(xs: tuple[dict[str, bool], ...]) -> list[frozenset[str]]:
        return [frozenset(k for k, v in x.items() if v) for x in xs]
    return evaluate_lasso(worker.gr1.assumption_formula(), letters(run.prefix_inputs),
                          letters(run.cycle_inputs))


#: How :func:`draw_run` makes a robot behaviour: a random lasso of steps, a random
#: schedule in seconds, or the robot's own trajectory.
TRACE_KINDS = ("steps", "timed", "trajectory")


def draw_run(worker: ReactiveWorker, rng: np.random.Generator, kind: str,
             robot=None, tries: int = 50) -> tuple[JointLasso, str]:
    """The strategy's run on one seeded random robot behaviour that keeps the
    assumptions, and the kind actually drawn.

    ``kind`` is one of :data:`TRACE_KINDS`. ``"trajectory"`` needs ``robot`` (an
    object with ``period`` (s), ``at(t)`` and ``stopped(t)`` giving the inputs, e.g.
    :class:`~ltl_human_motion.robot.events.RobotEvents`): from a random phase it runs 1-3
    cycles, then stops. A behaviour that breaks an assumption is drawn again as
    ``"timed"``, then ``"steps"``.
    """
    if kind not in TRACE_KINDS:
        raise ValueError(f"kind must be one of {TRACE_KINDS}, got {kind!r}")
    if kind == "trajectory" and robot is not None:
        phase = float(rng.uniform(0.0, robot.period))
        until = int(rng.integers(1, 4)) * robot.period

        def events(t: float) -> dict[str, bool]:
            return robot.at(t + phase) if t < until else robot.stopped(t + phase)
        run, _ = timed_run(worker, events, until)
        if keeps_assumptions(worker, run):
            return run, "trajectory"
    if kind in ("timed", "trajectory"):
        for _ in range(tries):
            try:
                events, until = random_schedule(worker, rng)
            except SpecError:
                break
            run, _ = timed_run(worker, events, until)
            if keeps_assumptions(worker, run):
                return run, "timed"
    return run_strategy(worker, *random_input_lasso(worker, rng)), "steps"


def joint_satisfies(worker: ReactiveWorker, run: JointLasso) -> bool:
    """Whether the joint run meets the whole specification (independent evaluator)."""
    pre = [worker.letter(x, k) for x, k in zip(run.prefix_inputs, run.prefix_tasks)]
    cyc = [worker.letter(x, k) for x, k in zip(run.cycle_inputs, run.cycle_tasks)]
    return evaluate_lasso(worker.specification.formula, pre, cyc)
