"""Backend selection: ``"auto"`` (Spot if importable, else built-in), ``"builtin"``,
``"spot"``. Both backends return the same :class:`Automaton` type."""

from __future__ import annotations

from ltl_human_motion.ltl.automaton import Automaton, degeneralize
from ltl_human_motion.ltl.formula import Formula
from ltl_human_motion.ltl.translate_builtin import translate_builtin
from ltl_human_motion.ltl.translate_spot import spot_available, translate_spot

__all__ = ["BACKENDS", "resolve_backend", "translate"]

BACKENDS = ("auto", "builtin", "spot")


def resolve_backend(backend: str) -> str:
    """The backend that ``backend`` stands for ("builtin" or "spot").

    Raises
    ------
    ValueError
        For an unknown name.
    MissingDependencyError
        For "spot" when Spot is not installed.
    """
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    if backend == "auto":
        return "spot" if spot_available() else "builtin"
    return backend


def translate(formula: Formula, backend: str = "auto", state_based: bool = False) -> Automaton:
    """Translate an LTL formula into a (generalized) Büchi automaton.

    Parameters
    ----------
    formula : Formula
    backend : {"auto", "builtin", "spot"}
    state_based : bool
        Return a state-based Büchi automaton (one acceptance set, marks on states),
        comparable with ``ltl2tgba -B``; otherwise a transition-based generalized one.
    """
    if resolve_backend(backend) == "spot":
        return translate_spot(formula, state_based=state_based)
    aut = translate_builtin(formula)
    return degeneralize(aut) if state_based else aut
