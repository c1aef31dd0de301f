"""Motions of a reactive worker's runs, verified against the whole specification
(docs/reactive.md).

A strategy's run on one robot behaviour is a joint lasso of inputs and tasks
(:func:`~ltl_human_motion.tasks.reactive.run_strategy`). Its task sequence (prefix, then
the cycle once) is planned and verified by the existing pipeline; the letters the
verifier observes on the motion, joined step by step with the robot's inputs, are then
checked against the whole specification by the independent evaluator.

The motion of a run is a function of its task sequence alone (the random draws of the
planner are seeded by the sequence, not by the robot behaviour): many robot behaviours
make the strategy do the same tasks (10,000 random ones on the demo's specification make
171 task sequences), and those runs get the same motion, byte for byte.
:class:`RunMotions` plans and verifies each sequence's motion once
(:class:`SequenceMotion`, kept in a :class:`~ltl_human_motion.kernel.cache.BoundedCache`
keyed by the sequence's task indices) and joins its observed letters with each run's own
inputs.
"""

from __future__ import annotations

import hashlib
import zlib
from dataclasses import dataclass, field, replace

import numpy as np

from ltl_human_motion.errors import PlanningError, VerificationError
from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.ltl.evaluator import evaluate_lasso
from ltl_human_motion.ltl.formula import TRUE
from ltl_human_motion.ltl.sequences import TaskSequence
from ltl_human_motion.tasks.reactive import JointLasso, ReactiveWorker

__all__ = ["MOTION_ATTEMPTS", "RunMotions", "SequenceMotion", "TraceMotion", "motion_of_run",
           "motion_sha256"]

#: Random draws of a task sequence's motion tried before it is reported not verified (as
#: :data:`~ltl_human_motion.planning.strategy_motion.MOVE_ATTEMPTS` for the live player's
#: moves). With one draw per run, 6 of 783 runs failed ``joint_speed``, each at a toe in a
#: walk: the gait graph's transitions turn -> forward at 1.24 m/s -> stop left the swing
#: toe 12-17 cm off; with the pipeline's repair (those junctions' ramps stretched) the
#: blended toe peaks at the forward clip's own 4.47 m/s, and giving the bones their lengths
#: back carries the knee's shorter ramp down the shin to 4.94 m/s (limit 4.90 m/s). The
#: next draw walks another way.
MOTION_ATTEMPTS = 3

#: Task sequences whose motions :class:`RunMotions` keeps.
SEQUENCE_CACHE_SIZE = 4096


@dataclass
class TraceMotion:
    """The motion of one run and what its checks said.

    Attributes
    ----------
    verified : bool
        The pipeline's checks passed and the observed joint trace meets the whole
        specification.
    motion_checks : bool
        The pipeline's checks alone (collision, termination, smoothness, feet,
        biomechanics, the always-on conjuncts).
    observed_satisfies : bool
        The letters observed on the motion, joined with the inputs, meet the whole
        specification.
    duration : float
        Seconds of motion.
    reaction : float or None
        Longest wait step of the motion, s: from a wait, the worker starts its next task
        within this long of an event (None: no wait).
    failed : list of str
        Names of the failed checks, or the planning error's reason.
    detail : str
    synth : SynthesizedMotion or None
    sha256 : str
        Hash of the motion's bytes (:func:`motion_sha256`; empty when none was made).
    attempts : int
        Random draws planned for the sequence's motion.
    cached : bool
        The sequence's motion and its checks were made for an earlier run (same bytes).
    """

    verified: bool
    motion_checks: bool
    observed_satisfies: bool
    duration: float = 0.0
    reaction: float | None = None
    failed: list[str] = field(default_factory=list)
    detail: str = ""
    synth: object = None
    sha256: str = ""
    attempts: int = 0
    cached: bool = False


@dataclass(frozen=True)
class SequenceMotion:
    """The planned and verified motion of one task sequence.

    Attributes
    ----------
    synth : SynthesizedMotion or None
        None when no draw could be planned.
    passed : bool
        The pipeline's checks passed.
    failed : tuple of str
        Failed checks of the last draw, or the planning error's reason.
    detail : str
    attempts : int
        Draws planned (the first verified one is kept, else the last).
    sha256 : str
        :func:`motion_sha256` of ``synth`` (empty when None).
    rejected : tuple of str
        Why each draw before the kept one was not kept (its failed checks' details).
    """

    synth: object
    passed: bool
    failed: tuple[str, ...]
    detail: str
    attempts: int
    sha256: str
    rejected: tuple[str, ...] = ()


def motion_sha256(synth) -> str:
    """SHA-256 of a synthesized motion's bytes: joint positions (T, J, 3), root yaw (T,),
    task index (T,) and object tracks (T, 3) by name."""
    h = hashlib.sha256()
    for a in (synth.motion.positions, synth.root_yaw, synth.task_index):
        h.update(np.ascontiguousarray(a).tobytes())
    for name in sorted(synth.objects):
        h.update(name.encode())
        h.update(np.ascontiguousarray(synth.objects[name]).tobytes())
    return h.hexdigest()


