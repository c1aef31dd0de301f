"""The revised NIOSH lifting equation (Waters, Putz-Anderson, Garg & Fine, Ergonomics 36
(1993) 749-776; Applications Manual, NIOSH publication 94-110, 1994), metric form.

    RWL = LC * HM * VM * DM * AM * FM * CM,   LI = load / RWL

with LC = 23 kg, HM = 25/H, VM = 1 - 0.003 |V - 75|, DM = 0.82 + 4.5/D, AM = 1 - 0.0032 A
(H, V, D in cm, A in degrees), FM from the frequency table (manual Table 5) and CM from the
coupling table (manual Table 7). Out of range: H < 25 -> HM = 1, H > 63 -> 0; V > 175 ->
VM = 0; D < 25 -> DM = 1, D > 175 -> 0; A > 135 -> AM = 0; F < 0.2 lifts/min counts as
0.2, F > 15 -> FM = 0.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

__all__ = ["LOAD_CONSTANT", "LiftResult", "coupling_multiplier", "frequency_multiplier",
           "lift"]

#: kg, the load constant (Waters et al. 1993).
LOAD_CONSTANT = 23.0

#: Lifts per minute of the rows of the frequency table (manual Table 5).
_FREQUENCIES = np.array([0.2, 0.5, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15])
#: FM [row][duration column]: <= 1 h (V < 75, V >= 75), <= 2 h (...), <= 8 h (...).
_FM = np.array([
    [1.00, 1.00, 0.95, 0.95, 0.85, 0.85],
    [0.97, 0.97, 0.92, 0.92, 0.81, 0.81],
    [0.94, 0.94, 0.88, 0.88, 0.75, 0.75],
    [0.91, 0.91, 0.84, 0.84, 0.65, 0.65],
    [0.88, 0.88, 0.79, 0.79, 0.55, 0.55],
    [0.84, 0.84, 0.72, 0.72, 0.45, 0.45],
    [0.80, 0.80, 0.60, 0.60, 0.35, 0.35],
    [0.75, 0.75, 0.50, 0.50, 0.27, 0.27],
    [0.70, 0.70, 0.42, 0.42, 0.22, 0.22],
    [0.60, 0.60, 0.35, 0.35, 0.18, 0.18],
    [0.52, 0.52, 0.30, 0.30, 0.00, 0.15],
    [0.45, 0.45, 0.26, 0.26, 0.00, 0.13],
    [0.41, 0.41, 0.00, 0.23, 0.00, 0.00],
    [0.37, 0.37, 0.00, 0.21, 0.00, 0.00],
    [0.00, 0.34, 0.00, 0.00, 0.00, 0.00],
    [0.00, 0.31, 0.00, 0.00, 0.00, 0.00],
    [0.00, 0.28, 0.00, 0.00, 0.00, 0.00],
])
_DURATIONS = {"1h": 0, "2h": 1, "8h": 2}
#: CM for (V < 75 cm, V >= 75 cm) by coupling quality (manual Table 7).
_CM = {"good": (1.00, 1.00), "fair": (0.95, 1.00), "poor": (0.90, 0.90)}


def frequency_multiplier(frequency: float, duration: str, v_cm: float) -> float:
    """FM of the manual's Table 5.

    ``frequency`` in lifts per minute (rounded up to the next table row, the conservative
    reading of the table; below 0.2 counts as 0.2); ``duration`` ``"1h"``, ``"2h"`` or
    ``"8h"`` (work durations of at most 1, 2 or 8 hours); ``v_cm`` the vertical location.
    """
    if duration not in _DURATIONS:
        raise ValueError(f"duration must be one of {sorted(_DURATIONS)}, got {duration!r}")
    if not np.isfinite(frequency) or frequency < 0:
        raise ValueError(f"frequency must be >= 0 lifts/min, got {frequency}")
    if frequency > _FREQUENCIES[-1]:
        return 0.0
    row = int(np.searchsorted(_FREQUENCIES, frequency - 1e-9, side="left"))
    return float(_FM[row, 2 * _DURATIONS[duration] + (1 if v_cm >= 75 else 0)])


def coupling_multiplier(coupling: str, v_cm: float) -> float:
    """CM of the manual's Table 7 (``good``, ``fair`` or ``poor``)."""
    if coupling not in _CM:
        raise ValueError(f"coupling must be one of {sorted(_CM)}, got {coupling!r}")
    return _CM[coupling][1 if v_cm >= 75 else 0]


@dataclass(frozen=True)
class LiftResult:
    """Multipliers, RWL and LI of one end (origin or destination) of a lift.

    Lengths in cm, angle in degrees, masses in kg.
    """

    H: float
    V: float
    D: float
    A: float
    F: float
    HM: float
    VM: float
    DM: float
    AM: float
    FM: float
    CM: float
    RWL: float
    load: float
    LI: float

    def to_dict(self) -> dict[str, float]:
        return asdict(self)


def lift(load_kg: float, h_cm: float, v_cm: float, d_cm: float, a_deg: float = 0.0,
         frequency: float = 0.2, duration: str = "1h", coupling: str = "good"
         ) -> LiftResult:
    """RWL and lifting index at one end of a lift.

    Parameters
    ----------
    load_kg : float
        Weight of the object.
    h_cm, v_cm : float
        Horizontal location of the hands from the mid-point between the ankles, and their
        height above the floor, at this end.
    d_cm : float
        Vertical travel between origin and destination.
    a_deg : float
        Asymmetry angle at this end.
    frequency, duration, coupling
        See :func:`frequency_multiplier` and :func:`coupling_multiplier`.
    """
    for name, v in (("load_kg", load_kg), ("h_cm", h_cm), ("v_cm", v_cm), ("d_cm", d_cm),
                    ("a_deg", a_deg)):
        if not np.isfinite(v) or v < 0:
            raise ValueError(f"lift: {name} must be finite and >= 0, got {v}")
    hm = 1.0 if h_cm <= 25 else (25.0 / h_cm if h_cm <= 63 else 0.0)
    vm = 1.0 - 0.003 * abs(v_cm - 75.0) if v_cm <= 175 else 0.0
    dm = 1.0 if d_cm <= 25 else (0.82 + 4.5 / d_cm if d_cm <= 175 else 0.0)
    am = 1.0 - 0.0032 * a_deg if a_deg <= 135 else 0.0
    fm = frequency_multiplier(frequency, duration, v_cm)
    cm = coupling_multiplier(coupling, v_cm)
    rwl = LOAD_CONSTANT * hm * vm * dm * am * fm * cm
    li = float(load_kg / rwl) if rwl > 0 else float("inf")
    return LiftResult(float(h_cm), float(v_cm), float(d_cm), float(a_deg), float(frequency),
                      hm, vm, dm, am, fm, cm, rwl, float(load_kg), li)
