"""The shared segment kernel: compiled and numpy paths agree, exact for parallel segments,
and importing the core does not import numba."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from ltl_human_motion.kernel import segments
from ltl_human_motion.kernel.segments import (
    check_capsules,
    compiled,
    group_min_signed_distances,
    min_signed_distance,
    segment_distances,
    segment_segment_distance,
    signed_distances,
)
from ltl_human_motion.scene import capsule_capsule_distance
from ltl_human_motion.scene import segment_segment_distance as scene_distance

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(not compiled(), reason="numba is a pinned dependency")


@contextlib.contextmanager
def numpy_path() -> Iterator[None]:
    """Run the kernel's numpy fallback (as without numba) inside the block."""
    saved = segments._compiled
    segments._compiled = lambda: None   # type: ignore[assignment]
    try:
        yield
    finally:
        segments._compiled = saved      # type: ignore[assignment]


def both(fn, *args):
    """``fn(*args)`` on the compiled path and on the numpy path."""
    out = fn(*args)
    with numpy_path():
        return out, fn(*args)


coords = arrays(np.float64, (5, 2, 3), elements=st.floats(-2.0, 2.0, allow_nan=False))
radii = arrays(np.float64, (5,), elements=st.floats(0.0, 0.2, allow_nan=False))


@settings(max_examples=200, deadline=None)
@given(P=coords, Q=coords, pr=radii, qr=radii, parallel=st.booleans())
def test_compiled_and_numpy_paths_agree(P, Q, pr, qr, parallel) -> None:
    if parallel:   # make every pair nearly parallel: the refined branch of both paths
        Q = P[:, None, 0] + 0.3 + np.stack([np.zeros_like(P[:, 0]), P[:, 1] - P[:, 0]], 1)
    fast, slow = both(segment_distances, P, Q)
    np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-9)
    for fn, args in ((min_signed_distance, (P, pr, Q, qr)),
                     (group_min_signed_distances, (P, pr, Q, qr, [0, 2, 3]))):
        fast, slow = both(fn, *args)
        np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-9)
    exact = fast_matrix = signed_distances(P, pr, Q, qr)
    np.testing.assert_allclose(fast_matrix, segment_distances(P, Q) - pr[:, None] - qr,
                               atol=1e-12)
    assert min_signed_distance(P, pr, Q, qr) == pytest.approx(exact.min(), abs=1e-12)
    el_fast, el_slow = both(segment_segment_distance, P[:, 0], P[:, 1], Q[:, 0], Q[:, 1])
    np.testing.assert_allclose(el_fast, el_slow, atol=1e-9)
    np.testing.assert_allclose(el_fast, np.diag(segment_distances(P, Q)), atol=1e-12)


PARALLEL_CASES = [
    # (p0, p1, q0, q1, exact distance)
    ([0, 0, 0], [1, 0, 0], [0.5, 0, 0], [2, 0, 0], 0.0),           # collinear, overlapping
    ([0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0], 0.0),             # collinear, touching
    ([0, 0, 0], [1, 0, 0], [3, 0, 0], [2, 0, 0], 1.0),             # collinear, apart
    ([0, 0, 0], [1, 0, 0], [0.2, 0.3, 0], [0.7, 0.3, 0], 0.3),     # parallel, side by side
    ([0.1, 0.2, 0.3], [1.3, -0.4, 2.2], [1.3, -0.4, 2.2], [2.5, -1.0, 4.1], 0.0),
    ([0.0, 6.10351562e-05, 6.10351562e-05], [6.10351562e-05, 0.786905002, 6.10351562e-05],
     [0.0, 0.0, 6.10351562e-05], [6.10351562e-05, 0.786905002, 6.10351562e-05], 0.0),
]


@pytest.mark.parametrize("p0, p1, q0, q1, expected", PARALLEL_CASES)
def test_scene_and_robot_share_the_exact_kernel_for_parallel_segments(p0, p1, q0, q1,
                                                                       expected) -> None:
    """The old scene formula gave 4.7e-9 m for touching collinear segments; now scene,
    robot and both paths give the exact value."""
    P, Q = np.array([[p0, p1]], float), np.array([[q0, q1]], float)
    fast, slow = both(scene_distance, p0, p1, q0, q1)
    assert float(fast) == pytest.approx(expected, abs=1e-12)
    assert float(slow) == pytest.approx(expected, abs=1e-12)
    fast, slow = both(segment_distances, P, Q)
    assert fast[0, 0] == pytest.approx(expected, abs=1e-12)
    assert slow[0, 0] == pytest.approx(expected, abs=1e-12)
    assert capsule_capsule_distance(P[0], 0.1, Q[0], 0.2) == pytest.approx(expected - 0.3,
                                                                           abs=1e-12)


