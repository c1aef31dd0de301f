"""The self-penetration check's compiled search for the deepest pair
(biomechanics._deepest_penetration) finds what the full (T, P) depth table's argmax does."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.kernel.segments import compiled_module
from ltl_human_motion.motion import biomechanics
from ltl_human_motion.motion.skeleton import Skeleton


def _table_argmax(p: np.ndarray, stature: float) -> tuple[int, int, float]:
    depth, _ = biomechanics.self_penetration(p, stature)
    f, k = np.unravel_index(int(np.argmax(depth)), depth.shape)
    return int(f), int(k), float(depth[f, k])


def _walk(n: int, rng: np.random.Generator, sk: Skeleton, noise: float) -> np.ndarray:
    """A rest pose swinging its limbs smoothly (and jittered by ``noise``), (n, J, 3)."""
    t = np.arange(n)[:, None, None] / 120.0
    phase = rng.uniform(0, 2 * np.pi, size=(1, sk.rest_positions().shape[0], 3))
    swing = 0.08 * np.sin(2 * np.pi * 1.1 * t + phase)
    return sk.rest_positions()[None] + swing + rng.normal(size=swing.shape) * noise


def test_deepest_penetration_equals_the_table_argmax() -> None:
    if compiled_module("ltl_human_motion.kernel._segments_numba") is None:
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(8)
    for trial in range(24):
        stature = float(rng.uniform(1.5, 2.0))
        sk = Skeleton(stature)
        p = _walk(int(rng.integers(1, 600)), rng, sk, [0.0, 0.002, 0.02, 0.2][trial % 4])
        if trial % 5 == 0:
            p = np.round(p, 1)                      # exact ties between frames and pairs
        assert biomechanics._deepest_penetration(p, stature) == _table_argmax(p, stature)
    still = np.repeat(Skeleton(1.75).rest_positions()[None], 30, axis=0)
    assert biomechanics._deepest_penetration(still, 1.75) == _table_argmax(still, 1.75)


def test_penetration_entry_without_the_kernel_is_the_same(monkeypatch) -> None:
    """The entry reads the same frame, pair and depth from either path."""
    rng = np.random.default_rng(9)
    p = _walk(300, rng, Skeleton(1.8), 0.05)
    labels = ["walk"] * len(p)
    fast = biomechanics._penetration_entry(p, 120.0, labels, 1.8)
    monkeypatch.setattr(biomechanics, "_deepest_penetration", lambda *args: None)
    assert biomechanics._penetration_entry(p, 120.0, labels, 1.8) == fast


def test_max_self_penetration_is_the_table_maximum(monkeypatch) -> None:
    """By the compiled search and without it, the largest depth of the (T, P) table."""
    rng = np.random.default_rng(10)
    poses = [_walk(int(rng.integers(1, 300)), rng, Skeleton(1.7), noise)
             for noise in (0.0, 0.02, 0.2)]
    poses[1][3, 4, 0] = np.nan                      # not finite: the table's maximum, nan
    want = [float(np.max(biomechanics.self_penetration(p, 1.7)[0])) for p in poses]
    for _ in range(2):
        got = [biomechanics.max_self_penetration(p, 1.7) for p in poses]
        assert got[0] == want[0] and got[2] == want[2] and np.isnan(got[1])
        monkeypatch.setattr(biomechanics, "_deepest_penetration", lambda *args: None)
