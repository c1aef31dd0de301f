"""The compiled bone-length walk (motion._retarget_numba) gives the numpy path's numbers
bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.kernel.segments import compiled_module
from ltl_human_motion.motion import retarget
from ltl_human_motion.motion.skeleton import Skeleton


@pytest.mark.parametrize("rigid_hips", [True, False])
def test_compiled_enforce_bone_lengths_equals_numpy(monkeypatch, rigid_hips: bool) -> None:
    if compiled_module("ltl_human_motion.motion._retarget_numba") is None:
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(4)
    cases = []
    for trial in range(30):
        sk = Skeleton(float(rng.uniform(1.5, 2.0)))
        pos = sk.rest_positions()[None] + rng.normal(
            scale=[0.001, 0.03, 0.3][trial % 3], size=(int(rng.integers(1, 300)), 23, 3))
        if trial % 4 == 0:
            pos = np.round(pos, 2)                     # exact and signed zeros
        if trial % 5 == 0:
            pos[::3, 8] = pos[::3, 7]                  # degenerate source bones
        if trial % 7 == 0:
            pos = pos.astype(np.float32)
        cases.append((sk, pos))
    compiled = [retarget.enforce_bone_lengths(p, sk, rigid_hips) for sk, p in cases]
    monkeypatch.setattr(retarget, "_compiled_chain", lambda *args: None)
    for (sk, p), got in zip(cases, compiled):
        ref = retarget.enforce_bone_lengths(p, sk, rigid_hips)
        assert got.dtype == ref.dtype and got.shape == ref.shape
        assert got.tobytes() == ref.tobytes()
