"""Lines drawn over the solids with the pieces that something hides cut out.

mplot3d paints whole collections back to front by one depth each, so a floor grid, a
path or a region's wire box is either painted entirely over the worker or entirely under
it: the grid crossed the legs, a region's edge the face. Here every line is cut into
short pieces; a piece is kept only if the straight ray from it to the camera misses the
obstacles, the objects and the worker's capsules, and the kept pieces are drawn above
every solid. A line in front of the worker is then drawn over it, a line behind it is
hidden, as in a real view.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.kernel.segments import segment_distances

__all__ = ["LINE_ZORDER", "CellLines", "camera_position", "chop", "hidden_by_capsules",
           "hidden_by_triangles"]

#: Above every collection mplot3d sorts (their z-orders count up from about 1).
LINE_ZORDER = 1.0e5
#: Length of the pieces the lines are cut into, m.
PIECE_LENGTH = 0.04
#: Triangles tested at once against all pieces (bounds the memory of the test).
_TRI_CHUNK = 64


def camera_position(ax) -> np.ndarray:
    """Position of the camera of 3D axes ``ax`` in data coordinates, shape (3,).

    The projection ``M = ax.get_proj()`` maps the camera centre ``C`` to a point at
    infinity in front of the viewer: the x, y and w rows of ``M [C, 1]`` are zero.
    """
    m = np.asarray(ax.get_proj(), dtype=np.float64)
    rows = m[[0, 1, 3]]
    return np.linalg.solve(rows[:, :3], -rows[:, 3])


def chop(segments: np.ndarray, step: float = PIECE_LENGTH) -> tuple[np.ndarray, np.ndarray]:
    """Cut segments (M, 2, 3) into pieces no longer than ``step``.

    Returns
    -------
    pieces : ndarray, shape (N, 2, 3)
        In the order of the segments, each segment's pieces from its start to its end.
    owner : ndarray, shape (N,)
        Index of the segment each piece belongs to.
    """
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 3)
    if not len(seg):
        return np.zeros((0, 2, 3)), np.zeros(0, dtype=np.int64)
    length = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1)
    counts = np.maximum(np.ceil(length / step).astype(np.int64), 1)
    owner = np.repeat(np.arange(len(seg)), counts)
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    k = np.arange(len(owner)) - first[owner]
    t0 = (k / counts[owner])[:, None]
    t1 = ((k + 1) / counts[owner])[:, None]
    a, d = seg[owner, 0], seg[owner, 1] - seg[owner, 0]
    return np.stack([a + t0 * d, a + t1 * d], axis=1), owner


def hidden_by_triangles(points: np.ndarray, eye: np.ndarray, triangles: np.ndarray
                        ) -> np.ndarray:
    """Which points (N, 3) a triangle (F, 3, 3) hides from ``eye`` (3,), shape (N,) bool.

    A point is hidden if the segment from it to the eye crosses a triangle
    (Moeller-Trumbore); a point on a triangle's own surface is not hidden by it.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    tri = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    hidden = np.zeros(len(p), dtype=bool)
    if not len(p) or not len(tri):
        return hidden
    d = np.asarray(eye, dtype=np.float64)[None, :] - p                  # (N, 3)
    for s in range(0, len(tri), _TRI_CHUNK):
        t = tri[s:s + _TRI_CHUNK]
        e1, e2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]                    # (F, 3)
        h = np.cross(d[:, None, :], e2[None])                           # (N, F, 3)
        a = np.einsum("fk,nfk->nf", e1, h)
        ok = np.abs(a) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, a, 1.0), 0.0)
        sv = p[:, None, :] - t[None, :, 0]                              # (N, F, 3)
        u = inv * np.einsum("nfk,nfk->nf", sv, h)
        q = np.cross(sv, e1[None])
        v = inv * np.einsum("nk,nfk->nf", d, q)
        dist = inv * np.einsum("fk,nfk->nf", e2, q)
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (dist > 1e-6) & (dist < 1.0)
        hidden |= hit.any(axis=1)
    return hidden


