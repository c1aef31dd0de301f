"""The synthesis pipeline: LTL specification and cell in, verified motions out.

Stages (timed separately, as in the paper's Tab. III):

1. ``automaton``  parse the specification, add the always-on conjuncts, translate;
2. ``sequence``   task sequences from accepting lassos (variations);
3. ``planning``   A* over the gait primitives and goal primitives per task;
4. ``blending``   concatenate with the cubic C1 blend, track the objects;
5. ``verification`` every check of :mod:`.verify`; a failing motion is not returned.
"""

from __future__ import annotations

import functools
import inspect
import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ltl_human_motion.deadline import Deadline, checkpoint
from ltl_human_motion.deadline import active as active_deadline
from ltl_human_motion.errors import PlanningError, VerificationError
from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion.realism import realism_summary
from ltl_human_motion.motion.retarget import enforce_bone_lengths
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX
from ltl_human_motion.motion.types import Motion
from ltl_human_motion.planning.blend import JUNCTION_SPREAD, concatenate, junction_frames
from ltl_human_motion.planning.feasibility import check_steps
from ltl_human_motion.planning.footlock import lock_feet
from ltl_human_motion.planning.junction_repair import (
    JUNCTION_REPAIRS,
    JunctionRepairs,
    repaired,
    unlock_weights,
)
from ltl_human_motion.planning.plan_state import PlannerOptions
from ltl_human_motion.planning.planner import Plan, SequencePlanner
from ltl_human_motion.planning.result import SynthesisStats, SynthesizedMotion, TaskSegment
from ltl_human_motion.planning.verify import VerificationOptions, failure_error, verify_motion
from ltl_human_motion.scene.cell_yaml import resolve_cell
from ltl_human_motion.vocabulary import task_step, task_text

if TYPE_CHECKING:
    from ltl_human_motion.ltl.sequences import TaskSequence
    from ltl_human_motion.ltl.spec import Specification
    from ltl_human_motion.motion.library import MotionLibrary
    from ltl_human_motion.scene.cell import Cell

__all__ = ["SynthesisOptions", "get_library", "resolve_cell", "synthesize"]


@dataclass(frozen=True)
class SynthesisOptions:
    """Options of :func:`synthesize`.

    Attributes
    ----------
    sequence_mode : {"coverage", "random", "all"}
        How task-sequence variations are chosen (see :mod:`ltl_human_motion.ltl`).
    backend : {"auto", "builtin", "spot"}
        LTL translator.
    planner : PlannerOptions
    verification : VerificationOptions
    verify : bool
        Refuse motions that fail a check (default). False returns them with the report.
    library_source : str or None
        Extra motion files or a folder (e.g. a CMU BVH database) for the gait library.
    max_seconds : float or None
        Time budget of each call (s): checked between the stages and in the translator's
        and the A* search's loops; when spent,
        :class:`~ltl_human_motion.deadline.BudgetExhaustedError` names the stage.
    deadline : Deadline or None
        A :class:`~ltl_human_motion.deadline.Deadline` of the caller's instead (one it
        can cancel, e.g. a node shutting down); overrides ``max_seconds``.
    foot_locking : bool
        Join the primitives by offset blending and pin the planted feet
        (:mod:`~ltl_human_motion.planning.footlock`) before verification: whole-motion
        foot skate of S1/S2 0.0001 m/s instead of 0.06-0.09 m/s. Always done with the
        biomechanical checks (``VerificationOptions.biomechanics``, the default), which
        refuse a skating foot; this option is for verification without them, where a
        motion whose locked feet moved a pose into an obstacle is blended again without
        it (``stats.foot_locking`` says which).
    """

    sequence_mode: str = "all"
    backend: str = "auto"
    planner: PlannerOptions = field(default_factory=PlannerOptions)
    verification: VerificationOptions = field(default_factory=VerificationOptions)
    verify: bool = True
    library_source: str | None = None
    max_seconds: float | None = None
    deadline: Deadline | None = field(default=None, compare=False)
    foot_locking: bool = False

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SynthesisOptions:
        """Options from plain values, e.g. the ROS service's ``options_json``.

        Keys: ``sequence_mode``, ``backend``, ``verify``, ``library_source``,
        ``heuristic_speed``, ``max_nodes``, ``max_seconds`` (the time budget of each
        call, and of each search), ``cost_noise``, ``eps``, ``max_joint_speed``,
        ``biomechanics`` (false: without the biomechanical checks).
        Unknown keys raise ValueError naming them.
        """
        from ltl_human_motion.planning.astar import SearchBudget
        known = {"sequence_mode", "backend", "verify", "library_source", "heuristic_speed",
                 "max_nodes", "max_seconds", "cost_noise", "eps", "max_joint_speed",
                 "biomechanics"}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"unknown synthesis options {unknown}; expected some of "
                             f"{sorted(known)}")
        base = cls()
        planner = base.planner
        if "heuristic_speed" in data or "cost_noise" in data:
            planner = replace(planner, heuristic_speed=float(data.get(
                "heuristic_speed", planner.heuristic_speed)), cost_noise=float(data.get(
                    "cost_noise", planner.cost_noise)))
        if "max_nodes" in data or "max_seconds" in data:
            planner = replace(planner, budget=SearchBudget(
                int(data.get("max_nodes", planner.budget.max_nodes)),
                None if data.get("max_seconds", planner.budget.max_seconds) is None
                else float(data.get("max_seconds", planner.budget.max_seconds))))
        max_seconds = data.get("max_seconds")
        if max_seconds is not None:
            Deadline(max_seconds)                          # ValueError unless a number > 0
        ver = base.verification
        if "eps" in data or "max_joint_speed" in data:
            ver = replace(ver, eps=float(data.get("eps", ver.eps)),
                          max_joint_speed=float(data.get("max_joint_speed", ver.max_joint_speed)))
        if "biomechanics" in data:
            if not isinstance(data["biomechanics"], bool):
                raise ValueError(f"synthesis option 'biomechanics' must be true or false, "
                                 f"got {data['biomechanics']!r}")
            ver = replace(ver, biomechanics=data["biomechanics"])
        return cls(sequence_mode=str(data.get("sequence_mode", base.sequence_mode)),
                   backend=str(data.get("backend", base.backend)),
                   planner=planner, verification=ver, verify=bool(data.get("verify", True)),
                   library_source=data.get("library_source"),
                   max_seconds=None if max_seconds is None else float(max_seconds))


