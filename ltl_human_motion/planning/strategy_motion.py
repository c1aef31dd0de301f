"""A reactive worker's strategy with a verified motion for every move it can make
(docs/reactive.md, "Live in ROS").

Live, the worker's next task depends on the robot, so its motion cannot be one sequence
planned before playback. :func:`build_program` explores the strategy over every input
valuation (:func:`strategy_moves`: each move ``(worker state, task) -> worker state`` the
strategy can ever make) and plans each move once with the existing pipeline: the tasks
that first reach the move's worker state (a shortest path of the worker's model), then
the move's task, synthesized and verified as one motion, of which the move's own frames
(from the end of the task before to the end of its task) are kept as a
:class:`StepClip`. :class:`~ltl_human_motion.planning.strategy_executor.StrategyExecutor`
plays the clips as the strategy picks them.

A :class:`StrategyProgram` is saved as one ``.npz`` (:func:`save_program`, no pickles):
the specification, the cell as given, the stature and the clips; :func:`load_program`
solves the game again (deterministic: the same strategy) and checks that it makes the
same moves.
"""

from __future__ import annotations

import json
import uuid
from collections import deque
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ltl_human_motion.atomic import atomic_write_bytes
from ltl_human_motion.errors import PlanningError, SpecError, VerificationError
from ltl_human_motion.ltl.formula import TRUE
from ltl_human_motion.ltl.gr1 import input_valuations
from ltl_human_motion.ltl.sequences import TaskSequence
from ltl_human_motion.tasks.reactive import ReactiveWorker, reactive_worker

__all__ = ["START", "Move", "StepClip", "StrategyProgram", "build_program", "load_program",
           "new_strategy_id", "save_program", "strategy_moves"]

#: Worker state of the start, before the first move.
START = -1

#: Plans tried per move (other random draws) before the move is refused.
MOVE_ATTEMPTS = 3

#: Inputs valuations explored per strategy state; beyond, the exploration is refused.
MAX_EXPLORED_MEMORIES = 4096


@dataclass(frozen=True)
class Move:
    """One move of the strategy: ``task`` (index into the worker's tasks) from worker
    state ``source`` (:data:`START` at the start) to worker state ``target``."""

    source: int
    task: int
    target: int


@dataclass(frozen=True)
class StepClip:
    """The verified motion of one move.

    Attributes
    ----------
    move : Move
    task : str
        The task's key, e.g. ``"assemble(R1)"``.
    positions : ndarray, shape (T, J, 3)
        Joint positions, world frame, m.
    yaw : ndarray, shape (T,)
        Body heading about +z, rad (unwrapped).
    objects : dict of str to ndarray, shape (T, 3)
        Object positions, m.
    fps : float
    verified : bool
        The pipeline's checks passed on the motion the clip was cut from.
    failed : tuple of str
        The checks that failed (empty when verified).
    """

    move: Move
    task: str
    positions: np.ndarray
    yaw: np.ndarray
    objects: dict[str, np.ndarray]
    fps: float
    verified: bool
    failed: tuple[str, ...] = ()

    @property
    def duration(self) -> float:
        """Seconds of the clip (its last frame at this time)."""
        return (len(self.positions) - 1) / self.fps


@dataclass
class StrategyProgram:
    """A solved reactive specification and the motion of each of its moves.

    Attributes
    ----------
    strategy_id : str
    spec : str
    cell : str
        The cell as given (a name or inline YAML).
    stature : float
        m.
    worker : ReactiveWorker
    clips : dict of (int, int) to StepClip
        Keyed by (source worker state, task index).
    """

    strategy_id: str
    spec: str
    cell: str
    stature: float
    worker: ReactiveWorker
    clips: dict[tuple[int, int], StepClip]

    @property
    def verified(self) -> bool:
        """Every clip's motion passed the pipeline's checks."""
        return all(c.verified for c in self.clips.values())

    @property
    def inputs(self) -> tuple[str, ...]:
        """The specification's input keys, in the game's order."""
        return tuple(self.worker.gr1.inputs)


def new_strategy_id() -> str:
    """A fresh, unique strategy id such as ``strategy_3f2a9c1b7d4e``."""
    return f"strategy_{uuid.uuid4().hex[:12]}"


