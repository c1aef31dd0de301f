"""Whether a part can be moved between two places at all: a flood fill of the free space
of the part's centre (configuration space of a translating box).

Parts only translate (:mod:`.feasibility`), so the centre of part ``O`` can be where the
box of ``O`` meets no obstacle: the obstacles grown by the part's half extents (a
Minkowski sum). :func:`can_pass` fills that space on a voxel grid from where the part
lies and asks whether it reaches a place where the task puts it. The answer only ever
errs towards yes: a voxel counts as blocked only where it lies wholly inside one grown
axis-aligned box; obstacle parts of other shapes (cylinders, turned boxes, meshes) are
not grown at all. So it refuses only a part that no motion can bring there, such as a
casting wider than a machine's door opening.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.scene.shapes import Box

__all__ = ["VOXEL", "can_pass"]

#: Edge of the voxels, metres.
VOXEL = 0.04

_FREE: BoundedCache = BoundedCache(32)
#: Components of the free space per obstacle layout (owner: the cell's obstacle tuple,
#: which cells jittered from one another share), workspace and part size.
_LABELS: BoundedCache = BoundedCache(32)


def _free_space(cell, half: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Free voxels (X, Y, Z) of bool for a box of half extents ``half`` (3,), and the
    grid's origin (3,) (the centre of voxel (0, 0, 0))."""
    lo, hi = (np.asarray(v, dtype=np.float64) for v in cell.workspace)
    shape = np.maximum(np.ceil((hi - lo) / VOXEL).astype(int), 1)
    free = np.ones(shape, dtype=bool)
    origin = lo + VOXEL / 2
    for part in cell.part_set.parts:
        if not (isinstance(part, Box) and part.axis_aligned):
            continue
        p_lo, p_hi = part.aabb()
        g_lo, g_hi = p_lo - half, p_hi + half
        # voxels whose whole cube lies inside the grown box
        a = np.ceil((g_lo + VOXEL / 2 - origin) / VOXEL).astype(int)
        b = np.floor((g_hi - VOXEL / 2 - origin) / VOXEL).astype(int) + 1
        a, b = np.clip(a, 0, shape), np.clip(b, 0, shape)
        if np.all(b > a):
            free[a[0]:b[0], a[1]:b[1], a[2]:b[2]] = False
    return free, origin


def _reachable(cell, part: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The labelled free space (:func:`_components`) of ``part``'s size, the grid's origin
    and the labels its centre can reach from where it lies (none: every voxel, the part
    lies where no voxel is free); cached per cell (by identity) and part."""
    return _FREE.get_or_build((part,), lambda: _fill(cell, part), owner=cell)


def _components(cell, half: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The labelled components of the free space (:func:`_free_space`) and the grid's
    origin; built once per obstacle layout, workspace and part size (a part moved to
    another place of the same cell reuses it)."""
    def build() -> tuple[np.ndarray, np.ndarray]:
        from scipy import ndimage
        free, origin = _free_space(cell, half)
        return ndimage.label(free)[0], origin
    lo, hi = (np.asarray(v, dtype=np.float64) for v in cell.workspace)
    key = (tuple(lo.tolist()), tuple(hi.tolist()), tuple(half.tolist()))
    return _LABELS.get_or_build(key, build, owner=cell.obstacles)


def _fill(cell, part: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_reachable`, computed."""
    p_lo, p_hi = (np.asarray(v, dtype=np.float64) for v in cell.object(part).shape.aabb())
    labels, origin = _components(cell, (p_hi - p_lo) / 2)
    k = np.clip(np.round(((p_lo + p_hi) / 2 - origin) / VOXEL).astype(int), 0,
                np.array(labels.shape) - 1)
    near = labels[max(k[0] - 1, 0):k[0] + 2, max(k[1] - 1, 0):k[1] + 2,
                  max(k[2] - 1, 0):k[2] + 2]
    return labels, origin, np.unique(near[near > 0])


def can_pass(cell, part: str, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Whether the centre of ``part`` can get from where it lies into the box
    [``lo``, ``hi``] (3,) without its box meeting an obstacle (module docstring: the
    answer errs towards True)."""
    labels, origin, seeds = _reachable(cell, part)
    a = np.floor((np.asarray(lo) - origin) / VOXEL).astype(int)
    b = np.ceil((np.asarray(hi) - origin) / VOXEL).astype(int) + 1
    a, b = np.clip(a, 0, labels.shape), np.clip(b, 0, labels.shape)
    if np.any(b <= a) or not seeds.size:
        return True
    return bool(np.isin(labels[a[0]:b[0], a[1]:b[1], a[2]:b[2]], seeds).any())
