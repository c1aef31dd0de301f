"""Compiled step loop of :mod:`ltl_human_motion.robot.offline_ssm` (imported on first use).

The control steps run one after another, as the live loop runs them: the arm's joints at
trajectory time ``tau_k`` (minimum-jerk interpolation of
:meth:`~ltl_human_motion.robot.sim.trajectory.JointTrajectory.positions`), its capsules
(the DH chain of :func:`~ltl_human_motion.robot.kinematics.robot_capsules`), the
separation with the one pair kernel of :mod:`ltl_human_motion.kernel._segments_numba`
(same pairs, same order as its ``batched_min_signed``), the speed command of
:func:`~ltl_human_motion.robot.ssm.slider_from_separation` and
``tau_{k+1} = tau_k + dt * slider_k``. Results agree with the numpy path to rounding
(the chain products are summed in another order than BLAS sums them).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ltl_human_motion.kernel._segments_numba import _pair_of

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")

#: Mode codes of :func:`run_steps` (``MODES[code]`` is the live loop's mode string).
MODES = ("full", "reduced", "stop")
#: m. A box gap lower-bounds a separation to rounding; a horizon is skipped only when its
#: bound exceeds the best effective separation by more than this.
_BOUND_SLACK = 1e-9


@_jit
def slider(separation, sp, margin, min_slider, max_slider):
    """:func:`~ltl_human_motion.robot.ssm.slider_from_separation`, operation for operation."""
    if not math.isfinite(separation):
        if math.isnan(separation) or separation < 0:
            separation = 0.0
    if separation <= sp:
        return min_slider
    if separation >= sp + margin:
        return max_slider
    frac = (separation - sp) / margin
    return min_slider + frac * (max_slider - min_slider)


@_jit
def _joints_at(t, traj_start, traj_move, q_from, q_to, cycle_time, q):
    """q (6,) at trajectory time t, as ``JointTrajectory.positions``."""
    tc = t % cycle_time
    k = -1
    for i in range(traj_start.shape[0]):
        if traj_start[i] <= tc:
            k = i
    tau = min((tc - traj_start[k]) / traj_move[k], 1.0)
    s = tau ** 3.0 * (10 - 15 * tau + 6 * tau ** 2.0)
    for j in range(6):
        q[j] = q_from[k, j] + s * (q_to[k, j] - q_from[k, j])


@_jit
def _capsules_at(q, dh_d, dh_a, cos_alpha, sin_alpha, tool_length, base, frame, seg):
    """Arm capsules seg (7, 2, 3) in the world frame for joints q (6,); ``frame`` (4, 4)
    is scratch space."""
    frame[:, :] = base
    for i in range(6):
        ct, st = math.cos(q[i]), math.sin(q[i])
        ca, sa = cos_alpha[i], sin_alpha[i]
        a, d = dh_a[i], dh_d[i]
        for r in range(3):
            f0, f1, f2, f3 = frame[r, 0], frame[r, 1], frame[r, 2], frame[r, 3]
            seg[i, 0, r] = f3
            frame[r, 0] = f0 * ct + f1 * st
            frame[r, 1] = -f0 * st * ca + f1 * ct * ca + f2 * sa
            frame[r, 2] = f0 * st * sa - f1 * ct * sa + f2 * ca
            frame[r, 3] = f0 * a * ct + f1 * a * st + f2 * d + f3
    for r in range(3):
        for i in range(6):
            seg[i, 1, r] = seg[i + 1, 0, r] if i < 5 else frame[r, 3]
        seg[6, 0, r] = frame[r, 3]
        seg[6, 1, r] = frame[r, 3] + tool_length * frame[r, 2]


@_jit
def _box_gap(lo_a, hi_a, lo_b, hi_b):
    """Distance between boxes a and b (3,): a lower bound of their contents'."""
    acc = 0.0
    for r in range(3):
        g = max(max(lo_a[r] - hi_b[r], lo_b[r] - hi_a[r]), 0.0)
        acc += g * g
    return math.sqrt(acc)


@_jit
def _box_of(seg, radius, lo, hi):
    """Box lo, hi (3,) of capsules seg (L, 2, 3) of radius at most ``radius``."""
    for r in range(3):
        a, b = np.inf, -np.inf
        for i in range(seg.shape[0]):
            for e in range(2):
                a = min(a, seg[i, e, r])
                b = max(b, seg[i, e, r])
        lo[r] = a - radius
        hi[r] = b + radius


@_jit
def _capsule_box(seg, i, radius, lo, hi):
    """Box lo, hi (3,) of capsule seg[i] (2, 3) of ``radius``."""
    for r in range(3):
        a, b = seg[i, 0, r], seg[i, 1, r]
        lo[r] = min(a, b) - radius
        hi[r] = max(a, b) + radius


@_jit
def _pruned(lo, hi, qlo, qhi, lead, bar):
    """Whether capsules in box lo, hi lie so far from box qlo, qhi that their separation
    plus ``lead`` is at least ``bar`` (disjoint boxes: the gap bounds it from below)."""
    g = _box_gap(lo, hi, qlo, qhi)
    return g > 0.0 and g + lead - _BOUND_SLACK >= bar


