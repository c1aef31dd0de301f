"""enter / enclose / collision as defined in Sec. II-B, against brute-force sampling."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.scene import (
    Box,
    body_clearance,
    capsules_from_positions,
    cell_by_name,
    cell_from_yaml,
    collision,
    enclose,
    enclose_object,
    enter,
    enter_object,
    ground_enter,
    object_clearance,
)

REST = Skeleton().rest_positions()
HAND = JOINT_INDEX["r_hand"]


@pytest.fixture(scope="module")
def paper():
    return cell_by_name("paper_cell")


def _placed(offset):
    """Rest pose translated by ``offset`` (..., 3): shape (..., J, 3)."""
    return REST + np.asarray(offset, dtype=float)[..., None, :]


def _surface_points(seg, radius, n=24, rng=None):
    """Points on a capsule surface: end-cap and side samples, shape (M, 3)."""
    rng = rng or np.random.default_rng(0)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    t = np.linspace(0, 1, n)[:, None]
    axis = seg[0] + t * (seg[1] - seg[0])
    return np.concatenate([seg[0] + radius * d, seg[1] + radius * d, axis + radius * d])


def test_enclose_hand_matches_sampled_surface():
    region = Box.from_bounds([0.9, -1.1, 0.9], [1.1, -0.9, 1.1])
    rng = np.random.default_rng(7)
    # Hands near the region, in a vertical hand orientation (rest pose).
    # The 0.19 m long capsule fits the 0.2 m box only for palm heights in [0.945, 0.959].
    hands = rng.uniform([0.92, -1.08, 0.93], [1.08, -0.92, 0.975], size=(400, 3))
    pos = _placed(hands - REST[HAND])           # hanging hand, palm centre at ``hands``
    got = enclose(pos, region, "r_hand")
    assert got.shape == (400,) and got.any() and (~got).any()
    seg, rad = capsules_from_positions(pos, parts="r_hand")
    for i in range(len(pos)):
        pts = _surface_points(seg[i, 0], rad[0], rng=rng)
        if got[i]:
            assert np.all(region.contains(pts))
        else:
            # Some point of the capsule lies outside: an end ball pokes out.
            ends = seg[i, 0]
            sd = region.signed_distance(ends)
            assert np.max(sd) > -rad[0] - 1e-12


def test_enter_matches_dense_sampling():
    region = Box.from_bounds([0.9, -1.1, 0.9], [1.1, -0.9, 1.1])
    rng = np.random.default_rng(8)
    hands = rng.uniform([0.7, -1.3, 0.7], [1.3, -0.7, 1.4], size=(300, 3))
    pos = _placed(hands - REST[HAND])
    got = enter(pos, region, "r_hand")
    seg, rad = capsules_from_positions(pos, parts="r_hand")
    t = np.linspace(0, 1, 2001)[:, None]
    for i in range(len(pos)):
        axis = seg[i, 0, 0] + t * (seg[i, 0, 1] - seg[i, 0, 0])
        dmin = region.distance(axis).min()
        if got[i]:
            assert dmin <= rad[0] + 1e-4
        else:
            assert dmin > rad[0]
    # With a margin the region grows by B(eps).
    grown = enter(pos, region, "r_hand", margin=0.1)
    assert np.all(grown >= got) and grown.sum() > got.sum()


def test_whole_body_enter_and_region_objects(paper):
    assert enter(REST, paper.start_region)
    assert not enter(REST, paper.region("R1"))
    assert enter(_placed([0.6, -1.0, 0.0]), paper.region("R1"), margin=0.5)
    assert not enclose(REST, paper.start_region)       # the body is taller than R0
    # A SceneObject target is its occupancy at its initial position.
    assert enter_object(paper.object("O1"), Box([-1.0, -1.0, 0.3], [0.2, 0.2, 0.2]))
    assert not enter_object(paper.object("O1"), paper.region("R1"))
    at_r1 = paper.object("O1").occupancy_at(paper.region("R1").center)
    assert enclose_object(at_r1, paper.region("R1"))
    assert not enclose_object(at_r1.translated([0.06, 0.0, 0.0]), paper.region("R1"))
    assert enter_object(at_r1.translated([0.06, 0.0, 0.0]), paper.region("R1"))


def test_collision_with_static_obstacles(paper):
    frames = np.stack([_placed([0.0, 0.0, 0.0]), _placed([1.2, -1.0, 0.0]),
                       _placed([0.45, -1.0, 0.0]), _placed([0.9, -1.0, 0.0])])
    hits = collision(frames, paper)
    assert hits.tolist() == [False, True, False, True]
    clear = body_clearance(frames, paper)
    assert clear.shape == (4,)
    assert clear[0] > 0.25 and clear[1] <= 0.0
    # Standing 0.2 m in front of the bench edge (x = 0.8): the hands hang 0.12 m in front.
    assert 0.0 < clear[2] < 0.25
    assert collision(frames[2], paper, margin=clear[2] + 1e-3)
    with pytest.raises(ValueError, match="margin"):
        collision(frames, paper, margin=-0.1)


def test_carried_objects_count_for_collision(paper):
    frames = np.repeat(REST[None], 4, axis=0)
    bench_top = np.array([1.2, -1.0, 0.82])
    carried = {"O1": np.array([[0.0, 0.5, 1.0], bench_top, [np.nan] * 3, [1.2, -1.0, 1.0]])}
    hits = collision(frames, paper, carried=carried)
    assert hits.tolist() == [False, True, False, False]
    d = object_clearance(paper, "O1", carried["O1"])
    assert np.isinf(d[2]) and d[1] == 0.0
    np.testing.assert_allclose(d[3], 1.0 - 0.05 - 0.85, atol=1e-9)   # above the bench top
    with pytest.raises(ValueError, match="carried"):
        collision(frames, paper, carried={"O1": np.zeros((3, 3))})


def test_carried_object_near_a_cylinder_uses_exact_distance(paper):
    column = paper.obstacle("drill_press").parts[1]
    assert column.kind == "cylinder"
    # Beside the column, 5 cm from its surface, above the drill press's other parts.
    p = column.center + np.array([column.radius + 0.05 + 0.05, 0.0, 0.0])
    d = object_clearance(paper, "O1", p[None])
    assert d[0] == pytest.approx(0.05, abs=1e-4)


def test_ground_enter():
    assert ground_enter(REST, ("l_foot",), 0.0)
    assert not ground_enter(REST, "head", 1.26)
    lowered = _placed([0.0, 0.0, -0.8])
    assert ground_enter(lowered, "head", 1.26)
    floor_cell = cell_from_yaml("start_region: R0\nfloor_z: 0.5\nregions:\n"
                                "  R0: {lo: [-1, -1, 0.5], hi: [1, 1, 0.6]}\n")
    assert ground_enter(REST, "l_knee", 0.0, floor_z=floor_cell.floor_z)


def test_distance_to_is_the_exact_body_region_gap(paper):
    from ltl_human_motion.scene import distance_to, segment_box_distance
    r1 = paper.region("R1")
    poses = np.stack([_placed([0.0, 0.0, 0.0]), _placed([0.5, -1.0, 0.0]),
                      _placed([1.0, -1.0, 0.3])])
    got = distance_to(poses, r1)
    seg, rad = capsules_from_positions(poses)
    ref = np.maximum(np.min(segment_box_distance(seg[..., 0, :], seg[..., 1, :], r1.lo, r1.hi)
                            - rad, axis=-1), 0.0)
    np.testing.assert_allclose(got, ref, atol=1e-9)
    assert got[0] > 1.0 and got[2] == 0.0
    assert distance_to(poses[1], r1, "r_hand") >= got[1]
