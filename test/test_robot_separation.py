"""Capsule separation against a brute-force reference, and ISO/TS 15066 SSM."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from ltl_human_motion.robot import (
    SLIDER_MIN,
    SSMParameters,
    check_capsules,
    min_distance,
    pair_distances,
    predictive_separation,
    segment_distances,
    separation,
    signed_distances,
    slider_from_separation,
)


def _point_segment(points: np.ndarray, seg: np.ndarray) -> np.ndarray:
    d = seg[1] - seg[0]
    dd = float(d @ d)
    t = np.zeros(len(points)) if dd == 0 else np.clip((points - seg[0]) @ d / dd, 0, 1)
    return np.linalg.norm(points - (seg[0] + t[:, None] * d), axis=1)


def brute_force(P: np.ndarray, Q: np.ndarray, n: int = 2001) -> np.ndarray:
    """Distances between segments from dense samples of each against the other segment
    (an upper bound of the exact distance, within half a sampling step)."""
    u = np.linspace(0.0, 1.0, n)[:, None]
    out = np.empty((len(P), len(Q)))
    for i, p in enumerate(P):
        a = p[0] + u * (p[1] - p[0])
        for j, q in enumerate(Q):
            b = q[0] + u * (q[1] - q[0])
            out[i, j] = min(_point_segment(a, q).min(), _point_segment(b, p).min())
    return out


def random_segments(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    P = rng.normal(size=(9, 2, 3))
    Q = rng.normal(size=(6, 2, 3))
    P[0, 1] = P[0, 0]                                  # a point
    Q[1, 1] = Q[1, 0]                                  # a point
    P[1] = Q[1]                                        # point against point
    Q[2] = P[2] + np.array([0.05, 0.02, 0])                # parallel, overlapping
    Q[3] = P[3][::-1] + np.array([0, 0.3, 0])           # antiparallel
    Q[4, 1] = Q[4, 0] + 3.0 * (P[4, 1] - P[4, 0])      # parallel, different length
    P[5] = Q[5]                                        # identical
    return P, Q


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_segment_distances_match_brute_force(seed: int) -> None:
    rng = np.random.default_rng(seed)
    P, Q = random_segments(rng)
    exact = segment_distances(P, Q)
    ref = brute_force(P, Q)
    step = np.linalg.norm(P[:, 1] - P[:, 0], axis=1)[:, None] \
        + np.linalg.norm(Q[:, 1] - Q[:, 0], axis=1)[None, :]
    assert np.all(exact <= ref + 1e-9)                 # exact is never above the samples
    assert np.all(ref - exact <= step / 2000 + 1e-9)   # and within the sampling step


def test_capsule_separation_and_closest_pair() -> None:
    rng = np.random.default_rng(7)
    hs = rng.uniform(-1, 1, size=(17, 2, 3))
    hr = rng.uniform(0.03, 0.12, 17)
    rs = rng.uniform(-1, 1, size=(7, 2, 3)) + np.array([1.5, 0, 0])
    rr = rng.uniform(0.04, 0.08, 7)
    d = pair_distances(hs, hr, rs, rr)
    ref = brute_force(hs, rs) - hr[:, None] - rr[None, :]
    assert d.shape == (17, 7)
    assert np.allclose(d, ref, atol=3e-3)
    res = separation(hs, hr, rs, rr)
    assert res.distance == pytest.approx(d.min())
    assert d[res.human_index, res.robot_index] == res.distance
    assert min_distance(hs, hr, rs, rr) == pytest.approx(res.distance)
    assert min_distance(hs, hr, rs, rr, validate=False) == pytest.approx(res.distance)


def test_overlapping_capsules_are_negative() -> None:
    seg = np.array([[[0, 0, 0], [1, 0, 0]]], dtype=float)
    other = np.array([[[0.5, 0.1, -1], [0.5, 0.1, 1]]], dtype=float)
    assert min_distance(seg, [0.1], other, [0.05]) == pytest.approx(0.1 - 0.15)


@pytest.mark.parametrize(("segments", "radii", "match"), [
    (np.full((2, 2, 3), np.nan), [0.1, 0.1], "NaN"),
    (np.zeros((2, 2, 3)), [0.1, -0.1], "radii"),
    (np.zeros((2, 3, 3)), [0.1, 0.1], "shape"),
    (np.zeros((2, 2, 3)), [0.1], "radii must have shape"),
    (np.full((1, 2, 3), 1e6), [0.1], "coordinates"),
    (np.zeros((0, 2, 3)), np.zeros(0), "K >= 1"),
    ([["a"]], [0.1], "numeric"),
])
def test_bad_capsules_raise(segments: object, radii: object, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        check_capsules(segments, radii)
    with pytest.raises(ValueError, match=match):
        min_distance(segments, radii, np.zeros((1, 2, 3)), [0.1])


def test_protective_distance_sums_the_iso_terms() -> None:
    p = SSMParameters(human_speed=1.6, robot_speed=1.0, reaction_time=0.1, stopping_time=0.3,
                      stopping_distance=0.15, intrusion_distance=0.1, sensor_uncertainty=0.05,
                      robot_uncertainty=0.02)
    expected = 1.6 * 0.4 + 1.0 * 0.1 + 0.15 + 0.1 + 0.05 + 0.02
    assert p.protective_distance == pytest.approx(expected)
    assert p.terms()["S_p"] == pytest.approx(expected)
    assert sum(v for k, v in p.terms().items() if k != "S_p") == pytest.approx(expected)


def test_slider_mapping_band_and_minimum() -> None:
    p = SSMParameters(margin=0.5)
    sp = p.protective_distance
    assert slider_from_separation(sp + 0.6, p) == 1.0
    assert slider_from_separation(sp + 0.5, p) == 1.0
    assert slider_from_separation(sp, p) == SLIDER_MIN
    assert slider_from_separation(-1.0, p) == SLIDER_MIN
    assert slider_from_separation(float("nan"), p) == SLIDER_MIN
    mid = slider_from_separation(sp + 0.25, p)
    assert mid == pytest.approx(SLIDER_MIN + 0.5 * (1 - SLIDER_MIN))
    xs = np.linspace(sp - 0.2, sp + 0.8, 101)
    ys = [slider_from_separation(x, p) for x in xs]
    assert np.all(np.diff(ys) >= 0) and min(ys) >= SLIDER_MIN


@pytest.mark.parametrize("kwargs", [{"min_slider": 0.0}, {"human_speed": -1.0},
                                    {"margin": 0.0}, {"reaction_time": float("nan")}])
def test_ssm_parameters_are_validated(kwargs: dict) -> None:
    with pytest.raises(ValueError, match="SSMParameters"):
        SSMParameters(**kwargs)


def test_predictive_separation_discounts_by_time() -> None:
    p = SSMParameters(prediction_discount_speed=0.5)
    assert predictive_separation(2.0, [1.0, 0.4], [0.5, 1.0], p) == pytest.approx(0.9)
    assert predictive_separation(0.3, [1.0], [0.5], p) == pytest.approx(0.3)
    assert predictive_separation(0.3, [], [], p) == pytest.approx(0.3)
    with pytest.raises(ValueError, match="equal length"):
        predictive_separation(1.0, [1.0, 2.0], [0.1], p)


coords = arrays(np.float64, (4, 2, 3), elements=st.floats(-2.0, 2.0, allow_nan=False))


@settings(max_examples=200, deadline=None)
@given(P=coords, Q=coords, angle=st.floats(-np.pi, np.pi), shift=st.floats(-3.0, 3.0))
def test_segment_distance_properties(P: np.ndarray, Q: np.ndarray, angle: float,
                                     shift: float) -> None:
    d = segment_distances(P, Q)
    assert np.all(d >= 0)
    assert np.allclose(d, segment_distances(Q, P).T, atol=1e-6)          # symmetric
    ends = np.linalg.norm(P[:, None, :, None] - Q[None, :, None, :], axis=-1)
    assert np.all(d <= ends.min(axis=(2, 3)) + 1e-9)                     # <= endpoint gaps
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    moved = segment_distances(P @ R.T + shift, Q @ R.T + shift)
    assert np.allclose(d, moved, atol=1e-6)                              # rigid invariance


def test_nearly_parallel_segments_sharing_an_end_point_touch() -> None:
    """Found by hypothesis: rounding of nearly parallel pairs once gave 6e-5 m, not 0."""
    e = 6.10351562e-05
    P = np.array([[[0.0, e, e], [e, 7.86905002e-01, e]]])
    Q = np.array([[[0.0, 0.0, e], [e, 7.86905002e-01, e]]])
    assert segment_distances(P, Q)[0, 0] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_signed_distances_are_exact_at_the_minimum_overall_and_per_group(seed: int) -> None:
    """The control loop's fast path: never below the exact values, and equal to them at
    the minimum (overall and per group of rows), nearly parallel pairs included."""
    rng = np.random.default_rng(seed)
    P, Q = random_segments(rng)
    e = 6.10351562e-05                      # the nearly parallel pair hypothesis found
    P = np.concatenate([P, [[[0.0, e, e], [e, 7.86905002e-01, e]]]])
    Q = np.concatenate([Q, [[[0.0, 0.0, e], [e, 7.86905002e-01, e]]]])
    pr, qr = rng.uniform(0.0, 0.1, len(P)), rng.uniform(0.0, 0.1, len(Q))
    exact = segment_distances(P, Q) - pr[:, None] - qr[None, :]
    fast = signed_distances(P, pr, Q, qr)
    assert np.all(fast >= exact - 1e-12)
    assert fast.min() == pytest.approx(exact.min(), abs=1e-12)
    groups = np.array([0, 3, 7])
    grouped = signed_distances(P, pr, Q, qr, row_groups=groups)
    assert np.allclose(np.minimum.reduceat(grouped.min(axis=1), groups),
                       np.minimum.reduceat(exact.min(axis=1), groups), atol=1e-12)
