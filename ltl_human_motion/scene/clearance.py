"""Clearance of many capsules to all obstacle parts of a cell at once.

:meth:`Shape.capsule_clearance` answers for one part; a body check asks for every frame,
every capsule and every part. :class:`PartSet` holds the parts' bounding boxes (and the
axis-aligned boxes' centres and half extents) as arrays, so that the bound of every
(capsule, part) pair is computed in one vectorized pass, and only the pairs whose bound
is below ``exact_below`` are computed exactly: axis-aligned boxes all together in closed
form (:func:`~ltl_human_motion.scene.geometry.segment_aabb_distance`), other parts with
their own exact method. The values are those of the per-part methods: exact below
``exact_below``, a lower bound (the bounding-box gap minus the radius) at or above it.

:meth:`PartSet.body_clearance` first compares whole bodies (the bounding box of a
frame's capsules) with the parts: a part far from a body is not compared capsule by
capsule, and gets that (smaller, still at least ``exact_below``) bound instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import ModuleType

import numpy as np

from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.scene.geometry import box_gap, point_bounds, segment_aabb_distance
from ltl_human_motion.scene.shapes import EXACT_BELOW, Box, Shape

__all__ = ["PartSet", "part_set"]


class PartSet:
    """The solid parts of a cell's obstacles, arranged for vectorized clearance queries.

    Parameters
    ----------
    parts : sequence of Shape

    Attributes
    ----------
    parts : tuple of Shape
    lo, hi : ndarray, shape (P, 3)
        Bounding boxes of the parts.
    is_box : ndarray of bool, shape (P,)
        Axis-aligned boxes (computed together in closed form).
    center, half : ndarray, shape (P, 3)
        Centre and half extents of the axis-aligned boxes (zeros for other parts).
    """

    def __init__(self, parts: Sequence[Shape]) -> None:
        self.parts = tuple(parts)
        n = len(self.parts)
        self.lo = np.zeros((n, 3))
        self.hi = np.zeros((n, 3))
        self.center = np.zeros((n, 3))
        self.half = np.zeros((n, 3))
        self.is_box = np.zeros(n, dtype=bool)
        for i, part in enumerate(self.parts):
            self.lo[i], self.hi[i] = part.aabb()
            if isinstance(part, Box) and part.axis_aligned:
                self.is_box[i] = True
                self.center[i], self.half[i] = part.center, part.half
        self._others = [i for i in range(n) if not self.is_box[i]]

    def __len__(self) -> int:
        return len(self.parts)

    def _exact(self, a: np.ndarray, b: np.ndarray, radii: np.ndarray,
               part: np.ndarray) -> np.ndarray:
        """Exact clearance of capsules ``[a, b]`` (N, 3) with radii (N,) to parts (N,)."""
        out = np.empty(len(part))
        box = self.is_box[part]
        if box.any():
            c, h = self.center[part[box]], self.half[part[box]]
            nb = _compiled_bounds()
            if nb is not None:
                dist = np.empty(int(box.sum()))
                nb.segment_aabb_distance(np.ascontiguousarray(a[box] - c),
                                         np.ascontiguousarray(b[box] - c),
                                         np.ascontiguousarray(-h), np.ascontiguousarray(h),
                                         dist)
            else:
                dist = segment_aabb_distance(a[box] - c, b[box] - c, -h, h)
            out[box] = dist - radii[box]
        for k in self._others:
            sel = part == k
            if sel.any():
                seg = np.stack([a[sel], b[sel]], axis=-2)
                out[sel] = self.parts[k]._exact_capsule_clearance(seg, radii[sel])
        return out

    def exact_pairs(self, a: np.ndarray, b: np.ndarray, radii: np.ndarray,
                    part: np.ndarray) -> np.ndarray:
        """Exact clearance (N,) of capsules ``[a, b]`` (N, 3), (N, 3) with radii (N,) to
        one part each, indices (N,)."""
        return self._exact(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64),
                           np.asarray(radii, dtype=np.float64), np.asarray(part))

    def _refine(self, a: np.ndarray, b: np.ndarray, radii: np.ndarray, part: np.ndarray,
                exact_below: float) -> np.ndarray:
        """Clearance of capsules (N,) to one part each: bound, exact below ``exact_below``."""
        out = box_gap(np.minimum(a, b), np.maximum(a, b), self.lo[part],
                       self.hi[part]) - radii
        near = np.flatnonzero(out < exact_below)
        if near.size:
            out[near] = self._exact(a[near], b[near], radii[near], part[near])
        return out

    def pair_clearance(self, segments: np.ndarray, radii: np.ndarray,
                       exact_below: float = EXACT_BELOW) -> np.ndarray:
        """Clearance of every capsule to every part.

        Parameters
        ----------
        segments : ndarray, shape (N, 2, 3)
        radii : ndarray, shape (N,)
        exact_below : float
            Pairs whose bound is below this are computed exactly.

        Returns
        -------
        clearance : ndarray, shape (N, P)
            As :meth:`Shape.capsule_clearance` of each part.
        """
        nb = _compiled_bounds()
        if nb is not None and np.isfinite(segments).all():
            return self._pair_clearance_compiled(nb, segments, radii, exact_below)
        a, b = segments[:, 0], segments[:, 1]
        out = box_gap(np.minimum(a, b)[:, None], np.maximum(a, b)[:, None],
                       self.lo, self.hi) - radii[:, None]
        n_idx, p_idx = np.nonzero(out < exact_below)
        if n_idx.size:
            out[n_idx, p_idx] = self._exact(a[n_idx], b[n_idx], radii[n_idx], p_idx)
        return out

    def _pair_clearance_compiled(self, nb: ModuleType, segments: np.ndarray,
                                 radii: np.ndarray, exact_below: float) -> np.ndarray:
        """:meth:`pair_clearance` of finite capsules (N, 2, 3) with radii (N,), the bounds
        and the boxes' exact values compiled (:func:`._clearance_numba.pair_bounds`), the
        other parts' exact values as in numpy; (N, P)."""
        seg = np.ascontiguousarray(segments, dtype=np.float64)
        rad = np.ascontiguousarray(radii, dtype=np.float64)
        P = len(self.parts)
        out = np.empty((len(seg), P))
        others = np.empty(out.size, dtype=np.intp)
        n_others = nb.pair_bounds(seg, rad, self.lo, self.hi, float(exact_below), self.is_box,
                                  self.center, self.half, out, others)
        if n_others:
            n_idx, p_idx = np.divmod(others[:n_others], P)
            out.ravel()[others[:n_others]] = self._exact(seg[n_idx, 0], seg[n_idx, 1],
                                                         rad[n_idx], p_idx)
        return out

    def capsule_clearance(self, segments: np.ndarray, radii: np.ndarray,
                          exact_below: float = EXACT_BELOW) -> np.ndarray:
        """Smallest clearance of capsules (..., 2, 3) with radii (broadcast against (...))
        to any part, shape (...): the minimum over the parts of
        :meth:`Shape.capsule_clearance` with this ``exact_below``; ``inf`` without parts.
        """
        seg = np.asarray(segments, dtype=np.float64)
        if seg.ndim < 2 or seg.shape[-2:] != (2, 3):
            raise ValueError(f"segments must have shape (..., 2, 3), got {seg.shape}")
        lead = seg.shape[:-2]
        if not self.parts:
            return np.full(lead, np.inf)
        rad = np.broadcast_to(np.asarray(radii, dtype=np.float64), lead).reshape(-1)
        flat = seg.reshape(-1, 2, 3)
        if flat.shape[0] == 0:
            return np.full(lead, np.inf)
        return self.pair_clearance(flat, rad, exact_below).min(axis=1).reshape(lead)

    def body_clearance(self, segments: np.ndarray, radii: np.ndarray,
                       exact_below: float = EXACT_BELOW,
                       bounds: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """Smallest clearance of each body (a set of capsules) to any part.

        Parameters
        ----------
        segments : array-like, shape (..., K, 2, 3)
            The capsules of each body (frame).
        radii : array-like, shape (K,)
        exact_below : float
        bounds : (ndarray (..., 3), ndarray (..., 3)), optional
            A box around each body's capsule end points (e.g. of its joints), if known.

        Returns
        -------
        clearance : ndarray, shape (...)
            Exact below ``exact_below``; at or above it a lower bound (for a part far
            from the body, the gap between the body's and the part's bounding boxes
            minus the largest radius); ``inf`` without parts.
        """
        seg = np.asarray(segments, dtype=np.float64)
        if seg.ndim < 3 or seg.shape[-2:] != (2, 3):
            raise ValueError(f"segments must have shape (..., K, 2, 3), got {seg.shape}")
        lead, K = seg.shape[:-3], seg.shape[-3]
        if not self.parts:
            return np.full(lead, np.inf)
        rad = np.broadcast_to(np.asarray(radii, dtype=np.float64), (K,))
        if K == 0 or int(np.prod(lead)) == 0:
            return np.full(lead, np.inf)
        if bounds is None:
            lo, hi = point_bounds(seg.reshape(-1, 2 * K, 3))
        else:
            lo, hi = (np.asarray(b, dtype=np.float64).reshape(-1, 3) for b in bounds)
        nb = _compiled_bounds()
        if nb is not None:
            return self._body_clearance_compiled(nb, seg.reshape(-1, K, 2, 3), rad, lo, hi,
                                                 exact_below).reshape(lead)
        body = box_gap(lo[:, None], hi[:, None], self.lo, self.hi) - rad.max()     # (F, P)
        f_idx, p_idx = np.nonzero(body < exact_below)
        if f_idx.size:
            # Each (body, part) pair that is near: its K capsules against that part.
            caps = seg.reshape(-1, K, 2, 3)[f_idx]                          # (M, K, 2, 3)
            part = np.repeat(p_idx, K)
            vals = self._refine(caps[:, :, 0].reshape(-1, 3), caps[:, :, 1].reshape(-1, 3),
                                np.tile(rad, f_idx.size), part, exact_below)
            body[f_idx, p_idx] = vals.reshape(-1, K).min(axis=1)
        out = body.min(axis=1)
        return out.reshape(lead)


    def _body_clearance_compiled(self, nb: ModuleType, seg: np.ndarray, rad: np.ndarray,
                                 lo: np.ndarray, hi: np.ndarray, exact_below: float
                                 ) -> np.ndarray:
        """:meth:`body_clearance` of bodies (F, K, 2, 3) with their boxes lo, hi (F, 3),
        the bounds and the boxes' exact values compiled (:mod:`._clearance_numba`; in one
        pass where every part is an axis-aligned box), the other parts' as in numpy."""
        seg = np.ascontiguousarray(seg, dtype=np.float64)
        if not self._others and np.isfinite(seg).all() and np.isfinite(lo).all() \
                and np.isfinite(hi).all():
            out = np.empty(len(seg))
            nb.body_clearance_boxes(seg, np.ascontiguousarray(rad, dtype=np.float64),
                                    np.ascontiguousarray(lo), np.ascontiguousarray(hi),
                                    self.lo, self.hi, float(exact_below), self.center,
                                    self.half, out)
            return out
        body, f_idx, p_idx, caps = nb.body_bounds(
            seg, np.ascontiguousarray(rad, dtype=np.float64), np.ascontiguousarray(lo),
            np.ascontiguousarray(hi), self.lo, self.hi, float(exact_below))
        if f_idx.size:
            K = seg.shape[1]
            others = np.empty(caps.size, dtype=np.intp)
            n_others = nb.exact_box_caps(seg, rad, f_idx, p_idx, caps, float(exact_below),
                                         self.is_box, self.center, self.half, others)
            if n_others:
                m, k = np.divmod(others[:n_others], K)
                ends = seg[f_idx[m], k]                                          # (N, 2, 3)
                caps.ravel()[others[:n_others]] = self._exact(ends[:, 0], ends[:, 1],
                                                              rad[k], p_idx[m])
            body[f_idx, p_idx] = caps.min(axis=1)
        return body.min(axis=1)


def _compiled_bounds() -> ModuleType | None:
    """The compiled bounds (:mod:`._clearance_numba`), where the compiled kernel is in use."""
    from ltl_human_motion.kernel.segments import compiled_module
    return compiled_module("ltl_human_motion.scene._clearance_numba")


_PART_SETS: BoundedCache[PartSet] = BoundedCache(64)


def part_set(obstacles: tuple) -> PartSet:
    """The :class:`PartSet` of a cell's obstacles (``cell.obstacles``), built once.

    Cells made from one another (jittered objects or regions) share the obstacle tuple
    and so the part set. The cache keeps the tuple alive, so its id stays unique.
    """
    return _PART_SETS.get_or_build(
        "parts", lambda: PartSet([p for ob in obstacles for p in ob.parts]), owner=obstacles)
