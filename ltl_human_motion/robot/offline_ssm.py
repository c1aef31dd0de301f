"""Speed and separation monitoring in simulated time: the live loop's decisions over a
motion's timeline, at the live loop's 125 Hz, much faster than real time.

Per control step ``k`` (time ``t_k = k / rate``) this does what one
:meth:`~ltl_human_motion.robot.coexistence.CoexistenceController.step` does against the
simulated controller (:class:`~ltl_human_motion.robot.sim.state.SimulatedUR`): read the
arm's joints at its trajectory time ``tau_k``, compute the human-robot capsule separation
(:func:`~ltl_human_motion.robot.separation.signed_distances`, optionally with predicted
occupancy through :func:`~ltl_human_motion.robot.ssm.predictive_separation`), turn it into
a speed-slider command (:func:`~ltl_human_motion.robot.coexistence.ssm_command`), and let
the arm advance ``tau_{k+1} = tau_k + slider_k / rate`` as the simulated controller does.

Where the compiled segment kernel is in use (numba), the steps run one after another in
compiled code (:mod:`._offline_numba`): per step the arm's joints, its capsules and the
separation, with the live loop's pair kernel, cost a few microseconds; a predicted sample
is skipped when the body box is too far away to lower the effective separation, and so
are the human capsules and capsule pairs whose boxes lie too far apart to be the closest.
Its numbers agree with the numpy path's to rounding (tests hold them together).

The numpy path evaluates many steps at once. While the command stays the same, the
arm's trajectory times are known ahead, so a run of steps is evaluated together: the
separations with :func:`batched_separations` (the live kernel's quantity, vectorized over
steps; tests check they agree), then the command of each step in order. The first step
whose command changes ends the run (later steps assumed the old command and are
evaluated again), so every step's decision is exactly the one a step-by-step loop makes.

On both paths, at full speed, steps whose body and arm bounding boxes lie more than
S_p + margin apart skip the distance (the command is full speed whatever it is).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ltl_human_motion.kernel.segments import batched_min_signed_distances, compiled_module
from ltl_human_motion.robot.coexistence import ControlDecision, ssm_command
from ltl_human_motion.robot.kinematics import URModel, robot_capsules, ur_model
from ltl_human_motion.robot.metrics import metrics_from_columns
from ltl_human_motion.robot.sim.trajectory import JointTrajectory
from ltl_human_motion.robot.ssm import SSMParameters, predictive_separation
from ltl_human_motion.scene.occupancy import body_boxes, capsules_from_positions

__all__ = ["CONTROL_RATE", "OfflineSSMResult", "batched_separations", "run_offline_ssm"]

#: Hz, the live coexistence loop's rate (UR RTDE at 125 Hz).
CONTROL_RATE = 125.0
#: Steps evaluated together while the arm runs at full speed (1 s at 125 Hz).
_CHUNK = 125
#: Steps tried ahead after a bulk attempt failed.
_MIN_LOOK = 4


@dataclass
class OfflineSSMResult:
    """What an offline run saw and did.

    Attributes
    ----------
    time : ndarray, shape (N,)
        Step times (s) from the start of the motion.
    slider : ndarray, shape (N,)
    separation : ndarray, shape (N,)
        Current separation (m); NaN at full-speed steps whose bounding boxes were more
        than S_p + margin apart (their separation is larger; the minimum is exact).
    trajectory_time : ndarray, shape (N + 1,)
        The arm's trajectory time before each step and at the end (s).
    mode : ndarray of str, shape (N,)
    metrics : dict
        :func:`~ltl_human_motion.robot.metrics.commissioning_metrics` of the run plus
        ``effective_cycle_time``, ``nominal_cycle_time``, ``throughput_ratio``,
        ``frames_below_sp`` (motion frames with separation below S_p), ``time_below_sp``,
        ``evaluated_steps`` (steps whose separation was computed; on the numpy path
        discarded speculation included).
    """

    time: np.ndarray
    slider: np.ndarray
    separation: np.ndarray
    trajectory_time: np.ndarray
    mode: np.ndarray
    metrics: dict[str, Any] = field(default_factory=dict)

    def decisions(self, protective_distance: float) -> list[ControlDecision]:
        """The run as live-loop :class:`ControlDecision` records."""
        return [ControlDecision(float(t), float(s), True, str(m), float(d), float(d),
                                protective_distance, True)
                for t, s, m, d in zip(self.time, self.slider, self.mode, self.separation)]


def _box_gap(lo_a: np.ndarray, hi_a: np.ndarray, lo_b: np.ndarray, hi_b: np.ndarray
             ) -> np.ndarray:
    """Distance between boxes (M, 3) a and b, (M,): a lower bound of their contents'."""
    gap = np.maximum(np.maximum(lo_a - hi_b, lo_b - hi_a), 0.0)
    return np.sqrt((gap * gap).sum(axis=-1))


