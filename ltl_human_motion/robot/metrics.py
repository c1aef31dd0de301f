"""Commissioning metrics of a coexistence run: JSON summary and a PNG plot.

Feed every :class:`~ltl_human_motion.robot.coexistence.ControlDecision` to a
:class:`DecisionRecorder` (it is a valid ``on_decision`` callback), then call
:func:`commissioning_metrics` and :func:`write_commissioning_report`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from ltl_human_motion.atomic import atomic_path, atomic_write_text
from ltl_human_motion.robot.coexistence import ControlDecision

__all__ = ["DecisionRecorder", "commissioning_metrics", "metrics_from_columns",
           "plot_commissioning", "write_commissioning_report"]


class DecisionRecorder:
    """Collects control decisions; pass it as ``on_decision``."""

    def __init__(self) -> None:
        self.decisions: list[ControlDecision] = []

    def __call__(self, decision: ControlDecision) -> None:
        self.decisions.append(decision)

    def arrays(self) -> dict[str, np.ndarray]:
        """Columns ``time``, ``slider``, ``separation``, ``effective_separation``,
        ``protective_distance`` (each (N,)) and ``mode`` (N,) str."""
        return _columns(self.decisions)


def _columns(decisions: Sequence[ControlDecision]) -> dict[str, np.ndarray]:
    return {
        "time": np.array([d.time for d in decisions], dtype=np.float64),
        "slider": np.array([d.slider for d in decisions], dtype=np.float64),
        "separation": np.array([d.separation for d in decisions], dtype=np.float64),
        "effective_separation": np.array([d.effective_separation for d in decisions],
                                         dtype=np.float64),
        "protective_distance": np.array([d.protective_distance for d in decisions],
                                        dtype=np.float64),
        "mode": np.array([d.mode for d in decisions], dtype=object),
    }


def _durations(t: np.ndarray) -> np.ndarray:
    if len(t) < 2:
        return np.zeros(len(t))
    dt = np.diff(t)
    return np.append(dt, np.median(dt))


def _intervals(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges [start, end) where ``mask`` is true."""
    padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


def commissioning_metrics(decisions: Sequence[ControlDecision],
                          cycle_times: Sequence[float] = (),
                          baseline_cycle_time: float | None = None,
                          max_slider: float = 1.0, min_slider: float = 0.01) -> dict[str, Any]:
    """Summary of one run.

    Parameters
    ----------
    decisions : sequence of ControlDecision
        In time order; at least one.
    cycle_times : sequence of float
        Robot cycle times measured in the run (s).
    baseline_cycle_time : float, optional
        Cycle time without a human (s), e.g. the nominal one of the trajectory.
    max_slider, min_slider : float
        The SSM slider range (to classify reduced speed and stops).

    Returns
    -------
    dict
        JSON-serialisable: ``duration``, ``steps``, ``rate_hz``, ``min_separation``,
        ``min_separation_time``, ``protective_distance``, ``time_reduced_speed``,
        ``time_min_speed``, ``fraction_reduced_speed``, ``time_by_mode``, ``violations``
        (intervals with separation below S_p: start, end, min separation, max slider),
        ``cycle_times``, ``mean_cycle_time``, ``baseline_cycle_time``, ``cycle_time_ratio``.
    """
    if not decisions:
        raise ValueError("commissioning_metrics needs at least one decision")
    return metrics_from_columns(_columns(decisions), cycle_times, baseline_cycle_time,
                                max_slider, min_slider)


