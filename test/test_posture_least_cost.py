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
