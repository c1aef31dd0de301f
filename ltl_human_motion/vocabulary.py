"""The task vocabulary of Table I, in one place for every layer.

Argument kinds: ``"object"`` (an object of the cell), ``"region"`` (a region of the
cell), ``"duration"`` (seconds, a number). ``sit`` takes the object to sit on;
``standUp``, ``bend``, ``stoop`` and ``kneel`` take none. The region atom ``enter(R)``
is true at a step whose task puts the body into R (:data:`ENTERING_TASKS`). A cell's
shorthands (``assemble(R): leftHand(R) & rightHand(R)``) are conjunctions of these
tasks (:func:`shorthand_conjuncts`).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

from ltl_human_motion.errors import PlanningError

__all__ = ["ENTERING_TASKS", "HAND_TASKS", "INPUT_ARGUMENTS", "REGION_ATOM", "TASK_ARGUMENTS",
           "TASK_NAMES", "TaskStep", "shorthand_conjuncts", "task_step", "task_text",
           "two_hand_region"]

TASK_ARGUMENTS: dict[str, tuple[str, ...]] = {
    "wait": ("duration",),
    "move": ("object", "region"),
    "leftHand": ("region",),
    "rightHand": ("region",),
    "insert": ("object", "object"),
    "extract": ("object", "object"),
    "grasp": ("object",),
    "release": ("object",),
    "sit": ("object",),
    "standUp": (),
    "bend": (),
    "stoop": (),
    "kneel": (),
    "walk": ("region",),
    "carry": ("object", "region"),
}

#: Built-in input propositions (robot events the worker observes, docs/reactive.md) and
#: their argument kinds: ``robot_in(R)`` (a capsule of the robot's body is inside region
#: R), ``robot_moving`` (its joint speed is above a threshold), ``offered(O)`` (the robot
#: holds part O in a handover region). A cell declares Boolean inputs of its own under
#: ``inputs:``. Inputs are read, never done: they are not tasks.
INPUT_ARGUMENTS: dict[str, tuple[str, ...]] = {
    "robot_in": ("region",),
    "robot_moving": (),
    "offered": ("object",),
}

#: Table I task names in the paper's order.
TASK_NAMES: tuple[str, ...] = tuple(TASK_ARGUMENTS)

#: The region atom ``enter(R)``: true at a step whose task puts the body into R.
REGION_ATOM = "enter"

#: Tasks whose termination condition puts (part of) the body into a region, with the
#: index of that region among their arguments.
ENTERING_TASKS: dict[str, int] = {"walk": 0, "carry": 1, "leftHand": 0, "rightHand": 0}

#: Tasks done with the hands (``assemble`` is the two-hand shorthand): goal primitives
#: with a hand target, before which the arms are raised to the carry stance.
HAND_TASKS: tuple[str, ...] = ("grasp", "release", "move", "leftHand", "rightHand",
                               "assemble", "insert", "extract")


_BODY_TOKEN = re.compile(r"\s*(?:([A-Za-z_][A-Za-z0-9_]*)\s*(\(([^()]*)\))?|(&)|(\()|(\)))")


def shorthand_conjuncts(body: str) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """The conjuncts of a shorthand body, e.g. ``"leftHand(R) & rightHand(R)"`` ->
    ``(("leftHand", ("R",)), ("rightHand", ("R",)))``, arguments as written.

    The body must be a conjunction of tasks: ``&`` between tasks, grouping parentheses
    allowed, a task without arguments written bare (``standUp``).

    Raises
    ------
    ValueError
        Anything else (``|``, ``X``, ``!``, an empty or unbalanced body), naming the
        position.
    """
    out: list[tuple[str, tuple[str, ...]]] = []
    pos, depth, want_task = 0, 0, True
    text = body.rstrip()
    while pos < len(text):
        pos += len(text[pos:]) - len(text[pos:].lstrip())
        m = _BODY_TOKEN.match(text, pos)
        if not m or m.end() == pos:
            raise ValueError(f"shorthand body {body!r}: only a conjunction of tasks is "
                             f"allowed, not {text[pos:].strip()[:20]!r} at character {pos + 1}")
        name, _call, args, amp, lpar, rpar = m.groups()
        if name is not None and name not in ("X", "F", "G", "U", "W", "R", "M") and want_task:
            out.append((name, tuple(a.strip() for a in (args or "").split(",") if a.strip())))
            want_task = False
        elif amp and not want_task:
            want_task = True
        elif lpar and want_task:
            depth += 1
        elif rpar and not want_task and depth > 0:
            depth -= 1
        else:
            raise ValueError(f"shorthand body {body!r}: only a conjunction of tasks is "
                             f"allowed, not {m.group(0).strip()!r} at character {pos + 1}")
        pos = m.end()
    if want_task or depth:
        raise ValueError(f"shorthand body {body!r}: incomplete conjunction of tasks")
    return tuple(out)


def two_hand_region(params: tuple[str, ...], body: str) -> bool:
    """Whether a one-parameter shorthand is ``leftHand(R) & rightHand(R)`` (Table I's
    ``assemble``), in any order or grouping."""
    if len(params) != 1:
        return False
    try:
        conj = set(shorthand_conjuncts(body))
    except ValueError:
        return False
    return conj == {("leftHand", params), ("rightHand", params)}


@dataclass(frozen=True)
class TaskStep:
    """One step of a task sequence as the planner takes it.

    Attributes
    ----------
    text : str
        The step as written in the sequence, e.g. ``"assemble(R1)"``.
    kind : str
        The goal task realising it: a Table I task, or ``"assemble"`` for a two-hand
        shorthand.
    args : tuple of str
        The arguments of ``kind``.
    """

    text: str
    kind: str
    args: tuple[str, ...]


def task_text(name: str, args: tuple[str, ...]) -> str:
    """How task ``name(args)`` is written: ``"grasp(O1)"``, ``"standUp"``."""
    return f"{name}({', '.join(args)})" if args else name


def task_step(name: str, args: tuple[str, ...],
              shorthands: Mapping[str, tuple[tuple[str, ...], str]],
              text: str | None = None) -> TaskStep:
    """The :class:`TaskStep` of task ``name(args)``, shorthands expanded.

    Raises
    ------
    PlanningError
        (reason ``"unsupported"``) for a shorthand with no motion of its own: only
        ``leftHand(R) & rightHand(R)`` is one step (``assemble``).
    """
    args = tuple(str(a) for a in args)
    text = text if text is not None else task_text(name, args)
    if name in shorthands:
        params, body = shorthands[name]
        if len(args) == 1 and two_hand_region(params, body):
            return TaskStep(text, "assemble", args)
        raise PlanningError(f"shorthand {name} ({body}) has no motion of its own; only "
                            "two-hand shorthands like leftHand(R) & rightHand(R) can be "
                            "planned as one step", task=name, reason="unsupported")
    return TaskStep(text, name, args)
