"""The standing-place search's least posture cost (postures.least_cost, cheapest
candidates first) is the posture grid's least cost (postures._grid), to the bit."""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.goals.body import _Start
from ltl_human_motion.motion.goals.postures import _grid, least_cost
from ltl_human_motion.motion.goals.tasks import _hand_targets
from ltl_human_motion.motion.skeleton import Skeleton


def test_least_cost_is_the_grid_minimum() -> None:
    rng = np.random.default_rng(3)
    reached = 0
    for trial in range(40):
        sk = Skeleton(float(rng.choice([1.55, 1.75, 1.95])))
        st = _Start(sk, None)
        task = str(rng.choice(["grasp", "release", "assemble", "leftHand"]))
        target = np.array([rng.uniform(0.1, 0.9), rng.uniform(-0.3, 0.3),
                           rng.uniform(0.0, 2.0)])
        hand = "both" if task == "assemble" else str(rng.choice(["l_hand", "r_hand"]))
        targets, active, _ = _hand_targets(task, target, hand)
        _, _, _, cost, capped, kneel = _grid(sk, st, targets, active, task)
        for capped_only in (False, True):
            want = float(np.min(np.where(capped | kneel, cost, np.inf) if capped_only
                                else cost))
            assert least_cost(sk, st, targets, active, task, capped_only) == want
        reached += bool(np.isfinite(cost).any())
    assert 5 < reached < 40


def test_posture_clear_is_the_strict_grid_answer() -> None:
    """posture_clear (cheapest candidates first) answers as _grid with strict does, with
    obstacles (a wall ahead at random distances) and under low boards."""
    from ltl_human_motion.motion.goals.postures import posture_clear
    from ltl_human_motion.motion.goals.tasks import LEVEL_PATH_TASKS, _check_board
    rng = np.random.default_rng(5)
    answers = set()
    for trial in range(60):
        sk = Skeleton(float(rng.choice([1.55, 1.75, 1.95])))
        task = str(rng.choice(["grasp", "release", "assemble"]))
        target = np.array([rng.uniform(0.2, 0.8), rng.uniform(-0.2, 0.2),
                           rng.uniform(0.05, 1.6)])
        wall = float(rng.uniform(0.1, 1.2))

        def obstacles(poses: np.ndarray, parts: tuple, wall: float = wall) -> np.ndarray:
            return (wall - poses[..., 0]).min(axis=-1)

        board = (float(rng.uniform(0.05, 0.3)), target[2] + 0.2, target[2] + 0.25) \
            if trial % 3 == 0 else None
        hand = "both" if task == "assemble" else "r_hand"
        targets, active, _ = _hand_targets(task, target, hand)
        grid_board = _check_board(board) if board is not None and task in LEVEL_PATH_TASKS \
            else None
        want = bool(np.isfinite(_grid(sk, _Start(sk, None), targets, active, task,
                                      grid_board, obstacles, strict=True)[3]).any())
        got = posture_clear(task, target, sk, obstacles, hand=hand, board=board)
        assert got == want
        answers.add(got)
    assert answers == {True, False}
