"""Run one labelled pair through the synthesis pipeline and judge the outcome.

Shared by ``bench/scenarios.py`` and the test suite: :func:`run_pair` synthesizes and
classifies what happened (verified, refused with which error, timed out);
:func:`judge` compares that with the pair's label and names the failure family.
"""

from __future__ import annotations

import re
import signal
import time
from dataclasses import asdict, dataclass

from ltl_human_motion.errors import (
    CellError,
    LtlHumanMotionError,
    PlanningError,
    SpecError,
    VerificationError,
)

__all__ = ["Outcome", "failure_cause", "judge", "prepare_cell", "run_pair"]


class _PairTimeoutError(Exception):
    """Raised by the alarm when a pair runs past its time limit; ``task`` is the task
    step the planner was working on (None if it was elsewhere)."""

    def __init__(self, task: str | None = None) -> None:
        super().__init__(task)
        self.task = task


@dataclass
class Outcome:
    """What one synthesis call did.

    Attributes
    ----------
    status : {"verified", "planning", "verification", "spec", "cell", "timeout", "crash"}
    seconds : float
        Wall time of the synthesize call (the motion library is loaded before).
    reason : str or None
        ``PlanningError.reason`` (or ``"unsatisfiable"`` for an unsatisfiable
        specification), the failed check for verification errors.
    task : str or None
        The task a PlanningError names.
    message : str
    cpu_seconds : float
        Processor time of the synthesize call (this process, all its threads).
    """

    status: str
    seconds: float
    reason: str | None = None
    task: str | None = None
    message: str = ""
    cpu_seconds: float = 0.0

    def as_dict(self) -> dict:
        return asdict(self)


def _on_alarm(signum, frame) -> None:
    task = None
    while frame is not None:                 # the innermost task step being planned
        if frame.f_code.co_name == "_plan_step" and "text" in frame.f_locals:
            task = str(frame.f_locals["text"])
            break
        frame = frame.f_back
    raise _PairTimeoutError(task)


def run_pair(spec: str, cell, stature: float, seed: int, timeout: float | None = None,
             biomechanics: bool = True) -> Outcome:
    """Synthesize one motion for ``spec`` in ``cell`` and classify the result.

    Parameters
    ----------
    spec : str
    cell : Cell, str or Path
        Anything :func:`~ltl_human_motion.planning.pipeline.resolve_cell` takes.
    stature : float
    seed : int
    timeout : float, optional
        Seconds; uses SIGALRM, so only in a process's main thread.
    biomechanics : bool
        Verify with the biomechanical checks (``VerificationOptions.biomechanics``, the
        default); False without them.
    """
    from ltl_human_motion.planning.pipeline import SynthesisOptions, get_library, synthesize
    from ltl_human_motion.planning.verify import VerificationOptions
    options = SynthesisOptions(verification=VerificationOptions(biomechanics=biomechanics))
    get_library(float(stature))                      # loaded before timing
    use_alarm = timeout is not None and timeout > 0
    if use_alarm:
        previous = signal.signal(signal.SIGALRM, _on_alarm)
        signal.setitimer(signal.ITIMER_REAL, float(timeout))
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        motions = synthesize(spec, cell, stature=float(stature), seed=int(seed),
                             options=options)
        passed = bool(motions[0].verification.get("passed", False))
        out = Outcome("verified" if passed else "verification", 0.0,
                      None if passed else "unknown")
    except _PairTimeoutError as exc:
        where = f" (planning {exc.task})" if exc.task else ""
        out = Outcome("timeout", 0.0, None, exc.task,
                      f"no answer within {timeout} s{where}")
    except PlanningError as exc:
        out = Outcome("planning", 0.0, exc.reason, exc.task, str(exc))
    except VerificationError as exc:
        out = Outcome("verification", 0.0, exc.check, None, str(exc))
    except SpecError as exc:
        text = str(exc)
        # refused by the specification layer before any motion search: unsatisfiable, or
        # satisfiable but physically impossible in the cell model (tasks/)
        unsat = ("unsatisfiable" in text or "admits no sequence" in text
                 or "no sequence of task steps is physically possible" in text)
        out = Outcome("spec", 0.0, "unsatisfiable" if unsat else "error", None, text)
    except CellError as exc:
        out = Outcome("cell", 0.0, "error", None, str(exc))
    except (LtlHumanMotionError, ValueError, RuntimeError, IndexError, KeyError,
            TypeError, AttributeError, ZeroDivisionError, FloatingPointError) as exc:
        out = Outcome("crash", 0.0, type(exc).__name__, None, f"{type(exc).__name__}: {exc}")
    finally:
        if use_alarm:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, previous)
    out.seconds = time.perf_counter() - t0
    out.cpu_seconds = time.process_time() - c0
    return out