def batched_separations(P: np.ndarray, p_radii: np.ndarray, Q: np.ndarray,
                         q_radii: np.ndarray) -> np.ndarray:
    """Minimum signed capsule separation per batch entry, shape (M,).

    ``min_signed_distance(P[i], p_radii, Q[i], q_radii)`` for every ``i``, with the one
    exact kernel the live loop uses (:mod:`ltl_human_motion.kernel.segments`, its batched
    entry point), so offline and live decisions see the same numbers.

    Parameters
    ----------
    P : ndarray, shape (M, K, 2, 3)
    p_radii : ndarray, shape (K,)
    Q : ndarray, shape (M, L, 2, 3)
    q_radii : ndarray, shape (L,)
    """
    return batched_min_signed_distances(P, p_radii, Q, q_radii)


def _violations(t: np.ndarray, dt: float, below: np.ndarray, sep: np.ndarray,
                slider: np.ndarray, min_slider: float) -> list[dict[str, Any]]:
    """Intervals below S_p, as :func:`commissioning_metrics` reports them."""
    out = []
    padded = np.concatenate([[False], below, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    for a, b in zip(edges[::2], edges[1::2]):
        out.append({"start": float(t[a]), "end": float(t[b - 1] + dt),
                    "min_separation": float(sep[a:b].min()),
                    "max_slider": float(slider[a:b].max()),
                    "slowed_to_min": bool(np.all(slider[a:b] <= min_slider + 1e-9))})
    return out


@dataclass(frozen=True)
class _Occupancy:
    """The motion's capsules sampled at the control steps.

    Attributes
    ----------
    hseg, hrad : ndarray, shape (T, K, 2, 3), (K,)
        Human capsules per motion frame.
    hlo, hhi : ndarray, shape (T, 3)
        Body boxes per frame (radii included).
    frame : ndarray of int, shape (N,)
        Motion frame of each step.
    pred_frames : ndarray of int, shape (N, H)
        Motion frames of the predicted samples.
    horizons : ndarray, shape (H,)
        Seconds ahead of the predicted samples.
    """

    hseg: np.ndarray
    hrad: np.ndarray
    hlo: np.ndarray
    hhi: np.ndarray
    frame: np.ndarray
    pred_frames: np.ndarray
    horizons: np.ndarray


def _occupancy(pos: np.ndarray, fps: float, stature: float, t: np.ndarray,
               prediction_horizon: float, prediction_step: float) -> _Occupancy:
    """Capsules, body boxes and the frames of steps at times ``t`` (N,) of a motion
    ``pos`` (T, 23, 3)."""
    T = len(pos)
    hseg, hrad = capsules_from_positions(pos, stature)            # (T, K, 2, 3), (K,)
    hlo, hhi = body_boxes(pos, stature)
    frame = np.minimum(np.rint(t * fps).astype(np.int64), T - 1)
    n_pred = math.floor(prediction_horizon / prediction_step + 1e-9) \
        if prediction_horizon > 0 else 0
    horizons = prediction_step * np.arange(1, n_pred + 1)
    pred_frames = np.minimum(frame[:, None] + np.rint(horizons * fps).astype(np.int64)[None],
                             T - 1)                               # (N, H)
    return _Occupancy(np.ascontiguousarray(hseg), hrad, hlo, hhi, frame,
                      np.ascontiguousarray(pred_frames), horizons)


@dataclass
class _Steps:
    """What the control steps commanded (arrays as in :class:`OfflineSSMResult`), the
    current box gap ``lb`` (N,) of the steps whose distance was skipped (inf elsewhere)
    and the arm capsules of step ``j`` (``arm(j)`` for an index array: (M, 7, 2, 3))."""

    slider: np.ndarray
    sep: np.ndarray
    tau: np.ndarray
    modes: np.ndarray
    lb: np.ndarray
    n_eval: int
    arm: Callable[[np.ndarray], np.ndarray]


def _compiled_steps() -> ModuleType | None:
    """The compiled step loop, where the compiled segment kernel is in use."""
    return compiled_module("ltl_human_motion.robot._offline_numba")


def _steps_compiled(nb: ModuleType, occ: _Occupancy, trajectory: JointTrajectory,
                    m: URModel, B: np.ndarray, params: SSMParameters, dt: float,
                    tau0: float) -> _Steps:
    """The steps one after another, compiled (:mod:`._offline_numba`)."""
    n = len(occ.frame)
    start, move, q_from, q_to = trajectory.segment_arrays()
    d, a, alpha = m._dh
    slider, sep, tau = np.empty(n), np.empty(n), np.empty(n + 1)
    codes, lb = np.empty(n, dtype=np.int8), np.empty(n)
    rseg = np.empty((n, 7, 2, 3))
    n_eval = nb.run_steps(
        occ.hseg, occ.hrad, occ.hlo, occ.hhi, occ.frame, occ.pred_frames, occ.horizons,
        start, move, q_from, q_to, trajectory.cycle_time, d, a, np.cos(alpha), np.sin(alpha),
        float(m.tool_length), np.ascontiguousarray(B),
        np.asarray(m.link_radii, dtype=np.float64), params.protective_distance,
        params.margin, params.min_slider, params.max_slider,
        params.prediction_discount_speed, dt, float(tau0), slider, sep, tau, codes, lb, rseg)
    modes = np.asarray(nb.MODES, dtype=object)[codes]
    return _Steps(slider, sep, tau, modes, lb, int(n_eval), lambda j: rseg[j])


def _chunk_separations(occ: _Occupancy, idx: np.ndarray, rseg: np.ndarray,
                       rrad: np.ndarray, at_full: bool, params: SSMParameters,
                       lb: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Separations of the steps ``idx`` (M,) with arm capsules ``rseg`` (M, 7, 2, 3).

    Returns which steps needed a distance (M,), the current separations (M,) and the
    predicted ones (M, H) (NaN where not needed; None without prediction). ``at_full``:
    the steps run at full speed, and those whose boxes lie S_p + margin apart need no
    distance (the command is full speed whatever it is); their box gaps go to ``lb``.
    """
    frame, pred_frames, horizons = occ.frame, occ.pred_frames, occ.horizons
    M, n_pred = len(idx), len(horizons)
    need = np.ones(M, dtype=bool)
    if at_full:
        ends = rseg.reshape(M, -1, 3)       # all end points of a step's capsules
        rmax = float(rrad.max())
        rlo = ends.min(axis=1) - rmax
        rhi = ends.max(axis=1) + rmax
        lb[idx] = _box_gap(occ.hlo[frame[idx]], occ.hhi[frame[idx]], rlo, rhi)
        bound = lb[idx]
        for h in range(n_pred):
            f = pred_frames[idx, h]
            bound = np.minimum(bound, _box_gap(occ.hlo[f], occ.hhi[f], rlo, rhi)
                               + params.prediction_discount_speed * horizons[h])
        need = bound < params.protective_distance + params.margin
    cur = np.full(M, np.nan)
    pred = np.full((M, n_pred), np.nan) if n_pred else None
    if need.any():
        cur[need] = batched_separations(occ.hseg[frame[idx[need]]], occ.hrad, rseg[need], rrad)
        if n_pred:
            pf = pred_frames[idx[need]].reshape(-1)
            rrep = np.repeat(rseg[need], n_pred, axis=0)
            pred[need] = batched_separations(occ.hseg[pf], occ.hrad, rrep,
                                             rrad).reshape(-1, n_pred)
    return need, cur, pred


def _steps_numpy(occ: _Occupancy, trajectory: JointTrajectory, m: URModel, B: np.ndarray,
                 params: SSMParameters, dt: float, tau0: float) -> _Steps:
    """The steps in speculative runs, with numpy (see the module docstring)."""
    n = len(occ.frame)
    n_pred = len(occ.horizons)
    slider, sep, tau = np.empty(n), np.empty(n), np.empty(n + 1)
    modes = np.empty(n, dtype=object)
    tau[0] = tau0
    full = params.max_slider
    rrad = np.asarray(m.link_radii, dtype=np.float64)
    lb = np.full(n, np.inf)
    n_eval = 0
    k = 0
    look = _MIN_LOOK
    guess = full
    while k < n:
        # Speculate that the command stays at ``guess`` for ``look`` steps: the arm's
        # trajectory times are then known, and the steps are evaluated together. Steps up
        # to and including the first whose command differs are exact (each one's robot pose
        # depends only on the commands before it); the rest are discarded.
        idx = np.arange(k, min(k + look, n))
        taus = tau[k] + (idx - k) * dt * guess
        rseg = robot_capsules(trajectory.positions(taus), m, B)[0]
        need, cur, pred = _chunk_separations(occ, idx, rseg, rrad, guess >= full, params, lb)
        n_eval += int(need.sum())
        M = len(idx)
        # Commands in step order up to the first that differs from ``guess``: steps that
        # need no distance run at full speed (== guess, as they only occur at full speed).
        accepted = M
        for i in np.flatnonzero(need).tolist():
            if n_pred:
                sl, mode = ssm_command(predictive_separation(float(cur[i]), pred[i],
                                                             occ.horizons, params), params)
            else:
                sl, mode = ssm_command(float(cur[i]), params)
            modes[k + i] = mode
            if sl != guess:
                accepted = i + 1
                break
        else:
            sl = guess
        head = slice(k, k + accepted)
        slider[k:k + accepted - 1] = guess
        slider[k + accepted - 1] = sl
        modes[head][~need[:accepted]] = "full"
        sep[head] = cur[:accepted]
        # tau[j + 1] = tau[j] + dt * slider[j], added in step order as a loop would.
        tau[k:k + accepted + 1] = np.cumsum(np.concatenate(([tau[k]],
                                                           dt * slider[head])))
        guess = sl
        if params.min_slider < guess < full:
            look = 1           # reduced speed follows the separation: it changes every step
        else:
            look = min(2 * look, _CHUNK) if accepted == len(idx) else _MIN_LOOK
        k += accepted
    return _Steps(slider, sep, tau, modes, lb, n_eval,
                  lambda j: robot_capsules(trajectory.positions(tau[j]), m, B)[0])


def _fill_minimum(steps: _Steps, occ: _Occupancy, rrad: np.ndarray) -> int:
    """Make the minimum separation exact: evaluate the skipped steps whose box gap lies
    below the smallest separation (in place); returns their number."""
    sep = steps.sep
    best = np.nanmin(sep) if np.isfinite(sep).any() else math.inf
    todo = np.flatnonzero(np.isnan(sep) & (steps.lb < best))
    for a in range(0, len(todo), _CHUNK):
        j = todo[a:a + _CHUNK]
        sep[j] = batched_separations(occ.hseg[occ.frame[j]], occ.hrad, steps.arm(j), rrad)
    return len(todo)


def run_offline_ssm(positions: ArrayLike, fps: float, trajectory: JointTrajectory,
                    model: str | URModel = "ur5e", base: ArrayLike | None = None,
                    params: SSMParameters | None = None, stature: float = 1.75,
                    duration: float | None = None, rate: float = CONTROL_RATE,
                    prediction_horizon: float = 0.0, prediction_step: float = 0.1,
                    trajectory_start: float = 0.0) -> OfflineSSMResult:
    """Run SSM over a motion against a robot trajectory in simulated time.

    Parameters
    ----------
    positions : array-like, shape (T, 23, 3)
        The worker's joint positions (world frame), ``fps`` frames per second; the last
        frame holds after the motion ends.
    trajectory : JointTrajectory
        The arm's looping program (trajectory time advances at the slider rate).
    model, base
        Arm model and world-from-base transform (4, 4).
    params : SSMParameters
    stature : float
        Worker height (capsule radii).
    duration : float, optional
        Seconds to simulate (default: the motion's duration).
    rate : float
        Control rate (Hz).
    prediction_horizon, prediction_step : float
        Use the motion's own future as predicted occupancy, at ``prediction_step``,
        2 ``prediction_step``, ... up to ``prediction_horizon`` seconds ahead (as the
        occupancy node publishes it); 0 = reactive.
    trajectory_start : float
        The arm's trajectory time at the start (s).
    """
    pos = np.asarray(positions, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[1:] != (23, 3) or len(pos) < 1:
        raise ValueError(f"positions must have shape (T, 23, 3), got {pos.shape}")
    if not (math.isfinite(fps) and fps > 0 and math.isfinite(rate) and rate > 0):
        raise ValueError(f"fps and rate must be > 0, got {fps}, {rate}")
    params = params if params is not None else SSMParameters()
    m = ur_model(model)
    B = np.eye(4) if base is None else np.asarray(base, dtype=np.float64)
    if B.shape != (4, 4) or not np.all(np.isfinite(B)):
        raise ValueError(f"base: expected a finite (4, 4) transform, got shape {B.shape}")
    duration = (len(pos) - 1) / fps if duration is None else float(duration)
    n = max(round(duration * rate), 1)
    dt = 1.0 / rate
    t = np.arange(n) * dt
    occ = _occupancy(pos, fps, stature, t, prediction_horizon, prediction_step)
    nb = _compiled_steps()
    steps = (_steps_compiled(nb, occ, trajectory, m, B, params, dt, trajectory_start)
             if nb is not None else
             _steps_numpy(occ, trajectory, m, B, params, dt, trajectory_start))
    n_eval = steps.n_eval + _fill_minimum(steps, occ, np.asarray(m.link_radii, dtype=np.float64))
    result = OfflineSSMResult(t, steps.slider, steps.sep, steps.tau, steps.modes)
    result.metrics = _metrics(result, trajectory, params, occ.frame, dt, prediction_horizon,
                              n_eval)
    return result


def _metrics(result: OfflineSSMResult, trajectory: JointTrajectory, params: SSMParameters,
             frame: np.ndarray, dt: float, prediction_horizon: float, n_eval: int
             ) -> dict[str, Any]:
    """The run's metrics (see :class:`OfflineSSMResult`)."""
    t, slider, sep, tau = result.time, result.slider, result.separation, result.trajectory_time
    n = len(t)
    sp = params.protective_distance
    cycles = np.flatnonzero(np.diff(np.floor(tau / trajectory.cycle_time)) > 0)
    cycle_times = np.diff(np.concatenate([[0.0], (cycles + 1) * dt])).tolist()
    columns = {"time": t, "slider": slider, "separation": sep,
               "effective_separation": sep, "protective_distance": np.full(n, sp),
               "mode": result.mode}
    metrics = metrics_from_columns(columns, cycle_times, trajectory.cycle_time,
                                   params.max_slider, params.min_slider)
    ratio = float((tau[-1] - tau[0]) / (n * dt))
    below = sep < sp
    metrics["violations"] = _violations(t, dt, below, sep, slider, params.min_slider)
    metrics.update({
        "nominal_cycle_time": trajectory.cycle_time,
        "throughput_ratio": ratio,
        "effective_cycle_time": trajectory.cycle_time / ratio if ratio > 0 else None,
        "frames_below_sp": sorted({int(f) for f in frame[below]}),
        "time_below_sp": float(below.sum() * dt),
        "evaluated_steps": n_eval,
        "prediction_horizon": float(prediction_horizon),
    })
    return metrics
