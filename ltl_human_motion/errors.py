"""Exception types shared by the whole package.

Every error a user can cause derives from :class:`LtlHumanMotionError`, so the CLI and
the ROS nodes can turn it into a message without a traceback.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def did_you_mean(name: object, known: Iterable[str]) -> str:
    """``"did you mean 'X'? "`` for the known name closest to a misspelt ``name``, or "".

    A name that differs only in case is always suggested; otherwise the closest by
    :func:`difflib.get_close_matches` (similarity 0.6 or more).
    """
    if not isinstance(name, str) or not name:
        return ""
    names = [k for k in known if isinstance(k, str)]
    same_case = [k for k in names if k.lower() == name.lower() and k != name]
    close = same_case or difflib.get_close_matches(name, names, n=1, cutoff=0.6)
    return f"did you mean '{close[0]}'? " if close and close[0] != name else ""


class LtlHumanMotionError(Exception):
    """Base class of all errors caused by user input or unmet requirements."""


class SpecError(LtlHumanMotionError, ValueError):
    """A malformed, ill-typed or unsatisfiable LTL specification.

    ``line`` and ``column`` are 1-based positions in the specification text (or None
    when the error is not tied to one position).
    """

    def __init__(self, message: str, text: str = "", line: int | None = None,
                 column: int | None = None) -> None:
        self.message = message
        self.text = text
        self.line = line
        self.column = column
        super().__init__(self.__str__())

    def __str__(self) -> str:
        if self.line is None:
            return self.message
        where = f"line {self.line}, column {self.column}"
        pointer = ""
        if self.text:
            lines = self.text.splitlines() or [""]
            src = lines[self.line - 1] if 0 < self.line <= len(lines) else ""
            pointer = f"\n  {src}\n  {' ' * max((self.column or 1) - 1, 0)}^"
        return f"{where}: {self.message}{pointer}"


class CellError(LtlHumanMotionError, ValueError):
    """A malformed cell description; the message names the file and the key."""


class MotionFormatError(LtlHumanMotionError, ValueError):
    """A corrupt or unsupported motion file; the message names the file and line/frame."""


class PlanningError(LtlHumanMotionError):
    """Motion planning failed; the message names the task and the reason.

    ``step_index``: the position of the failed step in the task sequence being planned
    (None where the failure is not a step's, or before any step). ``search``: how the
    walk's search ended where a walk failed (``"budget"``, ``"no_stop"``, ...), else
    None. ``situation``: what the planner held the failed step's situation to be
    (:meth:`~ltl_human_motion.planning.planner.SequencePlanner.situation`), or None."""

    def __init__(self, message: str, task: str | None = None, reason: str | None = None,
                 search: str | None = None) -> None:
        self.task = task
        self.reason = reason
        self.search = search
        self.step_index: int | None = None
        self.situation: tuple | None = None
        super().__init__(message)


class VerificationError(LtlHumanMotionError):
    """A synthesized motion failed a verification check; ``check`` names which."""

    def __init__(self, message: str, check: str) -> None:
        self.check = check
        super().__init__(message)


class MissingDependencyError(LtlHumanMotionError, ImportError):
    """An optional dependency is not installed; the message says what to install."""
