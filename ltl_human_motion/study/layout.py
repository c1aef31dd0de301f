"""What differs between two layouts of a cell study: the changes, in words, and a top view.

:func:`layout_changes` compares two cells item by item (parts, furniture, regions, the start
region, the floor height): what was added or removed, what moved and by how much, what
changed its size or shape. :func:`plot_layouts` draws both layouts from above side by
side on one floor, the changed items in colour with an arrow from where they stood.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ltl_human_motion.viz._common import new_figure, save_figure

__all__ = ["LayoutChange", "draw_floor_plan", "floor_axes", "layout_changes",
           "plot_layouts"]

#: Shifts and size changes below this (m) are not changes.
TOLERANCE = 1e-6
_CHANGED = "tab:red"


@dataclass(frozen=True)
class LayoutChange:
    """One item that differs between layout A and layout B.

    Attributes
    ----------
    kind : str
        ``"part"``, ``"furniture"``, ``"region"`` or ``"floor"``.
    name : str
    change : str
        ``"moved"``, ``"resized"``, ``"reshaped"`` (the same bounds, other solids),
        ``"added"`` (only in B) or ``"removed"`` (only in A).
    shift : ndarray or None, shape (3,)
        B's centre minus A's (m), for a moved item.
    size_a, size_b : ndarray or None, shape (3,)
        Bounds' extent in A and in B (m).
    """

    kind: str
    name: str
    change: str
    shift: np.ndarray | None = None
    size_a: np.ndarray | None = None
    size_b: np.ndarray | None = None

    @property
    def distance(self) -> float:
        """How far the item moved (m; 0 unless moved)."""
        return 0.0 if self.shift is None else float(np.linalg.norm(self.shift))

    def describe(self) -> str:
        """The change in words, e.g. ``furniture workbench moved 0.25 m (+0.25 m in y)``."""
        what = f"{self.kind} {self.name}"
        if self.change == "moved":
            axes = ", ".join(f"{d:+.2f} m in {a}" for a, d in zip("xyz", self.shift)
                             if abs(d) > TOLERANCE)
            return f"{what} moved {self.distance:.2f} m ({axes})"
        if self.change == "resized":
            return f"{what} resized from {_dims(self.size_a)} to {_dims(self.size_b)}"
        if self.change == "reshaped":
            return f"{what} has other solids within the same bounds ({_dims(self.size_a)})"
        size = self.size_a if self.size_a is not None else self.size_b
        return f"{what} {self.change}" + ("" if size is None else f" ({_dims(size)})")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        out: dict[str, Any] = {"kind": self.kind, "name": self.name, "change": self.change,
                               "text": self.describe()}
        if self.shift is not None:
            out["shift"] = [float(v) for v in self.shift]
            out["distance"] = self.distance
        for key in ("size_a", "size_b"):
            value = getattr(self, key)
            if value is not None:
                out[key] = [float(v) for v in value]
        return out


def _dims(size: np.ndarray | None) -> str:
    return "?" if size is None else " x ".join(f"{v:.2f}" for v in size) + " m"


def _bounds(kind: str, item: Any) -> tuple[np.ndarray, np.ndarray]:
    if kind == "part":
        return item.shape.aabb()
    return item.aabb() if kind == "furniture" else (item.lo, item.hi)


def _solids(kind: str, item: Any) -> list[tuple[np.ndarray, np.ndarray]]:
    """The bounds of each solid (one for a part or a region)."""
    if kind == "furniture":
        return [p.aabb() for p in item.parts]
    return [_bounds(kind, item)]


def _items(cell: Any) -> dict[tuple[str, str], Any]:
    items: dict[tuple[str, str], Any] = {("part", n): o for n, o in cell.objects.items()}
    items.update({("furniture", ob.name): ob for ob in cell.obstacles})
    items.update({("region", n): r for n, r in cell.regions.items()})
    items[("region", cell.start_region.name)] = cell.start_region
    return items


def _compare(kind: str, name: str, a: Any, b: Any) -> LayoutChange | None:
    (lo_a, hi_a), (lo_b, hi_b) = _bounds(kind, a), _bounds(kind, b)
    size_a, size_b = hi_a - lo_a, hi_b - lo_b
    if np.any(np.abs(size_a - size_b) > TOLERANCE):
        return LayoutChange(kind, name, "resized", size_a=size_a, size_b=size_b)
    shift = 0.5 * (lo_b + hi_b) - 0.5 * (lo_a + hi_a)
    solids_a, solids_b = _solids(kind, a), _solids(kind, b)
    same = len(solids_a) == len(solids_b) and all(
        np.allclose(sa[0] + shift, sb[0], atol=1e-5) and np.allclose(sa[1] + shift, sb[1],
                                                                      atol=1e-5)
        for sa, sb in zip(solids_a, solids_b))
    if not same:
        return LayoutChange(kind, name, "reshaped", size_a=size_a, size_b=size_b)
    if np.any(np.abs(shift) > TOLERANCE):
        return LayoutChange(kind, name, "moved", shift=shift, size_a=size_a, size_b=size_b)
    return None


def layout_changes(a: Any, b: Any) -> list[LayoutChange]:
    """Every item that differs between cells ``a`` and ``b`` (scene ``Cell`` objects), in
    the order parts, furniture, regions, floor; an empty list when they are the same."""
    items_a, items_b = _items(a), _items(b)
    out = []
    for key in [*items_a, *(k for k in items_b if k not in items_a)]:
        kind, name = key
        if key not in items_b:
            lo, hi = _bounds(kind, items_a[key])
            out.append(LayoutChange(kind, name, "removed", size_a=hi - lo))
        elif key not in items_a:
            lo, hi = _bounds(kind, items_b[key])
            out.append(LayoutChange(kind, name, "added", size_b=hi - lo))
        else:
            change = _compare(kind, name, items_a[key], items_b[key])
            if change is not None:
                out.append(change)
    if abs(float(a.floor_z) - float(b.floor_z)) > TOLERANCE:
        out.append(LayoutChange("floor", "floor", "moved",
                                shift=np.array([0.0, 0.0, float(b.floor_z - a.floor_z)])))
    order = {"part": 0, "furniture": 1, "region": 2, "floor": 3}
    return sorted(out, key=lambda c: order[c.kind])


def draw_floor_plan(ax, cell: Any, robot: dict[str, Any] | None = None,
                    changed: frozenset[str] | set[str] = frozenset()) -> None:
    """The cell from above on ``ax``: furniture, regions (dashed), parts (squares), the
    robot's base; the items named in ``changed`` in red."""
    from matplotlib.patches import Rectangle
    for ob in cell.obstacles:
        hot = ob.name in changed
        for part in ob.parts:
            lo, hi = part.aabb()
            ax.add_patch(Rectangle(lo[:2], *(hi[:2] - lo[:2]),
                                   color=_CHANGED if hot else (ob.color or "grey"),
                                   alpha=0.55, lw=0, zorder=3))
        lo, hi = ob.aabb()
        ax.text(0.5 * (lo[0] + hi[0]), hi[1] + 0.04, ob.name, ha="center", fontsize=8,
                color=_CHANGED if hot else "black", zorder=5)
    for name, reg in cell.regions.items():
        hot = name in changed
        ax.add_patch(Rectangle(reg.lo[:2], *(reg.hi[:2] - reg.lo[:2]), fill=False, ls="--",
                               ec=_CHANGED if hot else "black", lw=1.4 if hot else 0.8,
                               zorder=4))
        ax.text(reg.lo[0], reg.lo[1] - 0.12, name, fontsize=8,
                color=_CHANGED if hot else "black", zorder=5)
    for name, obj in cell.objects.items():
        hot = name in changed
        # A black edge keeps a part's square apart from a heat map's cells.
        ax.plot(*obj.position[:2], "s", color=_CHANGED if hot else (obj.color or "black"),
                ms=7, mec="black", mew=1.2, zorder=5)
        ax.text(obj.position[0] + 0.06, obj.position[1] + 0.06, name, fontsize=8, zorder=5,
                color=_CHANGED if hot else "black")
    if robot:
        x, y = robot["base_xyz"][:2]
        ax.plot(x, y, "k^", ms=9, zorder=6)
        ax.text(x + 0.06, y - 0.15, "robot", fontsize=8, zorder=6)