def metrics_from_columns(c: dict[str, np.ndarray], cycle_times: Sequence[float] = (),
                         baseline_cycle_time: float | None = None, max_slider: float = 1.0,
                         min_slider: float = 0.01) -> dict[str, Any]:
    """:func:`commissioning_metrics` of a run given as columns (the arrays of
    :meth:`DecisionRecorder.arrays`: ``time``, ``slider``, ``separation``,
    ``protective_distance``, each (N,), and ``mode`` (N,) str), e.g. an offline run's."""
    t = c["time"]
    if len(t) == 0:
        raise ValueError("commissioning_metrics needs at least one decision")
    if np.any(np.diff(t) < 0):
        raise ValueError("decisions must be in time order")
    dt = _durations(t)
    sep = c["separation"]
    known = np.isfinite(sep)
    sp = float(c["protective_distance"][-1])
    imin = int(np.nanargmin(np.where(known, sep, np.inf))) if known.any() else None
    below = known & (sep < c["protective_distance"])
    violations = []
    for a, b in _intervals(below):
        violations.append({
            "start": float(t[a] - t[0]), "end": float(t[b - 1] - t[0] + dt[b - 1]),
            "min_separation": float(np.min(sep[a:b])),
            "max_slider": float(np.max(c["slider"][a:b])),
            "slowed_to_min": bool(np.all(c["slider"][a:b] <= min_slider + 1e-9)),
        })
    reduced = c["slider"] < max_slider - 1e-9
    modes: dict[str, float] = {}
    for mode in sorted(set(c["mode"])):
        modes[str(mode)] = float(np.sum(dt[c["mode"] == mode]))
    cycles = [float(x) for x in cycle_times]
    mean_cycle = float(np.mean(cycles)) if cycles else None
    ratio = (mean_cycle / baseline_cycle_time
             if mean_cycle is not None and baseline_cycle_time else None)
    duration = float(t[-1] - t[0] + dt[-1])
    return {
        "duration": duration,
        "steps": len(t),
        "rate_hz": float((len(t) - 1) / (t[-1] - t[0])) if len(t) > 1 and t[-1] > t[0]
        else None,
        "min_separation": None if imin is None else float(sep[imin]),
        "min_separation_time": None if imin is None else float(t[imin] - t[0]),
        "protective_distance": sp,
        "time_reduced_speed": float(np.sum(dt[reduced])),
        "time_min_speed": float(np.sum(dt[c["slider"] <= min_slider + 1e-9])),
        "fraction_reduced_speed": float(np.sum(dt[reduced]) / duration) if duration > 0
        else 0.0,
        "time_by_mode": modes,
        "violations": violations,
        "cycle_times": cycles,
        "mean_cycle_time": mean_cycle,
        "baseline_cycle_time": baseline_cycle_time,
        "cycle_time_ratio": ratio,
    }


def plot_commissioning(decisions: Sequence[ControlDecision], path: str | os.PathLike[str],
                       title: str = "coexistence run") -> Path:
    """PNG of separation (with S_p) and the speed command over time; written atomically."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        from ltl_human_motion.errors import MissingDependencyError

        raise MissingDependencyError("plots need matplotlib: pip install matplotlib") from exc
    c = _columns(decisions)
    t = c["time"] - (c["time"][0] if len(c["time"]) else 0.0)
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
    try:
        ax1.plot(t, c["separation"], label="min separation")
        if np.any(np.isfinite(c["effective_separation"])
                  & (c["effective_separation"] != c["separation"])):
            ax1.plot(t, c["effective_separation"], "--", label="effective (predicted)")
        ax1.plot(t, c["protective_distance"], "r:", label="S_p")
        below = np.isfinite(c["separation"]) & (c["separation"] < c["protective_distance"])
        dt = _durations(t)
        for i, (a, b) in enumerate(_intervals(below)):
            for ax in (ax1, ax2):
                ax.axvspan(t[a], t[b - 1] + dt[b - 1], color="red", alpha=0.15, lw=0,
                           label="below S_p" if i == 0 and ax is ax1 else None)
        ax1.set_ylabel("separation [m]")
        ax1.legend(loc="upper right", fontsize="small")
        ax1.set_title(title)
        ax2.step(t, c["slider"], where="post")
        ax2.set_ylabel("speed slider")
        ax2.set_xlabel("time [s]")
        ax2.set_ylim(0, 1.05)
        path = Path(path)
        with atomic_path(path, suffix=".png") as tmp:
            fig.savefig(tmp, format="png", dpi=100)
    finally:
        plt.close(fig)
    return path


def write_commissioning_report(decisions: Sequence[ControlDecision],
                               out_dir: str | os.PathLike[str], name: str = "coexistence",
                               cycle_times: Sequence[float] = (),
                               baseline_cycle_time: float | None = None,
                               max_slider: float = 1.0, min_slider: float = 0.01,
                               extra: dict[str, Any] | None = None) -> tuple[Path, Path]:
    """Write ``<name>.json`` (metrics) and ``<name>.png`` (plot) into ``out_dir``.

    Returns
    -------
    json_path, png_path : Path
    """
    metrics = commissioning_metrics(decisions, cycle_times, baseline_cycle_time, max_slider,
                                    min_slider)
    if extra:
        metrics["extra"] = extra
    out = Path(out_dir)
    json_path = out / f"{name}.json"
    atomic_write_text(json_path, json.dumps(_jsonable(metrics), indent=2, allow_nan=False)
                      + "\n")
    png_path = plot_commissioning(decisions, out / f"{name}.png", title=name)
    return json_path, png_path


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if hasattr(value, "__dataclass_fields__"):
        return _jsonable(asdict(value))
    return value
