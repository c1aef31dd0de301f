"""Run one labelled pair through the synthesis pipeline and judge the outcome.

Shared by ``bench/scenarios.py`` and the test suite: :func:`run_pair` synthesizes and
classifies what happened (verified, refused with which error, timed out);
:func:`judge` compares that with the pair's label and names the failure family.
"""

from __future__ import annotations

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

__all__ = ["Outcome", "judge", "run_pair"]


class _PairTimeoutError(Exception):
    """Raised by the alarm when a pair runs past its time limit."""


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
    """

    status: str
    seconds: float
    reason: str | None = None
    task: str | None = None
    message: str = ""

    def as_dict(self) -> dict:
        return asdict(self)


def _on_alarm(signum, frame) -> None:
    raise _PairTimeoutError()


def run_pair(spec: str, cell, stature: float, seed: int, timeout: float | None = None
             ) -> Outcome:
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
    """
    from ltl_human_motion.planning.pipeline import get_library, synthesize
    get_library(float(stature))                      # loaded before timing
    use_alarm = timeout is not None and timeout > 0
    if use_alarm:
        previous = signal.signal(signal.SIGALRM, _on_alarm)
        signal.setitimer(signal.ITIMER_REAL, float(timeout))
    t0 = time.perf_counter()
    try:
        motions = synthesize(spec, cell, stature=float(stature), seed=int(seed))
        passed = bool(motions[0].verification.get("passed", False))
        out = Outcome("verified" if passed else "verification", 0.0,
                      None if passed else "unknown")
    except _PairTimeoutError:
        out = Outcome("timeout", 0.0, message=f"no answer within {timeout} s")
    except PlanningError as exc:
        out = Outcome("planning", 0.0, exc.reason, exc.task, str(exc))
    except VerificationError as exc:
        out = Outcome("verification", 0.0, exc.check, None, str(exc))
    except SpecError as exc:
        text = str(exc)
        unsat = "unsatisfiable" in text or "admits no sequence" in text
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
    return out


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
        ``"timeout"``, ``"false_verified"``, ``"wrong_reason:reach<-planning:blocked"``.
    """
    o = outcome
    if o.status == "planning":
        got = f"planning:{_task_kind(o.task)}:{o.reason}"
    elif o.status in ("verification", "spec", "cell", "crash"):
        got = f"{o.status}:{o.reason}"
    else:
        got = o.status
    if expect == "feasible":
        return (True, "ok") if o.status == "verified" else (False, got)
    if o.status == "verified":
        return False, "false_verified"
    right = (o.status == "planning" and o.reason == expected_reason) or (
        o.status == "spec" and o.reason == "unsatisfiable" == expected_reason)
    return (True, "ok") if right else (False, f"wrong_reason:{expected_reason}<-{got}")
