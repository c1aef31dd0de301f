"""Speed and separation monitoring (SSM) after ISO/TS 15066.

Protective separation distance::

    S_p = S_h + S_r + S_s + C + Z_d + Z_r
    S_h = v_h (T_r + T_s)      human approach while the robot reacts and stops
    S_r = v_r T_r              robot travel during its reaction time
    S_s                        robot stopping distance
    C                          intrusion distance (body parts reaching past the sensed shape)
    Z_d + Z_r                  position uncertainty of the sensing and of the robot

The speed command is a speed-slider fraction: full speed when the separation exceeds
``S_p + margin``, linearly reduced inside that band, and the minimum at or below ``S_p``.

The minimum is 1 % rather than 0: on UR controllers a speed slider at 0 turns the next
slider change into a protective stop, so this module never commands 0. The slider minimum
therefore stands for "stop": at 1 % the arm creeps at a hundredth of its speed, which the
parameters must account for (``robot_speed`` and ``stopping_distance`` are those at full
speed, a conservative choice). SSM here is a commissioning and research aid, not a
certified safety function.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

__all__ = ["SLIDER_MIN", "SSMParameters", "predictive_separation", "slider_from_separation"]

#: Smallest speed-slider command (1 %), standing for "stop" (see the module docstring).
SLIDER_MIN = 0.01


@dataclass(frozen=True)
class SSMParameters:
    """Parameters of speed and separation monitoring (SI units).

    Attributes
    ----------
    human_speed : float
        v_h, m/s (ISO 13855 walking speed 1.6 m/s).
    robot_speed : float
        v_r, m/s: highest speed of the robot towards the human at full slider.
    reaction_time : float
        T_r, s: sensing + processing + communication latency.
    stopping_time : float
        T_s, s.
    stopping_distance : float
        S_s, m.
    intrusion_distance : float
        C, m.
    sensor_uncertainty, robot_uncertainty : float
        Z_d and Z_r, m.
    margin : float
        Width (m) of the band above S_p in which the speed is reduced linearly.
    min_slider, max_slider : float
        Slider range; ``min_slider`` must be >= 0.01 (see the module docstring).
    prediction_discount_speed : float
        m/s. A predicted separation ``d`` reached ``dt`` seconds ahead counts as
        ``d + prediction_discount_speed * dt`` now (the robot still has ``dt`` to slow
        down); see :func:`predictive_separation`.
    """

    human_speed: float = 1.6
    robot_speed: float = 1.0
    reaction_time: float = 0.1
    stopping_time: float = 0.3
    stopping_distance: float = 0.15
    intrusion_distance: float = 0.1
    sensor_uncertainty: float = 0.05
    robot_uncertainty: float = 0.02
    margin: float = 0.5
    min_slider: float = SLIDER_MIN
    max_slider: float = 1.0
    prediction_discount_speed: float = 0.5

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise ValueError(f"SSMParameters.{f.name}: expected a finite number >= 0, "
                                 f"got {value!r}")
        if self.margin <= 0:
            raise ValueError(f"SSMParameters.margin must be > 0, got {self.margin}")
        if not SLIDER_MIN <= self.min_slider <= self.max_slider <= 1.0:
            raise ValueError("SSMParameters: need 0.01 <= min_slider <= max_slider <= 1, got "
                             f"{self.min_slider}, {self.max_slider}")

    @property
    def protective_distance(self) -> float:
        """S_p (m)."""
        s_h = self.human_speed * (self.reaction_time + self.stopping_time)
        s_r = self.robot_speed * self.reaction_time
        return (s_h + s_r + self.stopping_distance + self.intrusion_distance
                + self.sensor_uncertainty + self.robot_uncertainty)

    def terms(self) -> dict[str, float]:
        """The summands of S_p by name (for reports)."""
        return {
            "S_h": self.human_speed * (self.reaction_time + self.stopping_time),
            "S_r": self.robot_speed * self.reaction_time,
            "S_s": self.stopping_distance,
            "C": self.intrusion_distance,
            "Z_d": self.sensor_uncertainty,
            "Z_r": self.robot_uncertainty,
            "S_p": self.protective_distance,
        }


def slider_from_separation(separation: float, params: SSMParameters) -> float:
    """Speed-slider command for a separation.

    Parameters
    ----------
    separation : float
        Minimum human-robot capsule separation (m); NaN counts as 0 (unknown = closest).
    params : SSMParameters

    Returns
    -------
    float
        In ``[params.min_slider, params.max_slider]``.
    """
    if not math.isfinite(separation):
        separation = 0.0 if math.isnan(separation) or separation < 0 else separation
    sp = params.protective_distance
    if separation <= sp:
        return params.min_slider
    if separation >= sp + params.margin:
        return params.max_slider
    frac = (separation - sp) / params.margin
    return params.min_slider + frac * (params.max_slider - params.min_slider)


def predictive_separation(current: float, predicted: Sequence[float],
                          horizons: Sequence[float], params: SSMParameters) -> float:
    """Effective separation when a predicted occupancy is available.

    Parameters
    ----------
    current : float
        Separation now (m).
    predicted : sequence of float, length H
        Separation from the predicted human capsules ``horizons[i]`` seconds ahead.
    horizons : sequence of float, length H
        Seconds ahead (>= 0).
    params : SSMParameters

    Returns
    -------
    float
        ``min(current, min_i(predicted[i] + v_disc * horizons[i]))`` with
        ``v_disc = params.prediction_discount_speed``: an approach predicted later weighs
        less, since there is more time to slow down.
    """
    d = np.asarray(predicted, dtype=np.float64)
    h = np.asarray(horizons, dtype=np.float64)
    if d.shape != h.shape or d.ndim != 1:
        raise ValueError(f"predicted and horizons must be 1-D of equal length, got {d.shape}, "
                         f"{h.shape}")
    if d.size == 0:
        return float(current)
    if np.any(~np.isfinite(h)) or np.any(h < 0):
        raise ValueError("horizons must be finite and >= 0")
    return float(min(current, float(np.min(d + params.prediction_discount_speed * h))))
