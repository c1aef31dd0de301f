"""The revised NIOSH lifting equation (Waters, Putz-Anderson, Garg & Fine, Ergonomics 36
(1993) 749-776; Applications Manual, NIOSH publication 94-110, 1994, revised 9/2021).

    RWL = LC * HM * VM * DM * AM * FM * CM,   LI = load / RWL

Metric form (the default): LC = 23 kg, HM = 25/H, VM = 1 - 0.003 |V - 75|,
DM = 0.82 + 4.5/D, AM = 1 - 0.0032 A (H, V, D in cm, A in degrees). U.S. customary form
(``units="us"``, the form of the manual's worked examples): LC = 51 lb, HM = 10/H,
VM = 1 - 0.0075 |V - 30|, DM = 0.82 + 1.8/D (inches). The two sets of constants are not
exact conversions of each other (manual p. 7), so each is kept as published.

FM comes from the frequency table (manual Table 5), linearly interpolated between the two
nearest rows (manual p. 7: "the appropriate multiplier must be interpolated"), with V at
the *origin* of the lift selecting the column (manual p. 15); CM from the coupling table
(manual Table 7) with V at the end being evaluated (manual Example 4, Figure 14).
Out of range (metric; U.S. in brackets): H < 25 [10] -> HM = 1, H > 63 [25] -> 0;
V > 175 [70] -> VM = 0; D < 25 [10] -> DM = 1, D > 175 [70] -> 0; A > 135 -> AM = 0;
F < 0.2 lifts/min counts as 0.2, F > 15 -> FM = 0.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

__all__ = ["LOAD_CONSTANT", "LiftResult", "coupling_multiplier", "frequency_multiplier",
           "lift"]

#: kg, the load constant (Waters et al. 1993).
LOAD_CONSTANT = 23.0


@dataclass(frozen=True)
class _Units:
    """Constants of one unit system of the manual's p. 7 table (lengths in cm or in)."""

    lc: float           # load constant (kg or lb)
    h_min: float        # H at or below which HM = 1
    h_max: float        # H above which HM = 0
    v_opt: float        # V of VM = 1
    v_slope: float      # VM = 1 - v_slope * |V - v_opt|
    v_max: float        # V above which VM = 0
    d_min: float        # D at or below which DM = 1
    d_max: float        # D above which DM = 0
    d_num: float        # DM = 0.82 + d_num / D
    v_split: float      # V splitting the FM and CM columns (30 in = 75 cm, Tables 5, 7)


_UNITS = {
    "metric": _Units(LOAD_CONSTANT, 25.0, 63.0, 75.0, 0.003, 175.0, 25.0, 175.0, 4.5, 75.0),
    "us": _Units(51.0, 10.0, 25.0, 30.0, 0.0075, 70.0, 10.0, 70.0, 1.8, 30.0),
}

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


def frequency_multiplier(frequency: float, duration: str, v_cm: float,
                         units: str = "metric") -> float:
    """FM of the manual's Table 5.

    ``frequency`` in lifts per minute, linearly interpolated between the two nearest rows
    (manual p. 7; its Example 7 interpolates F = 2.4 between the rows for 2 and 3; below
    0.2 counts as 0.2, above 15 gives 0); ``duration`` ``"1h"``, ``"2h"`` or ``"8h"`` (work
    durations of at most 1, 2 or 8 hours); ``v_cm`` the vertical location at the origin
    (cm, or inches with ``units="us"``).
    """
    if duration not in _DURATIONS:
        raise ValueError(f"duration must be one of {sorted(_DURATIONS)}, got {duration!r}")
    if not np.isfinite(frequency) or frequency < 0:
        raise ValueError(f"frequency must be >= 0 lifts/min, got {frequency}")
    if frequency > _FREQUENCIES[-1]:
        return 0.0
    col = _FM[:, 2 * _DURATIONS[duration] + (1 if v_cm >= _units(units).v_split else 0)]
    return float(np.interp(frequency, _FREQUENCIES, col))


def coupling_multiplier(coupling: str, v_cm: float, units: str = "metric") -> float:
    """CM of the manual's Table 7 (``good``, ``fair`` or ``poor``) at vertical location
    ``v_cm`` (cm, or inches with ``units="us"``)."""
    if coupling not in _CM:
        raise ValueError(f"coupling must be one of {sorted(_CM)}, got {coupling!r}")
    return _CM[coupling][1 if v_cm >= _units(units).v_split else 0]


def _units(units: str) -> _Units:
    if units not in _UNITS:
        raise ValueError(f"units must be one of {sorted(_UNITS)}, got {units!r}")
    return _UNITS[units]


@dataclass(frozen=True)
class LiftResult:
    """Multipliers, RWL and LI of one end (origin or destination) of a lift.

    Lengths in cm, angle in degrees, masses in kg (inches and pounds for a lift computed
    with ``units="us"``).
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
         frequency: float = 0.2, duration: str = "1h", coupling: str = "good",
         v_origin_cm: float | None = None, units: str = "metric") -> LiftResult:
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
    v_origin_cm : float, optional
        V at the origin of the lift, which selects the FM column also at the destination
        (manual p. 15); default ``v_cm`` (this end is the origin).
    units : str
        ``"metric"`` (cm, kg) or ``"us"`` (inches, pounds; LC = 51 lb).
    """
    for name, v in (("load_kg", load_kg), ("h_cm", h_cm), ("v_cm", v_cm), ("d_cm", d_cm),
                    ("a_deg", a_deg)):
        if not np.isfinite(v) or v < 0:
            raise ValueError(f"lift: {name} must be finite and >= 0, got {v}")
    u = _units(units)
    hm = 1.0 if h_cm <= u.h_min else (u.h_min / h_cm if h_cm <= u.h_max else 0.0)
    vm = 1.0 - u.v_slope * abs(v_cm - u.v_opt) if v_cm <= u.v_max else 0.0
    dm = 1.0 if d_cm <= u.d_min else (0.82 + u.d_num / d_cm if d_cm <= u.d_max else 0.0)
    am = 1.0 - 0.0032 * a_deg if a_deg <= 135 else 0.0
    fm = frequency_multiplier(frequency, duration, v_cm if v_origin_cm is None
                              else v_origin_cm, units)
    cm = coupling_multiplier(coupling, v_cm, units)
    rwl = u.lc * hm * vm * dm * am * fm * cm
    li = float(load_kg / rwl) if rwl > 0 else float("inf")
    return LiftResult(float(h_cm), float(v_cm), float(d_cm), float(a_deg), float(frequency),
                      hm, vm, dm, am, fm, cm, rwl, float(load_kg), li)
