"""Distance helpers, shapes and frame conversions against brute-force references."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ltl_human_motion.scene import (
    Box,
    Cylinder,
    MeshShape,
    Sphere,
    capsule_capsule_distance,
    extents_zup_from_yup,
    point_box_distance,
    point_segment_distance,
    segment_box_distance,
    segment_segment_distance,
    shape_distance,
    shape_enclosed_in,
    shapes_intersect,
    yup_from_zup,
    zup_from_yup,
)
from ltl_human_motion.scene.geometry import (
    min_along_segment,
    point_box_signed_distance,
    point_polygon_signed_distance,
)

T = np.linspace(0.0, 1.0, 4001)


def _sample(a, b, t=T):
    return a[..., None, :] + t[:, None] * (b - a)[..., None, :]


def test_frames_convert_the_paper_points():
    paper = np.array([[-1.0, 0.2, 1.0], [-1.5, 0.3, -1.2]])
    np.testing.assert_allclose(zup_from_yup(paper), [[-1.0, -1.0, 0.2], [-1.5, 1.2, 0.3]])
    rng = np.random.default_rng(0)
    p = rng.normal(size=(5, 4, 3))
    np.testing.assert_allclose(yup_from_zup(zup_from_yup(p)), p)
    # A proper rotation: lengths and handedness are kept.
    e = np.eye(3)
    z = zup_from_yup(e)
    np.testing.assert_allclose(np.cross(z[0], z[1]), z[2])
    np.testing.assert_allclose(z[1], [0.0, 0.0, 1.0])          # paper up -> our up
    np.testing.assert_allclose(extents_zup_from_yup([1.0, 2.0, 3.0]), [1.0, 3.0, 2.0])
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        zup_from_yup(np.zeros((3, 2)))


def test_segment_segment_distance_matches_sampling():
    rng = np.random.default_rng(1)
    p0, p1, q0, q1 = rng.normal(size=(4, 300, 3))
    d = segment_segment_distance(p0, p1, q0, q1)
    qs = _sample(q0, q1, np.linspace(0, 1, 801))
    ref = np.min(point_segment_distance(qs, p0[:, None], p1[:, None]), axis=1)
    assert np.all(d <= ref + 1e-12)
    np.testing.assert_allclose(d, ref, atol=5e-3)
    # Degenerate and parallel cases.
    a = np.zeros(3)
    assert segment_segment_distance(a, a, [1, 0, 0], [1, 0, 0]) == pytest.approx(1.0)
    assert segment_segment_distance([0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]) == \
        pytest.approx(1.0)
    assert segment_segment_distance([0, 0, 0], [1, 0, 0], [2, 1, 0], [3, 1, 0]) == \
        pytest.approx(np.sqrt(2.0))
    assert capsule_capsule_distance(np.array([[0, 0, 0], [1, 0, 0]]), 0.2,
                                    np.array([[0, 1, 0], [1, 1, 0]]), 0.3) == pytest.approx(0.5)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-2.0, 2.0), min_size=6, max_size=6))
def test_segment_box_distance_is_the_minimum_along_the_segment(coords):
    a, b = np.array(coords[:3]), np.array(coords[3:])
    lo, hi = np.array([-0.3, -0.2, 0.0]), np.array([0.4, 0.5, 0.6])
    d = segment_box_distance(a, b, lo, hi)
    ref = point_box_distance(_sample(a, b), lo, hi).min()
    assert d <= ref + 1e-9
    assert d >= ref - np.linalg.norm(b - a) / len(T) - 1e-9


def test_golden_section_handles_flat_minima_and_endpoints():
    lo, hi = np.zeros(3), np.ones(3)
    # Segment through the box: the minimum (0) is a whole interval.
    assert segment_box_distance([-1, 0.5, 0.5], [2, 0.5, 0.5], lo, hi) == 0.0
    # Minimum at an end point.
    assert segment_box_distance([2, 0.5, 0.5], [3, 0.5, 0.5], lo, hi) == pytest.approx(1.0)
    f = min_along_segment(lambda p: np.abs(p[..., 0] - 0.3), np.zeros((4, 1)), np.ones((4, 1)))
    np.testing.assert_allclose(f, 0.0, atol=1e-8)


def test_signed_distances_of_primitives():
    box = Box([0.0, 0.0, 0.5], [1.0, 2.0, 1.0])
    pts = np.array([[0.0, 0.0, 0.5], [0.0, 0.0, 2.0], [1.5, 0.0, 0.5], [0.4, 0.0, 0.5]])
    np.testing.assert_allclose(box.signed_distance(pts), [-0.5, 1.0, 1.0, -0.1])
    np.testing.assert_allclose(point_box_signed_distance(pts, box.aabb()[0], box.aabb()[1]),
                               box.signed_distance(pts))
    cyl = Cylinder([0.0, 0.0, 1.0], 0.5, 1.0)
    np.testing.assert_allclose(cyl.signed_distance(np.array([[0, 0, 1.0], [1.0, 0, 1.0],
                                                             [0.8, 0, 1.9]])),
                               [-0.5, 0.5, np.hypot(0.3, 0.4)])
    ball = Sphere([1.0, 0.0, 0.0], 0.5)
    assert ball.distance(np.array([3.0, 0.0, 0.0])) == pytest.approx(1.5)
    assert ball.contains(np.array([1.2, 0.0, 0.1]))


def test_turned_box_agrees_with_its_mesh():
    box = Box([0.3, -0.2, 0.5], [1.0, 0.4, 1.0], yaw=0.6)
    mesh = MeshShape(box.to_trimesh())
    rng = np.random.default_rng(4)
    pts = rng.uniform(-1.5, 1.5, size=(300, 3))
    np.testing.assert_array_equal(mesh.contains(pts), box.contains(pts))
    np.testing.assert_allclose(mesh.signed_distance(pts), box.signed_distance(pts), atol=1e-9)
    seg = rng.uniform(-1.5, 1.5, size=(60, 2, 3))
    r = np.full(60, 0.08)
    a = box.capsule_clearance(seg, r, exact_below=np.inf)
    b = mesh.capsule_clearance(seg, r, exact_below=np.inf)
    np.testing.assert_array_equal(a <= 0, b <= 0)
    np.testing.assert_allclose(a[a > 0], b[a > 0], atol=1e-5)


def test_capsule_clearance_far_values_are_lower_bounds():
    box = Box([0.0, 0.0, 0.5], [1.0, 1.0, 1.0])
    rng = np.random.default_rng(5)
    seg = rng.uniform(-3, 3, size=(400, 2, 3))
    fast = box.capsule_clearance(seg, 0.05)
    exact = box.capsule_clearance(seg, 0.05, exact_below=np.inf)
    near = exact < 0.25
    np.testing.assert_allclose(fast[near], exact[near])
    assert np.all(fast <= exact + 1e-12) and np.all(fast[~near] >= 0.25 - 1e-12)


def test_shape_distance_intersection_and_enclosure():
    a = Box([0.0, 0.0, 0.0], [1.0, 1.0, 1.0])
    b = Box([2.0, 0.0, 0.0], [1.0, 1.0, 1.0])
    assert shape_distance(a, b) == pytest.approx(1.0)
    assert not shapes_intersect(a, b) and shapes_intersect(a, b, margin=1.0)
    c = Cylinder([0.0, 1.2, 0.0], 0.3, 1.0)
    assert shape_distance(a, c) == pytest.approx(0.4, abs=1e-4)      # fcl GJK tolerance
    assert shapes_intersect(a, Sphere([0.6, 0.0, 0.0], 0.2))
    small = Box([0.1, 0.0, 0.0], [0.2, 0.2, 0.2])
    assert shape_enclosed_in(small, a) and not shape_enclosed_in(a, small)
    assert shape_enclosed_in(small, Cylinder([0, 0, 0], 0.3, 0.4))
    assert not shape_enclosed_in(small.moved_to([0.35, 0, 0]), Cylinder([0, 0, 0], 0.3, 0.4))
    assert shape_enclosed_in(Sphere([0, 0, 0], 0.1), Sphere([0.05, 0, 0], 0.16))
    assert not shape_enclosed_in(Sphere([0, 0, 0], 0.1), Sphere([0.1, 0, 0], 0.16))
    # A box turned by 45 degrees pokes out of the axis-aligned box of equal size.
    assert not shape_enclosed_in(Box([0, 0, 0], [0.9, 0.9, 0.9], yaw=np.pi / 4), a)
    # Containment in a mesh: a solid inside a closed surface touches it at distance 0.
    shell = MeshShape(Box([0, 0, 0], [2.0, 2.0, 2.0]).to_trimesh())
    assert shape_distance(small, shell) == 0.0
    assert shape_enclosed_in(small, shell)


def test_polygon_signed_distance():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    pts = np.array([[0.5, 0.5], [2.0, 0.5], [2.0, 2.0], [0.9, 0.5]])
    np.testing.assert_allclose(point_polygon_signed_distance(pts, square),
                               [-0.5, 1.0, np.sqrt(2.0), -0.1])


def test_polygon_signed_distance_compiled_equals_numpy() -> None:
    """The compiled signed distance (floor maps) gives the numpy path's numbers bit for
    bit, for points inside, outside, on the vertices and on the edges."""
    from ltl_human_motion.scene import geometry
    from ltl_human_motion.scene.shapes import Box
    rng = np.random.default_rng(3)
    for poly in (Box([0.3, -0.2, 0.5], [0.8, 0.4, 1.0], yaw=0.4).footprint().vertices,
                 np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])):
        pts = np.concatenate([rng.uniform(-1.5, 1.5, (2000, 2)), poly,
                              (poly + np.roll(poly, -1, axis=0)) / 2.0]).reshape(-1, 4, 2)
        got = point_polygon_signed_distance(pts, poly)
        want = geometry._polygon_signed_distance(pts, *geometry._polygon_edges(poly))
        assert got.shape == (len(pts), 4)
        assert got.tobytes() == want.tobytes()
        assert (got < 0).any() and (got > 0.3).any() and (got == 0.0).any()


def test_shapes_validate_their_input():
    with pytest.raises(ValueError, match="extents must be positive"):
        Box([0, 0, 0], [1.0, 0.0, 1.0])
    with pytest.raises(ValueError, match=r"center must have shape \(3,\)"):
        Box([0, 0], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="lo < hi"):
        Box.from_bounds([0, 0, 0], [1, 0, 1])
    with pytest.raises(ValueError, match="radius and height must be positive"):
        Cylinder([0, 0, 0], -1.0, 1.0)
    with pytest.raises(ValueError, match=r"segments must have shape"):
        Box([0, 0, 0], [1, 1, 1]).capsule_clearance(np.zeros((3, 3)), 0.1)


def test_closed_form_segment_box_distance_matches_dense_sampling() -> None:
    from ltl_human_motion.scene.geometry import point_box_distance, segment_aabb_distance
    rng = np.random.default_rng(42)
    lo, hi = np.array([-0.3, -0.2, -0.5]), np.array([0.4, 0.1, 0.2])
    a = rng.uniform(-1.5, 1.5, (500, 3))
    b = a + rng.normal(0.0, 0.8, (500, 3))
    b[:50] = a[:50]                                     # degenerate segments (points)
    b[50:100, 1] = a[50:100, 1]                         # parallel to a face
    exact = segment_aabb_distance(a, b, lo, hi)
    t = np.linspace(0.0, 1.0, 4001)
    dense = point_box_distance(a[:, None] + t[None, :, None] * (b - a)[:, None], lo, hi).min(1)
    assert np.all(exact <= dense + 1e-12)               # never above a point of the segment
    np.testing.assert_allclose(exact, dense, atol=2e-4)
    inside = segment_aabb_distance(np.zeros((1, 3)), np.ones((1, 3)) * 0.05, lo, hi)
    assert inside[0] == 0.0
