"""Several humans' occupancy fused into the one occupancy the controller checks.

Each human streams its own capsules and predictions, stamped on its own clock. The
controller takes one set: every human's capsules together, stamped with the *oldest*
stamp (so that one silent human makes the whole occupancy stale, never fresh), and every
prediction re-timed from that oldest stamp.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["FusedOccupancy", "OccupancySample", "fuse_occupancies"]


@dataclass
class OccupancySample:
    """One human's occupancy: stamp (s, ROS time), capsules and predictions.

    Attributes
    ----------
    human_id : str
    stamp : float
    segments : ndarray, shape (K, 2, 3)
    radii : ndarray, shape (K,)
    predicted : list of (float, ndarray (P, 2, 3), ndarray (P,))
        Seconds ahead of ``stamp``, capsules and radii of each predicted sample.
    """

    human_id: str
    stamp: float
    segments: NDArray[np.float64]
    radii: NDArray[np.float64]
    predicted: list[tuple[float, NDArray[np.float64], NDArray[np.float64]]]


@dataclass(frozen=True)
class FusedOccupancy:
    """The occupancy of all humans at once, as ``CoexistenceController.update_occupancy``
    takes it: capsules (K, 2, 3), radii (K,), the oldest stamp (controller clock, s) and
    the predictions re-timed from it (None without any)."""

    segments: NDArray[np.float64]
    radii: NDArray[np.float64]
    stamp: float
    predicted: list[tuple[float, NDArray[np.float64], NDArray[np.float64]]] | None


def fuse_occupancies(entries: Sequence[tuple[float, OccupancySample]],
                     use_prediction: bool = True) -> FusedOccupancy:
    """Fuse the latest sample of each human.

    Parameters
    ----------
    entries : sequence of (float, OccupancySample)
        For each human, the sample's stamp on the controller's clock and the sample; at
        least one.
    use_prediction : bool
        Keep the predictions (re-timed: a prediction ``h`` s ahead of a stamp ``s`` is
        ``h + s - stamp`` s ahead of the oldest stamp).

    Returns
    -------
    FusedOccupancy
    """
    if not entries:
        raise ValueError("fuse_occupancies: no human to fuse")
    stamp = min(s for s, _ in entries)
    if len(entries) == 1:
        segments, radii = entries[0][1].segments, entries[0][1].radii
    else:
        segments = np.concatenate([e.segments for _, e in entries])
        radii = np.concatenate([e.radii for _, e in entries])
    predicted = None
    if use_prediction:
        predicted = [(h + (s - stamp), ps, pr) for s, e in entries
                     for h, ps, pr in e.predicted] or None
    return FusedOccupancy(segments, radii, stamp, predicted)
