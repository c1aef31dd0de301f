"""A navigation field's values at floor points by the compiled loop
(_navigation_numba.cell_values) are numpy's lookup at NavigationField._cells, bit for bit:
random points, points on the cells' rounding ties, off the grid, NaN and infinite."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ltl_human_motion.kernel.segments import compiled_module
from ltl_human_motion.planning.navigation import NavigationField


def test_compiled_cell_values_equal_the_numpy_lookup() -> None:
    if compiled_module("ltl_human_motion.planning._navigation_numba") is None:
        pytest.skip("numba kernels not in use")
    field = NavigationField(np.array([-1.0, -2.0]), np.array([3.0, 2.5]),
                            lambda xy: np.hypot(xy[:, 0] - 1.0, xy[:, 1]) > 0.5,
                            lambda xy: np.hypot(xy[:, 0] - 2.5, xy[:, 1] - 2.0) < 0.3, 0.05)
    rng = np.random.default_rng(0)
    for trial in range(400):
        n = int(rng.integers(0, 40))
        x, y = rng.uniform(-3.0, 5.0, n), rng.uniform(-4.0, 4.0, n)
        if trial % 3 == 0:
            x = np.round(x / 0.025) * 0.025           # halfway between cell centres
        if trial % 7 == 0 and n > 3:
            x[0], y[1], x[2], x[3] = np.nan, np.inf, -np.inf, 1e30
        poses = np.stack([x, y, y], axis=1)           # strided columns, as the search's
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            i, j = field._cells(x, y)
        for table, read in ((field.dist, field.distance), (field.descent, field.heading)):
            assert np.array_equal(read(poses[:, 0], poses[:, 1]), table[i, j], equal_nan=True)
