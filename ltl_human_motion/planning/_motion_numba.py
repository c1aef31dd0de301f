"""Compiled loops of :mod:`ltl_human_motion.planning.footlock` (imported on first use):
the sequential passes over a motion's frames, operation for operation as the Python/numpy
paths compute them (the same numbers; tests hold them together)."""

from __future__ import annotations

import math

import numba
import numpy as np

from ltl_human_motion.motion._ik_numba import chain

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def decay_envelope(w: np.ndarray, step: float) -> np.ndarray:
    """``w`` (T,) raised so that no value falls by more than ``step`` per frame towards
    either end (a backward pass, then a forward pass)."""
    out = w.copy()
    T = out.shape[0]
    for t in range(T - 2, -1, -1):
        out[t] = max(out[t], out[t + 1] - step)
    for t in range(1, T):
        out[t] = max(out[t], out[t - 1] - step)
    return out


@_jit
def rate_limited(x: np.ndarray, step: float) -> np.ndarray:
    """``x`` (T, 3) with every frame-to-frame change at most ``step`` (a forward, then a
    backward pass)."""
    rows = x.copy()
    T = rows.shape[0]
    for t in range(1, T):
        _limit(rows, t, t - 1, step)
    for t in range(T - 2, -1, -1):
        _limit(rows, t, t + 1, step)
    return rows


@_jit
def _limit(rows, t, prev, step):
    px, py, pz = rows[prev, 0], rows[prev, 1], rows[prev, 2]
    dx, dy, dz = rows[t, 0] - px, rows[t, 1] - py, rows[t, 2] - pz
    n = math.sqrt(dx * dx + dy * dy + dz * dz)
    if n > step:
        k = step / n
        rows[t, 0] = px + dx * k
        rows[t, 1] = py + dy * k
        rows[t, 2] = pz + dz * k


@_jit
def _clip01(x: float) -> float:
    """``np.clip(x, 0, 1)``, signed zero and NaN included."""
    if x < 0.0:
        return 0.0
    if x > 1.0:
        return 1.0
    return x


@_jit
def _floor(x: float, least: float) -> float:
    """``np.maximum(x, least)`` of a finite ``x``."""
    return x if x > least else least


@_jit
def segment_gaps(p0, p1, q0, q1, gap, dist) -> None:
    """``footlock._segment_gaps`` frame by frame: gap[t] (3,) from the closest point of
    segment [q0[t], q1[t]] to that of [p0[t], p1[t]] and dist[t] its length (all (T, 3),
    finite), each sum over x, y, z in numpy's order."""
    for t in range(p0.shape[0]):
        u0, u1, u2 = p1[t, 0] - p0[t, 0], p1[t, 1] - p0[t, 1], p1[t, 2] - p0[t, 2]
        v0, v1, v2 = q1[t, 0] - q0[t, 0], q1[t, 1] - q0[t, 1], q1[t, 2] - q0[t, 2]
        w0, w1, w2 = p0[t, 0] - q0[t, 0], p0[t, 1] - q0[t, 1], p0[t, 2] - q0[t, 2]
        a = u0 * u0 + u1 * u1 + u2 * u2
        b = 0.0 + u0 * v0 + u1 * v1 + u2 * v2      # (numpy's sums start from +0.0)
        c = v0 * v0 + v1 * v1 + v2 * v2
        d = 0.0 + u0 * w0 + u1 * w1 + u2 * w2
        e = 0.0 + v0 * w0 + v1 * w1 + v2 * w2
        den = a * c - b * b
        sp = _clip01((b * e - c * d) / _floor(den, 1e-12)) if den > 1e-12 else 0.0
        s = (b * sp + e) / _floor(c, 1e-12)
        if s < 0:
            sp = _clip01(-d / _floor(a, 1e-12))
        elif s > 1:
            sp = _clip01((b - d) / _floor(a, 1e-12))
        s = _clip01(s)
        g0 = (p0[t, 0] + sp * u0) - (q0[t, 0] + s * v0)
        g1 = (p0[t, 1] + sp * u1) - (q0[t, 1] + s * v1)
        g2 = (p0[t, 2] + sp * u2) - (q0[t, 2] + s * v2)
        gap[t, 0], gap[t, 1], gap[t, 2] = g0, g1, g2
        dist[t] = math.sqrt(g0 * g0 + g1 * g1 + g2 * g2)


