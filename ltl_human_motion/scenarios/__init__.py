"""Scenario corpus and random scenario generator for measuring synthesis in many cells.

``corpus``: the labelled (cell, specification) pairs of ``scenarios/specs.yaml``;
``generator``: seeded random cells and specifications; ``unseen``: seeded cells of the
layouts the corpus lacked (machine chambers, boards, desks, conveyors, aisles, two-handed
parts), labelled from geometry by ``labels``. Plain Python, no ROS.
"""

from ltl_human_motion.scenarios.corpus import DWYER_PATTERNS, Pair, load_corpus

__all__ = ["DWYER_PATTERNS", "Pair", "load_corpus"]