def test_elementwise_broadcasts_and_checks_shapes() -> None:
    rng = np.random.default_rng(3)
    p0, p1 = rng.normal(size=(2, 4, 1, 3))
    q0, q1 = rng.normal(size=(2, 6, 3))
    d = segment_segment_distance(p0, p1, q0, q1)
    assert d.shape == (4, 6)
    np.testing.assert_allclose(d, segment_distances(np.stack([p0[:, 0], p1[:, 0]], 1),
                                                    np.stack([q0, q1], 1)), atol=1e-12)
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        segment_segment_distance(np.zeros(2), np.ones(2), np.zeros(2), np.ones(2))


@pytest.mark.parametrize("bad, match", [
    (np.full((2, 2, 3), np.nan), "NaN"),
    (np.full((2, 2, 3), 2e3), "coordinates beyond"),
])
def test_check_capsules_rejects_nonsense_on_both_paths(bad, match) -> None:
    for path in (contextlib.nullcontext, numpy_path):
        with path():
            with pytest.raises(ValueError, match=match):
                check_capsules(bad, [0.1, 0.1])
            with pytest.raises(ValueError, match=r"radii must be in"):
                check_capsules(np.zeros((2, 2, 3)), [0.1, -1.0])


def test_core_imports_without_numba_and_the_switch_turns_it_off() -> None:
    code = ("import sys\n"
            "import ltl_human_motion.scene, ltl_human_motion.robot, ltl_human_motion.planning\n"
            "import ltl_human_motion.motion\n"
            "assert 'numba' not in sys.modules, 'numba imported at start-up'\n"
            "from ltl_human_motion.kernel.segments import compiled, min_signed_distance\n"
            "import numpy as np\n"
            "assert not compiled()\n"
            "s = np.array([[[0, 0, 0], [1, 0, 0]]], float)\n"
            "print(min_signed_distance(s, [0.1], s + [0, 1, 0], [0.2]))\n"
            "assert 'numba' not in sys.modules\n")
    env = dict(os.environ, LTL_HUMAN_MOTION_NUMBA="0")
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert float(proc.stdout) == pytest.approx(0.7)


def test_read_only_inputs_use_the_compiled_signature() -> None:
    seg = np.broadcast_to(np.array([[0.0, 0, 0], [1, 0, 0]]), (3, 2, 2, 3))[0]
    rad = np.broadcast_to(np.array([0.1]), (2,))
    assert not seg.flags.writeable and not rad.flags.writeable
    checked, radii = check_capsules(seg, rad)
    assert checked.flags.writeable and radii.flags.writeable
    before = {name: len(getattr(segments._compiled(), name).signatures)
              for name in ("group_min_signed", "bounded")}
    assert min_signed_distance(seg, rad, seg + np.array([0, 1.0, 0]), rad) == \
        pytest.approx(0.8)
    after = {name: len(getattr(segments._compiled(), name).signatures) for name in before}
    assert after == before, "a read-only input compiled a new specialization"


def test_joint_segment_distances_are_the_pair_kernels() -> None:
    rng = np.random.default_rng(11)
    X = rng.normal(size=(30, 9, 3))
    X[:10, 3] = X[:10, 2]                                # point segments
    X[10:20, 5] = X[10:20, 4] + 0.5 * (X[10:20, 1] - X[10:20, 0])   # parallel pairs
    ends_a = np.array([[0, 1], [2, 3], [4, 5], [2, 3], [7, 8]])
    ends_b = np.array([[4, 5], [6, 7], [0, 1], [2, 3], [8, 7]])
    want = segment_segment_distance(X[:, ends_a[:, 0]], X[:, ends_a[:, 1]],
                                    X[:, ends_b[:, 0]], X[:, ends_b[:, 1]])
    fast, slow = both(segments.joint_segment_distances, X, ends_a, ends_b)
    assert fast.shape == (30, 5)
    # The same pair kernel on the same end points: bit for bit on each path.
    assert np.array_equal(fast, want)
    with numpy_path():
        assert np.array_equal(slow, segment_segment_distance(
            X[:, ends_a[:, 0]], X[:, ends_a[:, 1]], X[:, ends_b[:, 0]], X[:, ends_b[:, 1]]))
    assert np.allclose(fast, slow, atol=1e-12, rtol=0)
    with pytest.raises(ValueError, match="joint segments"):
        segments.joint_segment_distances(X[0], ends_a, ends_b)
    with pytest.raises(ValueError, match="beyond"):
        segments.joint_segment_distances(X, ends_a, ends_b + 9)