@functools.lru_cache(maxsize=8)
def get_library(stature: float = DEFAULT_STATURE, source: str | None = None):
    """The motion library for one body size, cached in memory and on disk."""
    from ltl_human_motion.motion.library import load_library
    return load_library(stature=stature, source=source)


_SEQUENCE_CACHE: BoundedCache[list] = BoundedCache(256)


def _task_sequences(specification, cell, n: int, seed: int, mode: str, cycles: int,
                    backend: str) -> tuple[list, float, float]:
    """Task sequences from the cell model's product search (memoized per formula,
    candidate steps, cell and these arguments) and the seconds spent on the automaton
    and the sequences.

    Returns
    -------
    sequences, automaton_seconds, sequence_seconds
        The times are those of the call that computed the entry (0 on a cache hit).
    """
    from ltl_human_motion.tasks import plan_sequences
    key = (specification.formula, specification.letters, n,
           seed if mode == "random" else None, mode, cycles, backend)
    hit = _SEQUENCE_CACHE.get(key, owner=cell)
    if hit is not None:
        return hit, 0.0, 0.0
    # The cell model's product search builds the automaton on the fly, as it goes.
    sequences, stats = plan_sequences(specification, cell, n=n, seed=seed, mode=mode,
                                      cycles=cycles, backend=backend)
    t_automaton, t_sequence = stats.automaton_seconds, stats.search_seconds
    _SEQUENCE_CACHE.put(key, sequences, owner=cell)
    return sequences, t_automaton, t_sequence


def _start_pose(cell, first_target: np.ndarray | None, rng: np.random.Generator
                ) -> tuple[float, float, float]:
    """A floor pose inside the start region, facing the first target (seeded jitter)."""
    r0 = cell.start_region
    lo, hi = np.asarray(r0.lo, dtype=float), np.asarray(r0.hi, dtype=float)
    centre = (lo + hi) / 2.0
    half = np.maximum((hi - lo) / 2.0 - 0.05, 0.0)
    xy = centre[:2] + rng.uniform(-1.0, 1.0, 2) * np.minimum(half[:2], 0.1)
    if first_target is not None:
        yaw = math.atan2(first_target[1] - xy[1], first_target[0] - xy[0])
    else:
        yaw = 0.0
    yaw += float(rng.uniform(-0.3, 0.3))
    return float(xy[0]), float(xy[1]), yaw


