"""Compiled loops of :mod:`ltl_human_motion.planning.navigation` (imported on first use):
the bilinear floor clearance of :class:`~ltl_human_motion.planning.navigation.ClearanceMap`
and the trilinear obstacle distance of its ``_trilinear``, operation for operation as the
numpy paths compute them (the same numbers; tests hold them together), without the numpy
calls' overhead on the few dozen points of a search step."""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def _cell(grid, v):
    """``searchsorted(grid, v, side="right") - 1`` clamped to ``[0, len(grid) - 2]``."""
    lo, hi = 0, grid.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if grid[mid] <= v:
            lo = mid + 1
        else:
            hi = mid
    return min(max(lo - 1, 0), grid.shape[0] - 2)


@_jit
def _bilinear_at(xs, ys, values, in_lo, in_hi, x, y):
    """The clearance at (x, y) on the grid values (nx, ny) at xs (nx,), ys (ny,); -1
    outside the box in_lo, in_hi (2,)."""
    if not (x >= in_lo[0] and x <= in_hi[0] and y >= in_lo[1] and y <= in_hi[1]):
        return -1.0
    i, j = _cell(xs, x), _cell(ys, y)
    x0, y0 = xs[i], ys[j]
    tx = (x - x0) / (xs[i + 1] - x0)
    ty = (y - y0) / (ys[j + 1] - y0)
    sx, sy = 1 - tx, 1 - ty
    v = 0.0 + values[i, j] * sx * sy
    v = v + values[i, j + 1] * sx * ty
    v = v + values[i + 1, j] * tx * sy
    return v + values[i + 1, j + 1] * tx * ty


@_jit
def bilinear(xs, ys, values, in_lo, in_hi, xy, out) -> None:
    """out[n] = clearance at xy[n] (N, 2) on the grid values (nx, ny) at xs (nx,), ys
    (ny,); -1 outside the box in_lo, in_hi (2,)."""
    for n in range(xy.shape[0]):
        out[n] = _bilinear_at(xs, ys, values, in_lo, in_hi, xy[n, 0], xy[n, 1])


@_jit
def _trilinear_at(grid, u0, u1, u2):
    """Trilinear interpolation of grid (nx, ny, nz) at index coordinates (u0, u1, u2),
    finite: corners clamped to the grid, weights ``1 - f`` and ``1 - (1 - f)``, the
    eight corners summed in C order."""
    nx, ny, nz = grid.shape
    b0, b1, b2 = math.floor(u0), math.floor(u1), math.floor(u2)
    w00 = 1.0 - (u0 - b0)
    w10 = 1.0 - (u1 - b1)
    w20 = 1.0 - (u2 - b2)
    w01, w11, w21 = 1.0 - w00, 1.0 - w10, 1.0 - w20
    i0, i1 = int(min(max(b0, 0.0), nx - 1)), int(min(max(b0 + 1, 0.0), nx - 1))
    j0, j1 = int(min(max(b1, 0.0), ny - 1)), int(min(max(b1 + 1, 0.0), ny - 1))
    k0, k1 = int(min(max(b2, 0.0), nz - 1)), int(min(max(b2 + 1, 0.0), nz - 1))
    v = 0.0
    v = v + grid[i0, j0, k0] * w00 * w10 * w20
    v = v + grid[i0, j0, k1] * w00 * w10 * w21
    v = v + grid[i0, j1, k0] * w00 * w11 * w20
    v = v + grid[i0, j1, k1] * w00 * w11 * w21
    v = v + grid[i1, j0, k0] * w01 * w10 * w20
    v = v + grid[i1, j0, k1] * w01 * w10 * w21
    v = v + grid[i1, j1, k0] * w01 * w11 * w20
    v = v + grid[i1, j1, k1] * w01 * w11 * w21
    return v


