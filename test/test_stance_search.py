"""Where else a blocked goal step stands (planning/stance_search.py): candidate stances
ranked by how far they are from where the blocked try stood, checked by the goal model,
never near one whose motion was blocked; and, on a real cell, a seated task that the
first place blocks done from a stance the model found."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from ltl_human_motion.planning.pipeline import get_library
from ltl_human_motion.planning.plan_state import PlanContext, PlannerOptions
from ltl_human_motion.planning.stance_search import (
    SPREAD,
    STANCE_BACKS,
    STANCE_CHECKS,
    WALK_FAILED_NEAR,
    Stance,
    StanceTries,
    candidate_stances,
    clear_stances,
)
from ltl_human_motion.scenarios.corpus import load_corpus
from ltl_human_motion.scenarios.run import judge, run_pair
from ltl_human_motion.scenarios.unseen import build_cell
from ltl_human_motion.scene.cell_yaml import cell_from_yaml


@pytest.fixture(scope="module")
def chamber():
    built = build_cell("chamber", 0, 0)
    cell = cell_from_yaml(built.yaml, source=built.name)
    return PlanContext.build(cell, get_library(1.75), np.random.default_rng(0),
                             PlannerOptions())


def _target(ctx: PlanContext) -> np.ndarray:
    name = next(iter(ctx.cell.objects))
    return np.asarray(ctx.cell.object(name).position, dtype=float)


def test_candidates_are_free_distinct_and_nearest_first(chamber):
    target = _target(chamber)
    stood = (float(target[0]) - 0.6, float(target[1]), 0.0)
    found = candidate_stances(chamber, target, stood, math.pi, [(0.5, -0.15), (0.5, 0.15)])
    assert len(found) > 10
    costs = [s.cost for s in found]
    assert costs == sorted(costs)
    xy = np.array([s.pose[:2] for s in found])
    # all but the steps straight back from where the blocked try stood: placed out of
    # the furniture
    assert np.sum(chamber.stand_map(xy) <= chamber.stand_room) <= len(STANCE_BACKS) - 1
    assert len({s.pose for s in found}) == len(found)
    assert all(math.hypot(s.pose[0] - stood[0], s.pose[1] - stood[1]) >= 0.03
               or abs(s.pose[2]) >= math.radians(5.0) for s in found)


def _stances(n: int) -> list[Stance]:
    """``n`` stances 5 cm apart along x, facing +x."""
    return [Stance(0.0, (0.5, 0.0), (0.05 * k, 0.0, 0.0), 0.05 * k) for k in range(n)]


def test_checks_spread_out_and_clear_motions_come_first():
    checked: list[float] = []

    def motion_ok(pose):
        checked.append(pose[0])
        return pose[0] > 0.5

    found = [s.pose[0] for s in clear_stances(_stances(60), lambda pose: True, motion_ok)]
    assert len(checked) == STANCE_CHECKS
    assert all(b - a >= SPREAD - 1e-9 for a, b in itertools.pairwise(checked))
    clear = [x for x in checked if x > 0.5]
    assert found == clear + [x for x in checked if x <= 0.5]


def test_no_motion_is_made_where_no_posture_is_clear_and_those_come_last():
    made: list[float] = []
    found = list(clear_stances(_stances(10), lambda pose: pose[0] >= 0.2,
                               lambda pose: made.append(pose[0]) or True))
    assert min(made) >= 0.2
    assert [s.pose[0] for s in found] == pytest.approx(made + [0.0, 0.15])


def test_stances_out_of_the_models_reach_are_never_tried():
    found = list(clear_stances(_stances(10), lambda pose: True,
                               lambda pose: None if pose[0] < 0.2 else False))
    assert found and min(s.pose[0] for s in found) >= 0.2


def test_later_stances_are_searched_only_when_asked_and_not_by_a_failed_walk():
    calls: list[int] = []

    def find():
        for k, stance in enumerate(_stances(8)):
            calls.append(k)
            yield stance

    tries = StanceTries(find)
    assert calls == []
    first = tries.next()
    assert first.pose[0] == 0.0 and calls == [0]
    tries.walk_failed(first)
    # 5, 10 cm from the stance no walk got to: skipped
    assert tries.next().pose[0] >= WALK_FAILED_NEAR and calls == [0, 1, 2, 3]
    assert [tries.next() is None for _ in range(5)][-1]


def test_sitting_where_the_first_place_blocks_the_hand():
    """The desk blocks the left hand of the sit from the place the walk to the chair
    ends at; the worker sits from a stance the model checked (a 1.55 m worker)."""
    pair = next(p for p in load_corpus() if p.id == "seats/job/fetch_then_sit")
    outcome = run_pair(pair.spec, pair.cell_file, 1.55, 0, timeout=30.0)
    ok, family = judge(pair.expect, pair.reason, outcome)
    assert ok, f"{family}: {outcome.message[:300]}"
