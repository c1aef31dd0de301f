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
from ltl_human_motion.scene.body_mesh import BODY_DISPLAY_SCALE
from ltl_human_motion.scene.cell import Cell
from ltl_human_motion.scene.occupancy import capsules_from_positions
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

__all__ = ["clear_view_azimuth", "render_animation", "render_snapshots", "task_snapshot_times"]


def _frame_title(synth: SynthesizedMotion, frame: int) -> str:
    task = synth.active_task(frame)
    return f"t = {frame / synth.fps:.2f} s  " + (task if task else "(between tasks)")


BODY_STYLES = ("shaded", "stick")
#: Capsule tessellation of the animated body (latitudes, longitudes): coarser than the
#: snapshots' so that a GIF frame draws in about 0.1 s.
_GIF_DETAIL = (5, 8)
#: Zoom of the animation's axes: without ticks and panes the cell can fill more of it.
_GIF_ZOOM = 1.35


def _check_body(body: str) -> None:
    if body not in BODY_STYLES:
        raise ValueError(f"body must be one of {', '.join(BODY_STYLES)}, got {body!r}")


def _occluding_capsules(synth: SynthesizedMotion, frame: int, body: str
                        ) -> tuple[np.ndarray, np.ndarray] | None:
    """The capsules that hide lines behind the worker (the shaded body's), or None."""
    if body != "shaded":
        return None
    seg, rad = capsules_from_positions(synth.positions[frame], synth.motion.skeleton.stature)
    return seg, rad * BODY_DISPLAY_SCALE


def _path_segments(synth: SynthesizedMotion, z: float) -> np.ndarray:
    """The pelvis path on the floor as segments, shape (T - 1, 2, 3)."""
    root = synth.positions[:, 0].copy()
    root[:, 2] = z
    return np.stack([root[:-1], root[1:]], axis=1)


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


def task_snapshot_times(synth: SynthesizedMotion, max_panels: int = 9) -> list[float]:
    """Times (s) for a sheet of snapshots: the start, then the middle of each task.

    With more tasks than ``max_panels - 1``, tasks evenly spread over the motion are
    kept (always the first and the last).
    """
    if max_panels < 1:
        raise ValueError(f"max_panels must be positive, got {max_panels}")
    mids = [(seg.start_frame + seg.end_frame) / 2 / synth.fps for seg in synth.timeline]
    if len(mids) > max_panels - 1:
        keep = np.unique(np.round(np.linspace(0, len(mids) - 1, max_panels - 1)).astype(int))
        mids = [mids[i] for i in keep] if max_panels > 1 else []
    return sorted({0.0, *(round(t, 2) for t in mids)})[:max_panels]


#: Azimuths (deg) :func:`clear_view_azimuth` chooses from, the default view first, and the
#: camera's distance (m) along which an obstacle counts as hiding the worker.
VIEW_AZIMUTHS = tuple(-125.0 + 30.0 * k for k in range(12))
_VIEW_REACH = 6.0


def clear_view_azimuth(synth: SynthesizedMotion, cell: Cell, elev: float = 20.0) -> float:
    """The view azimuth (deg, matplotlib's) from which the fewest of the worker's pelvis,
    head and hand positions during its tasks are hidden by an obstacle, of
    :data:`VIEW_AZIMUTHS` (the default view where it hides none; ties go to the one
    nearest it): a fixed camera looked at a machine tender's back through the machine.
    Each point is hidden where the straight line from it towards the camera passes
    through an obstacle part's box."""
    if not cell.obstacles:
        return VIEW_AZIMUTHS[0]
    working = np.flatnonzero(np.asarray(synth.task_index) >= 0)
    frames = working if working.size else np.arange(synth.n_frames)
    frames = frames[np.linspace(0, len(frames) - 1, min(len(frames), 60)).astype(int)]
    pts = synth.positions[frames][:, [0, 4, 9, 14]].reshape(-1, 3)     # (N, 3)
    lo, hi = cell.part_set.lo, cell.part_set.hi                          # (P, 3)
    e = np.radians(elev)
    hidden = []
    for azim in VIEW_AZIMUTHS:
        a = np.radians(azim)
        d = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (lo[None] - pts[:, None]) / d                           # (N, P, 3)
            t2 = (hi[None] - pts[:, None]) / d
        near = np.nanmax(np.minimum(t1, t2), axis=2)
        far = np.nanmin(np.maximum(t1, t2), axis=2)
        hit = (near <= far) & (far > 0.0) & (near < _VIEW_REACH)
        hidden.append(int(hit.any(axis=1).sum()))
    return VIEW_AZIMUTHS[int(np.argmin(hidden))]


def _one_collection(faces: list[tuple[np.ndarray, np.ndarray]]):
    """One collection of faces [(triangles (F, 3, 3), RGBA (F, 4)), ...], ordered by depth
    face by face (edges in the face colour hide the seams between faces)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    tri, rgba = _joined(faces)
    return Poly3DCollection(tri, facecolors=rgba, edgecolors=rgba, linewidths=0.3)


def _joined(faces: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """The faces' triangles (F, 3, 3) and RGBA (F, 4) in one pair of arrays."""
    if not faces:
        return np.zeros((0, 3, 3)), np.zeros((0, 4))
    return np.concatenate([f[0] for f in faces]), np.concatenate([f[1] for f in faces])


def _part_faces(tri: np.ndarray, color: str) -> tuple[np.ndarray, np.ndarray]:
    """A part's faces, shaded and darker than the furniture it rests on (F, 3, 3), (F, 4)."""
    rgba = shaded(tri, color)
    rgba[:, :3] *= 0.85
    return tri, rgba


def _stack(polys: dict[str, np.ndarray]) -> np.ndarray:
    """All objects' triangles in one array, shape (F, 3, 3)."""
    return np.concatenate(list(polys.values())) if polys else np.zeros((0, 3, 3))


