"""scene.geometry.point_bounds by the compiled fold (scene._clearance_numba) equals
numpy's min and max bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.kernel.segments import compiled_module


def test_compiled_point_bounds_equal_numpy() -> None:
    """scene.geometry.point_bounds by the compiled fold: numpy's min and max bit for bit,
    NaN and signed zeros included."""
    from ltl_human_motion.scene import geometry
    if compiled_module("ltl_human_motion.scene._clearance_numba") is None:
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(3)
    for trial in range(60):
        shape = [(5, 23, 3), (23, 3), (4, 7, 23, 3), (100, 1, 3), (1, 3)][trial % 5]
        x = rng.normal(size=shape)
        if trial % 3 == 0:
            x = np.round(x)
        if trial % 7 == 0:
            x.flat[rng.integers(0, x.size, 3)] = np.nan
        rows = np.ascontiguousarray(np.moveaxis(x, -2, 0))
        lo, hi = geometry.point_bounds(x)
        assert lo.tobytes() == rows.min(axis=0).tobytes()
        assert hi.tobytes() == rows.max(axis=0).tobytes()