class RunMotions:
    """Motions of a worker's runs: each task sequence planned and verified once.

    Parameters
    ----------
    worker : ReactiveWorker
    cell : Cell
    library : MotionLibrary
    seed : int
        Base seed; a sequence's draws are seeded by it and the variant ``crc32(sequence) *
        MOTION_ATTEMPTS + attempt``.
    stature : float
        m.
    options : SynthesisOptions, optional
    cache_size : int
        Task sequences kept (the oldest goes first).
    """

    def __init__(self, worker: ReactiveWorker, cell, library, seed: int, stature: float,
                 options=None, cache_size: int = SEQUENCE_CACHE_SIZE) -> None:
        from ltl_human_motion.ltl.spec import Specification
        from ltl_human_motion.planning.pipeline import SynthesisOptions

        self.worker, self.cell, self.library = worker, cell, library
        self.seed, self.stature = int(seed), float(stature)
        self.options = replace(options or SynthesisOptions(), verify=False)
        spec = worker.specification
        # The motion's own checks take the always-on conjuncts; the inputs are not on the
        # motion, so the whole specification is checked on each run's joint trace.
        self._motion_spec = Specification(text=spec.text, user_formula=TRUE,
                                          always_on=spec.always_on, tasks=worker.tasks,
                                          vocabulary=spec.vocabulary)
        self._cache: BoundedCache[SequenceMotion] = BoundedCache(cache_size)
        #: Task sequences planned so far, and draws planned for them.
        self.planned = 0
        self.draws = 0

    def sequence_motion(self, prefix: tuple[int, ...], cycle: tuple[int, ...]
                        ) -> tuple[SequenceMotion, bool]:
        """The motion of task indices ``prefix`` then ``cycle`` (once), and whether it
        came from the cache."""
        key = (tuple(prefix), tuple(cycle))
        hit = self._cache.get(key)
        if hit is not None:
            return hit, True
        return self._cache.put(key, self._plan(*key)), False

    def _plan(self, prefix: tuple[int, ...], cycle: tuple[int, ...]) -> SequenceMotion:
        from ltl_human_motion.planning.feasibility import check_steps
        from ltl_human_motion.planning.pipeline import MotionRequest, _synthesize_one

        tasks = self.worker.tasks
        seq = TaskSequence(tuple(tasks[k] for k in prefix), tuple(tasks[k] for k in cycle))
        text = f"{' ; '.join(t.key for t in seq.prefix)} | {' ; '.join(t.key for t in seq.cycle)}"
        tag = zlib.crc32(text.encode())
        self.planned += 1
        try:
            check_steps(self.cell, [(t.name, tuple(t.args)) for t in seq.tasks], self.stature)
        except PlanningError as exc:
            return SequenceMotion(None, False, (str(exc.reason or "planning"),), str(exc), 0,
                                  "")
        last = SequenceMotion(None, False, ("planning",), "", 0, "")
        rejected: list[str] = []
        for attempt in range(MOTION_ATTEMPTS):
            if attempt:
                rejected.append(last.detail or ", ".join(last.failed))
            self.draws += 1
            try:
                synth = _synthesize_one(MotionRequest(
                    self.worker.specification.text, self._motion_spec, seq, self.cell,
                    self.library, self.seed, tag * MOTION_ATTEMPTS + attempt, self.options,
                    self.stature))
            except (PlanningError, VerificationError) as exc:
                reason = getattr(exc, "reason", None) or getattr(exc, "check", None) \
                    or "planning"
                last = SequenceMotion(None, False, (str(reason),), str(exc), attempt + 1, "",
                                      tuple(rejected))
                continue
            report = synth.verification
            failed = tuple(k for k, c in report.items()
                           if isinstance(c, dict) and not c["passed"])
            last = SequenceMotion(synth, bool(report["passed"]), failed,
                                  "; ".join(f"{k}: {report[k]['detail']}" for k in failed),
                                  attempt + 1, motion_sha256(synth), tuple(rejected))
            if last.passed:
                break
        return last

    def motion(self, run: JointLasso) -> TraceMotion:
        """The motion of ``run``'s tasks and its checks, with the observed letters joined
        with ``run``'s inputs and checked against the whole specification."""
        seq, cached = self.sequence_motion(run.prefix_tasks, run.cycle_tasks)
        if seq.synth is None:
            return TraceMotion(False, False, False, failed=list(seq.failed), detail=seq.detail,
                               attempts=seq.attempts, cached=cached)
        synth = seq.synth
        observed = [frozenset(x) for x in synth.verification["ltl"]["trace"]]
        inputs = [*run.prefix_inputs, *run.cycle_inputs]
        joint = [letter | frozenset(k for k, v in x.items() if v)
                 for letter, x in zip(observed, inputs)]
        n = len(run.prefix_tasks)
        observed_ok = len(joint) == len(inputs) and evaluate_lasso(
            self.worker.specification.formula, joint[:n], joint[n:])
        failed = list(seq.failed) + ([] if observed_ok else ["reactive_ltl"])
        fps = synth.motion.fps
        waits = [(s.end_frame - s.start_frame) / fps for s in synth.timeline
                 if s.task.startswith("wait(")]
        return TraceMotion(seq.passed and observed_ok, seq.passed, observed_ok,
                           float(synth.motion.duration), max(waits) if waits else None,
                           failed, seq.detail, synth, seq.sha256, seq.attempts, cached)


def motion_of_run(worker: ReactiveWorker, run: JointLasso, cell, library, seed: int,
                  stature: float, options=None) -> TraceMotion:
    """Plan, blend and verify the motion of ``run``'s tasks (prefix, cycle once), without
    a cache (:class:`RunMotions` keeps the motions of the sequences it planned).

    Parameters
    ----------
    worker : ReactiveWorker
    run : JointLasso
    cell : Cell
    library : MotionLibrary
    seed : int
    stature : float
        m.
    options : SynthesisOptions, optional
    """
    return RunMotions(worker, cell, library, seed, stature, options, cache_size=1).motion(run)
