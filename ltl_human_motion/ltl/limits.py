"""Named size limits of a specification, checked once, up front, before any translation.

A specification beyond them is refused with a :class:`~ltl_human_motion.errors.SpecError`
naming the limit, instead of a RecursionError from a recursive pass or minutes of
translation (issue 17: 12 ``GF`` terms took 39 s, ``X^300`` 113 s, 200 nested ``->`` a
RecursionError). The translator also checks the active time budget in its main loop
(:func:`ltl_human_motion.deadline.checkpoint`).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from ltl_human_motion.deadline import BudgetExhaustedError, Deadline, active, current
from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl.formula import (
    Finally,
    Formula,
    Globally,
    Next,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
)

__all__ = ["MAX_NESTING", "MAX_SPEC_CHARS", "MAX_TEMPORAL_OPERATORS",
           "MAX_TRANSLATION_SECONDS", "check_formula_limits", "nesting_depth",
           "temporal_operators", "translation_budget"]

#: Characters of specification text. Table I's and the batch corpus's longest specs are
#: under 400 characters; 20,000 leaves room for generated ones.
MAX_SPEC_CHARS = 20_000
#: Operator nesting depth. The paper's specs nest at most ~12 deep (S2 with its
#: shorthands); the recursive passes (nnf, equality, rendering) stay far below Python's
#: recursion limit of 1000 at 100.
MAX_NESTING = 100
#: Temporal operators (X, F, G, U, R, W, M) after shorthand expansion. The explicit
#: tableau grew exponentially with them (12 ``GF`` terms took 39-73 s); synthesis now
#: builds the product with the cell model on the fly (tasks/), which answers or refuses
#: within its work budget (about 10 s on this machine at worst), and a service request
#: also has its time budget. 64 admits 20-part kitting with a response rule per part
#: (``G(grasp(Pi) -> F insert(Pi, kit))``: 40) and refuses machine-made formulas.
MAX_TEMPORAL_OPERATORS = 64
#: Seconds that building a specification's whole automaton may take (the explicit
#: translation of :func:`~ltl_human_motion.ltl.sequences.synthesize_sequences` and
#: ``tasks --automaton``). Table I's specifications take under 0.05 s; 12 ``G F`` terms
#: took over 90 s and a 49-deep ``U`` chain 40 s (issue 34), where the on-the-fly search
#: of a cell with geometry answers or refuses within its work budget.
MAX_TRANSLATION_SECONDS = 2.0

_TEMPORAL = (Next, Finally, Globally, Until, Release, WeakUntil, StrongRelease)


def nesting_depth(f: Formula) -> int:
    """Depth of the formula tree of ``f`` (an atom is 1), without recursion."""
    deepest = 0
    stack = [(f, 1)]
    while stack:
        g, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend((c, d + 1) for c in g.children())
    return deepest


def temporal_operators(f: Formula) -> int:
    """Number of temporal operator nodes in ``f`` (shared subformulas counted once per
    occurrence), without recursion."""
    count = 0
    stack = [f]
    while stack:
        g = stack.pop()
        if isinstance(g, _TEMPORAL):
            count += 1
        stack.extend(g.children())
    return count


def check_formula_limits(f: Formula, text: str = "") -> None:
    """Raise SpecError when ``f`` nests deeper than :data:`MAX_NESTING` or has more than
    :data:`MAX_TEMPORAL_OPERATORS` temporal operators."""
    depth = nesting_depth(f)
    if depth > MAX_NESTING:
        raise SpecError(f"the specification nests operators {depth} deep; at most "
                        f"{MAX_NESTING} are allowed (MAX_NESTING)", text=text)
    temporal = temporal_operators(f)
    if temporal > MAX_TEMPORAL_OPERATORS:
        raise SpecError(f"the specification has {temporal} temporal operators; at most "
                        f"{MAX_TEMPORAL_OPERATORS} are allowed (MAX_TEMPORAL_OPERATORS), "
                        "beyond which translation takes minutes; split the task or "
                        "remove repeated terms", text=text)


@contextmanager
def translation_budget() -> Iterator[None]:
    """Run the block (a translation) under :data:`MAX_TRANSLATION_SECONDS`, or under the
    active deadline when that one ends sooner (a request's budget, or an enclosing
    translation budget).

    Raises
    ------
    SpecError
        When the block's own budget is spent; the message names the limit.
    """
    outer = current()
    if outer is not None and outer.remaining() <= MAX_TRANSLATION_SECONDS:
        yield
        return
    own = Deadline(MAX_TRANSLATION_SECONDS)
    try:
        with active(own):
            yield
    except BudgetExhaustedError:
        if not own.expired:
            raise
        raise SpecError(
            "the specification is too complex to translate into an automaton within "
            f"{MAX_TRANSLATION_SECONDS:g} s (MAX_TRANSLATION_SECONDS); split it into smaller "
            "specifications, or plan with a cell that has geometry (e.g. --cell "
            "paper_cell), whose search builds only the states it visits") from None
