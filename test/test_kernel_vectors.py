"""The column-wise 3-vector products give numpy's numbers bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.kernel.vectors import cross3, dot3, norm3


@pytest.mark.parametrize("shape", [(1, 3), (2, 3), (7, 3), (5000, 3), (40, 23, 3), (3,)])
def test_products_are_numpys_bit_for_bit(shape):
    rng = np.random.default_rng(len(shape) * 100 + shape[0])
    a = rng.normal(size=shape) * rng.uniform(1e-3, 1e3, size=shape)
    b = rng.normal(size=shape)
    assert np.array_equal(dot3(a, b), np.sum(a * b, -1))
    assert np.array_equal(norm3(a), np.linalg.norm(a, axis=-1))
    assert np.array_equal(cross3(a, b), np.cross(a, b))
    if a.ndim > 1 and len(a) > 1:                           # strided views
        assert np.array_equal(dot3(a[::2], b[::2]), np.sum(a[::2] * b[::2], -1))
        assert np.array_equal(norm3(a[::2]), np.linalg.norm(a[::2], axis=-1))
    # Broadcasting against one vector, as angles against the vertical do.
    up = np.array([0.0, 0.0, 1.0])
    assert np.array_equal(cross3(a, up), np.cross(a, up))
    assert np.array_equal(dot3(a, up), np.sum(a * up, -1))


def test_signed_zeros_are_numpys():
    import itertools

    vals = [0.0, -0.0, 1e-300, -1e-300, 2.0]
    a = np.array(list(itertools.product(vals, repeat=3)))
    b = a[::-1].copy()
    bits = lambda x: np.ascontiguousarray(x).view(np.int64)   # noqa: E731
    assert np.array_equal(bits(dot3(a, b)), bits(np.sum(a * b, -1)))
    assert np.array_equal(bits(dot3(a, -b)), bits(np.sum(a * -b, -1)))
    assert np.array_equal(bits(norm3(a)), bits(np.linalg.norm(a, axis=-1)))
    assert np.array_equal(bits(cross3(a, b)), bits(np.cross(a, b)))