def prepare_cell(cell) -> float:
    """Build (or load) the planner's floor and obstacle fields of ``cell``; seconds taken.

    The first synthesis in a new obstacle layout pays this once (the fields are then
    cached on disk); the benchmark measures it apart from the time per pair.
    """
    from ltl_human_motion.planning.navigation import clearance_maps
    from ltl_human_motion.planning.pipeline import resolve_cell
    t0 = time.perf_counter()
    clearance_maps(resolve_cell(cell))
    return time.perf_counter() - t0


def _task_kind(task: str | None) -> str:
    if not task:
        return "?"
    return task.split("(", 1)[0].strip()


def judge(expect: str, expected_reason: str | None, outcome: Outcome) -> tuple[bool, str]:
    """Whether an outcome is right for a pair's label, and the family it falls in.

    A feasible pair must verify; an infeasible one must be refused with its reason
    (a PlanningError whose ``reason`` is it, or, for ``unsatisfiable``, a SpecError).

    Returns
    -------
    ok : bool
    family : str
        ``"ok"``, or e.g. ``"planning:grasp:blocked"``, ``"verification:collision"``,
        ``"timeout:grasp"`` (the task being planned when time ran out), ``"timeout"``,
        ``"false_verified"``, ``"wrong_reason:reach<-planning:blocked"``.
    """
    o = outcome
    if o.status == "planning":
        got = f"planning:{_task_kind(o.task)}:{o.reason}"
    elif o.status in ("verification", "spec", "cell", "crash"):
        got = f"{o.status}:{o.reason}"
    elif o.status == "timeout" and o.task:
        got = f"timeout:{_task_kind(o.task)}"
    else:
        got = o.status
    if expect == "feasible":
        return (True, "ok") if o.status == "verified" else (False, got)
    if o.status == "verified":
        return False, "false_verified"
    right = (o.status == "planning" and o.reason == expected_reason) or (
        o.status == "spec" and o.reason == "unsatisfiable" == expected_reason)
    return (True, "ok") if right else (False, f"wrong_reason:{expected_reason}<-{got}")


_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?")


def _verification_cause(text: str) -> str:
    """``"verification collision: right hand enters cnc"``, ``"verification joint_speed:
    r_toe"`` from a verification message."""
    m = re.match(r"verification failed \((\w+)[^)]*\): (?:\w+: )?(.*)", text)
    if not m:
        return "verification"
    check, detail = m.groups()
    deepest = re.search(r"deepest: (?:the )?(.+?) by [-\d.]+ ?cm", detail)
    if deepest:
        detail = deepest.group(1)
    elif "carried part meets an obstacle" in detail:
        detail = "a carried part meets an obstacle"
    else:
        detail = re.split(r" at | moves | is |[,;:(]", detail, maxsplit=1)[0]
    return f"verification {check}: {_NUMBER.sub('#', detail).strip()}"


def failure_cause(message: str, family: str = "") -> str:
    """A short cause of a failed run, the same for runs that failed alike.

    The first words of the refusal or verification message without its numbers: for a
    motion that ran into an obstacle the closest try (``"insert: right upper arm enters
    cnc"``), for a verification the check and the joint or body part
    (``"verification joint_speed: r_toe"``), else the message up to its first clause
    with numbers as ``#`` (``"grasp: no place to stop within # m of the reach spot"``).
    ``family`` (:func:`judge`'s) names runs without a message (``"false_verified"``).
    """
    text = " ".join(message.split())
    if not text:
        return family or "?"
    m = re.match(r"task (\w+)(?:\([^)]*\))?: (.*)", text)
    task, rest = (m.group(1), m.group(2)) if m else ("", text)
    closest = re.search(r"closest try: (?:the )?(.+?) by [-\d.]+ ?cm", rest)
    if closest:
        cause = closest.group(1)
    elif rest.startswith("verification failed"):
        return _verification_cause(rest)
    elif rest.startswith("no answer within"):
        planning = re.search(r"\(planning (\w+)", rest)
        return f"timeout {planning.group(1)}" if planning else "timeout"
    else:
        rest = re.sub(r"^reach \w+\([^)]*\) at \([^)]*\): ", "", rest)
        rest = re.sub(r"^cannot make an? \w+ motion for the target: (?:\w+: )?", "", rest)
        rest = re.sub(r"\[[^\]]*\]|\([-\d.,\s]+\)|\(start frame\)|'[^']*' ", "", rest)
        cause = _NUMBER.sub("#", re.split(r"[;:(]", rest, maxsplit=1)[0])
        cause = " ".join(cause.split()[:16])
    return f"{task}: {cause}" if task else cause
