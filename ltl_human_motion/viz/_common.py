"""Shared helpers of the plots: lazy matplotlib, atomic saving, drawing a cell in 3D.

Figures are plain ``matplotlib.figure.Figure`` objects on an Agg canvas: no pyplot,
no global state, no display needed.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from ltl_human_motion.atomic import atomic_path
from ltl_human_motion.errors import MissingDependencyError
from ltl_human_motion.motion.skeleton import PARENTS
from ltl_human_motion.scene.cell import Cell
from ltl_human_motion.scene.occupancy import capsules_from_positions
from ltl_human_motion.viz.lines import LINE_ZORDER, CellLines

PathLike = str | os.PathLike[str]

TASK_COLORS = {
    "walk": "#9ecae1", "carry": "#6baed6", "grasp": "#fdae6b", "release": "#fdd0a2",
    "move": "#a1d99b", "leftHand": "#c7e9c0", "rightHand": "#c7e9c0", "assemble": "#74c476",
    "insert": "#bcbddc", "extract": "#dadaeb", "sit": "#d9d9d9", "standUp": "#bdbdbd",
    "bend": "#fc9272", "stoop": "#fb6a4a", "kneel": "#ef3b2c", "wait": "#f0f0f0",
}
REGION_COLORS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:olive", "tab:cyan")


def require_matplotlib() -> Any:
    """Import matplotlib (Agg canvas) or raise MissingDependencyError."""
    try:
        import matplotlib
        from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: F401
        from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers "3d")
    except ImportError as exc:
        raise MissingDependencyError(
            "plotting needs matplotlib: pip install matplotlib") from exc
    return matplotlib


def new_figure(width: float, height: float, dpi: float = 100.0):
    """A Figure attached to an Agg canvas (never a window)."""
    require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=(width, height), dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig, path: PathLike, fmt: str | None = None) -> None:
    """Save ``fig`` atomically; the format comes from ``fmt`` or the file suffix."""
    fmt = fmt or os.path.splitext(os.fspath(path))[1].lstrip(".").lower() or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt)


def task_color(task: str) -> str:
    """Shading colour of a task label such as ``"grasp(O1)"``."""
    return TASK_COLORS.get(task.split("(")[0].strip(), "#e0e0e0")


def shaded(triangles: np.ndarray, color: str, light: tuple[float, float, float] = (-0.4, -0.6,
                                                                                   0.7)
           ) -> np.ndarray:
    """Per-face RGBA colours lit by a directional light, shape (F, 4)."""
    from matplotlib.colors import to_rgba
    tri = np.asarray(triangles, dtype=np.float64)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)
    lv = np.asarray(light) / np.linalg.norm(light)
    k = 0.55 + 0.45 * np.abs(n @ lv)
    rgba = np.tile(np.array(to_rgba(color)), (len(tri), 1))
    rgba[:, :3] *= k[:, None]
    return rgba


def box_edges(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The 12 edges of an axis-aligned box, shape (12, 2, 3)."""
    c = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                  for z in (lo[2], hi[2])])
    pairs = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7),
             (0, 4), (1, 5), (2, 6), (3, 7)]
    return np.array([[c[a], c[b]] for a, b in pairs])


def capsule_mesh(seg: np.ndarray, radius: float, n_around: int = 8, n_cap: int = 3
                 ) -> np.ndarray:
    """Quads of a capsule surface, shape (Q, 4, 3), for Poly3DCollection."""
    a, b = seg
    axis = b - a
    length = np.linalg.norm(axis)
    w = axis / length if length > 1e-9 else np.array([0.0, 0.0, 1.0])
    helper = np.array([1.0, 0, 0]) if abs(w[0]) < 0.9 else np.array([0, 1.0, 0])
    u = np.cross(w, helper)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    phi = np.linspace(0, 2 * np.pi, n_around + 1)
    # Latitudes from the bottom pole of a's hemisphere to the top pole of b's.
    lat = np.concatenate([np.linspace(-np.pi / 2, 0, n_cap + 1), np.linspace(0, np.pi / 2,
                                                                               n_cap + 1)])
    centers = np.concatenate([np.repeat(a[None], n_cap + 1, 0), np.repeat(b[None], n_cap + 1, 0)])
    ring = (np.cos(lat)[:, None, None] * (np.cos(phi)[None, :, None] * u + np.sin(phi)[None, :,
                                                                                          None] * v)
            + np.sin(lat)[:, None, None] * w) * radius + centers[:, None, :]
    quads = np.stack([ring[:-1, :-1], ring[:-1, 1:], ring[1:, 1:], ring[1:, :-1]], axis=2)
    return quads.reshape(-1, 4, 3)


