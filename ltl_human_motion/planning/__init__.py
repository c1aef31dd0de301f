"""Motion synthesis: A* over the motion automaton, blending, verification (Sec. III).

Typical use::

    from ltl_human_motion.planning import synthesize
    motions = synthesize("S1", "paper_cell", variants=2, seed=1)
"""

from ltl_human_motion.planning.pipeline import (
    SynthesisOptions,
    get_library,
    resolve_cell,
    synthesize,
)
from ltl_human_motion.planning.plan_state import PlannerOptions
from ltl_human_motion.planning.result import SynthesizedMotion, TaskSegment
from ltl_human_motion.planning.verify import VerificationOptions, verify_motion

__all__ = [
    "PlannerOptions",
    "SynthesisOptions",
    "SynthesizedMotion",
    "TaskSegment",
    "VerificationOptions",
    "get_library",
    "resolve_cell",
    "synthesize",
    "verify_motion",
]
