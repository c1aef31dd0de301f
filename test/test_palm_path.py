"""The palm path the whole-body program tracks (motion/goals/palm_path.py): remade round
furniture the reference's palm passes through, on the reference's timing, with the real
obstacle kernel (scene.clearance.PartSet) and the program's real field."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion.goals.palm_path import PathRoom, clear_palm_path, point_clearance
from ltl_human_motion.planning.constrained_goals import PartSetField
from ltl_human_motion.scene.clearance import PartSet
from ltl_human_motion.scene.shapes import Box

ROOM = PathRoom(0.055)


def _field(*boxes: tuple[tuple[float, ...], tuple[float, ...]], pose=(0.0, 0.0, 0.0)):
    return PartSetField(PartSet([Box.from_bounds(np.array(lo), np.array(hi))
                                 for lo, hi in boxes]), pose)


def _reference(a: np.ndarray, b: np.ndarray, frames: int = 40) -> np.ndarray:
    s = np.linspace(0.0, 1.0, frames)
    s = 10 * s**3 - 15 * s**4 + 6 * s**5                 # minimum jerk
    return a + (b - a) * s[:, None]


def test_a_clear_path_is_kept_as_it_is():
    field_ = _field(((1.0, -1.0, 0.0), (1.5, 1.0, 0.9)))
    ref = _reference(np.array([0.2, -0.2, 0.9]), np.array([0.6, -0.1, 1.3]))
    np.testing.assert_array_equal(clear_palm_path(field_, ref, ROOM), ref)


def test_a_palm_coming_up_through_a_board_goes_round_its_edge():
    """The reference rises to a part on a shelf board from below it: the remade path
    keeps ``ROOM`` from the board at every frame, ends where the reference does and
    starts as it does."""
    board = ((0.4, -0.5, 1.30), (0.9, 0.5, 1.325))
    field_ = _field(board)
    ref = _reference(np.array([0.55, -0.15, 0.95]), np.array([0.65, -0.15, 1.40]))
    assert point_clearance(field_, ref, 1.0).min() <= 0.0
    path = clear_palm_path(field_, ref, ROOM)
    assert path is not None and path.shape == ref.shape
    assert point_clearance(field_, path, 1.0).min() >= ROOM.radius - 1e-6
    np.testing.assert_allclose(path[[0, -1]], ref[[0, -1]])
    # round the board's front edge (x < 0.4), not through it
    assert path[:, 0].min() < board[0][0]
    # on the reference's timing: at rest where it is at rest
    np.testing.assert_allclose(path[:2], ref[:2], atol=1e-3)


def test_no_way_round_gives_none():
    """A palm end inside a closed box has no clear way to it."""
    field_ = _field(((0.4, -0.5, 1.0), (0.9, 0.5, 1.02)),
                    ((0.4, -0.5, 1.5), (0.9, 0.5, 1.52)),
                    ((0.38, -0.5, 1.0), (0.4, 0.5, 1.52)),
                    ((0.9, -0.5, 1.0), (0.92, 0.5, 1.52)),
                    ((0.38, -0.52, 1.0), (0.92, -0.5, 1.52)),
                    ((0.38, 0.5, 1.0), (0.92, 0.52, 1.52)))
    ref = _reference(np.array([0.1, 0.0, 1.2]), np.array([0.65, 0.0, 1.25]))
    assert clear_palm_path(field_, ref, ROOM) is None


@pytest.mark.parametrize("yaw", [0.0, 1.2])
def test_the_field_is_read_in_the_start_frame(yaw):
    """The same board seen from a worker turned by ``yaw``: the path is the same in the
    start frame."""
    c, s = np.cos(yaw), np.sin(yaw)
    lo, hi = np.array([0.4, -0.5, 1.30]), np.array([0.9, 0.5, 1.325])
    corners = np.array([[x, y] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])]) @ \
        np.array([[c, s], [-s, c]])
    world = ((*corners.min(axis=0), lo[2]), (*corners.max(axis=0), hi[2]))
    ref = _reference(np.array([0.55, -0.15, 0.95]), np.array([0.65, -0.15, 1.40]))
    path = clear_palm_path(_field(world, pose=(0.0, 0.0, yaw)), ref, ROOM)
    assert path is not None
    field_ = _field(world, pose=(0.0, 0.0, yaw))
    assert point_clearance(field_, path, 1.0).min() >= ROOM.radius - 1e-6
