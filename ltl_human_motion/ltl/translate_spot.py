"""Adapter to Spot's Python bindings (GPL, optional, imported lazily).

The only module that touches ``spot``. Spot translates the formula; its automaton leaves
Spot as HOA text and is read by :mod:`ltl_human_motion.ltl.hoa`, so no BDD or other Spot
object ever reaches the rest of the project.
"""

from __future__ import annotations

from functools import lru_cache

from ltl_human_motion.errors import MissingDependencyError
from ltl_human_motion.ltl.automaton import Automaton
from ltl_human_motion.ltl.formula import Formula, to_spot
from ltl_human_motion.ltl.hoa import automaton_from_hoa

__all__ = ["spot_available", "translate_spot"]


def _import_spot():
    try:
        import spot
    except ImportError:
        raise MissingDependencyError(
            "the Spot backend needs Spot's Python bindings ('import spot' failed); install "
            "Spot (e.g. 'conda install -c conda-forge spot' or the Debian package "
            "python3-spot from Spot's site) or use backend='builtin'") from None
    return spot


@lru_cache(maxsize=1)
def spot_available() -> bool:
    """True if ``import spot`` works (asked once per process: a failed import searches
    the whole path again)."""
    try:
        _import_spot()
    except MissingDependencyError:
        return False
    return True


def translate_spot(formula: Formula, state_based: bool = False) -> Automaton:
    """Translate with ``spot.translate(f, 'TGBA' or 'BA', 'small', 'high')``.

    Parameters
    ----------
    formula : Formula
    state_based : bool
        Ask Spot for a state-based Büchi automaton (as ``ltl2tgba -B``).

    Raises
    ------
    MissingDependencyError
        If Spot is not installed.
    """
    spot = _import_spot()
    f = spot.formula(to_spot(formula))
    options = ("BA", "SBAcc") if state_based else ("TGBA",)
    aut = spot.translate(f, *options, "small", "high")
    result = automaton_from_hoa(aut.to_str("hoa"))
    return Automaton(result.aps, result.num_states, result.initial, result.edges,
                     result.num_sets, result.state_based, str(formula))
