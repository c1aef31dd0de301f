"""Compiled loop of :func:`ltl_human_motion.motion.retarget.enforce_bone_lengths` (imported
on first use): the free bones' directions and the walk from the pelvis down the chain,
frame by frame in scalars, operation for operation as the numpy path computes them (the
same numbers; a test holds them together)."""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")


@_jit
def chain_positions(src, pelvis, free_j, free_p, free_len, rest_dir, rigid_j, rigid_bone,
                    parents, out) -> None:
    """out[t] (J, 3): pelvis[t], then each joint its parent plus its bone; a free joint
    free_j[m] (parent free_p[m]) gets length free_len[m] along its source bone in
    src[t] (T, J, 3) (rest_dir[m] where that is shorter than 1e-9), a rigid joint
    rigid_j[r] the bone rigid_bone[r, t] (3,)."""
    J = out.shape[1]
    bone = np.empty((J, 3))
    for t in range(src.shape[0]):
        for m in range(free_j.shape[0]):
            j, p = free_j[m], free_p[m]
            v0 = src[t, j, 0] - src[t, p, 0]
            v1 = src[t, j, 1] - src[t, p, 1]
            v2 = src[t, j, 2] - src[t, p, 2]
            norm = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
            if norm > 1e-9:
                bone[j, 0] = free_len[m] * (v0 / norm)
                bone[j, 1] = free_len[m] * (v1 / norm)
                bone[j, 2] = free_len[m] * (v2 / norm)
            else:
                bone[j, 0] = free_len[m] * rest_dir[m, 0]
                bone[j, 1] = free_len[m] * rest_dir[m, 1]
                bone[j, 2] = free_len[m] * rest_dir[m, 2]
        for r in range(rigid_j.shape[0]):
            for c in range(3):
                bone[rigid_j[r], c] = rigid_bone[r, t, c]
        for c in range(3):
            out[t, 0, c] = pelvis[t, c]
        for j in range(1, J):
            for c in range(3):
                out[t, j, c] = out[t, parents[j], c] + bone[j, c]
