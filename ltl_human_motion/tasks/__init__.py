"""Task planning with a cell model (core, no ROS, no motion planning).

The specification's Büchi automaton (built on the fly over the task alphabet,
:mod:`ltl_human_motion.ltl.onthefly`) times a model of what a worker can do in the cell
(:mod:`.model`), searched for cost-optimal accepting lassos (:mod:`.product`).

Typical use::

    from ltl_human_motion.tasks import plan_sequences
    sequences, stats = plan_sequences("F grasp(P0) & F grasp(P1)", cell, n=3)
"""

from ltl_human_motion.tasks.model import CellModel, CellState, Limits
from ltl_human_motion.tasks.product import ExplicitView, Lasso, ProductSearch
from ltl_human_motion.tasks.sequences import MODES, PlanStats, has_geometry, plan_sequences

__all__ = ["MODES", "CellModel", "CellState", "ExplicitView", "Lasso", "Limits",
           "PlanStats", "ProductSearch", "has_geometry", "plan_sequences"]
