"""The tasks of Table I and the kinds of their arguments.

Argument kinds: ``"object"`` (an object of the cell), ``"region"`` (a region of the
cell), ``"duration"`` (seconds, a number). ``sit`` takes the object to sit on;
``standUp``, ``bend``, ``stoop`` and ``kneel`` take none.
"""

from __future__ import annotations

__all__ = ["GAIT_TASKS", "REGION_TASKS", "TASK_ARGUMENTS", "TASK_NAMES"]

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

#: Table I task names in the paper's order.
TASK_NAMES: tuple[str, ...] = tuple(TASK_ARGUMENTS)

#: Tasks realised by gait primitives.
GAIT_TASKS: frozenset[str] = frozenset({"walk", "carry"})

#: Tasks whose termination condition puts (part of) the body into their region argument.
REGION_TASKS: frozenset[str] = frozenset({"walk", "carry", "leftHand", "rightHand"})
