"""Vectorized obstacle clearance (PartSet) against the per-part shape methods."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.scene import Box, Cylinder, Sphere, body_clearance, cell_by_name, collision
from ltl_human_motion.scene.cell import Obstacle
from ltl_human_motion.scene.clearance import PartSet, part_set
from ltl_human_motion.scene.geometry import box_gap, point_bounds, segment_aabb_distance
from ltl_human_motion.scene.occupancy import capsules_from_positions
from ltl_human_motion.scene.predicates import enter, object_clearance
from ltl_human_motion.scene.shapes import shape_distance

PARTS = (Box([1.2, -1.0, 0.825], [0.8, 1.2, 0.05]), Box([0.85, -1.55, 0.4], [0.06, 0.06, 0.8]),
         Box([0.3, 0.4, 0.5], [0.3, 0.2, 0.4], yaw=0.6), Cylinder([1.6, 1.4, 0.9], 0.05, 1.6),
         Sphere([-0.5, 0.5, 1.0], 0.2))


def _capsules(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    a = rng.uniform([-1.0, -2.0, 0.0], [2.0, 2.0, 2.0], (n, 3))
    b = a + rng.normal(scale=0.25, size=(n, 3))
    return np.stack([a, b], axis=-2), rng.uniform(0.03, 0.15, n)


@pytest.mark.parametrize("exact_below", [0.0, 0.01, 0.25, np.inf])
def test_part_set_matches_the_smallest_per_part_clearance(exact_below: float) -> None:
    seg, rad = _capsules(np.random.default_rng(1), 400)
    ps = PartSet(PARTS)
    got = ps.capsule_clearance(seg, rad, exact_below)
    ref = np.min([p.capsule_clearance(seg, rad, exact_below) for p in PARTS], axis=0)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12)
    exact = np.min([p.capsule_clearance(seg, rad, np.inf) for p in PARTS], axis=0)
    low = exact < exact_below
    np.testing.assert_allclose(got[low], exact[low], rtol=0, atol=1e-12)
    assert np.all(got <= exact + 1e-12)                     # a lower bound elsewhere
    assert np.all(got[~low] >= min(exact_below, 1e300) - 1e-12)


def test_body_clearance_is_exact_below_the_limit_and_a_bound_above() -> None:
    rng = np.random.default_rng(2)
    rest = Skeleton().rest_positions()
    frames = rest[None] + rng.uniform([-1, -2, 0], [2, 2, 0.3], (60, 1, 3))
    frames = frames + rng.normal(scale=0.03, size=frames.shape)
    seg, rad = capsules_from_positions(frames)
    ps = PartSet(PARTS)
    exact = ps.capsule_clearance(seg, rad, np.inf).min(axis=-1)
    for limit in (0.0, 0.05, 0.25):
        got = ps.body_clearance(seg, rad, limit)
        low = exact < limit
        np.testing.assert_allclose(got[low], exact[low], rtol=0, atol=1e-12)
        assert np.all(got <= exact + 1e-12)
        assert np.all(got[~low] >= limit - 1e-12)
        # With the joints' box given, the same answers.
        np.testing.assert_array_equal(
            ps.body_clearance(seg, rad, limit, bounds=point_bounds(frames)) < limit, low)


def test_collision_and_enter_agree_with_exact_clearances() -> None:
    cell = cell_by_name("paper_cell")
    rest = Skeleton().rest_positions()
    xs = np.linspace(0.2, 1.0, 33)
    frames = rest[None] + np.stack([np.array([x, -1.0, 0.0]) for x in xs])[:, None]
    seg, rad = capsules_from_positions(frames)
    exact = np.min([p.capsule_clearance(seg, rad, np.inf) for ob in cell.obstacles
                    for p in ob.parts], axis=0).min(axis=-1)
    for margin in (0.0, 0.02, 0.3):
        np.testing.assert_array_equal(collision(frames, cell, margin=margin), exact <= margin)
    clear = body_clearance(frames, cell)
    near = exact < 0.25
    np.testing.assert_allclose(clear[near], exact[near], rtol=0, atol=1e-12)
    region = cell.region("R1")
    region_exact = region.shape.capsule_clearance(seg, rad, np.inf).min(axis=-1)
    for margin in (0.0, 0.1, 0.5):
        np.testing.assert_array_equal(enter(frames, region, margin=margin),
                                      region_exact <= margin)


def test_object_clearance_matches_shape_distance() -> None:
    cell = cell_by_name("paper_cell")
    rng = np.random.default_rng(3)
    traj = rng.uniform([0.5, -1.8, 0.0], [1.8, 1.8, 1.8], (80, 3))
    traj[5] = np.nan
    got = object_clearance(cell, "O1", traj)
    obj = cell.object("O1")
    parts = [p for ob in cell.obstacles for p in ob.parts]
    for t in range(len(traj)):
        if not np.all(np.isfinite(traj[t])):
            assert np.isinf(got[t])
            continue
        ref = min(shape_distance(obj.occupancy_at(traj[t]), p) for p in parts)
        if ref <= 0.5:                       # exact up to 0.5 m, a lower bound beyond
            assert got[t] == pytest.approx(ref, abs=1e-9)
        else:
            assert got[t] <= ref + 1e-9


def test_part_sets_are_shared_by_cells_with_the_same_obstacles() -> None:
    cell = cell_by_name("paper_cell")
    assert part_set(cell.obstacles) is part_set(cell.obstacles)
    assert cell.part_set is part_set(cell.obstacles)
    other = (Obstacle("o", PARTS[:2]),)
    assert len(part_set(other)) == 2
    empty = PartSet(())
    seg, rad = _capsules(np.random.default_rng(0), 3)
    assert np.all(np.isinf(empty.capsule_clearance(seg, rad)))


def test_helpers_match_their_references() -> None:
    rng = np.random.default_rng(4)
    lo_a, lo_b = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    hi_a, hi_b = lo_a + rng.uniform(0, 1, (50, 3)), lo_b + rng.uniform(0, 1, (50, 3))
    gap = np.maximum(np.maximum(lo_b - hi_a, lo_a - hi_b), 0.0)
    np.testing.assert_array_equal(box_gap(lo_a, hi_a, lo_b, hi_b), np.linalg.norm(gap, axis=-1))
    pts = rng.normal(size=(7, 11, 3))
    lo, hi = point_bounds(pts)
    np.testing.assert_array_equal(lo, pts.min(axis=1))
    np.testing.assert_array_equal(hi, pts.max(axis=1))
    # Per-segment boxes give what one call per box gives.
    a, b = rng.normal(size=(30, 3)), rng.normal(size=(30, 3))
    per = segment_aabb_distance(a, b, lo_a[:30], hi_a[:30])
    one = [segment_aabb_distance(a[i:i + 1], b[i:i + 1], lo_a[i], hi_a[i])[0] for i in range(30)]
    np.testing.assert_array_equal(per, one)


@pytest.mark.parametrize("boxes_only", [False, True])
@pytest.mark.parametrize("exact_below", [float(np.nextafter(0.0, 1.0)), 0.05, 0.4, np.inf])
def test_body_clearance_compiled_bounds_equal_the_numpy_ones(exact_below, boxes_only,
                                                            monkeypatch) -> None:
    """Bit for bit, also where every part is an axis-aligned box (one compiled pass); the
    capsule-by-part clearances too."""
    from ltl_human_motion.scene import clearance

    if clearance._compiled_bounds() is None:
        pytest.skip("numba is not in use")
    rng = np.random.default_rng(4)
    rest = Skeleton().rest_positions()
    where = rng.uniform([-0.5, -2.0, 0.0], [2.0, 2.0, 0.0], (300, 1, 3))
    poses = rest[None] + where + rng.normal(scale=0.05, size=(300, *rest.shape))
    seg, rad = capsules_from_positions(poses, 1.75)
    boxes = PARTS[:2] + (Box([0.0, 0.0, 1.0], [0.2, 0.2, 0.2]),
                         Box([1.0, 1.0, 0.3], [0.5, 0.3, 0.6]),
                         Box([-0.3, -1.0, 1.2], [0.4, 0.4, 0.1]))
    ps = PartSet(boxes if boxes_only else PARTS)
    assert ps.is_box.all() == boxes_only
    fast = ps.body_clearance(seg, rad, exact_below)
    fast_bounded = ps.body_clearance(seg, rad, exact_below, bounds=point_bounds(poses))
    fast_pairs = ps.pair_clearance(seg.reshape(-1, 2, 3), np.tile(rad, len(poses)),
                                   exact_below)
    monkeypatch.setattr(clearance, "_compiled_bounds", lambda: None)
    slow = ps.body_clearance(seg, rad, exact_below)
    # Bit for bit: the same bounds, the same exact values of the same pairs.
    assert fast.tobytes() == slow.tobytes()
    assert fast_pairs.tobytes() == ps.pair_clearance(seg.reshape(-1, 2, 3),
                                                     np.tile(rad, len(poses)),
                                                     exact_below).tobytes()
    assert fast_bounded.tobytes() == ps.body_clearance(seg, rad, exact_below,
                                                      bounds=point_bounds(poses)).tobytes()
    assert np.any(slow < min(exact_below, 0.4)) and np.any(slow >= 0.05)


def test_compiled_segment_box_distance_equals_the_closed_form() -> None:
    """The compiled exact distance gives the numpy closed form's numbers bit for bit,
    also for segments parallel to a face, for points (zero length) and for segments that
    start on a face plane."""
    from ltl_human_motion.scene import clearance

    nb = clearance._compiled_bounds()
    if nb is None:
        pytest.skip("numba is not in use")
    rng = np.random.default_rng(6)
    n = 20000
    a = rng.normal(scale=0.5, size=(n, 3))
    b = a + rng.normal(scale=0.3, size=(n, 3))
    b[:500, 0] = a[:500, 0]
    b[500:1000, 1:] = a[500:1000, 1:]
    b[1000:1500] = a[1000:1500]
    half = np.abs(rng.normal(scale=0.3, size=(n, 3))) + 0.01
    # Ends on a face plane, going either way (crossings at +0 and -0, tied with t = 0).
    a[1500:2000, 0] = half[1500:2000, 0]
    a[2000:2500, 2] = -half[2000:2500, 2]
    b[2000:2500, 2] = a[2000:2500, 2] + rng.choice([-0.2, 0.2], 500)
    got = np.empty(n)
    nb.segment_aabb_distance(a, b, -half, half, got)
    want = segment_aabb_distance(a, b, -half, half)
    assert got.tobytes() == want.tobytes()
    assert np.any(want == 0.0) and np.any(want > 0.1)


def test_box_segment_distance_compiled_equals_the_closed_form() -> None:
    """A box's segment distance (the verifier's region checks) takes the compiled closed
    form where it is in use: the numpy closed form's numbers, bit for bit, in the shape
    of the segments given."""
    box = Box([0.4, -0.2, 0.9], [0.5, 0.3, 0.2], yaw=0.7)
    rng = np.random.default_rng(8)
    a = rng.normal(scale=0.6, size=(40, 7, 3)) + box.center
    b = a + rng.normal(scale=0.2, size=a.shape)
    got = box.segment_distance(a, b)
    want = segment_aabb_distance(box.to_local(a), box.to_local(b), -box.half, box.half)
    assert got.shape == (40, 7)
    assert got.tobytes() == want.tobytes()
    assert np.any(want == 0.0) and np.any(want > 0.1)
    assert box.segment_distance(a[0, 0], b[0, 0]).shape == ()
