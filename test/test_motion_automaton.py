"""Transition distance (closed form vs brute force), transitions, the motion automaton."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.sparse import csr_matrix

from ltl_human_motion.motion.automaton import (
    MotionAutomaton,
    align_windows,
    build_transitions,
    largest_scc,
    pair_distance,
    transition_distances,
    window_positions,
)
from ltl_human_motion.motion.types import MotionPrimitive


def _objective(params: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """The distance of the module docstring for one (theta, x0, y0), evaluated directly."""
    theta, x0, y0 = params
    c, s = np.cos(theta), np.sin(theta)
    moved = b.copy()
    moved[..., 0] = c * b[..., 0] - s * b[..., 1] + x0
    moved[..., 1] = s * b[..., 0] + c * b[..., 1] + y0
    per_frame = np.linalg.norm((a - moved).reshape(a.shape[0], -1), axis=1)   # ||.||_2 of 3m
    return float(np.sqrt(np.mean(per_frame ** 2)))


def _brute_force(a: np.ndarray, b: np.ndarray) -> float:
    best = np.inf
    for theta0 in np.linspace(-np.pi, np.pi, 13, endpoint=False):
        r = minimize(_objective, x0=[theta0, 0.0, 0.0], args=(a, b), method="Nelder-Mead",
                     options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 4000})
        best = min(best, r.fun)
    return best


@pytest.mark.parametrize("seed", range(6))
def test_closed_form_matches_brute_force(seed: int) -> None:
    rng = np.random.default_rng(seed)
    k, J = int(rng.integers(2, 7)), int(rng.integers(3, 24))
    a = rng.normal(size=(k, J, 3))
    b = rng.normal(size=(k, J, 3))
    d, theta, x0, y0 = align_windows(a, b)
    assert d == pytest.approx(_brute_force(a, b), rel=1e-6, abs=1e-9)
    assert d == pytest.approx(_objective(np.array([theta, x0, y0]), a, b), rel=1e-12)


def test_rigid_floor_motion_has_zero_distance() -> None:
    rng = np.random.default_rng(7)
    b = rng.normal(size=(5, 23, 3))
    theta, t = 0.83, np.array([1.5, -0.4])
    c, s = np.cos(theta), np.sin(theta)
    a = b.copy()
    a[..., 0] = c * b[..., 0] - s * b[..., 1] + t[0]
    a[..., 1] = s * b[..., 0] + c * b[..., 1] + t[1]
    d, th, x0, y0 = align_windows(a, b)
    assert d == pytest.approx(0.0, abs=1e-9)
    assert th == pytest.approx(theta)
    np.testing.assert_allclose([x0, y0], t, atol=1e-9)
    # a vertical shift is not removed by the alignment
    a[..., 2] += 0.1
    assert align_windows(a, b)[0] == pytest.approx(0.1 * np.sqrt(23), rel=1e-9)


def test_vectorized_distances_equal_pairwise() -> None:
    rng = np.random.default_rng(3)
    ends = rng.normal(size=(9, 4, 23, 3))
    starts = rng.normal(size=(7, 4, 23, 3))
    D = transition_distances(ends, starts, stature=1.6)
    loop = np.array([[pair_distance(e, s, stature=1.6) for s in starts] for e in ends])
    np.testing.assert_allclose(D, loop, rtol=1e-9, atol=1e-9)
    block = transition_distances(ends, starts, stature=1.6, rows=slice(2, 5))
    np.testing.assert_allclose(block, loop[2:5], rtol=1e-9)


def test_build_transitions_threshold_and_blocks() -> None:
    rng = np.random.default_rng(11)
    w = rng.normal(scale=0.05, size=(30, 3, 5, 3))
    D = transition_distances(w, w)
    delta = float(np.median(D))
    T = build_transitions(w, w, delta, block=7)
    dense = T.toarray()
    assert np.array_equal(dense > 0, D < delta)
    # A window's distance to itself is the closed form's rounding noise, about
    # sqrt(eps) * |w| (0 or 3e-9 by how the BLAS product of a block is summed).
    noise = 10 * np.sqrt(np.finfo(float).eps * np.max(np.sum(w.reshape(30, -1) ** 2, 1)))
    np.testing.assert_allclose(dense[D < delta], np.maximum(D[D < delta], 1e-12),
                               atol=noise)
    with pytest.raises(ValueError, match="delta must be positive"):
        build_transitions(w, w, 0.0)


def test_largest_scc() -> None:
    # 0 -> 1 -> 2 -> 0 is a cycle, 3 -> 4 -> 3 a smaller one, 5 only enters the big one
    edges = [(0, 1), (1, 2), (2, 0), (3, 4), (4, 3), (5, 0), (2, 3)]
    r, c = zip(*edges)
    A = csr_matrix((np.ones(len(edges)), (r, c)), shape=(6, 6))
    assert sorted(largest_scc(A).tolist()) == [0, 1, 2]
    assert sorted(largest_scc(A, np.array([3, 4, 5])).tolist()) == [3, 4]


def _prim(name: str, shift: float) -> MotionPrimitive:
    T = 8
    poses = np.zeros((T, 23, 3))
    poses[:, :, 2] = np.linspace(-0.9, 0.7, 23)
    poses[:, 5, 0] = shift + np.linspace(0, 0.1, T)
    root = np.zeros((T, 4))
    root[:, 0] = np.linspace(0, 0.2, T)
    root[:, 2] = 0.9
    return MotionPrimitive(name, "walk", poses, root, 120.0)


def test_motion_automaton_interface() -> None:
    prims = [_prim("a", 0.0), _prim("b", 0.0), _prim("c", 0.5)]
    ends = window_positions(prims, 3, end=True)
    starts = window_positions(prims, 3, end=False)
    assert ends.shape == (3, 3, 23, 3)
    T = build_transitions(ends, starts, delta=0.3)
    ma = MotionAutomaton(prims, T, initial=[0], delta=0.3, k_comp=3)
    assert ma.n_states == 3
    succ = ma.successors(0)
    assert succ.dtype.kind == "i" and np.all(np.diff(succ) > 0)
    assert set(succ.tolist()) == {0, 1}            # c's arm is 0.5 m off
    assert np.isinf(ma.distance(0, 2))
    assert ma.distance(0, 1) == pytest.approx(T[0, 1])
    assert ma.index("c") == 2
    with pytest.raises(ValueError, match="no primitive named"):
        ma.index("zzz")
    with pytest.raises(ValueError, match="state index"):
        ma.successors(3)
    g = ma.to_networkx()
    assert g.number_of_edges() == ma.n_transitions and g.nodes[0]["initial"]
