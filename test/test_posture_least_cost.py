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
    for _ in range(40):
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


def _walled_case(rng: np.random.Generator, ahead: tuple[float, float], top: float,
                 nearest_wall: float) -> tuple:
    """A random worker, hand task and target (3,) ``ahead`` of it up to height ``top``,
    and obstacle clearances of a wall across the way at a random distance."""
    sk = Skeleton(float(rng.choice([1.55, 1.75, 1.95])))
    task = str(rng.choice(["grasp", "release", "assemble"]))
    target = np.array([rng.uniform(*ahead), rng.uniform(-0.2, 0.2), rng.uniform(0.05, top)])
    wall = float(rng.uniform(nearest_wall, 1.2))

    def obstacles(poses: np.ndarray, parts: tuple) -> np.ndarray:
        return (wall - poses[..., 0]).min(axis=-1)

    return sk, task, target, obstacles


def test_posture_clear_is_the_strict_grid_answer() -> None:
    """posture_clear (cheapest candidates first) answers as _grid with strict does, with
    obstacles (a wall ahead at random distances) and under low boards."""
    from ltl_human_motion.motion.goals.postures import posture_clear
    from ltl_human_motion.motion.goals.tasks import LEVEL_PATH_TASKS, _check_board
    rng = np.random.default_rng(5)
    answers = set()
    for trial in range(60):
        sk, task, target, obstacles = _walled_case(rng, (0.2, 0.8), 1.6, 0.1)
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


def _grid_postures(sk, st, targets, active, task, board, obstacles, furniture):
    """The reach postures as _grid's whole table picks them (the cheapest finite)."""
    P, D, S, cost, capped, kneel = _grid(sk, st, targets, active, task, board, obstacles,
                                         furniture=furniture)
    order = np.argsort(cost, kind="stable")[:4]
    order = order[np.isfinite(cost[order])]
    return [(float(P[i]), float(D[i]), float(S[i]), bool(capped[i]), bool(kneel[i]))
            for i in order]


def test_reach_postures_are_the_grid_cheapest() -> None:
    """_reach_postures (cheapest candidates first, _grid where it must) picks what _grid's
    whole table does: with obstacles (a wall ahead), furniture under the targets or a
    board over them, and low boards."""
    from ltl_human_motion.motion.goals.postures import _reach_postures
    from ltl_human_motion.motion.goals.tasks import LEVEL_PATH_TASKS, _check_board
    rng = np.random.default_rng(11)
    kinds = set()
    for trial in range(80):
        sk, task, target, obstacles = _walled_case(rng, (0.25, 0.75), 1.5, 0.2)
        st = _Start(sk, None)
        board = None
        if trial % 4 == 0 and task in LEVEL_PATH_TASKS:
            board = _check_board((float(rng.uniform(0.05, 0.3)), target[2] + 0.2,
                                  target[2] + 0.25))
        under = (1.0, 0.0, float(target[0] - rng.uniform(0.0, 0.3)), float(target[2])) \
            if trial % 3 == 1 else None
        over = (1.0, 0.0, float(target[0] - rng.uniform(0.0, 0.3)), target[2] + 0.3,
                target[2] + 0.35) if trial % 3 == 2 else None
        hand = "both" if task == "assemble" else "l_hand"
        targets, active, _ = _hand_targets(task, target, hand)
        for obs in (None, obstacles):
            want = _grid_postures(sk, st, targets, active, task, board, obs, (under, over))
            try:
                got = [(p.pitch, p.drop, p.shift, p.capped, p.kneel) for p in _reach_postures(
                    sk, st, targets, active, task, target, board, obs, (under, over))]
            except ValueError:
                got = []
            assert got == want
            kinds.add(len(got))
    assert 0 in kinds and 4 in kinds


def test_no_posture_is_clear_where_every_posture_meets_an_obstacle() -> None:
    """posture_clear (the strict search) with an obstacle that every pose enters: never
    clear, also where a single candidate reaches the target (at the edge of reach)."""
    from ltl_human_motion.motion.goals import posture_clear
    sk = Skeleton(1.75)

    def everywhere(poses: np.ndarray, parts: tuple[str, ...]) -> np.ndarray:
        return np.full(len(poses), -1.0)

    free = [(task, x, z) for x in np.linspace(0.3, 0.9, 13) for z in np.linspace(0.1, 1.9, 19)
            for task in ("grasp", "rightHand")
            if posture_clear(task, np.array([x, -0.15, z]), sk, everywhere)]
    assert free == []
