"""Conversions between the paper's y-up frame and our z-up frame (REP 103).

The paper (Sec. IV) gives coordinates with **y up**. We use **z up**, x forward. The
conversion is a +90 degree rotation about x::

    (x, y, z)_paper  ->  (x, -z, y)_ours

so the paper's O1 ``[-1, 0.2, 1.0]`` becomes ``[-1.0, -1.0, 0.2]``. A cell file with
``frame: paper_yup`` is converted once, when it is loaded (:mod:`.cell`).
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.kernel.rotations import ZUP_FROM_YUP

__all__ = ["ZUP_FROM_YUP", "extents_zup_from_yup", "yup_from_zup", "zup_from_yup"]

def _as_vectors(points: np.ndarray, name: str) -> np.ndarray:
    arr = np.asarray(points, dtype=np.float64)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3), got {arr.shape}")
    return arr


def zup_from_yup(points: np.ndarray) -> np.ndarray:
    """Convert points from the paper's y-up frame to our z-up frame.

    Parameters
    ----------
    points : array-like, shape (..., 3)
        ``(x, y, z)`` in the y-up frame.

    Returns
    -------
    points : ndarray, shape (..., 3)
        ``(x, -z, y)``.
    """
    p = _as_vectors(points, "points")
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], axis=-1)


def yup_from_zup(points: np.ndarray) -> np.ndarray:
    """Inverse of :func:`zup_from_yup`: ``(x, y, z)_ours -> (x, z, -y)``.

    Parameters
    ----------
    points : array-like, shape (..., 3)

    Returns
    -------
    points : ndarray, shape (..., 3)
    """
    p = _as_vectors(points, "points")
    return np.stack([p[..., 0], p[..., 2], -p[..., 1]], axis=-1)


def extents_zup_from_yup(extents: np.ndarray) -> np.ndarray:
    """Convert box extents (non-negative side lengths) from y-up to z-up.

    Parameters
    ----------
    extents : array-like, shape (..., 3)
        ``(sx, sy, sz)`` with sy vertical.

    Returns
    -------
    extents : ndarray, shape (..., 3)
        ``(sx, sz, sy)``.
    """
    e = _as_vectors(extents, "extents")
    return np.stack([e[..., 0], e[..., 2], e[..., 1]], axis=-1)
