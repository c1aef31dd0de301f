"""Goal motions in the layouts the hand-shaped models failed in, synthesized and verified
as a user runs them (unseen-style cells of :mod:`ltl_human_motion.scenarios.unseen`,
the biomechanical checks on, every frame checked): a machine chamber's insert and
extract at three statures, the part taken out without passing through the chamber's
floor, and a part too wide for the door refused before planning."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.planning import synthesize
from ltl_human_motion.scenarios.unseen import build_cell
from ltl_human_motion.scene.cell_yaml import cell_from_yaml
from ltl_human_motion.scene.predicates import collision, object_clearance

pytestmark = pytest.mark.slow


def _cell(family: str, index: int = 0):
    built = build_cell(family, 0, index)
    return cell_from_yaml(built.yaml, source=built.name)


def _verified(spec: str, cell, stature: float):
    """The first motion of ``spec`` (synthesize raises unless it verified), with its
    body and carried parts checked again here on every frame."""
    motion = synthesize(spec, cell, stature=stature, seed=0)[0]
    assert not collision(motion.motion.positions, cell, stature=stature).any()
    return motion


@pytest.mark.parametrize("stature", [1.55, 1.75, 1.95])
def test_chamber_extract(stature):
    cell = _cell("chamber")
    motion = _verified("F extract(done, vise_a)", cell, stature)
    track = np.asarray(motion.objects["done"])
    carried = track[np.isfinite(track).all(axis=1)]
    # the part comes out of the chamber without passing through its floor
    assert object_clearance(cell, "done", carried).min() >= 0.0


@pytest.mark.parametrize("stature", [1.55, 1.75, 1.95])
def test_chamber_insert(stature):
    _verified("F insert(blank, vise_b)", _cell("chamber"), stature)


def test_a_part_wider_than_the_door_is_refused_before_planning():
    """A casting wider than the machine's door opening cannot be moved into its bay:
    refused at once with reason ``size``, naming the part and the region."""
    from ltl_human_motion.errors import PlanningError
    from ltl_human_motion.planning.feasibility import step_problems
    cell = _cell("chamber")
    problems = step_problems(cell, [("move", ("casting", "R_bay"))], 1.75)
    assert [p.reason for p in problems] == ["size"]
    assert "casting" in str(problems[0]) and "R_bay" in str(problems[0])
    assert step_problems(cell, [("move", ("blank", "R_bay"))], 1.75) == []
    with pytest.raises(PlanningError, match="wide enough"):
        synthesize("F move(casting, R_bay)", cell, stature=1.75)