def hidden_by_capsules(points: np.ndarray, eye: np.ndarray, segments: np.ndarray,
                       radii: np.ndarray) -> np.ndarray:
    """Which points (N, 3) a capsule (axes (K, 2, 3), radii (K,)) hides from ``eye``.

    A point is hidden if the segment from it to the eye passes within a capsule's radius
    of its axis (a point inside a capsule is hidden too). Shape (N,) bool.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    caps = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 3)
    if not len(p) or not len(caps):
        return np.zeros(len(p), dtype=bool)
    rays = np.stack([p, np.broadcast_to(np.asarray(eye, dtype=np.float64), p.shape)], axis=1)
    return (segment_distances(rays, caps) < np.asarray(radii)[None, :]).any(axis=1)


def _polyline(pieces: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """The kept pieces as one polyline with NaN rows between runs, shape (P, 3).

    A run goes on while each kept piece starts where the previous one ended (so a dash
    pattern runs on along a path made of many short segments).
    """
    idx = np.flatnonzero(keep)
    if not len(idx):
        return np.full((1, 3), np.nan)
    new_run = np.ones(len(idx), dtype=bool)
    new_run[1:] = ((idx[1:] != idx[:-1] + 1)
                   | ~np.all(np.isclose(pieces[idx[1:], 0], pieces[idx[:-1], 1]), axis=1))
    starts = np.flatnonzero(new_run)
    out = np.full((len(idx) + 2 * len(starts) - 1, 3), np.nan)
    row = 0
    for j, s in enumerate(starts):
        e = starts[j + 1] if j + 1 < len(starts) else len(idx)
        run = pieces[idx[s:e]]
        out[row:row + len(run) + 1] = np.concatenate([run[:1, 0], run[:, 1]])
        row += len(run) + 2
    return out


@dataclass
class _LineGroup:
    pieces: np.ndarray                 # (N, 2, 3)
    artist: object
    static_hidden: np.ndarray | None = None
    visible: np.ndarray | None = None  # (N,) after the last update


@dataclass
class CellLines:
    """The line work of one 3D axes, drawn above the solids with hidden pieces removed.

    Parameters
    ----------
    ax : Axes3D
        Its view (limits, angles) must be set before the first :meth:`update`.
    static_triangles : ndarray, shape (F, 3, 3)
        Solids that never move (obstacles, drawn supports).
    """

    ax: object
    static_triangles: np.ndarray
    groups: list[_LineGroup] = field(default_factory=list)
    _eye: np.ndarray | None = None

    def add(self, segments: np.ndarray, color: str, linewidth: float = 0.8,
            linestyle: str = "-") -> None:
        """Add segments (M, 2, 3) drawn in one style."""
        pieces, _ = chop(segments)
        (artist,) = self.ax.plot([], [], [], color=color, lw=linewidth, ls=linestyle,
                                 zorder=LINE_ZORDER)
        self.groups.append(_LineGroup(pieces, artist))

    def update(self, capsules: tuple[np.ndarray, np.ndarray] | None = None,
               triangles: np.ndarray | None = None) -> None:
        """Recompute what is visible with the moving solids at their current place.

        Parameters
        ----------
        capsules : (ndarray (K, 2, 3), ndarray (K,)), optional
            The worker's capsules (axes and radii).
        triangles : ndarray, shape (F, 3, 3), optional
            Moving solids (objects at this frame).
        """
        if self._eye is None:
            self._eye = camera_position(self.ax)
        for g in self.groups:
            mid = 0.5 * (g.pieces[:, 0] + g.pieces[:, 1])
            if g.static_hidden is None:
                g.static_hidden = hidden_by_triangles(mid, self._eye, self.static_triangles)
            hidden = g.static_hidden.copy()
            if triangles is not None and len(triangles):
                todo = ~hidden
                hidden[todo] = hidden_by_triangles(mid[todo], self._eye, triangles)
            if capsules is not None:
                todo = ~hidden
                hidden[todo] = hidden_by_capsules(mid[todo], self._eye, *capsules)
            g.visible = ~hidden
            line = _polyline(g.pieces, g.visible)
            g.artist.set_data_3d(line[:, 0], line[:, 1], line[:, 2])