@_jit
def trilinear(grid, u, out) -> None:
    """out[n] = trilinear interpolation of grid (nx, ny, nz) at index coordinates u[n]
    (N, 3), finite (:func:`_trilinear_at`)."""
    for n in range(u.shape[0]):
        out[n] = _trilinear_at(grid, u[n, 0], u[n, 1], u[n, 2])


@_jit
def _field_distance(grid, lo, res, far, p0, p1, p2):
    """The obstacle field's distance at one point (``ObstacleField.distance``): the
    trilinear value at index coordinates ``(p - lo) / res``, at least ``far`` off the
    grid."""
    nx, ny, nz = grid.shape
    u0, u1, u2 = (p0 - lo[0]) / res, (p1 - lo[1]) / res, (p2 - lo[2]) / res
    outside = (u0 < 0 or u0 > nx - 1 or u1 < 0 or u1 > ny - 1 or u2 < 0 or u2 > nz - 1)
    v = _trilinear_at(grid, u0, u1, u2)
    return max(v, far) if outside else v


@_jit
def field_distances(grid, lo, res, far, pts, out) -> None:
    """out[n] = the obstacle field's distance at pts[n] (N, 3), finite
    (:func:`_field_distance`)."""
    for n in range(pts.shape[0]):
        out[n] = _field_distance(grid, lo, res, far, pts[n, 0], pts[n, 1], pts[n, 2])


@_jit
def _box_near(lo0, lo1, lo2, hi0, hi1, hi2, part_lo, part_hi, parts, n_parts, limit2):
    """Whether the box lo, hi comes nearer than ``sqrt(limit2)`` to the box of any of
    the parts ``parts[:n_parts]`` (part_lo, part_hi (P, 3))."""
    for q in range(n_parts):
        p = parts[q]
        g0 = max(max(part_lo[p, 0] - hi0, lo0 - part_hi[p, 0]), 0.0)
        g1 = max(max(part_lo[p, 1] - hi1, lo1 - part_hi[p, 1]), 0.0)
        g2 = max(max(part_lo[p, 2] - hi2, lo2 - part_hi[p, 2]), 0.0)
        if g0 * g0 + g1 * g1 + g2 * g2 < limit2:
            return True
    return False


@_jit
def _group_least(grid, lo, res, far, c0, c1, c2, offsets, start, stop, thr, allowed):
    """The least field distance (:func:`_field_distance`) over the points c + offsets[k],
    ``start <= k < stop``, read until one has ``distance - thr < allowed`` (that one's
    distance); ``inf`` for no points."""
    least = np.inf
    for k in range(start, stop):
        d = _field_distance(grid, lo, res, far, c0 + offsets[k, 0], c1 + offsets[k, 1],
                            c2 + offsets[k, 2])
        if d < least:
            least = d
            if not d - thr >= allowed:
                break
    return least


