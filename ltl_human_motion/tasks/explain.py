"""Why a satisfiable specification has no task sequence in a cell (issue 16, item 6).

The product of the specification automaton and the cell model can be empty although
the formula is satisfiable, for example when the specification needs three parts in
hand at once. The explanation names

* the physical limit: the search is repeated with one limit relaxed at a time
  (:class:`~ltl_human_motion.tasks.model.Limits`: as many hands as parts, no posture
  preconditions); the limit whose relaxation makes a sequence possible is the one in
  conflict, else the part bookkeeping (a part must be held to be released, placed
  to be grasped again, inside a container to be extracted);
* a minimal set of conjuncts that conflicts with it (deletion-based, each trial a
  product search).
"""

from __future__ import annotations

from dataclasses import replace

from ltl_human_motion.ltl.formula import conj
from ltl_human_motion.ltl.spec import Specification
from ltl_human_motion.tasks.model import CellModel, Limits
from ltl_human_motion.tasks.product import SearchBudgetError, product_search

__all__ = ["explain_infeasible", "feasible"]

#: Product nodes one feasibility trial may expand (an explanation stays quick).
TRIAL_BUDGET = 20_000

#: Most conjuncts minimized one by one; a larger specification lists them all.
CORE_LIMIT = 16


def feasible(spec: Specification, model: CellModel, backend: str = "builtin") -> bool | None:
    """Whether the product of ``spec`` and ``model`` has an accepting lasso (None: the
    trial ran out of budget)."""
    search, _t, _l = product_search(spec, model, backend, weight=1e6, budget=TRIAL_BUDGET)
    try:
        return bool(search.lassos(1))
    except SearchBudgetError:
        return None


def _with_user_formula(spec: Specification, parts: list) -> Specification:
    return replace(spec, user_formula=conj(*parts))


def explain_infeasible(spec: Specification, model: CellModel, backend: str = "builtin") -> str:
    """A message naming the conflicting conjuncts and the physical limit."""
    from ltl_human_motion.ltl.formula import top_level_conjuncts
    from ltl_human_motion.ltl.translate_builtin import translate_builtin
    hands = 2 * max(1, len(model.part_names))
    relaxed = [
        (Limits(hands=hands, posture=model.limits.posture),
         f"the worker has {model.limits.hands} hands: at most {model.limits.hands} small "
         "parts in hand at once, and a part marked two_handed takes both"),
        (Limits(hands=model.limits.hands, posture=False),
         "posture: sit needs the worker standing"),
    ]
    limit = ("the parts' states: a part must be in hand to be released, placed, inserted "
             "or carried (fetched if a hand is free), not in hand to be grasped, and "
             "inside a container to be extracted")
    for limits, text in relaxed:
        if feasible(spec, model.with_limits(limits), backend):
            limit = text
            break
    satisfiable = not translate_builtin(spec.formula).is_empty() \
        if len(spec.tasks) <= 8 else True
    head = (f"specification '{spec.text}' is unsatisfiable" if not satisfiable else
            f"specification '{spec.text}' is satisfiable but no sequence of task steps is "
            f"physically possible in the cell; the limit in conflict is {limit}")
    parts = top_level_conjuncts(spec.user_formula)
    core = list(parts)
    if len(parts) <= CORE_LIMIT:
        for item in list(parts):
            trial = [p for p in core if p is not item]
            if trial and feasible(_with_user_formula(spec, trial), model, backend) is False:
                core = trial
    listed = "\n  ".join(f"conjunct {parts.index(c) + 1}: {c}" for c in core)
    return f"{head}; these conjuncts conflict with it:\n  {listed}"
