"""Static plots: the right-hand trajectory (paper Fig. 3) and an overview of a cell."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ltl_human_motion.planning.result import SynthesizedMotion
from ltl_human_motion.scene.cell import Cell
from ltl_human_motion.viz._common import (
    REGION_COLORS,
    PathLike,
    cell_bounds,
    draw_static_cell,
    new_figure,
    object_polys,
    save_figure,
    setup_axes3d,
    task_color,
)

__all__ = ["plot_cell", "plot_hand_trajectory"]


def plot_hand_trajectory(motions: SynthesizedMotion | Sequence[SynthesizedMotion],
                         path: PathLike, joint: str = "r_hand",
                         titles: Sequence[str] | None = None, dpi: float = 120.0) -> None:
    """Plot x, y and z of one joint over time, one subplot per motion (paper Fig. 3).

    Task spans of the timeline are shaded (colour by task; walking between tasks stays
    white) and labelled at the top.

    Parameters
    ----------
    motions : SynthesizedMotion or sequence of them
    path : path-like
        Output image (format from the suffix: png, pdf, svg).
    joint : str
        Joint to plot (default the right hand, as in the paper).
    titles : sequence of str, optional
        Subplot titles (default: the motions' specifications).
    dpi : float
    """
    items = [motions] if isinstance(motions, SynthesizedMotion) else list(motions)
    if not items:
        raise ValueError("need at least one motion to plot")
    for m in items:
        if not isinstance(m, SynthesizedMotion):
            raise ValueError(f"expected SynthesizedMotion, got {type(m).__name__}")
    if titles is not None and len(titles) != len(items):
        raise ValueError(f"got {len(titles)} titles for {len(items)} motions")
    idx = items[0].motion.skeleton.index(joint)
    fig = new_figure(5.0 * len(items), 3.4, dpi)
    axes = fig.subplots(1, len(items), squeeze=False)[0]
    for k, (ax, synth) in enumerate(zip(axes, items)):
        t = synth.timestamps
        traj = synth.positions[:, idx]
        lo = float(traj.min()) - 0.1
        hi = float(traj.max()) + 0.1
        seen: set[str] = set()
        for seg in synth.timeline:
            t0 = seg.start_frame / synth.fps
            t1 = max(seg.end_frame - 1, seg.start_frame) / synth.fps
            kind = seg.task.split("(")[0]
            ax.axvspan(t0, t1, color=task_color(seg.task), alpha=0.6, lw=0,
                       label=None if kind in seen else kind)
            seen.add(kind)
            ax.text((t0 + t1) / 2, hi, seg.task, fontsize=6, ha="center", va="bottom",
                    rotation=90 if (t1 - t0) < 0.08 * max(synth.duration, 1e-9) else 0,
                    clip_on=False)
        for c, (name, color) in enumerate(zip("xyz", ("tab:red", "tab:green", "tab:blue"))):
            ax.plot(t, traj[:, c], color=color, lw=1.2, label=name)
        ax.set_xlim(0.0, max(synth.duration, 1.0 / synth.fps))
        ax.set_ylim(lo, hi)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"{joint} position [m]")
        ax.set_title(titles[k] if titles is not None else (synth.spec or synth.motion.name),
                     fontsize=8, pad=18)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=6, loc="lower right", ncol=2)
    fig.tight_layout()
    save_figure(fig, path)


def plot_cell(cell: Cell, path: PathLike, elev: float = 25.0, azim: float = -125.0,
              dpi: float = 120.0) -> None:
    """Overview of a cell: a 3D view and a top view with the planner's floor footprints.

    Parameters
    ----------
    cell : Cell
    path : path-like
    elev, azim : float
        3D view angles in degrees.
    dpi : float
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    fig = new_figure(11.0, 5.0, dpi)
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    lo, hi = cell_bounds(cell)
    setup_axes3d(ax, lo, hi, elev, azim)
    lines = draw_static_cell(ax, cell, lo, hi)
    polys = object_polys(cell)
    lines.update(triangles=np.concatenate(list(polys.values())) if polys else None)
    for name, tri in polys.items():
        obj = cell.objects[name]
        ax.add_collection3d(Poly3DCollection(tri, facecolors=obj.color or "tab:orange",
                                             edgecolors="k", linewidths=0.2))
        ax.text(obj.position[0], obj.position[1], obj.shape.aabb()[1][2] + 0.05, name,
                fontsize=7)
    ax.set_title(f"{cell.name}", fontsize=9)

    top = fig.add_subplot(1, 2, 2)
    wl, wh = cell.workspace
    top.plot([wl[0], wh[0], wh[0], wl[0], wl[0]], [wl[1], wl[1], wh[1], wh[1], wl[1]],
             color="0.6", lw=0.8, label="workspace")
    for ob in cell.obstacles:
        for fp in ob.footprints():
            o = fp.outline()
            top.fill(o[:, 0], o[:, 1], color=ob.color or "0.5", alpha=0.7)
        c = 0.5 * (ob.aabb()[0] + ob.aabb()[1])
        top.text(c[0], c[1], ob.name, fontsize=7, ha="center", va="center")
    for i, (name, reg) in enumerate(cell.regions.items()):
        color = REGION_COLORS[i % len(REGION_COLORS)]
        top.plot([reg.lo[0], reg.hi[0], reg.hi[0], reg.lo[0], reg.lo[0]],
                 [reg.lo[1], reg.lo[1], reg.hi[1], reg.hi[1], reg.lo[1]], "--", color=color)
        role = " (start)" if reg is cell.start_region else (
            " (final)" if reg is cell.final_region else "")
        top.text(reg.center[0], reg.hi[1] + 0.05, name + role, color=color, fontsize=7,
                 ha="center")
    for name, obj in cell.objects.items():
        top.plot(*obj.position[:2], "s", color=obj.color or "tab:orange")
        top.text(obj.position[0] + 0.06, obj.position[1] + 0.06, name, fontsize=7)
    top.set_aspect("equal")
    top.set_xlim(lo[0], hi[0])
    top.set_ylim(lo[1], hi[1])
    top.set_xlabel("x [m]")
    top.set_ylabel("y [m]")
    top.set_title("top view (footprints)", fontsize=9)
    top.grid(True, lw=0.3)
    fig.tight_layout()
    save_figure(fig, path)