def floor_axes(ax, lo: np.ndarray, hi: np.ndarray, title: str) -> None:
    """Limits ``lo`` (2,) to ``hi`` (2,), equal scales, metre labels and ``title``."""
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)


def _ghosts(ax, first: dict[tuple[str, str], Any], changes: Sequence[LayoutChange]) -> None:
    """Where each changed item of the first layout stood (dotted), with an arrow to where
    it stands now for a moved one."""
    from matplotlib.patches import Rectangle
    for c in changes:
        item = first.get((c.kind, c.name))
        if item is None:
            continue
        la, ha = _bounds(c.kind, item)
        ax.add_patch(Rectangle(la[:2], *(ha[:2] - la[:2]), fill=False, ls=":", lw=1.2,
                               ec=_CHANGED, zorder=6))
        if c.change == "moved":
            start = 0.5 * (la + ha)
            ax.annotate("", xy=(start + c.shift)[:2], xytext=start[:2], zorder=7,
                        arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.4})


def plot_layouts(cells: Sequence[Any], labels: Sequence[str], path: Path,
                 changes: Sequence[LayoutChange] = (), robot: dict[str, Any] | None = None,
                 bounds: tuple[np.ndarray, np.ndarray] | None = None) -> Path:
    """Top views of the layouts side by side on one floor (``bounds``: lo (2,), hi (2,));
    the items of ``changes`` in red; in the other views, dotted, where each stood in the
    first, with an arrow to where a moved one stands."""
    from ltl_human_motion.viz._common import cell_bounds
    if bounds is None:
        los, his = zip(*(cell_bounds(c, None, margin=0.3) for c in cells))
        bounds = (np.min(los, axis=0)[:2], np.max(his, axis=0)[:2])
    lo, hi = bounds
    fig = new_figure(5.2 * len(cells), 5.4, dpi=110)
    changed = {c.name for c in changes}
    for i, (cell, label) in enumerate(zip(cells, labels)):
        ax = fig.add_subplot(1, len(cells), i + 1)
        draw_floor_plan(ax, cell, robot, changed)
        if i > 0:
            _ghosts(ax, _items(cells[0]), changes)
        floor_axes(ax, lo, hi, f"layout {label} ({cell.name}), from above")
    text = "; ".join(c.describe() for c in changes) or "no difference"
    fig.suptitle(f"What differs (red; dotted: where it stood in {labels[0]}): {text}",
                 fontsize=9, wrap=True)
    fig.tight_layout()
    save_figure(fig, path)
    return path
