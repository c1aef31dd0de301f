"""Motions of a reactive worker's runs, verified against the whole specification
(docs/reactive.md).

A strategy's run on one robot behaviour is a joint lasso of inputs and tasks
(:func:`~ltl_human_motion.tasks.reactive.run_strategy`). Its task sequence (prefix, then
the cycle once) is planned and verified by the existing pipeline; the letters the
verifier observes on the motion, joined step by step with the robot's inputs, are then
checked against the whole specification by the independent evaluator.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ltl_human_motion.errors import PlanningError, VerificationError
from ltl_human_motion.ltl.evaluator import evaluate_lasso
from ltl_human_motion.ltl.formula import TRUE
from ltl_human_motion.ltl.sequences import TaskSequence
from ltl_human_motion.tasks.reactive import JointLasso, ReactiveWorker

__all__ = ["TraceMotion", "motion_of_run"]


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
    """

    verified: bool
    motion_checks: bool
    observed_satisfies: bool
    duration: float = 0.0
    reaction: float | None = None
    failed: list[str] = field(default_factory=list)
    detail: str = ""
    synth: object = None


def motion_of_run(worker: ReactiveWorker, run: JointLasso, cell, library, seed: int,
                  stature: float, options=None) -> TraceMotion:
    """Plan, blend and verify the motion of ``run``'s tasks (prefix, cycle once).

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
    from ltl_human_motion.ltl.spec import Specification
    from ltl_human_motion.planning.feasibility import check_steps
    from ltl_human_motion.planning.pipeline import SynthesisOptions, _synthesize_one

    options = replace(options or SynthesisOptions(), verify=False)
    spec = worker.specification
    tasks = [worker.tasks[k] for k in (*run.prefix_tasks, *run.cycle_tasks)]
    # The motion's own checks take the always-on conjuncts; the inputs are not on the
    # motion, so the whole specification is checked below on the joint trace.
    motion_spec = Specification(text=spec.text, user_formula=TRUE, always_on=spec.always_on,
                                tasks=worker.tasks, vocabulary=spec.vocabulary)
    seq = TaskSequence(tuple(tasks[:len(run.prefix_tasks)]),
                       tuple(tasks[len(run.prefix_tasks):]))
    try:
        check_steps(cell, [(t.name, tuple(t.args)) for t in seq.tasks], stature)
        rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, 0])
        synth = _synthesize_one(spec.text, motion_spec, seq, cell, library, rng, seed, 0,
                                options, 0.0, 0.0, 0.0, float(stature))
    except (PlanningError, VerificationError) as exc:
        reason = getattr(exc, "reason", None) or getattr(exc, "check", None) or "planning"
        return TraceMotion(False, False, False, failed=[str(reason)], detail=str(exc))
    report = synth.verification
    observed = [frozenset(x) for x in report["ltl"]["trace"]]
    inputs = [*run.prefix_inputs, *run.cycle_inputs]
    joint = [letter | frozenset(k for k, v in x.items() if v)
             for letter, x in zip(observed, inputs)]
    n = len(run.prefix_tasks)
    observed_ok = len(joint) == len(inputs) and evaluate_lasso(spec.formula, joint[:n],
                                                               joint[n:])
    failed = [k for k, c in report.items() if isinstance(c, dict) and not c["passed"]]
    if not observed_ok:
        failed.append("reactive_ltl")
    detail = "; ".join(f"{k}: {report[k]['detail']}" for k in failed if k in report)
    fps = synth.motion.fps
    waits = [(s.end_frame - s.start_frame) / fps for s in synth.timeline
             if s.task.startswith("wait(")]
    return TraceMotion(bool(report["passed"]) and observed_ok, bool(report["passed"]),
                       observed_ok, float(synth.motion.duration),
                       max(waits) if waits else None, failed, detail, synth)
