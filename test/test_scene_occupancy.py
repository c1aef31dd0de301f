"""Body capsules: layout, scaling with stature, parts, vectorization."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.skeleton import JOINT_INDEX, JOINT_NAMES, Skeleton
from ltl_human_motion.scene import (
    BODY_CAPSULES,
    BODY_PARTS,
    body_radius_xy,
    capsule_radii,
    capsules_from_positions,
    occ,
    part_indices,
)


def test_capsules_cover_every_segment_and_the_table_i_parts():
    joints = {j for _, a, b, _ in BODY_CAPSULES for j in (a, b)}
    assert joints == set(JOINT_NAMES)
    for part in ("l_hand", "r_hand", "l_knee", "r_knee", "head", "buttocks", "torso", "pelvis",
                 "l_upper_arm", "l_lower_arm", "l_thigh", "l_shank", "l_foot"):
        assert part in BODY_PARTS
    assert len(set(BODY_PARTS)) == len(BODY_PARTS)
    assert all(r > 0 for *_, r in BODY_CAPSULES)


def test_rest_pose_occupancy_has_the_body_size():
    for stature in (1.5, 1.75, 2.0):
        rest = Skeleton(stature=stature).rest_positions()
        seg, rad = capsules_from_positions(rest, stature)
        assert seg.shape == (len(BODY_CAPSULES), 2, 3) and rad.shape == (len(BODY_CAPSULES),)
        top = np.max(seg[..., 2] + rad[:, None])
        assert top == pytest.approx(stature, rel=0.03)        # head top near the stature
        bottom = np.min(seg[..., 2] - rad[:, None])
        assert abs(bottom) < 0.03 * stature                   # feet at the floor
        width = np.ptp(np.concatenate([seg[..., 1] - rad[:, None], seg[..., 1] + rad[:, None]]))
        assert 0.2 * stature < width < 0.32 * stature         # shoulder/hand breadth
    np.testing.assert_allclose(capsule_radii(2.0) / capsule_radii(1.75), 2.0 / 1.75)
    assert body_radius_xy(1.75) == pytest.approx(0.26, abs=0.02)


def test_segments_follow_the_joints_and_vectorize():
    rng = np.random.default_rng(2)
    pos = rng.normal(size=(4, 5, len(JOINT_NAMES), 3))
    seg, _ = capsules_from_positions(pos)
    assert seg.shape == (4, 5, len(BODY_CAPSULES), 2, 3)
    k = BODY_PARTS.index("r_lower_arm")
    np.testing.assert_array_equal(seg[..., k, 0, :], pos[..., JOINT_INDEX["r_elbow"], :])
    np.testing.assert_array_equal(seg[..., k, 1, :], pos[..., JOINT_INDEX["r_wrist"], :])
    knee = BODY_PARTS.index("l_knee")
    np.testing.assert_array_equal(seg[..., knee, 0, :], seg[..., knee, 1, :])   # a sphere


def test_parts_and_aliases():
    rest = Skeleton().rest_positions()
    seg, rad = occ(rest, "rh")
    assert seg.shape == (1, 2, 3) and rad.shape == (1,)
    np.testing.assert_array_equal(seg[0, 1], rest[JOINT_INDEX["r_hand"]])
    seg, _ = occ(rest, ["lk", "rk", "head"])
    assert seg.shape == (3, 2, 3)
    assert list(part_indices("hands")) == sorted([BODY_PARTS.index("l_hand"),
                                                 BODY_PARTS.index("r_hand")])
    with pytest.raises(ValueError, match="unknown body part 'tail'"):
        part_indices("tail")
    with pytest.raises(ValueError, match=r"positions must have shape \(\.\.\., 23, 3\)"):
        capsules_from_positions(np.zeros((10, 3)))
    with pytest.raises(ValueError, match="stature must be positive"):
        capsule_radii(0.0)


def test_body_boxes_are_the_capsule_boxes():
    from ltl_human_motion.scene.occupancy import body_boxes, capsules_from_positions

    rng = np.random.default_rng(7)
    rest = Skeleton(stature=1.75).rest_positions()
    pos = rest[None] + rng.normal(scale=0.2, size=(40, len(JOINT_NAMES), 3))
    for stature in (1.6, 1.9):
        seg, rad = capsules_from_positions(pos, stature)
        lo, hi = body_boxes(pos, stature)
        # The same numbers, bit for bit, as the boxes of the capsules' end points +- radii.
        assert np.array_equal(lo, (seg.min(axis=2) - rad[:, None]).min(axis=1))
        assert np.array_equal(hi, (seg.max(axis=2) + rad[:, None]).max(axis=1))
    with pytest.raises(ValueError, match="shape"):
        body_boxes(pos[0], 1.75)
