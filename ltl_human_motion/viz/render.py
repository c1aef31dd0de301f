"""Offscreen 3D renderings of a synthesized motion in its cell (paper Fig. 2) and GIFs.

The worker is drawn as a shaded body (``body="shaded"``, the default: smooth capsules
built from its occupancy, sized by stature, :mod:`ltl_human_motion.scene.body_mesh`) or
as a stick figure (``body="stick"``: bones, with the translucent occupancy capsules if
``capsules``); obstacles are solid, regions dashed wire boxes, objects at their position
at that frame.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ltl_human_motion.atomic import atomic_path
from ltl_human_motion.errors import MissingDependencyError
from ltl_human_motion.planning.result import SynthesizedMotion
from ltl_human_motion.scene.cell import Cell
from ltl_human_motion.viz._common import (
    PathLike,
    body_quads,
    body_triangles,
    bone_segments,
    cell_bounds,
    draw_static_cell,
    new_figure,
    object_polys,
    save_figure,
    setup_axes3d,
    shaded,
)

__all__ = ["render_animation", "render_snapshots"]


def _frame_title(synth: SynthesizedMotion, frame: int) -> str:
    task = synth.active_task(frame)
    return f"t = {frame / synth.fps:.2f} s  " + (task if task else "(between tasks)")


BODY_STYLES = ("shaded", "stick")
#: Capsule tessellation of the animated body (latitudes, longitudes): coarser than the
#: snapshots' so that a GIF frame draws in about 0.1 s.
_GIF_DETAIL = (5, 8)


def _check_body(body: str) -> None:
    if body not in BODY_STYLES:
        raise ValueError(f"body must be one of {', '.join(BODY_STYLES)}, got {body!r}")


def _draw_worker(ax, synth: SynthesizedMotion, frame: int, capsules: bool,
                 body: str = "shaded") -> None:
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection
    pose = synth.positions[frame]
    if body == "shaded":
        tri, rgba = body_triangles(pose, synth.motion.skeleton.stature)
        # edges in the face colour hide the antialiasing seams between faces
        ax.add_collection3d(Poly3DCollection(tri, facecolors=rgba, edgecolors=rgba,
                                             linewidths=0.3))
        return
    if capsules:
        ax.add_collection3d(Poly3DCollection(body_quads(pose, synth.motion.skeleton.stature),
                                             facecolors="#4a90d9", edgecolors="none",
                                             alpha=0.35))
    ax.add_collection3d(Line3DCollection(bone_segments(pose), colors="#1f3b73", linewidths=1.5))


def render_snapshots(synth: SynthesizedMotion, cell: Cell, times: Sequence[float],
                     path: PathLike, ncols: int = 3, capsules: bool = True,
                     elev: float = 20.0, azim: float = -125.0, dpi: float = 110.0,
                     body: str = "shaded") -> None:
    """Several 3D panels of the worker in the cell at the given times (paper Fig. 2).

    Parameters
    ----------
    synth : SynthesizedMotion
    cell : Cell
    times : sequence of float
        Seconds; each is rounded to the nearest frame (clipped to the motion).
    path : path-like
        Output image (png, pdf, svg).
    ncols : int
        Panels per row.
    capsules : bool
        With ``body="stick"``: draw the occupancy capsules in addition to the bones.
    elev, azim : float
        View angles in degrees.
    dpi : float
    body : {"shaded", "stick"}
        A shaded body (default) or the stick figure.
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    _check_body(body)
    times = list(times)
    if not times:
        raise ValueError("need at least one time")
    if ncols < 1:
        raise ValueError(f"ncols must be positive, got {ncols}")
    ncols = min(ncols, len(times))
    nrows = -(-len(times) // ncols)
    fig = new_figure(4.0 * ncols, 3.6 * nrows, dpi)
    root = synth.positions[:, 0]
    lo, hi = cell_bounds(cell, synth.positions[:, [0, 4, 9, 14]].reshape(-1, 3))
    for k, time in enumerate(times):
        frame = synth.frame_at(time)
        ax = fig.add_subplot(nrows, ncols, k + 1, projection="3d")
        setup_axes3d(ax, lo, hi, elev, azim)
        draw_static_cell(ax, cell, lo, hi)
        ax.plot(root[:, 0], root[:, 1], np.full(len(root), cell.floor_z + 0.005), color="0.55",
                lw=0.6, ls=":")
        for name, tri in object_polys(cell, synth.objects_at(frame)).items():
            color = cell.objects[name].color or "tab:orange"
            ax.add_collection3d(Poly3DCollection(tri, facecolors=shaded(tri, color),
                                                 edgecolors="k", linewidths=0.2))
        _draw_worker(ax, synth, frame, capsules, body)
        ax.set_title(_frame_title(synth, frame), fontsize=8)
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.02, top=0.95, wspace=0.0, hspace=0.08)
    save_figure(fig, path)