@_jit
def held_points_clear(grid, lo, res, far, centres, offsets, starts, group_lo, group_hi,
                      part_lo, part_hi, limit, thr, standing, out) -> None:
    """out[m] = whether every point centres[m, s] + offsets[k] (centres (M, S, 3), offsets
    (K, 3), finite) has field distance (:func:`_field_distance`) ``d`` with ``d - thr >=
    allowed``: 0, or for ``standing[m]`` min(least ``d - thr`` at s = 0, 0) - 0.005.

    offsets[starts[g]:starts[g + 1]] lie in the box group_lo[g], group_hi[g] (G, 3);
    a group whose box at a sample keeps ``limit`` from every obstacle part's box
    (part_lo, part_hi (P, 3)) is not read (``limit``: ``thr`` and the interpolation
    error, so its points pass; ``inf`` reads every point). Stops at the first point
    that fails."""
    M, S, P, G = centres.shape[0], centres.shape[1], part_lo.shape[0], starts.shape[0] - 1
    limit2 = limit * limit
    olo0, olo1, olo2 = group_lo[:, 0].min(), group_lo[:, 1].min(), group_lo[:, 2].min()
    ohi0, ohi1, ohi2 = group_hi[:, 0].max(), group_hi[:, 1].max(), group_hi[:, 2].max()
    every = np.arange(P)
    near = np.empty(P, dtype=np.int64)
    for m in range(M):
        lo0 = lo1 = lo2 = np.inf
        hi0 = hi1 = hi2 = -np.inf
        for s in range(S):
            lo0, hi0 = min(lo0, centres[m, s, 0]), max(hi0, centres[m, s, 0])
            lo1, hi1 = min(lo1, centres[m, s, 1]), max(hi1, centres[m, s, 1])
            lo2, hi2 = min(lo2, centres[m, s, 2]), max(hi2, centres[m, s, 2])
        n_near = 0
        for p in range(P):
            if _box_near(lo0 + olo0, lo1 + olo1, lo2 + olo2, hi0 + ohi0, hi1 + ohi1,
                         hi2 + ohi2, part_lo, part_hi, every[p:p + 1], 1, limit2):
                near[n_near] = p
                n_near += 1
        ok = True
        allowed = 0.0
        first = 0
        if n_near and standing[m]:
            # the least at the first sample over every group near (the others keep thr)
            c0, c1, c2 = centres[m, 0, 0], centres[m, 0, 1], centres[m, 0, 2]
            least = np.inf
            for g in range(G):
                if _box_near(c0 + group_lo[g, 0], c1 + group_lo[g, 1], c2 + group_lo[g, 2],
                             c0 + group_hi[g, 0], c1 + group_hi[g, 1], c2 + group_hi[g, 2],
                             part_lo, part_hi, near, n_near, limit2):
                    least = min(least, _group_least(grid, lo, res, far, c0, c1, c2, offsets,
                                                    starts[g], starts[g + 1], thr, -np.inf))
            allowed = min(least - thr, 0.0) - 0.005
            first = 1
        for s in range(first, S if n_near else 0):
            c0, c1, c2 = centres[m, s, 0], centres[m, s, 1], centres[m, s, 2]
            if not _box_near(c0 + olo0, c1 + olo1, c2 + olo2, c0 + ohi0, c1 + ohi1, c2 + ohi2,
                             part_lo, part_hi, near, n_near, limit2):
                continue
            for g in range(G):
                if _box_near(c0 + group_lo[g, 0], c1 + group_lo[g, 1], c2 + group_lo[g, 2],
                             c0 + group_hi[g, 0], c1 + group_hi[g, 1], c2 + group_hi[g, 2],
                             part_lo, part_hi, near, n_near, limit2):
                    d = _group_least(grid, lo, res, far, c0, c1, c2, offsets, starts[g],
                                     starts[g + 1], thr, allowed)
                    if not d - thr >= allowed:
                        ok = False
                        break
            if not ok:
                break
        out[m] = ok


@_jit
def _joint_distance(grid, lo, res, far, pos, m, s, j, dj, read, stamp):
    """The field distance at joint j of sample s of candidate m (pos (M, S, J, 3)), read
    once per ``stamp`` into dj (J,) (``read`` (J,): the stamp it was read at)."""
    if read[j] != stamp:
        dj[j] = _field_distance(grid, lo, res, far, pos[m, s, j, 0], pos[m, s, j, 1],
                                pos[m, s, j, 2])
        read[j] = stamp
    return dj[j]


