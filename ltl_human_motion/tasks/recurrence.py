"""Recurrences of a specification: tasks it needs again and again (``G F phi``).

Under the finite-trace semantics of the product search (:mod:`~.product`) the worker's
cycle must pass every recurrence at least once, so it holds at least one step of each,
plus the hand-freeing steps that two hands force between grasps of different parts.
:func:`cycle_steps` gives that lower bound, so that a search tries tails of paths long
enough to be such a cycle; :func:`refuse_many_recurrences` refuses, before any search, a
specification with more recurrences than the search answers within its budget.
"""

from __future__ import annotations

from collections.abc import Sequence

from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl.evaluator import propositional_letters
from ltl_human_motion.ltl.formula import Atom, Finally, Formula, Globally, top_level_conjuncts
from ltl_human_motion.ltl.spec import Specification
from ltl_human_motion.tasks.model import CellModel

__all__ = ["MAX_RECURRENCES", "cycle_steps", "recurrences", "refuse_many_recurrences"]

#: Most recurrences on disjoint tasks a specification may have. Measured with
#: ``G F grasp(P0) & ... & G F grasp(Pn-1)`` in the kitting cell (2 shared cores,
#: under load): n = 5 is answered optimally in 0.2 s of CPU, n = 6 takes 4 s (weighted
#: A*, weight 3), n = 8 exhausts the search budget after about 17 s; the search for
#: such cycles is exponential in n.
MAX_RECURRENCES = 5


def recurrences(spec: Specification, letters: Sequence[frozenset[str]]
                ) -> list[tuple[Formula, frozenset[int]]]:
    """The top-level conjuncts ``G F phi`` (``phi`` propositional) of the specification,
    each with the indices of the candidate letters on which ``phi`` holds."""
    out = []
    for c in top_level_conjuncts(spec.user_formula):
        if isinstance(c, Globally) and isinstance(c.arg, Finally):
            holds = propositional_letters(c.arg.arg, letters)
            if holds is not None:
                out.append((c, frozenset(holds)))
    return out


def _disjoint(found: list[tuple[Formula, frozenset[int]]]) -> list[tuple[Formula, frozenset[int]]]:
    """A greedy packing of pairwise disjoint letter sets, smallest first (a cycle needs a
    distinct step for each, so their number bounds the cycle's length from below)."""
    packed: list[tuple[Formula, frozenset[int]]] = []
    used: set[int] = set()
    for f, letters in sorted(found, key=lambda x: (len(x[1]), str(x[0]))):
        if letters and used.isdisjoint(letters):
            packed.append((f, letters))
            used |= letters
    return packed


def cycle_steps(spec: Specification, model: CellModel, tasks: Sequence[Atom],
                letters: Sequence[frozenset[str]]) -> int:
    """A lower bound on the steps of an accepting cycle: one per disjoint recurrence,
    plus one hand-freeing step per grasped part beyond the hands (each recurrence whose
    only steps grasp one part, of distinct parts)."""
    packed = _disjoint(recurrences(spec, letters))
    grasped = set()
    for _f, idx in packed:
        heads = {tasks[i].args[0] for i in idx if tasks[i].name == "grasp" and tasks[i].args}
        if len(heads) == 1 and all(tasks[i].name == "grasp" for i in idx):
            part = model.part_index.get(next(iter(heads)))
            if part is not None:
                grasped.add(part)
    width = sum(model._width[p] for p in grasped)
    return len(packed) + max(0, width - model.limits.hands)


def refuse_many_recurrences(spec: Specification, letters: Sequence[frozenset[str]]) -> None:
    """Raise :class:`SpecError` when the specification has more than
    :data:`MAX_RECURRENCES` recurrences on disjoint tasks (before any search)."""
    packed = _disjoint(recurrences(spec, letters))
    if len(packed) <= MAX_RECURRENCES:
        return
    listed = ", ".join(str(f) for f, _ in packed)
    raise SpecError(
        f"specification '{spec.text}' needs {len(packed)} different tasks again and again "
        f"({listed}): every cycle of the worker must do each of them, and the search for "
        f"such cycles grows exponentially with their number; at most {MAX_RECURRENCES} "
        "are answered. Ask for one pass with F instead of G F (for example "
        "'F grasp(P0) & F grasp(P1) & ...'), or split the job into smaller cycles",
        text=spec.text)