def render_animation(synth: SynthesizedMotion, cell: Cell, path: PathLike, fps: float = 15.0,
                     capsules: bool = False, size: tuple[float, float] = (6.4, 4.8),
                     dpi: float = 80.0, elev: float = 20.0, azim: float = -125.0,
                     max_frames: int | None = None, body: str = "shaded") -> int:
    """Write an animated GIF of the motion (offscreen, no display needed).

    The motion is resampled to ``fps`` (nearest frames); the cell is drawn once and the
    worker's bones (and capsules, objects) are updated in place for every frame. The
    axes are hidden (a 0.5 m floor grid gives the scale), which halves the drawing time.

    Parameters
    ----------
    synth : SynthesizedMotion
    cell : Cell
    path : path-like
        Output ``.gif``.
    fps : float
        Frame rate of the GIF (at most the motion's).
    capsules : bool
        With ``body="stick"``: also draw the occupancy capsules (slower).
    size : (float, float)
        Figure size in inches.
    dpi : float
    elev, azim : float
    max_frames : int, optional
        Cap on the number of GIF frames (the frame rate is lowered to fit).
    body : {"shaded", "stick"}
        A shaded body (default) or the stick figure.

    Returns
    -------
    n_frames : int
        Number of frames written.
    """
    try:
        from PIL import Image
    except ImportError as exc:
        raise MissingDependencyError("GIF output needs pillow: pip install pillow") from exc
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps!r}")
    _check_body(body)
    fps = min(float(fps), synth.fps)
    n_out = max(int(np.floor(synth.duration * fps)) + 1, 1)
    if max_frames is not None:
        if max_frames < 1:
            raise ValueError(f"max_frames must be positive, got {max_frames}")
        if n_out > max_frames:
            fps = fps * (max_frames - 1) / max(n_out - 1, 1) if max_frames > 1 else fps
            n_out = max_frames
    frames = np.clip(np.round(np.arange(n_out) / fps * synth.fps).astype(int), 0,
                     synth.n_frames - 1)

    fig = new_figure(size[0], size[1], dpi)
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    lo, hi = cell_bounds(cell, synth.positions[:, [0, 4, 9, 14]].reshape(-1, 3))
    setup_axes3d(ax, lo, hi, elev, azim)
    ax.set_axis_off()                  # ticks and panes cost most of the drawing time
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.94)
    draw_static_cell(ax, cell, lo, hi, grid=0.5)
    stature = synth.motion.skeleton.stature
    bones = shell = None
    if body == "shaded":
        tri, rgba = body_triangles(synth.positions[0], stature, detail=_GIF_DETAIL)
        shell = Poly3DCollection(tri, facecolors=rgba, edgecolors=rgba, linewidths=0.3)
        ax.add_collection3d(shell)
    else:
        bones = Line3DCollection(bone_segments(synth.positions[0]), colors="#1f3b73",
                                 linewidths=1.8)
        ax.add_collection3d(bones)
    caps = None
    if capsules and body == "stick":
        caps = Poly3DCollection(body_quads(synth.positions[0], stature),
                                facecolors="#4a90d9", edgecolors="none", alpha=0.35)
        ax.add_collection3d(caps)
    obj_artists = {}
    base = object_polys(cell)
    for name, tri in base.items():
        art = Poly3DCollection(tri, facecolors=shaded(tri, cell.objects[name].color
                                                      or "tab:orange"),
                               edgecolors="k", linewidths=0.2)
        ax.add_collection3d(art)
        obj_artists[name] = art
    title = ax.set_title("", fontsize=9)
    canvas = fig.canvas
    images = []
    palette = None
    for frame in frames:
        pose = synth.positions[frame]
        if shell is not None:
            tri, rgba = body_triangles(pose, stature, detail=_GIF_DETAIL)
            shell.set_verts(tri)
            shell.set_facecolor(rgba)
            shell.set_edgecolor(rgba)
        if bones is not None:
            bones.set_segments(bone_segments(pose))
        if caps is not None:
            caps.set_verts(body_quads(pose, stature))
        for name, art in obj_artists.items():
            if name in synth.objects:
                shift = synth.objects[name][frame] - cell.objects[name].position
                art.set_verts(base[name] + shift)
        title.set_text(_frame_title(synth, int(frame)))
        canvas.draw()
        rgb = Image.fromarray(np.asarray(canvas.buffer_rgba())[..., :3].copy())
        if palette is None:          # one palette for all frames: fast and flicker-free
            palette = rgb.quantize(colors=160, method=Image.Quantize.MEDIANCUT)
        images.append(rgb.quantize(palette=palette, dither=Image.Dither.NONE))
    duration_ms = round(1000.0 / fps)
    with atomic_path(path) as tmp:
        images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                       duration=duration_ms, loop=0, optimize=False)
    return len(images)


