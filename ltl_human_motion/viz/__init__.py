"""Offscreen visualisation: hand trajectories (Fig. 3), snapshots (Fig. 2), GIFs, cells.

matplotlib is imported lazily inside the functions (Agg canvas, no display); a missing
installation raises :class:`~ltl_human_motion.errors.MissingDependencyError` naming the
package. Every file is written atomically.
"""

from ltl_human_motion.viz.demo import demo_synthesized_motion, reach_pose, standing_spot
from ltl_human_motion.viz.plots import plot_cell, plot_hand_trajectory
from ltl_human_motion.viz.render import render_animation, render_snapshots

__all__ = [
    "demo_synthesized_motion",
    "plot_cell",
    "plot_hand_trajectory",
    "reach_pose",
    "render_animation",
    "render_snapshots",
    "standing_spot",
]
