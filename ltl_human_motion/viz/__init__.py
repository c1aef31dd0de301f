"""Offscreen visualisation: hand trajectories (Fig. 3), snapshots (Fig. 2), GIFs, cells.

matplotlib is imported lazily inside the functions (Agg canvas, no display); a missing
installation raises :class:`~ltl_human_motion.errors.MissingDependencyError` naming the
package. Every file is written atomically.
"""

from ltl_human_motion.viz.plots import plot_cell, plot_hand_trajectory
from ltl_human_motion.viz.render import (
    render_animation,
    render_snapshots,
    task_snapshot_times,
)

__all__ = [
    "plot_cell",
    "plot_hand_trajectory",
    "render_animation",
    "render_snapshots",
    "task_snapshot_times",
]
