"""Movement times of people, for the durations of made primitives.

* **Reach and move times** follow Fitts' law, ``MT = a + b log2(2 D / W)`` (Fitts 1954;
  the Shannon form ``log2(D / W + 1)`` of MacKenzie 1992 is used so that short moves stay
  positive). Constants: ``a = 0.2 s`` and ``b = 0.1 s/bit``, the range MacKenzie (1992,
  *Human-Computer Interaction* 7:91, Table 3) reports for arm movements; they match MTM-1's
  Reach case B (reach to a single object whose location varies, Maynard, Stegemerten &
  Schwab 1948): 30 cm takes 12.8 TMU = 0.46 s in MTM-1 and 0.47 s here with
  ``W = 5 cm``.
* **Peak hand speed** of a minimum-jerk move of length ``D`` in time ``T`` is
  ``1.875 D / T`` (Flash & Hogan 1985); :func:`min_move_time` gives the shortest ``T``
  for a peak speed.
* **Sit-to-stand** takes 1.5-3 s in healthy adults (Schenkman et al. 1990, *Clinical
  Biomechanics* 5:133, 1.5-2.3 s at a self-selected pace; Bohannon 2006, five-times
  sit-to-stand 6-12 s, so 1.2-2.4 s each); kneeling down and getting up are of the same
  order (about 2 s each, Ikeda et al. 1991).
"""

from __future__ import annotations

import math

__all__ = ["FITTS_A", "FITTS_B", "MIN_JERK_PEAK", "SIT_TO_STAND_RANGE", "fitts_time",
           "min_move_time"]

#: Fitts' law intercept (s) and slope (s/bit) for arm movements (MacKenzie 1992).
FITTS_A = 0.2
FITTS_B = 0.1
#: Peak speed of a minimum-jerk move over its mean speed (Flash & Hogan 1985).
MIN_JERK_PEAK = 1.875
#: Duration range of a sit-to-stand (and of sitting down), s (Schenkman et al. 1990).
SIT_TO_STAND_RANGE = (1.5, 3.0)


def fitts_time(distance: float, width: float = 0.05) -> float:
    """Movement time (s) of a hand move over ``distance`` m to a target ``width`` m wide."""
    if distance < 0 or width <= 0:
        raise ValueError(f"distance must be >= 0 and width > 0, got {distance}, {width}")
    return FITTS_A + FITTS_B * math.log2(distance / width + 1.0)


def min_move_time(distance: float, peak_speed: float) -> float:
    """Shortest duration (s) of a minimum-jerk move of ``distance`` m whose peak speed
    stays at or under ``peak_speed`` m/s."""
    if peak_speed <= 0:
        raise ValueError(f"peak_speed must be positive, got {peak_speed}")
    return MIN_JERK_PEAK * max(distance, 0.0) / peak_speed
