"""The compiled two-bone IK (motion._ik_numba) gives the numpy path's numbers bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.kernel.segments import compiled_module
from ltl_human_motion.motion import ik


def _numpy_two_bone(base, target, l1, l2, pole, max_stretch=0.999, max_flexion=None):
    """The numpy path of :func:`ik.two_bone_ik` (its arithmetic, line for line)."""
    base, target, pole = (np.asarray(x, dtype=np.float64) for x in (base, target, pole))
    v = target - base
    dist = np.linalg.norm(v, axis=-1, keepdims=True)
    u = v / np.maximum(dist, 1e-9)
    dmin = abs(l1 - l2) + 1e-6
    if max_flexion is not None:
        dmin = max(dmin, float(np.sqrt(l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * np.cos(max_flexion))))
    d = np.clip(dist, dmin, max_stretch * (l1 + l2))
    end = base + u * d
    a = (l1 * l1 - l2 * l2 + d * d) / (2 * d)
    h = np.sqrt(np.maximum(l1 * l1 - a * a, 0.0))
    p = pole - np.sum(pole * u, axis=-1, keepdims=True) * u
    pn = np.linalg.norm(p, axis=-1, keepdims=True)
    alt = np.cross(u, np.array([0.0, 1.0, 0.0]))
    p = np.where(pn > 1e-9, p / np.maximum(pn, 1e-12),
                 alt / np.maximum(np.linalg.norm(alt, axis=-1, keepdims=True), 1e-12))
    return base + u * a + p * h, end


def test_compiled_two_bone_ik_equals_numpy() -> None:
    if compiled_module("ltl_human_motion.motion._ik_numba") is None:
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(1)
    for trial in range(200):
        n = int(rng.integers(1, 200))
        scale = [1e-3, 0.1, 1.0, 10.0][trial % 4]
        base, target = rng.normal(size=(2, n, 3)) * scale
        pole = rng.normal(size=(n, 3))
        if trial % 3 == 0:                          # exact and signed zeros
            base, target, pole = np.round(base, 1), np.round(target, 1), np.round(pole)
        if trial % 5 == 0:                          # poles along the chain, or none
            pole = 2.0 * (target - base)
            pole[::2] = 0.0
        if trial % 7 == 0:                          # targets at the base
            target[::3] = base[::3]
        if trial % 4 == 1:
            pole = pole[0]                          # broadcast
        elif trial % 4 == 2:
            base = base[0]
        l1, l2 = (float(x) for x in rng.uniform(0.05, 0.5, size=2))
        kw = {"max_stretch": 1.0} if trial % 2 else {}
        if trial % 6 == 1:
            kw["max_flexion"] = 2.5
        middle, end = ik.two_bone_ik(base, target, l1, l2, pole, **kw)
        ref_middle, ref_end = _numpy_two_bone(base, target, l1, l2, pole, **kw)
        assert middle.shape == ref_middle.shape and end.shape == ref_end.shape
        assert middle.tobytes() == ref_middle.tobytes() and end.tobytes() == ref_end.tobytes()


def test_two_bone_ik_single_chain_and_fallbacks() -> None:
    """One chain (3,) keeps its shape; float32 bone lengths and non-finite points take the
    numpy path (the same function, NaN where the input is)."""
    middle, end = ik.two_bone_ik(np.zeros(3), [0.3, 0.1, -0.5], 0.4, 0.4, [1.0, 0.0, 0.0])
    assert middle.shape == (3,) and end.shape == (3,)
    np.testing.assert_allclose(np.linalg.norm(middle), 0.4)
    np.testing.assert_allclose(np.linalg.norm(end - middle), 0.4)
    m32, _ = ik.two_bone_ik(np.zeros(3), [0.3, 0.1, -0.5], np.float32(0.4), np.float32(0.4),
                            [1.0, 0.0, 0.0])
    np.testing.assert_allclose(m32, middle, atol=1e-6)
    m_nan, _ = ik.two_bone_ik(np.zeros((2, 3)), [[np.nan, 0.0, 0.0], [0.3, 0.1, -0.5]],
                              0.4, 0.4, [1.0, 0.0, 0.0])
    assert np.isnan(m_nan[0]).all() and m_nan[1].tobytes() == middle.tobytes()