@_jit
def slower_foot_speed(ank, toe, fps, out) -> None:
    """out[t] for t >= 1: the slower horizontal speed of ``ank`` and ``toe`` (T, 3) from
    frame t - 1 to t (``np.linalg.norm`` of the steps, then their minimum, times fps)."""
    for t in range(1, ank.shape[0]):
        ax, ay = ank[t, 0] - ank[t - 1, 0], ank[t, 1] - ank[t - 1, 1]
        tx, ty = toe[t, 0] - toe[t - 1, 0], toe[t, 1] - toe[t - 1, 1]
        sa = math.sqrt(ax * ax + ay * ay)
        st = math.sqrt(tx * tx + ty * ty)
        out[t] = (sa if sa <= st else st) * fps


@_jit
def _roll(h, t, switch) -> float:
    """``footlock._roll_weight`` of frame t of h (T, 2)."""
    return _clip01(0.5 + (h[t, 0] - h[t, 1]) / (2.0 * switch))


@_jit
def _anchor_at(held, contact, a, b, fps, still_speed, still_time) -> int:
    """``footlock._anchor`` of the contact point held[t, contact[t], :2], t in [a, b)."""
    n = b - a
    speed = np.zeros(n)
    for i in range(1, n):
        dx = held[a + i, contact[a + i], 0] - held[a + i - 1, contact[a + i - 1], 0]
        dy = held[a + i, contact[a + i], 1] - held[a + i - 1, contact[a + i - 1], 1]
        speed[i] = math.sqrt(0.0 + dx * dx + dy * dy) * fps
    speed[0] = speed[min(1, n - 1)]
    i = 0
    while i < n:
        if speed[i] <= still_speed:
            j = i
            while j < n and speed[j] <= still_speed:
                j += 1
            if j - i >= still_time * fps:
                return (i + j) // 2
            i = j
        else:
            i += 1
    med = np.empty(2)
    col = np.empty(n)
    for c in range(2):              # np.median: the middle one or two, as np.mean takes them
        for i in range(n):
            col[i] = held[a + i, contact[a + i], c]
        col.sort()
        if n % 2:
            med[c] = (0.0 + col[n // 2]) / 1.0
        else:
            med[c] = (0.0 + col[n // 2 - 1] + col[n // 2]) / 2.0
    best = 0
    least = np.inf
    for i in range(n):
        dx = held[a + i, contact[a + i], 0] - med[0]
        dy = held[a + i, contact[a + i], 1] - med[1]
        d = math.sqrt(0.0 + dx * dx + dy * dy)
        if d < least:
            least = d
            best = i
    return best


@_jit
def _pin_offsets(held, h, switch, a, n, k):
    """The offsets (n, 2) that pin a stance's frames [a, a + n) at its anchor frame
    ``k``: the ground distance the blended foot travelled from frame a, taken from its
    value at k."""
    off = np.zeros((n, 2))          # travelled, then the pin offsets
    for i in range(1, n):
        beta = _roll(h, a + i, switch)
        for c in range(2):
            s0 = held[a + i, 0, c] - held[a + i - 1, 0, c]
            s1 = held[a + i, 1, c] - held[a + i - 1, 1, c]
            step = (1.0 - beta) * s0 + beta * s1
            off[i, c] = step if i == 1 else off[i - 1, c] + step
    ref0, ref1 = off[k - a, 0], off[k - a, 1]
    for i in range(n):
        off[i, 0] = ref0 - off[i, 0]
        off[i, 1] = ref1 - off[i, 1]
    return off


@_jit
def _lock_window(off, h, switch, a, n, k, max_lock, max_lock_ball):
    """The frames (lo, hi), relative to a, around the anchor ``k`` whose pin offsets
    ``off`` (n, 2) stay within the lock limits (heel or ball), and whether any frame of
    the stance exceeds them."""
    big = False
    ok = np.empty(n, dtype=np.bool_)
    for i in range(n):
        limit = max_lock_ball if _roll(h, a + i, switch) >= 1.0 else max_lock
        ok[i] = not (math.sqrt(0.0 + off[i, 0] * off[i, 0] + off[i, 1] * off[i, 1])
                     > limit)
        big = big or not ok[i]
    lo = k - a
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    hi = k - a
    while hi < n - 1 and ok[hi + 1]:
        hi += 1
    return lo, hi, big


@_jit
def _shuffle_entry(hc, vc, ta, tb, fps, still_speed, shuffle_time, contact_height,
                   stance_speed) -> int:
    """The frame a standing shuffle in [ta, tb) is entered at (``footlock._next_stance``):
    -2 where there is none (no still part of ``shuffle_time``), -1 where there is a
    still part but no frame to enter (the Python path raises)."""
    if tb - ta < shuffle_time * fps:
        return -2
    found = False
    i = ta
    while i < tb and not found:
        if vc[i] <= still_speed:
            j = i
            while j < tb and vc[j] <= still_speed:
                j += 1
            found = j - i >= shuffle_time * fps
            i = j
        else:
            i += 1
    if not found:
        return -2
    for i in range(ta, tb):
        if hc[i] <= contact_height and vc[i] <= stance_speed:
            return i
    return -1


@_jit
def _write_pins(held, joints, off, a, b, lo, ramp, disp, weight) -> None:
    """The pin displacements of frames [a, b) (offsets ``off`` from row ``lo``) at weight
    1, and the release ramps either side where they weigh more than what is there."""
    T = held.shape[0]
    n_rel = ramp.shape[0]
    for t in range(a, b):
        for j in range(2):
            for c in range(2):
                disp[t, j, c] = held[t, j, c] - joints[t, j, c] + off[t - a + lo, c]
        weight[t] = 1.0
    for i in range(n_rel):
        w = ramp[n_rel - 1 - i]
        if a - 1 - i >= 0 and weight[a - 1 - i] < w:
            for j in range(2):
                for c in range(2):
                    disp[a - 1 - i, j, c] = disp[a, j, c] * w
            weight[a - 1 - i] = w
        if b + i < T and weight[b + i] < w:
            for j in range(2):
                for c in range(2):
                    disp[b + i, j, c] = disp[b - 1, j, c] * w
            weight[b + i] = w


@_jit
def lock_stances(held, joints, h, hc, vc, contact, starts, ends, stance, ramp, fps,
                 consts, disp, weight) -> int:
    """The stance loop of ``footlock._foot_targets`` (its Python path, step for step):
    every stance [starts[r], ends[r]) pinned at its anchor and trimmed to its lock
    limits, the standing shuffle after it pinned too, and the release ramps; ``stance``
    (T,) is changed in place, ``disp`` (T, 2, 2) and ``weight`` (T,) filled. ``consts``:
    STILL_SPEED, STILL_TIME, MAX_LOCK, MAX_LOCK_BALL, CONTACT_SWITCH, SHUFFLE_STILL_TIME,
    CONTACT_HEIGHT, STANCE_SPEED. Returns 1 where the Python path would raise (a shuffle
    with a still part but no frame to enter), else 0."""
    still_speed, still_time, max_lock, max_lock_ball = consts[0], consts[1], consts[2], \
        consts[3]
    switch, shuffle_time, contact_height, stance_speed = consts[4], consts[5], consts[6], \
        consts[7]
    n_rel = ramp.shape[0]
    r = 0
    pending = False
    pa = pb = 0
    while pending or r < starts.shape[0]:
        if pending:
            a, b = pa, pb
            pending = False
        else:
            a, b = starts[r], ends[r]
            r += 1
        k = a + _anchor_at(held, contact, a, b, fps, still_speed, still_time)
        n = b - a
        off = _pin_offsets(held, h, switch, a, n, k)
        end = b
        lo, hi, big = _lock_window(off, h, switch, a, n, k, max_lock, max_lock_ball)
        if big:
            stance[a:a + lo] = False
            stance[a + hi + 1:b] = False
            a, b = a + lo, a + hi + 1
        else:
            lo = 0
        # the standing shuffle after the stance (footlock._next_stance)
        enter = _shuffle_entry(hc, vc, b + n_rel, end, fps, still_speed, shuffle_time,
                               contact_height, stance_speed)
        if enter == -1:
            return 1
        if enter >= 0:
            stance[enter:end] = True
            pending = True
            pa, pb = enter, end
        _write_pins(held, joints, off, a, b, lo, ramp, disp, weight)
    return 0


@_jit
def _unit_to(x0, x1, x2, y0, y1, y2, length):
    """x + length * (y - x) / max(|y - x|, 1e-12) (``footlock._unit3``), (3 floats)."""
    v0, v1, v2 = y0 - x0, y1 - x1, y2 - x2
    n = math.sqrt(0.0 + v0 * v0 + v1 * v1 + v2 * v2)
    n = n if n > 1e-12 else 1e-12
    return x0 + length * (v0 / n), x1 + length * (v1 / n), x2 + length * (v2 / n)


@_jit
def leg_corrections(p, hip, ank, toe, ank_all, toe_all, leg, f_len, moved, da, dt) -> None:
    """The first half of ``footlock._solve_leg``, step for step: the frames whose ankle
    or toe target moves (``moved`` (T,)), and the corrections da, dt (T, 3) towards the
    targets (zero elsewhere), the heel raised where the leg cannot reach the ankle's."""
    for t in range(p.shape[0]):
        m = False
        for c in range(3):
            m = m or abs(ank_all[t, c] - p[t, ank, c]) > 1e-9 \
                or abs(toe_all[t, c] - p[t, toe, c]) > 1e-9
        moved[t] = m
        if not m:
            for c in range(3):
                da[t, c] = 0.0
                dt[t, c] = 0.0
            continue
        h0, h1, h2 = p[t, hip, 0], p[t, hip, 1], p[t, hip, 2]
        a0, a1, a2 = ank_all[t, 0], ank_all[t, 1], ank_all[t, 2]
        o0, o1, o2 = toe_all[t, 0], toe_all[t, 1], toe_all[t, 2]
        r0, r1, r2 = p[t, ank, 0] - h0, p[t, ank, 1] - h1, p[t, ank, 2] - h2
        r = math.sqrt(0.0 + r0 * r0 + r1 * r1 + r2 * r2)
        reach = leg if leg > r else r
        w0, w1, w2 = a0 - h0, a1 - h1, a2 - h2
        if math.sqrt(0.0 + w0 * w0 + w1 * w1 + w2 * w2) > reach:
            g0, g1, g2 = o0 - h0, o1 - h1, o2 - h2
            D = math.sqrt(0.0 + g0 * g0 + g1 * g1 + g2 * g2)
            Dm = D if D > 1e-9 else 1e-9
            u0, u1, u2 = g0 / Dm, g1 / Dm, g2 / Dm
            x = (D * D + reach * reach - f_len * f_len) / (2.0 * Dm)
            x = -reach if x < -reach else x
            x = reach if x > reach else x
            rr = reach * reach - x * x
            rho = math.sqrt(rr if rr > 0.0 else 0.0)
            c0, c1, c2 = h0 + u0 * x, h1 + u1 * x, h2 + u2 * x
            q0, q1, q2 = a0 - c0, a1 - c1, a2 - c2
            s = 0.0 + q0 * u0 + q1 * u1 + q2 * u2
            q0, q1, q2 = q0 - s * u0, q1 - s * u1, q2 - s * u2
            qn = math.sqrt(0.0 + q0 * q0 + q1 * q1 + q2 * q2)
            qn = qn if qn > 1e-9 else 1e-9
            q0, q1, q2 = q0 / qn, q1 / qn, q2 / qn
            n0, n1, n2 = c0 + rho * q0, c1 + rho * q1, c2 + rho * q2
            if D <= reach + f_len and n2 >= a2:
                a0, a1, a2 = n0, n1, n2
                o0, o1, o2 = _unit_to(a0, a1, a2, o0, o1, o2, f_len)
        da[t, 0], da[t, 1], da[t, 2] = a0 - p[t, ank, 0], a1 - p[t, ank, 1], a2 - p[t, ank, 2]
        dt[t, 0], dt[t, 1], dt[t, 2] = o0 - p[t, toe, 0], o1 - p[t, toe, 1], o2 - p[t, toe, 2]


@_jit
def leg_solve(p, hip, knee, ank, toe, l_hip, r_hip, moved, da, dt, offset, l1, l2, dmin,
              dmax, f_len, pole_forward, kn_out, an_out, to_out) -> None:
    """The second half of ``footlock._solve_leg``, step for step: on the moved frames the
    knee, ankle and toe by two-bone IK from the hip towards the rate-limited targets
    p + da, p + dt (T, 3), the knee bent towards the smoothed ``offset`` (T, 3) and
    forward; kn_out, an_out, to_out (T, 3) hold the other frames' joints already."""
    for t in range(p.shape[0]):
        if not moved[t]:
            continue
        f0, f1 = p[t, toe, 0] - p[t, ank, 0], p[t, toe, 1] - p[t, ank, 1]
        fn = math.sqrt(0.0 + f0 * f0 + f1 * f1)
        fn = fn if fn > 1e-9 else 1e-9
        w0, w1, w2 = f0 / fn, f1 / fn, 0.0
        e0 = (p[t, l_hip, 1] - p[t, r_hip, 1]) * 1.0
        e1 = (p[t, l_hip, 0] - p[t, r_hip, 0]) * -1.0
        en = math.sqrt(0.0 + e0 * e0 + e1 * e1 + 0.0 * 0.0)
        en = en if en > 1e-9 else 1e-9
        e0, e1, e2 = e0 / en, e1 / en, 0.0 / en
        q0 = offset[t, 0] + 0.01 * w0
        q1 = offset[t, 1] + 0.01 * w1
        q2 = offset[t, 2] + 0.01 * w2
        lean = 0.0 + q0 * e0 + q1 * e1 + q2 * e2
        more = pole_forward - lean
        more = more if (more > 0.0 or more != more) else 0.0
        q0, q1, q2 = q0 + more * e0, q1 + more * e1, q2 + more * e2
        k0, k1, k2, n0, n1, n2 = chain(
            p[t, hip, 0], p[t, hip, 1], p[t, hip, 2],
            p[t, ank, 0] + da[t, 0], p[t, ank, 1] + da[t, 1], p[t, ank, 2] + da[t, 2],
            q0, q1, q2, l1, l2, dmin, dmax)
        kn_out[t, 0], kn_out[t, 1], kn_out[t, 2] = k0, k1, k2
        an_out[t, 0], an_out[t, 1], an_out[t, 2] = n0, n1, n2
        to_out[t, 0], to_out[t, 1], to_out[t, 2] = _unit_to(
            n0, n1, n2, p[t, toe, 0] + dt[t, 0], p[t, toe, 1] + dt[t, 1],
            p[t, toe, 2] + dt[t, 2], f_len)