def body_quads(positions: np.ndarray, stature: float) -> np.ndarray:
    """Capsule quads of one pose (J, 3), shape (Q, 4, 3)."""
    seg, rad = capsules_from_positions(positions, stature)
    return np.concatenate([capsule_mesh(s, r) for s, r in zip(seg, rad)])


def body_triangles(positions: np.ndarray, stature: float,
                   light: tuple[float, float, float] = (-0.4, -0.6, 0.7),
                   detail: tuple[int, int] = (6, 10)) -> tuple[np.ndarray, np.ndarray]:
    """The shaded body of one pose (J, 3): triangles (F, 3, 3) and their RGBA (F, 4).

    Built by :func:`~ltl_human_motion.scene.body_mesh.body_mesh`; faces are lit by a
    directional ``light`` (Lambert with an ambient floor) and sorted back to front is
    left to matplotlib.
    """
    from ltl_human_motion.scene.body_mesh import body_mesh
    v, f, rgb = body_mesh(positions, stature, detail)
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)
    lv = np.asarray(light, dtype=np.float64)
    lv /= np.linalg.norm(lv)
    k = 0.45 + 0.55 * np.clip(n @ lv, 0.0, 1.0)
    rgba = np.concatenate([np.clip(rgb * k[:, None], 0.0, 1.0), np.ones((len(tri), 1))], 1)
    return tri, rgba


def bone_segments(positions: np.ndarray) -> np.ndarray:
    """Bones of one pose (J, 3) as segments, shape (J - 1, 2, 3)."""
    return np.array([[positions[p], positions[j]] for j, p in enumerate(PARENTS) if p >= 0])


def cell_bounds(cell: Cell, extra: np.ndarray | None = None, margin: float = 0.3
                ) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of everything drawn: obstacles, regions, objects and ``extra`` points (N, 3)."""
    pts = []
    for ob in cell.obstacles:
        pts.extend(ob.aabb())
    for reg in cell.regions.values():
        pts.extend([reg.lo, reg.hi])
    for obj in cell.objects.values():
        pts.extend(obj.shape.aabb())
    if extra is not None and len(extra):
        pts.extend(np.asarray(extra).reshape(-1, 3))
    pts = np.array(pts) if pts else np.zeros((1, 3))
    lo, hi = pts.min(axis=0) - margin, pts.max(axis=0) + margin
    lo[2] = cell.floor_z
    hi[2] = max(hi[2], cell.floor_z + 2.0)
    lo = np.maximum(lo, cell.workspace_lo)
    hi = np.minimum(hi, cell.workspace_hi)
    return lo, hi


def setup_axes3d(ax, lo: np.ndarray, hi: np.ndarray, elev: float = 20.0,
                 azim: float = -125.0, zoom: float = 1.15) -> None:
    """Equal-scale 3D axes over ``[lo, hi]`` with z up."""
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(np.maximum(hi - lo, 1e-3)), zoom=zoom)
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel("x [m]", labelpad=-8)
    ax.set_ylabel("y [m]", labelpad=-8)
    ax.set_zlabel("z [m]", labelpad=-8)
    ax.tick_params(labelsize=6, pad=-3)


#: An object whose bottom is this far (m) above what lies under it gets a drawn support.
SUPPORT_GAP = 0.03
SUPPORT_COLOR = "#c8c8c8"


def object_supports(cell: Cell) -> list[tuple[np.ndarray, np.ndarray]]:
    """Boxes ``(lo (3,), hi (3,))`` to draw under objects that would float in the picture.

    A cell often leaves out what a part rests on (a tray, a cart: not an obstacle to the
    planner). Under every object whose bottom lies more than :data:`SUPPORT_GAP` above
    the highest surface beneath its centre (an obstacle part's top, another object's
    top, the floor), a pedestal of 60 % of its footprint reaches down to that surface.
    Drawing only: the planner does not know these pedestals.
    """
    tops = [p.aabb() for ob in cell.obstacles for p in ob.parts]
    tops += [o.shape.aabb() for o in cell.objects.values()]
    out = []
    for obj in cell.objects.values():
        lo, hi = (np.asarray(v, dtype=np.float64) for v in obj.shape.aabb())
        c = 0.5 * (lo + hi)
        under = [b[1][2] for b in tops
                 if b[0][0] <= c[0] <= b[1][0] and b[0][1] <= c[1] <= b[1][1]
                 and b[1][2] <= lo[2] + 1e-3 and not np.allclose(b[0], lo)]
        base = max([cell.floor_z, *under])
        if lo[2] - base > SUPPORT_GAP:
            half = 0.3 * (hi - lo)
            out.append((np.array([c[0] - half[0], c[1] - half[1], base]),
                        np.array([c[0] + half[0], c[1] + half[1], lo[2]])))
    return out


def box_triangles(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The 12 triangles of an axis-aligned box, shape (12, 3, 3)."""
    import trimesh
    box = trimesh.creation.box(bounds=np.array([lo, hi], dtype=np.float64))
    return np.asarray(box.triangles)


