"""Products of 3-vectors over long arrays, column by column.

numpy's reductions over a last axis of length 3 (``np.sum(a * b, -1)``,
``np.linalg.norm(v, axis=-1)``) run one tiny reduction per row, several times slower than
three elementwise passes over the columns. These functions give the same numbers, bit
for bit (numpy adds a row's three terms left to right, as these do; tests hold them
against numpy), for the per-frame angles of long motions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["cross3", "dot3", "norm3"]


def dot3(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.sum(a * b, -1)`` of vectors a, b (..., 3) (broadcast), shape (...)."""
    # numpy's sum starts from +0.0: it decides the sign of a zero result.
    return 0.0 + a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def norm3(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.linalg.norm(v, axis=-1)`` of vectors v (..., 3), shape (...)."""
    return np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1] + v[..., 2] * v[..., 2])


def cross3(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.cross(a, b)`` of vectors a, b (..., 3) (broadcast), shape (..., 3)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)
