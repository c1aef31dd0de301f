"""deepest_contact: which body part meets which obstacle, against per-capsule brute force."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.capsules import BODY_PARTS
from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.scene import capsules_from_positions, cell_from_yaml
from ltl_human_motion.scene.contacts import Contact, deepest_contact

REST = Skeleton().rest_positions()

CELL = """
start_region: R0
regions:
  R0: {lo: [-0.5, -0.5, 0.0], hi: [0.5, 0.5, 0.1]}
obstacles:
  beam:
    shape: box
    position: [0.0, 0.0, 1.80]
    size: [0.4, 0.4, 0.1]
  bench:
    shape: box
    position: [0.0, -0.55, 0.375]
    size: [0.6, 0.4, 0.75]
"""


@pytest.fixture(scope="module")
def cell():
    return cell_from_yaml(CELL)


def _brute_force(pose, cell):
    """(part, obstacle, depth) of the deepest capsule-obstacle pair of one pose."""
    seg, rad = capsules_from_positions(pose)
    best = (None, None, np.inf)
    for ob in cell.obstacles:
        d = ob.capsule_clearance(seg, rad)                     # (K,)
        k = int(np.argmin(d))
        if d[k] < best[2]:
            best = (BODY_PARTS[k], ob.name, float(d[k]))
    return best


def test_the_deepest_frame_part_and_obstacle_are_named(cell):
    lifts = np.array([0.0, 0.02, 0.12, 0.05])             # the head rises into the beam
    frames = REST[None] + lifts[:, None, None] * np.array([0.0, 0.0, 1.0])
    contact = deepest_contact(frames, cell, stature=1.75)
    assert isinstance(contact, Contact)
    part, obstacle, clearance = _brute_force(frames[2], cell)
    assert (contact.frame, contact.part, contact.obstacle) == (2, part, obstacle)
    assert contact.part == "head" and contact.obstacle == "beam"
    assert contact.depth == pytest.approx(-clearance, abs=1e-9)
    text = contact.describe(fps=100.0)
    assert text.startswith("the head enters beam by ") and text.endswith("at t = 0.02 s")


def test_a_side_part_is_named_with_its_side(cell):
    pose = REST + np.array([0.0, -0.2, -0.1])             # the right side into the bench
    contact = deepest_contact(pose, cell)
    part, obstacle, clearance = _brute_force(pose, cell)
    assert (contact.part, contact.obstacle) == (part, obstacle)
    assert contact.part.startswith("r_") and obstacle == "bench"
    assert contact.depth == pytest.approx(-clearance, abs=1e-9)
    assert "right" in contact.describe() and "frame 0" in contact.describe()


def test_no_contact_is_none_and_bad_shapes_are_refused(cell):
    assert deepest_contact(REST + np.array([2.0, 2.0, 0.0]), cell) is None
    with pytest.raises(ValueError, match=r"\(T, J, 3\)"):
        deepest_contact(np.zeros((4, 3, 2)), cell)