@_jit
def _samples_box(pos, m, samples, part_lo, part_hi):
    """The bounding box (lo x, y, z, hi x, y, z) of candidate ``m``'s joints over
    ``samples`` in ``pos`` (M, S, J, 3), and its least box gap to the parts' boxes
    (part_lo, part_hi (P, 3))."""
    blo0 = blo1 = blo2 = np.inf
    bhi0 = bhi1 = bhi2 = -np.inf
    for t in range(samples.shape[0]):
        s = samples[t]
        for j in range(pos.shape[2]):
            x, y, z = pos[m, s, j, 0], pos[m, s, j, 1], pos[m, s, j, 2]
            blo0, bhi0 = min(blo0, x), max(bhi0, x)
            blo1, bhi1 = min(blo1, y), max(bhi1, y)
            blo2, bhi2 = min(blo2, z), max(bhi2, z)
    box = np.inf
    for p in range(part_lo.shape[0]):
        g0 = max(max(part_lo[p, 0] - bhi0, blo0 - part_hi[p, 0]), 0.0)
        g1 = max(max(part_lo[p, 1] - bhi1, blo1 - part_hi[p, 1]), 0.0)
        g2 = max(max(part_lo[p, 2] - bhi2, blo2 - part_hi[p, 2]), 0.0)
        box = min(box, math.sqrt(g0 * g0 + g1 * g1 + g2 * g2))
    return blo0, blo1, blo2, bhi0, bhi1, bhi2, box

@_jit
def body_samples_clear(grid, lo, res, far, pos, cand, samples, ia, ib, long, need,
                       relative, part_lo, part_hi, limit, out) -> None:
    """``ObstacleField.clear`` of ``pos[cand][:, samples]`` in one call: out[n] for
    candidate cand[n] of pos (M, S, J, 3), sampled at ``samples`` (S',). A candidate
    whose sampled joints' bounding box keeps ``limit`` from every obstacle part's box
    (part_lo, part_hi (P, 3)) passes unread, as the numpy pre-test (``box_gap`` of
    ``point_bounds``, the same arithmetic); for the others, whether every capsule
    keeps its field gap >= 0 at every sample, or with ``relative`` >= min(its gap at
    the first sample, 0) - 0.005 (the gap: the nearer of its ends' distances, and of its
    middle's for a long capsule, less ``need`` (K,): radius, margin and interpolation
    allowance), each joint read once per sample. Stops at the first failing capsule. With a finite
    ``limit``, a capsule whose ends' box keeps its need and the interpolation error (a
    micrometre spare) from every part's box is not read: its gap is > 0."""
    K = ia.shape[0]
    J = pos.shape[2]
    P = part_lo.shape[0]
    dj = np.empty(J)
    read = np.zeros(J, dtype=np.int64)
    stamp = 0
    first = np.zeros(K)
    prune = limit < np.inf
    reach2 = np.empty(K)
    widest = 0.0
    for k in range(K):
        r = need[k] + res * math.sqrt(3.0) + 1e-6
        reach2[k] = r * r
        widest = max(widest, r * r)
    every = np.arange(P)
    near = np.empty(P, dtype=np.int64)
    for n in range(cand.shape[0]):
        m = cand[n]
        blo0, blo1, blo2, bhi0, bhi1, bhi2, box = _samples_box(pos, m, samples, part_lo,
                                                               part_hi)
        if not box < limit:
            out[n] = True
            continue
        n_near = P
        if prune:
            n_near = 0
            for p in range(P):
                if _box_near(blo0, blo1, blo2, bhi0, bhi1, bhi2, part_lo, part_hi,
                             every[p:p + 1], 1, widest):
                    near[n_near] = p
                    n_near += 1
        else:
            near[:] = every
        ok = True
        for t in range(-1 if relative else 0, samples.shape[0]):
            s = samples[max(t, 0)]
            stamp += 1
            for k in range(K):
                a, b = ia[k], ib[k]
                if prune and not _box_near(
                        min(pos[m, s, a, 0], pos[m, s, b, 0]),
                        min(pos[m, s, a, 1], pos[m, s, b, 1]),
                        min(pos[m, s, a, 2], pos[m, s, b, 2]),
                        max(pos[m, s, a, 0], pos[m, s, b, 0]),
                        max(pos[m, s, a, 1], pos[m, s, b, 1]),
                        max(pos[m, s, a, 2], pos[m, s, b, 2]),
                        part_lo, part_hi, near, n_near, reach2[k]):
                    gap = np.inf
                else:
                    d = min(_joint_distance(grid, lo, res, far, pos, m, s, a, dj, read, stamp),
                            _joint_distance(grid, lo, res, far, pos, m, s, b, dj, read, stamp))
                    if long[k]:
                        mid = _field_distance(grid, lo, res, far,
                                              (pos[m, s, a, 0] + pos[m, s, b, 0]) / 2.0,
                                              (pos[m, s, a, 1] + pos[m, s, b, 1]) / 2.0,
                                              (pos[m, s, a, 2] + pos[m, s, b, 2]) / 2.0)
                        d = min(d, mid)
                    gap = d - need[k]
                if t < 0:
                    first[k] = min(gap, 0.0) - 0.005
                elif not gap >= first[k]:
                    ok = False
                    break
            if not ok:
                break
        out[n] = ok