def draw_static_cell(ax, cell: Cell, lo: np.ndarray, hi: np.ndarray, labels: bool = True,
                     grid: float | None = None, solids_out: list | None = None) -> CellLines:
    """Floor, obstacles (solid), supports, regions (wire boxes) of ``cell`` on 3D axes ``ax``.

    ``grid``: spacing of floor grid lines in metres (for axes drawn without ticks).
    ``solids_out``: a list that receives the obstacles' and supports' faces as
    (triangles (F, 3, 3), RGBA (F, 4)) instead of drawing them, for the caller to draw in
    one collection with the worker (mplot3d orders whole collections by depth: a machine
    drawn as its own collection was painted over the worker standing in front of it).
    The line work (floor outline, grid, region edges) is returned as a
    :class:`~ltl_human_motion.viz.lines.CellLines`: add more lines to it (a path), then
    call its ``update`` with the worker before the figure is drawn, so that no line is
    painted across a solid in front of it.
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    z = cell.floor_z
    solids = []
    faces = [(np.asarray(ob.to_trimesh().triangles), ob.color or "0.5", 0.9)
             for ob in cell.obstacles]
    faces += [(box_triangles(s_lo, s_hi), SUPPORT_COLOR, 1.0)
              for s_lo, s_hi in object_supports(cell)]
    for tri, color, alpha in faces:
        solids.append(tri)
        rgba = shaded(tri, color)
        rgba[:, 3] = alpha
        if solids_out is not None:
            solids_out.append((tri, rgba))
        else:
            ax.add_collection3d(Poly3DCollection(tri, facecolors=rgba, edgecolors="none"))
    lines = CellLines(ax, np.concatenate(solids) if solids else np.zeros((0, 3, 3)))
    # The floor is an outline, not a filled polygon: mplot3d sorts whole collections by
    # depth, and a big floor would be painted over the worker's legs.
    corners = np.array([(lo[0], lo[1], z), (hi[0], lo[1], z), (hi[0], hi[1], z),
                        (lo[0], hi[1], z)])
    lines.add(np.stack([corners, np.roll(corners, -1, axis=0)], axis=1), "#b0b0b0", 0.8)
    if grid:
        xs = np.arange(np.ceil(lo[0] / grid), np.floor(hi[0] / grid) + 1) * grid
        ys = np.arange(np.ceil(lo[1] / grid), np.floor(hi[1] / grid) + 1) * grid
        segs = [[(x, lo[1], z), (x, hi[1], z)] for x in xs]
        segs += [[(lo[0], y, z), (hi[0], y, z)] for y in ys]
        lines.add(np.array(segs), "#d0d0d0", 0.5)
    for i, (name, reg) in enumerate(cell.regions.items()):
        color = REGION_COLORS[i % len(REGION_COLORS)]
        if reg.is_box:
            lines.add(box_edges(reg.lo, reg.hi), color, 1.0, "--")
        else:
            ax.add_collection3d(Poly3DCollection(reg.shape.triangles, facecolors=color,
                                                 alpha=0.15, edgecolors="none"))
        if labels:
            c = reg.center
            ax.text(c[0], c[1], reg.hi[2] + 0.05, name, color=color, fontsize=7,
                    zorder=LINE_ZORDER)
    return lines


def object_polys(cell: Cell, positions: dict[str, np.ndarray] | None = None
                 ) -> dict[str, np.ndarray]:
    """Triangles of every object at ``positions`` (default: initial), name -> (F, 3, 3)."""
    out = {}
    for name, obj in cell.objects.items():
        tri = np.asarray(obj.shape.to_trimesh().triangles)
        if positions is not None and name in positions:
            tri = tri + (np.asarray(positions[name]) - obj.position)
        out[name] = tri
    return out