@_jit
def _min_signed(P, pr, Q, qr, qlo, qhi, qbox_lo, qbox_hi, lead, limit, lo, hi):
    """Minimum separation of capsules P (K, 2, 3), (K,) against Q (L, 2, 3), (L,).

    Exact (the same number as ``batched_min_signed``: a minimum of the same pairs)
    wherever the minimum plus ``lead`` lies below ``limit``; otherwise a number whose sum
    with ``lead`` is at least ``limit``. Capsules of P and pairs whose boxes lie far enough
    apart are skipped: ``qlo, qhi`` (3,) is the box of all of Q, ``qbox_lo, qbox_hi``
    (L, 3) those of its capsules; ``lo, hi`` (3,) are scratch space.
    """
    best = np.inf
    for k in range(P.shape[0]):
        _capsule_box(P, k, pr[k], lo, hi)
        bar = min(limit, best + lead)
        if _pruned(lo, hi, qlo, qhi, lead, bar):
            continue
        for j in range(Q.shape[0]):
            if _pruned(lo, hi, qbox_lo[j], qbox_hi[j], lead, min(limit, best + lead)):
                continue
            d = _pair_of(P, k, Q, j) - pr[k] - qr[j]
            if d < best:
                best = d
    return best


@_jit
def run_steps(hseg, hrad, hlo, hhi, frames, pred_frames, horizons, traj_start, traj_move,
              q_from, q_to, cycle_time, dh_d, dh_a, cos_alpha, sin_alpha, tool_length, base,
              rrad, sp, margin, min_slider, max_slider, discount, dt, tau0,
              slider_out, sep_out, tau_out, mode_out, lb_out, rseg_out):
    """The offline SSM's control steps; returns the number of separations evaluated.

    Parameters
    ----------
    hseg, hrad : (T, K, 2, 3), (K,) human capsules per motion frame.
    hlo, hhi : (T, 3) body boxes per frame (capsule radii included).
    frames, pred_frames, horizons : (N,), (N, H), (H,) motion frame of each step, of each
        predicted sample, and the samples' seconds ahead.
    traj_start, traj_move, q_from, q_to, cycle_time : the trajectory's segments.
    dh_d, dh_a, cos_alpha, sin_alpha, tool_length, base, rrad : the arm and its pose.
    sp, margin, min_slider, max_slider, discount : SSM parameters (S_p, band, slider range,
        prediction discount speed).
    dt, tau0 : control period and the first trajectory time.
    slider_out, sep_out, mode_out, lb_out : (N,) outputs; ``sep_out`` NaN and ``lb_out`` the
        current box gap where a full-speed step's boxes lie beyond S_p + margin (no
        distance taken), ``lb_out`` inf elsewhere.
    tau_out : (N + 1,) trajectory times; rseg_out : (N, 7, 2, 3) arm capsules per step.
    """
    n = frames.shape[0]
    n_pred = horizons.shape[0]
    band = sp + margin
    rmax = rrad.max()
    q = np.empty(6)
    frame = np.empty((4, 4))
    rlo = np.empty(3)
    rhi = np.empty(3)
    link_lo = np.empty((7, 3))
    link_hi = np.empty((7, 3))
    lo = np.empty(3)
    hi = np.empty(3)
    tau_out[0] = tau0
    prev = max_slider
    n_eval = 0
    for k in range(n):
        rseg = rseg_out[k]
        _joints_at(tau_out[k], traj_start, traj_move, q_from, q_to, cycle_time, q)
        _capsules_at(q, dh_d, dh_a, cos_alpha, sin_alpha, tool_length, base, frame, rseg)
        f = frames[k]
        _box_of(rseg, rmax, rlo, rhi)
        for i in range(7):
            _capsule_box(rseg, i, rrad[i], link_lo[i], link_hi[i])
        need = True
        lb_out[k] = np.inf
        if prev >= max_slider:
            bound = _box_gap(hlo[f], hhi[f], rlo, rhi)
            lb_out[k] = bound
            for h in range(n_pred):
                p = pred_frames[k, h]
                bound = min(bound, _box_gap(hlo[p], hhi[p], rlo, rhi) + discount * horizons[h])
            need = bound < band
        if need:
            cur = _min_signed(hseg[f], hrad, rseg, rrad, rlo, rhi, link_lo, link_hi, 0.0,
                              np.inf, lo, hi)
            eff = cur
            # At or below S_p now, the command is the minimum whatever is predicted.
            if cur > sp:
                for h in range(n_pred):
                    p = pred_frames[k, h]
                    lead = discount * horizons[h]
                    if _pruned(hlo[p], hhi[p], rlo, rhi, lead, eff):
                        continue
                    eff = min(eff, _min_signed(hseg[p], hrad, rseg, rrad, rlo, rhi, link_lo,
                                               link_hi, lead, eff, lo, hi) + lead)
            sl = slider(eff, sp, margin, min_slider, max_slider)
            sep_out[k] = cur
            n_eval += 1
        else:
            sl = max_slider
            sep_out[k] = np.nan
        slider_out[k] = sl
        mode_out[k] = 0 if sl >= max_slider else 2 if sl <= min_slider else 1
        tau_out[k + 1] = tau_out[k] + dt * sl
        prev = sl
    return n_eval