@_jit
def _placed(disp, path, p, x, y, yaw, c, s, xs, ys, values, in_lo, in_hi, ends, gap, m
            ) -> None:
    """ends[m] and gap[m] of primitive p started at (x, y, yaw) (:func:`placed_paths`)."""
    ends[m, 0] = x + c * disp[p, 0] - s * disp[p, 1]
    ends[m, 1] = y + s * disp[p, 0] + c * disp[p, 1]
    ends[m, 2] = yaw + disp[p, 2]
    least = np.inf
    for k in range(path.shape[1]):
        v = _bilinear_at(xs, ys, values, in_lo, in_hi,
                         x + c * path[p, k, 0] - s * path[p, k, 1],
                         y + s * path[p, k, 0] + c * path[p, k, 1])
        if v < least or k == 0:
            least = v
    gap[m] = least


@_jit
def placed_paths(disp, path, ids, x, y, yaw, c, s, xs, ys, values, in_lo, in_hi, ends, gap
                 ) -> None:
    """The search's successor poses and root-path clearances in one call: for primitive
    ids[m] started at (x, y, yaw) (c, s: its cosine and sine), ends[m] (3,) its end pose
    (``astar._place``'s arithmetic) and gap[m] the least :func:`bilinear` clearance of
    its root path's points path[ids[m]] (S, 2) placed there (``astar._path_points``)."""
    for m in range(ids.shape[0]):
        _placed(disp, path, ids[m], x, y, yaw, c, s, xs, ys, values, in_lo, in_hi, ends,
                gap, m)


@_jit
def placed_paths_from(disp, path, ids, starts, c, s, xs, ys, values, in_lo, in_hi, ends,
                      gap) -> None:
    """:func:`placed_paths` with a start pose per primitive: ids[m] started at starts[m]
    (x, y, yaw), c[m] and s[m] the cosine and sine of its yaw."""
    for m in range(ids.shape[0]):
        _placed(disp, path, ids[m], starts[m, 0], starts[m, 1], starts[m, 2], c[m], s[m],
                xs, ys, values, in_lo, in_hi, ends, gap, m)


@_jit
def _cell_index(v, lo, res, n):
    """``NavigationField._cells``' index of coordinate v: ``rint((v - lo) / res)`` as
    numpy's cast makes it an int64 (the least int64 where the float is not finite or out
    of range), clamped to [0, n - 1]."""
    r = np.rint((v - lo) / res)
    k = int(r) if abs(r) < 9.2e18 else -9223372036854775807 - 1
    return min(max(k, 0), n - 1)


@_jit
def cell_values(table, lo0, lo1, res, x, y, out) -> None:
    """out[m] = table (nx, ny) at the grid cell of floor point (x[m], y[m]) (cells of
    side ``res`` centred on lo + k res, clamped to the table)."""
    nx, ny = table.shape
    for m in range(x.shape[0]):
        out[m] = table[_cell_index(x[m], lo0, res, nx), _cell_index(y[m], lo1, res, ny)]