def _object_tracks(cell, plan: Plan, spans: list[tuple[int, int]], positions: np.ndarray
                   ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Per-frame object positions (T, 3) and held masks (T,) from the step effects."""
    T = positions.shape[0]
    tracks: dict[str, np.ndarray] = {}
    held: dict[str, np.ndarray] = {}
    supply = {name: np.asarray(obj.position, dtype=float) for name, obj in cell.objects.items()}
    events: list[tuple[int, int, str, str, str | None]] = []
    flat = [sub for step in plan.steps for sub in (*step.sub_steps, step)]
    for order, step in enumerate(flat):
        if step.goal_segment is None:
            continue
        start = spans[step.goal_segment][0]
        contact = min(start + int(step.contact_frame or 0), T - 1)
        eff = step.objects_effect
        for name, joint in eff.attach:
            if name in eff.respawn:
                events.append((spans[step.first_segment][0], order, "respawn", name, None))
            events.append((contact, order, "grip", name, joint))
            # The part rests on its support until the hand lifts it (a grasp's lift frame).
            lift = contact if step.lift_frame is None else \
                min(start + int(step.lift_frame), T - 1)
            events.append((lift, order, "attach", name, joint))
        for name in eff.detach:
            events.append((contact, order, "detach", name, None))
    events.sort(key=lambda e: (e[0], e[1]))
    for name in cell.objects:
        pos = np.repeat(supply[name][None], T, axis=0)
        mask = np.zeros(T, dtype=bool)
        current = supply[name].copy()
        joint: str | None = None
        offset = grip = np.zeros(3)
        last = 0
        for frame, _, kind, obj, j in events:
            if obj != name:
                continue
            if joint is None:
                pos[last:frame] = current
            else:
                pos[last:frame] = positions[last:frame, JOINT_INDEX[joint]] + offset
                mask[last:frame] = True
            if kind == "respawn" and joint is None:
                current = supply[name].copy()
            elif kind == "grip":
                current = pos[frame - 1] if frame > 0 and joint is not None else current
                grip = current - positions[frame, JOINT_INDEX[j]]
            elif kind == "attach":
                current = pos[frame - 1] if frame > 0 and joint is not None else current
                joint = j
                offset = grip
            elif kind == "detach" and joint is not None:
                current = positions[frame, JOINT_INDEX[joint]] + offset
                joint = None
            last = frame
        if joint is None:
            pos[last:] = current
        else:
            pos[last:] = positions[last:, JOINT_INDEX[joint]] + offset
            mask[last:] = True
        tracks[name] = pos
        held[name] = mask
    return tracks, held


def _under_deadline(fn):
    """Run ``fn`` with ``options.deadline`` active (:func:`ltl_human_motion.deadline.active`)."""
    signature = inspect.signature(fn)

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any):
        options = signature.bind(*args, **kwargs).arguments.get("options")
        deadline = getattr(options, "deadline", None)
        if deadline is None and getattr(options, "max_seconds", None) is not None:
            deadline = Deadline(options.max_seconds)
        with active_deadline(deadline):
            return fn(*args, **kwargs)
    return wrapper


def _stature_of(library, stature: float | None) -> float:
    """The worker's stature, metres: ``stature``, else the library's, else
    ``DEFAULT_STATURE``; a ``ValueError`` where ``stature`` contradicts the library."""
    if library is not None and stature is not None \
            and abs(float(stature) - float(library.stature)) > 1e-6:
        raise ValueError(f"stature {float(stature):.3f} m does not match the library's "
                         f"{float(library.stature):.3f} m: pass one of them, or a library "
                         "of that stature (get_library(stature))")
    if stature is None:
        return DEFAULT_STATURE if library is None else float(library.stature)
    return float(stature)


@_under_deadline
def synthesize(spec: str, cell, library=None, variants: int = 1, seed: int = 0,
               cycles: int = 1, stature: float | None = None,
               options: SynthesisOptions | None = None) -> list[SynthesizedMotion]:
    """Synthesize ``variants`` verified full-body motions satisfying ``spec`` in ``cell``.

    Parameters
    ----------
    spec : str
        LTL specification (task predicates of Table I; a name of ``PAPER_SPECS`` such as
        ``"S1"`` also works).
    cell : Cell, str or Path
        The cell, its name (``config/<name>.yaml``), a YAML path or YAML text.
    library : MotionLibrary, optional
        Default: the cached library for ``stature``. Its skeleton's stature is the
        worker's (feasibility, verification, realism).
    variants : int
        Number of motions. Different task sequences come first (from the LTL
        variations); further variants re-plan sequences with other seeds.
    seed : int
        The same seed gives the same motions, byte for byte.
    cycles : int
        Repetitions of the accepting cycle.
    stature : float, optional
        Body height in metres; default the library's, else ``DEFAULT_STATURE``. Given with
        a library of another stature, a ``ValueError``.
    options : SynthesisOptions, optional

    Returns
    -------
    list of SynthesizedMotion
        Each verified (``.verification``) unless ``options.verify`` is False.

    Raises
    ------
    SpecError
        Malformed, ill-typed or unsatisfiable specification.
    CellError
        Malformed cell.
    PlanningError
        A task could not be planned (the message names the task and why).
    VerificationError
        A motion failed a check (the message names it). Before either is raised, up to
        ``OTHER_ORDERS`` other orders of the tasks are tried (the message says how many).
    """
    from ltl_human_motion.ltl.spec import build_specification

    if variants < 1:
        raise ValueError(f"variants must be >= 1, got {variants}")
    if cycles < 1:
        raise ValueError(f"cycles must be >= 1, got {cycles}")
    stature = _stature_of(library, stature)
    options = options or SynthesisOptions()
    t_all = time.perf_counter()
    cell = resolve_cell(cell)
    specification = build_specification(spec, cell)
    checkpoint("parsing")
    sequences, t_automaton, t_sequence = _task_sequences(
        specification, cell, variants, seed, options.sequence_mode, cycles, options.backend)
    checkpoint("sequence")
    if library is None:
        t0 = time.perf_counter()
        library = get_library(float(stature), options.library_source)
        t_library = time.perf_counter() - t0
    else:
        t_library = 0.0
    checkpoint("library")

    def one(seq, v: int, failed: dict | None = None) -> SynthesizedMotion:
        return _synthesize_one(MotionRequest(
            spec, specification, seq, cell, library, seed, v, options, float(stature),
            t_automaton, t_sequence, t_library, failed))
    others = functools.partial(_other_sequences, specification, cell,
                               variants + ORDER_CANDIDATES, seed, options, cycles)
    results = [_variant(one, sequences[v % len(sequences)], v, others, cell, float(stature))
               for v in range(variants)]
    total = time.perf_counter() - t_all
    for r in results:
        r.stats = replace(r.stats, batch_total_time=total)
    return results


#: Other task sequences (the next best of the product search) tried when the motion
#: planner cannot do a step in the order of the first; only those that never reach
#: the failed task after the same set of tasks (the same situation fails the same
#: way). A worker holding a bolt in one hand reached for a gear beside a shelf wall
#: with the other at 1.95 m; grasping the gear first worked (kitting, 1.95 m).
OTHER_ORDERS = 2
#: Sequences of the product search those are chosen from (many of the next best differ
#: from the first only by a task done again or a walk to where the worker is).
ORDER_CANDIDATES = 8

#: The planning failures another order of the steps may avoid (a blocked reach, a
#: search out of budget); the cell's own limits (reach, size, enclosed ...) are found
#: before any search and hold in every order.
_ORDER_REASONS = ("blocked", "budget", "unreachable")


def _variant(one: Callable[[Any, int], SynthesizedMotion], seq, v: int,
             others: Callable[[], list], cell, stature: float) -> SynthesizedMotion:
    """Variant ``v``: ``one(seq, v)``, refused before any search where no worker of
    this stature can do a step (:func:`.feasibility.check_steps`), else in another
    order of the tasks where the motion planner cannot (:func:`_in_another_order`)."""
    check_steps(cell, [(t.name, tuple(t.args)) for t in seq.tasks], stature)
    try:
        return one(seq, v)
    except PlanningError as exc:
        return _in_another_order(functools.partial(one, v=v), seq, exc, others, cell,
                                 stature)
    except VerificationError as exc:
        return _verified_in_another_order(functools.partial(one, v=v), seq, exc, others,
                                          cell, stature)


def _other_sequences(specification, cell, n: int, seed: int, options: SynthesisOptions,
                     cycles: int) -> list:
    """The first ``n`` task sequences of the product search (:func:`_task_sequences`)."""
    return _task_sequences(specification, cell, n, seed, options.sequence_mode, cycles,
                           options.backend)[0]


def _task_text(task) -> str:
    return task_text(task.name, tuple(task.args))


def _same_situation(other, seq, at: int, failed: set[str]) -> bool:
    """Whether sequence ``other`` comes to one of the ``failed`` tasks (texts) after the
    same tasks as ``seq`` came to its step ``at``, in any order and number (a task
    done again, a walk to where the worker is, leaves it in the same situation)."""
    before = {_task_text(t) for t in seq.tasks[:at]}
    done: set[str] = set()
    for task in other.tasks:
        if _task_text(task) in failed and done == before:
            return True
        done.add(_task_text(task))
    return False


def _failed_situation(seq, failure: PlanningError) -> tuple[int, set[str]] | None:
    """Where ``failure`` (raised planning ``seq``) happened, for :func:`_same_situation`:
    its step index and the texts of the task that failed; None if it does not say."""
    at = failure.step_index
    if at is None:
        return None
    return at, {_task_text(seq.tasks[at])} | ({failure.task} if failure.task else set())


def _in_another_order(one: Callable[[Any], SynthesizedMotion], seq,
                      failure: PlanningError, others: Callable[[], list], cell,
                      stature: float) -> SynthesizedMotion:
    """``one(sequence, failed=...)`` for the next sequences of ``others()`` (up to
    ``OTHER_ORDERS``) that do not come to the task ``failure`` (raised by ``one(seq)``)
    names in the same situation (:func:`_same_situation`); the first that plans. A step
    that failed in one order fails at once in another that comes to it holding the same
    parts with the same parts moved (``failed``: by
    :meth:`.planner.SequencePlanner.situation`). Raises ``failure`` (saying how many
    orders were tried) if none does, or if its reason is not one another order can
    change."""
    where = _failed_situation(seq, failure)
    if failure.reason not in _ORDER_REASONS or where is None:
        raise failure
    # every situation a step failed in so far: an order that comes to one of them again
    # is not tried (it would fail the same way)
    situations = [(seq, *where)]
    known = {} if failure.situation is None else {failure.situation: failure}
    tried = 0
    for other in _orders(others, cell, stature, lambda other: any(
            _same_situation(other, s, at, texts) for s, at, texts in situations)):
        tried += 1
        try:
            return _after_failures(one(other, failed=known), tried, failure)
        except PlanningError as exc:
            where = _failed_situation(other, exc)
            if where is not None:
                situations.append((other, *where))
            if exc.situation is not None:
                known.setdefault(exc.situation, exc)
    if tried:
        raise PlanningError(f"{failure}; {tried} other order(s) of the tasks failed too",
                            task=failure.task, reason=failure.reason) from failure
    raise failure


def _verified_in_another_order(one: Callable[[Any], SynthesizedMotion], seq,
                               failure: VerificationError, others: Callable[[], list],
                               cell, stature: float) -> SynthesizedMotion:
    """``one(sequence)`` for the next sequences of ``others()`` other than ``seq`` (see
    :func:`_orders`), where the motion of ``seq`` failed verification (``failure``,
    after the junction repairs): the first whose motion verifies. Raises ``failure``
    (saying how many orders were tried) if none does."""
    tried = 0
    for other in _orders(others, cell, stature, lambda other: other.tasks == seq.tasks):
        tried += 1
        try:
            return _after_failures(one(other), tried, failure)
        except (PlanningError, VerificationError):
            continue
    if tried:
        raise VerificationError(f"{failure}; {tried} other order(s) of the tasks failed "
                                "too", failure.check) from failure
    raise failure


def _after_failures(synth: SynthesizedMotion, failed: int, first: Exception
                    ) -> SynthesizedMotion:
    """``synth`` with ``stats.orders_failed`` (orders of the tasks that failed before its
    own) and ``stats.first_failure`` (why the first did)."""
    synth.stats = replace(synth.stats, orders_failed=failed, first_failure=str(first))
    return synth


def _orders(others: Callable[[], list], cell, stature: float, skip: Callable[[Any], bool]
            ) -> Iterator[Any]:
    """The next sequences of ``others()`` that ``skip`` (asked as each comes) does not
    rule out and a worker of this stature can do (:func:`.feasibility.check_steps`), at
    most ``OTHER_ORDERS``."""
    tried = 0
    for other in others():
        if tried >= OTHER_ORDERS:
            return
        if skip(other):
            continue
        try:
            check_steps(cell, [(t.name, tuple(t.args)) for t in other.tasks], stature)
        except PlanningError:
            continue
        tried += 1
        yield other


def _blended(plan: Plan, floor_cell, floor_z: float, library, realism: bool,
             spec_text: str, sequence: list[str], seed: int, variant: int,
             repairs: JunctionRepairs | None = None
             ) -> tuple[SynthesizedMotion, dict[str, np.ndarray], list[tuple[int, int]]]:
    """The plan's segments blended into one motion (with offset blending of junctions,
    as ``repairs`` changed them, and foot locking when ``realism``), its part tracks and
    task timeline, lifted from the planner's floor at z = 0 (``floor_cell``) by
    ``floor_z``; the held masks (T,) and the frame span of each segment."""
    repairs = repairs or JunctionRepairs()
    positions, root_yaw, _labels, spans = concatenate(
        plan.segments, spread=round(JUNCTION_SPREAD * library.fps) if realism else 0,
        fps=library.fps if realism else None, shares=repairs.shares,
        stretch=repairs.stretch)
    # Linear blends of joint positions shorten bones between unlike poses; restore them.
    positions = enforce_bone_lengths(positions, library.skeleton, rigid_hips=False)
    if realism:
        unlocked = positions
        positions = lock_feet(positions, library.fps, library.skeleton, 0.0)
        if repairs.unlock:
            w = unlock_weights(repairs.unlock, len(positions), library.fps)[:, None, None]
            positions = enforce_bone_lengths(positions + w * (unlocked - positions),
                                             library.skeleton, rigid_hips=False)
    tracks, held = _object_tracks(floor_cell, plan, spans, positions)
    targets = [step.target for step in plan.steps]
    if floor_z:
        lift = np.array([0.0, 0.0, float(floor_z)])
        positions = positions + lift
        tracks = {name: track + lift for name, track in tracks.items()}
        targets = [None if t is None else np.asarray(t) + lift for t in targets]
    timeline = []
    for step, target in zip(plan.steps, targets):
        if step.goal_segment is not None:
            a, b = spans[step.goal_segment]
        else:
            a = spans[step.first_segment][0]
            b = spans[step.last_segment][1]
        timeline.append(TaskSegment(step.task, a, b, step.primitive, target))
    task_index = np.full(positions.shape[0], -1, dtype=np.int64)
    for i, seg in enumerate(timeline):
        task_index[seg.start_frame:seg.end_frame] = i
    motion = Motion(positions, library.fps, library.skeleton,
                    name=f"{floor_cell.name}-seed{seed}-v{variant}")
    return SynthesizedMotion(motion=motion, root_yaw=root_yaw, task_index=task_index,
                             timeline=timeline, objects=tracks, spec=spec_text,
                             sequence=sequence, seed=int(seed)), held, spans


def _step_frames(plan: Plan, spans: list[tuple[int, int]]) -> list[dict[str, Any]]:
    """Every goal step of ``plan`` (sub-steps before their step) with its sequence
    index, hand and frames of the motion: ``goal`` [start, end) of its goal primitive,
    ``contact`` (the task's condition first holds) and ``lift`` (a grasp carries from)."""
    out = []
    for i, step in enumerate(plan.steps):
        for sub in (*step.sub_steps, step):
            if sub.goal_segment is None:
                continue
            a, b = spans[sub.goal_segment]
            out.append({"step": i, "task": sub.task, "kind": sub.kind, "hand": sub.hand,
                        "goal": [int(a), int(b)],
                        "contact": None if sub.contact_frame is None
                        else min(a + int(sub.contact_frame), b - 1),
                        "lift": None if sub.lift_frame is None
                        else min(a + int(sub.lift_frame), b - 1)})
    return out


@dataclass(frozen=True)
class MotionRequest:
    """One motion for :func:`synthesize` to make: a task sequence of the specification,
    planned, blended and verified in the cell.

    Attributes
    ----------
    spec_text : str
        The specification as the user wrote it (kept in the motion).
    specification : Specification
        Its parse, which the motion is verified against.
    sequence : TaskSequence
        The tasks in order.
    cell : Cell
    library : MotionLibrary
    seed : int
    variant : int
        Which motion of the call; with ``seed`` it seeds the plan's generator.
    options : SynthesisOptions
    stature : float
        The worker's, metres.
    automaton_time, sequence_time, library_time : float
        Seconds the call spent on the automaton, the sequences and the library (they
        count into the motion's ``total_time``).
    failed : dict, optional
        Steps that failed in an earlier order of the tasks
        (:attr:`.planner.SequencePlanner.failed_before`).
    """

    spec_text: str
    specification: Specification
    sequence: TaskSequence
    cell: Cell
    library: MotionLibrary
    seed: int
    variant: int
    options: SynthesisOptions
    stature: float
    automaton_time: float = 0.0
    sequence_time: float = 0.0
    library_time: float = 0.0
    failed: dict[tuple, PlanningError] | None = None


def _synthesize_one(request: MotionRequest) -> SynthesizedMotion:
    t_start = time.perf_counter()
    spec_text, specification, seq = request.spec_text, request.specification, request.sequence
    cell, library, seed, variant = request.cell, request.library, request.seed, request.variant
    options, stature = request.options, request.stature
    t_automaton, t_sequence = request.automaton_time, request.sequence_time
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, variant])
    steps = [task_step(t.name, t.args, cell.shorthands, t.key) for t in seq.tasks]
    # Planned on a floor at z = 0; the motion, the parts and the targets are lifted back
    # (_blended) and verified in the user's own cell.
    floor_cell = cell.floor_at_zero()
    planner = SequencePlanner(floor_cell, library, rng, replace(
        options.planner, refuse_self_penetration=options.verification.biomechanics),
        failed_before=request.failed)
    start = _start_pose(floor_cell, planner.target_of(steps[0].kind, steps[0].args), rng)
    t0 = time.perf_counter()
    plan = planner.plan(steps, start)
    t_planning = time.perf_counter() - t0
    checkpoint("planning")

    # Offset blending of junctions and foot locking move poses after the planner checked
    # them; verification checks the final motion (collisions included). Where by default
    # they moved a pose into an obstacle, the motion is blended again without them.
    strict = options.verification.biomechanics
    attempts = [True, False] if options.foot_locking and not strict else [strict]
    t_blending = t_verify = 0.0
    for realism in attempts:
        repairs = JunctionRepairs()
        for repair in range(JUNCTION_REPAIRS + 1):
            t0 = time.perf_counter()
            synth, held, spans = _blended(plan, floor_cell, cell.floor_z, library, realism,
                                          spec_text, [s.text for s in steps], seed, variant,
                                          repairs)
            t_blending += time.perf_counter() - t0
            checkpoint("blending")

            t0 = time.perf_counter()
            report = verify_motion(synth, cell, specification, seq, options.verification,
                                   held=held, stature=stature,
                                   blend_frames=library.overlap, raise_on_failure=False)
            t_verify += time.perf_counter() - t0
            checkpoint("verification")
            if report["passed"] or not realism or repair == JUNCTION_REPAIRS:
                break
            moved = repaired(report, synth, cell, held, stature, junction_frames(spans),
                             repairs, repair > 0, options.verification.limits)
            if moved is None:
                break
            repairs = moved
        if report["passed"] or report["collision"]["passed"]:
            break
    if not report["passed"] and options.verify:
        raise failure_error(report)
    compute = time.perf_counter() - t_start + t_automaton + t_sequence
    motion, timeline = synth.motion, synth.timeline
    synth.verification = report
    synth.stats = SynthesisStats(
        automaton_time=t_automaton, sequence_time=t_sequence,
        library_time=request.library_time, planning_time=t_planning,
        blending_time=t_blending, verification_time=t_verify, total_time=compute,
        nodes_expanded=int(plan.expanded), duration=motion.duration,
        real_time_factor=motion.duration / compute if compute > 0 else float("inf"),
        variant=variant, lasso=str(seq),
        goal_primitives=[{"task": s.task, "primitive": s.primitive,
                          "target": None if timeline[i].target is None
                          else [float(x) for x in timeline[i].target],
                          "frames": [timeline[i].start_frame, timeline[i].end_frame],
                          "walk_primitives": s.walk_segments, "expanded": s.expanded}
                         for i, s in enumerate(plan.steps)],
        start_pose=list(plan.start_pose),
        steps=_step_frames(plan, spans),
        segments=[[seg.name, int(a), int(b)] for seg, (a, b) in zip(plan.segments, spans)],
        realism=realism_summary(motion.positions, library.fps, stature, cell.floor_z),
        foot_locking=bool(realism),
    )
    return synth