def strategy_moves(worker: ReactiveWorker) -> list[Move]:
    """Every move the strategy can make, over every input valuation at every step
    (breadth first over the strategy's states; sorted).

    Raises
    ------
    SpecError
        When the strategy has more than :data:`MAX_EXPLORED_MEMORIES` states.
    """
    values = list(input_valuations(worker.gr1.inputs))
    moves: set[Move] = set()
    seen: set[tuple] = {()}
    queue: deque[dict] = deque([{}])
    while queue:
        state = queue.popleft()
        # Each state is explored on its own copy: the worker's strategy is not touched.
        strategy = replace(worker.strategy, state=dict(state), _chosen={})
        try:
            task = strategy.choose()
        except SpecError:
            continue                           # inputs that broke an assumption
        chosen = dict(strategy._chosen)
        moves.add(Move(int(state["cs"]) if state else START, task, int(chosen["cs"])))
        for v in values:
            strategy = replace(worker.strategy, state=dict(state), _chosen=dict(chosen))
            strategy.observe(v)
            key = strategy.memory()
            if key not in seen:
                if len(seen) >= MAX_EXPLORED_MEMORIES:
                    raise SpecError(f"the strategy has more than {MAX_EXPLORED_MEMORIES} "
                                    "states (MAX_EXPLORED_MEMORIES); use fewer inputs")
                seen.add(key)
                queue.append(dict(strategy.state))
    return sorted(moves, key=lambda m: (m.source, m.task, m.target))


def _paths(worker: ReactiveWorker) -> dict[int, list[int]]:
    """A shortest task path from the start to each worker state (breadth first)."""
    plant = worker.plant
    paths: dict[int, list[int]] = {}
    queue: deque[tuple[int, list[int]]] = deque()
    for k, s2, _ in plant.initial:
        if s2 not in paths:
            paths[s2] = [k]
            queue.append((s2, [k]))
    while queue:
        s, path = queue.popleft()
        for k, s2, _ in plant.moves[s]:
            if s2 not in paths:
                paths[s2] = [*path, k]
                queue.append((s2, [*path, k]))
    return paths


def _clip(worker: ReactiveWorker, move: Move, path: list[int], cell, library, seed: int,
          stature: float, options, attempt: int) -> StepClip:
    """Plan and verify ``path`` then ``move.task``; keep the move's frames."""
    from ltl_human_motion.ltl.spec import Specification
    from ltl_human_motion.planning.pipeline import MotionRequest, _synthesize_one

    spec = worker.specification
    # The clip is checked for everything a motion is (collision, feet, biomechanics, the
    # always-on conjuncts); the final region is the whole run's, not one move's.
    always_on = tuple((label, c) for label, c in spec.always_on
                      if not label.startswith("final region"))
    motion_spec = Specification(text=spec.text, user_formula=TRUE, always_on=always_on,
                                tasks=worker.tasks, vocabulary=spec.vocabulary)
    prefix = tuple(worker.tasks[k] for k in path)
    seq = TaskSequence(prefix, (worker.tasks[move.task],))
    # One random draw per move and attempt (the variant seeds the plan's generator).
    variant = ((2 + move.source) * (len(worker.tasks) + 1) + 1 + move.task) * MOVE_ATTEMPTS \
        + attempt
    synth = _synthesize_one(MotionRequest(spec.text, motion_spec, seq, cell, library, seed,
                                          variant, options, float(stature)))
    timeline = synth.timeline
    n = len(prefix)
    if len(timeline) < n + 1:
        raise PlanningError(f"the motion of {' ; '.join(t.key for t in seq.tasks)} has "
                            f"{len(timeline)} task segments, expected {n + 1}")
    first = int(timeline[n - 1].end_frame) if n else 0
    last = int(timeline[n].end_frame)
    report = synth.verification
    failed = tuple(k for k, c in report.items() if isinstance(c, dict) and not c["passed"])
    yaw = np.unwrap(np.asarray(synth.root_yaw, dtype=np.float64))
    return StepClip(move, worker.tasks[move.task].key,
                    np.array(synth.motion.positions[first:last + 1], dtype=np.float64),
                    yaw[first:last + 1].copy(),
                    {k: np.array(v[first:last + 1], dtype=np.float64)
                     for k, v in synth.objects.items() if np.ndim(v) == 2},
                    float(synth.motion.fps), bool(report["passed"]), failed)