def render_snapshots(synth: SynthesizedMotion, cell: Cell, times: Sequence[float],
                     path: PathLike, ncols: int = 3, capsules: bool = True,
                     elev: float = 20.0, azim: float | None = None, dpi: float = 110.0,
                     body: str = "shaded", panel_size: tuple[float, float] = (4.0, 3.6),
                     title: str | None = None) -> None:
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
        View angles in degrees (``azim`` None: :func:`clear_view_azimuth`).
    dpi : float
    body : {"shaded", "stick"}
        A shaded body (default) or the stick figure.
    panel_size : (float, float)
        Width and height of one panel in inches (pixels = inches * ``dpi``).
    title : str, optional
        A line above the panels (e.g. the specification and the task sequence).
    """
    _check_body(body)
    times = list(times)
    if not times:
        raise ValueError("need at least one time")
    if ncols < 1:
        raise ValueError(f"ncols must be positive, got {ncols}")
    ncols = min(ncols, len(times))
    nrows = -(-len(times) // ncols)
    if panel_size[0] <= 0 or panel_size[1] <= 0:
        raise ValueError(f"panel_size must be positive, got {panel_size}")
    azim = clear_view_azimuth(synth, cell, elev) if azim is None else float(azim)
    fig = new_figure(panel_size[0] * ncols, panel_size[1] * nrows, dpi)
    lo, hi = cell_bounds(cell, synth.positions[:, [0, 4, 9, 14]].reshape(-1, 3))
    path_segments = _path_segments(synth, cell.floor_z + 0.005)
    for k, time in enumerate(times):
        frame = synth.frame_at(time)
        ax = fig.add_subplot(nrows, ncols, k + 1, projection="3d")
        setup_axes3d(ax, lo, hi, elev, azim)
        solids: list = []
        lines = draw_static_cell(ax, cell, lo, hi, solids_out=solids)
        lines.add(path_segments, "0.55", 0.6, ":")
        polys = object_polys(cell, synth.objects_at(frame))
        solids += [_part_faces(tri, cell.objects[name].color or "tab:orange")
                   for name, tri in polys.items()]
        if body == "shaded":
            solids.append(body_triangles(synth.positions[frame],
                                         synth.motion.skeleton.stature))
        ax.add_collection3d(_one_collection(solids))
        if body != "shaded":
            _draw_worker(ax, synth, frame, capsules, body)
        lines.update(_occluding_capsules(synth, frame, body), _stack(polys))
        ax.set_title(_frame_title(synth, frame), fontsize=8)
    top = 0.95
    if title:
        top -= 0.3 / (panel_size[1] * nrows)
        fig.suptitle(title, fontsize=9, y=0.995, va="top")
    fig.subplots_adjust(left=0.03, right=1.0, bottom=0.02, top=top, wspace=0.0, hspace=0.08)
    save_figure(fig, path)


def render_animation(synth: SynthesizedMotion, cell: Cell, path: PathLike, fps: float = 15.0,
                     capsules: bool = False, size: tuple[float, float] = (10.0, 7.5),
                     dpi: float = 80.0, elev: float = 20.0, azim: float | None = None,
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
        Figure size in inches (the default, at ``dpi`` 80, makes 800 x 600 pixels).
    dpi : float
    elev, azim : float
        View angles in degrees (``azim`` None: :func:`clear_view_azimuth`).
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

    azim = clear_view_azimuth(synth, cell, elev) if azim is None else float(azim)
    fig = new_figure(size[0], size[1], dpi)
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    lo, hi = cell_bounds(cell, synth.positions[:, [0, 4, 9, 14]].reshape(-1, 3))
    setup_axes3d(ax, lo, hi, elev, azim, zoom=_GIF_ZOOM)
    ax.set_axis_off()                  # ticks and panes cost most of the drawing time
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.94)
    solids: list = []
    lines = draw_static_cell(ax, cell, lo, hi, grid=0.5, solids_out=solids)
    lines.add(_path_segments(synth, cell.floor_z + 0.005), "0.55", 0.6, ":")
    stature = synth.motion.skeleton.stature
    bones = None
    shell = _one_collection(solids)
    ax.add_collection3d(shell)
    if body != "shaded":
        bones = Line3DCollection(bone_segments(synth.positions[0]), colors="#1f3b73",
                                 linewidths=1.8)
        ax.add_collection3d(bones)
    caps = None
    if capsules and body == "stick":
        caps = Poly3DCollection(body_quads(synth.positions[0], stature),
                                facecolors="#4a90d9", edgecolors="none", alpha=0.35)
        ax.add_collection3d(caps)
    base = object_polys(cell)
    base_rgba = {name: _part_faces(tri, cell.objects[name].color or "tab:orange")[1]
                 for name, tri in base.items()}
    title = ax.set_title("", fontsize=9)
    canvas = fig.canvas
    images = []
    palette = None
    for frame in frames:
        pose = synth.positions[frame]
        moved = dict(base)
        for name in base:
            if name in synth.objects:
                moved[name] = base[name] + (synth.objects[name][frame]
                                            - cell.objects[name].position)
        faces = solids + [(moved[name], base_rgba[name]) for name in base]
        if body == "shaded":
            faces.append(body_triangles(pose, stature, detail=_GIF_DETAIL))
        tri, rgba = _joined(faces)
        shell.set_verts(tri)
        shell.set_facecolor(rgba)
        shell.set_edgecolor(rgba)
        if bones is not None:
            bones.set_segments(bone_segments(pose))
        if caps is not None:
            caps.set_verts(body_quads(pose, stature))
        lines.update(_occluding_capsules(synth, int(frame), body), _stack(moved))
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