def build_program(text: str, cell_text: str, cell, library, *, seed: int = 0,
                  stature: float = 1.75, options=None, strategy_id: str | None = None,
                  ) -> StrategyProgram:
    """Solve ``text`` on ``cell`` and plan and verify the motion of every move.

    Parameters
    ----------
    text : str
        The reactive specification.
    cell_text : str
        The cell as the caller gave it (name or YAML), kept to solve it again on load.
    cell : Cell
    library : MotionLibrary
    seed : int
    stature : float
        m.
    options : SynthesisOptions, optional

    Raises
    ------
    SpecError, UnrealizableError
        As :func:`~ltl_human_motion.tasks.reactive.reactive_worker` (before any motion).
    PlanningError
        A move with no verified motion in :data:`MOVE_ATTEMPTS` random draws (the move and
        each draw's reason are named).
    """
    from ltl_human_motion.planning.pipeline import SynthesisOptions

    options = replace(options or SynthesisOptions(), verify=False)
    worker = reactive_worker(text, cell)
    paths = _paths(worker)
    clips: dict[tuple[int, int], StepClip] = {}
    for move in strategy_moves(worker):
        path = [] if move.source == START else paths[move.source]
        reasons: list[str] = []
        for attempt in range(MOVE_ATTEMPTS):
            try:
                clip = _clip(worker, move, path, cell, library, seed, stature, options, attempt)
            except (PlanningError, VerificationError) as exc:
                reasons.append(str(exc))
                continue
            if clip.verified:
                clips[(move.source, move.task)] = clip
                break
            reasons.append("failed " + ", ".join(clip.failed))
        else:
            where = "the start" if move.source == START else f"worker state {move.source}"
            raise PlanningError(f"the strategy's move {worker.tasks[move.task].key} from "
                                f"{where} has no verified motion in {MOVE_ATTEMPTS} attempts: "
                                + "; ".join(reasons))
    return StrategyProgram(strategy_id or new_strategy_id(), text, cell_text, float(stature),
                           worker, clips)


def save_program(program: StrategyProgram, path: str | Path) -> None:
    """Write ``program`` as one ``.npz`` (atomically; no pickles)."""
    import io

    clips = sorted(program.clips.values(), key=lambda c: (c.move.source, c.move.task))
    meta = {"format": "ltl_human_motion strategy 1", "strategy_id": program.strategy_id,
            "spec": program.spec, "cell": program.cell, "stature": program.stature,
            "tasks": [t.key for t in program.worker.tasks],
            "clips": [{"source": c.move.source, "task": c.move.task, "target": c.move.target,
                       "key": c.task, "fps": c.fps, "verified": c.verified,
                       "failed": list(c.failed), "objects": sorted(c.objects)}
                      for c in clips]}
    arrays: dict[str, np.ndarray] = {"meta": np.array(json.dumps(meta))}
    for i, c in enumerate(clips):
        arrays[f"positions_{i}"] = c.positions
        arrays[f"yaw_{i}"] = c.yaw
        for j, name in enumerate(sorted(c.objects)):
            arrays[f"object_{i}_{j}"] = c.objects[name]
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    atomic_write_bytes(path, buffer.getvalue())


def load_program(path: str | Path, cell=None) -> StrategyProgram:
    """Read a program written by :func:`save_program` and solve its game again.

    ``cell`` is the resolved cell (default: resolve the saved one).

    Raises
    ------
    ValueError
        An unreadable or malformed file, or a strategy that no longer makes the saved
        moves (the cell or the code changed); the message names the file.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"].reshape(-1)[0]))
            entries = meta["clips"]
            positions = [z[f"positions_{i}"] for i in range(len(entries))]
            yaws = [z[f"yaw_{i}"] for i in range(len(entries))]
            objects = [{name: z[f"object_{i}_{j}"] for j, name in enumerate(e["objects"])}
                       for i, e in enumerate(entries)]
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise ValueError(f"{path}: not a strategy file ({type(exc).__name__}: {exc})") \
            from None
    if cell is None:
        from ltl_human_motion.scene.cell_yaml import resolve_cell
        cell = resolve_cell(meta["cell"])
    worker = reactive_worker(meta["spec"], cell)
    if [t.key for t in worker.tasks] != meta["tasks"]:
        raise ValueError(f"{path}: the specification now has the tasks "
                         f"{[t.key for t in worker.tasks]}, the file {meta['tasks']}")
    clips = {}
    for e, pos, yaw, objs in zip(entries, positions, yaws, objects):
        move = Move(int(e["source"]), int(e["task"]), int(e["target"]))
        clips[(move.source, move.task)] = StepClip(move, e["key"], pos, yaw, objs,
                                                   float(e["fps"]), bool(e["verified"]),
                                                   tuple(e["failed"]))
    missing = [m for m in strategy_moves(worker) if (m.source, m.task) not in clips]
    if missing:
        raise ValueError(f"{path}: the strategy now makes moves the file has no motion for "
                         f"({', '.join(worker.tasks[m.task].key for m in missing)})")
    return StrategyProgram(meta["strategy_id"], meta["spec"], meta["cell"],
                           float(meta["stature"]), worker, clips)
